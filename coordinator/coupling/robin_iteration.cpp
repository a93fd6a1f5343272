#include "coupling/robin_iteration.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "coupling/case_file_body.hpp"
#include "coupling/checkpoint_encoding.hpp"
#include "coupling/coupling_scheme.hpp"
#include "coupling/iteration_checkpoint.hpp"
#include "coupling/monolithic_solver.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point start, Clock::time_point end) {
  return std::chrono::duration<double>(end - start).count();
}

double maximum_absolute(const Eigen::VectorXd& values) {
  return values.size() == 0 ? 0.0 : values.lpNorm<Eigen::Infinity>();
}

/// Divergence and stagnation detection on the largest residual of each iteration.
class ProgressMonitor {
 public:
  explicit ProgressMonitor(const CouplingOptions& options) : options_(options) {}

  /// Returns the status that must stop the run, or nothing; fills `message`.
  std::optional<IterationStatus> check(const IterationRecord& record, std::string& message) {
    const double value = record.progress(options_.stopping == StoppingRule::either_sequence);
    best_history_.push_back(std::min(best(), value));
    if (record.iteration == 1) first_step_ = record.obstacle_step;
    smallest_step_ = std::min(smallest_step_, record.obstacle_step);
    std::ostringstream text;
    if (!std::isfinite(value) || !std::isfinite(record.obstacle_step)) {
      text << "the iteration diverged at iteration " << record.iteration
           << ": a residual is not finite";
    } else if (record.obstacle_step > first_step_ &&
               record.obstacle_step > options_.divergence_factor * smallest_step_) {
      // The scaled residuals saturate when the iterates blow up; the raw obstacle step does not.
      text << "the iteration diverged at iteration " << record.iteration << ": the obstacle update "
           << record.obstacle_step << " grew to more than " << options_.divergence_factor
           << " times its smallest value " << smallest_step_
           << " (the relaxation is too large for these bodies; try a smaller --relaxation)";
    } else if (stagnated() && best() >= no_contraction_level) {
      text << "the iteration diverged: after " << record.iteration
           << " iterations the largest residual is still " << best()
           << " of the solution's scale (the iterates oscillate without contracting; the "
              "relaxation is too large for these bodies; try a smaller --relaxation)";
    } else if (stagnated()) {
      text << "the iteration stagnated: the largest residual did not decrease by 1% in "
           << options_.stagnation_window << " iterations (it is " << value
           << "); if it is small, the contact QP tolerance (solver.qp_tolerance) may limit the "
              "attainable accuracy, otherwise the relaxation does not suit these bodies";
      message = text.str();
      return IterationStatus::stagnated;
    } else {
      return std::nullopt;
    }
    message = text.str();
    return IterationStatus::diverged;
  }

  ProgressMonitorState state() const { return {first_step_, smallest_step_, best_history_}; }
  void restore(const ProgressMonitorState& state) {
    first_step_ = state.first_step;
    smallest_step_ = state.smallest_step;
    best_history_ = state.best_history;
  }

 private:
  double best() const {
    return best_history_.empty() ? std::numeric_limits<double>::infinity() : best_history_.back();
  }
  bool stagnated() const {
    const std::size_t window = static_cast<std::size_t>(std::max(1, options_.stagnation_window));
    if (best_history_.size() <= window) return false;
    return best() > 0.99 * best_history_[best_history_.size() - 1 - window];
  }

  /// A run whose smallest residual is still this large after a stagnation window has not
  /// contracted at all: the iterates oscillate at the scale of the solution.
  static constexpr double no_contraction_level = 0.1;
  const CouplingOptions& options_;
  double first_step_ = 0.0;
  double smallest_step_ = std::numeric_limits<double>::infinity();
  std::vector<double> best_history_;  // smallest largest-residual up to each iteration
};

/// The largest max norm of the vectors.
double maximum_absolute(const std::vector<Eigen::VectorXd>& vectors) {
  double largest = 0.0;
  for (const Eigen::VectorXd& values : vectors)
    largest = std::max(largest, maximum_absolute(values));
  return largest;
}

/// The local indentation of the state's contact forces: c max|lambda|, with c the local
/// interface compliance measured by probe_responses and interface_compliance. A floor of the
/// displacement scale: when the interface barely moves (a symmetry plane between two equally loaded
/// bodies, d = 0), |d| and |u_N| are round-off, and residuals relative to them alone never fall
/// below the tolerance although the state is converged.
double force_displacement(const CouplingState& state, double compliance) {
  return compliance * maximum_absolute(state.contact_forces());
}

/// Scaled residuals of a state (IterationRecord's definitions; obstacle_change is set apart).
IterationRecord residual_record(int iteration, const CouplingProblem& problem,
                                const CouplingState& state, double compliance) {
  IterationRecord record;
  record.iteration = iteration;
  const std::vector<Eigen::VectorXd> traces = state.normal_traces();
  const std::vector<Eigen::VectorXd> forces = state.contact_forces();
  const ContactGraph& graph = problem.graph;
  const InterfaceResiduals residuals = interface_residuals(
      problem.gaps, graph.side(0, traces), graph.side(1, traces), graph.side(0, forces),
      graph.side(1, forces), force_displacement(state, compliance));
  const double correction = maximum_absolute(state.corrections());
  const double displacement_scale =
      std::max({maximum_absolute(problem.gaps), maximum_absolute(traces), correction,
                force_displacement(state, compliance), std::numeric_limits<double>::min()});
  record.penetration = residuals.penetration;
  record.force_balance = residuals.force_balance;
  record.complementarity = residuals.complementarity;
  record.correction = correction / displacement_scale;
  return record;
}

/// Per block (max norms): the step |x_{k+1} - x_k| and the fixed-point residual |H(x_k) - x_k|,
/// and the scale that makes them relative: max(|x_{k+1}|, |d|, |u1_N|, |u2_N|, c max|lambda|).
struct ObstacleChange {
  std::vector<double> per_block;
  std::vector<double> residual_per_block;
  double scale = 0.0;
  double relative() const { return *std::max_element(per_block.begin(), per_block.end()) / scale; }
};

ObstacleChange obstacle_change(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped,
                               const Eigen::VectorXd& next, const std::vector<int>& block_sizes,
                               const Eigen::VectorXd& gaps, const CouplingState& state,
                               double compliance) {
  ObstacleChange change;
  change.scale = std::max(
      {maximum_absolute(next), maximum_absolute(gaps), maximum_absolute(state.normal_traces()),
       force_displacement(state, compliance), std::numeric_limits<double>::min()});
  Eigen::Index offset = 0;
  for (const int size : block_sizes) {
    change.per_block.push_back(
        maximum_absolute(next.segment(offset, size) - iterate.segment(offset, size)));
    change.residual_per_block.push_back(
        maximum_absolute(mapped.segment(offset, size) - iterate.segment(offset, size)));
    offset += size;
  }
  return change;
}

/// The contact forces lambda_k of one body over the iterations, for an estimate of the distance
/// of lambda_k to the limit lambda*. With D_k = |lambda_k - lambda_{k-1}| (max norm), the larger
/// of two estimates:
///  - contraction: with rho = D_k / D_{k-1}, a sequence converging linearly with ratio rho has
///    |lambda_k - lambda*| <= rho / (1 - rho) D_k <= D_k / (1 - rho);
///  - step length: D_k was caused by the obstacle step s = |x_k - x_{k-1}| of the body's block,
///    while the obstacle is still r = |H(x_k) - x_k| from its fixed point; an accelerator that
///    takes a short step (an Aitken factor near 0) makes D_k small far from the solution, so
///    D_k r / s (lambda is Lipschitz in the obstacle, D_k / s estimates the constant).
/// For the plain relaxation s = delta r_{k-1} and the contraction estimate is the sharper one;
/// after an erratic short step the step estimate is. The bare change D_k underestimated the
/// error tenfold for rho = 0.9, and arbitrarily after a short step.
class ForceSequence {
 public:
  /// max(D_k / (1 - rho), D_k r / s) / |lambda_k| (rho capped at maximum_contraction, 0 without
  /// D_{k-1}), at most 1; 1 without a previous value.
  double relative_error_estimate(const Eigen::VectorXd& force, double obstacle_residual) const {
    if (previous_.size() != force.size()) return 1.0;  // no previous value: all changed
    const double change = maximum_absolute(force - previous_);
    const double contraction =
        previous_change_ > 0.0 ? std::min(change / previous_change_, maximum_contraction) : 0.0;
    const double step_estimate =
        obstacle_residual > step_ ? change * (obstacle_residual / std::max(step_, tiny)) : change;
    const double estimate = std::max(change / (1.0 - contraction), step_estimate);
    return std::min(estimate / std::max(maximum_absolute(force), tiny), 1.0);
  }
  /// Records lambda_k and the obstacle step |x_{k+1} - x_k| of the body's block that leads to
  /// lambda_{k+1}.
  void push(const Eigen::VectorXd& force, double obstacle_step) {
    previous_change_ = previous_.size() == force.size() ? maximum_absolute(force - previous_) : 0.0;
    previous_ = force;
    step_ = obstacle_step;
  }
  ForceSequenceState state() const { return {previous_, previous_change_, step_}; }
  void restore(const ForceSequenceState& state) {
    previous_ = state.previous;
    previous_change_ = state.previous_change;
    step_ = state.step;
  }

 private:
  static constexpr double maximum_contraction = 0.99;
  static constexpr double tiny = std::numeric_limits<double>::min();
  Eigen::VectorXd previous_;
  double previous_change_ = 0.0;
  double step_ = 0.0;
};

/// The residuals of the complete state of obstacle sequence k: its penetration and
/// complementarity, the change of its own obstacle blocks, and the estimated relative error of
/// its contact forces (ForceSequence).
SequenceResiduals completion_residuals(const CouplingState& completion,
                                       const CouplingProblem& problem, double compliance,
                                       double block_change, double obstacle_residual,
                                       const Eigen::VectorXd& force, const ForceSequence& forces) {
  const IterationRecord record = residual_record(0, problem, completion, compliance);
  SequenceResiduals residuals;
  residuals.obstacle_change = block_change;
  residuals.penetration = record.penetration;
  residuals.complementarity = record.complementarity;
  residuals.force_error = forces.relative_error_estimate(force, obstacle_residual);
  return residuals;
}

/// The contact forces of a sequence's bodies, stacked in body order.
Eigen::VectorXd sequence_forces(const CouplingState& state, const ObstacleSequence& sequence) {
  std::vector<Eigen::VectorXd> forces;
  for (const int body : sequence.bodies) {
    forces.push_back(state.bodies[static_cast<std::size_t>(body)].contact_force);
  }
  return concatenate(forces);
}

/// The largest of `per_block` over the sequence's blocks.
double sequence_block_value(const std::vector<double>& per_block,
                            const ObstacleSequence& sequence) {
  double largest = 0.0;
  for (const int block : sequence.blocks) {
    largest = std::max(largest, per_block[static_cast<std::size_t>(block)]);
  }
  return largest;
}

/// The result of a loop that had stopped when `checkpoint` was written.
RobinResult stopped_result(const IterationCheckpoint& checkpoint) {
  RobinResult result;
  result.status = checkpoint.status;
  result.message = checkpoint.message;
  result.algorithm = checkpoint.algorithm;
  result.history = checkpoint.history;
  result.state = checkpoint.state;
  result.completed_by_sequence = checkpoint.completed_by_sequence;
  result.restart_iterate = checkpoint.restart_iterate;
  result.initial_iterate = checkpoint.initial_iterate;
  result.critical_compute_seconds = checkpoint.critical_compute_seconds;
  result.wall_seconds = checkpoint.wall_seconds;
  result.coordinator_seconds = checkpoint.wall_seconds - checkpoint.port_seconds;
  return result;
}

/// The record of one iteration: the joint state's residuals, the obstacle change, the
/// counters and, per obstacle sequence, the largest residual of its complete state.
IterationRecord iteration_record(int iteration, const CouplingProblem& problem, double compliance,
                                 const CouplingScheme& scheme, const CouplingEvaluation& evaluation,
                                 const ObstacleChange& change,
                                 const std::vector<ForceSequence>& force_sequences) {
  IterationRecord record = residual_record(iteration, problem, evaluation.state, compliance);
  if (scheme.shares_contact_force()) {
    record.force_balance = force_sequences[0].relative_error_estimate(
        evaluation.state.bodies[0].contact_force,
        *std::max_element(change.residual_per_block.begin(), change.residual_per_block.end()));
  }
  record.obstacle_change = change.relative();
  record.obstacle_step = change.relative() * change.scale;
  record.active = evaluation.active;
  record.qp_iterations = evaluation.qp_iterations;
  const std::vector<ObstacleSequence> sequences = scheme.sequences();
  for (std::size_t k = 0; k < evaluation.completions.size(); ++k) {
    record.sequences.push_back(
        completion_residuals(evaluation.completions[k], problem, compliance,
                             sequence_block_value(change.per_block, sequences[k]) / change.scale,
                             sequence_block_value(change.residual_per_block, sequences[k]),
                             sequence_forces(evaluation.state, sequences[k]), force_sequences[k]));
  }
  return record;
}

/// When the joint state or (with "either-sequence") a complete state has every residual below
/// the tolerance: stores the accepted state and the status in `result` and returns true.
bool accept_converged_state(const IterationRecord& record, const CouplingEvaluation& evaluation,
                            const std::vector<ObstacleSequence>& sequences,
                            const CouplingOptions& options, RobinResult& result) {
  const std::string iterations = std::to_string(record.iteration) + " iterations";
  if (record.largest() <= options.tolerance) {
    result.status = IterationStatus::converged;
    result.message = "converged in " + iterations;
    return true;
  }
  if (options.stopping != StoppingRule::either_sequence) return false;
  for (std::size_t k = 0; k < record.sequences.size(); ++k) {
    if (record.sequences[k].largest() > options.tolerance) continue;
    result.state = evaluation.completions[k];
    result.status = IterationStatus::converged;
    result.completed_by_sequence = static_cast<int>(k) + 1;
    const bool alone = sequences[k].bodies.size() == 1;
    result.message = "converged in " + iterations + " (the obstacle sequence of " +
                     describe_bodies(sequences[k].bodies) + " reached its fixed point; " +
                     (evaluation.state.bodies.size() == 2
                          ? std::string("the other body takes its contact force)")
                          : std::string("the bodies touching ") + (alone ? "it" : "them") +
                                " take " + (alone ? "its" : "their") + " contact forces)");
    return true;
  }
  return false;
}

}  // namespace

double SequenceResiduals::largest() const {
  return std::max({obstacle_change, penetration, complementarity, force_error});
}

double IterationRecord::largest() const {
  return std::max({obstacle_change, penetration, force_balance, complementarity, correction});
}

double IterationRecord::progress(bool either_sequence) const {
  double value = largest();
  if (!either_sequence) return value;
  for (const SequenceResiduals& sequence : sequences) value = std::min(value, sequence.largest());
  return value;
}

const SequenceResiduals* RobinResult::accepted_sequence() const {
  if (history.empty() || completed_by_sequence == 0) return nullptr;
  return &history.back().sequences[completed_by_sequence - 1];
}

double RobinResult::final_largest_residual() const {
  if (history.empty()) return 0.0;
  const SequenceResiduals* accepted = accepted_sequence();
  return accepted != nullptr ? accepted->largest() : history.back().largest();
}

std::string to_string(IterationStatus status) {
  switch (status) {
    case IterationStatus::converged:
      return "converged";
    case IterationStatus::max_iterations:
      return "iteration limit reached";
    case IterationStatus::diverged:
      return "diverged";
    case IterationStatus::stagnated:
      return "stagnated";
  }
  return "unknown";
}

namespace {

/// The problem of two bodies and one interface from its vectors.
CouplingProblem two_body_problem(const Eigen::VectorXd& gaps, const Eigen::VectorXd& weights,
                                 const Eigen::VectorXd& probe_forces) {
  CouplingProblem problem;
  problem.graph = ContactGraph::two_bodies(gaps.size());
  problem.gaps = gaps;
  problem.weights = weights;
  problem.probe_forces = probe_forces;
  return problem;
}

}  // namespace

RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const Eigen::VectorXd& gaps, const CouplingOptions& options,
                                const IterationObserver& observer) {
  return run_robin_iteration(body1, body2, gaps, Eigen::VectorXd::Ones(gaps.size()), options,
                             observer);
}

RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const ContactPairing& pairing, const CouplingOptions& options,
                                const IterationObserver& observer) {
  return run_robin_iteration({&body1, &body2}, two_body_problem(pairing), options, nullptr, {},
                             observer);
}

RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const ContactPairing& pairing, const CouplingOptions& options,
                                const Eigen::VectorXd& initial_iterate,
                                const IterationObserver& observer) {
  return run_robin_iteration({&body1, &body2}, two_body_problem(pairing), options, &initial_iterate,
                             {}, observer);
}

RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const ContactPairing& pairing, const CouplingOptions& options,
                                const Eigen::VectorXd* initial_iterate,
                                const IterationContinuation& continuation,
                                const IterationObserver& observer) {
  return run_robin_iteration({&body1, &body2}, two_body_problem(pairing), options, initial_iterate,
                             continuation, observer);
}

RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const Eigen::VectorXd& gaps, const Eigen::VectorXd& weights,
                                const CouplingOptions& options, const IterationObserver& observer) {
  Eigen::VectorXd probe = weights;  // without positions: alternate in pair order
  for (Eigen::Index i = 1; i < probe.size(); i += 2) probe[i] = -probe[i];
  return run_robin_iteration({&body1, &body2}, two_body_problem(gaps, weights, probe), options,
                             nullptr, {}, observer);
}

namespace {

/// The accuracy the probe needs: c scales a floor of the residuals and compares bodies, so
/// three digits are plenty (the hint of CorrectionRequest.relative_accuracy).
constexpr double probe_relative_accuracy = 1e-3;

/// The local interface compliance c = max over bodies of |F^a r^a| / |r^a| (max norms), r^a the
/// short-wavelength probe on body a's rows (boundary weights of alternating sign,
/// coupling_scheme.hpp): the interface displacement per unit nodal force of a load that does
/// not bend the body as a whole, so c F is the local indentation of forces of size F, a scale
/// below that of the displacements contact forces spread over a zone cause. Measured by one
/// correction solve per body (iteration 0, all bodies in parallel; the factor only, so no contact
/// warm start changes). It scales the displacement floor of the residuals (force_displacement) and,
/// like them, scales with the loads. The responses also choose the contact body of
/// "dirichlet-neumann" with contact_body "auto" (CouplingProblem::probe_responses).
std::vector<Eigen::VectorXd> probe_responses(const std::vector<SubdomainPort*>& ports,
                                             const CouplingProblem& problem) {
  std::vector<Eigen::VectorXd> probes;
  for (std::size_t body = 0; body < ports.size(); ++body) {
    probes.push_back(problem.graph.body_part(static_cast<int>(body), problem.probe_forces));
    if (probes.back().size() > 0) {
      ports[body]->start_correction(probes.back(), 0, probe_relative_accuracy);
    }
  }
  std::vector<Eigen::VectorXd> responses(ports.size());
  for (std::size_t body = 0; body < ports.size(); ++body) {
    if (probes[body].size() > 0) responses[body] = ports[body]->finish_correction().normal_trace;
  }
  return responses;
}

/// c from the probe responses F^a r^a of probe_responses().
double interface_compliance(const CouplingProblem& problem,
                            const std::vector<Eigen::VectorXd>& responses) {
  double compliance = 0.0;
  for (std::size_t body = 0; body < responses.size(); ++body) {
    const double load =
        maximum_absolute(problem.graph.body_part(static_cast<int>(body), problem.probe_forces));
    if (load > 0.0) compliance = std::max(compliance, maximum_absolute(responses[body]) / load);
  }
  return compliance;
}

/// What the loop carries from one iteration to the next, besides the ports.
struct LoopMemory {
  Acceleration& acceleration;
  ProgressMonitor& monitor;
  std::vector<ForceSequence>& force_sequences;
};

/// Restores the loop's memory from `checkpoint` and repeats its contact solves (the servers'
/// warm start); returns the iterate of the next iteration. Throws CheckpointFormatError when
/// the checkpoint's iterate does not fit the scheme.
Eigen::VectorXd resume_loop(const IterationCheckpoint& checkpoint, CouplingScheme& scheme,
                            const LoopMemory& memory, Eigen::Index iterate_size,
                            RobinResult& result) {
  const bool iterates_fit =
      static_cast<int>(checkpoint.iterates.size()) == checkpoint.iteration &&
      std::all_of(checkpoint.iterates.begin(), checkpoint.iterates.end(),
                  [&](const Eigen::VectorXd& iterate) { return iterate.size() == iterate_size; });
  if (checkpoint.next_iterate.size() != iterate_size || !iterates_fit ||
      checkpoint.algorithm != result.algorithm) {
    std::ostringstream text;
    text << "the checkpoint's iterate (" << checkpoint.next_iterate.size() << " values, "
         << checkpoint.algorithm << ") does not fit this run's iteration (" << iterate_size
         << " values, " << result.algorithm << ")";
    throw CheckpointFormatError(text.str());
  }
  memory.acceleration.restore_state(checkpoint.acceleration);
  memory.monitor.restore(checkpoint.monitor);
  if (checkpoint.force_sequences.size() != memory.force_sequences.size()) {
    throw CheckpointFormatError("the checkpoint follows " +
                                std::to_string(checkpoint.force_sequences.size()) +
                                " obstacle sequences, this run's iteration " +
                                std::to_string(memory.force_sequences.size()));
  }
  for (std::size_t sequence = 0; sequence < checkpoint.force_sequences.size(); ++sequence) {
    memory.force_sequences[sequence].restore(checkpoint.force_sequences[sequence]);
  }
  result.history = checkpoint.history;
  result.initial_iterate = checkpoint.initial_iterate;
  result.restart_iterate = checkpoint.restart_iterate;
  result.critical_compute_seconds = checkpoint.critical_compute_seconds;
  result.state = checkpoint.state;
  for (std::size_t index = 0; index < checkpoint.iterates.size(); ++index) {
    scheme.repeat_contact_solves(checkpoint.iterates[index], static_cast<int>(index) + 1);
  }
  return checkpoint.next_iterate;
}

IterationCheckpoint make_checkpoint(const RobinResult& result, const LoopMemory& memory,
                                    const std::vector<Eigen::VectorXd>& iterates,
                                    const Eigen::VectorXd& next, bool stopped) {
  IterationCheckpoint checkpoint;
  checkpoint.iteration = static_cast<int>(result.history.size());
  checkpoint.stopped = stopped;
  checkpoint.status = result.status;
  checkpoint.message = result.message;
  checkpoint.algorithm = result.algorithm;
  checkpoint.completed_by_sequence = result.completed_by_sequence;
  checkpoint.iterates = iterates;
  checkpoint.next_iterate = next;
  checkpoint.initial_iterate = result.initial_iterate;
  checkpoint.restart_iterate = result.restart_iterate;
  checkpoint.state = result.state;
  checkpoint.acceleration = memory.acceleration.save_state();
  checkpoint.monitor = memory.monitor.state();
  for (const ForceSequence& sequence : memory.force_sequences) {
    checkpoint.force_sequences.push_back(sequence.state());
  }
  checkpoint.history = result.history;
  checkpoint.critical_compute_seconds = result.critical_compute_seconds;
  return checkpoint;
}

}  // namespace

RobinResult run_robin_iteration(const std::vector<SubdomainPort*>& ports,
                                const CouplingProblem& problem, const CouplingOptions& options,
                                const Eigen::VectorXd* initial_iterate,
                                const IterationContinuation& continuation,
                                const IterationObserver& observer) {
  const Eigen::VectorXd& gaps = problem.gaps;
  const IterationCheckpoint* resume = continuation.resume;
  if (resume != nullptr && resume->stopped) return stopped_result(*resume);
  const auto run_start = Clock::now();
  // the wall and port time of the iterations before a resume
  const double earlier_wall = resume != nullptr ? resume->wall_seconds : 0.0;
  double port_seconds = resume != nullptr ? resume->port_seconds : 0.0;
  const auto setup_start = Clock::now();
  CouplingProblem probed = problem;
  probed.probe_responses = probe_responses(ports, problem);
  const double compliance = interface_compliance(problem, probed.probe_responses);
  const std::unique_ptr<CouplingScheme> scheme = make_coupling_scheme(options, ports, probed);
  port_seconds += seconds_between(setup_start, Clock::now());
  const std::vector<int> block_sizes = scheme->block_sizes();
  const std::unique_ptr<Acceleration> acceleration =
      make_acceleration(effective_acceleration(options), block_sizes);
  RobinResult result;
  result.algorithm = scheme->describe();
  Eigen::VectorXd iterate = scheme->initial_iterate(
      options.initial_obstacle == InitialObstacle::zero ? Eigen::VectorXd::Zero(gaps.size())
                                                        : gaps);
  if (initial_iterate != nullptr && resume == nullptr) {
    if (initial_iterate->size() != iterate.size()) {
      throw InputError("the initial iterate of the " + result.algorithm + " iteration has " +
                       std::to_string(initial_iterate->size()) + " values, expected " +
                       std::to_string(iterate.size()));
    }
    iterate = *initial_iterate;
  }
  result.initial_iterate = iterate;
  ProgressMonitor monitor(options);
  const std::vector<ObstacleSequence> sequences = scheme->sequences();
  // each sequence's lambda over the iterations
  std::vector<ForceSequence> force_sequences(sequences.size());
  const LoopMemory memory{*acceleration, monitor, force_sequences};
  int first_iteration = 1;
  std::vector<Eigen::VectorXd> iterates;  // x_1 ... x_k, for checkpoints
  if (resume != nullptr) {
    const auto resume_start = Clock::now();
    iterate = resume_loop(*resume, *scheme, memory, iterate.size(), result);
    port_seconds += seconds_between(resume_start, Clock::now());
    first_iteration = resume->iteration + 1;
    if (continuation.checkpoint) iterates = resume->iterates;
  }
  result.status = IterationStatus::max_iterations;
  result.message = "the iteration limit of " + std::to_string(options.max_iterations) +
                   " iterations was reached before the tolerance " +
                   format_number(options.tolerance);
  for (int iteration = first_iteration; iteration <= options.max_iterations; ++iteration) {
    const auto iteration_start = Clock::now();
    const CouplingEvaluation evaluation = scheme->evaluate(iterate, iteration);
    const auto update_start = Clock::now();
    port_seconds += seconds_between(iteration_start, update_start);
    result.critical_compute_seconds += evaluation.critical_compute_seconds;
    // The obstacle update x_{k+1} = A(x_k, H(x_k)); "none" is the paper's (1 - delta) x + delta H.
    const Eigen::VectorXd next = acceleration->next(iterate, evaluation.mapped);
    const ObstacleChange change = obstacle_change(iterate, evaluation.mapped, next, block_sizes,
                                                  gaps, evaluation.state, compliance);
    IterationRecord record = iteration_record(iteration, problem, compliance, *scheme, evaluation,
                                              change, force_sequences);
    for (std::size_t k = 0; k < sequences.size(); ++k) {
      force_sequences[k].push(sequence_forces(evaluation.state, sequences[k]),
                              sequence_block_value(change.per_block, sequences[k]));
    }
    record.acceleration_state = acceleration->state();
    record.seconds = seconds_between(iteration_start, Clock::now());
    result.history.push_back(record);
    result.state = evaluation.state;
    result.restart_iterate = evaluation.mapped;
    bool stopped = accept_converged_state(record, evaluation, sequences, options, result);
    if (!stopped) {
      if (const auto stop = monitor.check(record, result.message)) {
        result.status = *stop;
        stopped = true;
      }
    }
    if (!stopped && iteration == options.max_iterations) stopped = true;
    if (continuation.checkpoint) {
      iterates.push_back(iterate);
      IterationCheckpoint checkpoint = make_checkpoint(result, memory, iterates, next, stopped);
      checkpoint.port_seconds = port_seconds;
      checkpoint.wall_seconds = earlier_wall + seconds_between(run_start, Clock::now());
      continuation.checkpoint(checkpoint);
    }
    if (observer) observer(record);
    if (stopped) break;
    iterate = next;
  }
  result.wall_seconds = earlier_wall + seconds_between(run_start, Clock::now());
  result.coordinator_seconds = result.wall_seconds - port_seconds;
  return result;
}

}  // namespace robin
