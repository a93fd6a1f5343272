// The stage-by-stage profile of summary.json ("profile", docs/outputs.md):
//  - robin-run: every documented key is there, every time finite and non-negative; each
//    body's server stages (mesh, assembly, ordering, factorization) sum to at most the server's
//    whole setup request, which with the transfer fits in the coordinator's setup stage; the
//    coordinator's stages, which run one after the other, sum to at most the wall time this
//    test measured around the robin-run process;
//  - robin-coordinator against a server playing protocol 2.1 (no stage times, no peak resident
//    size) and the Python server (protocol 2.5: no separate ordering, a peak resident size):
//    what was not reported is null, what was is a number;
//  - robin-monolithic writes the same keys, its bodies' server-only stages null, its bodies'
//    setups (one after the other) within its setup stage.
// No time is compared with a fixed threshold.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "remote_test_support.hpp"

namespace robin {
namespace {

using nlohmann::json;
using testing::example;
using testing::run_tool;
using testing::TemporaryDirectory;

const std::vector<std::string> coordinator_stages = {
    "launch",     "meshing", "setup", "contact_coupling", "contact_assignment",
    "iterations", "fields",  "output"};
const std::vector<std::string> body_stages = {"transfer",           "server_setup", "mesh",
                                              "assembly",           "ordering",     "factorization",
                                              "interface_operator", "fields"};
const std::vector<std::string> setup_stages = {"mesh", "assembly", "ordering", "factorization"};

json read_summary(const std::filesystem::path& directory) {
  std::ifstream file(directory / "summary.json");
  EXPECT_TRUE(file.good()) << directory;
  return file.good() ? json::parse(file) : json::object();
}

/// `object`[key] as seconds: present, a finite non-negative number.
double seconds_of(const json& object, const std::string& key) {
  if (!object.contains(key) || !object[key].is_number()) {
    ADD_FAILURE() << "'" << key << "' is not a number in " << object.dump();
    return 0.0;
  }
  const double seconds = object[key].get<double>();
  EXPECT_TRUE(std::isfinite(seconds) && seconds >= 0.0) << key << " = " << seconds;
  return seconds;
}

/// `object`[key] is present and null (not reported).
void expect_not_reported(const json& object, const std::string& key) {
  EXPECT_TRUE(object.contains(key) && object[key].is_null())
      << "'" << key << "' should be null in " << object.dump();
}

/// Whether `object`[key] is present and a positive integer (a size in bytes).
bool is_positive_byte_count(const json& object, const std::string& key) {
  return object.contains(key) && object.at(key).is_number_unsigned() &&
         object.at(key).get<std::uint64_t>() > 0;
}

/// Every coordinator stage is seconds; returns their sum.
double coordinator_sum(const json& profile) {
  double sum = 0.0;
  for (const std::string& key : coordinator_stages) sum += seconds_of(profile, key);
  return sum;
}

TEST(RunProfile, RobinRunReportsEveryStageWithinItsWallTime) {
  const TemporaryDirectory directory("profile-run");
  const std::filesystem::path output = directory.path() / "run";
  std::filesystem::create_directories(directory.path() / "logs");
  const auto start = std::chrono::steady_clock::now();
  const auto outcome = run_tool(
      "robin-run",
      {example("two_blocks_partial.toml").string(), "--output", output.string(), "--quiet"},
      directory.path() / "logs", 300.0);
  const double wall = testing::seconds_since(start);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  const json profile = read_summary(output)["profile"];
  ASSERT_TRUE(profile.is_object());
  const double sum = coordinator_sum(profile);
  EXPECT_LE(sum, wall) << profile.dump(1);
  EXPECT_GT(seconds_of(profile, "iterations"), 0.0);
  ASSERT_TRUE(profile["bodies"].is_array());
  ASSERT_EQ(profile["bodies"].size(), 2u);
  EXPECT_EQ(profile["bodies"][0]["name"], "lower");
  EXPECT_EQ(profile["bodies"][1]["name"], "upper");
  double fields = 0.0;
  for (const json& body : profile["bodies"]) {
    for (const std::string& key : body_stages) seconds_of(body, key);
    double setup = 0.0;
    for (const std::string& key : setup_stages) setup += seconds_of(body, key);
    const double server_setup = seconds_of(body, "server_setup");
    EXPECT_LE(setup, server_setup) << body.dump(1);
    EXPECT_LE(server_setup + seconds_of(body, "transfer"), seconds_of(profile, "setup"))
        << body.dump(1);
    EXPECT_LE(seconds_of(body, "interface_operator"), seconds_of(profile, "contact_assignment"));
    fields = std::max(fields, seconds_of(body, "fields"));
  }
  EXPECT_LE(fields, seconds_of(profile, "fields"));
}

TEST(RunProfile, WhatAServerDidNotReportIsNull) {
  const TemporaryDirectory directory("profile-old-servers");
  ServerLaunchOptions old_options = testing::server_options(directory.path() / "server-logs");
  old_options.extra_arguments = {"--protocol-minor", "1"};
  SubdomainServer lower("lower", old_options);
  SubdomainServer upper("upper", testing::python_server_options(directory.path() / "server-logs"));
  lower.await_listening();
  upper.await_listening();
  const std::filesystem::path output = directory.path() / "run";
  std::filesystem::create_directories(directory.path() / "logs");
  const auto outcome =
      run_tool("robin-coordinator",
               {example("two_blocks_partial.toml").string(), "--subdomain", lower.endpoint(),
                "--subdomain", upper.endpoint(), "--output", output.string(), "--quiet"},
               directory.path() / "logs", 300.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  const json profile = read_summary(output)["profile"];
  coordinator_sum(profile);
  ASSERT_EQ(profile["bodies"].size(), 2u);
  const json& old = profile["bodies"][0];
  for (const std::string& key : body_stages) expect_not_reported(old, key);
  expect_not_reported(old, "peak_resident_bytes");  // protocol 2.5
  const json& python = profile["bodies"][1];
  expect_not_reported(python, "ordering");  // SuperLU orders and factorizes in one call
  EXPECT_TRUE(is_positive_byte_count(python, "peak_resident_bytes"))  // protocol 2.5: VmHWM
      << python.dump();
  double setup = 0.0;
  for (const char* key : {"mesh", "assembly", "factorization"}) {
    setup += seconds_of(python, key);
  }
  EXPECT_LE(setup, seconds_of(python, "server_setup"));
  for (const char* key : {"transfer", "interface_operator", "fields"}) {
    seconds_of(python, key);
  }
}

TEST(RunProfile, RobinMonolithicWritesTheSameKeys) {
  const TemporaryDirectory directory("profile-monolithic");
  const std::filesystem::path output = directory.path() / "run";
  std::filesystem::create_directories(directory.path() / "logs");
  const auto start = std::chrono::steady_clock::now();
  const auto outcome = run_tool(
      "robin-monolithic",
      {example("two_blocks_partial.toml").string(), "--output", output.string(), "--quiet"},
      directory.path() / "logs", 300.0);
  const double wall = testing::seconds_since(start);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  json profile = read_summary(output)["profile"];
  ASSERT_TRUE(profile.is_object());
  expect_not_reported(profile, "fields");  // computed while writing the output
  profile["fields"] = 0.0;
  EXPECT_LE(coordinator_sum(profile), wall) << profile.dump(1);
  ASSERT_EQ(profile["bodies"].size(), 2u);
  double setups = 0.0;
  for (const json& body : profile["bodies"]) {
    for (const char* key : {"mesh", "transfer", "fields", "peak_resident_bytes"}) {
      expect_not_reported(body, key);
    }
    double stages = 0.0;
    for (const char* key : {"assembly", "ordering", "factorization"}) {
      stages += seconds_of(body, key);
    }
    EXPECT_NEAR(stages, seconds_of(body, "server_setup"), 1e-12 * stages);
    EXPECT_LE(seconds_of(body, "interface_operator"), seconds_of(profile, "contact_assignment"));
    setups += stages;
  }
  EXPECT_LE(setups, seconds_of(profile, "setup"));  // the bodies one after the other
}

}  // namespace
}  // namespace robin
