#pragma once
// A generalized inverse K^+ of a body's reduced stiffness K (free dofs), singular when the
// Dirichlet conditions leave rigid motions free, in the style of TFETI.
//
// With R (free x k, orthonormal) spanning the kernel of K (dof_map.hpp, rigid_body_modes):
//  - k = 0: K is SPD and K^+ = K^{-1}, the CholeskyFactor of K itself (nothing else is done,
//    so a body without rigid motions is computed exactly as before);
//  - k > 0: k "fixing" dofs c are removed. They are the first k columns chosen by a QR with
//    column pivoting of R' (k x free), so that R_c (k x k) is well conditioned: no rigid motion
//    vanishes on c, hence K_rr, K restricted to the remaining dofs r, is SPD, and
//        K^+ = [K_rr^{-1} 0; 0 0]     (rows and columns in the order r, c).
//    Since rank K = rank K_rr = free - k, K K^+ K = K: K^+ is a generalized inverse
//    (symmetric, positive semi-definite). K x = b is solvable iff R'b = 0, and then every
//    solution is x = K^+ b + R alpha.
//    The Moore-Penrose inverse is K^dagger = P K^+ P with P = I - R R' (for symmetric K and any
//    generalized inverse: K^dagger K = K K^dagger = P).
// Only K_rr is factorized (CHOLMOD, the same CholeskyFactor); nothing dense of the body's size
// is formed.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "numerics/cholesky.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/setup_progress.hpp"

namespace robin {

class GeneralizedInverse {
 public:
  /// Factorizes K (free x free) with kernel `kernel` (free x k orthonormal columns, k = 0 for an
  /// SPD K) with `options` (cholesky.hpp; trailing unknowns and points indexed by free dof):
  /// fixing dofs among the trailing unknowns are dropped. Throws as CholeskyFactor
  /// (SingularBodyError when K_rr is not positive definite: the kernel was not the whole null
  /// space, e.g. a disconnected mesh).
  GeneralizedInverse(const SparseMatrix& stiffness, Eigen::MatrixXd kernel,
                     const std::string& body_name, FactorizationOptions options = {});
  /// The same, taking K: it is freed (left empty) during the factorization (cholesky.hpp).
  GeneralizedInverse(SparseMatrix&& stiffness, Eigen::MatrixXd kernel, const std::string& body_name,
                     FactorizationOptions options = {});

  int size() const { return size_; }
  /// k, the dimension of the kernel.
  int rigid_mode_count() const { return static_cast<int>(kernel_.cols()); }
  /// R (free x k, orthonormal columns).
  const Eigen::MatrixXd& kernel() const { return kernel_; }
  /// The fixing dofs c (free indices), empty for k = 0.
  const std::vector<int>& fixing_dofs() const { return fixing_dofs_; }

  /// x = K^+ b (the CholeskyFactor's solve when k = 0).
  Eigen::VectorXd solve(const Eigen::VectorXd& right_hand_side) const;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& right_hand_sides) const;
  /// x = K^dagger b = P K^+ P b, P = I - R R': the minimum-norm least-squares solution of
  /// K x = b (the solution orthogonal to R when R'b = 0). K^+ b when k = 0.
  Eigen::VectorXd solve_minimum_norm(const Eigen::VectorXd& right_hand_side) const;

  /// B K^+ B' from the factor's trailing block (cholesky.hpp) for a sparse B (rows x size()):
  /// the columns of the fixing dofs drop out, K^+ being zero there.
  bool has_trailing_block() const { return factor_->has_trailing_block(); }
  Eigen::MatrixXd trailing_congruence(const SparseMatrix& trace) const;

  long factor_nonzeros() const { return factor_->factor_nonzeros(); }
  long solve_count() const { return factor_->solve_count(); }
  double ordering_seconds() const { return factor_->ordering_seconds(); }
  double factorization_seconds() const { return factor_->factorization_seconds(); }

 private:
  /// The K_rr indices of `unknowns` (free indices), fixing dofs dropped; std::invalid_argument
  /// naming `body_name` for an index out of range.
  std::vector<int> kept_only(const std::vector<int>& unknowns, const std::string& body_name) const;
  Eigen::VectorXd restrict_to_kept(const Eigen::VectorXd& values) const;
  Eigen::VectorXd expand_from_kept(const Eigen::VectorXd& values) const;

  int size_ = 0;
  Eigen::MatrixXd kernel_;
  std::vector<int> fixing_dofs_;
  std::vector<int> kept_index_;  // kept_index_[j]: position of dof j in K_rr, -1 for fixing dofs
  std::unique_ptr<CholeskyFactor> factor_;
};

}  // namespace robin
