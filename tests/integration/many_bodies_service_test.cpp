// A case of three bodies and two contact interfaces (tests/data/row_of_three.toml: a row of
// blocks, the middle one touching both others on non-matching meshes, coupled by mortar)
// through the real tools:
//  - robin-run (three robin-subdomain processes) converges and its contact files equal
//    robin-monolithic's, the one-QP solution of the same contact graph, to 1e-8;
//  - robin-coordinator against three long-running servers gives the same answer;
//  - the outputs name every body and interface: solution.pvd one part per body, one contact file
//    per interface, summary.json's "bodies" and "interfaces";
//  - mirror symmetry (numbers from outside the code): the row is symmetric about x = 1.5 (equal
//    outer blocks, mirrored meshes), so both interfaces carry the same contact resultant;
//  - robin-coordinator with two servers for the three bodies exits 2 naming the count.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "remote/server_launcher.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::ProcessOutcome;
using testing::run_tool;
using testing::TemporaryDirectory;

const std::filesystem::path data = ROBIN_TEST_DATA;

/// row_of_three.toml copied into `directory` with absolute mesh paths.
std::filesystem::path row_case(const std::filesystem::path& directory) {
  const std::string text = std::regex_replace(testing::read_text(data / "row_of_three.toml"),
                                              std::regex("mesh = \""), "mesh = \"" +
                                                                           data.string() + "/");
  const std::filesystem::path path = directory / "row_of_three.toml";
  std::ofstream(path) << text;
  return path;
}

const std::vector<std::string> contact_files{"contact_1_left_middle.csv",
                                             "contact_2_middle_right.csv"};

/// robin-monolithic's result directory of the row (computed once for every test).
const std::filesystem::path& monolithic_results() {
  static const TemporaryDirectory directory("many-bodies-monolithic");
  static const bool solved = [] {
    const ProcessOutcome outcome =
        run_tool("robin-monolithic",
                 {row_case(directory.path()).string(), "--output",
                  (directory.path() / "out").string()},
                 directory.path(), 120.0);
    EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
    return true;
  }();
  static_cast<void>(solved);
  return directory.path();
}

void expect_equal_to_monolithic(const std::filesystem::path& results, const std::string& what) {
  for (const std::string& file : contact_files) {
    ASSERT_TRUE(std::filesystem::exists(results / file)) << what << ": " << file;
    testing::expect_same_table(testing::csv_values(results / file),
                               testing::csv_values(monolithic_results() / "out" / file), 1e-8,
                               what + " " + file);
  }
}

TEST(ManyBodiesService, RobinRunEqualsTheMonolithicContactGraphSolution) {
  const TemporaryDirectory directory("many-bodies-run");
  const std::filesystem::path output = directory.path() / "out";
  const ProcessOutcome outcome = run_tool(
      "robin-run", {row_case(directory.path()).string(), "--output", output.string()},
      directory.path(), 300.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  expect_equal_to_monolithic(output, "robin-run");
  EXPECT_FALSE(std::filesystem::exists(output / "contact.csv"));  // one file per interface
  for (const std::string body : {"left", "middle", "right"}) {
    EXPECT_TRUE(std::filesystem::exists(output / (body + ".vtu"))) << body;
    EXPECT_TRUE(std::filesystem::exists(output / "logs" / ("server-" + body + ".log"))) << body;
  }
  const std::string pvd = testing::read_text(output / "solution.pvd");
  for (const std::string part : {"part=\"0\"", "part=\"1\"", "part=\"2\""}) {
    EXPECT_NE(pvd.find(part), std::string::npos) << pvd;
  }
  const nlohmann::json summary = testing::read_summary(output);
  EXPECT_EQ(summary["status"], "converged");
  ASSERT_EQ(summary["bodies"].size(), 3u);
  EXPECT_EQ(summary["bodies"][1]["name"], "middle");
  ASSERT_EQ(summary["interfaces"].size(), 2u);
  EXPECT_EQ(summary["interfaces"][0]["file"], contact_files[0]);
  EXPECT_EQ(summary["interfaces"][1]["bodies"], (nlohmann::json{"middle", "right"}));
  EXPECT_NE(summary["interfaces"][0]["contact_discretization"].get<std::string>().find("mortar"),
            std::string::npos);
  // mirror symmetry about x = 1.5: the same push through both interfaces
  const double first = summary["interfaces"][0]["contact_force_resultant"][0];
  const double second = summary["interfaces"][1]["contact_force_resultant"][0];
  EXPECT_GT(first, 0.1);
  EXPECT_NEAR(first, second, 1e-8 * first);
  EXPECT_EQ(summary["contact_force_resultant"], nullptr);  // several interfaces: see each one
}

TEST(ManyBodiesService, RobinCoordinatorAgainstThreeServersEqualsTheMonolithicSolution) {
  const TemporaryDirectory directory("many-bodies-coordinator");
  std::vector<std::string> bodies{"left", "middle", "right"};
  LocalServers servers(bodies, testing::server_options(directory.path(), "tcp://127.0.0.1:*"));
  servers.await_listening();
  std::vector<std::string> arguments{row_case(directory.path()).string(), "--output",
                                     (directory.path() / "out").string()};
  for (const std::string& endpoint : servers.endpoints()) {
    arguments.insert(arguments.end(), {"--subdomain", endpoint});
  }
  const ProcessOutcome outcome =
      run_tool("robin-coordinator", arguments, directory.path(), 300.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  expect_equal_to_monolithic(directory.path() / "out", "robin-coordinator");
}

TEST(ManyBodiesService, TwoServersForThreeBodiesAreACommandLineError) {
  const TemporaryDirectory directory("many-bodies-count");
  const ProcessOutcome outcome = run_tool(
      "robin-coordinator",
      {row_case(directory.path()).string(), "--output", (directory.path() / "out").string(),
       "--subdomain", "tcp://127.0.0.1:9", "--subdomain", "tcp://127.0.0.1:10"},
      directory.path(), 60.0);
  EXPECT_EQ(outcome.exit, "exited with status 2") << outcome.errors;
  EXPECT_NE(outcome.errors.find("has 3 bodies: give one --subdomain ENDPOINT per body"),
            std::string::npos)
      << outcome.errors;
}

}  // namespace
}  // namespace robin
