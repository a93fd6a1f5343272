#pragma once
// The result directory of one run: never a mix of two runs' files, never an older success in
// view while a run is going on or after it failed.
//
// Life of a directory:
//   1. check_result_directory (at command-line time): a directory holding files is refused
//      unless the user asked to overwrite. Overwriting removes an earlier run's files, its
//      staging areas and the temporary files of an atomic write a kill interrupted
//      (".summary.json.tmp-PID-N").
//   2. ResultDirectory's constructor removes the previous run's files (the names in its
//      summary.json "files" list and the names every run writes; anything else is left alone
//      and listed by leftover_files()), then writes summary.json with status "running", the run
//      id, the start time, the product and protocol versions and the case file's SHA-256.
//   3. The run writes its files into staging() (a hidden subdirectory).
//   4. commit() moves each staged file into place (rename: each file appears whole) and writes
//      summary.json last, atomically (temporary name, then rename), with the files list, the
//      end time and the status given by the caller. fail() writes summary.json with status
//      "failed" or "interrupted" and the message instead, and removes the staged files.
//   5. A coupled run keeps checkpoint.json (checkpoint.hpp) in the directory while it runs;
//      commit() removes it after summary.json, fail() keeps it: the run can be resumed.
// A run killed before commit() leaves summary.json saying "running" with its start time. A run
// whose case file cannot be read records that with record_failed_start.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace robin {

/// What to do with a result directory that already holds files: refuse it, replace an earlier
/// run's files, or continue the run whose checkpoint.json it holds (checkpoint.hpp: the
/// checkpoint and logs/ are kept, the earlier attempt's staging areas removed).
enum class ExistingResults { refuse, overwrite, resume };

/// How a run that did not produce results ended.
enum class RunFailure { failed, interrupted };

/// A result directory that cannot be used (holds files, cannot be created or written). The
/// message names the directory and what to do.
class ResultDirectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws ResultDirectoryError when `directory` exists and holds any entry while `policy` is
/// refuse (the message lists up to five of the entries and names --overwrite); entries named in
/// `ignored` do not count.
void check_result_directory(const std::filesystem::path& directory, ExistingResults policy,
                            const std::set<std::string>& ignored = {});

/// SHA-256 of a file's bytes as 64 lower-case hex digits. Throws std::runtime_error naming the
/// file when it cannot be read.
std::string file_sha256(const std::filesystem::path& path);

/// The current time in UTC as ISO 8601 ("2026-11-25T07:01:02Z").
std::string utc_timestamp();

class ResultDirectory {
 public:
  /// Prepares `directory` for a run of `tool` on `case_file` (see the file comment). Throws
  /// ResultDirectoryError when it holds files and `policy` is refuse, or cannot be written.
  /// A case file that cannot be read is recorded with case_sha256 null.
  ResultDirectory(std::filesystem::path directory, ExistingResults policy, std::string tool,
                  const std::filesystem::path& case_file);
  ~ResultDirectory();
  ResultDirectory(const ResultDirectory&) = delete;
  ResultDirectory& operator=(const ResultDirectory&) = delete;

  const std::filesystem::path& directory() const { return directory_; }
  /// Where the run writes its result files (created by the constructor).
  const std::filesystem::path& staging() const { return staging_; }
  const std::string& run_id() const { return run_id_; }
  /// Entries of the directory that were neither removed nor written by this run.
  const std::vector<std::string>& leftover_files() const { return leftovers_; }

  /// Moves the staged files into place and writes summary.json last: `summary` plus the run's
  /// record (run_id, tool, case, case_sha256, started, ended, files). `summary` must carry
  /// "status". Throws std::runtime_error naming the file that could not be moved or written.
  void commit(nlohmann::json summary);

  /// Adds `key` to the run's record (e.g. "resumed_from", "server_restarts"); summary.json is
  /// rewritten at once while the run goes on. Throws std::runtime_error naming the file.
  void add_to_record(const std::string& key, nlohmann::json value);

  /// Records a run that ended without results: summary.json with the run's record, the status
  /// "failed" or "interrupted" and `message`; the staged files are removed. Never throws.
  void fail(RunFailure failure, const std::string& message) noexcept;

 private:
  nlohmann::json record(const std::string& status) const;
  void remove_staging() noexcept;

  std::filesystem::path directory_;
  std::filesystem::path staging_;
  std::string tool_;
  std::string case_file_;
  std::string case_sha256_;
  std::string run_id_;
  std::string started_;
  std::vector<std::string> leftovers_;
  nlohmann::json additions_ = nlohmann::json::object();  // add_to_record
  bool finished_ = false;
};

/// Records a run that failed before it could start, at the case file (a TOML syntax error, an
/// unknown key, a bad --set): prepares `directory` as ResultDirectory's constructor does under
/// `policy` and writes summary.json with status "failed", `tool`, the case file's path, its
/// SHA-256 (null when the file cannot be read) and `message`. Throws ResultDirectoryError when
/// the directory cannot be used (then nothing is recorded).
void record_failed_start(const std::filesystem::path& directory, ExistingResults policy,
                         const std::string& tool, const std::filesystem::path& case_file,
                         const std::string& message);

/// Writes `bytes` to `path` opened with fopen mode `mode` ("wb" replaces, "ab" appends), then
/// flushes it to the disk (fsync); false when any step failed.
bool write_durably(const std::filesystem::path& path, const std::string& bytes, const char* mode);

/// Writes `text` to `path` atomically: a temporary file in the same directory, flushed, then
/// renamed over `path`. Throws std::runtime_error naming `path`.
void write_file_atomically(const std::filesystem::path& path, const std::string& text);

}  // namespace robin
