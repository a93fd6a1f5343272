// Quasi-static load steps ([loading]) against numbers from outside the code:
//  - the contact patch test in steps (examples/non_matching_blocks_steps.toml): the solution is
//    linear in the load, so the pressure of step k is exactly t_k p, p = 0.01 / (H1 (1 - nu1^2)
//    / E1 + H2 (1 - nu2^2) / E2), at every multiplier node, for the Robin iteration and for the
//    monolithic reference;
//  - Hertz in steps (examples/hertz_steps.toml): the contact zone grows with the load, so the
//    solution is not linear in it; every step equals a fresh monolithic solve of the case at
//    that step's load (the prescribed displacement written as t_k times the original) to 1e-8
//    on the contact forces, and starting each step from the previous one takes fewer Robin
//    iterations than a fresh run at the same load (printed, compared as counts, not timed).

#include <gtest/gtest.h>

#include <cstdio>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "pressure_error.hpp"

namespace robin {
namespace {

CaseDefinition example(const std::string& name) {
  return read_case_file(std::filesystem::path(ROBIN_EXAMPLES) / name);
}

/// The exact pressure of the patch test at load factor 1 (the values of the case file).
double exact_patch_pressure() {
  const double lower = 0.5 * (1.0 - 0.3 * 0.3) / 1000.0;
  const double upper = 0.4 * (1.0 - 0.25 * 0.25) / 400.0;
  return 0.01 / (lower + upper);
}

/// The case with every prescribed displacement multiplied by `factor` in its definition and
/// without [loading]: a fresh case at that load, built without the load-factor code.
CaseDefinition scaled_case(CaseDefinition definition, double factor) {
  definition.loading = {};
  for (BodyCase& body : definition.bodies) {
    for (DirichletCondition& condition : body.definition.dirichlet) {
      if (condition.x) *condition.x *= factor;
      if (condition.y) *condition.y *= factor;
    }
    body.definition.body_force *= factor;
    for (TractionCondition& traction : body.definition.tractions) {
      traction.vector *= factor;
      traction.pressure *= factor;
    }
  }
  return definition;
}

TEST(LoadSteps, PatchTestPressureIsTheLoadFactorTimesTheExactPressureAtEveryStep) {
  CaseDefinition definition = example("non_matching_blocks_steps.toml");
  ASSERT_EQ(definition.loading.factors, (std::vector<double>{0.5, 1.0, 2.0}));
  definition.solver.qp.relative_tolerance = 1e-14;
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.steps.size(), 3u);
  for (const LoadStepResult& step : robin.steps) {
    ASSERT_EQ(step.iteration.status, IterationStatus::converged) << step.iteration.message;
    const double pressure = step.factor * exact_patch_pressure();
    std::printf("patch test step %d (factor %g): %zu iterations, pressure error %.2e\n", step.step,
                step.factor, step.iteration.history.size(),
                largest_pressure_error(robin.pairing(),
                                       step.iteration.state.bodies[0].contact_force, pressure));
    EXPECT_LE(largest_pressure_error(robin.pairing(), step.iteration.state.bodies[0].contact_force,
                                     pressure),
              1e-8);
    EXPECT_LE(largest_pressure_error(robin.pairing(), step.iteration.state.bodies[1].contact_force,
                                     pressure),
              1e-8);
    EXPECT_EQ(step.warm_started, step.step > 1);
  }
  // The last step is what the run reports as its result.
  EXPECT_EQ(robin.iteration.state.bodies[0].contact_force,
            robin.steps.back().iteration.state.bodies[0].contact_force);

  LocalProblem problem = prepare_local_problem(definition);
  MprgpParameters parameters = definition.solver.qp;
  const std::vector<MonolithicStep> steps = solve_monolithic_steps(
      *problem.bodies[0], *problem.bodies[1], problem.pairing(), definition.loading, parameters);
  ASSERT_EQ(steps.size(), 3u);
  for (const MonolithicStep& step : steps) {
    ASSERT_EQ(step.result.qp.status, QpStatus::converged);
    EXPECT_LE(largest_pressure_error(problem.pairing(), step.result.contact_force,
                                     step.factor * exact_patch_pressure()),
              1e-10);
  }
}

/// The coupling options of a run: the case's (IQN-ILS, either sequence) or the paper's plain
/// iteration (fixed relaxation 0.5, joint stopping test).
class HertzStepsTest : public ::testing::TestWithParam<bool> {};

TEST_P(HertzStepsTest, StepsEqualFreshMonolithicSolvesAndWarmStartsSaveIterations) {
  const bool plain = GetParam();
  CaseDefinition definition = example("hertz_steps.toml");
  definition.solver.qp.relative_tolerance = 1e-14;
  if (plain) {
    definition.coupling.acceleration.method = AccelerationMethod::none;
    definition.coupling.relaxation = 0.5;
    definition.coupling.stopping = StoppingRule::joint;
  }
  const std::vector<double> factors = definition.loading.factors;
  ASSERT_EQ(factors, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.steps.size(), factors.size());

  int previous_active = 0;
  for (const LoadStepResult& step : robin.steps) {
    ASSERT_EQ(step.iteration.status, IterationStatus::converged) << step.iteration.message;
    // A fresh monolithic solve of the case written at this step's load.
    const CaseDefinition fresh = scaled_case(definition, step.factor);
    const LocalProblem problem = prepare_local_problem(fresh);
    ASSERT_EQ(problem.pairing().size(), robin.pairing().size());
    const MonolithicResult reference = solve_monolithic(*problem.bodies[0], *problem.bodies[1],
                                                        problem.pairing(), fresh.solver.qp);
    ASSERT_EQ(reference.qp.status, QpStatus::converged);
    const double scale = reference.contact_force.lpNorm<Eigen::Infinity>();
    ASSERT_GT(scale, 0.0);
    const double error1 = (step.iteration.state.bodies[0].contact_force - reference.contact_force)
                              .lpNorm<Eigen::Infinity>() /
                          scale;
    const double error2 = (step.iteration.state.bodies[1].contact_force - reference.contact_force)
                              .lpNorm<Eigen::Infinity>() /
                          scale;
    EXPECT_LE(error1, 1e-8) << "step " << step.step;
    EXPECT_LE(error2, 1e-8) << "step " << step.step;
    int active = 0;
    for (Eigen::Index i = 0; i < reference.contact_force.size(); ++i) {
      if (reference.contact_force[i] > 0.0) ++active;
    }
    // The contact zone grows with the load: the problem is not linear in the load factor.
    EXPECT_GE(active, previous_active) << "step " << step.step;
    previous_active = active;

    // A fresh Robin run of the same load.
    InProcessPort fresh1, fresh2;
    const CoupledRunResult cold = run_coupled_case(fresh, {&fresh1, &fresh2}, fresh.coupling);
    ASSERT_EQ(cold.iteration.status, IterationStatus::converged);
    std::printf(
        "hertz (%s) step %d (factor %g): %d active pairs, %zu iterations from the "
        "previous steps, %zu from the gap; contact force error %.2e / %.2e\n",
        plain ? "plain iteration" : "IQN-ILS", step.step, step.factor, active,
        step.iteration.history.size(), cold.iteration.history.size(), error1, error2);
    // Never more iterations than a fresh run; with the plain iteration (whose count depends on
    // the distance of the start from the solution) strictly fewer from the second step on, and
    // with IQN-ILS from the third, when two previous steps give the extrapolation.
    if (step.step > 1) {
      EXPECT_LE(step.iteration.history.size(), cold.iteration.history.size())
          << "step " << step.step;
    }
    if (step.step > (plain ? 1 : 2)) {
      EXPECT_LT(step.iteration.history.size(), cold.iteration.history.size())
          << "step " << step.step;
    }
  }
  // The last three steps touch more pairs than the first: the zone did grow.
  EXPECT_GT(previous_active, 0);
}

INSTANTIATE_TEST_SUITE_P(Iteration, HertzStepsTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? std::string("PlainIteration")
                                             : std::string("CaseOptions");
                         });

TEST(LoadSteps, ColdStepsStartFromTheInitialObstacleLikeFreshRuns) {
  CaseDefinition definition = example("hertz_steps.toml");
  definition.loading.factors = {0.5, 1.0};
  definition.loading.warm_start = false;
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.steps.size(), 2u);
  for (const LoadStepResult& step : robin.steps) {
    EXPECT_FALSE(step.warm_started);
    EXPECT_EQ(step.iteration.status, IterationStatus::converged);
  }
}

}  // namespace
}  // namespace robin
