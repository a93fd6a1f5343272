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
//  - robin-coordinator with two servers for the three bodies exits 2 naming the count;
//  - the shipped keystone arch (examples/arch.toml: four bodies, the keystone floating, held by
//    contact alone): robin-run equals robin-monolithic to 1e-8 on every interface, and both
//    satisfy global equilibrium (the reactions of the supports balance the applied loads, the
//    contact forces cancelling between the bodies) and the keystone's own (its three
//    interfaces' forces balance its weight);
//  - a stack of three blocks under uniform compression on non-matching meshes, the middle one
//    floating (tests/data/stack_of_three.toml): the pressure at every multiplier row of both
//    interfaces is the exact series-spring value, 1e-10 from robin-monolithic and 1e-8 from
//    robin-run.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <iostream>
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

/// tests/data/`name` copied into `directory` with absolute mesh paths.
std::filesystem::path data_case(const std::filesystem::path& directory, const std::string& name) {
  const std::string text = std::regex_replace(
      testing::read_text(data / name), std::regex("mesh = \""), "mesh = \"" + data.string() + "/");
  const std::filesystem::path path = directory / name;
  std::ofstream(path) << text;
  return path;
}

std::filesystem::path row_case(const std::filesystem::path& directory) {
  return data_case(directory, "row_of_three.toml");
}

const std::vector<std::string> contact_files{"contact_1_left_middle.csv",
                                             "contact_2_middle_right.csv"};

/// robin-monolithic's result directory of the row (computed once for every test).
const std::filesystem::path& monolithic_results() {
  static const TemporaryDirectory directory("many-bodies-monolithic");
  static const bool solved = [] {
    const ProcessOutcome outcome = run_tool(
        "robin-monolithic",
        {row_case(directory.path()).string(), "--output", (directory.path() / "out").string()},
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
  const ProcessOutcome outcome =
      run_tool("robin-run", {row_case(directory.path()).string(), "--output", output.string()},
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
  const ProcessOutcome outcome = run_tool("robin-coordinator", arguments, directory.path(), 300.0);
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

Eigen::Vector2d vector_of(const nlohmann::json& pair) {
  return {pair[0].get<double>(), pair[1].get<double>()};
}

/// Global equilibrium: the reactions of every body's supports and the applied loads sum to zero;
/// the keystone's (body 3's) interfaces balance its weight: interfaces 1 and 2 are the
/// abutments' push on it (body a on body b), interface 3 its push on the platen.
void expect_arch_equilibrium(const nlohmann::json& summary, const std::string& what) {
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  double scale = 0.0;
  for (const nlohmann::json& body : summary["bodies"]) {
    const Eigen::Vector2d reaction = vector_of(body["reaction_resultant"]);
    total += reaction + vector_of(body["applied_force"]);
    scale = std::max(scale, reaction.norm());
  }
  EXPECT_LE(total.norm(), 1e-8 * scale)
      << what << ": sum of reactions and loads " << total.transpose();
  const nlohmann::json& interfaces = summary["interfaces"];
  ASSERT_EQ(interfaces.size(), 3u);
  const Eigen::Vector2d weight = vector_of(summary["bodies"][2]["applied_force"]);
  EXPECT_NEAR(weight.y(), -1.3, 1e-12) << "the keystone's area is 1.3, its body force -1";
  const Eigen::Vector2d on_keystone = vector_of(interfaces[0]["contact_force_resultant"]) +
                                      vector_of(interfaces[1]["contact_force_resultant"]) -
                                      vector_of(interfaces[2]["contact_force_resultant"]);
  EXPECT_LE((on_keystone + weight).norm(), 1e-8 * on_keystone.norm())
      << what << ": contact forces on the keystone " << on_keystone.transpose();
}

TEST(ManyBodiesService, KeystoneArchWithAFloatingBodyEqualsTheMonolithicSolution) {
  const TemporaryDirectory directory("many-bodies-arch");
  const std::string arch = testing::example("arch.toml").string();
  const ProcessOutcome monolithic =
      run_tool("robin-monolithic", {arch, "--output", (directory.path() / "monolithic").string()},
               directory.path(), 300.0);
  ASSERT_EQ(monolithic.exit, "exited with status 0") << monolithic.errors;
  const ProcessOutcome run =
      run_tool("robin-run", {arch, "--output", (directory.path() / "run").string()},
               directory.path(), 600.0);
  ASSERT_EQ(run.exit, "exited with status 0") << run.errors;
  for (const std::string file :
       {"contact_1_abutment_left_keystone.csv", "contact_2_abutment_right_keystone.csv",
        "contact_3_keystone_platen.csv"}) {
    testing::expect_same_table(testing::csv_values(directory.path() / "run" / file),
                               testing::csv_values(directory.path() / "monolithic" / file), 1e-8,
                               "arch " + file);
  }
  const nlohmann::json run_summary = testing::read_summary(directory.path() / "run");
  EXPECT_EQ(run_summary["status"], "converged");
  expect_arch_equilibrium(run_summary, "robin-run");
  expect_arch_equilibrium(testing::read_summary(directory.path() / "monolithic"),
                          "robin-monolithic");
}

/// The plane-strain constrained modulus E (1 - nu) / ((1 + nu)(1 - 2 nu)), nu = 0.3.
double constrained_modulus(double young) {
  return young * 0.7 / (1.3 * 0.4);
}

/// Every row's pressure in the contact files of `results` within `relative` of `exact`.
void expect_uniform_pressure(const std::filesystem::path& results, double exact, double relative,
                             const std::string& what) {
  for (const std::string file : {"contact_1_bottom_middle.csv", "contact_2_middle_top.csv"}) {
    const auto columns = testing::read_csv(results / file);
    ASSERT_TRUE(columns.count("pressure") != 0) << what << " " << file;
    const std::vector<std::string>& pressures = columns.at("pressure");
    ASSERT_GE(pressures.size(), 8u) << what << " " << file;
    double worst = 0.0;
    for (const std::string& pressure : pressures) {
      worst = std::max(worst, std::abs(std::stod(pressure) - exact) / exact);
    }
    std::cout << what << " " << file << ": " << pressures.size()
              << " rows, largest relative pressure error " << worst << "\n";
    EXPECT_LE(worst, relative) << what << " " << file;
  }
}

TEST(ManyBodiesService, FloatingBlockInAStackOnNonMatchingMeshesHasTheExactUniformPressure) {
  const TemporaryDirectory directory("many-bodies-stack");
  const std::string stack = data_case(directory.path(), "stack_of_three.toml").string();
  const double exact =
      0.01 / (1.0 / constrained_modulus(1000.0) + 1.0 / constrained_modulus(300.0) +
              1.0 / constrained_modulus(2000.0));
  const ProcessOutcome monolithic =
      run_tool("robin-monolithic", {stack, "--output", (directory.path() / "monolithic").string()},
               directory.path(), 300.0);
  ASSERT_EQ(monolithic.exit, "exited with status 0") << monolithic.errors;
  expect_uniform_pressure(directory.path() / "monolithic", exact, 1e-10, "robin-monolithic");
  const ProcessOutcome run =
      run_tool("robin-run", {stack, "--output", (directory.path() / "run").string()},
               directory.path(), 600.0);
  ASSERT_EQ(run.exit, "exited with status 0") << run.errors;
  expect_uniform_pressure(directory.path() / "run", exact, 1e-8, "robin-run");
  const nlohmann::json summary = testing::read_summary(directory.path() / "run");
  EXPECT_NE(summary["interfaces"][0]["contact_discretization"].get<std::string>().find("mortar"),
            std::string::npos);
}

}  // namespace
}  // namespace robin
