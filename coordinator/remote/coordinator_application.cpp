#include "remote/coordinator_application.hpp"

#include <fmt/ranges.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "coupling/case_file_overrides.hpp"
#include "coupling/result_directory.hpp"
#include "coupling/run_outputs.hpp"
#include "numerics/errors.hpp"
#include "remote/remote_port.hpp"
#include "remote/run_interruption.hpp"
#include "remote/run_resume.hpp"

namespace robin {

namespace {

const char* const exit_code_footer =
    "Exit codes: 0 converged; 3 iteration limit reached; 4 diverged; 5 stagnated (results are "
    "written in these cases); 1 bad input or a server failure; 2 bad command line; 130/143 "
    "stopped by SIGINT/SIGTERM.";

/// The option `name` (TEXT, one of the texts of `order`, as listed in the help and in the
/// error for another value), stored in `value` as the enum (coupling/coupling_choices.hpp).
/// `order` empty: every choice, in the case file's order.
template <OptionChoice Choice>
void add_choice_option(CLI::App& app, const std::string& name, std::optional<Choice>& value,
                       const std::string& description, const std::vector<Choice>& order = {}) {
  std::vector<std::string> texts;
  for (const Choice choice : order) texts.push_back(to_string(choice));
  if (order.empty()) texts = choice_texts<Choice>();
  app.add_option_function<std::string>(
         name,
         [&value](const std::string& text) { value = choice_from_text<Choice>(text).value(); },
         description)
      ->check(CLI::IsMember(texts));
}

/// Accepts numbers strictly between `low` and `high` (the case file's ranges).
CLI::Validator open_interval(double low, double high) {
  return CLI::Validator(
      [low, high](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return "'" + text + "' is not a number";
        if (value > low && value < high) return "";
        return "must be in (" + fmt::format("{}", low) + ", " + fmt::format("{}", high) +
               "), got " + text;
      },
      "in (" + fmt::format("{}", low) + ", " + fmt::format("{}", high) + ")");
}

/// Accepts a directory that exists or can be created, and in which a file can be written (the
/// results are written at the end of a run: a typo must fail before the servers start). Leaves
/// no trace: the directories it had to create for the test are removed again.
CLI::Validator writable_directory() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::vector<std::filesystem::path> created;  // innermost first
        std::error_code error;
        for (std::filesystem::path path = std::filesystem::absolute(text, error);
             !path.empty() && !std::filesystem::exists(path, error); path = path.parent_path()) {
          created.push_back(path);
          if (path == path.parent_path()) break;
        }
        std::string problem;
        std::filesystem::create_directories(text, error);
        const std::filesystem::path probe =
            std::filesystem::path(text) / (".robin-write-test-" + std::to_string(::getpid()));
        if (error) {
          problem = "cannot create the directory '" + text + "': " + error.message();
        } else if (!std::ofstream(probe)) {
          problem = "cannot write into the directory '" + text + "'";
        }
        std::filesystem::remove(probe, error);
        for (const std::filesystem::path& path : created) std::filesystem::remove(path, error);
        return problem;
      },
      "DIR");
}

/// Accepts finite numbers > 0 (CLI11's PositiveNumber prints its range as 300 digits).
CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return "'" + text + "' is not a number";
        if (value > 0.0 && std::isfinite(value)) return "";
        return "must be a finite number > 0, got " + text;
      },
      "> 0");
}

std::shared_ptr<spdlog::logger> coordinator_logger() {
  auto log = spdlog::get("coordinator");
  return log ? log : make_coordinator_logger("info");
}

/// The run's display; a plain one when the settings have none.
std::shared_ptr<ProgressDisplay> display_of(const CoordinatorSettings& settings) {
  return settings.display ? settings.display
                          : std::make_shared<ProgressDisplay>(ProgressOutput::plain);
}

RunObserver make_observer(const std::shared_ptr<spdlog::logger>& log,
                          const CouplingOptions& options,
                          const std::shared_ptr<ProgressDisplay>& display) {
  RunObserver observer;
  observer.stage = [log](const std::string& text) { log->info("{}", text); };
  observer.warning = [log](const std::string& text) { log->warn("{}", text); };
  observer.iteration = [log, options, display](const IterationRecord& record) {
    display->finish();  // the setup is over: its status lines stay as they are
    log->info("{}", progress_line(record, options));
    throw_if_stop_requested();
  };
  return observer;
}

/// The value the stopping test compares with the tolerance (IterationRecord::progress) and the
/// state it belongs to: "the joint state" or "obstacle sequence k".
std::pair<double, std::string> stopping_value(const IterationRecord& record,
                                              const CouplingOptions& options) {
  std::pair<double, std::string> value{record.largest(), "the joint state"};
  if (options.stopping != StoppingRule::either_sequence) return value;
  for (std::size_t k = 0; k < record.sequences.size(); ++k) {
    if (record.sequences[k].largest() < value.first) {
      value = {record.sequences[k].largest(), "obstacle sequence " + std::to_string(k + 1)};
    }
  }
  return value;
}

/// Shows each server's progress during setup and fields from its StatusReplies. Plain: a line
/// when a stage begins (with the body's DOFs) and, while a stage lasts, one every 10 s, so that
/// a long setup never looks hung; live: the body's status line, rewritten at every reply. One
/// reporter per port (it keeps that port's last stage).
std::function<void(const std::string&, const std::string&, const ServerStatus&)> progress_reporter(
    const std::shared_ptr<spdlog::logger>& log, const std::shared_ptr<ProgressDisplay>& display) {
  struct Shown {
    std::string stage;
    double reported_at = 0.0;  // stage_seconds of the last line about this stage
  };
  auto shown = std::make_shared<Shown>();
  return [log, shown, display](const std::string& body, const std::string& step,
                               const ServerStatus& status) {
    if (!status.busy || status.stage.empty()) return;
    const std::string dofs =
        status.dof_count > 0 ? fmt::format(" ({} DOFs)", status.dof_count) : std::string();
    std::string line;
    if (status.stage != shown->stage) {
      shown->stage = status.stage;
      shown->reported_at = status.stage_seconds;
      line = fmt::format("body '{}' {}: {}{}, {:.1f} s into the request", body, step, status.stage,
                         dofs, status.request_seconds);
    } else if (status.stage_seconds - shown->reported_at >= 10.0) {
      shown->reported_at = status.stage_seconds;
      line = fmt::format("body '{}' {}: still in {}{} after {:.0f} s", body, step, status.stage,
                         dofs, status.stage_seconds);
    }
    display->update(body, {step + ": " + status.stage, status.dof_count, status.request_seconds},
                    line, *log);
  };
}

/// Logs how the run ended and where the results are; returns the exit code of its status.
/// Converged: which state the stopping test accepted, its largest residual against the
/// tolerance, and the residuals of that state (the one the result files hold).
int report_outcome(const CoupledRunResult& result, const CoordinatorSettings& settings,
                   spdlog::logger& log) {
  const RobinResult& iteration = result.iteration;
  const CouplingOptions& options = result.options;
  const std::string stopping =
      fmt::format("{} stopping, tolerance {:.0e}", to_string(options.stopping), options.tolerance);
  std::string outcome =
      fmt::format("{} after {} iterations", to_string(iteration.status), iteration.history.size());
  if (iteration.history.empty()) {
    outcome += " (" + stopping + ")" + (iteration.message.empty() ? "" : ": " + iteration.message);
  } else if (iteration.status == IterationStatus::converged) {
    const IterationRecord& last = iteration.history.back();
    if (const SequenceResiduals* accepted = iteration.accepted_sequence()) {
      outcome += fmt::format(
          ": obstacle sequence {} reached {:.1e} < tolerance {:.0e} ({}; {}); final state: "
          "penetration {:.1e}, complementarity {:.1e}, obstacle change {:.1e}, force error "
          "estimate {:.1e}",
          iteration.completed_by_sequence, accepted->largest(), options.tolerance,
          to_string(options.stopping) + " stopping",
          result.outputs.size() == 2
              ? fmt::format("body {} takes its contact force", 3 - iteration.completed_by_sequence)
              : std::string("the other bodies take their neighbours' contact forces"),
          accepted->penetration, accepted->complementarity, accepted->obstacle_change,
          accepted->force_error);
    } else {
      outcome += fmt::format(
          ": the joint state reached {:.1e} < tolerance {:.0e} ({} stopping); final state: "
          "obstacle change {:.1e}, penetration {:.1e}, force balance {:.1e}, complementarity "
          "{:.1e}, correction {:.1e}",
          last.largest(), options.tolerance, to_string(options.stopping), last.obstacle_change,
          last.penetration, last.force_balance, last.complementarity, last.correction);
    }
  } else {
    const auto [value, state] = stopping_value(iteration.history.back(), options);
    outcome += fmt::format(" ({}): the stopping test's last value {:.1e} ({}){}", stopping, value,
                           state, iteration.message.empty() ? "" : "; " + iteration.message);
  }
  int code = exit_code(iteration.status);
  if (code == 0) {
    log.info("{}", outcome);
  } else {
    log.warn("{}", outcome);
  }
  if (result.excluded_clearance.relative_penetration > excluded_pair_penetration_limit) {
    log.error("{}", result.excluded_clearance.description);
    code = 1;
  }
  double compute = 0.0, round_trip = 0.0;
  for (const PortTimings& timings : result.port_timings) {
    compute += timings.compute_seconds;
    round_trip += timings.round_trip_seconds;
  }
  log.info(
      "wall time {:.3f} s (setup {:.3f} s, iteration {:.3f} s); summed over the {} servers: "
      "compute {:.3f} s, request round trips {:.3f} s",
      result.total_seconds, result.setup_seconds, iteration.wall_seconds,
      result.port_timings.size(), compute, round_trip);
  log.info("results in {} (open solution.pvd in ParaView)", settings.output_directory.string());
  return code;
}

}  // namespace

void add_coordinator_options(CLI::App& app, CoordinatorSettings& settings) {
  app.add_option("case", settings.case_file,
                 "case file (TOML, see docs/case-format.md); with --resume, the checkpointed "
                 "one by default")
      ->check(CLI::ExistingFile);
  CLI::Option* output =
      app.add_option("--output,-o", settings.output_directory, "directory for the result files")
          ->check(writable_directory());
  CLI::Option* overwrite =
      app.add_flag("--overwrite", settings.overwrite,
                   "replace the results of an earlier run in the output directory (a directory "
                   "holding files is refused otherwise)");
  app.add_option("--resume", settings.resume_directory,
                 "continue the run whose checkpoint is in DIR (after the coordinator died or "
                 "was stopped) instead of starting one; DIR is the output directory; a changed "
                 "case file or option is refused")
      ->type_name("DIR")
      ->excludes(output)
      ->excludes(overwrite);
  app.add_option("--max-server-restarts", settings.max_server_restarts,
                 "how often a server lost mid-run is replaced per body (robin-run restarts it, "
                 "robin-coordinator waits for it) before the run fails; 0: never")
      ->check(CLI::NonNegativeNumber);
  // Refused before any server starts: a typo must not cost a setup, an earlier run's files
  // must not be mixed with this run's.
  app.final_callback([&settings] {
    if (!settings.resume_directory.empty()) {
      settings.output_directory = settings.resume_directory;
      if (!std::filesystem::exists(settings.resume_directory / checkpoint_file_name)) {
        throw CLI::ValidationError(
            "--resume", "'" + settings.resume_directory.string() +
                            "' holds no checkpoint.json: nothing to resume there (a run "
                            "writes it after its first iteration and removes it once its "
                            "results are written)");
      }
      return;
    }
    if (settings.case_file.empty()) throw CLI::RequiredError("case");
    if (settings.output_directory.empty()) throw CLI::RequiredError("--output");
    try {
      // logs/: the servers' logs of this run when a launcher (deploy/remote-servers.sh) wrote
      // them there before starting the coordinator
      check_result_directory(
          settings.output_directory,
          settings.overwrite ? ExistingResults::overwrite : ExistingResults::refuse, {"logs"});
    } catch (const ResultDirectoryError& error) {
      throw CLI::ValidationError("--output", error.what());
    }
  });
  app.add_option("--relaxation", settings.relaxation,
                 "relaxation delta of the obstacle update, in (0, 2)")
      ->check(open_interval(0.0, 2.0));
  app.add_option("--relaxation1", settings.relaxation1, "relaxation delta of body 1's obstacle")
      ->check(open_interval(0.0, 2.0));
  app.add_option("--relaxation2", settings.relaxation2, "relaxation delta of body 2's obstacle")
      ->check(open_interval(0.0, 2.0));
  add_choice_option(
      app, "--acceleration", settings.acceleration,
      "obstacle update: 'iqn-ils' (quasi-Newton), 'aitken' or 'none' (the "
      "paper's fixed relaxation); default from the case file (docs/case-format.md)",
      {AccelerationMethod::iqn_ils, AccelerationMethod::aitken, AccelerationMethod::none});
  add_choice_option(app, "--algorithm", settings.algorithm,
                    "coupling algorithm: 'robin' (the paper's Steklov-Poincare choice, default), "
                    "'robin-constant' (needs --alpha), 'dirichlet-neumann' or 'neumann-neumann'");
  app.add_option("--alpha", settings.alpha,
                 "'robin-constant': the constant alpha_S (length per pressure)")
      ->check(positive());
  add_choice_option(app, "--contact-body", settings.contact_body,
                    "'dirichlet-neumann': the body that solves the contact problem: 1, 2 or auto");
  add_choice_option(app, "--stopping", settings.stopping,
                    "'either-sequence' (default: stop when one obstacle sequence's complete state "
                    "converged) or 'joint' (the paper's test on both)");
  app.add_option("--tolerance", settings.tolerance, "tolerance on every scaled residual")
      ->check(positive());
  app.add_option("--max-iterations", settings.max_iterations, "iteration limit")->check(positive());
  add_choice_option(app, "--initial-obstacle", settings.initial_obstacle,
                    "initial obstacles: 'gap' (g0 = d) or 'zero' (g0 = 0)");
  app.add_option("--timeout", settings.timeout_seconds,
                 "deadline of each interface-sized request to a server (contact solve, "
                 "correction, handshake), in seconds; default from the case file, 60")
      ->check(positive());
  app.add_option("--setup-timeout", settings.setup_timeout_seconds,
                 "deadline of the mesh-sized requests (body setup: meshing, assembly, "
                 "factorization; fields), in seconds; default from the case file, 3600")
      ->check(positive());
  app.add_option("--heartbeat-timeout", settings.heartbeat_timeout_seconds,
                 "during setup and fields, a server that does not answer StatusRequest for this "
                 "long (seconds) is declared hung (servers of protocol 2.1; 0: off)")
      ->check(CLI::NonNegativeNumber);
  CLI::Option* log_level =
      app.add_option("--log-level", settings.log_level, "trace, debug, info, warn, error, off")
          ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_flag("--quiet,-q", settings.quiet, "log only warnings and errors")->excludes(log_level);
  add_override_option(app, settings.overrides);
  app.footer(exit_code_footer);
}

CouplingOptions merged_coupling_options(const CouplingOptions& from_case,
                                        const CoordinatorSettings& settings) {
  CouplingOptions options = from_case;
  if (settings.relaxation) {
    // --relaxation sets the shared delta; it overrides per-body values from the case file.
    options.relaxation = *settings.relaxation;
    options.relaxation1.reset();
    options.relaxation2.reset();
  }
  if (settings.relaxation1) options.relaxation1 = *settings.relaxation1;
  if (settings.relaxation2) options.relaxation2 = *settings.relaxation2;
  if (settings.acceleration) options.acceleration.method = *settings.acceleration;
  if (settings.algorithm) options.algorithm = *settings.algorithm;
  if (settings.alpha) options.alpha = *settings.alpha;
  if (settings.contact_body) options.contact_body = *settings.contact_body;
  if (settings.stopping) options.stopping = *settings.stopping;
  if (settings.tolerance) options.tolerance = *settings.tolerance;
  if (settings.max_iterations) options.max_iterations = *settings.max_iterations;
  if (settings.initial_obstacle) options.initial_obstacle = *settings.initial_obstacle;
  if (settings.timeout_seconds) options.request_timeout_seconds = *settings.timeout_seconds;
  if (settings.setup_timeout_seconds)
    options.setup_timeout_seconds = *settings.setup_timeout_seconds;
  return options;
}

std::shared_ptr<spdlog::logger> make_coordinator_logger(const std::string& level,
                                                        const ProgressDisplay* display) {
  auto log = make_progress_logger("coordinator", level, display);
  spdlog::set_default_logger(log);
  return log;
}

std::string progress_line(const IterationRecord& record, const CouplingOptions& options) {
  const auto [value, state] = stopping_value(record, options);
  std::string sequences;
  if (record.sequences.size() == 2) {
    sequences = fmt::format("; obstacle sequences {:.2e}/{:.2e}", record.sequences[0].largest(),
                            record.sequences[1].largest());
  }
  return fmt::format(
      "iteration {}: stopping test {:.2e} ({}; tolerance {:.0e}){}; joint state: obstacle change "
      "{:.2e}, penetration {:.2e}, force balance {:.2e}, complementarity {:.2e}, correction "
      "{:.2e}; active {}, QP iterations {}, {:.3f} s; {}",
      record.iteration, value, state, options.tolerance, sequences, record.obstacle_change,
      record.penetration, record.force_balance, record.complementarity, record.correction,
      fmt::join(record.active, "/"), fmt::join(record.qp_iterations, "/"), record.seconds,
      record.acceleration_state);
}

namespace {

/// summary.json "failed" naming the case file's error; nothing when the directory is unusable.
void record_unusable_case(const CoordinatorSettings& settings, const std::string& message) {
  try {
    record_failed_start(settings.output_directory,
                        settings.overwrite ? ExistingResults::overwrite : ExistingResults::refuse,
                        settings.tool, settings.case_file,
                        in_case_file(settings.case_file, message));
  } catch (const std::exception&) {
    // the output directory cannot be used: the error was logged, there is nowhere to record it
  }
}

}  // namespace

std::optional<CaseDefinition> load_case(CoordinatorSettings& settings) {
  try {
    if (!settings.resume_directory.empty()) {
      settings.resume = std::make_shared<const RunCheckpoint>(prepare_resume(settings));
    }
    CaseDefinition definition = read_case_file(settings.case_file, settings.overrides);
    if (settings.resume) check_resumable(definition, *settings.resume);
    return definition;
  } catch (const std::exception& error) {
    coordinator_logger()->error("{}", error.what());
    if (settings.resume_directory.empty()) record_unusable_case(settings, error.what());
    return std::nullopt;
  }
}

int failure_exit_code(const std::exception& error) {
  auto log = coordinator_logger();
  if (const int signal_number = stop_signal(); signal_number != 0) {
    log->warn("{}", RunInterrupted(signal_number).what());
    return interrupted_exit_code(signal_number);
  }
  log->error("{}", error.what());
  return 1;
}

namespace {

/// The directory's record of a resumed run, and a log line about it.
void record_resume(ResultDirectory& results, const RunCheckpoint& checkpoint, spdlog::logger& log) {
  nlohmann::json from = {{"run_id", checkpoint.run_id},
                         {"first_run_id", checkpoint.first_run_id},
                         {"first_started", checkpoint.started},
                         {"iteration", checkpoint.iteration.iteration}};
  if (checkpoint.step > 0) from["load_step"] = checkpoint.step;
  results.add_to_record("resumed_from", from);
  log.info("resuming run {} after iteration {}{} (checkpoint in {})", checkpoint.run_id,
           checkpoint.iteration.iteration,
           checkpoint.step > 0 ? fmt::format(" of load step {}", checkpoint.step) : "",
           results.directory().string());
}

/// The identity of this run in its checkpoints (checkpoint.hpp); the loop state is added per
/// iteration.
RunCheckpoint checkpoint_identity(const CaseDefinition& definition,
                                  const CoordinatorSettings& settings,
                                  const ResultDirectory& results) {
  RunCheckpoint identity;
  identity.run_id = results.run_id();
  identity.first_run_id = settings.resume ? settings.resume->first_run_id : results.run_id();
  identity.started = settings.resume ? settings.resume->started : utc_timestamp();
  identity.case_file = std::filesystem::absolute(definition.file).string();
  identity.case_sha256 = file_sha256(definition.file);
  std::ifstream file(definition.file, std::ios::binary);
  identity.case_text.assign(std::istreambuf_iterator<char>(file), {});
  identity.overrides = definition.overrides;
  identity.options = computation_options(settings);
  return identity;
}

}  // namespace

int run_coordinator(const CaseDefinition& definition, const CoordinatorSettings& settings,
                    const std::vector<std::string>& endpoints,
                    const std::vector<ChannelOptions>& channels, const ServerRestart& restart,
                    const std::function<void()>& servers_done) {
  auto log = coordinator_logger();
  const std::size_t body_count = definition.bodies.size();
  if (endpoints.size() != body_count || (!channels.empty() && channels.size() != body_count)) {
    log->error("{}: the case has {} bodies but {} servers were given (one per body, in body order)",
               definition.file.string(), body_count, endpoints.size());
    return 2;
  }
  const CouplingOptions options = merged_coupling_options(definition.coupling, settings);
  const std::shared_ptr<ProgressDisplay> display = display_of(settings);
  display->set_bodies(body_names(definition));
  CaseDefinition observed = definition;  // tells the display as each body's mesh is made
  observed.meshing = meshing_reporter(definition, display, log);
  std::unique_ptr<ResultDirectory> results;
  const ExistingResults policy = settings.resume      ? ExistingResults::resume
                                 : settings.overwrite ? ExistingResults::overwrite
                                                      : ExistingResults::refuse;
  RunCheckpoint checkpoint;
  try {
    results = std::make_unique<ResultDirectory>(settings.output_directory, policy, settings.tool,
                                                definition.file);
    if (settings.resume) record_resume(*results, *settings.resume, *log);
    checkpoint = checkpoint_identity(definition, settings, *results);
  } catch (const std::exception& error) {
    return failure_exit_code(error);
  }
  if (!results->leftover_files().empty()) {
    log->warn("the output directory {} also holds files that are not results of a run: {}",
              settings.output_directory.string(), fmt::join(results->leftover_files(), ", "));
  }
  std::vector<std::unique_ptr<RemotePort>> ports(body_count);
  std::vector<std::unique_ptr<RemotePort>> replaced_ports;  // kept until the run ends
  const auto make_port = [&](int alpha, const std::string& endpoint) {
    RemotePortOptions port_options;
    port_options.request_timeout_seconds = options.request_timeout_seconds;
    port_options.setup_timeout_seconds = options.setup_timeout_seconds;
    if (!channels.empty()) port_options.channel = channels[static_cast<std::size_t>(alpha)];
    port_options.heartbeat_timeout_seconds = settings.heartbeat_timeout_seconds;
    port_options.on_status = progress_reporter(log, display);
    const std::string& body = definition.bodies[static_cast<std::size_t>(alpha)].definition.name;
    ports[static_cast<std::size_t>(alpha)] =
        std::make_unique<RemotePort>(endpoint, body, port_options);
    log->info("body {} '{}' on server {}", alpha + 1, body, endpoint);
  };
  RunContinuation continuation;
  if (settings.resume) {
    continuation.resume = &settings.resume->iteration;
    continuation.resume_steps = &settings.resume->steps;
    checkpoint.steps = settings.resume->steps;
  }
  BackgroundCheckpointWriter writer(settings.output_directory);
  continuation.checkpoint = [&](const IterationCheckpoint& iteration) {
    checkpoint.step =
        definition.loading.stepped() ? static_cast<int>(checkpoint.steps.size()) + 1 : 0;
    checkpoint.iteration = iteration;
    writer.write(checkpoint);
  };
  continuation.step_completed = [&](const LoadStepCheckpoint& step) {
    checkpoint.steps.push_back(step);
  };
  if (settings.servers_write_fields) {
    continuation.server_write_directory = results->staging().filename();
  }
  std::vector<int> restarts(body_count, 0);
  nlohmann::json restart_records = nlohmann::json::array();
  if (restart.lost && restart.restart && settings.max_server_restarts > 0) {
    continuation.replacement.lost = [&](int body) {
      return restart.lost(body, ports[static_cast<std::size_t>(body)]->connection_lost());
    };
    continuation.replacement.replace = [&](int body, const std::string& failure) {
      const auto index = static_cast<std::size_t>(body);
      const std::string& name = definition.bodies[index].definition.name;
      if (restarts[index] >= settings.max_server_restarts) {
        throw PortError(
            fmt::format("{}\n  the server of body '{}' was lost again after {} restarts "
                        "(--max-server-restarts {}): the run stops",
                        failure, name, restarts[index], settings.max_server_restarts));
      }
      ++restarts[index];
      log->warn("lost the server of body '{}': {}; replacing it (restart {} of {})", name, failure,
                restarts[index], settings.max_server_restarts);
      std::string endpoint;
      try {
        endpoint = restart.restart(body);
      } catch (const std::exception& error) {
        throw PortError(fmt::format(
            "{}\n  the server of body '{}' cannot be replaced (restart "
            "{} of {}): {}",
            failure, name, restarts[index], settings.max_server_restarts, error.what()));
      }
      restart_records.push_back({{"body", name},
                                 {"restart", restarts[index]},
                                 {"of", settings.max_server_restarts},
                                 {"endpoint", endpoint},
                                 {"failure", failure}});
      results->add_to_record("server_restarts", restart_records);
      replaced_ports.push_back(std::move(ports[index]));
      make_port(body, endpoint);
      return static_cast<SubdomainPort*>(ports[index].get());
    };
  }
  bool servers_released = false;
  // Ends every server's run (once per port) and tells servers_done, the first time only.
  const auto release_servers = [&] {
    for (auto& port : ports) {
      if (port) port->end_run();
    }
    if (!servers_released && servers_done) servers_done();
    servers_released = true;
  };
  int code = 1;
  try {
    std::vector<SubdomainPort*> run_ports;
    for (std::size_t alpha = 0; alpha < body_count; ++alpha) {
      make_port(static_cast<int>(alpha), endpoints[alpha]);
      run_ports.push_back(ports[alpha].get());
    }
    const CoupledRunResult result = run_coupled_case(
        observed, run_ports, options, make_observer(log, options, display), continuation);
    writer.finish();  // the last checkpoint is on disk (or its error thrown) before the outputs
    display->finish();
    release_servers();  // the fields are in: the servers can stop while the files are written
    write_coupled_outputs(*results, definition, result);
    code = report_outcome(result, settings, *log);
  } catch (const InputError& error) {  // e.g. unmatched contact nodes: name the case file
    display->finish();
    const InputError named(in_case_file(definition.file, error.what()));
    code = failure_exit_code(named);
    results->fail(stop_signal() != 0 ? RunFailure::interrupted : RunFailure::failed, named.what());
  } catch (const std::exception& error) {
    display->finish();
    code = failure_exit_code(error);
    results->fail(stop_signal() != 0 ? RunFailure::interrupted : RunFailure::failed, error.what());
  }
  release_servers();
  return code;
}

}  // namespace robin
