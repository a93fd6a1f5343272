// Mortar contact on non-matching meshes against numbers from outside the code:
//  - the contact patch test (examples/non_matching_blocks.toml): two blocks meshed
//    independently (triangles against quadrilaterals, 11 against 15 nodes on the contact edge),
//    uniform uniaxial compression; the exact pressure p = 0.01 / (H1 (1 - nu1^2) / E1 +
//    H2 (1 - nu2^2) / E2) at every multiplier node, to 1e-10, from the monolithic reference and
//    from the Robin iteration, with either side as the non-mortar side;
//  - node-to-segment collocation fails the same test (the known failure of NTS);
//  - on matching flat meshes mortar coupling gives the node-to-node answer.

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

/// The exact pressure of the patch test: p = delta / (H1 (1 - nu1^2) / E1 + H2 (1 - nu2^2) / E2).
double exact_patch_pressure() {
  const double lower = 0.5 * (1.0 - 0.3 * 0.3) / 1000.0;
  const double upper = 0.4 * (1.0 - 0.25 * 0.25) / 400.0;
  return 0.01 / (lower + upper);
}

MonolithicResult solve_reference(const LocalProblem& problem, double qp_tolerance = 1e-14) {
  MprgpParameters parameters = problem.definition.solver.qp;
  parameters.relative_tolerance = qp_tolerance;
  return solve_monolithic(*problem.bodies[0], *problem.bodies[1], problem.pairing(), parameters);
}

class MortarPatchTest : public ::testing::TestWithParam<std::string> {};

TEST_P(MortarPatchTest, MonolithicPressureIsExactAtEveryMultiplierNode) {
  CaseDefinition definition = example("non_matching_blocks.toml");
  definition.contact.non_mortar = GetParam();
  const LocalProblem problem = prepare_local_problem(definition);
  const int expected_side = GetParam() == "lower" ? 0 : 1;  // "": the finer side, the upper
  EXPECT_EQ(problem.pairing().non_mortar_body, expected_side);
  EXPECT_EQ(problem.pairing().size(), GetParam() == "lower" ? 11u : 15u);
  const MonolithicResult result = solve_reference(problem);
  ASSERT_EQ(result.qp.status, QpStatus::converged);
  EXPECT_LE(largest_pressure_error(problem.pairing(), result.contact_force, exact_patch_pressure()),
            1e-10);
}

TEST_P(MortarPatchTest, RobinIterationConvergesToTheMonolithicMortarSolution) {
  CaseDefinition definition = example("non_matching_blocks.toml");
  definition.contact.non_mortar = GetParam();
  definition.solver.qp.relative_tolerance = 1e-14;
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.iteration.status, IterationStatus::converged) << robin.iteration.message;
  std::printf("patch test, non-mortar side '%s': %zu iterations\n", GetParam().c_str(),
              robin.iteration.history.size());
  const LocalProblem problem = prepare_local_problem(definition);
  const MonolithicResult reference = solve_reference(problem);
  const double scale = reference.contact_force.lpNorm<Eigen::Infinity>();
  EXPECT_LE((robin.iteration.state.bodies[0].contact_force - reference.contact_force)
                .lpNorm<Eigen::Infinity>(),
            1e-8 * scale);
  EXPECT_LE((robin.iteration.state.bodies[1].contact_force - reference.contact_force)
                .lpNorm<Eigen::Infinity>(),
            1e-8 * scale);
  EXPECT_LE(largest_pressure_error(robin.pairing(), robin.iteration.state.bodies[0].contact_force,
                                   exact_patch_pressure()),
            1e-8);
}

INSTANTIATE_TEST_SUITE_P(NonMortarSide, MortarPatchTest, ::testing::Values("", "lower", "upper"));

TEST(MortarPatch, ExactOnFinerMeshesToo) {
  // 51 against 72 contact nodes: many overlaps away from the origin, where the projections'
  // round-off once lost Gauss points (a Newton tolerance below the coordinates' round-off).
  CaseDefinition definition = example("non_matching_blocks.toml");
  for (BodyCase& body : definition.bodies) body.mesh_options.size = 0.02;
  const LocalProblem problem = prepare_local_problem(definition);
  EXPECT_EQ(problem.pairing().size(), 72u);
  const MonolithicResult result = solve_reference(problem);
  ASSERT_EQ(result.qp.status, QpStatus::converged);
  EXPECT_LE(largest_pressure_error(problem.pairing(), result.contact_force, exact_patch_pressure()),
            1e-10);
}

TEST(NodeToSegment, FailsTheContactPatchTestThatMortarPasses) {
  CaseDefinition definition = example("non_matching_blocks.toml");
  definition.contact.method = ContactMethod::node_to_segment;
  definition.contact.non_mortar = "lower";
  const LocalProblem problem = prepare_local_problem(definition);
  const MonolithicResult result = solve_reference(problem);
  ASSERT_EQ(result.qp.status, QpStatus::converged);
  const double error =
      largest_pressure_error(problem.pairing(), result.contact_force, exact_patch_pressure());
  std::printf("node-to-segment patch test: largest pressure error %.3e\n", error);
  EXPECT_GT(error, 1e-3);
}

TEST(MortarOnMatchingMeshes, GivesTheNodeToNodeAnswer) {
  CaseDefinition definition = example("two_blocks.toml");
  definition.contact.method = ContactMethod::node_to_node;
  const LocalProblem node_to_node = prepare_local_problem(definition);
  definition.contact.method = ContactMethod::mortar;
  const LocalProblem mortar = prepare_local_problem(definition);
  ASSERT_EQ(mortar.pairing().size(), node_to_node.pairing().size());
  for (std::size_t j = 0; j < mortar.pairing().size(); ++j) {
    EXPECT_NEAR(mortar.pairing().pairs[j].weight, node_to_node.pairing().pairs[j].weight, 1e-13);
    EXPECT_NEAR(mortar.pairing().pairs[j].gap, node_to_node.pairing().pairs[j].gap, 1e-13);
  }
  const MonolithicResult first = solve_reference(node_to_node);
  const MonolithicResult second = solve_reference(mortar);
  const double scale = first.contact_force.lpNorm<Eigen::Infinity>();
  EXPECT_LE((first.contact_force - second.contact_force).lpNorm<Eigen::Infinity>(), 1e-10 * scale);
}

TEST(MortarSideCoarser, SemidefiniteContactProblemOfTheMortarBodyConverges) {
  // More rows than the mortar body's edge has normal degrees of freedom: that body's F is
  // singular. robin-run stopped on a contact QP breakdown here (p'Ap = -6.55e-27) before MPRGP
  // moved along null directions (mprgp.cpp, null_direction_step).
  const CaseDefinition definition =
      read_case_file(std::filesystem::path(ROBIN_TEST_DATA) / "row_pair_mortar.toml");
  const LocalProblem problem = prepare_local_problem(definition);
  EXPECT_EQ(problem.pairing().non_mortar_body, 1);
  EXPECT_EQ(problem.pairing().size(), 7u);  // on 6 free normal degrees of freedom of the left edge
  InProcessPort port1, port2;
  const CoupledRunResult robin =
      run_coupled_case(definition, {&port1, &port2}, definition.coupling);
  ASSERT_EQ(robin.iteration.status, IterationStatus::converged) << robin.iteration.message;
  const MonolithicResult reference = solve_reference(problem);
  ASSERT_EQ(reference.qp.status, QpStatus::converged);
  const double scale = reference.contact_force.lpNorm<Eigen::Infinity>();
  EXPECT_LE((robin.iteration.state.bodies[0].contact_force - reference.contact_force)
                .lpNorm<Eigen::Infinity>(),
            1e-8 * scale);
}

TEST(AutomaticContactMethod, ChoosesMortarForNonMatchingAndNodeToNodeForMatchingMeshes) {
  CaseDefinition matching = example("two_blocks.toml");
  EXPECT_EQ(prepare_local_problem(matching).pairing().non_mortar_body, -1);
  CaseDefinition non_matching = example("non_matching_blocks.toml");
  non_matching.contact.method = ContactMethod::automatic;
  EXPECT_EQ(prepare_local_problem(non_matching).pairing().non_mortar_body, 1);
}

}  // namespace
}  // namespace robin
