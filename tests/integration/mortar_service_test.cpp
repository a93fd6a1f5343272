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
#include "python_coupling_support.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
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

/// Runs the example `case_file` across robin-subdomain and robin-subdomain-py.
void expect_python_and_cpp_equal_monolithic(const std::string& case_file) {
  testing::expect_python_and_cpp_equal_monolithic(read_case_file(example(case_file)), case_file);
}

TEST(MortarService, PythonServerWithItsOwnMeshAgainstTheCppServerEqualsMonolithic) {
  expect_python_and_cpp_equal_monolithic("non_matching_blocks.toml");
}

TEST(MortarService, CurvedCylinderOnThePythonServerEqualsMonolithic) {
  expect_python_and_cpp_equal_monolithic("hertz_cylinder.toml");
}

}  // namespace
}  // namespace robin
