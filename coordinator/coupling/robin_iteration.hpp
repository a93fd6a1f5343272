#pragma once
// Algorithm (Q_m) of Ipopa & Sassi (2008), paper (10)-(13), driven through two subdomain
// ports. One iteration, with d the initial gaps:
//   step 1 (both bodies in parallel): u^a = argmin 1/2 u'K^a u - f^a'u s.t. B^a u <= g^a,
//          returning u^a_N and lambda^a >= 0;
//   step 2 (both in parallel): w^1_N = F^1 (lambda^2 - lambda^1), w^2_N = F^2 (lambda^1 -
//   lambda^2); step 3: g^1 <- (1 - delta) g^1 + delta (w^2_N - u^2_N + d),
//           g^2 <- (1 - delta) g^2 + delta (w^1_N - u^1_N + d),
//           or an accelerated update of the same map (CouplingOptions::acceleration).
// Convergence: every scaled residual of IterationRecord below the tolerance. At the fixed point
// lambda^1 = lambda^2, w = 0 and the state solves the monolithic problem (Prop. 3.2).
// With stopping "either-sequence" (default) the run also stops when the complete state of one
// obstacle sequence has all its residuals below the tolerance (coupling_scheme.hpp). The same
// loop runs the other algorithms of coupling_scheme.hpp.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "coupling/case_file.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/coupling_scheme.hpp"
#include "coupling/subdomain_port.hpp"

namespace robin {

/// Residuals of the complete state of one obstacle sequence (coupling_scheme.hpp,
/// "Completions"), scaled as in IterationRecord. Its force balance and correction vanish by
/// construction; force_error stands in for them: the estimated relative distance of the
/// sequence's contact force to its limit (robin_iteration.cpp, ForceSequence), since small
/// displacement residuals alone can hide a force error amplified by the interface stiffness.
struct SequenceResiduals {
  double obstacle_change = 0.0;  // change of the sequence's own obstacle block
  double penetration = 0.0;
  double complementarity = 0.0;
  double force_error = 0.0;
  double largest() const;
};

/// Residuals of one iteration, all dimensionless: displacement-like quantities are divided by
/// the displacement scale D = max(|d|, |u1_N|, |u2_N|, c F) (and |w_N| for the correction), forces
/// by F = max(|lambda1|, |lambda2|); c = max_a |F^a r| / |r|, the local interface compliance
/// measured by one correction solve per body with the short-wavelength probe r at the start of
/// the loop (iteration 0). On a contact graph the same over every row, with 1 and 2 the
/// row's two sides (bodies a and b of its interface) and every body's u_N, w_N and lambda.
///
/// Stopping, on the value progress() below (history.csv: stopping_residual): converged when it
/// is at most the tolerance; diverged when the raw obstacle step grows beyond divergence_factor
/// times its smallest value (and beyond the first step), or when it has not contracted at all
/// (still >= 0.1) after a stagnation window; stagnated when it has not decreased by 1% in
/// stagnation_window iterations.
struct IterationRecord {
  int iteration = 0;
  double obstacle_change = 0.0;    // |g_new - g_old| / max(|g_new|, D), both bodies, max norm
  double obstacle_step = 0.0;      // |g_new - g_old| (length), unscaled: watched for divergence
  double penetration = 0.0;        // max(0, u1_N + u2_N - d) / D
  double force_balance = 0.0;      // |lambda1 - lambda2| / F (for "dirichlet-neumann", whose
                                   // bodies share lambda: |lambda_k - lambda_{k-1}| / F)
  double complementarity = 0.0;    // |lambda (d - u1_N - u2_N)| / (F D), lambda = mean
  double correction = 0.0;         // max(|w1_N|, |w2_N|) / D
  std::vector<int> active;         // per body: closed rows seen by its contact solve
  std::vector<int> qp_iterations;  // per body: iterations of its contact QP
  double seconds = 0.0;            // wall time of the iteration
  std::string acceleration_state;  // e.g. "iqn-ils 4 columns", for progress lines
  /// "robin": the residuals of the complete state of each obstacle sequence
  /// (coupling_scheme.hpp, "Completions"); empty for the other algorithms.
  std::vector<SequenceResiduals> sequences;
  double largest() const;  // the largest residual of the joint state
  /// What the stopping test compares with the tolerance: largest(), or with
  /// `either_sequence` the smallest of largest() and the sequence residuals.
  double progress(bool either_sequence) const;
};

enum class IterationStatus { converged, max_iterations, diverged, stagnated };
std::string to_string(IterationStatus status);

struct RobinResult {
  IterationStatus status = IterationStatus::max_iterations;
  std::string message;    // why it stopped, for people
  std::string algorithm;  // the scheme, e.g. "dirichlet-neumann (contact body 1)"
  std::vector<IterationRecord> history;
  /// The state of the last iteration, per body in body order (contact_graph.hpp; two bodies:
  /// pair order): the obstacles g of the last contact solves, u_N, lambda, w_N.
  CouplingState state;
  /// 0, or the obstacle sequence (1, 2) whose complete state was accepted: then `state` holds
  /// that state (the contact forces of both sides of every row equal, corrections zero) and its
  /// residuals are history.back().sequences[completed_by_sequence - 1], not those of the joint
  /// state.
  int completed_by_sequence = 0;
  /// The residuals of the accepted complete state, or null when the joint state was accepted
  /// (or the run stopped otherwise).
  const SequenceResiduals* accepted_sequence() const;
  /// The largest scaled residual of the state in the fields above: that of the accepted
  /// complete state, or of the last joint state.
  double final_largest_residual() const;
  /// The iterate a nearby problem (the next load step) starts from: the fixed-point image
  /// H(x) of the last iteration (for "robin" the obstacles (w2_N - u2_N + d, w1_N - u1_N + d)),
  /// which at convergence is the fixed point itself. Its layout is the scheme's iterate, so it
  /// is valid only for a run of the same algorithm on the same pairing.
  Eigen::VectorXd restart_iterate;
  /// The iterate of the first iteration (the scheme's start from the initial obstacle, or the
  /// given initial iterate).
  Eigen::VectorXd initial_iterate;
  double coordinator_seconds = 0.0;  // time in the coordinator's own computations
  /// Critical path of the bodies' compute: sum over iterations of the slowest contact solve plus
  /// the slowest correction solve, as reported by the bodies.
  double critical_compute_seconds = 0.0;
  double wall_seconds = 0.0;
  /// Transport time: wall - coordinator - critical compute (for in-process ports this is the
  /// serialisation of the two bodies, which run one after the other).
  double messaging_seconds() const {
    return wall_seconds - coordinator_seconds - critical_compute_seconds;
  }
};

using IterationObserver = std::function<void(const IterationRecord&)>;

struct IterationCheckpoint;  // iteration_checkpoint.hpp

/// Checkpointing and resuming the loop (iteration_checkpoint.hpp).
struct IterationContinuation {
  /// When set, the loop continues after this checkpoint's iteration k instead of starting: it
  /// restores the acceleration, the monitors and the history, repeats the contact solves of
  /// iteration k (the servers' warm start) and runs iteration k + 1 at its next_iterate; a
  /// checkpoint of a stopped loop is returned as the result without any request. Must come
  /// from a run of the same algorithm and options on the same pairing.
  const IterationCheckpoint* resume = nullptr;
  /// Told the loop's state after every iteration (after the stopping test), e.g. to write it.
  std::function<void(const IterationCheckpoint&)> checkpoint;
};

/// Runs the coupling algorithm of options.algorithm (coupling_scheme.hpp) on the contact graph
/// of `problem`, with one port per body (body order) whose contact has been assigned (each body
/// its rows in body order), starting from `initial_iterate` when it is not null, checkpointed
/// and possibly resumed as `continuation` says (its resume takes precedence over
/// `initial_iterate`). Throws PortError when a port fails or a contact QP does not converge (the
/// message names server, body and step), InputError for inconsistent options.
RobinResult run_robin_iteration(const std::vector<SubdomainPort*>& ports,
                                const CouplingProblem& problem, const CouplingOptions& options,
                                const Eigen::VectorXd* initial_iterate,
                                const IterationContinuation& continuation,
                                const IterationObserver& observer = {});

/// The same for two bodies and one interface:
/// Runs the coupling algorithm of options.algorithm (coupling_scheme.hpp) on two ports whose
/// contact has been assigned, with the pairs' initial gaps and boundary weights (pair order).
/// Throws PortError when a port fails or a contact QP does not converge (the message names
/// server, body and step), InputError for inconsistent options.
RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const Eigen::VectorXd& gaps, const Eigen::VectorXd& weights,
                                const CouplingOptions& options,
                                const IterationObserver& observer = {});
/// The same for a pairing (gaps, weights and the probe of short_wavelength_forces).
RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const ContactPairing& pairing, const CouplingOptions& options,
                                const IterationObserver& observer = {});
/// The same, starting from `initial_iterate` (the restart_iterate of a previous run of the same
/// algorithm on the same pairing, e.g. the previous load step) instead of the initial
/// obstacle of `options`. Throws InputError when its size is not that of the scheme's iterate.
RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const ContactPairing& pairing, const CouplingOptions& options,
                                const Eigen::VectorXd& initial_iterate,
                                const IterationObserver& observer = {});
/// The same, starting from `initial_iterate` when it is not null, checkpointed and possibly
/// resumed as `continuation` says (its resume takes precedence over `initial_iterate`).
RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const ContactPairing& pairing, const CouplingOptions& options,
                                const Eigen::VectorXd* initial_iterate,
                                const IterationContinuation& continuation,
                                const IterationObserver& observer = {});
/// The same with unit weights (enough for every algorithm but "robin-constant").
RobinResult run_robin_iteration(SubdomainPort& body1, SubdomainPort& body2,
                                const Eigen::VectorXd& gaps, const CouplingOptions& options,
                                const IterationObserver& observer = {});

}  // namespace robin
