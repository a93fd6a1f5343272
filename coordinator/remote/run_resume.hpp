#pragma once
// `--resume DIR` of robin-run and robin-coordinator (docs/outputs.md, "Checkpoint and
// resume"): the checkpoint of DIR supplies the case file, the --set overrides and the options
// of the interrupted run; the resumed run must compute the same thing, so a resume is refused,
// naming what changed, when
//   the case file's SHA-256 differs from the checkpointed one (the message names the file,
//   both hashes and the keys whose values changed),
//   a --set override or an option that changes the computation (--tolerance, --algorithm, ...)
//   is given with another value than the interrupted run had (or was not given then),
//   the checkpoint's load step does not fit the case's [loading] (a checkpoint of a run with
//   load steps for a case without, or the reverse; the case's hash makes this unlikely).

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "coupling/checkpoint.hpp"
#include "remote/coordinator_application.hpp"

namespace robin {

/// A resume that would not compute the interrupted run; the message says what differs.
class ResumeRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The options of `settings` that change the computation and were given, as
/// {"--tolerance": 1e-6, ...}.
nlohmann::json computation_options(const CoordinatorSettings& settings);

/// Reads the checkpoint of settings.resume_directory and completes `settings` from it: the case
/// file (when none is given), the overrides and the computation options not given. Throws
/// ResumeRefused when they differ from the checkpoint's or the case file changed, and
/// CheckpointFormatError when the checkpoint cannot be used.
RunCheckpoint prepare_resume(CoordinatorSettings& settings);

/// Throws ResumeRefused when the checkpoint's load step (RunCheckpoint::step) does not fit the
/// case's [loading] steps (checked once the case is read).
void check_resumable(const CaseDefinition& definition, const RunCheckpoint& checkpoint);

}  // namespace robin
