// Checkpoint and resume, and the recovery from a lost server, through the real binaries
// (robin-run, robin-coordinator, robin-subdomain). The oracle of every test is an
// uninterrupted run of the same case computed in the same test:
//  - robin-run killed with SIGKILL mid-iteration, then `robin-run --resume DIR`: history.csv
//    (every column but the wall time) and contact.csv equal the uninterrupted run's (to 1e-12
//    relative), summary.json says "resumed_from" the checkpoint's iteration, and the checkpoint
//    files are gone; before that, a resume with a changed case file is refused naming the key
//    and both hashes, and one with a changed --tolerance naming the option;
//  - a robin-subdomain killed with SIGKILL during setup, during the iterations, during a
//    correction solve (made long enough to be hit by robin-subdomain's testing-only
//    --testing-stage-delay) and during the fields: robin-run restarts it (logging server, body,
//    step and "restart 1 of 2"), and contact.csv and history.csv equal the uninterrupted run's
//    (1e-10 and 1e-12 relative);
//  - robin-coordinator killed with SIGKILL mid-iteration against two long-running servers,
//    then `robin-coordinator --resume DIR` against the same servers: history.csv (but the wall
//    time) and contact.csv equal those of an uninterrupted robin-coordinator run against the
//    same servers (1e-12 relative);
//  - robin-coordinator against servers started by the test: one is killed mid-iteration and
//    started again at the same endpoint within --server-grace-period; the run carries on to
//    the same contact.csv;
//  - a server that is lost at every start is replaced --max-server-restarts times (2), then
//    the run fails naming the body and the limit;
//  - examples/hertz_steps.toml ([loading], four steps, coarser mesh): robin-run killed with
//    SIGKILL in step 2 and resumed, and a robin-subdomain killed in step 2 (robin-run restarts
//    it): steps.csv, history.csv (but the wall times), every step's contact.csv and
//    summary.json's load_steps equal the uninterrupted run's (1e-12 relative, iteration counts
//    exactly), after the contact solves of step 1 were repeated.
// The case: examples/asymmetric.toml with `--stopping joint` (85 iterations of a few ms) and,
// for the setup and fields kills, finer meshes so that those stages last long enough to be hit.

#include <gtest/gtest.h>
#include <sys/prctl.h>
#include <sys/wait.h>

#include <cmath>
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

using testing::case_copy;
using testing::csv_values;
using testing::example;
using testing::expect_same_table;
using testing::read_summary;
using testing::read_text;
using testing::run_to_end;
using testing::start_tool;
using testing::TemporaryDirectory;
using testing::wait_until;

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

/// The checkpoint.json of result directory `output` (an empty object while there is none: the
/// coordinator writes it on a thread of its own, after the iteration it records is logged).
nlohmann::json checkpoint_on_disk(const std::filesystem::path& output) {
  std::ifstream file(output / "checkpoint.json");
  const nlohmann::json checkpoint = nlohmann::json::parse(file, nullptr, false);
  return checkpoint.is_object() ? checkpoint : nlohmann::json::object();
}

/// Whether the checkpoint on disk in `output` records iteration `iteration` or a later one (of
/// load step `step` when it is not 0).
bool checkpointed_iteration(const std::filesystem::path& output, int iteration, int step = 0) {
  const nlohmann::json checkpoint = checkpoint_on_disk(output);
  if (!checkpoint.contains("loop")) return false;
  if (step != 0 && checkpoint.value("step", 0) != step) return false;
  return checkpoint["loop"].value("iteration", 0) >= iteration;
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
  ASSERT_TRUE(wait_until([&] { return checkpointed_iteration(output, 10); }, 60.0))
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

TEST(Resume, KilledRobinCoordinatorResumesAgainstTheSameServers) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-coordinator-resume");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.05);
  // Two long-running servers, used by every run of this test.
  std::array<std::unique_ptr<SubdomainServer>, 2> servers;
  std::vector<std::string> endpoints;
  for (int index = 0; index < 2; ++index) {
    servers[index] = std::make_unique<SubdomainServer>(
        index == 0 ? "block" : "cantilever", testing::server_options(directory.path() / "logs"));
    servers[index]->await_listening();
    endpoints.insert(endpoints.end(), {"--subdomain", servers[index]->endpoint()});
  }
  const auto coordinator_arguments = [&](const std::filesystem::path& output) {
    return with(with({case_file.string(), "--output", output.string()}, endpoints), joint_stopping);
  };
  // The oracle: the uninterrupted run against the same servers.
  const std::filesystem::path reference = directory.path() / "reference";
  EXPECT_EQ(run_to_end("robin-coordinator", coordinator_arguments(reference),
                       directory.path() / "reference.stderr"),
            "exited with status 0")
      << read_text(directory.path() / "reference.stderr");

  const std::filesystem::path output = directory.path() / "resumed";
  const std::filesystem::path killed_log = directory.path() / "killed.stderr";
  const auto run = start_tool("robin-coordinator", coordinator_arguments(output), killed_log);
  ASSERT_TRUE(wait_until([&] { return checkpointed_iteration(output, 10); }, 60.0))
      << read_text(killed_log);
  ASSERT_EQ(kill(run->pid(), SIGKILL), 0);
  ASSERT_TRUE(run->wait_for_exit(10.0));
  ASSERT_EQ(run->exit_description(), "was killed by signal 9 (Killed)");
  EXPECT_EQ(read_summary(output).value("status", ""), "running");
  std::ifstream checkpoint_file(output / "checkpoint.json");
  const nlohmann::json checkpoint = nlohmann::json::parse(checkpoint_file, nullptr, false);
  ASSERT_TRUE(checkpoint.is_object()) << "no checkpoint.json";
  const int checkpointed = checkpoint["loop"]["iteration"].get<int>();
  std::cout << "robin-coordinator killed after the checkpoint of iteration " << checkpointed
            << "\n";
  EXPECT_GE(checkpointed, 10);

  const std::filesystem::path resume_log = directory.path() / "resume.stderr";
  EXPECT_EQ(
      run_to_end("robin-coordinator", with({"--resume", output.string()}, endpoints), resume_log),
      "exited with status 0")
      << read_text(resume_log);
  EXPECT_NE(read_text(resume_log)
                .find("continuing the iteration after iteration " + std::to_string(checkpointed)),
            std::string::npos)
      << read_text(resume_log);
  expect_same_table(csv_values(output / "history.csv", "seconds"),
                    csv_values(reference / "history.csv", "seconds"), 1e-12,
                    "robin-coordinator history.csv");
  expect_same_table(csv_values(output / "contact.csv"), csv_values(reference / "contact.csv"),
                    1e-12, "robin-coordinator contact.csv");
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "converged");
  EXPECT_EQ(summary.value("tool", ""), "robin-coordinator");
  EXPECT_EQ(summary["resumed_from"].value("iteration", 0), checkpointed);
  EXPECT_FALSE(std::filesystem::exists(output / "checkpoint.json"));
  for (const auto& server : servers) EXPECT_FALSE(server->exited_within(0.0)) << "a server stopped";
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

/// Runs robin-run on `case_file` (with `arguments` more), kills body `body`'s server with
/// SIGKILL `delay` after the log shows `moment`, and checks that the run recovers to the
/// reference's answer. The log watched for `moment` is robin-run's, or `watched_log` (relative
/// to the run's output directory) when given. Returns robin-run's log.
std::string expect_recovery(const std::filesystem::path& directory,
                            const std::filesystem::path& case_file,
                            const std::filesystem::path& reference, const std::string& body,
                            const std::string& moment, const std::string& name,
                            std::chrono::milliseconds delay = std::chrono::milliseconds(0),
                            const std::filesystem::path& watched_log = {},
                            const std::vector<std::string>& arguments = {}) {
  const std::filesystem::path output = directory / name;
  const std::filesystem::path log = directory / (name + ".stderr");
  const auto run = start_tool(
      "robin-run",
      with(with({case_file.string(), "--output", output.string()}, joint_stopping), arguments),
      log);
  const std::filesystem::path watched = watched_log.empty() ? log : output / watched_log;
  int pid = 0;
  EXPECT_TRUE(wait_until(
      [&] {
        pid = server_pid(read_text(log), body);
        return (pid != 0 && read_text(watched).find(moment) != std::string::npos) ||
               !run->running();
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
  // two_blocks on a finer mesh: a setup of 0.1-0.2 s (each body's begins when its mesh is in; the
  // kill comes 40 ms after the upper body's began) and fields of about 0.2 s
  const std::filesystem::path case_file = case_copy(directory.path(), 0.01, "two_blocks.toml");
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  // after the handshake, within the setup request
  const std::string setup =
      expect_recovery(directory.path(), case_file, reference, "upper", "setting up body 'upper'",
                      "upper-setup", std::chrono::milliseconds(40));
  EXPECT_NE(setup.find("step setup"), std::string::npos) << setup;
  const std::string fields =
      expect_recovery(directory.path(), case_file, reference, "lower",
                      "collecting the fields of both bodies", "lower-fields");
  EXPECT_NE(fields.find("step fields"), std::string::npos) << fields;
}

TEST(ServerRecovery, RobinRunRestartsAServerKilledDuringACorrectionSolve) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-correction");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.05);
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  // A correction solve lasts about a millisecond: the cantilever's first server waits 30 s at
  // the start of the correction of iteration 20 (--testing-stage-delay), and is killed while
  // it waits. The wrapper passes the option to that first start only, so the restarted server
  // redoes iteration 20 at once. It is called robin-subdomain so that robin-run's log names it
  // as it names the real one.
  const std::filesystem::path wrapper = directory.path() / "delayed" / "robin-subdomain";
  std::filesystem::create_directories(wrapper.parent_path());
  const std::string server = testing::tool("robin-subdomain").string();
  std::ofstream(wrapper) << "#!/bin/sh\nif mkdir '" << (directory.path() / "first-start").string()
                         << "' 2>/dev/null; then\n  exec '" << server
                         << "' \"$@\" --testing-stage-delay correction@20=30\nfi\nexec '" << server
                         << "' \"$@\"\n";
  std::filesystem::permissions(wrapper, std::filesystem::perms(0755));
  const std::string log = expect_recovery(
      directory.path(), case_file, reference, "cantilever", "correction request (iteration 20)",
      "cantilever-correction", std::chrono::milliseconds(0), "logs/server-cantilever.log",
      {"--server-executable", server, "--server-executable", wrapper.string()});
  EXPECT_NE(log.find("step correction (iteration 20)"), std::string::npos) << log;
  EXPECT_NE(log.find("continuing the iteration after iteration"), std::string::npos) << log;
  // the restarted server did not wait
  const std::string server_log =
      read_text(directory.path() / "cantilever-correction" / "logs" / "server-cantilever.log");
  const auto waited = server_log.find("correction request (iteration 20)");
  EXPECT_NE(waited, std::string::npos) << server_log;
  EXPECT_EQ(server_log.find("correction request (iteration", waited + 1), std::string::npos)
      << server_log;
  // The option takes only the correction stage and a number of seconds.
  for (const char* value : {"setup=1", "correction=x", "correction@0=1", "correction"}) {
    EXPECT_EQ(run_to_end("robin-subdomain",
                         {"--listen", "tcp://127.0.0.1:*", "--testing-stage-delay", value},
                         directory.path() / "bad-delay.stderr"),
              "exited with status 2")
        << value;
  }
}

TEST(ServerRecovery, RobinCoordinatorWaitsForAServerToComeBack) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-remote");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.05);
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
  // The oracle: the uninterrupted run against servers started the same way (robin-run's own
  // servers may run another number of BLAS threads, whose rounding differs).
  const std::filesystem::path reference = directory.path() / "reference";
  EXPECT_EQ(run_to_end("robin-coordinator",
                       with({case_file.string(), "--output", reference.string(), "--subdomain",
                             endpoints[0], "--subdomain", endpoints[1]},
                            joint_stopping),
                       directory.path() / "reference.stderr"),
            "exited with status 0")
      << read_text(directory.path() / "reference.stderr");
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

// ---- Load steps ----------------------------------------------------------------------------

/// A wrapper robin-subdomain in `directory`/delayed that makes the first server it starts
/// wait `seconds` at the start of the correction of iteration `iteration` of every load step
/// (--testing-stage-delay) and starts the later ones as they are. It is called robin-subdomain
/// so that robin-run's log names it as it names the real one.
std::filesystem::path delaying_server(const std::filesystem::path& directory, int iteration,
                                      int seconds) {
  const std::filesystem::path wrapper = directory / "delayed" / "robin-subdomain";
  std::filesystem::create_directories(wrapper.parent_path());
  const std::string server = testing::tool("robin-subdomain").string();
  std::ofstream(wrapper) << "#!/bin/sh\nif mkdir '" << (directory / "first-start").string()
                         << "' 2>/dev/null; then\n  exec '" << server
                         << "' \"$@\" --testing-stage-delay correction@" << iteration << "="
                         << seconds << "\nfi\nexec '" << server << "' \"$@\"\n";
  std::filesystem::permissions(wrapper, std::filesystem::perms(0755));
  return wrapper;
}

/// Whether `log` shows iteration `iteration` of load step `step` done ("load step 2/4" and then
/// "iteration 1:").
bool shows_step_iteration(const std::string& log, int step, int iteration) {
  const auto at = log.find("load step " + std::to_string(step) + "/");
  return at != std::string::npos &&
         log.find("iteration " + std::to_string(iteration) + ":", at) != std::string::npos;
}

/// steps.csv of `directory` as numbers (csv_values, written to `copy` first), with its status
/// column (text) as 1 for "converged" and 0 otherwise, and without its wall times.
std::vector<std::vector<double>> steps_table(const std::filesystem::path& directory,
                                             const std::filesystem::path& copy) {
  std::ofstream(copy) << std::regex_replace(
      std::regex_replace(read_text(directory / "steps.csv"), std::regex(",converged,"), ",1,"),
      std::regex(",[a-z_]+,"), ",0,");
  return csv_values(copy, "seconds");
}

/// The result files of a run with load steps equal the reference's: steps.csv, history.csv
/// (every iteration of every step) and each step's contact.csv (but the wall times), the
/// top-level contact.csv, and summary.json's load_steps.
void expect_same_steps(const std::filesystem::path& output, const std::filesystem::path& reference,
                       const std::string& name, double tolerance) {
  expect_same_table(steps_table(output, output.parent_path() / (name + "-steps.csv")),
                    steps_table(reference, output.parent_path() / "reference-steps.csv"), tolerance,
                    name + " steps.csv");
  expect_same_table(csv_values(output / "history.csv", "seconds"),
                    csv_values(reference / "history.csv", "seconds"), tolerance,
                    name + " history.csv");
  for (const char* step : {"step_001", "step_002", "step_003", "step_004"}) {
    const std::filesystem::path contact = std::filesystem::path("steps") / step / "contact.csv";
    ASSERT_TRUE(std::filesystem::exists(reference / contact)) << contact;
    expect_same_table(csv_values(output / contact), csv_values(reference / contact), tolerance,
                      name + " " + contact.string());
  }
  expect_same_table(csv_values(output / "contact.csv"), csv_values(reference / "contact.csv"),
                    tolerance, name + " contact.csv");
  const nlohmann::json steps = read_summary(output)["load_steps"];
  const nlohmann::json expected = read_summary(reference)["load_steps"];
  ASSERT_EQ(steps.size(), expected.size()) << name;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    for (const char* key :
         {"status", "iterations", "qp_iterations", "warm_started", "active_pairs"}) {
      EXPECT_EQ(steps[k][key], expected[k][key]) << name << " step " << k + 1 << " " << key;
    }
    EXPECT_NEAR(steps[k].value("largest_pressure", 0.0), expected[k].value("largest_pressure", 1.0),
                tolerance * std::abs(expected[k].value("largest_pressure", 1.0)))
        << name << " step " << k + 1;
  }
}

/// robin-run on `case_file` into `output` with the cylinder's first server waiting 3 s at the
/// start of the correction of iteration 2 of every load step (delaying_server).
std::unique_ptr<ChildProcess> start_delayed_steps(const std::filesystem::path& directory,
                                                  const std::filesystem::path& case_file,
                                                  const std::filesystem::path& output,
                                                  const std::filesystem::path& log) {
  const std::filesystem::path wrapper = delaying_server(directory, 2, 3);
  return start_tool(
      "robin-run",
      with({case_file.string(), "--output", output.string(), "--server-executable",
            testing::tool("robin-subdomain").string(), "--server-executable", wrapper.string()},
           joint_stopping),
      log);
}

TEST(Resume, KilledLoadStepRunResumesAtTheInterruptedStep) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-resume-steps");
  // The Hertz contact in four load steps (examples/hertz_steps.toml) on a coarser mesh.
  const std::filesystem::path case_file = case_copy(directory.path(), 0.2, "hertz_steps.toml");
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  ASSERT_EQ(read_summary(reference)["load_steps"].size(), 4u);

  // Killed while the cylinder's server waits in iteration 2 of step 2: after the checkpoint of
  // that step's iteration 1 is on disk.
  const std::filesystem::path output = directory.path() / "resumed";
  const std::filesystem::path first_log = directory.path() / "killed.stderr";
  const auto run = start_delayed_steps(directory.path(), case_file, output, first_log);
  ASSERT_TRUE(wait_until([&] { return checkpointed_iteration(output, 1, 2); }, 60.0))
      << read_text(first_log);
  ASSERT_EQ(kill(run->pid(), SIGKILL), 0);
  ASSERT_TRUE(run->wait_for_exit(10.0));
  ASSERT_EQ(run->exit_description(), "was killed by signal 9 (Killed)");
  EXPECT_TRUE(wait_until([] { return waitpid(-1, nullptr, WNOHANG) == -1; }, 10.0));
  std::ifstream checkpoint_file(output / "checkpoint.json");
  const nlohmann::json checkpoint = nlohmann::json::parse(checkpoint_file, nullptr, false);
  ASSERT_TRUE(checkpoint.is_object()) << "no checkpoint.json";
  EXPECT_EQ(checkpoint.value("format", 0), 3);
  EXPECT_EQ(checkpoint.value("step", 0), 2);
  EXPECT_EQ(checkpoint["load_steps"].size(), 1u);
  EXPECT_EQ(checkpoint["loop"].value("iteration", 0), 1);
  EXPECT_FALSE(checkpoint["loop"].value("stopped", true));

  const std::filesystem::path resume_log = directory.path() / "resume.stderr";
  EXPECT_EQ(run_to_end("robin-run", {"--resume", output.string()}, resume_log),
            "exited with status 0")
      << read_text(resume_log);
  const std::string resumed = read_text(resume_log);
  EXPECT_NE(resumed.find("repeating the contact solves of the 1 load steps before"),
            std::string::npos)
      << resumed;
  EXPECT_NE(resumed.find("continuing the iteration after iteration 1"), std::string::npos)
      << resumed;
  expect_same_steps(output, reference, "resumed", 1e-12);
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "converged");
  EXPECT_EQ(summary["resumed_from"].value("load_step", 0), 2);
  EXPECT_EQ(summary["resumed_from"].value("iteration", 0), 1);
  EXPECT_FALSE(std::filesystem::exists(output / "checkpoint.json"));
  EXPECT_FALSE(std::filesystem::exists(output / "checkpoint-iterates.bin"));
}

TEST(ServerRecovery, RobinRunRestartsAServerKilledDuringALoadStep) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory directory("robin-recovery-steps");
  const std::filesystem::path case_file = case_copy(directory.path(), 0.2, "hertz_steps.toml");
  const std::filesystem::path reference = reference_run(directory.path(), case_file);
  // The cylinder's server is killed while it waits in iteration 2 of step 2.
  const std::filesystem::path output = directory.path() / "recovered";
  const std::filesystem::path log = directory.path() / "recovered.stderr";
  const auto run = start_delayed_steps(directory.path(), case_file, output, log);
  int pid = 0;
  ASSERT_TRUE(wait_until(
      [&] {
        const std::string text = read_text(log);
        pid = server_pid(text, "cylinder");
        return pid != 0 && shows_step_iteration(text, 2, 1);
      },
      60.0))
      << read_text(log);
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  while (run->read_line(ChildProcess::Clock::now() + std::chrono::seconds(120))) {
  }
  ASSERT_TRUE(run->wait_for_exit(120.0));
  const std::string text = read_text(log);
  EXPECT_EQ(run->exit_description(), "exited with status 0") << text;
  EXPECT_NE(text.find("lost the server of body 'cylinder'"), std::string::npos) << text;
  EXPECT_NE(text.find("(restart 1 of 2)"), std::string::npos) << text;
  EXPECT_NE(text.find("repeating the contact solves of the 1 load steps before"), std::string::npos)
      << text;
  expect_same_steps(output, reference, "recovered", 1e-12);
  EXPECT_EQ(read_summary(output)["server_restarts"].size(), 1u);
}

}  // namespace
}  // namespace robin
