#pragma once
// The state of the coupling loop (robin_iteration.hpp) after an iteration: everything the loop
// needs to continue as if it had never stopped. With x_k the iterate of iteration k:
//   the iterate x_{k+1} of the next iteration and the iterates x_1 ... x_k (a resumed loop
//   first repeats the contact solves at x_1 ... x_k, so that each server's contact QP is
//   warm-started from lambda_k bit for bit as in the uninterrupted run: a server warm-starts
//   from its previous contact force, which a new or set-up-again server has forgotten, and
//   the result of a QP depends on its start within the QP tolerance);
//   the acceleration's history (Acceleration::save_state: IQN-ILS columns, Aitken factors);
//   the divergence and stagnation monitor (first and smallest obstacle step, the running
//   minimum of the stopping residual), each body's force sequence (its previous lambda, the
//   previous change and obstacle step: the force error estimates);
//   the records of iterations 1..k (history.csv), the state of iteration k and, once the loop
//   has stopped, its status, so that a resumed run goes straight to the fields.
// Its size is O(interface x (history_depth + a few)) plus O(k) residual records, besides the
// iterates x_1 ... x_k, which its JSON form leaves out (checkpoint.hpp appends them to a
// binary file, one per iteration).

#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "coupling/robin_iteration.hpp"

namespace robin {

/// ProgressMonitor's memory (robin_iteration.cpp).
struct ProgressMonitorState {
  double first_step = 0.0;
  double smallest_step = 0.0;
  std::vector<double> best_history;
};

/// ForceSequence's memory (robin_iteration.cpp): lambda_{k}, |lambda_k - lambda_{k-1}| and the
/// obstacle step of the sequence's blocks.
struct ForceSequenceState {
  Eigen::VectorXd previous;
  double previous_change = 0.0;
  double step = 0.0;
};

struct IterationCheckpoint {
  int iteration = 0;     // k: the iterations completed
  bool stopped = false;  // the loop has stopped after iteration k (status, message below)
  IterationStatus status = IterationStatus::max_iterations;
  std::string message;
  std::string algorithm;  // RobinResult::algorithm
  int completed_by_sequence = 0;
  std::vector<Eigen::VectorXd> iterates;             // x_1 ... x_k (not in to_json)
  Eigen::VectorXd next_iterate;                      // x_{k+1} (meaningless once stopped)
  Eigen::VectorXd initial_iterate, restart_iterate;  // RobinResult's
  CouplingState state;          // the state of iteration k (RobinResult's), per body
  nlohmann::json acceleration;  // Acceleration::save_state()
  ProgressMonitorState monitor;
  std::vector<ForceSequenceState> force_sequences;  // one per obstacle sequence
  std::vector<IterationRecord> history;
  double critical_compute_seconds = 0.0;  // RobinResult's, up to iteration k
  double port_seconds = 0.0;              // time in port requests, up to iteration k
  double wall_seconds = 0.0;              // the loop's wall time, up to iteration k
};

/// A load step of a case with [loading] (case_file_loading.hpp) that was completed (its loop
/// stopped and its fields were collected) before a checkpoint: what the step outputs need
/// (the loop's stopped state: status, history, the state of its last iteration, its initial and
/// restart iterates) and its iterates x_1 ... x_k, whose contact solves a resumed run repeats
/// so that the servers' contact warm start is the uninterrupted run's. Its fields are collected
/// again; the acceleration's state is not kept (a completed step does not continue).
struct LoadStepCheckpoint {
  int step = 0;  // 1, 2, ...
  double factor = 1.0;
  bool warm_started = false;
  double seconds = 0.0;  // the step's wall time
  IterationCheckpoint iteration;
};

/// The checkpoint as JSON (checkpoint_encoding.hpp: every double exact), without `iterates`,
/// and back (with `iterates` empty). from_json throws CheckpointFormatError naming the field
/// that is missing or malformed.
nlohmann::json to_json(const IterationCheckpoint& checkpoint);
IterationCheckpoint iteration_checkpoint_from_json(const nlohmann::json& document);
/// The same for a completed load step (its loop under "loop", stopped).
nlohmann::json to_json(const LoadStepCheckpoint& step);
LoadStepCheckpoint load_step_checkpoint_from_json(const nlohmann::json& document);

}  // namespace robin
