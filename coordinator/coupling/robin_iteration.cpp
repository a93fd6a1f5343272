#include "coupling/robin_iteration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "coupling/monolithic_solver.hpp"

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
    const double value = record.largest();
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

void require_converged(const ContactSolveResult& result, const SubdomainPort& port, int iteration) {
  if (result.status == QpStatus::converged) return;
  throw PortError(port.describe() + ", step contact solve (iteration " + std::to_string(iteration) +
                  "): the contact QP returned '" + to_string(result.status) +
                  "': " + result.message);
}

IterationRecord make_record(int iteration, const Eigen::VectorXd& gaps,
                            const ContactSolveResult& contact1, const ContactSolveResult& contact2,
                            const Eigen::VectorXd& correction1, const Eigen::VectorXd& correction2,
                            double obstacle_change) {
  IterationRecord record;
  record.iteration = iteration;
  const InterfaceResiduals residuals =
      interface_residuals(gaps, contact1.normal_trace, contact2.normal_trace,
                          contact1.contact_force, contact2.contact_force);
  const double displacement_scale =
      std::max({maximum_absolute(gaps), maximum_absolute(contact1.normal_trace),
                maximum_absolute(contact2.normal_trace), maximum_absolute(correction1),
                maximum_absolute(correction2), std::numeric_limits<double>::min()});
  record.penetration = residuals.penetration;
  record.force_balance = residuals.force_balance;
  record.complementarity = residuals.complementarity;
  record.correction =
      std::max(maximum_absolute(correction1), maximum_absolute(correction2)) / displacement_scale;
  record.obstacle_change = obstacle_change;
  record.active1 =
      static_cast<int>(std::count(contact1.active.begin(), contact1.active.end(), true));
  record.active2 =
      static_cast<int>(std::count(contact2.active.begin(), contact2.active.end(), true));
  record.qp_iterations1 = contact1.iterations;
  record.qp_iterations2 = contact2.iterations;
  return record;
}

}  // namespace

double IterationRecord::largest() const {
  return std::max({obstacle_change, penetration, force_balance, complementarity, correction});
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

RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const Eigen::VectorXd& gaps, const CouplingOptions& options,
                                const IterationObserver& observer) {
  const auto run_start = Clock::now();
  double port_seconds = 0.0;
  const Eigen::Index size = gaps.size();
  const std::unique_ptr<Acceleration> acceleration = make_acceleration(
      effective_acceleration(options), static_cast<int>(size), static_cast<int>(size));
  Eigen::VectorXd iterate(2 * size), mapped(2 * size);
  RobinResult result;
  Eigen::VectorXd obstacle1 =
      options.initial_obstacle == "zero" ? Eigen::VectorXd::Zero(gaps.size()) : gaps;
  Eigen::VectorXd obstacle2 = obstacle1;
  ProgressMonitor monitor(options);
  result.status = IterationStatus::max_iterations;
  result.message = "the iteration limit of " + std::to_string(options.max_iterations) +
                   " iterations was reached before the tolerance " +
                   std::to_string(options.tolerance);
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    const auto iteration_start = Clock::now();
    // Step 1, both bodies in parallel: u^a = argmin ... s.t. B^a u <= g^a.
    body1.start_contact_solve(obstacle1, iteration);
    body2.start_contact_solve(obstacle2, iteration);
    const ContactSolveResult contact1 = body1.finish_contact_solve();
    const ContactSolveResult contact2 = body2.finish_contact_solve();
    require_converged(contact1, body1, iteration);
    require_converged(contact2, body2, iteration);
    // Step 2: K^1 w^1 = B^1'(lambda^2 - lambda^1), K^2 w^2 = B^2'(lambda^1 - lambda^2).
    const Eigen::VectorXd imbalance = contact2.contact_force - contact1.contact_force;
    const auto correction_start = Clock::now();
    port_seconds += seconds_between(iteration_start, correction_start);
    body1.start_correction(imbalance, iteration);
    body2.start_correction(-imbalance, iteration);
    const CorrectionSolveResult correction1 = body1.finish_correction();
    const CorrectionSolveResult correction2 = body2.finish_correction();
    const auto update_start = Clock::now();
    port_seconds += seconds_between(correction_start, update_start);
    result.critical_compute_seconds += std::max(contact1.seconds, contact2.seconds) +
                                       std::max(correction1.seconds, correction2.seconds);
    // Step 3: the obstacle update x_{k+1} = A(x_k, H(x_k)) on x = (g1, g2), with the map
    // H = (w2_N - u2_N + d, w1_N - u1_N + d); "none" is the paper's (1 - delta) x + delta H.
    iterate << obstacle1, obstacle2;
    mapped << correction2.normal_trace - contact2.normal_trace + gaps,
        correction1.normal_trace - contact1.normal_trace + gaps;
    const Eigen::VectorXd next = acceleration->next(iterate, mapped);
    const Eigen::VectorXd next1 = next.head(size);
    const Eigen::VectorXd next2 = next.tail(size);
    const double change_scale =
        std::max({maximum_absolute(next1), maximum_absolute(next2), maximum_absolute(gaps),
                  maximum_absolute(contact1.normal_trace), maximum_absolute(contact2.normal_trace),
                  std::numeric_limits<double>::min()});
    const double change =
        std::max(maximum_absolute(next1 - obstacle1), maximum_absolute(next2 - obstacle2)) /
        change_scale;
    IterationRecord record =
        make_record(iteration, gaps, contact1, contact2, correction1.normal_trace,
                    correction2.normal_trace, change);
    record.obstacle_step = change * change_scale;
    record.acceleration_state = acceleration->state();
    record.seconds = seconds_between(iteration_start, Clock::now());
    result.history.push_back(record);
    result.obstacle1 = obstacle1;
    result.obstacle2 = obstacle2;
    result.normal_trace1 = contact1.normal_trace;
    result.normal_trace2 = contact2.normal_trace;
    result.contact_force1 = contact1.contact_force;
    result.contact_force2 = contact2.contact_force;
    result.correction1 = correction1.normal_trace;
    result.correction2 = correction2.normal_trace;
    if (observer) observer(record);
    if (record.largest() <= options.tolerance) {
      result.status = IterationStatus::converged;
      result.message = "converged in " + std::to_string(iteration) + " iterations";
      break;
    }
    if (const auto stop = monitor.check(record, result.message)) {
      result.status = *stop;
      break;
    }
    obstacle1 = next1;
    obstacle2 = next2;
  }
  result.wall_seconds = seconds_between(run_start, Clock::now());
  result.coordinator_seconds = result.wall_seconds - port_seconds;
  return result;
}

}  // namespace robin
