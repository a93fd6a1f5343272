// Contact of solid (3D) bodies against numbers from outside the code:
//  - Hertz point contact (examples/hertz_3d.toml: a sphere of radius R, its curvature the
//    initial gap (x^2 + y^2)/(2R), on a flat body; a quarter model): the contact radius and the
//    peak pressure fitted to the computed pressures against Hertz's a = (3PR/(4E*))^(1/3) and
//    p0 = 3P/(2 pi a^2), P the computed load, within 3 % on the finest mesh (that of the
//    example), both errors falling as the mesh is refined;
//  - the three-dimensional contact patch test (examples/non_matching_solids.toml: tetrahedra
//    against hexahedra, non-matching, mortar): the exact uniaxial pressure
//    p = delta / (H1/E1 + H2/E2) at every multiplier node to 1e-10, from the case file through
//    the monolithic solve and through the Robin iteration;
//  - the Robin iteration (in-process ports) equals the monolithic solution to 1e-8 on these
//    cases, also with the sphere 100 times stiffer than the flat.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "pressure_error.hpp"

namespace robin {
namespace {

CaseDefinition hertz_case(double mesh_size, const std::vector<std::string>& overrides = {}) {
  std::vector<std::string> all = {"body[1].mesh_size=" + std::to_string(mesh_size),
                                  "body[2].mesh_size=" + std::to_string(mesh_size)};
  all.insert(all.end(), overrides.begin(), overrides.end());
  return read_case_file(std::filesystem::path(ROBIN_EXAMPLES) / "hertz_3d.toml", all);
}

MonolithicResult solve_reference(const LocalProblem& problem) {
  MprgpParameters parameters = problem.definition.solver.qp;
  parameters.relative_tolerance = 1e-13;
  return solve_monolithic(*problem.bodies[0], *problem.bodies[1], problem.pairing(), parameters);
}

struct HertzFit {
  double load = 0.0;            // P, the whole sphere's (four times the quarter's resultant)
  double radius = 0.0;          // a fitted
  double peak = 0.0;            // p0 fitted
  std::size_t active_rows = 0;  // rows with a positive pressure
};

/// Least squares fit of p^2 = p0^2 - (p0^2 / a^2) r^2 over the rows in contact (p_j > 0) with
/// r_j < `reach`, p_j = lambda_j / m_j at the distance r_j of the row's node from the axis.
HertzFit fit_hertz(const ContactPairing& pairing, const Eigen::VectorXd& force, double reach) {
  HertzFit fit;
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d right = Eigen::Vector2d::Zero();
  for (std::size_t j = 0; j < pairing.size(); ++j) {
    const double lambda = force[static_cast<Eigen::Index>(j)];
    fit.load += 4.0 * lambda;
    const double pressure = lambda / pairing.pairs[j].weight;
    const double r2 = pairing.pairs[j].position.head<2>().squaredNorm();
    if (!(pressure > 0.0) || r2 >= reach * reach) continue;
    const Eigen::Vector2d row(1.0, -r2);
    normal += row * row.transpose();
    right += row * pressure * pressure;
    ++fit.active_rows;
  }
  const Eigen::Vector2d coefficients = normal.ldlt().solve(right);  // p0^2, p0^2 / a^2
  fit.peak = std::sqrt(coefficients[0]);
  fit.radius = std::sqrt(coefficients[0] / coefficients[1]);
  return fit;
}

/// The fit over every row in contact, then again over the rows within 0.8 a of the axis: the
/// pressure of the rows at the edge of the contact zone, where the exact pressure has an
/// infinite slope, carries the largest discretization error.
HertzFit fit_hertz(const ContactPairing& pairing, const Eigen::VectorXd& force) {
  const HertzFit first = fit_hertz(pairing, force, std::numeric_limits<double>::infinity());
  return fit_hertz(pairing, force, 0.8 * first.radius);
}

TEST(SolidHertz, ContactRadiusAndPeakPressureWithinThreePercentOfHertz) {
  const double young = 1000.0, poisson = 0.3, sphere_radius = 1.0;
  const double contact_modulus = young / (2.0 * (1.0 - poisson * poisson));
  std::printf("%8s %8s %10s %10s %10s %10s %10s\n", "h", "rows", "P", "a", "error(a)", "p0",
              "error(p0)");
  std::vector<double> radius_errors, peak_errors;
  for (const double mesh_size : {0.08, 0.04, 0.02}) {
    const LocalProblem problem = prepare_local_problem(hertz_case(mesh_size));
    const MonolithicResult result = solve_reference(problem);
    ASSERT_EQ(result.qp.status, QpStatus::converged);
    const HertzFit fit = fit_hertz(problem.pairing(), result.contact_force);
    const double radius = std::cbrt(3.0 * fit.load * sphere_radius / (4.0 * contact_modulus));
    const double peak = 3.0 * fit.load / (2.0 * std::numbers::pi * radius * radius);
    radius_errors.push_back(std::abs(fit.radius - radius) / radius);
    peak_errors.push_back(std::abs(fit.peak - peak) / peak);
    std::printf("%8.3g %8zu %10.4g %10.4g %10.2e %10.4g %10.2e\n", mesh_size, fit.active_rows,
                fit.load, fit.radius, radius_errors.back(), fit.peak, peak_errors.back());
  }
  for (std::size_t k = 1; k < radius_errors.size(); ++k) {
    std::printf("observed order between h = %g and h/2: a %.2f, p0 %.2f\n", 0.08 / (1 << (k - 1)),
                std::log2(radius_errors[k - 1] / radius_errors[k]),
                std::log2(peak_errors[k - 1] / peak_errors[k]));
  }
  EXPECT_LE(radius_errors.back(), 0.03);
  EXPECT_LE(peak_errors.back(), 0.03);
  for (std::size_t k = 1; k < radius_errors.size(); ++k) {
    EXPECT_LT(radius_errors[k], radius_errors[k - 1]);
    EXPECT_LT(peak_errors[k], peak_errors[k - 1]);
  }
}

double relative_difference(const Eigen::VectorXd& value, const Eigen::VectorXd& reference) {
  return (value - reference).lpNorm<Eigen::Infinity>() / reference.lpNorm<Eigen::Infinity>();
}

/// The exact pressure of examples/non_matching_solids.toml (uniaxial stress, rollers).
double exact_patch_pressure() {
  return 0.01 / (0.5 / 1000.0 + 0.4 / 400.0);
}

CaseDefinition patch_case_with(const std::vector<std::string>& overrides) {
  return read_case_file(std::filesystem::path(ROBIN_EXAMPLES) / "non_matching_solids.toml",
                        overrides);
}

CaseDefinition patch_case() {
  return patch_case_with({});
}

TEST(SolidMortarPatch, PressureIsExactAtEveryMultiplierNodeFromTheCaseFile) {
  for (const std::string non_mortar : {"", "lower", "upper"}) {
    CaseDefinition definition = patch_case();
    definition.contact.non_mortar = non_mortar;
    const LocalProblem problem = prepare_local_problem(definition);
    ASSERT_GT(problem.pairing().size(), 0u);
    const MonolithicResult result = solve_reference(problem);
    ASSERT_EQ(result.qp.status, QpStatus::converged);
    EXPECT_LE(
        largest_pressure_error(problem.pairing(), result.contact_force, exact_patch_pressure()),
        1e-10)
        << "non-mortar side '" << non_mortar << "'";
    definition.solver.qp.relative_tolerance = 1e-14;
    definition.coupling.tolerance = 1e-12;
    InProcessPort port1, port2;
    const CoupledRunResult robin =
        run_coupled_case(definition, {&port1, &port2}, definition.coupling);
    ASSERT_EQ(robin.iteration.status, IterationStatus::converged) << robin.iteration.message;
    EXPECT_LE(largest_pressure_error(robin.pairing(), robin.iteration.state.bodies[0].contact_force,
                                     exact_patch_pressure()),
              1e-10)
        << "non-mortar side '" << non_mortar << "'";
  }
}

/// The Robin iteration on `definition` against its monolithic solution.
void expect_robin_matches_monolithic(CaseDefinition definition) {
  definition.solver.qp.relative_tolerance = 1e-13;
  definition.coupling.tolerance = 1e-11;
  definition.coupling.max_iterations = 500;
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.iteration.status, IterationStatus::converged) << robin.iteration.message;
  std::printf("%zu iterations, %zu rows\n", robin.iteration.history.size(), robin.pairing().size());
  const LocalProblem problem = prepare_local_problem(definition);
  const MonolithicResult reference = solve_reference(problem);
  ASSERT_EQ(reference.qp.status, QpStatus::converged);
  ASSERT_EQ(robin.pairing().size(), problem.pairing().size());
  for (int alpha = 0; alpha < 2; ++alpha) {
    const BodyInterfaceState& body = robin.iteration.state.bodies[static_cast<std::size_t>(alpha)];
    EXPECT_LE(relative_difference(body.contact_force, reference.contact_force), 1e-8);
    EXPECT_LE(relative_difference(body.normal_trace,
                                  reference.normal_traces[static_cast<std::size_t>(alpha)]),
              1e-8);
  }
}

TEST(SolidRobinVersusMonolithic, HertzSphereOnAFlat) {
  expect_robin_matches_monolithic(hertz_case(0.04));
}

TEST(SolidRobinVersusMonolithic, NonMatchingSolidsByMortar) {
  expect_robin_matches_monolithic(patch_case());
}

TEST(SolidRobinVersusMonolithic, NonMatchingSolidsOneHundredTimesStiffer) {
  expect_robin_matches_monolithic(patch_case_with({"body[2].material.young=100000"}));
}

TEST(SolidRobinVersusMonolithic, SphereHundredTimesStifferThanTheFlat) {
  expect_robin_matches_monolithic(hertz_case(0.04, {"body[2].material.young=100000"}));
}

}  // namespace
}  // namespace robin
