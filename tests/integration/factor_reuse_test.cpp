// A long-running robin-subdomain keeps a body's factor for a later run of the same body
// (issue 16, reuse): two robin-coordinator runs of examples/two_blocks_partial.toml against the
// same two servers, the second with the upper block pushed twice as far (--set on its top's
// prescribed displacement). Each server logs that the second SetupBody reused the factorization
// of the first run, and the second run's contact.csv equals that of a robin-run of the changed
// case on fresh servers (every column, 1e-10 relative): the kept factor, B and F give the
// answer a full setup gives. A third run with another material is set up from scratch (no
// reuse logged for it) and equals its own fresh robin-run as well.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "remote/server_launcher.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::read_csv;
using testing::run_tool;
using testing::TemporaryDirectory;

constexpr const char* reuse_line = "factorization of the previous run reused";

std::string file_text(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

std::size_t occurrences(const std::string& text, const std::string& word) {
  std::size_t count = 0;
  for (auto at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++count;
  return count;
}

/// Every numeric column of two contact.csv files agrees to `tolerance` relative to the
/// column's largest magnitude.
void expect_same_contact_state(const std::filesystem::path& actual,
                               const std::filesystem::path& expected, double tolerance) {
  const auto left = read_csv(actual);
  const auto right = read_csv(expected);
  ASSERT_FALSE(right.empty()) << expected;
  for (const auto& [name, column] : right) {
    ASSERT_EQ(left.count(name), 1u) << name;
    const std::vector<std::string>& other = left.at(name);
    ASSERT_EQ(other.size(), column.size()) << name;
    double scale = 1e-300;
    for (const std::string& cell : column) scale = std::max(scale, std::abs(std::stod(cell)));
    for (std::size_t row = 0; row < column.size(); ++row) {
      EXPECT_LE(std::abs(std::stod(other[row]) - std::stod(column[row])), tolerance * scale)
          << "contact.csv column " << name << ", row " << row + 1;
    }
  }
}

/// robin-run of examples/two_blocks_partial.toml with `overrides`, into `directory`/name.
std::filesystem::path fresh_run(const std::filesystem::path& directory, const std::string& name,
                                const std::vector<std::string>& overrides) {
  std::vector<std::string> arguments = {example("two_blocks_partial.toml").string(), "--output",
                                        (directory / name).string()};
  arguments.insert(arguments.end(), overrides.begin(), overrides.end());
  std::filesystem::create_directories(directory / (name + "-logs"));
  const auto outcome = run_tool("robin-run", arguments, directory / (name + "-logs"), 300.0);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  return directory / name / "contact.csv";
}

TEST(FactorReuse, ALaterRunOfTheSameBodyReusesTheFactorAndGivesTheFreshAnswer) {
  const TemporaryDirectory directory("factor-reuse");
  ServerLaunchOptions options = testing::server_options(directory.path() / "server-logs");
  options.log_level = "info";
  SubdomainServer lower("lower", options);
  SubdomainServer upper("upper", options);
  lower.await_listening();
  upper.await_listening();
  const auto coordinator_run = [&](const std::string& name,
                                   const std::vector<std::string>& overrides) {
    std::vector<std::string> arguments = {example("two_blocks_partial.toml").string(),
                                          "--subdomain",
                                          lower.endpoint(),
                                          "--subdomain",
                                          upper.endpoint(),
                                          "--output",
                                          (directory.path() / name).string()};
    arguments.insert(arguments.end(), overrides.begin(), overrides.end());
    std::filesystem::create_directories(directory.path() / (name + "-logs"));
    const auto outcome =
        run_tool("robin-coordinator", arguments, directory.path() / (name + "-logs"), 300.0);
    EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
    return directory.path() / name / "contact.csv";
  };

  const std::vector<std::string> deeper = {"--set", "body[2].dirichlet[1].y=-0.02"};
  coordinator_run("first", {});
  for (const SubdomainServer* server : {&lower, &upper}) {
    EXPECT_EQ(occurrences(file_text(server->log_file()), reuse_line), 0u) << server->label();
  }
  const auto second = coordinator_run("second", deeper);
  for (const SubdomainServer* server : {&lower, &upper}) {
    EXPECT_EQ(occurrences(file_text(server->log_file()), reuse_line), 1u)
        << server->label() << ":\n"
        << file_text(server->log_file());
  }
  expect_same_contact_state(second, fresh_run(directory.path(), "second-fresh", deeper), 1e-10);

  const std::vector<std::string> stiffer = {"--set", "body[2].material.young=3000"};
  const auto third = coordinator_run("third", stiffer);
  // The lower body is unchanged (its factor is reused again); the upper one is set up anew.
  EXPECT_EQ(occurrences(file_text(lower.log_file()), reuse_line), 2u);
  EXPECT_EQ(occurrences(file_text(upper.log_file()), reuse_line), 1u);
  expect_same_contact_state(third, fresh_run(directory.path(), "third-fresh", stiffer), 1e-10);
}

}  // namespace
}  // namespace robin
