// Mortar contact through the real service: robin-run (two robin-subdomain processes) on the
// non-matching blocks reproduces the patch test's exact pressure in contact.csv; and an
// external code, the independent Python server robin-subdomain-py, owning one body meshed
// differently from the other (quadrilaterals against triangles, or the curved cylinder against
// the block), coupled by mortar to a C++ server, gives the monolithic mortar solution to 1e-8.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "coupling/coupled_run.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::python_server_options;
using testing::server_options;
using testing::TemporaryDirectory;

/// The patch test's exact pressure (examples/non_matching_blocks.toml).
double exact_patch_pressure() {
  return 0.01 / (0.5 * (1.0 - 0.3 * 0.3) / 1000.0 + 0.4 * (1.0 - 0.25 * 0.25) / 400.0);
}

TEST(MortarService, RobinRunReproducesThePatchTestPressureInContactCsv) {
  const TemporaryDirectory output("mortar-run");
  const testing::ProcessOutcome outcome =
      testing::run_tool("robin-run",
                        {example("non_matching_blocks.toml").string(), "--output",
                         (output.path() / "results").string(), "--log-level", "warn"},
                        output.path(), 120.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  std::ifstream table(output.path() / "results" / "contact.csv");
  std::string line;
  std::getline(table, line);  // header: pair,x,y,nx,ny,gap0,un1,un2,lambda1,lambda2,pressure
  int rows = 0;
  while (std::getline(table, line)) {
    const double pressure = std::stod(line.substr(line.rfind(',') + 1));
    EXPECT_NEAR(pressure, exact_patch_pressure(), 1e-8 * exact_patch_pressure()) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 15);  // the upper block's contact nodes carry the multipliers
  std::ifstream summary(output.path() / "results" / "summary.json");
  std::stringstream text;
  text << summary.rdbuf();
  EXPECT_NE(text.str().find("mortar coupling (non-mortar side: body 'upper')"), std::string::npos);
}

/// Runs `case_file` with body 1 on robin-subdomain and body 2 on robin-subdomain-py, and compares
/// the contact forces with the monolithic mortar solution of the same discretization.
void expect_python_and_cpp_equal_monolithic(const std::string& case_file) {
  const TemporaryDirectory logs("mortar-python");
  CaseDefinition definition = read_case_file(example(case_file));
  definition.solver.qp.relative_tolerance = 1e-13;
  SubdomainServer cpp(definition.bodies[0].definition.name, server_options(logs.path()));
  SubdomainServer python(definition.bodies[1].definition.name, python_server_options(logs.path()));
  cpp.await_listening();
  python.await_listening();
  RemotePortOptions port_options;
  port_options.request_timeout_seconds = 120.0;
  RemotePort body1(cpp.endpoint(), definition.bodies[0].definition.name, port_options);
  RemotePort body2(python.endpoint(), definition.bodies[1].definition.name, port_options);
  const CoupledRunResult run = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  EXPECT_EQ(body2.server_name().rfind("robin-subdomain-py ", 0), 0u) << body2.server_name();
  body1.end_run();
  body2.end_run();
  ASSERT_EQ(run.iteration.status, IterationStatus::converged) << run.iteration.message;
  EXPECT_GE(run.pairing().non_mortar_body, 0);

  const LocalProblem problem = prepare_local_problem(definition);
  MprgpParameters reference = definition.solver.qp;
  reference.relative_tolerance = 1e-14;
  const MonolithicResult monolithic =
      solve_monolithic(*problem.bodies[0], *problem.bodies[1], problem.pairing(), reference);
  ASSERT_EQ(monolithic.qp.status, QpStatus::converged);
  std::printf("%s, C++ and Python servers: %zu iterations\n", case_file.c_str(),
              run.iteration.history.size());
  EXPECT_TRUE(testing::vectors_close(run.iteration.state.bodies[0].contact_force,
                                     monolithic.contact_force, 1e-8));
  EXPECT_TRUE(testing::vectors_close(run.iteration.state.bodies[1].contact_force,
                                     monolithic.contact_force, 1e-8));
}

TEST(MortarService, PythonServerWithItsOwnMeshAgainstTheCppServerEqualsMonolithic) {
  expect_python_and_cpp_equal_monolithic("non_matching_blocks.toml");
}

TEST(MortarService, CurvedCylinderOnThePythonServerEqualsMonolithic) {
  expect_python_and_cpp_equal_monolithic("hertz_cylinder.toml");
}

}  // namespace
}  // namespace robin
