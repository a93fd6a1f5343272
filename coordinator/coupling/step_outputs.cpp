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

/// What steps.csv and "load_steps" say about the interface state of one step.
struct StepInterface {
  int active_pairs = 0;                                 // pairs with a positive mean contact force
  double largest_pressure = 0.0;                        // max_i (lambda1_i + lambda2_i) / (2 m_i)
  Eigen::Vector2d resultant = Eigen::Vector2d::Zero();  // contact_resultant of the mean force
};

StepInterface step_interface(const ContactPairing& pairing, const Eigen::VectorXd& force1,
                             const Eigen::VectorXd& force2) {
  StepInterface summary;
  if (force1.size() != static_cast<Eigen::Index>(pairing.size()) || force2.size() != force1.size())
    return summary;
  const Eigen::VectorXd mean = 0.5 * (force1 + force2);
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    const double force = mean[static_cast<Eigen::Index>(i)];
    if (force > 0.0) ++summary.active_pairs;
    summary.largest_pressure = std::max(summary.largest_pressure, force / pairing.pairs[i].weight);
  }
  summary.resultant = contact_resultant(pairing, mean);
  return summary;
}

/// The PVD series of both bodies over the steps: file k of body b is
/// steps/step_NNN/<file name of body b>.
void write_series(const std::filesystem::path& directory, const LoadingOptions& loading,
                  const std::vector<std::array<std::string, 2>>& files) {
  std::vector<PvdDataSet> datasets;
  for (std::size_t k = 0; k < files.size(); ++k) {
    for (int part = 0; part < 2; ++part) {
      const std::filesystem::path file =
          step_directory(static_cast<int>(k + 1), loading.factors.size()) / files[k][part];
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
  const bool either_sequence = result.options.stopping == "either-sequence";
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
    const StepInterface interface =
        step_interface(result.pairing, iteration.state.bodies[0].contact_force,
                       iteration.state.bodies[1].contact_force);
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
  std::vector<std::array<std::string, 2>> files;
  const std::filesystem::path table_path = directory / "steps.csv";
  std::ofstream table = open_csv(table_path);
  table << "step,load_factor,status,iterations,qp_iterations,warm_started,final_residual,"
           "active_pairs,largest_pressure,resultant_x,resultant_y,seconds\n";
  for (const LoadStepResult& step : result.steps) {
    const std::filesystem::path step_path =
        directory / step_directory(step.step, loading.factors.size());
    std::filesystem::create_directories(step_path);
    files.push_back({write_body_output(step_path, step.outputs[0]),
                     write_body_output(step_path, step.outputs[1])});
    const RobinResult& iteration = step.iteration;
    const InterfaceState state = two_body_interface_state(iteration.state);
    if (state.normal_trace1.size() == static_cast<Eigen::Index>(result.pairing.size())) {
      write_contact_csv(step_path / "contact.csv", result.pairing, state);
    }
    const StepInterface interface =
        step_interface(result.pairing, iteration.state.bodies[0].contact_force,
                       iteration.state.bodies[1].contact_force);
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
    const StepInterface interface =
        step_interface(problem.pairing, result.contact_force, result.contact_force);
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
  std::vector<std::array<std::string, 2>> files;
  const std::filesystem::path table_path = directory / "steps.csv";
  std::ofstream table = open_csv(table_path);
  table << "step,load_factor,status,iterations,active_pairs,largest_pressure,resultant_x,"
           "resultant_y,seconds\n";
  for (const MonolithicStep& step : steps) {
    const std::filesystem::path step_path =
        directory / step_directory(step.step, loading.factors.size());
    const MonolithicResult& result = step.result;
    std::array<std::string, 2> names;
    for (int alpha = 0; alpha < 2; ++alpha) {
      problem.bodies[alpha]->set_load_factor(step.factor);
      names[alpha] = write_body_vtu(step_path, *problem.bodies[alpha], result.contact_force);
    }
    files.push_back(names);
    write_contact_csv(step_path / "contact.csv", problem.pairing,
                      {result.normal_traces[0], result.normal_traces[1], result.contact_force,
                       result.contact_force});
    const StepInterface interface =
        step_interface(problem.pairing, result.contact_force, result.contact_force);
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
