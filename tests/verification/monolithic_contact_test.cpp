// Verification of the monolithic two-body reference against analytic results:
//  - plane-strain Hertz (cylinder on a flat, gap x^2/2R), force-driven: the load P is prescribed
//    (the depth of the platen on the cylinder's top is found to carry it), the contact resultant
//    equals P to 1e-8, and the half-width and peak pressure are within 5% of
//    a = sqrt(4PR/(pi E*)), p0 = 2P/(pi a);
//  - partial contact of two blocks: KKT residuals below 1e-10, each body's nodal equilibrium
//    K u - f + B'lambda = 0 on its free dofs (K assembled here, u the returned displacement
//    field) and its normal trace B u equal to the returned u_N, all below 1e-10 relative.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>

#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/result_files.hpp"
#include "numerics/elasticity.hpp"

namespace robin {
namespace {

std::filesystem::path example(const std::string& name) {
  return std::filesystem::path(ROBIN_EXAMPLES) / name;
}

/// Sum of the reaction forces of a body (its Dirichlet boundaries).
Eigen::Vector3d total_reaction(const BodySolver& body, const Eigen::VectorXd& contact_force) {
  const Eigen::VectorXd reaction = body.reactions(body.displacement(contact_force));
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (Eigen::Index node = 0; node < reaction.size() / 2; ++node) {
    total.head<2>() += reaction.segment<2>(2 * node);
  }
  return total;
}

/// Each body is in equilibrium: reactions + applied loads + contact forces = 0, where the
/// contact force on body 2 is the resultant sum lambda_i n1_i and on body 1 its opposite.
/// Returns the larger of the two imbalances relative to |resultant|.
double expect_equilibrium(const LocalProblem& problem, const Eigen::VectorXd& force,
                          double tolerance) {
  const Eigen::Vector3d resultant = contact_resultant(problem.pairing(), force);
  double worst = 0.0;
  for (int alpha = 0; alpha < 2; ++alpha) {
    const BodySolver& body = *problem.bodies[alpha];
    const Eigen::Vector3d contact = alpha == 0 ? Eigen::Vector3d(-resultant) : resultant;
    const Eigen::Vector3d balance = total_reaction(body, force) + body.applied_force() + contact;
    EXPECT_LE(balance.norm(), tolerance * resultant.norm()) << "body " << body.name();
    worst = std::max(worst, balance.norm() / resultant.norm());
  }
  return worst;
}

/// The nodal contact load B'lambda of body `alpha` (full size, 2 per node): lambda_i n_i at
/// its node of pair i, with n = n1 on body 1 and n = -n1 on body 2 (docs/method.md).
Eigen::VectorXd transpose_trace(const ContactPairing& pairing, int alpha, Eigen::Index dof_count,
                                const Eigen::VectorXd& force) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(dof_count);
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    const ContactPair& pair = pairing.pairs[i];
    const int node = alpha == 0 ? pair.node1 : pair.node2;
    const Eigen::Vector3d normal = alpha == 0 ? pair.normal : Eigen::Vector3d(-pair.normal);
    load.segment<2>(2 * node) += force[static_cast<Eigen::Index>(i)] * normal.head<2>();
  }
  return load;
}

/// (B u)_i = u(node_i) . n_i of body `alpha` for a full displacement field u.
Eigen::VectorXd normal_trace(const ContactPairing& pairing, int alpha,
                             const Eigen::VectorXd& displacement) {
  Eigen::VectorXd trace(static_cast<Eigen::Index>(pairing.size()));
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    const ContactPair& pair = pairing.pairs[i];
    const int node = alpha == 0 ? pair.node1 : pair.node2;
    const Eigen::Vector3d normal = alpha == 0 ? pair.normal : Eigen::Vector3d(-pair.normal);
    trace[static_cast<Eigen::Index>(i)] = displacement.segment<2>(2 * node).dot(normal.head<2>());
  }
  return trace;
}

/// Nodal equilibrium of body `alpha` on its free dofs, from a stiffness K assembled here and
/// the displacement field u the body returns for lambda: max_free |K u - f + B'lambda|,
/// relative to the largest nodal force max |K u| (reactions included). The body must carry no
/// body force or traction (f = 0: it is loaded through prescribed displacements only).
double free_dof_imbalance(const BodySolver& body, const ContactPairing& pairing, int alpha,
                          const Eigen::VectorXd& force) {
  EXPECT_EQ(body.definition().body_force.squaredNorm(), 0.0) << body.name();
  EXPECT_TRUE(body.definition().tractions.empty()) << body.name();
  const SparseMatrix stiffness = assemble_stiffness(body.mesh(), body.definition().material);
  const Eigen::VectorXd internal = stiffness * body.displacement(force);
  const Eigen::VectorXd residual =
      internal + transpose_trace(pairing, alpha, internal.size(), force);
  double worst = 0.0;
  for (Eigen::Index dof = 0; dof < residual.size(); ++dof) {
    if (!body.dofs().is_prescribed(static_cast<int>(dof))) {
      worst = std::max(worst, std::abs(residual[dof]));
    }
  }
  return worst / internal.cwiseAbs().maxCoeff();
}

/// The monolithic solve of examples/hertz.toml with the cylinder's top displaced by -depth (the
/// rigid platen through which the load is applied) and its contact resultant P (vertical).
struct HertzSolve {
  LocalProblem problem;
  MonolithicResult result;
  double load = 0.0;
};

HertzSolve solve_hertz(double depth) {
  CaseDefinition definition = read_case_file(example("hertz.toml"));
  for (DirichletCondition& condition : definition.bodies[1].definition.dirichlet) {
    if (condition.boundary == "top") condition.y = -depth;
  }
  HertzSolve solve{prepare_local_problem(definition), {}, 0.0};
  solve.result = solve_monolithic(*solve.problem.bodies[0], *solve.problem.bodies[1],
                                  solve.problem.pairing(), solve.problem.definition.solver.qp);
  EXPECT_EQ(solve.result.qp.status, QpStatus::converged) << solve.result.qp.message;
  solve.load = contact_resultant(solve.problem.pairing(), solve.result.contact_force).y();
  return solve;
}

/// Force control: the platen depth whose contact resultant is `load`, to 1e-10 relative, by
/// the Illinois variant of regula falsi on P(depth) - load (P is continuous and increasing in
/// the depth, affine while the active set stays fixed, so the bracket closes in few solves).
HertzSolve solve_hertz_under_load(double load) {
  double low = 0.0, high = 0.002;
  double residual_low = -load, residual_high = solve_hertz(high).load - load;
  while (residual_high <= 0.0) residual_high = solve_hertz(high *= 2.0).load - load;
  int last_side = 0;
  for (int solves = 0; solves < 40; ++solves) {
    const double depth =
        (low * residual_high - high * residual_low) / (residual_high - residual_low);
    HertzSolve solve = solve_hertz(depth);
    const double residual = solve.load - load;
    if (std::abs(residual) <= 1e-10 * load) return solve;
    if (residual > 0.0) {
      high = depth, residual_high = residual;
      if (last_side > 0) residual_low /= 2.0;
      last_side = 1;
    } else {
      low = depth, residual_low = residual;
      if (last_side < 0) residual_high /= 2.0;
      last_side = -1;
    }
  }
  ADD_FAILURE() << "no platen depth gives the load " << load;
  return solve_hertz(low);
}

// Force-driven: the load P is prescribed (P for the half-width a = 0.05 by Hertz's formula) and
// the platen depth is found to carry exactly P; a and p0 are then the a-priori Hertz values.
TEST(MonolithicContact, HertzHalfWidthAndPeakPressure) {
  const double young = 1000.0, poisson = 0.3, radius = 1.0;
  const double effective_modulus = 1.0 / (2.0 * (1.0 - poisson * poisson) / young);
  const double half_width = 0.05;
  const double load = std::numbers::pi * effective_modulus * half_width * half_width / (4 * radius);
  const double peak_pressure = 2.0 * load / (std::numbers::pi * half_width);
  const HertzSolve solve = solve_hertz_under_load(load);
  const LocalProblem& problem = solve.problem;
  const MonolithicResult& result = solve.result;

  // The contact resultant is the prescribed load, and the platen (the top's reaction) and the
  // flat's support carry it: each body is in equilibrium.
  EXPECT_NEAR(solve.load, load, 1e-8 * load);
  expect_equilibrium(problem, result.contact_force, 1e-8);
  EXPECT_NEAR(-total_reaction(*problem.bodies[1], result.contact_force).y(), load, 1e-8 * load);

  // Measured half-width: midway between the outermost closed pair and its open neighbour on
  // each side; peak pressure: largest lambda_i / m_i.
  const auto& pairs = problem.pairing().pairs;
  int closed = 0;
  double measured_peak = 0.0;
  double outer_closed = 0.0, inner_open = 1e300;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const double x = std::abs(pairs[i].position.x());
    if (result.contact_force[i] > 0) {
      ++closed;
      outer_closed = std::max(outer_closed, x);
      measured_peak = std::max(measured_peak, result.contact_force[i] / pairs[i].weight);
    }
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const double x = std::abs(pairs[i].position.x());
    if (result.contact_force[i] == 0 && x > outer_closed) inner_open = std::min(inner_open, x);
  }
  const double measured_half_width = 0.5 * (outer_closed + inner_open);
  std::printf(
      "Hertz under the load P = %.6g: a = %.6g (measured %.6g), p0 = %.6g (measured %.6g), %d "
      "closed pairs, resultant %.12g\n",
      load, half_width, measured_half_width, peak_pressure, measured_peak, closed, solve.load);
  EXPECT_GE(closed, 20);
  EXPECT_NEAR(measured_half_width, half_width, 0.05 * half_width);
  EXPECT_NEAR(measured_peak, peak_pressure, 0.05 * peak_pressure);
}

TEST(MonolithicContact, PartialContactSatisfiesKktAndEquilibrium) {
  const LocalProblem problem =
      prepare_local_problem(read_case_file(example("two_blocks_partial.toml")));
  const MonolithicResult result = solve_monolithic(*problem.bodies[0], *problem.bodies[1],
                                                   problem.pairing(), problem.definition.solver.qp);
  ASSERT_EQ(result.qp.status, QpStatus::converged) << result.qp.message;
  int closed = 0;
  for (Eigen::Index i = 0; i < result.contact_force.size(); ++i) {
    closed += result.contact_force[i] > 0;
  }
  const int open = static_cast<int>(result.contact_force.size()) - closed;
  std::printf("partial contact: %d closed, %d open pairs\n", closed, open);
  EXPECT_GT(closed, 2);
  EXPECT_GT(open, 2);
  // lambda >= 0 by construction of the dual; the rest of KKT measured independently here.
  EXPECT_GE(result.contact_force.minCoeff(), 0.0);
  const Eigen::VectorXd clearance =
      problem.pairing().gaps() - result.normal_traces[0] - result.normal_traces[1];
  const double displacement_scale = problem.pairing().gaps().cwiseAbs().maxCoeff();
  const double force_scale = result.contact_force.maxCoeff();
  const double penetration = std::max(0.0, -clearance.minCoeff()) / displacement_scale;
  const double complementarity =
      result.contact_force.cwiseProduct(clearance).cwiseAbs().maxCoeff() /
      (force_scale * displacement_scale);
  EXPECT_LE(penetration, 1e-10);
  EXPECT_LE(complementarity, 1e-10);
  std::cout << "partial contact: penetration " << penetration << ", complementarity "
            << complementarity << "\n";

  // Each body: K u = f - B'lambda on its free dofs for the returned force, and the returned
  // normal trace is the trace of that displacement field.
  for (int alpha = 0; alpha < 2; ++alpha) {
    const BodySolver& body = *problem.bodies[alpha];
    const double imbalance =
        free_dof_imbalance(body, problem.pairing(), alpha, result.contact_force);
    const Eigen::VectorXd returned = alpha == 0 ? result.normal_traces[0] : result.normal_traces[1];
    const double trace_error =
        (normal_trace(problem.pairing(), alpha, body.displacement(result.contact_force)) - returned)
            .cwiseAbs()
            .maxCoeff() /
        displacement_scale;
    EXPECT_LE(imbalance, 1e-10) << body.name();
    EXPECT_LE(trace_error, 1e-10) << body.name();
    std::cout << "body " << body.name() << ": |K u - f + B'lambda| / |K u| = " << imbalance
              << ", |B u - u_N| / scale = " << trace_error << "\n";
  }
  const double equilibrium = expect_equilibrium(problem, result.contact_force, 1e-10);
  std::cout << "partial contact: global equilibrium " << equilibrium << " (relative)\n";
}

}  // namespace
}  // namespace robin
