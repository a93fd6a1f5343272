#pragma once
// The coordinator application shared by robin-coordinator (servers given by endpoint) and
// robin-run (servers started locally): command-line options, the "coordinator" logger,
// progress lines, the coupled run on two RemotePorts, the result files and the exit code.
//
// Exit codes: 0 converged; 3 iteration limit reached; 4 diverged; 5 stagnated (the result
// files are written in these four cases); 1 bad input, a server failure or any other error
// (the message is logged); 2 bad command line; 128 + signal when stopped by SIGINT (130) or
// SIGTERM (143).

#include <CLI/CLI.hpp>
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "command_line.hpp"  // parse_command_line, add_version_option
#include "coupling/case_file.hpp"
#include "coupling/checkpoint.hpp"
#include "coupling/robin_iteration.hpp"
#include "remote/progress_display.hpp"
#include "remote/request_channel.hpp"

namespace spdlog {
class logger;
}

namespace robin {

/// The command line shared by both executables. Unset options keep the case file's values.
struct CoordinatorSettings {
  /// The program, as summary.json records it ("robin-run" or "robin-coordinator").
  std::string tool = "robin-coordinator";
  std::filesystem::path case_file;
  std::filesystem::path output_directory;
  bool overwrite = false;  // --overwrite: replace an earlier run's results (result_directory.hpp)
  std::optional<double> relaxation;
  std::optional<double> relaxation1, relaxation2;
  std::optional<AccelerationMethod> acceleration;  // "iqn-ils", "aitken" or "none"
  std::optional<CouplingAlgorithm> algorithm;      // coupling/coupling_scheme.hpp
  std::optional<double> alpha;                     // "robin-constant"
  std::optional<ContactBodyChoice> contact_body;   // "dirichlet-neumann": "1", "2" or "auto"
  std::optional<StoppingRule> stopping;            // "either-sequence" or "joint"
  std::optional<double> tolerance;
  std::optional<int> max_iterations;
  std::optional<InitialObstacle> initial_obstacle;  // "gap" or "zero"
  std::optional<double> timeout_seconds;            // deadline of each interface-sized request
  std::optional<double> setup_timeout_seconds;      // deadline of the setup and fields requests
  double heartbeat_timeout_seconds = 10.0;          // remote_port.hpp; 0: no heartbeat
  std::string log_level = "info";
  bool quiet = false;  // --quiet: the coordinator logs only warnings and errors
  /// --set KEY=VALUE: overrides of case-file keys, in order (coupling/case_file_overrides.hpp).
  std::vector<std::string> overrides;
  /// --resume DIR: continue the run checkpointed in DIR (run_resume.hpp); DIR is then also the
  /// output directory.
  std::filesystem::path resume_directory;
  /// Filled by load_case on --resume: the checkpoint to continue from.
  std::shared_ptr<const RunCheckpoint> resume;
  /// --max-server-restarts: how often a lost server of each body is replaced (robin-run
  /// restarts it, robin-coordinator waits for it) before the run fails.
  int max_server_restarts = 2;
  /// --server-grace-period (robin-coordinator): how long to wait for a lost server to answer
  /// at its endpoint again.
  double server_grace_period_seconds = 30.0;
  /// How the bodies' meshing and setup progress is shown (progress_display.hpp); null: plain
  /// log lines.
  std::shared_ptr<ProgressDisplay> display;
  /// robin-run's local robin-subdomain servers, started with --output-root = the output
  /// directory: each writes its body's .vtu into the run's staging area itself, in parallel, and
  /// replies without the fields (RunContinuation::server_write_directory). False: the coordinator
  /// writes every file (servers given by endpoint, or started elsewhere or from another
  /// executable).
  bool servers_write_fields = false;
};

/// How run_coordinator replaces the server of a body that was lost mid-run (robin-run:
/// restarts its process; robin-coordinator: waits for it at its endpoint). Empty hooks: a lost
/// server fails the run.
struct ServerRestart {
  /// Whether the server of `body` is gone, given whether its connection dropped.
  std::function<bool(int body, bool connection_lost)> lost;
  /// Brings a server for `body` back and returns its endpoint; throws std::runtime_error
  /// saying why it cannot.
  std::function<std::string(int body)> restart;
};

/// Adds CASE, --output, --relaxation, --tolerance, --max-iterations, --initial-obstacle,
/// --timeout, --setup-timeout, --log-level, --quiet and --set to `app`, and the exit codes to
/// its footer.
void add_coordinator_options(CLI::App& app, CoordinatorSettings& settings);

/// The case's [coupling] options with the command-line overrides applied.
CouplingOptions merged_coupling_options(const CouplingOptions& from_case,
                                        const CoordinatorSettings& settings);

/// Creates the logger "coordinator" (standard error, timestamps, `level`; through `display`'s
/// sink when it is live) and makes it the default logger. Throws std::invalid_argument for an
/// unknown level.
std::shared_ptr<spdlog::logger> make_coordinator_logger(const std::string& level,
                                                        const ProgressDisplay* display = nullptr);

/// One line per iteration: the value the stopping test compares with the tolerance (the
/// smallest of the joint state's and the obstacle sequences' largest residuals with
/// "either-sequence" stopping, the joint state's otherwise) and whose it is, each obstacle
/// sequence's largest residual, the joint state's residuals (%.2e), the active set sizes, QP
/// iterations, seconds and the acceleration's state.
std::string progress_line(const IterationRecord& record, const CouplingOptions& options);

/// Reads the case file; logs the error (an InputError naming file, line and field) and returns
/// nullopt when it is unusable, after recording the failure in the output directory's
/// summary.json (result_directory.hpp, record_failed_start; not when the directory cannot be
/// used). With --resume, first reads the checkpoint and completes `settings` from it
/// (run_resume.hpp), logging why a resume is refused; a refused resume leaves the directory
/// as the interrupted run left it.
std::optional<CaseDefinition> load_case(CoordinatorSettings& settings);

/// Runs the case against the servers at `endpoints`, one per body in body order (the first gets
/// body 1), writes the result files into the output directory and returns the exit code (see
/// the file comment). The servers' runs are always ended. `channels[i]` sets the transport and
/// the waiting hooks of port i (empty: the defaults for every port); the iteration also stops
/// between iterations on a stop signal.
/// `restart` replaces lost servers (at most settings.max_server_restarts per body); the run
/// checkpoints every iteration into the output directory and, with settings.resume,
/// continues from that checkpoint.
/// `servers_done` (when set) is called once, on this thread, when no request goes to the servers
/// any more: after a run that produced results, once the fields are in and every server's run is
/// ended, before the result files are written (so that robin-run can stop its servers
/// meanwhile); after a failed run, just before returning. It is not called when no run starts
/// (wrong number of endpoints, unusable output directory).
int run_coordinator(const CaseDefinition& definition, const CoordinatorSettings& settings,
                    const std::vector<std::string>& endpoints,
                    const std::vector<ChannelOptions>& channels = {},
                    const ServerRestart& restart = {},
                    const std::function<void()>& servers_done = {});

/// Logs a failure and returns its exit code: 128 + signal once a stop signal was received
/// (whatever exception the interruption surfaced as), 1 otherwise.
int failure_exit_code(const std::exception& error);

}  // namespace robin
