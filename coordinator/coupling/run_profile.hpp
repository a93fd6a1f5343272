#pragma once
// The stage-by-stage profile of a run, written into summary.json as "profile" (docs/outputs.md
// lists every key): the coordinator's stages, which follow one another, and each body's stages
// as measured where the body lives. Every time is wall-clock seconds; a stage that was not
// reported (a server of protocol 2.1 or older) is null.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/subdomain_port.hpp"

namespace robin {

/// The coordinator's stages, in the order they run (the sum is at most the run's wall time).
struct RunProfile {
  double launch_seconds = 0.0;              // program start to the run's start (seconds_launched)
  double meshing_seconds = 0.0;             // reading the .msh files or meshing the .geo bodies
  double setup_seconds = 0.0;               // every body's setup request, in parallel
  double contact_coupling_seconds = 0.0;    // pairing or mortar rows
  double contact_assignment_seconds = 0.0;  // every body's AssignContact, one after another
  double iterations_seconds = 0.0;          // the iteration (every load step's)
  double fields_seconds = 0.0;              // collecting every body's fields (every load step's)
  double output_seconds = 0.0;              // writing the result files but summary.json
  std::vector<BodyProfile> bodies;          // body order
};

/// Seconds since this program started (static initialization of the coordinator library):
/// for robin-run, reading the case and launching the servers until they listen; for
/// robin-coordinator and robin-monolithic, reading the case.
double seconds_launched();

/// The "profile" object of summary.json for a coupled run whose bodies are `names`.
nlohmann::json profile_json(const RunProfile& profile, const std::vector<std::string>& names);

/// The per-body object of "profile.bodies" for a body of that profile.
nlohmann::json body_profile_json(const BodyProfile& profile, const std::string& name);

/// The profile of a body set up in this process (robin-monolithic): its assembly, ordering,
/// factorization and interface operator; setup is their sum but the interface operator; no mesh
/// decoding, transfer or fields of its own.
BodyProfile local_body_profile(const BodySolver& body);

/// The "profile" object of robin-monolithic's summary.json: the keys of profile_json, the
/// bodies set up one after the other, "iterations" the monolithic solve (`result`'s, or every
/// load step's when `steps` is not empty), "fields" null (the fields are computed while writing
/// the output).
nlohmann::json monolithic_profile_json(const LocalProblem& problem, double launch_seconds,
                                       const std::vector<MonolithicStep>& steps,
                                       const MonolithicResult& result, double output_seconds);

}  // namespace robin
