// Hertz on non-matching meshes with a true curved contact boundary (examples/hertz_cylinder.toml:
// a half cylinder of radius R = 1 meshed on its own, on a block standing for the half-space,
// coupled by mortar): the half-width a and the peak pressure p0 of the computed pressure, fitted
// as p^2 = p0^2 (1 - x^2 / a^2), against Hertz's a_H = sqrt(4 P R / (pi E*)) and
// p0_H = 2 P / (pi a_H) for the computed load P; and the Robin iteration against the monolithic
// mortar solution of the same discretization (contact forces to 1e-8).
// The error table over four mesh sizes, with its observed order, is
// benchmarks/hertz_mortar_study.sh (docs/verification.md).

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/result_files.hpp"

namespace robin {
namespace {

constexpr double pi = 3.14159265358979323846;

CaseDefinition hertz_cylinder(double mesh_size) {
  CaseDefinition definition =
      read_case_file(std::filesystem::path(ROBIN_EXAMPLES) / "hertz_cylinder.toml");
  for (BodyCase& body : definition.bodies) body.mesh_options.size = mesh_size;
  definition.solver.qp.relative_tolerance = 1e-13;
  return definition;
}

struct HertzFit {
  double half_width = 0.0;
  double peak = 0.0;
};

/// Least-squares fit of p^2 = p0^2 - (p0 / a)^2 x^2 over the loaded constraints, the two
/// outermost left out (they straddle the edge of the contact zone).
HertzFit fit_pressure(const ContactPairing& pairing, const Eigen::VectorXd& force) {
  std::vector<std::pair<double, double>> loaded;
  const double largest = force.maxCoeff();
  for (std::size_t j = 0; j < pairing.size(); ++j) {
    const double value = force[static_cast<Eigen::Index>(j)];
    if (value > 1e-9 * largest)
      loaded.emplace_back(pairing.pairs[j].position.x(), value / pairing.pairs[j].weight);
  }
  std::sort(loaded.begin(), loaded.end());
  const std::size_t first = 1, last = loaded.size() - 1;
  Eigen::MatrixXd design(static_cast<Eigen::Index>(last - first), 2);
  Eigen::VectorXd squares(design.rows());
  for (std::size_t k = first; k < last; ++k) {
    const auto row = static_cast<Eigen::Index>(k - first);
    design(row, 0) = 1.0;
    design(row, 1) = loaded[k].first * loaded[k].first;
    squares[row] = loaded[k].second * loaded[k].second;
  }
  const Eigen::Vector2d coefficients = design.colPivHouseholderQr().solve(squares);
  return {std::sqrt(-coefficients[0] / coefficients[1]), std::sqrt(coefficients[0])};
}

TEST(MortarHertz, HalfWidthAndPeakPressureWithinTwoPercentOfHertz) {
  const CaseDefinition definition = hertz_cylinder(0.05);
  const LocalProblem problem = prepare_local_problem(definition);
  EXPECT_GE(problem.pairing().non_mortar_body, 0);  // mortar
  const MonolithicResult result = solve_monolithic(*problem.bodies[0], *problem.bodies[1],
                                                   problem.pairing(), definition.solver.qp);
  ASSERT_EQ(result.qp.status, QpStatus::converged);
  const double load = std::abs(contact_resultant(problem.pairing(), result.contact_force).y());
  const double effective = 1000.0 / (2.0 * (1.0 - 0.3 * 0.3));
  const double hertz_width = std::sqrt(4.0 * load * 1.0 / (pi * effective));
  const double hertz_peak = 2.0 * load / (pi * hertz_width);
  const HertzFit fit = fit_pressure(problem.pairing(), result.contact_force);
  std::printf("P = %.6g: a = %.6f (Hertz %.6f), p0 = %.5f (Hertz %.5f)\n", load, fit.half_width,
              hertz_width, fit.peak, hertz_peak);
  EXPECT_LE(std::abs(fit.half_width - hertz_width) / hertz_width, 0.02);
  EXPECT_LE(std::abs(fit.peak - hertz_peak) / hertz_peak, 0.02);
}

TEST(MortarHertz, RobinIterationConvergesToTheMonolithicMortarSolution) {
  const CaseDefinition definition = hertz_cylinder(0.1);
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.iteration.status, IterationStatus::converged) << robin.iteration.message;
  std::printf("Hertz cylinder, mortar: %zu iterations\n", robin.iteration.history.size());
  const LocalProblem problem = prepare_local_problem(definition);
  MprgpParameters reference = definition.solver.qp;
  reference.relative_tolerance = 1e-14;
  const MonolithicResult monolithic =
      solve_monolithic(*problem.bodies[0], *problem.bodies[1], problem.pairing(), reference);
  ASSERT_EQ(monolithic.qp.status, QpStatus::converged);
  const double scale = monolithic.contact_force.lpNorm<Eigen::Infinity>();
  EXPECT_LE((robin.iteration.state.bodies[0].contact_force - monolithic.contact_force)
                .lpNorm<Eigen::Infinity>(),
            1e-8 * scale);
  EXPECT_LE((robin.iteration.state.bodies[1].contact_force - monolithic.contact_force)
                .lpNorm<Eigen::Infinity>(),
            1e-8 * scale);
}

}  // namespace
}  // namespace robin
