// Verification of the monolithic two-body reference against analytic results:
//  - plane-strain Hertz (cylinder on a flat, gap x^2/2R): half-width and peak pressure within 5%
//    of a = sqrt(4PR/(pi E*)), p0 = 2P/(pi a), and the contact resultant equal to the load taken
//    by the Dirichlet boundary (reaction) to 1e-8;
//  - partial contact of two blocks: KKT residuals below 1e-10 and global equilibrium.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/result_files.hpp"

namespace robin {
namespace {

std::filesystem::path example(const std::string& name) {
  return std::filesystem::path(ROBIN_EXAMPLES) / name;
}

/// Sum of the reaction forces of a body (its Dirichlet boundaries).
Eigen::Vector2d total_reaction(const BodySolver& body, const Eigen::VectorXd& contact_force) {
  const Eigen::VectorXd reaction = body.reactions(body.displacement(contact_force));
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (Eigen::Index node = 0; node < reaction.size() / 2; ++node) {
    total += reaction.segment<2>(2 * node);
  }
  return total;
}

/// Each body is in equilibrium: reactions + applied loads + contact forces = 0, where the
/// contact force on body 2 is the resultant sum lambda_i n1_i and on body 1 its opposite.
void expect_equilibrium(const LocalProblem& problem, const Eigen::VectorXd& force) {
  const Eigen::Vector2d resultant = contact_resultant(problem.pairing, force);
  for (int alpha = 0; alpha < 2; ++alpha) {
    const BodySolver& body = *problem.bodies[alpha];
    const Eigen::Vector2d contact = alpha == 0 ? Eigen::Vector2d(-resultant) : resultant;
    const Eigen::Vector2d balance = total_reaction(body, force) + body.applied_force() + contact;
    EXPECT_LE(balance.norm(), 1e-8 * resultant.norm()) << "body " << body.name();
  }
}

TEST(MonolithicContact, HertzHalfWidthAndPeakPressure) {
  const LocalProblem problem = prepare_local_problem(read_case_file(example("hertz.toml")));
  const MonolithicResult result = solve_monolithic(*problem.bodies[0], *problem.bodies[1],
                                                   problem.pairing, problem.definition.solver.qp);
  ASSERT_EQ(result.qp.status, QpStatus::converged) << result.qp.message;
  expect_equilibrium(problem, result.contact_force);

  // The load P is the force the upper body's top boundary pushes with (its reaction).
  const double load = -total_reaction(*problem.bodies[1], result.contact_force).y();
  const double resultant = contact_resultant(problem.pairing, result.contact_force).y();
  EXPECT_NEAR(resultant, load, 1e-8 * load);

  const double young = 1000.0, poisson = 0.3, radius = 1.0;
  const double effective_modulus = 1.0 / (2.0 * (1.0 - poisson * poisson) / young);
  const double half_width = std::sqrt(4.0 * load * radius / (std::numbers::pi * effective_modulus));
  const double peak_pressure = 2.0 * load / (std::numbers::pi * half_width);

  // Measured half-width: midway between the outermost closed pair and its open neighbour on
  // each side; peak pressure: largest lambda_i / m_i.
  const auto& pairs = problem.pairing.pairs;
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
  std::printf("Hertz: P = %.6g, a = %.6g (measured %.6g), p0 = %.6g (measured %.6g), %d closed pairs\n",
              load, half_width, measured_half_width, peak_pressure, measured_peak, closed);
  EXPECT_GE(closed, 20);
  EXPECT_NEAR(measured_half_width, half_width, 0.05 * half_width);
  EXPECT_NEAR(measured_peak, peak_pressure, 0.05 * peak_pressure);
}

TEST(MonolithicContact, PartialContactSatisfiesKktAndEquilibrium) {
  const LocalProblem problem =
      prepare_local_problem(read_case_file(example("two_blocks_partial.toml")));
  const MonolithicResult result = solve_monolithic(*problem.bodies[0], *problem.bodies[1],
                                                   problem.pairing, problem.definition.solver.qp);
  ASSERT_EQ(result.qp.status, QpStatus::converged) << result.qp.message;
  int closed = 0;
  for (Eigen::Index i = 0; i < result.contact_force.size(); ++i) closed += result.contact_force[i] > 0;
  const int open = static_cast<int>(result.contact_force.size()) - closed;
  std::printf("partial contact: %d closed, %d open pairs\n", closed, open);
  EXPECT_GT(closed, 2);
  EXPECT_GT(open, 2);
  // lambda >= 0 by construction of the dual; the rest of KKT measured independently here.
  EXPECT_GE(result.contact_force.minCoeff(), 0.0);
  const Eigen::VectorXd clearance =
      problem.pairing.gaps() - result.normal_trace1 - result.normal_trace2;
  const double displacement_scale = problem.pairing.gaps().cwiseAbs().maxCoeff();
  const double force_scale = result.contact_force.maxCoeff();
  EXPECT_GE(clearance.minCoeff(), -1e-10 * displacement_scale);
  EXPECT_LE(result.contact_force.cwiseProduct(clearance).cwiseAbs().maxCoeff(),
            1e-10 * force_scale * displacement_scale);
  EXPECT_LE(result.residuals.force_balance, 1e-10);
  expect_equilibrium(problem, result.contact_force);
}

}  // namespace
}  // namespace robin
