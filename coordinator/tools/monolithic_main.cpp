// robin-monolithic CASE --output DIR [--set KEY=VALUE ...] [--quiet]
// The single-process reference solver of the whole contact problem (paper (5)): two bodies, or N
// bodies on the contact graph of the case's [[interface]] tables.
// Exit codes: 0 converged (or --help, --version); 1 bad input or failure (also: a Dirichlet
// condition drives an excluded contact pair into penetration; the results are written); 2 bad
// command line; 3 the contact QP did not converge (the results are written); 130 / 143 stopped
// by SIGINT / SIGTERM (summary.json then says "interrupted").

#include <fmt/ranges.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "coupling/case_file_overrides.hpp"
#include "coupling/interface_outputs.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/result_directory.hpp"
#include "coupling/result_files.hpp"
#include "coupling/robin_iteration.hpp"
#include "coupling/run_profile.hpp"
#include "coupling/step_outputs.hpp"
#include "numerics/errors.hpp"
#include "remote/progress_display.hpp"
#include "remote/run_interruption.hpp"
#include "remote/stop_signal_watcher.hpp"

namespace {

using robin::LocalProblem;
using robin::MonolithicResult;

/// The keys of summary.json about the contact (robin-coordinator writes the same): per
/// interface in "interfaces"; for one interface also at the top level, as always.
void add_contact_summary(nlohmann::json& summary, const LocalProblem& problem,
                         const robin::CouplingState& state) {
  const robin::GraphCoupling& coupling = problem.coupling;
  const std::vector<std::string> names = robin::body_names(problem.definition);
  Eigen::Index rows = 0;
  for (const robin::ContactPairing& pairing : coupling.pairings) {
    rows += static_cast<Eigen::Index>(pairing.size());
  }
  summary["contact_pairs"] = rows;
  summary["contact_discretization"] =
      fmt::format("{}", fmt::join(robin::describe_interfaces(coupling, names), "; "));
  summary["excluded_pairs"] = robin::excluded_pair_lines(coupling);
  summary["initial_overlap"] =
      fmt::format("{}", fmt::join(robin::overlap_warnings(coupling), "; "));
  const nlohmann::json interfaces = robin::interfaces_json(
      coupling, robin::interface_definitions(problem.definition), names, state);
  summary["contact_force_resultant"] =
      coupling.pairings.size() == 1 ? interfaces[0]["contact_force_resultant"] : nullptr;
  summary["interfaces"] = interfaces;
}

/// Body `alpha`'s rigid amplitudes in `result` (empty for a body without rigid motions).
Eigen::VectorXd rigid_amplitudes_of(const MonolithicResult& result, std::size_t alpha) {
  return alpha < result.rigid_amplitudes.size() ? result.rigid_amplitudes[alpha]
                                                : Eigen::VectorXd();
}

/// The sum of body `alpha`'s reactions at its prescribed degrees of freedom in the solution.
Eigen::Vector3d reaction_resultant(const LocalProblem& problem, const MonolithicResult& result,
                                   const robin::CouplingState& state, std::size_t alpha) {
  const robin::BodySolver& body = *problem.bodies[alpha];
  const Eigen::VectorXd reactions = body.reactions(
      body.displacement(state.bodies[alpha].contact_force, rigid_amplitudes_of(result, alpha)));
  const int dimension = body.mesh().dimension;
  Eigen::Vector3d resultant = Eigen::Vector3d::Zero();
  resultant.head(dimension) =
      reactions.reshaped(dimension, reactions.size() / dimension).rowwise().sum();
  return resultant;
}

nlohmann::json make_summary(const LocalProblem& problem, const MonolithicResult& result,
                            double total_seconds) {
  nlohmann::json summary;
  summary["method"] = "monolithic";
  summary["case"] = problem.definition.file.string();
  summary["overrides"] = problem.definition.overrides;  // --set KEY=VALUE, in order
  summary["converged"] = result.qp.status == robin::QpStatus::converged;
  // how the run ended, in robin-coordinator's words (a QP that did not converge hit its limit)
  summary["status"] = robin::to_string(result.qp.status == robin::QpStatus::converged
                                           ? robin::IterationStatus::converged
                                           : robin::IterationStatus::max_iterations);
  summary["qp_status"] = robin::to_string(result.qp.status);
  summary["iterations"] = result.qp.iterations;
  summary["operator_applications"] = result.qp.operator_applications;
  const robin::CouplingState state =
      robin::monolithic_state(problem.coupling.problem.graph, result);
  add_contact_summary(summary, problem, state);
  summary["residuals"] = {{"penetration", result.residuals.penetration},
                          {"force_balance", result.residuals.force_balance},
                          {"complementarity", result.residuals.complementarity}};
  double assembly = 0, factorization = 0;
  for (std::size_t alpha = 0; alpha < problem.bodies.size(); ++alpha) {
    const auto& body = problem.bodies[alpha];
    const Eigen::Vector3d reaction = reaction_resultant(problem, result, state, alpha);
    const int dimension = body->mesh().dimension;
    summary["bodies"].push_back(
        {{"name", body->name()},
         {"dofs", body->free_dof_count()},
         {"nodes", body->mesh().node_count()},
         {"elements", body->mesh().element_count()},
         {"factor_nonzeros", body->factor_nonzeros()},
         {"applied_force", robin::vector_json(body->applied_force(), dimension)},
         {"reaction_resultant", robin::vector_json(reaction, dimension)}});
    assembly += body->timings().assembly_seconds;
    factorization += body->timings().ordering_seconds + body->timings().factorization_seconds +
                     body->timings().interface_seconds;
  }
  summary["timings"] = {{"mesh", problem.mesh_seconds},
                        {"assembly", assembly},
                        {"factorization", factorization},
                        {"solve", result.solve_seconds},
                        {"total", total_seconds}};
  return summary;
}

/// The index of the mesh node nearest to `point`.
Eigen::Index nearest_node(const robin::Mesh& mesh, const Eigen::Vector3d& point) {
  Eigen::Index nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < mesh.nodes.size(); ++k) {
    const double distance = (mesh.nodes[k] - point).squaredNorm();
    if (distance < best) {
      best = distance;
      nearest = static_cast<Eigen::Index>(k);
    }
  }
  return nearest;
}

/// The excluded pairs in the solution (node ids are this process's mesh node indices).
robin::ExcludedPairClearance excluded_pair_clearance(const LocalProblem& problem,
                                                     const MonolithicResult& result) {
  const robin::ContactGraph& graph = problem.coupling.problem.graph;
  const robin::CouplingState state = robin::monolithic_state(graph, result);
  std::vector<Eigen::VectorXd> displacements;
  for (std::size_t alpha = 0; alpha < problem.bodies.size(); ++alpha) {
    displacements.push_back(problem.bodies[alpha]->displacement(
        state.bodies[alpha].contact_force, rigid_amplitudes_of(result, alpha)));
  }
  const auto displacement_of = [&](int body, const robin::ContactPair& pair, int side) {
    const auto index = static_cast<std::size_t>(body);
    Eigen::Index node = side == 0 ? pair.node1 : pair.node2;
    if (node < 0) {  // the mortar side of a mortar row has no node of its own: the nearest one
      node =
          nearest_node(problem.bodies[index]->mesh(), side == 0 ? pair.position : pair.position2);
    }
    const int dimension = problem.bodies[index]->mesh().dimension;
    Eigen::Vector3d displacement = Eigen::Vector3d::Zero();
    displacement.head(dimension) = displacements[index].segment(dimension * node, dimension);
    return displacement;
  };
  return robin::graph_excluded_clearance(problem.coupling, state, displacement_of);
}

/// Writes the result files into the directory's staging area (result_directory.hpp); the
/// caller commits them with summary.json.
void write_outputs(const std::filesystem::path& directory, const LocalProblem& problem,
                   const MonolithicResult& result) {
  const robin::ContactGraph& graph = problem.coupling.problem.graph;
  const robin::CouplingState state = robin::monolithic_state(graph, result);
  std::vector<std::string> files;
  for (std::size_t alpha = 0; alpha < problem.bodies.size(); ++alpha) {
    files.push_back(robin::write_body_vtu(directory, *problem.bodies[alpha],
                                          state.bodies[alpha].contact_force,
                                          rigid_amplitudes_of(result, alpha)));
  }
  robin::write_solution_pvd(directory, files);
  robin::write_contact_files(directory, problem.coupling, robin::body_names(problem.definition),
                             state);
}

int solve_and_write(const robin::CaseDefinition& definition, robin::ResultDirectory& results,
                    std::chrono::steady_clock::time_point start,
                    const std::shared_ptr<robin::ProgressDisplay>& display);

/// The result directory in which a stop signal records "interrupted" (on_stop_signal): set
/// while the run computes; null before, and once its files are committed or its failure
/// recorded. The main thread holds the mutex while it commits.
struct ActiveResults {
  std::mutex mutex;
  robin::ResultDirectory* results = nullptr;
};

ActiveResults& active_results() {
  static ActiveResults active;
  return active;
}

/// StopSignalWatcher's handler: records the interruption (unless the results are complete),
/// logs it and ends the process with 128 + signal.
void on_stop_signal(int signal_number) {
  ActiveResults& active = active_results();
  const std::lock_guard<std::mutex> lock(active.mutex);  // waits for a commit under way
  const std::string message = robin::RunInterrupted(signal_number).what();
  if (active.results != nullptr) active.results->fail(robin::RunFailure::interrupted, message);
  if (auto log = spdlog::get("monolithic")) {
    log->warn("{}", message);
    log->flush();
  }
  robin::end_interrupted_process(signal_number);
}

/// Reads the case file; when it is unusable, records that in the output directory (unless the
/// directory itself is unusable) and rethrows.
robin::CaseDefinition read_case(const std::filesystem::path& case_path,
                                const std::vector<std::string>& overrides,
                                const std::filesystem::path& output,
                                robin::ExistingResults existing) {
  try {
    return robin::read_case_file(case_path, overrides);
  } catch (const std::exception& error) {
    try {
      robin::record_failed_start(output, existing, "robin-monolithic", case_path,
                                 robin::in_case_file(case_path, error.what()));
    } catch (const std::exception&) {
      // the output directory cannot be used: the error is logged by main
    }
    throw;
  }
}

/// Reads the case, prepares the result directory and solves; a failure after the directory was
/// prepared is recorded in its summary.json.
int run(const std::filesystem::path& case_path, const std::vector<std::string>& overrides,
        const std::filesystem::path& output, robin::ExistingResults existing,
        const std::shared_ptr<robin::ProgressDisplay>& display) {
  auto log = spdlog::get("monolithic");
  const auto start = std::chrono::steady_clock::now();
  const robin::CaseDefinition definition = read_case(case_path, overrides, output, existing);
  robin::ResultDirectory results(output, existing, "robin-monolithic", case_path);
  {
    const std::lock_guard<std::mutex> lock(active_results().mutex);
    active_results().results = &results;
  }
  if (!results.leftover_files().empty()) {
    log->warn("the output directory {} also holds files that are not results of a run: {}",
              output.string(), fmt::join(results.leftover_files(), ", "));
  }
  try {
    return solve_and_write(definition, results, start, display);
  } catch (const std::exception& error) {
    const std::lock_guard<std::mutex> lock(active_results().mutex);
    active_results().results = nullptr;
    results.fail(robin::RunFailure::failed, robin::in_case_file(case_path, error.what()));
    throw;
  }
}

/// prepare_local_problem, showing each body's meshing and setup stages as they begin (with the
/// body's DOFs and the seconds since its setup began): a long setup never looks hung.
LocalProblem prepare_with_progress(const robin::CaseDefinition& definition,
                                   const std::shared_ptr<robin::ProgressDisplay>& display) {
  auto log = spdlog::get("monolithic");
  display->set_bodies(robin::body_names(definition));
  robin::CaseDefinition observed = definition;
  observed.meshing = robin::meshing_reporter(definition, display, log);
  std::map<std::string, std::chrono::steady_clock::time_point> setup_started;
  LocalProblem problem = robin::prepare_local_problem(
      observed, [&](const std::string& body, robin::SetupStage stage, long dof_count) {
        const auto now = std::chrono::steady_clock::now();
        const auto started = setup_started.emplace(body, now).first->second;
        const double seconds = std::chrono::duration<double>(now - started).count();
        display->update(
            body, {robin::to_string(stage), dof_count, seconds},
            fmt::format("body '{}': {} ({} DOFs)", body, robin::to_string(stage), dof_count), *log);
      });
  display->finish();
  return problem;
}

/// Solves the case (all its load steps) and commits the result files with summary.json.
int solve_and_write(const robin::CaseDefinition& definition, robin::ResultDirectory& results,
                    std::chrono::steady_clock::time_point start,
                    const std::shared_ptr<robin::ProgressDisplay>& display) {
  const double launched = robin::seconds_launched();  // the profile's "launch"
  auto log = spdlog::get("monolithic");
  const std::filesystem::path& case_path = definition.file;
  log->info("case {}: bodies '{}'", case_path.string(),
            fmt::join(robin::body_names(definition), "', '"));
  log->info("reading and meshing {}",
            definition.bodies.size() == 2 ? std::string("both bodies") : "the bodies");
  const LocalProblem problem = prepare_with_progress(definition, display);
  for (const auto& body : problem.bodies) {
    log->info("body '{}': {} dofs, assembly {:.3f} s, factorization {:.3f} s ({} nonzeros in L)",
              body->name(), body->free_dof_count(), body->timings().assembly_seconds,
              body->timings().ordering_seconds + body->timings().factorization_seconds,
              body->factor_nonzeros());
  }
  const std::vector<std::string> names = robin::body_names(definition);
  for (const std::string& line : robin::describe_interfaces(problem.coupling, names))
    log->info("{}", line);
  for (const std::string& line : robin::excluded_pair_lines(problem.coupling))
    log->warn("{}", line);
  for (const std::string& line : robin::overlap_warnings(problem.coupling)) log->warn("{}", line);
  // [loading]: every step at its load factor, the last one reported below (step_outputs.hpp).
  const robin::CouplingProblem& graph_problem = problem.coupling.problem;
  std::vector<robin::BodySolver*> bodies;
  for (const auto& body : problem.bodies) bodies.push_back(body.get());
  const std::vector<robin::MonolithicStep> steps = robin::solve_monolithic_steps(
      bodies, graph_problem.graph, graph_problem.gaps, definition.loading, definition.solver.qp);
  const MonolithicResult result =
      steps.empty() ? robin::solve_monolithic(problem.body_solvers(), graph_problem.graph,
                                              graph_problem.gaps, definition.solver.qp)
                    : steps.back().result;
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The outcome, worded as robin-coordinator's: what the stopping test looked at, then the
  // residuals of the final state (one contact force for both bodies: no force balance).
  log->info(
      "{} after {} MPRGP iterations ({} operator products, {:.3f} s): projected gradient {:.1e} "
      "against qp_tolerance {:.0e} relative to ||F|| ||lambda||; final state: penetration {:.1e}, "
      "complementarity {:.1e}",
      robin::to_string(result.qp.status), result.qp.iterations, result.qp.operator_applications,
      result.solve_seconds, result.qp.projected_gradient_norm,
      definition.solver.qp.relative_tolerance, result.residuals.penetration,
      result.residuals.complementarity);
  nlohmann::json summary = make_summary(problem, result, total);
  const robin::ExcludedPairClearance clearance = excluded_pair_clearance(problem, result);
  summary["excluded_pair_penetration"] = clearance.relative_penetration;
  if (!steps.empty()) summary["load_steps"] = robin::monolithic_steps_json(problem, steps);
  {
    // a stop signal now waits for the complete results
    const std::lock_guard<std::mutex> lock(active_results().mutex);
    const auto output_start = std::chrono::steady_clock::now();
    write_outputs(results.staging(), problem, result);
    if (!steps.empty()) robin::write_monolithic_step_outputs(results.staging(), problem, steps);
    const double output_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - output_start).count();
    summary["profile"] =
        robin::monolithic_profile_json(problem, launched, steps, result, output_seconds);
    results.commit(summary);
    active_results().results = nullptr;
  }
  log->info("results in {} (open solution.pvd in ParaView)", results.directory().string());
  if (result.qp.status != robin::QpStatus::converged) {
    log->error("the contact QP did not converge: {}", result.qp.message);
    return 3;
  }
  if (clearance.relative_penetration > robin::excluded_pair_penetration_limit) {
    log->error("{}", clearance.description);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"robin-monolithic: single-process reference solve of a contact case"};
  std::filesystem::path case_path, output;
  std::string level = "info";
  bool quiet = false;
  std::vector<std::string> overrides;
  app.add_option("case", case_path, "case file (TOML, see docs/case-format.md)")->required();
  bool overwrite = false;
  app.add_option("--output,-o", output, "directory for the result files")->required();
  app.add_flag("--overwrite", overwrite,
               "replace the results of an earlier run in the output directory (a directory "
               "holding files is refused otherwise)");
  app.final_callback([&] {
    try {
      robin::check_result_directory(
          output, overwrite ? robin::ExistingResults::overwrite : robin::ExistingResults::refuse);
    } catch (const robin::ResultDirectoryError& error) {
      throw CLI::ValidationError("--output", error.what());
    }
  });
  CLI::Option* log_level =
      app.add_option("--log-level", level, "trace, debug, info, warn, error, off")
          ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_flag("--quiet,-q", quiet, "log only warnings and errors")->excludes(log_level);
  robin::add_override_option(app, overrides);
  robin::add_version_option(app, "robin-monolithic");
  app.footer(
      "Exit codes: 0 converged; 1 bad input or a failure; 2 bad command line; 3 the contact QP "
      "did not converge (results are written); 130/143 stopped by SIGINT/SIGTERM.");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;

  const auto display =
      std::make_shared<robin::ProgressDisplay>(robin::progress_output_of_this_process(quiet));
  auto log = robin::make_progress_logger("monolithic", quiet ? "warn" : level, display.get());
  robin::install_stop_signal_handlers();
  const robin::StopSignalWatcher watcher(on_stop_signal);
  try {
    return run(case_path, overrides, output,
               overwrite ? robin::ExistingResults::overwrite : robin::ExistingResults::refuse,
               display);
  } catch (const robin::InputError& error) {
    display->finish();  // the error goes below the status lines
    log->error("{}", robin::in_case_file(case_path, error.what()));
  } catch (const robin::SingularBodyError& error) {
    display->finish();
    log->error("{}", robin::in_case_file(case_path, error.what()));
  } catch (const std::exception& error) {
    display->finish();
    log->error("failed: {}", error.what());
  }
  return 1;
}
