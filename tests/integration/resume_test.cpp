// Checkpoint and resume, and the recovery from a lost server, through the real binaries
// (robin-run, robin-coordinator, robin-subdomain). The oracle of every test is an
// uninterrupted run of the same case computed in the same test:
//  - robin-run killed with SIGKILL mid-iteration, then `robin-run --resume DIR`: history.csv
//    (every column but the wall time) and contact.csv equal the uninterrupted run's (to 1e-12
//    relative), summary.json says "resumed_from" the checkpoint's iteration, and the checkpoint
//    files are gone; before that, a resume with a changed case file is refused naming the key
//    and both hashes, and one with a changed --tolerance naming the option;
//  - a robin-subdomain killed with SIGKILL during setup, during the iterations and during the
//    fields: robin-run restarts it (logging server, body, step and "restart 1 of 2"), and
//    contact.csv and history.csv equal the uninterrupted run's (1e-10 and 1e-12 relative);
//  - robin-coordinator against servers started by the test: one is killed mid-iteration and
//    started again at the same endpoint within --server-grace-period; the run carries on to
//    the same contact.csv;
//  - a server that is lost at every start is replaced --max-server-restarts times (2), then
//    the run fails naming the body and the limit.
// The case: examples/asymmetric.toml with `--stopping joint` (85 iterations of a few ms) and,
// for the setup and fields kills, finer meshes so that those stages last long enough to be hit.

#include <gtest/gtest.h>
#include <sys/prctl.h>
#include <sys/wait.h>

#include <csignal>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "remote/child_process.hpp"
#include "remote/server_launcher.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::TemporaryDirectory;

std::string read_text(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

bool wait_until(const std::function<bool()>& condition, double seconds) {
  const auto start = std::chrono::steady_clock::now();
  while (!condition()) {
    if (testing::seconds_since(start) > seconds) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

/// examples/`name` copied into `directory` with absolute mesh paths and the mesh size
/// `mesh_size` for both bodies.
std::filesystem::path case_copy(const std::filesystem::path& directory, double mesh_size,
                                const std::string& name = "asymmetric.toml") {
  std::string text = std::regex_replace(read_text(example(name)), std::regex("meshes/"),
                                        example("meshes").string() + "/");
  std::ostringstream size;
  size << "mesh_size = " << mesh_size;
  text = std::regex_replace(text, std::regex("mesh_size = 0\\.1"), size.str());
  const std::filesystem::path path = directory / name;
  std::ofstream(path) << text;
  return path;
}

/// A table of numbers read from a CSV file with a header row; `skipped` columns left out.
std::vector<std::vector<double>> csv_values(const std::filesystem::path& path,
                                            const std::string& skipped = "") {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  std::vector<bool> keep;
  std::istringstream header(line);
  for (std::string name; std::getline(header, name, ',');) keep.push_back(name != skipped);
  std::vector<std::vector<double>> rows;
  while (std::getline(file, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    std::size_t column = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++column) {
      if (column < keep.size() && keep[column]) row.push_back(cell.empty() ? 0.0 : std::stod(cell));
    }
    rows.push_back(row);
  }
  return rows;
}

/// Every value of `actual` within `relative` (of the largest magnitude of its column) of
/// `expected`, with the same shape; prints the largest relative difference.
void expect_same_table(const std::vector<std::vector<double>>& actual,
                       const std::vector<std::vector<double>>& expected, double relative,
                       const std::string& what) {
  ASSERT_EQ(actual.size(), expected.size()) << what << ": rows";
  ASSERT_FALSE(expected.empty()) << what;
  std::vector<double> scale(expected[0].size(), 1e-300);
  for (const auto& row : expected) {
    for (std::size_t k = 0; k < row.size() && k < scale.size(); ++k) {
      scale[k] = std::max(scale[k], std::abs(row[k]));
    }
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(actual[i].size(), expected[i].size()) << what << ": row " << i;
    for (std::size_t k = 0; k < expected[i].size(); ++k) {
      worst = std::max(worst, std::abs(actual[i][k] - expected[i][k]) / scale[k]);
    }
  }
  std::cout << what << ": largest relative difference " << worst << "\n";
  EXPECT_LE(worst, relative) << what;
}

nlohmann::json read_summary(const std::filesystem::path& directory) {
  std::ifstream file(directory / "summary.json");
  return file.good() ? nlohmann::json::parse(file, nullptr, false) : nlohmann::json::object();
}

/// A tool started in the background, its standard error in `log`.
std::unique_ptr<ChildProcess> start_tool(const std::string& tool,
                                         const std::vector<std::string>& arguments,
                                         const std::filesystem::path& log) {
  ChildProcessOptions options;
  options.executable = testing::tool(tool);
  options.arguments = arguments;
  options.log_file = log;
  return std::make_unique<ChildProcess>(options);
}

/// Runs a tool to its end (at most 120 s); returns its exit description.
std::string run_to_end(const std::string& tool, const std::vector<std::string>& arguments,
                       const std::filesystem::path& log) {
  const auto process = start_tool(tool, arguments, log);
  while (process->read_line(ChildProcess::Clock::now() + std::chrono::seconds(120))) {
  }
  EXPECT_TRUE(process->wait_for_exit(120.0)) << tool << " did not finish";
  return process->exit_description();
}

const std::vector<std::string> joint_stopping = {"--stopping", "joint"};

std::vector<std::string> with(std::vector<std::string> arguments,
                              const std::vector<std::string>& more) {
  arguments.insert(arguments.end(), more.begin(), more.end());
  return arguments;
}

/// The uninterrupted run of `case_file` into `directory`/reference; its result directory.
std::filesystem::path reference_run(const std::filesystem::path& directory,
                                    const std::filesystem::path& case_file) {
  const std::filesystem::path output = directory / "reference";
  const std::string exit = run_to_end(
      "robin-run", with({case_file.string(), "--output", output.string()}, joint_stopping),
      directory / "reference.stderr");
  EXPECT_EQ(exit, "exited with status 0") << read_text(directory / "reference.stderr");
  return output;
}

// ---- Checkpoint and resume ----------------------------------------------------------------

TEST(Resume, KilledCoordinatorResumesToTheSameHistoryAndAnswer) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-resume");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.05);
  const std::filesystem::path reference = reference_run(directory.path(), case_file);

  const std::filesystem::path output = directory.path() / "resumed";
  const std::filesystem::path first_log = directory.path() / "killed.stderr";
  const auto run = start_tool(
      "robin-run", with({case_file.string(), "--output", output.string()}, joint_stopping),
      first_log);
  ASSERT_TRUE(wait_until(
      [&] { return read_text(first_log).find("iteration 10:") != std::string::npos; }, 60.0))
      << read_text(first_log);
  ASSERT_EQ(kill(run->pid(), SIGKILL), 0);
  ASSERT_TRUE(run->wait_for_exit(10.0));
  ASSERT_EQ(run->exit_description(), "was killed by signal 9 (Killed)");
  // its servers die with it (parent-death signal); reap them here, the subreaper
  EXPECT_TRUE(wait_until([] { return waitpid(-1, nullptr, WNOHANG) == -1; }, 10.0));
  std::ifstream checkpoint_file(output / "checkpoint.json");
  const nlohmann::json checkpoint = nlohmann::json::parse(checkpoint_file, nullptr, false);
  ASSERT_TRUE(checkpoint.is_object()) << "no checkpoint.json";
  const int checkpointed = checkpoint["loop"]["iteration"].get<int>();
  std::cout << "killed after the checkpoint of iteration " << checkpointed << "\n";
  EXPECT_GE(checkpointed, 10);
  EXPECT_EQ(read_summary(output).value("status", ""), "running");

  // A changed case file is refused, naming the key and both hashes.
  const std::string original = read_text(case_file);
  std::ofstream(case_file) << std::regex_replace(original, std::regex("tolerance = 1e-8"),
                                                 "tolerance = 1e-7");
  const std::filesystem::path refused_log = directory.path() / "refused.stderr";
  EXPECT_EQ(run_to_end("robin-run", {"--resume", output.string()}, refused_log),
            "exited with status 1");
  const std::string refusal = read_text(refused_log);
  EXPECT_NE(refusal.find("coupling.tolerance: 1e-08 -> 1e-07"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find(checkpoint["case_sha256"].get<std::string>()), std::string::npos)
      << refusal;
  std::ofstream(case_file) << original;
  // A changed option is refused, naming it.
  EXPECT_EQ(
      run_to_end("robin-run", {"--resume", output.string(), "--tolerance", "1e-6"}, refused_log),
      "exited with status 1");
  EXPECT_NE(read_text(refused_log).find("--tolerance 1e-06 (the interrupted run did not give"),
            std::string::npos)
      << read_text(refused_log);

  const std::filesystem::path resume_log = directory.path() / "resume.stderr";
  EXPECT_EQ(run_to_end("robin-run", {"--resume", output.string()}, resume_log),
            "exited with status 0")
      << read_text(resume_log);
  EXPECT_NE(read_text(resume_log)
                .find("continuing the iteration after iteration " + std::to_string(checkpointed)),
            std::string::npos)
      << read_text(resume_log);
  expect_same_table(csv_values(output / "history.csv", "seconds"),
                    csv_values(reference / "history.csv", "seconds"), 1e-12, "history.csv");
  expect_same_table(csv_values(output / "contact.csv"), csv_values(reference / "contact.csv"),
                    1e-12, "contact.csv");
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "converged");
  EXPECT_EQ(summary["resumed_from"].value("iteration", 0), checkpointed);
  EXPECT_EQ(summary["resumed_from"].value("run_id", ""), checkpoint.value("run_id", "x"));
  EXPECT_FALSE(std::filesystem::exists(output / "checkpoint.json"));
  EXPECT_FALSE(std::filesystem::exists(output / "checkpoint-iterates.bin"));
}

// ---- Lost servers -------------------------------------------------------------------------

/// The pid of the robin-subdomain of body `body` from robin-run's log line
/// "robin-subdomain for body 'BODY' (pid N) listening on ..." (the first such line); 0 if none.
int server_pid(const std::string& log, const std::string& body) {
  const std::string marker = "robin-subdomain for body '" + body + "' (pid ";
  const auto at = log.find(marker);
  if (at == std::string::npos) return 0;
  return std::stoi(log.substr(at + marker.size()));
}

/// Runs robin-run on `case_file`, kills body `body`'s server with SIGKILL `delay` after the log
/// shows `moment`, and checks that the run recovers to the reference's answer. Returns the log.
std::string expect_recovery(const std::filesystem::path& directory,
                            const std::filesystem::path& case_file,
                            const std::filesystem::path& reference, const std::string& body,
                            const std::string& moment, const std::string& name,
                            std::chrono::milliseconds delay = std::chrono::milliseconds(0)) {
  const std::filesystem::path output = directory / name;
  const std::filesystem::path log = directory / (name + ".stderr");
  const auto run = start_tool(
      "robin-run", with({case_file.string(), "--output", output.string()}, joint_stopping), log);
  int pid = 0;
  EXPECT_TRUE(wait_until(
      [&] {
        const std::string text = read_text(log);
        pid = server_pid(text, body);
        return (pid != 0 && text.find(moment) != std::string::npos) || !run->running();
      },
      60.0));
  EXPECT_NE(pid, 0) << read_text(log);
  std::this_thread::sleep_for(delay);
  if (pid != 0) {
    EXPECT_EQ(kill(pid, SIGKILL), 0);
  }
  while (run->read_line(ChildProcess::Clock::now() + std::chrono::seconds(120))) {
  }
  EXPECT_TRUE(run->wait_for_exit(120.0));
  const std::string text = read_text(log);
  EXPECT_EQ(run->exit_description(), "exited with status 0") << text;
  EXPECT_NE(text.find("lost the server of body '" + body + "'"), std::string::npos) << text;
  EXPECT_NE(text.find("(restart 1 of 2)"), std::string::npos) << text;
  const auto lost = text.find("lost the server of body");
  if (lost != std::string::npos) {
    std::cout << name << ": " << text.substr(lost, text.find('\n', lost) - lost) << "\n";
  }
  expect_same_table(csv_values(output / "contact.csv"), csv_values(reference / "contact.csv"),
                    1e-10, name + " contact.csv");
  expect_same_table(csv_values(output / "history.csv", "seconds"),
                    csv_values(reference / "history.csv", "seconds"), 1e-12, name + " history.csv");
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "converged");
  EXPECT_EQ(summary["server_restarts"].size(), 1u) << summary.dump(2);
  return text;
}

TEST(ServerRecovery, RobinRunRestartsAServerKilledDuringTheIterations) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-iterations");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.05);
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  const std::string log = expect_recovery(directory.path(), case_file, reference, "block",
                                          "iteration 15:", "block-iterations");
  EXPECT_NE(log.find("continuing the iteration after iteration"), std::string::npos) << log;
  expect_recovery(directory.path(), case_file, reference, "cantilever",
                  "iteration 40:", "cantilever-iterations");
}

TEST(ServerRecovery, RobinRunRestartsAServerKilledDuringSetupAndFields) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-setup");
  // two_blocks on a finer mesh: a setup of about 0.1 s and fields of about 0.2 s
  const std::filesystem::path case_file = case_copy(directory.path(), 0.02, "two_blocks.toml");
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  // after the handshake, within the setup request
  const std::string setup =
      expect_recovery(directory.path(), case_file, reference, "upper", "setting up both bodies",
                      "upper-setup", std::chrono::milliseconds(40));
  EXPECT_NE(setup.find("step setup"), std::string::npos) << setup;
  const std::string fields =
      expect_recovery(directory.path(), case_file, reference, "lower",
                      "collecting the fields of both bodies", "lower-fields");
  EXPECT_NE(fields.find("step fields"), std::string::npos) << fields;
}

TEST(ServerRecovery, RobinCoordinatorWaitsForAServerToComeBack) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-remote");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.05);
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  // Two servers at fixed ipc endpoints, so that a restarted one is found at the same address.
  std::array<std::string, 2> endpoints;
  std::array<std::unique_ptr<SubdomainServer>, 2> servers;
  for (int index = 0; index < 2; ++index) {
    endpoints[index] = "ipc://" + (directory.path() / ("server" + std::to_string(index))).string();
    servers[index] = std::make_unique<SubdomainServer>(
        index == 0 ? "block" : "cantilever",
        testing::server_options(directory.path() / "logs", endpoints[index]));
    servers[index]->await_listening();
  }
  const std::filesystem::path output = directory.path() / "remote";
  const std::filesystem::path log = directory.path() / "remote.stderr";
  const auto run =
      start_tool("robin-coordinator",
                 with({case_file.string(), "--output", output.string(), "--subdomain", endpoints[0],
                       "--subdomain", endpoints[1], "--server-grace-period", "20"},
                      joint_stopping),
                 log);
  ASSERT_TRUE(wait_until(
      [&] { return read_text(log).find("iteration 20:") != std::string::npos || !run->running(); },
      60.0));
  ASSERT_EQ(kill(servers[1]->pid(), SIGKILL), 0);
  servers[1].reset();                                           // reaps it
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // down for a while
  servers[1] = std::make_unique<SubdomainServer>(
      "cantilever", testing::server_options(directory.path() / "logs", endpoints[1]));
  servers[1]->await_listening();
  while (run->read_line(ChildProcess::Clock::now() + std::chrono::seconds(120))) {
  }
  EXPECT_TRUE(run->wait_for_exit(120.0));
  const std::string text = read_text(log);
  EXPECT_EQ(run->exit_description(), "exited with status 0") << text;
  EXPECT_NE(text.find("lost the server of body 'cantilever'"), std::string::npos) << text;
  EXPECT_NE(text.find("(restart 1 of 2)"), std::string::npos) << text;
  expect_same_table(csv_values(output / "contact.csv"), csv_values(reference / "contact.csv"),
                    1e-10, "robin-coordinator contact.csv");
}

TEST(ServerRecovery, RestartsAreBounded) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-bounded");
  // A "server" that announces an endpoint nobody binds and exits: every start is lost at once.
  const std::filesystem::path lying = directory.path() / "lying-server";
  std::ofstream(lying) << "#!/bin/sh\necho 'listening on ipc://"
                       << (directory.path() / "nobody").string() << "'\n";
  std::filesystem::permissions(lying, std::filesystem::perms(0755));
  const std::filesystem::path log = directory.path() / "bounded.stderr";
  const std::string exit =
      run_to_end("robin-run",
                 {example("two_blocks.toml").string(), "--output",
                  (directory.path() / "out").string(), "--server-executable",
                  testing::tool("robin-subdomain").string(), "--server-executable", lying.string()},
                 log);
  const std::string text = read_text(log);
  EXPECT_EQ(exit, "exited with status 1") << text;
  EXPECT_NE(text.find("(restart 1 of 2)"), std::string::npos) << text;
  EXPECT_NE(text.find("(restart 2 of 2)"), std::string::npos) << text;
  EXPECT_NE(text.find("the server of body 'upper' was lost again after 2 restarts "
                      "(--max-server-restarts 2)"),
            std::string::npos)
      << text;
  EXPECT_EQ(read_summary(directory.path() / "out").value("status", ""), "failed");
}

}  // namespace
}  // namespace robin
