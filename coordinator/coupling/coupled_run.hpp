#pragma once
// A whole coupled run on one port per body: setup of every body (in parallel), the coupling of
// the contact interfaces into constraint rows (contact graph), contact assignment, the Robin
// iteration, the final fields, and the result files. Two bodies are the graph of one edge.
// Shared by robin-coordinator (remote ports) and the in-process mode / tests.

#include <filesystem>
#include <nlohmann/json.hpp>

#include "coupling/case_file.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/graph_coupling.hpp"
#include "coupling/iteration_checkpoint.hpp"
#include "coupling/port_recovery.hpp"
#include "coupling/robin_iteration.hpp"
#include "coupling/run_profile.hpp"
#include "coupling/subdomain_port.hpp"

namespace robin {

/// One quasi-static load step of a case with [loading] (case_file_loading.hpp).
struct LoadStepResult {
  int step = 0;               // 1, 2, ...
  double factor = 1.0;        // the load factor of the step
  bool warm_started = false;  // started from the previous steps' fixed points
  RobinResult iteration;
  std::vector<BodyOutput> outputs;  // body order
  ExcludedPairClearance excluded_clearance;
  std::vector<PortTimings> port_timings;  // the step alone: load factor, iteration, fields
  double seconds = 0.0;                   // wall time of the step
};

struct CoupledRunResult {
  CouplingOptions options;  // the options the iteration ran with
  /// Per interface its rows, per body its operator, and the graph's problem.
  GraphCoupling coupling;
  RobinResult iteration;
  std::vector<BodyOutput> outputs;                  // body order
  std::vector<InterfaceDescription> interfaces;     // body order: the servers' descriptions
  std::vector<PortTimings> port_timings;            // whole run
  std::vector<PortTimings> iteration_port_timings;  // the iteration alone (no setup, fields)
  /// The excluded pairs in the final state (contact_pairing.hpp): a penetration beyond
  /// excluded_pair_penetration_limit means a Dirichlet condition drives the bodies into each
  /// other, which the tools report as an error.
  ExcludedPairClearance excluded_clearance;
  double setup_seconds = 0.0;     // meshing, server setups, contact coupling, assignment
  double meshing_seconds = 0.0;   // reading and meshing every body (coordinator side)
  double coupling_seconds = 0.0;  // building the contact rows (pairing or mortar)
  double total_seconds = 0.0;
  /// The load steps of a case with [loading], in order, up to the first that did not converge
  /// (the run stops there); empty for a case without [loading]. The fields above then describe
  /// the last step computed (iteration, outputs, iteration_port_timings), except
  /// excluded_clearance, the largest penetration over the steps.
  std::vector<LoadStepResult> steps;
  /// What the run did about lost servers, in order, for people (empty: nothing was lost).
  std::vector<std::string> recoveries;
  /// The stages of the run (run_profile.hpp); output_seconds is set by write_coupled_outputs.
  RunProfile profile;

  /// The rows of the only interface of a two-body case. Throws std::logic_error when the case
  /// has several interfaces.
  const ContactPairing& pairing() const;
};

/// Checkpoints, resume and server recovery of a coupled run (docs/outputs.md, "Checkpoint and
/// resume").
struct RunContinuation {
  /// The iteration continues after this checkpoint instead of starting (the bodies are set up
  /// and the contact assigned as usual first). With [loading], the checkpoint of load step
  /// resume_steps->size() + 1.
  const IterationCheckpoint* resume = nullptr;
  /// [loading]: the load steps completed before `resume`'s (their results are taken from here,
  /// their fields collected again, and their contact solves repeated before the resumed step,
  /// so that the servers' contact warm start is the uninterrupted run's). Null: none.
  const std::vector<LoadStepCheckpoint>* resume_steps = nullptr;
  /// Told the iteration's state after every iteration (with [loading], of the current step).
  std::function<void(const IterationCheckpoint&)> checkpoint;
  /// [loading]: told each load step once it is completed (its loop stopped, its fields
  /// collected), before the next step's first checkpoint; not the resumed steps before
  /// `resume`'s.
  std::function<void(const LoadStepCheckpoint&)> step_completed;
  /// Replaces lost servers (port_recovery.hpp); empty: a lost server fails the run.
  ServerReplacement replacement;
  /// Not empty: every body's server writes its fields file itself into this directory, relative
  /// to the servers' output root (robin-run's local servers: the result directory's staging
  /// area), a load step's into steps/step_NNN of it (step_outputs.hpp), and leaves the mesh and
  /// fields out of its reply unless a contact pair is excluded (whose clearance needs the
  /// displacements). Empty: the fields come back and the coordinator writes the files.
  std::filesystem::path server_write_directory;
};

/// Observer of the run's stages ("setup", "pairing", iteration records) for progress lines.
struct RunObserver {
  std::function<void(const std::string&)> stage;
  /// Excluded contact pairs and an initial overlap (stage when empty).
  std::function<void(const std::string&)> warning;
  IterationObserver iteration;
};

/// Runs the case on the ports, one per body in body order (ports[0] gets body 1). `options`
/// replaces the case's [coupling] table (the caller merges command-line overrides). Throws
/// PortError, InputError. A case with [loading] sets the bodies up and assigns the contact once,
/// then per step sets the load factor on every port (SetLoadFactor: the servers keep K's factor and
/// F), runs the iteration (with loading.warm_start from the previous steps' fixed points: the last
/// one, or the linear extrapolation through the last two to the step's factor), and collects the
/// fields; it stops after the first step that does not converge.
/// With `continuation`, the iteration is checkpointed and may resume, and a lost server is
/// replaced: its body set up again and the stage it was lost in repeated, the iteration from
/// its last checkpoint (port_recovery.hpp). With [loading], a load step that starts on servers
/// that have not seen the steps before it (a resume, a replaced server) first repeats those
/// steps' contact solves at their load factors (their contact warm start).
CoupledRunResult run_coupled_case(const CaseDefinition& definition,
                                  const std::vector<SubdomainPort*>& ports,
                                  const CouplingOptions& options, const RunObserver& observer = {},
                                  const RunContinuation& continuation = {});

/// Exit code of a run: 0 converged, 3 iteration limit, 4 diverged, 5 stagnated.
int exit_code(IterationStatus status);

}  // namespace robin
