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
  /// Throws SingularBodyError naming `body_name` when the matrix is not positive definite or
  /// numerically singular (pivot ratio min L_jj^2 / max L_jj^2 < 1e-13, i.e. cond > 1e13);
  /// InputError when it is empty or not square. Solves are not thread-safe (CHOLMOD workspace).
  CholeskyFactor(const SparseMatrix& matrix, const std::string& body_name);
  ~CholeskyFactor();
  CholeskyFactor(const CholeskyFactor&) = delete;
  CholeskyFactor& operator=(const CholeskyFactor&) = delete;

  int size() const;
  /// x = K^{-1} b: one forward and one backward triangular solve.
  Eigen::VectorXd solve(const Eigen::VectorXd& right_hand_side) const;
  /// Multiple right-hand sides at once (supernodal solves in blocks of at most 64 columns).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& right_hand_sides) const;
  /// Number of entries stored in the lower triangle of the supernodal factor L (including the
  /// explicit zeros of supernode amalgamation).
  long factor_nonzeros() const;
  /// Number of right-hand sides solved so far: +1 per vector solve, +columns per matrix solve
  /// (each right-hand side costs one forward and one backward triangular solve).
  long solve_count() const { return solve_count_; }

 private:
  struct Implementation;
  std::unique_ptr<Implementation> implementation_;
  mutable long solve_count_ = 0;
};

}  // namespace robin
