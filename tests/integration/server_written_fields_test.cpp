// Who writes <body>.vtu (docs/outputs.md, "The life of a result directory"): robin-run's own
// local robin-subdomain servers write their bodies' files themselves (FieldsRequest.
// write_directory under the --output-root robin-run gives them, and since protocol 2.5
// omit_fields_from_reply); with --server-executable the coordinator writes them from full
// replies, as robin-coordinator does. Both runs are real robin-run processes with real servers.
//  - The files are the same bytes both ways. They must be: both are written by
//    write_body_output (numerics/body_output.hpp) from the same mesh and fields (the protocol
//    carries the doubles exactly, and the coordinator gives the stress back its component
//    names), and that writer is deterministic (zlib at a fixed level over the same bytes); the
//    iteration is the same computation on the same input both ways.
//  - contact.csv, solution.pvd and the numbers of summary.json are the same: the reply without
//    fields carries all the coordinator needs.
//  - The fields did not travel: each body's bytes received drop by at least the coordinates and
//    displacements of its nodes (4 doubles per node in 2D, the node count read from the file).
//  - With [loading] every step's files are the same both ways.
//  - Each server's peak resident set size in summary.json (protocol 2.5) is that server's VmHWM,
//    read from /proc/PID/status by this test while the server is still alive.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "remote_test_support.hpp"

namespace robin {
namespace {

using nlohmann::json;
using testing::example;
using testing::read_text;
using testing::run_tool;
using testing::TemporaryDirectory;

/// Runs robin-run on `case_file` into `output` (testing::run_robin_run) and expects success.
void run_robin_run(const std::filesystem::path& case_file, const std::filesystem::path& output,
                   bool coordinator_writes) {
  const auto outcome = testing::run_robin_run(case_file, output, coordinator_writes);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
}

/// The same bytes at `relative` in both result directories (and a file that is not empty).
void expect_same_file(const std::filesystem::path& servers,
                      const std::filesystem::path& coordinator,
                      const std::filesystem::path& relative) {
  ASSERT_TRUE(std::filesystem::is_regular_file(servers / relative)) << relative;
  ASSERT_TRUE(std::filesystem::is_regular_file(coordinator / relative)) << relative;
  const std::string written = read_text(servers / relative);
  EXPECT_GT(written.size(), 0u) << relative;
  EXPECT_TRUE(written == read_text(coordinator / relative))
      << relative << " differs between the server-written and coordinator-written runs";
}

/// The numbers of summary.json that come from the iteration and the fields replies.
json result_numbers(const json& summary) {
  json numbers = {{"status", summary["status"]},
                  {"iterations", summary["iterations"]},
                  {"final_residuals", summary["final_residuals"]},
                  {"contact_force_resultant", summary["contact_force_resultant"]},
                  {"excluded_pair_penetration", summary["excluded_pair_penetration"]},
                  {"interfaces", summary["interfaces"]}};
  for (const json& body : summary["bodies"]) {
    numbers["bodies"].push_back({{"name", body["name"]},
                                 {"dofs", body["dofs"]},
                                 {"reaction_resultant", body["reaction_resultant"]},
                                 {"applied_force", body["applied_force"]}});
  }
  if (summary.contains("load_steps")) {
    for (json step : summary["load_steps"]) {
      step.erase("seconds");
      numbers["load_steps"].push_back(step);
    }
  }
  return numbers;
}

TEST(ServerWrittenFields, SameFilesAndNumbersAsWhenTheCoordinatorWritesThem) {
  const TemporaryDirectory directory("server-written");
  const std::filesystem::path servers = directory.path() / "servers";
  const std::filesystem::path coordinator = directory.path() / "coordinator";
  run_robin_run(example("two_blocks_partial.toml"), servers, false);
  run_robin_run(example("two_blocks_partial.toml"), coordinator, true);
  for (const char* file : {"lower.vtu", "upper.vtu", "solution.pvd", "contact.csv"}) {
    expect_same_file(servers, coordinator, file);
  }
  const json written = testing::read_summary(servers);
  const json sent = testing::read_summary(coordinator);
  EXPECT_EQ(result_numbers(written), result_numbers(sent));
  EXPECT_EQ(written["files"], sent["files"]);
  for (std::size_t body = 0; body < 2; ++body) {
    const std::string name = written["bodies"][body]["name"];
    const long saved = sent["bodies"][body]["bytes_received"].get<long>() -
                       written["bodies"][body]["bytes_received"].get<long>();
    const long nodes = testing::vtu_point_count(servers / (name + ".vtu"));
    ASSERT_GT(nodes, 0) << name;
    EXPECT_GE(saved, 4 * 8 * nodes) << name << ": the fields came back anyway";
  }
  for (const auto& entry : std::filesystem::directory_iterator(servers)) {
    EXPECT_NE(entry.path().filename().string().rfind(".staging-", 0), 0u) << entry.path();
  }
}

TEST(ServerWrittenFields, EveryLoadStepsFilesAreTheSame) {
  const TemporaryDirectory directory("server-written-steps");
  const std::filesystem::path servers = directory.path() / "servers";
  const std::filesystem::path coordinator = directory.path() / "coordinator";
  run_robin_run(example("hertz_steps.toml"), servers, false);
  run_robin_run(example("hertz_steps.toml"), coordinator, true);
  const json summary = testing::read_summary(servers);
  ASSERT_EQ(summary["load_steps"].size(), 4u) << summary.dump(1);
  EXPECT_EQ(result_numbers(summary), result_numbers(testing::read_summary(coordinator)));
  expect_same_file(servers, coordinator, "solution.pvd");
  for (int step = 1; step <= 4; ++step) {
    const std::filesystem::path step_directory = "steps/step_00" + std::to_string(step);
    for (const json& body : summary["bodies"]) {
      expect_same_file(servers, coordinator,
                       step_directory / (body["name"].get<std::string>() + ".vtu"));
    }
    expect_same_file(servers, coordinator, step_directory / "contact.csv");
  }
}

/// VmHWM of process `pid` in bytes, from /proc/PID/status (kB = 1024 bytes); 0 when unreadable.
std::uint64_t high_water_mark(pid_t pid) {
  std::smatch match;
  const std::string status = read_text("/proc/" + std::to_string(pid) + "/status");
  if (!std::regex_search(status, match, std::regex("VmHWM:\\s+([0-9]+) kB"))) return 0;
  return std::stoull(match[1].str()) * 1024;
}

TEST(ServerPeakMemory, SummaryReportsEachServersHighWaterMark) {
  const TemporaryDirectory directory("server-peak");
  SubdomainServer lower("lower", testing::server_options(directory.path() / "server-logs"));
  SubdomainServer upper("upper", testing::server_options(directory.path() / "server-logs"));
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
  const json bodies = testing::read_summary(output)["profile"]["bodies"];
  ASSERT_EQ(bodies.size(), 2u);
  // FieldsRequest was each server's last long request: what it reported then is its peak up to
  // its reply, which only the reply's serialization (a small share of a server's memory) and
  // EndRun may have raised since.
  const std::vector<pid_t> pids = {lower.pid(), upper.pid()};
  for (std::size_t body = 0; body < 2; ++body) {
    const std::uint64_t measured = high_water_mark(pids[body]);
    ASSERT_GT(measured, 0u) << "no VmHWM for " << pids[body];
    ASSERT_TRUE(bodies[body]["peak_resident_bytes"].is_number_unsigned()) << bodies[body].dump();
    const auto reported = bodies[body]["peak_resident_bytes"].get<std::uint64_t>();
    EXPECT_LE(reported, measured) << bodies[body]["name"];
    EXPECT_GE(static_cast<double>(reported), 0.9 * static_cast<double>(measured))
        << bodies[body]["name"];
  }
}

}  // namespace
}  // namespace robin
