// The result directory of a run (coupling/result_directory.hpp):
//  - a directory holding files is refused unless overwriting, naming the directory, its
//    entries and --overwrite; a file where the directory should be is refused;
//  - while a run goes on, summary.json says "running" with the run id, the start time and the
//    case file's SHA-256 (checked against the FIPS 180-2 test vector of "abc");
//  - overwriting removes the earlier run's files (those its summary.json lists, the fixed names,
//    .vtu files, staging areas) and leaves any other file, listed as a leftover, and logs/;
//  - commit moves the staged files into place and lists them in summary.json, written last;
//  - fail records "failed" or "interrupted" with the message and removes the staged files, so
//    that an earlier run's "converged" never stays in view;
//  - overwriting removes the temporary files a killed atomic write left (.NAME.tmp-PID-N), not
//    other hidden files;
//  - record_failed_start writes a "failed" summary.json for a run whose case file is unusable,
//    with the case file's hash when it can be read and null when not, honouring refuse and
//    overwrite.

#include "coupling/result_directory.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "../test_files.hpp"

namespace robin {
namespace {

using testing::file_text;
using testing::TemporaryDirectory;
using testing::write_text;
namespace fs = std::filesystem;

nlohmann::json read_summary(const fs::path& directory) {
  return nlohmann::json::parse(file_text(directory / "summary.json"));
}

fs::path write_case(const fs::path& directory) {
  const fs::path case_file = directory / "case.toml";
  write_text(case_file, "abc");  // SHA-256 test vector of FIPS 180-2, appendix B.1
  return case_file;
}

TEST(ResultDirectory, HashesTheCaseFileWithSha256) {
  const TemporaryDirectory work("result-hash");
  EXPECT_EQ(file_sha256(write_case(work.path())),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  write_text(work.path() / "empty", "");
  EXPECT_EQ(file_sha256(work.path() / "empty"),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_THROW(file_sha256(work.path() / "missing"), std::runtime_error);
}

TEST(ResultDirectory, RefusesADirectoryHoldingFilesUnlessOverwriting) {
  const TemporaryDirectory work("result-refuse");
  const fs::path output = work.path() / "out";
  EXPECT_NO_THROW(check_result_directory(output, ExistingResults::refuse));  // does not exist
  fs::create_directories(output);
  EXPECT_NO_THROW(check_result_directory(output, ExistingResults::refuse));  // empty
  write_text(output / "history.csv", "old");
  try {
    check_result_directory(output, ExistingResults::refuse);
    FAIL() << "a directory holding history.csv was accepted";
  } catch (const ResultDirectoryError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(output.string()), std::string::npos) << message;
    EXPECT_NE(message.find("history.csv"), std::string::npos) << message;
    EXPECT_NE(message.find("--overwrite"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(check_result_directory(output, ExistingResults::overwrite));
  write_text(work.path() / "a_file", "");
  EXPECT_THROW(check_result_directory(work.path() / "a_file", ExistingResults::overwrite),
               ResultDirectoryError);
  EXPECT_THROW(ResultDirectory(output, ExistingResults::refuse, "test", write_case(work.path())),
               ResultDirectoryError);
  EXPECT_EQ(file_text(output / "history.csv"), "old");
}

TEST(ResultDirectory, SaysRunningWhileTheRunGoesOnThenCommitsItsFilesAndSummaryLast) {
  const TemporaryDirectory work("result-commit");
  const fs::path output = work.path() / "out";
  ResultDirectory results(output, ExistingResults::refuse, "test-tool", write_case(work.path()));
  const nlohmann::json running = read_summary(output);
  EXPECT_EQ(running["status"], "running");
  EXPECT_EQ(running["run_id"], results.run_id());
  EXPECT_EQ(results.run_id().size(), 32u);
  EXPECT_EQ(running["tool"], "test-tool");
  EXPECT_FALSE(running["versions"]["product"].get<std::string>().empty());
  EXPECT_EQ(running["versions"]["protocol"].get<std::string>().rfind("2.", 0), 0u);  // 2.x
  EXPECT_EQ(running["case_sha256"],
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_TRUE(running["ended"].is_null());
  EXPECT_EQ(running["started"].get<std::string>().size(), 20u);  // 2026-11-25T07:01:02Z

  write_text(results.staging() / "body.vtu", "vtu");
  write_text(results.staging() / "history.csv", "new");
  EXPECT_FALSE(fs::exists(output / "body.vtu"));  // not in view before the commit
  results.commit({{"status", "converged"}, {"iterations", 7}});
  const nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary["status"], "converged");
  EXPECT_EQ(summary["iterations"], 7);
  EXPECT_EQ(summary["run_id"], running["run_id"]);
  EXPECT_FALSE(summary["ended"].is_null());
  EXPECT_EQ(summary["files"], nlohmann::json::array({"body.vtu", "history.csv", "summary.json"}));
  EXPECT_EQ(file_text(output / "body.vtu"), "vtu");
  EXPECT_FALSE(fs::exists(results.staging()));
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(output)) ++entries;
  EXPECT_EQ(entries, 3);  // no staging area or temporary file is left behind
}

TEST(ResultDirectory, OverwritingRemovesTheEarlierRunsFilesOnlyAndKeepsLogs) {
  const TemporaryDirectory work("result-overwrite");
  const fs::path output = work.path() / "out";
  fs::create_directories(output / "logs");
  write_text(output / "logs" / "server-upper.log", "log of this run");
  write_text(output / "summary.json",
             R"({"status": "converged", "files": ["old_body.vtu", "extra.dat", "../outside"]})");
  write_text(output / "old_body.vtu", "");
  write_text(output / "extra.dat", "listed by the earlier run");
  write_text(output / "contact.png", "");
  write_text(output / "notes.txt", "the user's");
  write_text(work.path() / "outside", "not in the directory");
  fs::create_directories(output / ".staging-0123");
  const ResultDirectory results(output, ExistingResults::overwrite, "test",
                                write_case(work.path()));
  EXPECT_FALSE(fs::exists(output / "old_body.vtu"));
  EXPECT_FALSE(fs::exists(output / "extra.dat"));
  EXPECT_FALSE(fs::exists(output / "contact.png"));
  EXPECT_FALSE(fs::exists(output / ".staging-0123"));
  EXPECT_TRUE(fs::exists(output / "notes.txt"));
  EXPECT_TRUE(fs::exists(work.path() / "outside"));  // a listed path leading out is ignored
  EXPECT_EQ(file_text(output / "logs" / "server-upper.log"), "log of this run");
  EXPECT_EQ(results.leftover_files(), std::vector<std::string>{"notes.txt"});
  EXPECT_EQ(read_summary(output)["status"], "running");
}

TEST(ResultDirectory, AFailedOrInterruptedRunSaysSoAndLeavesNoEarlierSuccessInView) {
  const TemporaryDirectory work("result-fail");
  const fs::path output = work.path() / "out";
  const fs::path case_file = write_case(work.path());
  {
    ResultDirectory first(output, ExistingResults::refuse, "test", case_file);
    write_text(first.staging() / "body.vtu", "first");
    first.commit({{"status", "converged"}});
  }
  {
    ResultDirectory second(output, ExistingResults::overwrite, "test", case_file);
    EXPECT_FALSE(fs::exists(output / "body.vtu"));
    write_text(second.staging() / "body.vtu", "half-written");
    second.fail(RunFailure::failed, "server tcp://host:1 (body 'upper'), step setup: gone");
    EXPECT_FALSE(fs::exists(second.staging()));
  }
  const nlohmann::json failed = read_summary(output);
  EXPECT_EQ(failed["status"], "failed");
  EXPECT_EQ(failed["converged"], false);
  EXPECT_EQ(failed["message"], "server tcp://host:1 (body 'upper'), step setup: gone");
  EXPECT_FALSE(fs::exists(output / "body.vtu"));
  {
    ResultDirectory third(output, ExistingResults::overwrite, "test", case_file);
    third.fail(RunFailure::interrupted, "stopped by SIGTERM");
  }
  EXPECT_EQ(read_summary(output)["status"], "interrupted");
  { const ResultDirectory abandoned(output, ExistingResults::overwrite, "test", case_file); }
  EXPECT_EQ(read_summary(output)["status"], "failed");
}

TEST(ResultDirectory, OverwritingRemovesTemporaryFilesOfAKilledAtomicWrite) {
  const TemporaryDirectory work("result-temporary");
  const fs::path output = work.path() / "out";
  fs::create_directories(output);
  // what write_file_atomically leaves when the process is killed between writing and renaming
  write_text(output / ".summary.json.tmp-4242-0", "{\"status\": \"conv");
  write_text(output / ".checkpoint.json.tmp-4242-3", "{");
  write_text(output / ".hidden-notes", "the user's");
  EXPECT_THROW(check_result_directory(output, ExistingResults::refuse), ResultDirectoryError);
  const ResultDirectory results(output, ExistingResults::overwrite, "test",
                                write_case(work.path()));
  EXPECT_FALSE(fs::exists(output / ".summary.json.tmp-4242-0"));
  EXPECT_FALSE(fs::exists(output / ".checkpoint.json.tmp-4242-3"));
  EXPECT_TRUE(fs::exists(output / ".hidden-notes"));
  EXPECT_EQ(results.leftover_files(), std::vector<std::string>{".hidden-notes"});
}

TEST(ResultDirectory, RecordsARunWhoseCaseFileCannotBeRead) {
  const TemporaryDirectory work("result-failed-start");
  const fs::path output = work.path() / "out";
  const fs::path case_file = write_case(work.path());
  // a readable case file with an error: its hash is recorded
  record_failed_start(output, ExistingResults::refuse, "robin-run", case_file,
                      "case.toml:3: unknown key 'x'");
  nlohmann::json summary = read_summary(output);
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_EQ(summary["tool"], "robin-run");
  EXPECT_EQ(summary["case"], case_file.string());
  EXPECT_EQ(summary["case_sha256"],
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(summary["message"], "case.toml:3: unknown key 'x'");
  EXPECT_FALSE(summary["ended"].is_null());
  // a missing case file: no hash; an earlier run's files are replaced under overwrite only
  EXPECT_THROW(record_failed_start(output, ExistingResults::refuse, "robin-run",
                                   work.path() / "missing.toml", "cannot be read"),
               ResultDirectoryError);
  record_failed_start(output, ExistingResults::overwrite, "robin-monolithic",
                      work.path() / "missing.toml", "missing.toml: cannot be read");
  summary = read_summary(output);
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_TRUE(summary["case_sha256"].is_null());
  EXPECT_EQ(summary["message"], "missing.toml: cannot be read");
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(output)) ++entries;
  EXPECT_EQ(entries, 1);  // summary.json only
  // a file where the directory should be: nothing recorded
  write_text(work.path() / "a_file", "");
  EXPECT_THROW(
      record_failed_start(work.path() / "a_file", ExistingResults::overwrite, "t", case_file, "x"),
      ResultDirectoryError);
  EXPECT_EQ(file_text(work.path() / "a_file"), "");
}

TEST(ResultDirectory, WritesFilesAtomically) {
  const TemporaryDirectory work("result-atomic");
  write_text(work.path() / "file", "old");
  write_file_atomically(work.path() / "file", "new content");
  EXPECT_EQ(file_text(work.path() / "file"), "new content");
  EXPECT_THROW(write_file_atomically(work.path() / "missing" / "file", "x"), std::runtime_error);
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(work.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

}  // namespace
}  // namespace robin
