#pragma once
// The checkpoint files of a coupled run (docs/outputs.md, "Checkpoint and resume"), written
// after every iteration and read by `robin-run --resume DIR` / `robin-coordinator --resume
// DIR`:
//   DIR/checkpoint-iterates.bin  the iterates x_1, x_2, ... of the iteration, one record per
//                                iteration appended (an unsigned 64-bit count n, then n
//                                IEEE 754 doubles, both in the machine's byte order); with
//                                [loading], those of the completed load steps first, in
//                                order, then those of the current step;
//   DIR/checkpoint.json          written atomically (write_file_atomically: a temporary
//                                name, flushed, renamed) after the record is appended: the
//                                loop's state after iteration k (iteration_checkpoint.hpp),
//                                which says how many records are valid (k, plus those of
//                                the completed load steps; a record beyond, from an append
//                                cut short, is ignored), the completed load steps
//                                (iteration_checkpoint.hpp), and the run it belongs
//                                to, so that a resume with a changed case or changed options is
//                                refused: the case file's path, SHA-256 and text (the text
//                                names the changed keys), the --set overrides and the
//                                command-line options that change the computation.
// Per iteration this writes O(interface x history depth) bytes plus the residual records.

#include <condition_variable>
#include <exception>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "coupling/iteration_checkpoint.hpp"

namespace robin {

/// The names of the checkpoint files inside a result directory.
extern const char* const checkpoint_file_name;
extern const char* const checkpoint_iterates_file_name;

struct RunCheckpoint {
  /// 3: with the load steps of a case with [loading]; 2: without them (a run with [loading]
  /// was not checkpointed); 1 had fixed pairs of vectors instead of per-body states.
  static constexpr int current_format = 3;
  std::string run_id;        // the run that wrote it (ResultDirectory::run_id)
  std::string first_run_id;  // the run that started from scratch (itself, or resumed ones')
  std::string started;       // when that first run started (UTC, ISO 8601)
  std::string case_file;     // absolute path of the case file
  std::string case_sha256;
  std::string case_text;
  std::vector<std::string> overrides;  // --set KEY=VALUE, in order
  /// The command-line options that change the computation, name -> value ("--tolerance":
  /// 1e-6); an option not given is absent.
  nlohmann::json options = nlohmann::json::object();
  /// The load step `iteration` belongs to (1-based), 0 for a case without [loading].
  int step = 0;
  /// The load steps completed before it (steps 1 ... step - 1).
  std::vector<LoadStepCheckpoint> steps;
  IterationCheckpoint iteration;
};

/// Writes the checkpoints of one run (one process) into a directory.
class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::filesystem::path directory);
  /// Writes checkpoint-iterates.bin (whole, atomically, on the first call; then by appending
  /// the iterates it lacks) and then checkpoint.json atomically. Throws std::runtime_error
  /// naming the file that cannot be written.
  void write(const RunCheckpoint& checkpoint);

 private:
  std::filesystem::path directory_;
  std::size_t iterates_written_ = 0;
  bool first_ = true;
};

/// A CheckpointWriter on a thread of its own, so that the iteration does not wait for the files
/// and their fsyncs: write() hands a copy of the checkpoint over and returns. A checkpoint handed
/// over while an earlier one is still being written replaces the one waiting: only the newest is
/// written, and the files may then skip an iteration, which a resumed run repeats (resuming from
/// any checkpoint gives the uninterrupted run's answer). An error of the writing thread is thrown
/// by the next write() or by finish(); the destructor waits for the writing, errors dropped.
class BackgroundCheckpointWriter {
 public:
  explicit BackgroundCheckpointWriter(std::filesystem::path directory);
  ~BackgroundCheckpointWriter();
  BackgroundCheckpointWriter(const BackgroundCheckpointWriter&) = delete;
  BackgroundCheckpointWriter& operator=(const BackgroundCheckpointWriter&) = delete;

  void write(const RunCheckpoint& checkpoint);
  /// Waits until the newest checkpoint handed over is written; throws the writing's error.
  void finish();

 private:
  void write_in_turn();
  void throw_error();  // the writing thread's error, once (mutex_ held)

  CheckpointWriter writer_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<RunCheckpoint> waiting_;
  bool writing_ = false;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

/// Reads the checkpoint files of `directory`. Throws CheckpointFormatError
/// (checkpoint_encoding.hpp) naming the file and what is wrong with it (missing, unreadable,
/// another format, a malformed field, too few iterates).
RunCheckpoint read_checkpoint(const std::filesystem::path& directory);

/// The keys whose values differ between two TOML texts (flattened key paths as the case
/// reader names them, "coupling.tolerance", "body[2].mesh_size"), each as
/// "KEY: OLD -> NEW" (a missing side shown as "(absent)"), at most `limit` of them and then
/// "...". Empty when both parse to the same values; a text that does not parse is named.
std::vector<std::string> toml_differences(const std::string& before, const std::string& after,
                                          std::size_t limit = 10);

}  // namespace robin
