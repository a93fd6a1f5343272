#pragma once
// Sparse Cholesky factor of a body's stiffness (CHOLMOD supernodal, through Eigen's
// CholmodSupport), computed once and reused for every solve.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "numerics/elasticity.hpp"

namespace robin {

class CholeskyFactor {
 public:
  /// Factorizes the symmetric positive definite `matrix` (only its lower triangle is read).
  /// Throws SingularBodyError naming `body_name` when the matrix is not positive definite.
  CholeskyFactor(const SparseMatrix& matrix, const std::string& body_name);
  ~CholeskyFactor();
  CholeskyFactor(const CholeskyFactor&) = delete;
  CholeskyFactor& operator=(const CholeskyFactor&) = delete;

  int size() const;
  /// x = K^{-1} b: one forward and one backward triangular solve.
  Eigen::VectorXd solve(const Eigen::VectorXd& right_hand_side) const;
  /// Multiple right-hand sides at once (blocked supernodal solves).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& right_hand_sides) const;
  /// Number of nonzeros of the factor L.
  long factor_nonzeros() const;
  /// Number of solves performed so far (each is two triangular solves per column).
  long solve_count() const { return solve_count_; }

 private:
  struct Implementation;
  std::unique_ptr<Implementation> implementation_;
  mutable long solve_count_ = 0;
};

}  // namespace robin
