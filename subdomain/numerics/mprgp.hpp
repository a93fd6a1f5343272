#pragma once
// MPRGP (Modified Proportioning with Reduced Gradient Projections, Dostal & Schoberl,
// Comput. Optim. Appl. 30, 2005) for the bound-constrained quadratic program
//
//   minimise q(x) = 1/2 x'Ax - b'x   subject to   x >= lower,
//
// with A symmetric positive definite (semidefinite is tolerated as long as q is bounded
// below on the feasible set). Conjugate gradients on the free set, proportioning steps that
// release constraints, and expansion steps (a projected gradient step of fixed length
// alpha in (0, 2/||A||]) that add them.
//
// Gradient g = Ax - b. Free set F = {i : x_i > lower_i}. Free gradient phi_i = g_i on F,
// chopped gradient beta_i = min(g_i, 0) off F; the projected gradient g^P = phi + beta is
// zero exactly at the KKT point (x >= l, g >= 0, g'(x - l) = 0).
// Stopping: ||g^P|| <= relative_tolerance * ||b|| (or absolute_tolerance when b = 0), or
// relative to ||A|| ||x - l|| (MprgpParameters::solution_scaled_tolerance).

#include <Eigen/Core>
#include <functional>
#include <string>

#include "numerics/linear_operator.hpp"

namespace robin {

struct MprgpParameters {
  double relative_tolerance = 1e-12;
  double absolute_tolerance = 1e-300;
  /// When true the relative tolerance multiplies ||A|| ||x - l|| (finite bounds only; ||b||
  /// while x = l) instead of ||b||. This is the natural scale of the dual contact problem,
  /// whose right-hand side e - g is dominated by the large gaps of open pairs: relative to
  /// ||b|| the contact forces of the closed pairs would only be resolved to
  /// relative_tolerance ||b|| / (||A|| ||x||), which the Robin iteration then cannot beat.
  bool solution_scaled_tolerance = false;
  int max_iterations = 20000;
  /// Proportioning constant Gamma > 0: a proportioning step is taken when
  /// ||beta||^2 > Gamma^2 phi~'phi (phi~ the reduced free gradient).
  double proportioning = 1.0;
  /// Expansion step alpha = step_factor / ||A||, step_factor in (0, 2].
  double step_factor = 1.9;
  /// ||A|| estimate; computed with power iterations when <= 0.
  double operator_norm = 0.0;
  /// When set, the stopping threshold at the iterate x is max(iterate_threshold(x),
  /// absolute_tolerance) instead of the relative tolerance's: the inner solves of SMALBE
  /// (smalbe.hpp) stop at min(M ||C x - d||, eta). Empty (the default): the relative tolerance.
  std::function<double(const Eigen::VectorXd&)> iterate_threshold;
};

enum class QpStatus { converged, not_converged, breakdown };
std::string to_string(QpStatus status);

struct MprgpResult {
  Eigen::VectorXd solution;
  Eigen::VectorXd gradient;  // A x - b at the solution
  QpStatus status = QpStatus::not_converged;
  int iterations = 0;  // CG + expansion + proportioning steps
  int conjugate_gradient_steps = 0;
  int expansion_steps = 0;
  int proportioning_steps = 0;
  int operator_applications = 0;  // products with A, including the norm estimate
  double projected_gradient_norm = 0.0;
  double operator_norm = 0.0;  // the ||A|| estimate used
  std::string message;         // reason for not_converged / breakdown
};

/// Solves the QP from the starting point `initial` (projected onto the feasible set). A may be
/// semidefinite: a conjugate direction p with p'Ap = 0 (to round-off, 1e-13 ||A|| p'p) moves the
/// iterate along it to the nearest bound; breakdown is reported for a p'Ap below that (A
/// indefinite) and for a problem unbounded along a null direction.
/// Converged means ||g^P|| <= max(relative_tolerance ||b||, absolute_tolerance) for the
/// gradient recomputed as A x - b (the recurrence gradient is replaced when it drifts). Entries
/// of `lower` may be -infinity (unbounded); NaN or +infinity, or sizes that differ from
/// matrix.size(), throw std::invalid_argument. The returned gradient is always A x - b and
/// the returned x is always feasible (x_i >= lower_i exactly; x_i == lower_i is active).
/// Products with A: the norm estimate (10 when operator_norm <= 0), 1 for the initial
/// gradient, 1 per CG or proportioning step, 2 per expansion step, 1 per recomputation.
MprgpResult solve_mprgp(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                        const Eigen::VectorXd& lower, const Eigen::VectorXd& initial,
                        const MprgpParameters& parameters = {});

/// Largest eigenvalue estimate of A by power iterations (returns an upper-biased value).
double estimate_operator_norm(const LinearOperator& matrix, int iterations, int& applications);

}  // namespace robin
