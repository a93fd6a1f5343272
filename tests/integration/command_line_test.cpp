// The command-line conventions of every tool, through the real executables in build/bin and the
// Python server: --version prints the product version (the file VERSION at the top of the
// repository) and the protocol version and exits 0; --help exits 0; a bad command line exits
// 2. --quiet leaves only warnings and errors. --set KEY=VALUE overrides case-file keys in
// robin-monolithic and robin-run: the contact pressure of the contact patch test
// (examples/non_matching_blocks.toml) follows the overridden load and modulus as its analytic
// value says; robin-monolithic records the overrides in summary.json; a bad value is an input
// error (1) naming the override, a malformed override a command-line error (2).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "protocol_version.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using nlohmann::json;
using testing::example;
using testing::ProcessOutcome;
using testing::run_tool;
using testing::TemporaryDirectory;

const std::vector<std::string> tools{"robin-run",       "robin-coordinator", "robin-monolithic",
                                     "robin-subdomain", "robin-keygen",      "robin-mesh-reader"};

std::string product_version() {
  std::ifstream file(std::filesystem::path(ROBIN_EXAMPLES).parent_path() / "VERSION");
  std::string version;
  std::getline(file, version);
  return version;
}

std::string protocol_version() {
  return std::to_string(protocol::protocol_major) + "." + std::to_string(protocol::protocol_minor);
}

/// The uniform contact pressure of the patch test (the comment of non_matching_blocks.toml):
/// p = d / (H1 (1 - nu1^2) / E1 + H2 (1 - nu2^2) / E2), H1 = 0.5, H2 = 0.4, nu1 = 0.3,
/// nu2 = 0.25, with the top displacement d and the lower block's modulus E1.
double patch_pressure(double displacement, double young1) {
  return displacement / (0.5 * (1.0 - 0.09) / young1 + 0.4 * (1.0 - 0.0625) / 400.0);
}

/// The pressure column of DIRECTORY/contact.csv.
std::vector<double> pressures(const std::filesystem::path& directory) {
  std::ifstream in(directory / "contact.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.substr(line.rfind(',') + 1), "pressure");
  std::vector<double> values;
  while (std::getline(in, line)) values.push_back(std::stod(line.substr(line.rfind(',') + 1)));
  return values;
}

json summary(const std::filesystem::path& directory) {
  std::ifstream in(directory / "summary.json");
  return json::parse(in);
}

class CommandLine : public ::testing::Test {
 protected:
  TemporaryDirectory directory_{"command-line"};
};

TEST_F(CommandLine, VersionOfEveryTool) {
  const std::string expected = product_version() + " (protocol " + protocol_version() + ")";
  ASSERT_FALSE(product_version().empty());
  for (const std::string& tool : tools) {
    const ProcessOutcome outcome = run_tool(tool, {"--version"}, directory_.path(), 30);
    EXPECT_EQ(outcome.exit, "exited with status 0") << tool << outcome.errors;
    EXPECT_EQ(outcome.output, tool + " " + expected + "\n") << tool;
  }
  const ProcessOutcome check =
      run_tool("robin-coordinator", {"--check-server", "tcp://127.0.0.1:9", "--version"},
               directory_.path(), 30);
  EXPECT_EQ(check.exit, "exited with status 0") << check.errors;
  EXPECT_EQ(check.output, "robin-coordinator --check-server " + expected + "\n");
}

TEST_F(CommandLine, HelpOfEveryToolExitsZero) {
  for (const std::string& tool : tools) {
    const ProcessOutcome outcome = run_tool(tool, {"--help"}, directory_.path(), 30);
    EXPECT_EQ(outcome.exit, "exited with status 0") << tool << outcome.errors;
    EXPECT_NE(outcome.output.find("--version"), std::string::npos) << tool;
  }
}

TEST_F(CommandLine, BadCommandLinesExitTwo) {
  for (const std::string& tool : tools) {
    const ProcessOutcome outcome = run_tool(tool, {"--no-such-option"}, directory_.path(), 30);
    EXPECT_EQ(outcome.exit, "exited with status 2") << tool << outcome.errors;
    EXPECT_NE(outcome.errors.find("Run with --help"), std::string::npos) << tool;
  }
  // Required options missing.
  const ProcessOutcome monolithic = run_tool("robin-monolithic", {}, directory_.path(), 30);
  EXPECT_EQ(monolithic.exit, "exited with status 2") << monolithic.errors;
  const ProcessOutcome server = run_tool("robin-subdomain", {}, directory_.path(), 30);
  EXPECT_EQ(server.exit, "exited with status 2") << server.errors;
}

TEST_F(CommandLine, PythonServerVersionHelpAndUsage) {
  const std::string server =
      (std::filesystem::path(ROBIN_EXAMPLES).parent_path() / "python" / "robin-subdomain-py")
          .string();
  const auto run = [&](const std::string& arguments) {
    const std::string command = "/usr/bin/python3 " + server + " " + arguments + " 2>/dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    std::string output;
    char buffer[4096];
    while (pipe != nullptr && std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
    const int status = pipe != nullptr ? pclose(pipe) : -1;
    return std::make_pair(WIFEXITED(status) ? WEXITSTATUS(status) : -1, output);
  };
  const auto [version_status, version] = run("--version");
  EXPECT_EQ(version_status, 0);
  // The Python server speaks its own protocol version (python/robin_subdomain/protocol.py).
  EXPECT_EQ(version.rfind("robin-subdomain-py " + product_version() + " (protocol ", 0), 0u)
      << version;
  EXPECT_EQ(run("--help").first, 0);
  EXPECT_EQ(run("--no-such-option").first, 2);
}

TEST_F(CommandLine, QuietLeavesOnlyWarningsAndErrors) {
  const std::filesystem::path output = directory_.path() / "quiet";
  const ProcessOutcome outcome = run_tool(
      "robin-monolithic",
      {example("non_matching_blocks.toml").string(), "--output", output.string(), "--quiet"},
      directory_.path(), 300);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  EXPECT_EQ(outcome.errors.find("[info]"), std::string::npos) << outcome.errors;
  EXPECT_TRUE(std::filesystem::exists(output / "summary.json"));
  // --quiet and --log-level contradict each other.
  const ProcessOutcome both =
      run_tool("robin-run",
               {example("two_blocks.toml").string(), "--output",
                (directory_.path() / "both").string(), "--quiet", "--log-level", "debug"},
               directory_.path(), 30);
  EXPECT_EQ(both.exit, "exited with status 2") << both.errors;
}

TEST_F(CommandLine, MonolithicOverridesFollowThePatchTestsAnalyticPressure) {
  const std::filesystem::path output = directory_.path() / "monolithic";
  const std::vector<std::string> overrides{"body[2].dirichlet[1].y=-0.02",
                                           "body[1].material.young=2000"};
  std::vector<std::string> arguments{example("non_matching_blocks.toml").string(), "--output",
                                     output.string()};
  for (const std::string& text : overrides) {
    arguments.push_back("--set");
    arguments.push_back(text);
  }
  const ProcessOutcome outcome = run_tool("robin-monolithic", arguments, directory_.path(), 300);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  const double expected = patch_pressure(0.02, 2000.0);
  const std::vector<double> values = pressures(output);
  ASSERT_FALSE(values.empty());
  for (const double value : values) EXPECT_NEAR(value, expected, 1e-8 * expected);
  EXPECT_EQ(summary(output)["overrides"], json(overrides));
}

TEST_F(CommandLine, CoupledRunOverrideScalesThePressure) {
  const std::filesystem::path output = directory_.path() / "coupled";
  const ProcessOutcome outcome =
      run_tool("robin-run",
               {example("non_matching_blocks.toml").string(), "--output", output.string(), "--set",
                "body[2].dirichlet[1].y=-0.005", "--quiet"},
               directory_.path(), 300);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  EXPECT_EQ(outcome.errors.find("[info]"), std::string::npos) << outcome.errors;
  const double expected = patch_pressure(0.005, 1000.0);
  const std::vector<double> values = pressures(output);
  ASSERT_FALSE(values.empty());
  for (const double value : values) EXPECT_NEAR(value, expected, 1e-6 * expected);
}

TEST_F(CommandLine, OverrideErrors) {
  const std::string case_file = example("two_blocks.toml").string();
  for (const std::string tool : {"robin-monolithic", "robin-run"}) {
    const ProcessOutcome value =
        run_tool(tool,
                 {case_file, "--output", (directory_.path() / (tool + "-value")).string(), "--set",
                  "coupling.tolerance=abc"},
                 directory_.path(), 60);
    EXPECT_EQ(value.exit, "exited with status 1") << tool << value.errors;
    EXPECT_NE(value.errors.find("--set coupling.tolerance=abc: coupling.tolerance: expected a "
                                "number, found a string"),
              std::string::npos)
        << tool << value.errors;
    const ProcessOutcome unknown =
        run_tool(tool,
                 {case_file, "--output", (directory_.path() / (tool + "-unknown")).string(),
                  "--set", "coupling.tolerence=1e-9"},
                 directory_.path(), 60);
    EXPECT_EQ(unknown.exit, "exited with status 1") << tool << unknown.errors;
    EXPECT_NE(
        unknown.errors.find("--set coupling.tolerence=1e-9: unknown key 'coupling.tolerence'"),
        std::string::npos)
        << tool << unknown.errors;
    const ProcessOutcome malformed =
        run_tool(tool,
                 {case_file, "--output", (directory_.path() / (tool + "-malformed")).string(),
                  "--set", "coupling.tolerance"},
                 directory_.path(), 60);
    EXPECT_EQ(malformed.exit, "exited with status 2") << tool << malformed.errors;
    EXPECT_NE(malformed.errors.find("expected KEY=VALUE"), std::string::npos)
        << tool << malformed.errors;
  }
}

}  // namespace
}  // namespace robin
