// Solid (3D) bodies through the real service, against numbers from outside the code:
//  - robin-run (two robin-subdomain processes) on examples/non_matching_solids.toml (tetrahedra
//    against hexahedra, mortar) writes the patch test's exact pressure into every row of
//    contact.csv;
//  - robin-coordinator against two robin-subdomain servers started beforehand writes the same;
//  - robin-run and robin-monolithic on examples/hertz_3d.toml write the same contact forces;
//  - with the iterative inner solver (solver.linear_solver = "multigrid": AMG-preconditioned
//    conjugate gradients stopped at a relative residual of 1e-12, docs/method.md) robin-run
//    reproduces the patch test's pressure and the direct robin-monolithic's contact forces on
//    the sphere to 1e-7 relative (an error bound of cond(K) x 1e-12 for cond(K) up to 1e5);
//  - robin-coordinator's coupling with the independent Python server owning the hexahedral
//    block and robin-subdomain the tetrahedral one gives the monolithic mortar solution.

#include <gtest/gtest.h>

#include <cstdio>

#include "coupling/coupled_run.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "python_coupling_support.hpp"
#include "remote/remote_port.hpp"
#include "remote/server_launcher.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::TemporaryDirectory;

/// The exact pressure of examples/non_matching_solids.toml: p = delta / (H1/E1 + H2/E2).
double exact_patch_pressure() {
  return 0.01 / (0.5 / 1000.0 + 0.4 / 400.0);
}

/// Runs `tool` on `case_file` with `extra` arguments into `directory`/`name`; returns the
/// columns of its contact.csv.
std::map<std::string, std::vector<std::string>> run_case(const std::string& tool,
                                                         const std::string& case_file,
                                                         const std::vector<std::string>& extra,
                                                         const TemporaryDirectory& directory,
                                                         const std::string& name) {
  std::vector<std::string> arguments = {example(case_file).string(), "--output",
                                        (directory.path() / name).string(), "--log-level", "warn"};
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  const testing::ProcessOutcome outcome = testing::run_tool(tool, arguments, directory.path(), 300);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  return testing::read_csv(directory.path() / name / "contact.csv");
}

/// Every row of `columns` (contact.csv) has the patch test's exact pressure to `relative`.
void expect_patch_pressure(const std::map<std::string, std::vector<std::string>>& columns,
                           double relative) {
  ASSERT_TRUE(columns.count("pressure"));
  ASSERT_GT(columns.at("pressure").size(), 20u);
  for (const std::string& pressure : columns.at("pressure")) {
    EXPECT_NEAR(std::stod(pressure), exact_patch_pressure(), relative * exact_patch_pressure());
  }
}

/// The contact forces lambda1, lambda2 of `run` equal those of `monolithic` to `relative` of the
/// largest monolithic lambda1.
void expect_same_contact_forces(const std::map<std::string, std::vector<std::string>>& run,
                                const std::map<std::string, std::vector<std::string>>& monolithic,
                                double relative) {
  ASSERT_EQ(run.at("lambda1").size(), monolithic.at("lambda1").size());
  double largest = 0.0;
  for (const std::string& value : monolithic.at("lambda1")) {
    largest = std::max(largest, std::abs(std::stod(value)));
  }
  ASSERT_GT(largest, 0.0);
  for (const char* column : {"lambda1", "lambda2"}) {
    for (std::size_t k = 0; k < run.at(column).size(); ++k) {
      EXPECT_NEAR(std::stod(run.at(column)[k]), std::stod(monolithic.at(column)[k]),
                  relative * largest)
          << column << " row " << k;
    }
  }
}

/// robin-monolithic's arguments for the sphere on the coarse mesh the sphere tests use.
const std::vector<std::string> coarse_sphere = {"--set", "body[1].mesh_size=0.04", "--set",
                                                "body[2].mesh_size=0.04"};

TEST(SolidService, RobinRunReproducesTheThreeDimensionalPatchTestPressure) {
  const TemporaryDirectory output("solid-patch");
  const auto columns = run_case("robin-run", "non_matching_solids.toml", {}, output, "run");
  ASSERT_TRUE(columns.count("z") && columns.count("nz")) << "contact.csv of a solid case has z, nz";
  expect_patch_pressure(columns, 1e-8);
}

TEST(SolidService, RobinCoordinatorAgainstTwoServersReproducesThePatchTestPressure) {
  const TemporaryDirectory output("solid-coordinator");
  SubdomainServer lower("lower", testing::server_options(output.path()));
  SubdomainServer upper("upper", testing::server_options(output.path()));
  lower.await_listening();
  upper.await_listening();
  const auto columns =
      run_case("robin-coordinator", "non_matching_solids.toml",
               {"--subdomain", lower.endpoint(), "--subdomain", upper.endpoint()}, output, "run");
  expect_patch_pressure(columns, 1e-8);
}

TEST(SolidService, RobinRunEqualsRobinMonolithicOnTheSphere) {
  const TemporaryDirectory output("solid-hertz");
  std::vector<std::string> tight = coarse_sphere;
  tight.insert(tight.end(), {"--tolerance", "1e-11"});
  const auto run = run_case("robin-run", "hertz_3d.toml", tight, output, "run");
  const auto monolithic =
      run_case("robin-monolithic", "hertz_3d.toml", coarse_sphere, output, "mono");
  expect_same_contact_forces(run, monolithic, 1e-8);
}

TEST(SolidService, RobinRunWithTheMultigridSolverReproducesThePatchTestPressure) {
  const TemporaryDirectory output("solid-patch-multigrid");
  const auto columns = run_case("robin-run", "non_matching_solids.toml",
                                {"--set", "solver.linear_solver=multigrid"}, output, "run");
  expect_patch_pressure(columns, 1e-7);
}

TEST(SolidService, RobinRunWithTheMultigridSolverEqualsTheDirectMonolithicOnTheSphere) {
  const TemporaryDirectory output("solid-hertz-multigrid");
  std::vector<std::string> multigrid = coarse_sphere;
  multigrid.insert(multigrid.end(),
                   {"--tolerance", "1e-10", "--set", "solver.linear_solver=multigrid"});
  const auto run = run_case("robin-run", "hertz_3d.toml", multigrid, output, "run");
  const auto monolithic =
      run_case("robin-monolithic", "hertz_3d.toml", coarse_sphere, output, "mono");
  expect_same_contact_forces(run, monolithic, 1e-7);
  // summary.json names each body's solver: the one asked for, and "auto"'s choice for these
  // small bodies (direct)
  for (const auto& [name, expected] :
       std::vector<std::pair<std::string, std::string>>{{"run", "multigrid"}, {"mono", "direct"}}) {
    const nlohmann::json bodies = testing::read_summary(output.path() / name)["profile"]["bodies"];
    ASSERT_EQ(bodies.size(), 2u) << name;
    for (const nlohmann::json& body : bodies) EXPECT_EQ(body["linear_solver"], expected) << name;
  }
}

TEST(SolidService, PythonServerOwningTheHexahedraEqualsMonolithic) {
  CaseDefinition definition = read_case_file(example("non_matching_solids.toml"));
  definition.coupling.tolerance = 1e-11;
  testing::expect_python_and_cpp_equal_monolithic(definition, "non_matching_solids.toml");
}

}  // namespace
}  // namespace robin
