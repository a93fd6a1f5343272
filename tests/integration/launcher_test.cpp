// The executables end to end:
//  - robin-run on examples/two_blocks.toml exits 0, writes a summary.json that says converged
//    with the contact resultant equal to the in-process run's, and leaves no robin-subdomain
//    behind: this test makes itself a child subreaper, so a server the launcher failed to reap
//    would become this process's child (found in /proc), and the servers' ports are closed;
//  - robin-coordinator with one or three --subdomain options exits 2 with a clear message.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/prctl.h>
#include <sys/socket.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/result_files.hpp"
#include "remote/child_process.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::ProcessOutcome;
using testing::run_tool;
using testing::TemporaryDirectory;

/// The processes whose parent is this process and whose command name is `name`.
std::vector<int> children_named(const std::string& name) {
  std::vector<int> pids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string pid = entry.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    std::getline(stat, line);
    // pid (comm) state ppid ...
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    char state = 0;
    int parent = 0;
    rest >> state >> parent;
    if (parent == getpid() && line.substr(open + 1, close - open - 1) == name.substr(0, 15)) {
      pids.push_back(std::stoi(pid));
    }
  }
  return pids;
}

/// True when a TCP connection to tcp://HOST:PORT is refused (nothing listens there any more).
bool tcp_port_closed(const std::string& endpoint) {
  const std::string prefix = "tcp://";
  const auto colon = endpoint.rfind(':');
  if (endpoint.rfind(prefix, 0) != 0 || colon == std::string::npos) return false;
  const std::string host = endpoint.substr(prefix.size(), colon - prefix.size());
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(std::stoi(endpoint.substr(colon + 1))));
  if (inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) return false;
  const int socket_descriptor = socket(AF_INET, SOCK_STREAM, 0);
  const int result =
      connect(socket_descriptor, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  close(socket_descriptor);
  return result != 0;
}

/// (pid, endpoint) of every "... (pid N) listening on ENDPOINT" line of the launcher's log.
std::vector<std::pair<std::string, std::string>> listening_servers(const std::string& log) {
  std::vector<std::pair<std::string, std::string>> servers;
  std::istringstream lines(log);
  const std::string pid_marker = "(pid ", listening_marker = ") listening on ";
  for (std::string line; std::getline(lines, line);) {
    const auto listening = line.find(listening_marker);
    const auto pid = line.rfind(pid_marker, listening);
    if (listening == std::string::npos || pid == std::string::npos) continue;
    std::istringstream endpoint(line.substr(listening + listening_marker.size()));
    std::string word;
    endpoint >> word;
    servers.emplace_back(line.substr(pid + pid_marker.size(), listening - pid - pid_marker.size()),
                         word);
  }
  return servers;
}

double in_process_resultant_y() {
  const CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  InProcessPort body1, body2;
  const CoupledRunResult result =
      run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  const Eigen::VectorXd mean =
      0.5 * (result.iteration.contact_force1 + result.iteration.contact_force2);
  return contact_resultant(result.pairing, mean).y();
}

TEST(RobinRun, SolvesTwoBlocksAndLeavesNoServerBehind) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory output("robin-run");
  const ProcessOutcome outcome = run_tool(
      "robin-run", {example("two_blocks.toml").string(), "--output", output.path().string()},
      output.path(), 120.0);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;

  std::ifstream summary_file(output.path() / "summary.json");
  ASSERT_TRUE(summary_file.good()) << "no summary.json; " << outcome.errors;
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary.at("converged"), true);
  const double expected = in_process_resultant_y();
  EXPECT_NE(expected, 0.0);
  EXPECT_NEAR(summary.at("contact_force_resultant").at(1).get<double>(), expected,
              1e-12 * std::abs(expected));

  // The launcher logged "<server> (pid N) listening on ENDPOINT" for both servers.
  const auto servers = listening_servers(outcome.errors);
  for (const auto& [pid, endpoint] : servers) {
    EXPECT_FALSE(std::filesystem::exists("/proc/" + pid)) << "server pid " << pid << " remains";
    EXPECT_TRUE(tcp_port_closed(endpoint)) << endpoint << " still accepts connections";
  }
  EXPECT_EQ(servers.size(), 2u) << outcome.errors;
  EXPECT_TRUE(children_named("robin-subdomain").empty()) << "orphaned servers were reparented here";
  EXPECT_TRUE(std::filesystem::exists(output.path() / "logs" / "server-lower.log"));
  EXPECT_TRUE(std::filesystem::exists(output.path() / "logs" / "server-upper.log"));
}

TEST(RobinCoordinator, RequiresExactlyTwoSubdomains) {
  const TemporaryDirectory output("robin-coordinator-arguments");
  const std::string case_file = example("two_blocks.toml").string();
  for (const std::vector<std::string>& endpoints :
       {std::vector<std::string>{"tcp://127.0.0.1:5555"},
        std::vector<std::string>{"tcp://127.0.0.1:5555", "tcp://127.0.0.1:5556",
                                 "tcp://127.0.0.1:5557"}}) {
    std::vector<std::string> arguments{case_file, "--output", output.path().string()};
    for (const std::string& endpoint : endpoints) {
      arguments.insert(arguments.end(), {"--subdomain", endpoint});
    }
    const ProcessOutcome outcome = run_tool("robin-coordinator", arguments, output.path(), 30.0);
    EXPECT_EQ(outcome.exit, "exited with status 2") << outcome.errors;
    EXPECT_NE(outcome.errors.find("exactly two --subdomain"), std::string::npos) << outcome.errors;
    EXPECT_NE(outcome.errors.find("got " + std::to_string(endpoints.size())), std::string::npos)
        << outcome.errors;
  }
}

}  // namespace
}  // namespace robin
