#pragma once
// The stiffness solve and the local contact problem of a body with an iterative inner solver
// (BodySolverOptions::linear_solver = multigrid).
//
// Stiffness solve. K x = b by conjugate gradients (conjugate_gradient.hpp) preconditioned by one
// V-cycle of smoothed-aggregation AMG (algebraic_multigrid.hpp) with the rigid body modes as its
// near-null space; stopped when ||b - K x|| <= tolerance ||b||.
//
// Contact problem. With u the free dofs, b the reduced load and c = g - B u_p:
//   minimise 1/2 u'Ku - b'u  subject to  B u <= c,
// whose KKT conditions are K u = b - B' lambda, lambda >= 0, c - B u >= 0, lambda'(c - B u) = 0.
// It is solved by the primal-dual active set method (Hintermueller, Ito and Kunisch 2002: a
// semismooth Newton method on these complementarity conditions). For an active set A, the
// equality-constrained problem
//   minimise 1/2 u'Ku - b'u  subject to  B_A u = c_A
// is solved with S = B_A B_A' (sparse, one row per active constraint; cholesky.hpp) and the
// orthogonal projection P = I - B_A' S^{-1} B_A onto ker B_A:
//   u_0 = u_prev + B_A' S^{-1} (c_A - B_A u_prev)   (the previous iterate moved onto B_A u = c_A),
//   u = u_0 + v,  v in ker B_A:  P K P v = P (b - K u_0),
// by conjugate gradients from v = 0 with the preconditioner P M^{-1} P. Its iterates stay in
// ker B_A, on which P K P and P M^{-1} P are positive definite, so this is PCG on the subspace.
// It stops when ||P (b - K u)|| <= tolerance (||b|| + ||K u_0||): relative to the size of the
// terms of K u + B' lambda = b, not of their projected difference, so neither a warm start nor a
// body loaded through its contact alone (b = 0: P K u_0 is small once u_0 is near equilibrium,
// while K u_0 is the contact force) tightens the test. Then
//   lambda_A = S^{-1} B_A (b - K u)   (K u + B_A' lambda_A = b in the least-squares sense),
// lambda = 0 off A, and the next active set is
//   A' = { j in A : lambda_j >= -tolerance ||lambda||_inf }
//        u { j not in A : (B u - c)_j > tolerance ||B u||_inf },
// the semismooth Newton step's set {lambda_j + rho (B u - c)_j > 0} with noise thresholds. When
// A' = A the Signorini conditions hold to the tolerances; negative lambda_j within the threshold
// are returned as 0. The steps are inexact while the set changes: solved (and thresholded) to
// PrimalContactOptions::changing_set_tolerance; the first step that finds the set unchanged is
// repeated from its own solution to the final tolerance, and the method stops when that one
// finds it unchanged too. After PrimalContactOptions::inexact_steps steps every step is solved to
// the final tolerance (so that rounding of the inexact steps cannot make the set cycle). Rows of B
// without a free dof cannot be made active (their value is fixed). The first active set is the
// previous solve's, or { j : (B u - c)_j > 0 } at the initial u.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "numerics/algebraic_multigrid.hpp"
#include "numerics/conjugate_gradient.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/linear_operator.hpp"
#include "numerics/mprgp.hpp"

namespace robin {

/// K^{-1} b by AMG-preconditioned conjugate gradients (the file comment).
class MultigridStiffnessSolver {
 public:
  /// Sets the AMG hierarchy up for the symmetric positive definite `lower` (its lower triangle;
  /// its storage taken over),
  /// with `near_null_space` (free x m), `dof_nodes` and `node_positions` as AlgebraicMultigrid
  /// takes them. `relative_tolerance` is the conjugate gradients' stopping tolerance;
  /// `body_name` names the body in errors.
  MultigridStiffnessSolver(SparseMatrix&& lower, const Eigen::MatrixXd& near_null_space,
                           const std::vector<int>& dof_nodes,
                           const std::vector<Eigen::Vector3d>& node_positions,
                           double relative_tolerance, std::string body_name);
  ~MultigridStiffnessSolver();
  MultigridStiffnessSolver(const MultigridStiffnessSolver&) = delete;
  MultigridStiffnessSolver& operator=(const MultigridStiffnessSolver&) = delete;

  int size() const;
  const LinearOperator& stiffness() const;
  /// The lower triangle of K, rebuilt from the AMG's blocks.
  SparseMatrix stiffness_matrix() const;
  const Preconditioner& preconditioner() const;
  double relative_tolerance() const { return relative_tolerance_; }
  const std::string& body_name() const { return body_name_; }

  /// x = K^{-1} b from the initial guess `initial` (zero when empty), to `relative_tolerance`
  /// (this solver's own when 0). Throws std::runtime_error naming the body when conjugate
  /// gradients stop without converging.
  Eigen::VectorXd solve(const Eigen::VectorXd& right_hand_side, const Eigen::VectorXd& initial = {},
                        double relative_tolerance = 0.0) const;
  /// Conjugate gradients for `matrix` x = b with `preconditioner` (the projected operators of the
  /// contact problem), counted like solve(); returns the result, throws as solve() does.
  ConjugateGradientResult solve_with(const LinearOperator& matrix,
                                     const Preconditioner& preconditioner,
                                     const Eigen::VectorXd& right_hand_side,
                                     Eigen::VectorXd& solution, double relative_tolerance) const;

  long solve_count() const { return solve_count_; }
  long iterations() const { return iterations_; }
  double setup_seconds() const;

 private:
  std::unique_ptr<AlgebraicMultigrid> multigrid_;
  double relative_tolerance_;
  std::string body_name_;
  mutable long solve_count_ = 0;
  mutable long iterations_ = 0;
};

/// The warm start of the next contact solve: the last solution and its active set.
struct PrimalContactState {
  Eigen::VectorXd displacement;   // u, free dofs (empty: none yet)
  std::vector<bool> active;       // the active set of u
  Eigen::VectorXd contact_force;  // lambda of u
};

struct PrimalContactResult {
  Eigen::VectorXd solution;      // lambda >= 0, one per row of B
  Eigen::VectorXd gradient;      // c - B u (the dual gradient: g - u_N)
  Eigen::VectorXd displacement;  // u, free dofs
  QpStatus status = QpStatus::not_converged;
  int iterations = 0;                    // active set steps
  int operator_applications = 0;         // conjugate gradient iterations, all steps
  double projected_gradient_norm = 0.0;  // ||P (b - K u)|| of the last step
  std::string message;
};

struct PrimalContactOptions {
  /// The active set thresholds and the projected conjugate gradients' tolerance (the file
  /// comment); at least the stiffness solver's tolerance is used.
  double relative_tolerance = 1e-12;
  /// The tolerance of the steps while the active set still changes (inexact steps: the set only
  /// needs to be right); the step that finds the set unchanged is repeated to
  /// relative_tolerance.
  double changing_set_tolerance = 1e-3;
  /// At most this many inexact steps; the later ones are solved to relative_tolerance.
  int inexact_steps = 10;
  int maximum_active_set_steps = 100;
};

/// Solves the contact problem of the file comment for the stiffness behind `stiffness`, the
/// constraint operator `trace` (B on the free dofs, rows x free), the load `load` (b) and the
/// bound `bound` (c), warm-started from and updating `state` (an empty state starts from
/// `initial_displacement` with the active set it penetrates). The state is updated only when
/// the solve converges.
PrimalContactResult solve_primal_contact(const MultigridStiffnessSolver& stiffness,
                                         const SparseMatrix& trace, const Eigen::VectorXd& load,
                                         const Eigen::VectorXd& bound,
                                         const Eigen::VectorXd& initial_displacement,
                                         PrimalContactState& state,
                                         const PrimalContactOptions& options = {});

}  // namespace robin
