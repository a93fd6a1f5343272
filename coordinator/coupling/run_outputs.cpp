#include "coupling/run_outputs.hpp"

#include <chrono>
#include <fstream>
#include <iomanip>
#include <limits>

#include "coupling/history_rows.hpp"
#include "coupling/interface_outputs.hpp"
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
  const bool either_sequence = options.stopping == StoppingRule::either_sequence;
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

/// The keys of summary.json about the contact (robin-monolithic writes the same): per
/// interface in "interfaces"; for one interface also at the top level, as always.
void add_contact_summary(nlohmann::json& summary, const CaseDefinition& definition,
                         const CoupledRunResult& result) {
  const GraphCoupling& coupling = result.coupling;
  const std::vector<std::string> names = body_names(definition);
  std::size_t rows = 0;
  std::string discretization;
  for (const std::string& line : describe_interfaces(coupling, names)) {
    discretization += (discretization.empty() ? "" : "; ") + line;
  }
  std::string overlaps;
  for (const std::string& line : overlap_warnings(coupling)) {
    overlaps += (overlaps.empty() ? "" : "; ") + line;
  }
  for (const ContactPairing& pairing : coupling.pairings) rows += pairing.size();
  summary["contact_pairs"] = rows;
  summary["contact_discretization"] = discretization;
  summary["excluded_pairs"] = excluded_pair_lines(coupling);
  summary["excluded_pair_penetration"] = result.excluded_clearance.relative_penetration;
  summary["initial_overlap"] = overlaps;
  nlohmann::json interfaces = nlohmann::json::array();
  if (has_interface_state(coupling, result.iteration.state)) {
    interfaces =
        interfaces_json(coupling, interface_definitions(definition), names, result.iteration.state);
  }
  summary["contact_force_resultant"] = coupling.pairings.size() == 1 && !interfaces.empty()
                                           ? interfaces[0]["contact_force_resultant"]
                                           : nlohmann::json(nullptr);
  summary["interfaces"] = interfaces;
}

nlohmann::json make_summary(const CaseDefinition& definition, const CoupledRunResult& result) {
  const RobinResult& iteration = result.iteration;
  nlohmann::json summary;
  summary["method"] = "robin";
  summary["case"] = definition.file.string();
  summary["overrides"] = definition.overrides;  // --set KEY=VALUE, in order
  summary["converged"] = iteration.status == IterationStatus::converged;
  summary["status"] = to_string(iteration.status);
  summary["message"] = iteration.message;
  summary["iterations"] = iteration.history.size();
  summary["algorithm"] = iteration.algorithm;
  summary["acceleration"] = to_string(result.options.acceleration.method);
  summary["stopping"] = to_string(result.options.stopping);
  summary["completed_by_sequence"] = iteration.completed_by_sequence;
  summary["relaxation"] = result.options.relaxation;
  summary["tolerance"] = result.options.tolerance;
  summary["initial_obstacle"] = to_string(result.options.initial_obstacle);
  if (!iteration.history.empty()) {
    summary["final_residuals"] = final_residuals_json(iteration);
    summary["joint_state_residuals"] = residuals_json(iteration.history.back());
  }
  add_contact_summary(summary, definition, result);
  double server_compute = 0.0;
  long iteration_bytes = 0;
  for (const PortTimings& timings : result.iteration_port_timings) {
    iteration_bytes += timings.bytes_sent + timings.bytes_received;
  }
  const double iterations = std::max<double>(1.0, static_cast<double>(iteration.history.size()));
  for (std::size_t alpha = 0; alpha < result.outputs.size(); ++alpha) {
    const PortTimings& timings = result.port_timings.at(alpha);
    const BodyOutput& output = result.outputs[alpha];
    summary["bodies"].push_back(
        {{"name", output.body_name},
         {"dofs", result.interfaces[alpha].dof_count},
         {"server_compute_seconds", timings.compute_seconds},
         {"round_trip_seconds", timings.round_trip_seconds},
         {"bytes_sent", timings.bytes_sent},
         {"bytes_received", timings.bytes_received},
         {"reaction_resultant", vector_json(output.reaction_resultant, output.mesh.dimension)},
         {"applied_force", vector_json(output.applied_force, output.mesh.dimension)}});
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
  std::vector<std::string> files;
  for (const BodyOutput& output : result.outputs) {
    files.push_back(place_body_output(directory, output));
  }
  write_solution_pvd(directory, files);
  const RobinResult& iteration = result.iteration;
  if (has_interface_state(result.coupling, iteration.state)) {
    write_contact_files(directory, result.coupling, body_names(definition), iteration.state);
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
  summary["profile"] = profile_json(profile, body_names(definition));
  results.commit(summary);
}

}  // namespace robin
