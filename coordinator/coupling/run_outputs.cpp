#include "coupling/run_outputs.hpp"

#include <chrono>
#include <fstream>
#include <iomanip>
#include <limits>

#include "coupling/history_rows.hpp"
#include "coupling/result_files.hpp"
#include "coupling/step_outputs.hpp"

namespace robin {
namespace {

/// history.csv, one row per iteration (docs/outputs.md describes every column): the joint
/// state's residuals and counters, the largest residual of each obstacle sequence's complete
/// state ("robin" only; empty otherwise), and what the stopping test compared with the
/// tolerance: stopping_residual = IterationRecord::progress, the run converged at the first row
/// where stopping_residual <= tolerance.
void write_history_csv(const std::filesystem::path& path,
                       const std::vector<IterationRecord>& history,
                       const CouplingOptions& options) {
  std::ofstream file(path);
  if (!file) throw std::runtime_error("cannot write '" + path.string() + "'");
  file << std::setprecision(std::numeric_limits<double>::max_digits10);
  write_history_header(file, history_body_count(history));
  file << '\n';
  const bool either_sequence = options.stopping == "either-sequence";
  for (const IterationRecord& record : history) {
    write_history_row(file, record, either_sequence, options.tolerance);
    file << '\n';
  }
  if (!file) throw std::runtime_error("cannot write '" + path.string() + "'");
}

nlohmann::json residuals_json(const IterationRecord& record) {
  return {{"obstacle_change", record.obstacle_change},
          {"penetration", record.penetration},
          {"force_balance", record.force_balance},
          {"complementarity", record.complementarity},
          {"correction", record.correction}};
}

/// The residuals of the state the run reports (RobinResult::completed_by_sequence): an accepted
/// complete state has no force imbalance and no correction by construction, and carries the
/// estimated error of its contact force instead.
nlohmann::json final_residuals_json(const RobinResult& iteration) {
  const SequenceResiduals* accepted = iteration.accepted_sequence();
  if (accepted == nullptr) return residuals_json(iteration.history.back());
  return {{"obstacle_change", accepted->obstacle_change},
          {"penetration", accepted->penetration},
          {"force_balance", 0.0},
          {"complementarity", accepted->complementarity},
          {"correction", 0.0},
          {"force_error_estimate", accepted->force_error}};
}

nlohmann::json make_summary(const CaseDefinition& definition, const CoupledRunResult& result) {
  const RobinResult& iteration = result.iteration;
  const Eigen::VectorXd mean_force =
      0.5 * (iteration.state.bodies[0].contact_force + iteration.state.bodies[1].contact_force);
  const Eigen::Vector2d resultant = contact_resultant(result.pairing, mean_force);
  nlohmann::json summary;
  summary["method"] = "robin";
  summary["case"] = definition.file.string();
  summary["overrides"] = definition.overrides;  // --set KEY=VALUE, in order
  summary["converged"] = iteration.status == IterationStatus::converged;
  summary["status"] = to_string(iteration.status);
  summary["message"] = iteration.message;
  summary["iterations"] = iteration.history.size();
  summary["algorithm"] = iteration.algorithm;
  summary["acceleration"] = result.options.acceleration.method;
  summary["stopping"] = result.options.stopping;
  summary["completed_by_sequence"] = iteration.completed_by_sequence;
  summary["relaxation"] = result.options.relaxation;
  summary["tolerance"] = result.options.tolerance;
  summary["initial_obstacle"] = result.options.initial_obstacle;
  if (!iteration.history.empty()) {
    summary["final_residuals"] = final_residuals_json(iteration);
    summary["joint_state_residuals"] = residuals_json(iteration.history.back());
  }
  summary["contact_pairs"] = result.pairing.size();
  summary["contact_discretization"] = describe_contact(
      result.pairing, definition.bodies[0].definition.name, definition.bodies[1].definition.name);
  summary["excluded_pairs"] = result.pairing.excluded;
  summary["excluded_pair_penetration"] = result.excluded_clearance.relative_penetration;
  summary["initial_overlap"] = overlap_warning(result.pairing);
  summary["contact_force_resultant"] = {resultant.x(), resultant.y()};
  double server_compute = 0.0;
  long iteration_bytes = 0;
  for (int alpha = 0; alpha < 2; ++alpha) {
    iteration_bytes += result.iteration_port_timings[alpha].bytes_sent +
                       result.iteration_port_timings[alpha].bytes_received;
  }
  const double iterations = std::max<double>(1.0, static_cast<double>(iteration.history.size()));
  for (int alpha = 0; alpha < 2; ++alpha) {
    const PortTimings& timings = result.port_timings[alpha];
    const BodyOutput& output = result.outputs[alpha];
    summary["bodies"].push_back(
        {{"name", output.body_name},
         {"dofs", result.interfaces[alpha].dof_count},
         {"server_compute_seconds", timings.compute_seconds},
         {"round_trip_seconds", timings.round_trip_seconds},
         {"bytes_sent", timings.bytes_sent},
         {"bytes_received", timings.bytes_received},
         {"reaction_resultant", {output.reaction_resultant.x(), output.reaction_resultant.y()}},
         {"applied_force", {output.applied_force.x(), output.applied_force.y()}}});
    server_compute += timings.compute_seconds;
  }
  summary["bytes_per_iteration"] = static_cast<double>(iteration_bytes) / iterations;
  const double messaging = iteration.messaging_seconds();
  summary["timings"] = {{"setup", result.setup_seconds},
                        {"meshing", result.meshing_seconds},
                        {"contact_coupling", result.coupling_seconds},
                        {"iteration", iteration.wall_seconds},
                        {"server_compute", server_compute},
                        {"server_compute_critical_path", iteration.critical_compute_seconds},
                        {"coordinator_compute", iteration.coordinator_seconds},
                        {"messaging", messaging},
                        {"messaging_share_of_iteration",
                         iteration.wall_seconds > 0 ? messaging / iteration.wall_seconds : 0.0},
                        {"total", result.total_seconds}};
  return summary;
}

}  // namespace

void write_coupled_outputs(ResultDirectory& results, const CaseDefinition& definition,
                           const CoupledRunResult& result) {
  const auto start = std::chrono::steady_clock::now();
  const std::filesystem::path& directory = results.staging();
  const std::string file1 = write_body_output(directory, result.outputs[0]);
  const std::string file2 = write_body_output(directory, result.outputs[1]);
  write_solution_pvd(directory, file1, file2);
  const RobinResult& iteration = result.iteration;
  const InterfaceState state = two_body_interface_state(iteration.state);
  if (state.normal_trace1.size() == static_cast<Eigen::Index>(result.pairing.size())) {
    write_contact_csv(directory / "contact.csv", result.pairing, state);
  }
  write_history_csv(directory / "history.csv", iteration.history, result.options);
  nlohmann::json summary = make_summary(definition, result);
  if (!result.steps.empty()) {  // [loading]: the time series and per-step files (step_outputs)
    write_coupled_step_outputs(directory, definition, result);
    summary["load_steps"] = coupled_steps_json(result);
  }
  RunProfile profile = result.profile;
  profile.output_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary["profile"] = profile_json(
      profile, {definition.bodies[0].definition.name, definition.bodies[1].definition.name});
  results.commit(summary);
}

}  // namespace robin
