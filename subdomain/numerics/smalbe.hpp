#pragma once
// SMALBE-M (semi-monotonic augmented Lagrangian for bound and equality constraints, Dostal,
// "Optimal Quadratic Programming Algorithms", Springer 2009, ch. 6) for
//
//   minimise q(x) = 1/2 x'Ax - b'x   subject to   x >= lower,  C x = d,
//
// A symmetric positive semi-definite and positive definite on the null space of C (the dual of
// a floating body's contact problem, body_solver.hpp: A = F, C = G = (B R)', d = h = R'f), C
// a small dense matrix of full row rank m (m <= 3 per floating body).
//
// The rows of C are first made orthonormal: C' = Q T (thin QR), Q'x = T^{-T} d =: d~, and the
// multiplier of the orthonormal rows is mu~ = T mu. With the augmented Lagrangian
//   L(x, mu~, rho) = q(x) + mu~'(Q'x - d~) + rho/2 ||Q'x - d~||^2,   rho = ||A||,
// outer iteration k:
//   1. x^k >= lower minimises L(., mu~^k, rho) by MPRGP (mprgp.hpp, operator A + rho QQ')
//      until ||g^P(x^k)|| <= max(min(M_k ||Q'x^k - d~||, eta), epsilon s_g);
//   2. mu~^{k+1} = mu~^k + rho (Q'x^k - d~): the inner gradient at x^k is then exactly
//      A x^k - b + Q mu~^{k+1}, the gradient of the Lagrangian at the new multiplier;
//   3. stop when ||g^P|| <= epsilon s_g and ||Q'x - d~|| <= epsilon s_f;
//   4. if L(x^k, mu~^k, rho) < L(x^{k-1}, mu~^{k-1}, rho) + rho/2 ||Q'x^k - d~||^2 then
//      M_{k+1} = M_k / beta (the semi-monotonic update of the inner precision), else M_k.
// Scales: s_g = ||A|| ||x - lower|| (||b|| while x = lower), s_f = max(||x||, ||d~||), as the
// solution-scaled test of MPRGP. eta = ||b||, M_0 = ||A||, beta = 10.
// The KKT conditions at the returned (x, mu): x >= lower, g = A x - b + C'mu >= 0 on the
// active set, g = 0 on the free set, C x = d.
//
// An infeasible equality (no x >= lower with C x = d) makes mu grow without bound while the
// equality residual stays at its least-squares minimum: the outer iterations are bounded
// (max_outer_iterations), and the caller should test feasibility first
// (nonnegative_least_squares.hpp), so that this never runs for an infeasible problem.

#include <Eigen/Core>
#include <string>

#include "numerics/linear_operator.hpp"
#include "numerics/mprgp.hpp"

namespace robin {

struct SmalbeParameters {
  /// epsilon of the stopping test (both the projected gradient and the equality residual).
  double relative_tolerance = 1e-12;
  int max_outer_iterations = 200;
  /// The bound of all inner MPRGP iterations together.
  int max_iterations = 20000;
  /// beta > 1: the factor by which the inner precision bound M is reduced.
  double bound_reduction = 10.0;
  /// ||A|| estimate; computed with power iterations when <= 0.
  double operator_norm = 0.0;
};

struct SmalbeResult {
  Eigen::VectorXd solution;    // x (feasible: x >= lower exactly)
  Eigen::VectorXd multiplier;  // mu, the multiplier of C x = d (size m)
  Eigen::VectorXd gradient;    // A x - b + C'mu
  QpStatus status = QpStatus::not_converged;
  int outer_iterations = 0;
  int iterations = 0;  // all inner MPRGP iterations
  int operator_applications = 0;
  double projected_gradient_norm = 0.0;  // of the gradient above
  double equality_residual = 0.0;        // ||C x - d||
  double operator_norm = 0.0;
  std::string message;  // why not converged
};

/// Solves the QP from `initial` (projected onto x >= lower) and the multiplier `initial_multiplier`
/// (size m, or empty for 0). Throws std::invalid_argument for mismatched sizes or a C that is
/// not of full row rank.
SmalbeResult solve_smalbe(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                          const Eigen::VectorXd& lower, const Eigen::MatrixXd& equality_matrix,
                          const Eigen::VectorXd& equality_target, const Eigen::VectorXd& initial,
                          const Eigen::VectorXd& initial_multiplier,
                          const SmalbeParameters& parameters = {});

}  // namespace robin
