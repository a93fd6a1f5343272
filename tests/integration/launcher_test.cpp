// The executables end to end:
//  - robin-run on examples/two_blocks.toml exits 0, writes a summary.json that says converged
//    with the contact resultant equal to the in-process run's, and leaves no robin-subdomain
//    behind: this test makes itself a child subreaper, so a server the launcher failed to reap
//    would become this process's child (found in /proc), and the servers' ports are closed;
//  - robin-coordinator with one --subdomain option, or three for a case of two bodies, exits 2
//    with a clear message;
//  - robin-run stopped by SIGINT / SIGTERM during the body setup exits 130 / 143 within a
//    deadline and its servers are gone (reaped by it, not orphaned);
//  - robin-run whose second server exits before listening, or announces an endpoint and then
//    exits, exits 1 naming that server, and stops the first one;
//  - a contact QP tolerance far looser than the coupling tolerance makes robin-run stop with
//    exit 5 and "stagnated", still writing its result files;
//  - command-line options override the case file's [coupling] table (seen in summary.json),
//    and --timeout 0 is rejected with exit 2;
//  - robin-run's local servers get an equal share of the processors as their BLAS and OpenMP
//    thread counts, unless robin-run's environment sets them; --threads-per-server wins.
// The tests that must not hang run robin-run with a real deadline (run_robin_run).

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>

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

/// The processes whose parent is `parent` and whose command name is `name` (any name: empty).
std::vector<int> child_processes(pid_t parent, const std::string& name = "") {
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
    int parent_pid = 0;
    rest >> state >> parent_pid;
    if (parent_pid == static_cast<int>(parent) &&
        (name.empty() || line.substr(open + 1, close - open - 1) == name.substr(0, 15))) {
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
  const Eigen::VectorXd mean = 0.5 * (result.iteration.state.bodies[0].contact_force +
                                      result.iteration.state.bodies[1].contact_force);
  return contact_resultant(result.pairing(), mean).y();
}

TEST(RobinRun, SolvesTwoBlocksAndLeavesNoServerBehind) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory output("robin-run");
  // the results in a subdirectory: robin-run refuses a non-empty one (robin-run.stderr)
  const ProcessOutcome outcome =
      run_tool("robin-run",
               {example("two_blocks.toml").string(), "--output", (output.path() / "out").string()},
               output.path(), 120.0);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;

  std::ifstream summary_file(output.path() / "out" / "summary.json");
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
  EXPECT_TRUE(child_processes(getpid(), "robin-subdomain").empty())
      << "orphaned servers were reparented here";
  EXPECT_TRUE(std::filesystem::exists(output.path() / "out" / "logs" / "server-lower.log"));
  EXPECT_TRUE(std::filesystem::exists(output.path() / "out" / "logs" / "server-upper.log"));
}

TEST(RobinCoordinator, RequiresOneSubdomainPerBody) {
  const TemporaryDirectory output("robin-coordinator-arguments");
  const std::string case_file = example("two_blocks.toml").string();
  for (const std::vector<std::string>& endpoints :
       {std::vector<std::string>{"tcp://127.0.0.1:5555"},
        std::vector<std::string>{"tcp://127.0.0.1:5555", "tcp://127.0.0.1:5556",
                                 "tcp://127.0.0.1:5557"}}) {
    std::vector<std::string> arguments{case_file, "--output", (output.path() / "out").string()};
    for (const std::string& endpoint : endpoints) {
      arguments.insert(arguments.end(), {"--subdomain", endpoint});
    }
    const ProcessOutcome outcome = run_tool("robin-coordinator", arguments, output.path(), 30.0);
    EXPECT_EQ(outcome.exit, "exited with status 2") << outcome.errors;
    const std::string expected = endpoints.size() == 1
                                     ? "give one --subdomain ENDPOINT option per body, at least two"
                                     : "has 2 bodies: give one --subdomain ENDPOINT per body";
    EXPECT_NE(outcome.errors.find(expected), std::string::npos) << outcome.errors;
    EXPECT_NE(outcome.errors.find("got " + std::to_string(endpoints.size())), std::string::npos)
        << outcome.errors;
  }
}

// ---- Helpers of the tests below -----------------------------------------------------------

std::string read_text(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// Polls `condition` every 20 ms until it holds (true) or `seconds` have passed (false).
bool wait_until(const std::function<bool()>& condition, double seconds) {
  const auto start = std::chrono::steady_clock::now();
  while (!condition()) {
    if (testing::seconds_since(start) > seconds) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

/// True when no process `pid` exists, not even as a zombie (kill fails with ESRCH).
bool process_gone(int pid) {
  return kill(pid, 0) == -1 && errno == ESRCH;
}

/// Makes this process the child subreaper of its descendants, so that a server that robin-run
/// failed to reap is reparented here (orphans()) instead of to init, where it would vanish
/// unseen. The destructor kills and reaps whatever is left, so a failing test leaves nothing
/// running; declare it before the ChildProcess of robin-run (destroyed after it).
class OrphanCatcher {
 public:
  OrphanCatcher() { EXPECT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0); }
  ~OrphanCatcher() {
    for (const int pid : orphans()) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
  OrphanCatcher(const OrphanCatcher&) = delete;
  OrphanCatcher& operator=(const OrphanCatcher&) = delete;
  /// This process's children (robin-run itself must have been reaped).
  std::vector<int> orphans() const { return child_processes(getpid()); }
};

/// Writes examples/`name` into `directory` with its mesh paths made absolute (they are
/// relative to the case file), and every occurrence of each `from` replaced by its `to` (each
/// must occur); returns the new file's path.
std::filesystem::path write_case_variant(
    const std::filesystem::path& directory, const std::string& name,
    const std::vector<std::pair<std::string, std::string>>& replacements) {
  const std::string meshes = example("meshes").string() + "/";
  std::string text = std::regex_replace(read_text(example(name)), std::regex("meshes/"), meshes);
  for (const auto& [from, to] : replacements) {
    EXPECT_NE(text.find(from), std::string::npos) << "'" << from << "' is not in " << name;
    for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
  }
  const std::filesystem::path path = directory / name;
  std::ofstream(path) << text;
  return path;
}

/// Writes an executable /bin/sh script `name` with body `text` into `directory`.
std::filesystem::path write_script(const std::filesystem::path& directory, const std::string& name,
                                   const std::string& text) {
  const std::filesystem::path path = directory / name;
  std::ofstream(path) << "#!/bin/sh\n" << text;
  std::filesystem::permissions(path, std::filesystem::perms(0755));
  return path;
}

nlohmann::json read_summary(const std::filesystem::path& directory) {
  std::ifstream file(directory / "summary.json");
  EXPECT_TRUE(file.good()) << "no summary.json in " << directory;
  return file.good() ? nlohmann::json::parse(file) : nlohmann::json::object();
}

/// Runs build/bin/robin-run `arguments` (with `environment` added to this process's) and kills it
/// unless it exits within `timeout_seconds` (run_tool's deadline only starts once the tool has
/// closed its standard output), a failure. Prints the exit and the measured time.
ProcessOutcome run_robin_run(
    const std::vector<std::string>& arguments, const std::filesystem::path& directory,
    double timeout_seconds,
    const std::vector<std::pair<std::string, std::string>>& environment = {}) {
  ChildProcessOptions options;
  options.executable = testing::tool("robin-run");
  options.arguments = arguments;
  options.environment = environment;
  options.log_file = directory / "robin-run.stderr";
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + std::chrono::duration_cast<ChildProcess::Clock::duration>(
                                    std::chrono::duration<double>(timeout_seconds));
  ChildProcess process(options);
  ProcessOutcome outcome;
  try {
    while (const auto line = process.read_line(deadline)) outcome.output += *line + "\n";
  } catch (const ChildTimeout&) {
  }
  EXPECT_TRUE(process.wait_for_exit(std::max(0.0, timeout_seconds - testing::seconds_since(start))))
      << "robin-run did not exit within " << timeout_seconds << " s";
  outcome.exit = process.exit_description();
  outcome.errors = read_text(options.log_file);
  std::cout << "robin-run " << outcome.exit << " after " << testing::seconds_since(start) << " s\n";
  return outcome;
}

// ---- Stopping robin-run by a signal -------------------------------------------------------

/// Starts `options` with TMPDIR set to `temporary` in its environment (restored here after the
/// start): a server killed while meshing cannot remove its temporary mesh file, which then
/// stays in the test's directory instead of /tmp.
std::unique_ptr<ChildProcess> start_with_temporary_directory(
    const ChildProcessOptions& options, const std::filesystem::path& temporary) {
  const char* previous = std::getenv("TMPDIR");
  const std::optional<std::string> saved =
      previous ? std::optional<std::string>(previous) : std::nullopt;
  setenv("TMPDIR", temporary.c_str(), 1);
  auto process = std::make_unique<ChildProcess>(options);  // has executed: its copy is made
  if (saved) {
    setenv("TMPDIR", saved->c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  return process;
}

/// Waits (at most 120 s) until robin-run logged that the body setup began, then returns the
/// pids of its robin-subdomain children; empty when it ended before.
std::vector<int> servers_once_setting_up(ChildProcess& run, const std::filesystem::path& log) {
  const bool setting_up = wait_until(
      [&] { return read_text(log).find("setting up body") != std::string::npos || !run.running(); },
      120.0);
  if (!setting_up || !run.running()) return {};
  return child_processes(run.pid(), "robin-subdomain");
}

/// Starts robin-run on Hertz with a mesh fine enough (h = 0.02 instead of 0.1) that the body
/// setup lasts seconds, sends `signal_number` once the setup has begun, and checks the exit
/// status 128 + signal within a "does not hang" deadline, and that the two servers it started
/// are gone: reaped by robin-run (with this process the subreaper, an unreaped server would
/// remain visible here as an orphan or zombie).
void expect_signal_stops_run(int signal_number) {
  OrphanCatcher catcher;
  const TemporaryDirectory directory("robin-run-signal");
  ChildProcessOptions options;
  options.executable = testing::tool("robin-run");
  options.arguments = {
      write_case_variant(directory.path(), "hertz.toml", {{"mesh_size = 0.1", "mesh_size = 0.02"}})
          .string(),
      "--output", (directory.path() / "out").string()};
  options.log_file = directory.path() / "robin-run.stderr";
  const std::unique_ptr<ChildProcess> process =
      start_with_temporary_directory(options, directory.path());
  ChildProcess& run = *process;
  const std::vector<int> servers = servers_once_setting_up(run, options.log_file);
  ASSERT_EQ(servers.size(), 2u) << run.exit_description() << "\n" << read_text(options.log_file);
  ASSERT_EQ(kill(run.pid(), signal_number), 0);
  const auto signalled = std::chrono::steady_clock::now();
  ASSERT_TRUE(run.wait_for_exit(30.0)) << "robin-run still runs 30 s after the signal";
  std::cout << "robin-run " << run.exit_description() << " " << testing::seconds_since(signalled)
            << " s after signal " << signal_number << "\n";
  EXPECT_EQ(run.exit_description(), "exited with status " + std::to_string(128 + signal_number))
      << read_text(options.log_file);
  for (const int pid : servers) {
    EXPECT_TRUE(wait_until([pid] { return process_gone(pid); }, 5.0)) << "server " << pid;
  }
  EXPECT_TRUE(catcher.orphans().empty()) << "robin-run left processes behind";
}

TEST(RobinRunSignals, SigintDuringSetupExits130AndStopsServers) {
  expect_signal_stops_run(SIGINT);
}

TEST(RobinRunSignals, SigtermDuringSetupExits143AndStopsServers) {
  expect_signal_stops_run(SIGTERM);
}

// ---- A failing server ---------------------------------------------------------------------

/// robin-run on two_blocks with body 1 on the real robin-subdomain and body 2 ('upper') on a
/// script `name` running `script`; checks exit 1 within 60 s, that the error names the script
/// as body 'upper''s server and contains `reason`, that every server pid robin-run logged is
/// gone and that nothing was orphaned. Returns robin-run's standard error.
std::string expect_failing_upper_server(const std::string& name, const std::string& script,
                                        const std::string& reason) {
  OrphanCatcher catcher;
  const TemporaryDirectory directory("robin-run-failing-server");
  const std::filesystem::path failing = write_script(directory.path(), name, script);
  const ProcessOutcome outcome = run_robin_run(
      {example("two_blocks.toml").string(), "--output", (directory.path() / "out").string(),
       "--server-executable", testing::tool("robin-subdomain").string(), "--server-executable",
       failing.string(), "--max-server-restarts", "0"},  // the failure itself, not restarts
      directory.path(), 60.0);
  EXPECT_EQ(outcome.exit, "exited with status 1") << outcome.errors;
  EXPECT_NE(outcome.errors.find(name + " for body 'upper' (pid "), std::string::npos)
      << outcome.errors;
  EXPECT_NE(outcome.errors.find(reason), std::string::npos) << outcome.errors;
  for (const auto& [pid, endpoint] : listening_servers(outcome.errors)) {
    EXPECT_TRUE(wait_until([&] { return process_gone(std::stoi(pid)); }, 5.0)) << "pid " << pid;
  }
  EXPECT_TRUE(catcher.orphans().empty()) << "robin-run left processes behind";
  return outcome.errors;
}

TEST(RobinRunFailingServer, ServerExitingBeforeListeningIsNamed) {
  expect_failing_upper_server("failing-server", "exit 3\n",
                              "stopped before listening (it exited with status 3)");
}

TEST(RobinRunFailingServer, ServerExitingAfterListeningIsNamed) {
  // It announces an ipc endpoint nobody binds, then exits: the coordinator's first request
  // cannot be answered, and the launcher must report the exit instead of waiting.
  const TemporaryDirectory unused("robin-run-no-endpoint");
  const std::string errors = expect_failing_upper_server(
      "lying-server", "echo 'listening on ipc://" + (unused.path() / "nobody").string() + "'\n",
      "exited with status 0");
  // Both servers were announced (the real one for 'lower' too), so both were checked gone.
  EXPECT_EQ(listening_servers(errors).size(), 2u) << errors;
}

// ---- Exit codes of the iteration, and the command line ------------------------------------

TEST(RobinRunExit, StagnationExits5AndWritesResults) {
  // The contact QPs stop at relative accuracy 1e-6, so the residuals level off far above the
  // tolerance 1e-15 (and far below the 0.1 that would mean divergence): within a window of 5
  // iterations they stop decreasing by 1% -- measured: 16 iterations, largest residual 2.6e-6.
  const TemporaryDirectory directory("robin-run-stagnation");
  const std::filesystem::path output = directory.path() / "out";
  const std::filesystem::path case_file = write_case_variant(
      directory.path(), "two_blocks.toml",
      {{"[coupling]", "[solver]\nqp_tolerance = 1e-6\n\n[coupling]\nstagnation_window = 5"}});
  const ProcessOutcome outcome =
      run_robin_run({case_file.string(), "--output", output.string(), "--tolerance", "1e-15"},
                    directory.path(), 120.0);
  EXPECT_EQ(outcome.exit, "exited with status 5") << outcome.errors;
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "stagnated");
  EXPECT_EQ(summary.value("converged", true), false);
  const int iterations = summary.value("iterations", 0);
  EXPECT_GT(iterations, 5);    // a full window after the first iteration
  EXPECT_LT(iterations, 100);  // the case's max_iterations was not what stopped it
  EXPECT_NE(summary.value("message", "").find("stagnated"), std::string::npos);
  for (const char* file :
       {"history.csv", "contact.csv", "solution.pvd", "lower.vtu", "upper.vtu"}) {
    EXPECT_TRUE(std::filesystem::exists(output / file)) << file;
  }
  // One history row per iteration below the header.
  std::ifstream history(output / "history.csv");
  EXPECT_EQ(std::count(std::istreambuf_iterator<char>(history), {}, '\n'), iterations + 1);
}

TEST(RobinRunCommandLine, OptionsOverrideTheCaseFile) {
  // The case says relaxation 0.25, and by default IQN-ILS, either-sequence stopping and at
  // most 100 iterations: every value in summary.json below comes from the command line.
  const TemporaryDirectory directory("robin-run-overrides");
  const std::filesystem::path output = directory.path() / "out";
  const std::filesystem::path case_file = write_case_variant(
      directory.path(), "two_blocks.toml", {{"relaxation = 0.5", "relaxation = 0.25"}});
  const ProcessOutcome outcome =
      run_robin_run({case_file.string(), "--output", output.string(), "--acceleration", "none",
                     "--relaxation", "0.5", "--stopping", "joint", "--max-iterations", "2"},
                    directory.path(), 120.0);
  EXPECT_EQ(outcome.exit, "exited with status 3") << outcome.errors;
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("acceleration", ""), "none");
  EXPECT_EQ(summary.value("stopping", ""), "joint");
  EXPECT_EQ(summary.value("relaxation", 0.0), 0.5);
  EXPECT_EQ(summary.value("status", ""), "iteration limit reached");
  EXPECT_EQ(summary.value("converged", true), false);
  EXPECT_EQ(summary.value("iterations", 0), 2);
}

TEST(RobinRunCommandLine, ZeroTimeoutIsRejected) {
  // A bad option value is a command-line error (exit 2) found before anything is written.
  const TemporaryDirectory directory("robin-run-timeout");
  const std::filesystem::path output = directory.path() / "out";
  const ProcessOutcome outcome = run_robin_run(
      {example("two_blocks.toml").string(), "--output", output.string(), "--timeout", "0"},
      directory.path(), 30.0);
  EXPECT_EQ(outcome.exit, "exited with status 2") << outcome.errors;
  EXPECT_NE(outcome.errors.find("--timeout"), std::string::npos) << outcome.errors;
  EXPECT_NE(outcome.errors.find("must be a finite number > 0"), std::string::npos)
      << outcome.errors;
  EXPECT_FALSE(std::filesystem::exists(output));
}

// ---- Threads of the servers -----------------------------------------------------------------

/// What each server of a robin-run on examples/two_blocks.toml had in its environment of
/// OPENBLAS_NUM_THREADS, OMP_NUM_THREADS and OMP_THREAD_LIMIT ("NAME=value" lines, sorted):
/// --server-executable is a script that writes those lines into a file of its own and then execs
/// robin-subdomain.
std::vector<std::string> server_thread_settings(
    const std::vector<std::string>& options,
    const std::vector<std::pair<std::string, std::string>>& environment) {
  const TemporaryDirectory directory("robin-run-threads");
  const std::filesystem::path script = write_script(
      directory.path(), "server.sh",
      "env | grep -E '^(OPENBLAS_NUM_THREADS|OMP_NUM_THREADS|OMP_THREAD_LIMIT)=' | sort > '" +
          directory.path().string() + "/environment-'$$\nexec '" +
          testing::tool("robin-subdomain").string() + "' \"$@\"\n");
  std::vector<std::string> arguments = {example("two_blocks.toml").string(), "--output",
                                        (directory.path() / "out").string(), "--server-executable",
                                        script.string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  const ProcessOutcome outcome = run_robin_run(arguments, directory.path(), 120.0, environment);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  std::vector<std::string> settings;
  for (const auto& entry : std::filesystem::directory_iterator(directory.path())) {
    if (entry.path().filename().string().rfind("environment-", 0) == 0) {
      settings.push_back(read_text(entry.path()));
    }
  }
  return settings;
}

/// `variable`'s value in this process's environment, or `otherwise` when it is not set.
std::string environment_value(const char* variable, const std::string& otherwise) {
  const char* value = std::getenv(variable);
  return value != nullptr ? value : otherwise;
}

TEST(RobinRunThreads, LocalServersShareTheProcessorsUnlessTheEnvironmentSetsThreads) {
  cpu_set_t set;
  CPU_ZERO(&set);
  ASSERT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  const std::string share = std::to_string(std::max(1, CPU_COUNT(&set) / 2));  // two servers
  // OPENBLAS_NUM_THREADS set for robin-run is passed on; OMP_NUM_THREADS and OMP_THREAD_LIMIT,
  // unless this test's own environment has them, are the share.
  const std::string expected =
      "OMP_NUM_THREADS=" + environment_value("OMP_NUM_THREADS", share) +
      "\nOMP_THREAD_LIMIT=" + environment_value("OMP_THREAD_LIMIT", share) +
      "\nOPENBLAS_NUM_THREADS=5\n";
  const std::vector<std::string> settings =
      server_thread_settings({}, {{"OPENBLAS_NUM_THREADS", "5"}});
  EXPECT_EQ(settings, std::vector<std::string>(2, expected));
}

TEST(RobinRunThreads, ThreadsPerServerOverridesTheEnvironment) {
  const std::vector<std::string> settings = server_thread_settings(
      {"--threads-per-server", "3"}, {{"OPENBLAS_NUM_THREADS", "5"}, {"OMP_NUM_THREADS", "7"}});
  EXPECT_EQ(settings, std::vector<std::string>(
                          2, "OMP_NUM_THREADS=3\nOMP_THREAD_LIMIT=3\nOPENBLAS_NUM_THREADS=3\n"));
}

}  // namespace
}  // namespace robin
