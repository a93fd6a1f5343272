#pragma once
// The monolithic reference (paper (5)): minimise sum_alpha 1/2 u'K u - f'u subject
// to B1 u1 + B2 u2 <= d, solved in its dual form
//   minimise 1/2 lambda'(F1 + F2) lambda - lambda'(e1 + e2 - d),  lambda >= 0,
// with the same factors and the same MPRGP as the subdomain solves. On a contact graph
// (contact_graph.hpp) lambda has one entry per row in global order, C_alpha lambda is body
// alpha's part of it (body order), and the dual is
//   minimise 1/2 lambda'(sum_alpha C_alpha' F^alpha C_alpha) lambda
//            - lambda'(sum_alpha C_alpha' e^alpha - d),  lambda >= 0,
// u^alpha_N = e^alpha - F^alpha C_alpha lambda.
//
// Floating bodies (body_solver.hpp, "Floating bodies"): body alpha with k_alpha > 0 rigid
// motions R^alpha adds the equality rows G^alpha C_alpha lambda = h^alpha (G^alpha = (B^alpha
// R^alpha)', h^alpha = R^alpha'f^alpha) to the dual, which SMALBE-M (smalbe.hpp) solves instead
// of MPRGP; alpha^alpha = -mu^alpha (the multiplier of its rows) and
//   u^alpha_N = e^alpha - F^alpha C_alpha lambda + B^alpha R^alpha alpha^alpha.
// Refused (SingularBodyError naming the floating bodies): the stacked G not of full row rank
// (a rigid motion of floating bodies together that moves no row, e.g. two floating bodies that
// touch only each other), or no lambda >= 0 with G lambda = h (the loads pull them away).

#include <Eigen/Core>
#include <vector>

#include "coupling/case_file_loading.hpp"
#include "coupling/contact_graph.hpp"
#include "coupling/contact_pairing.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

/// Scaled residuals of a two-body contact state; see docs/case-format.md "Residuals".
struct InterfaceResiduals {
  double penetration = 0.0;    // max(0, u1_N + u2_N - d) / displacement scale
  double force_balance = 0.0;  // max |lambda1 - lambda2| / force scale
  double complementarity =
      0.0;  // max |lambda_i (d - u1_N - u2_N)_i| / (force scale * displacement scale)
};

struct MonolithicResult {
  Eigen::VectorXd contact_force;  // lambda (same on both sides of a row), global order
  /// u_N per body, body order (two bodies: u1_N, u2_N in pair order)
  std::vector<Eigen::VectorXd> normal_traces;
  MprgpResult qp;
  /// alpha per body (k values; empty for a body without rigid motions): its displacement is
  /// BodySolver::displacement(C_alpha lambda, alpha).
  std::vector<Eigen::VectorXd> rigid_amplitudes;
  InterfaceResiduals residuals;
  double solve_seconds = 0.0;
};

/// The monolithic problem of the contact graph: `bodies` in body order, each assigned its rows
/// in body order; `gaps` d in global order. MPRGP starts from `initial_force` (lambda >= 0,
/// global order) when it is given, from 0 otherwise. Throws InputError when a body's contact
/// size is not its number of rows in the graph.
MonolithicResult solve_monolithic(const std::vector<const BodySolver*>& bodies,
                                  const ContactGraph& graph, const Eigen::VectorXd& gaps,
                                  const MprgpParameters& parameters,
                                  const Eigen::VectorXd& initial_force = {});

/// Two bodies: both must have been given pairing.assignment(0) and (1). MPRGP starts from
/// `initial_force` (lambda >= 0, pair order) when it is given, from 0 otherwise.
MonolithicResult solve_monolithic(const BodySolver& body1, const BodySolver& body2,
                                  const ContactPairing& pairing, const MprgpParameters& parameters,
                                  const Eigen::VectorXd& initial_force = {});

/// One quasi-static load step of the monolithic reference.
struct MonolithicStep {
  int step = 0;         // 1, 2, ...
  double factor = 1.0;  // the load factor of the step
  MonolithicResult result;
};

/// The load steps of `loading` (case_file_loading.hpp): for each factor t_k, both bodies' loads
/// and prescribed displacements are scaled by t_k (BodySolver::set_load_factor: the factors and
/// F are kept) and the monolithic problem is solved, MPRGP starting from the previous step's
/// contact force when loading.warm_start. Stops after the first step whose QP did not converge;
/// leaves both bodies at the last computed step's factor.
std::vector<MonolithicStep> solve_monolithic_steps(BodySolver& body1, BodySolver& body2,
                                                   const ContactPairing& pairing,
                                                   const LoadingOptions& loading,
                                                   const MprgpParameters& parameters);
/// The same on a contact graph (the bodies in body order, each assigned its rows).
std::vector<MonolithicStep> solve_monolithic_steps(const std::vector<BodySolver*>& bodies,
                                                   const ContactGraph& graph,
                                                   const Eigen::VectorXd& gaps,
                                                   const LoadingOptions& loading,
                                                   const MprgpParameters& parameters);

/// Residuals of (u1_N, u2_N, lambda1, lambda2) against the gaps d. Displacement scale:
/// max(max|d|, max|u1_N|, max|u2_N|, displacement_floor, tiny); force scale:
/// max(max lambda, tiny).
InterfaceResiduals interface_residuals(const Eigen::VectorXd& gap, const Eigen::VectorXd& trace1,
                                       const Eigen::VectorXd& trace2, const Eigen::VectorXd& force1,
                                       const Eigen::VectorXd& force2,
                                       double displacement_floor = 0.0);

}  // namespace robin
