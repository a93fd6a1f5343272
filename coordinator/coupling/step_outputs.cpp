#include "coupling/step_outputs.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <fstream>
#include <iomanip>
#include <limits>
#include <locale>
#include <sstream>
#include <stdexcept>

#include "coupling/history_rows.hpp"
#include "coupling/interface_outputs.hpp"
#include "coupling/result_files.hpp"
#include "numerics/body_output.hpp"

namespace robin {
namespace {

/// Shortest decimal text that parses back to the same double.
std::string exact_text(double value) {
  std::array<char, 32> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

std::ofstream open_csv(const std::filesystem::path& path) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open '" + path.string() + "' for writing");
  out.imbue(std::locale::classic());
  return out;
}

void close_csv(std::ofstream& out, const std::filesystem::path& path) {
  out.close();
  if (!out) throw std::runtime_error("error while writing '" + path.string() + "' (disk full?)");
}

/// What steps.csv and "load_steps" say about the interface state of one step: for one interface
/// its summary; for several, the active rows summed, the largest pressure over all, and the
/// resultant of the first interface (each interface's own in summary.json's "interfaces").
InterfaceSummary step_interface(const GraphCoupling& coupling, const CouplingState& state) {
  InterfaceSummary total;
  for (std::size_t k = 0; k < coupling.pairings.size(); ++k) {
    const InterfaceSummary one = summarize_interface(
        coupling.pairings[k], interface_state(coupling.problem.graph, state, k));
    total.active_pairs += one.active_pairs;
    total.largest_pressure = std::max(total.largest_pressure, one.largest_pressure);
    if (k == 0) total.resultant = one.resultant;
  }
  return total;
}

/// The PVD series of every body over the steps: file k of body b is
/// steps/step_NNN/<file name of body b>.
void write_series(const std::filesystem::path& directory, const LoadingOptions& loading,
                  const std::vector<std::vector<std::string>>& files) {
  std::vector<PvdDataSet> datasets;
  for (std::size_t k = 0; k < files.size(); ++k) {
    for (int part = 0; part < static_cast<int>(files[k].size()); ++part) {
      const std::filesystem::path file =
          step_directory(static_cast<int>(k + 1), loading.factors.size()) /
          files[k][static_cast<std::size_t>(part)];
      datasets.push_back({loading.timestep(k), part, file.generic_string()});
    }
  }
  write_pvd_series(directory / "solution.pvd", datasets);
}

/// history.csv of a stepped run: the columns of a single run's history.csv (docs/outputs.md),
/// after the step number and its load factor, for every iteration of every step.
void write_coupled_history(const std::filesystem::path& path, const CoupledRunResult& result) {
  std::ofstream file = open_csv(path);
  file << std::setprecision(std::numeric_limits<double>::max_digits10);
  file << "step,load_factor,";
  std::size_t bodies = 2;
  if (!result.steps.empty()) bodies = history_body_count(result.steps.front().iteration.history);
  write_history_header(file, bodies);
  file << '\n';
  const bool either_sequence = result.options.stopping == StoppingRule::either_sequence;
  for (const LoadStepResult& step : result.steps) {
    for (const IterationRecord& record : step.iteration.history) {
      file << step.step << ',' << exact_text(step.factor) << ',';
      write_history_row(file, record, either_sequence, result.options.tolerance);
      file << '\n';
    }
  }
  close_csv(file, path);
}

int qp_iterations(const RobinResult& iteration) {
  int total = 0;
  for (const IterationRecord& record : iteration.history) {
    for (const int count : record.qp_iterations) total += count;
  }
  return total;
}

}  // namespace

std::filesystem::path step_directory(int step, std::size_t count) {
  const std::size_t digits = std::max<std::size_t>(3, std::to_string(count).size());
  std::ostringstream name;
  name << "step_" << std::setw(static_cast<int>(digits)) << std::setfill('0') << step;
  return std::filesystem::path("steps") / name.str();
}

nlohmann::json coupled_steps_json(const CoupledRunResult& result) {
  nlohmann::json steps = nlohmann::json::array();
  for (const LoadStepResult& step : result.steps) {
    const RobinResult& iteration = step.iteration;
    const InterfaceSummary interface = step_interface(result.coupling, iteration.state);
    steps.push_back(
        {{"step", step.step},
         {"load_factor", step.factor},
         {"status", to_string(iteration.status)},
         {"converged", iteration.status == IterationStatus::converged},
         {"iterations", iteration.history.size()},
         {"qp_iterations", qp_iterations(iteration)},
         {"warm_started", step.warm_started},
         {"final_residual", iteration.final_largest_residual()},
         {"active_pairs", interface.active_pairs},
         {"largest_pressure", interface.largest_pressure},
         {"contact_force_resultant", {interface.resultant.x(), interface.resultant.y()}},
         {"excluded_pair_penetration", step.excluded_clearance.relative_penetration},
         {"seconds", step.seconds}});
  }
  return steps;
}

void write_coupled_step_outputs(const std::filesystem::path& directory,
                                const CaseDefinition& definition, const CoupledRunResult& result) {
  const LoadingOptions& loading = definition.loading;
  std::vector<std::vector<std::string>> files;
  const std::vector<std::string> names = body_names(definition);
  const std::filesystem::path table_path = directory / "steps.csv";
  std::ofstream table = open_csv(table_path);
  table << "step,load_factor,status,iterations,qp_iterations,warm_started,final_residual,"
           "active_pairs,largest_pressure,resultant_x,resultant_y,seconds\n";
  for (const LoadStepResult& step : result.steps) {
    const std::filesystem::path step_path =
        directory / step_directory(step.step, loading.factors.size());
    std::filesystem::create_directories(step_path);
    files.emplace_back();
    for (const BodyOutput& output : step.outputs) {
      files.back().push_back(place_body_output(step_path, output));
    }
    const RobinResult& iteration = step.iteration;
    if (has_interface_state(result.coupling, iteration.state)) {
      write_contact_files(step_path, result.coupling, names, iteration.state);
    }
    const InterfaceSummary interface = step_interface(result.coupling, iteration.state);
    table << step.step << ',' << exact_text(step.factor) << ',' << to_string(iteration.status)
          << ',' << iteration.history.size() << ',' << qp_iterations(iteration) << ','
          << (step.warm_started ? 1 : 0) << ',' << exact_text(iteration.final_largest_residual())
          << ',' << interface.active_pairs << ',' << exact_text(interface.largest_pressure) << ','
          << exact_text(interface.resultant.x()) << ',' << exact_text(interface.resultant.y())
          << ',' << exact_text(step.seconds) << '\n';
  }
  close_csv(table, table_path);
  write_series(directory, loading, files);
  write_coupled_history(directory / "history.csv", result);
}

nlohmann::json monolithic_steps_json(const LocalProblem& problem,
                                     const std::vector<MonolithicStep>& steps) {
  nlohmann::json entries = nlohmann::json::array();
  for (const MonolithicStep& step : steps) {
    const MonolithicResult& result = step.result;
    const InterfaceSummary interface =
        step_interface(problem.coupling, monolithic_state(problem.coupling.problem.graph, result));
    entries.push_back(
        {{"step", step.step},
         {"load_factor", step.factor},
         {"status", to_string(result.qp.status)},
         {"converged", result.qp.status == QpStatus::converged},
         {"iterations", result.qp.iterations},
         {"active_pairs", interface.active_pairs},
         {"largest_pressure", interface.largest_pressure},
         {"contact_force_resultant", {interface.resultant.x(), interface.resultant.y()}},
         {"seconds", result.solve_seconds}});
  }
  return entries;
}

void write_monolithic_step_outputs(const std::filesystem::path& directory,
                                   const LocalProblem& problem,
                                   const std::vector<MonolithicStep>& steps) {
  const LoadingOptions& loading = problem.definition.loading;
  std::vector<std::vector<std::string>> files;
  const std::filesystem::path table_path = directory / "steps.csv";
  std::ofstream table = open_csv(table_path);
  table << "step,load_factor,status,iterations,active_pairs,largest_pressure,resultant_x,"
           "resultant_y,seconds\n";
  const ContactGraph& graph = problem.coupling.problem.graph;
  for (const MonolithicStep& step : steps) {
    const std::filesystem::path step_path =
        directory / step_directory(step.step, loading.factors.size());
    const MonolithicResult& result = step.result;
    const CouplingState state = monolithic_state(graph, result);
    files.emplace_back();
    for (std::size_t alpha = 0; alpha < problem.bodies.size(); ++alpha) {
      problem.bodies[alpha]->set_load_factor(step.factor);
      const Eigen::VectorXd rigid_amplitudes = alpha < result.rigid_amplitudes.size()
                                                   ? result.rigid_amplitudes[alpha]
                                                   : Eigen::VectorXd();
      files.back().push_back(write_body_vtu(step_path, *problem.bodies[alpha],
                                            state.bodies[alpha].contact_force, rigid_amplitudes));
    }
    write_contact_files(step_path, problem.coupling, body_names(problem.definition), state);
    const InterfaceSummary interface = step_interface(problem.coupling, state);
    table << step.step << ',' << exact_text(step.factor) << ',' << to_string(result.qp.status)
          << ',' << result.qp.iterations << ',' << interface.active_pairs << ','
          << exact_text(interface.largest_pressure) << ',' << exact_text(interface.resultant.x())
          << ',' << exact_text(interface.resultant.y()) << ',' << exact_text(result.solve_seconds)
          << '\n';
  }
  close_csv(table, table_path);
  write_series(directory, loading, files);
}

}  // namespace robin
