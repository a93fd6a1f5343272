// What a run records in its result directory, through the real binaries:
//  - robin-monolithic stopped by SIGINT / SIGTERM during a setup of seconds (Hertz at
//    h = 0.02) exits 130 / 143 and leaves summary.json "interrupted" naming the signal, no
//    staging area and none of its meshing processes;
//  - a case file that cannot be read (a TOML syntax error; an unknown key given by --set)
//    leaves summary.json "failed" naming the case file, the line and the error, with the case
//    file's SHA-256 (checked against sha256sum), written by robin-run, robin-coordinator and
//    robin-monolithic; rerun with --overwrite over an earlier success it removes that
//    success's files;
//  - robin-run records tool "robin-run", robin-monolithic "robin-monolithic".

#include <gtest/gtest.h>
#include <sys/prctl.h>
#include <sys/wait.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>

#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::read_summary;
using testing::read_text;
using testing::run_to_end;
using testing::start_tool;
using testing::TemporaryDirectory;
using testing::wait_until;

/// sha256sum's digest of `path` (an oracle outside the code under test).
std::string sha256sum(const std::filesystem::path& path) {
  std::FILE* pipe = popen(("sha256sum '" + path.string() + "'").c_str(), "r");
  if (pipe == nullptr) return "";
  char digest[65] = {};
  const bool read = std::fscanf(pipe, "%64s", digest) == 1;
  pclose(pipe);
  return read ? digest : "";
}

bool has_staging_area(const std::filesystem::path& directory) {
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    if (entry.path().filename().string().rfind(".staging-", 0) == 0) return true;
  }
  return false;
}

void expect_monolithic_interrupted(int signal_number) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);  // its meshing children would come to us
  const TemporaryDirectory directory("robin-monolithic-signal");
  const std::filesystem::path output = directory.path() / "out";
  const std::filesystem::path log = directory.path() / "monolithic.stderr";
  // its meshing directory, which a process ended at once cannot remove, goes into ours
  const char* previous = std::getenv("TMPDIR");
  const std::string saved = previous != nullptr ? previous : "";
  setenv("TMPDIR", directory.path().c_str(), 1);
  const auto run = start_tool("robin-monolithic",
                              {example("hertz.toml").string(), "--output", output.string(), "--set",
                               "body[1].mesh_size=0.02", "--set", "body[2].mesh_size=0.02"},
                              log);
  if (previous != nullptr) {
    setenv("TMPDIR", saved.c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  ASSERT_TRUE(wait_until(
      [&] {
        return read_text(log).find("reading and meshing") != std::string::npos || !run->running();
      },
      60.0));
  ASSERT_TRUE(run->running()) << read_text(log);
  ASSERT_EQ(read_summary(output).value("status", ""), "running");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the meshing
  ASSERT_EQ(kill(run->pid(), signal_number), 0);
  ASSERT_TRUE(run->wait_for_exit(30.0)) << "robin-monolithic still runs 30 s after the signal";
  EXPECT_EQ(run->exit_description(), "exited with status " + std::to_string(128 + signal_number))
      << read_text(log);
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "interrupted") << summary.dump(2);
  EXPECT_EQ(summary.value("tool", ""), "robin-monolithic");
  EXPECT_NE(summary.value("message", "").find("stopped by signal " + std::to_string(signal_number)),
            std::string::npos)
      << summary.dump(2);
  EXPECT_FALSE(has_staging_area(output));
  EXPECT_FALSE(std::filesystem::exists(output / "contact.csv"));
  // no meshing process is left: any would now be this process's child
  EXPECT_TRUE(wait_until([] { return waitpid(-1, nullptr, WNOHANG) == -1; }, 5.0));
}

TEST(RunRecord, RobinMonolithicStoppedBySigintSaysInterrupted) {
  expect_monolithic_interrupted(SIGINT);
}

TEST(RunRecord, RobinMonolithicStoppedBySigtermSaysInterrupted) {
  expect_monolithic_interrupted(SIGTERM);
}

/// Checks the "failed" summary.json a tool wrote for an unreadable case file.
void expect_failed_start(const std::filesystem::path& output, const std::string& tool,
                         const std::filesystem::path& case_file, const std::string& error) {
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "failed") << tool << "\n" << summary.dump(2);
  EXPECT_EQ(summary.value("tool", ""), tool);
  EXPECT_EQ(summary.value("case", ""), case_file.string());
  EXPECT_EQ(summary.value("case_sha256", ""), sha256sum(case_file)) << tool;
  const std::string message = summary.value("message", "");
  EXPECT_EQ(message.rfind(case_file.string(), 0), 0u) << tool << ": " << message;
  EXPECT_NE(message.find(error), std::string::npos) << tool << ": " << message;
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(output)) ++entries;
  EXPECT_EQ(entries, 1) << tool << ": only summary.json";
}

TEST(RunRecord, AnUnreadableCaseFileLeavesAFailedSummary) {
  const TemporaryDirectory directory("robin-failed-start");
  const std::filesystem::path broken = directory.path() / "broken.toml";
  std::ofstream(broken) << "title = \"broken\"\n[coupling\ntolerance = 1e-8\n";
  for (const std::string tool : {"robin-run", "robin-monolithic"}) {
    const std::filesystem::path output = directory.path() / tool;
    const std::string exit = run_to_end(tool, {broken.string(), "--output", output.string()},
                                        directory.path() / (tool + ".stderr"));
    EXPECT_EQ(exit, "exited with status 1") << read_text(directory.path() / (tool + ".stderr"));
    expect_failed_start(output, tool, broken, ":2:");  // the line of the syntax error
  }
  // robin-coordinator, with a key the case format does not know; its servers are never reached
  const std::filesystem::path output = directory.path() / "robin-coordinator";
  const std::string exit =
      run_to_end("robin-coordinator",
                 {example("two_blocks.toml").string(), "--output", output.string(), "--set",
                  "coupling.no_such_key=1", "--subdomain", "tcp://127.0.0.1:9", "--subdomain",
                  "tcp://127.0.0.1:9"},
                 directory.path() / "robin-coordinator.stderr");
  EXPECT_EQ(exit, "exited with status 1");
  expect_failed_start(output, "robin-coordinator", example("two_blocks.toml"),
                      "unknown key 'coupling.no_such_key'");
}

TEST(RunRecord, AFailedRerunLeavesNoEarlierSuccessInView) {
  const TemporaryDirectory directory("robin-failed-rerun");
  const std::filesystem::path output = directory.path() / "out";
  EXPECT_EQ(
      run_to_end("robin-run",
                 {example("two_blocks.toml").string(), "--output", output.string(), "--quiet"},
                 directory.path() / "first.stderr"),
      "exited with status 0");
  nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "converged");
  EXPECT_EQ(summary.value("tool", ""), "robin-run");
  ASSERT_TRUE(std::filesystem::exists(output / "contact.csv"));
  // a bad value: robin-monolithic fails at the case file, over the earlier success
  EXPECT_EQ(run_to_end("robin-monolithic",
                       {example("two_blocks.toml").string(), "--output", output.string(),
                        "--overwrite", "--set", "body[1].material.young=-1"},
                       directory.path() / "second.stderr"),
            "exited with status 1");
  summary = read_summary(output);
  EXPECT_EQ(summary.value("status", ""), "failed") << summary.dump(2);
  EXPECT_EQ(summary.value("tool", ""), "robin-monolithic");
  EXPECT_NE(summary.value("message", "").find("body[1].material.young"), std::string::npos)
      << summary.dump(2);
  for (const char* name : {"contact.csv", "history.csv", "solution.pvd"}) {
    EXPECT_FALSE(std::filesystem::exists(output / name)) << name;
  }
}

}  // namespace
}  // namespace robin
