#include "coupling/run_profile.hpp"

#include <chrono>
#include <optional>

namespace robin {
namespace {

using Clock = std::chrono::steady_clock;

/// Set during static initialization, before main().
const Clock::time_point program_start = Clock::now();

nlohmann::json optional_seconds(const std::optional<double>& seconds) {
  return seconds ? nlohmann::json(*seconds) : nlohmann::json(nullptr);
}

/// The summary key of a stage: "interface operator" becomes "interface_operator".
std::string key_of(SetupStage stage) {
  std::string key = to_string(stage);
  for (char& character : key) {
    if (character == ' ') character = '_';
  }
  return key;
}

}  // namespace

double seconds_launched() {
  return std::chrono::duration<double>(Clock::now() - program_start).count();
}

nlohmann::json body_profile_json(const BodyProfile& profile, const std::string& name) {
  nlohmann::json body = {{"name", name},
                         {"transfer", optional_seconds(profile.transfer_seconds)},
                         {"server_setup", optional_seconds(profile.setup_seconds)}};
  for (SetupStage stage :
       {SetupStage::mesh, SetupStage::assembly, SetupStage::ordering, SetupStage::factorization,
        SetupStage::interface_operator, SetupStage::fields}) {
    const auto found = profile.stages.find(stage);
    body[key_of(stage)] =
        found == profile.stages.end() ? nlohmann::json(nullptr) : nlohmann::json(found->second);
  }
  body["peak_resident_bytes"] = profile.peak_resident_bytes
                                    ? nlohmann::json(*profile.peak_resident_bytes)
                                    : nlohmann::json(nullptr);
  body["linear_solver"] = profile.linear_solver.empty() ? nlohmann::json(nullptr)
                                                        : nlohmann::json(profile.linear_solver);
  return body;
}

nlohmann::json profile_json(const RunProfile& profile, const std::vector<std::string>& names) {
  nlohmann::json json = {{"launch", profile.launch_seconds},
                         {"meshing", profile.meshing_seconds},
                         {"setup", profile.setup_seconds},
                         {"contact_coupling", profile.contact_coupling_seconds},
                         {"contact_assignment", profile.contact_assignment_seconds},
                         {"iterations", profile.iterations_seconds},
                         {"fields", profile.fields_seconds},
                         {"output", profile.output_seconds}};
  json["bodies"] = nlohmann::json::array();
  for (std::size_t alpha = 0; alpha < profile.bodies.size(); ++alpha) {
    json["bodies"].push_back(body_profile_json(profile.bodies[alpha], names.at(alpha)));
  }
  return json;
}

BodyProfile local_body_profile(const BodySolver& body) {
  const BodyTimings& timings = body.timings();
  BodyProfile profile;
  profile.stages = {{SetupStage::assembly, timings.assembly_seconds},
                    {SetupStage::ordering, timings.ordering_seconds},
                    {SetupStage::factorization, timings.factorization_seconds},
                    {SetupStage::interface_operator, timings.interface_seconds}};
  profile.setup_seconds = timings.setup_seconds();
  profile.linear_solver = linear_solver_name(body.linear_solver());
  return profile;
}

nlohmann::json monolithic_profile_json(const LocalProblem& problem, double launch_seconds,
                                       const std::vector<MonolithicStep>& steps,
                                       const MonolithicResult& result, double output_seconds) {
  double solve_seconds = steps.empty() ? result.solve_seconds : 0.0;
  for (const MonolithicStep& step : steps) solve_seconds += step.result.solve_seconds;
  RunProfile profile;
  profile.launch_seconds = launch_seconds;
  profile.meshing_seconds = problem.mesh_seconds;
  profile.setup_seconds = problem.setup_seconds;
  profile.contact_coupling_seconds = problem.coupling_seconds;
  profile.contact_assignment_seconds = problem.assignment_seconds;
  profile.iterations_seconds = solve_seconds;
  profile.output_seconds = output_seconds;
  std::vector<std::string> names;
  for (const auto& body : problem.bodies) {
    profile.bodies.push_back(local_body_profile(*body));
    names.push_back(body->name());
  }
  nlohmann::json json = profile_json(profile, names);
  json["fields"] = nullptr;
  return json;
}

}  // namespace robin
