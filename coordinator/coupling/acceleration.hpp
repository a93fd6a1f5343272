#pragma once
// Convergence acceleration of the Robin obstacle iteration (paper (13), step 3).
//
// The iteration is a fixed-point map x -> H(x) on the stacked obstacles x = (g^1, g^2), with
//   H^1(g) = w^2_N - u^2_N + d,   H^2(g) = w^1_N - u^1_N + d,
// and residual r(x) = H(x) - x. The two blocks are independent maps, H^1 depending on g^1 only and
// H^2 on g^2 only (docs/method.md, "Either sequence alone"; in the all-active regime they are
// linear, "Choosing delta"), which is why every method can run per body. Methods:
//   "none"    x_{k+1} = (1 - delta_a) x_k + delta_a H(x_k) per body: exactly the paper's update;
//   "aitken"  the same with a dynamic factor omega per body (Irons-Tuck / Aitken);
//   "iqn-ils" Anderson mixing / interface quasi-Newton with inverse least squares, on each
//             body (per_body, the default) or on the stacked vector.
// The module is plain arithmetic on vectors: no transport, no logging.

#include <Eigen/Core>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "coupling/coupling_choices.hpp"

namespace robin {

struct AccelerationOptions {
  /// "none", "aitken" or "iqn-ils". Default "iqn-ils" (per body, full mixing); with the
  /// "either-sequence" stopping of the Robin loop its iteration count does not grow with the
  /// mesh on the cases of docs/iteration-study.md, which lists the counts of every method.
  AccelerationMethod method = AccelerationMethod::iqn_ils;
  /// delta per body: the step of "none", and the first step (and every restart) of "iqn-ils".
  double relaxation1 = 0.5, relaxation2 = 0.5;
  /// "aitken": the first omega of each body, then |omega| is clamped to [minimum, maximum]
  /// keeping its sign (relaxation1/2 do not apply). The bounds also bound the "aitken" mixing
  /// of "iqn-ils".
  double aitken_initial = 0.5, aitken_minimum = 1e-4, aitken_maximum = 1.0;
  int history_depth = 10;           // "iqn-ils": secant columns kept, newest first
  double filter_threshold = 1e-10;  // "iqn-ils": drop a column when |R_ii| < threshold ||V||_F
  /// "iqn-ils": when a quasi-Newton step gives ||r_k|| > growth ||r_{k-1}||, forget the history
  /// and take a relaxation step.
  double safeguard_growth = 2.0;
  /// "iqn-ils": how the least-squares point x^ and its predicted image h^ are mixed,
  /// x_{k+1} = (1 - beta) x^ + beta h^ per body (acceleration_quasi_newton.hpp):
  /// full (beta = 1, classical IQN-ILS; the default), relaxation (beta = relaxation1/2) or
  /// aitken (beta = the secant estimate of the newest column, |beta| in [aitken_minimum,
  /// aitken_maximum]). With "either-sequence" stopping only the well-conditioned obstacle
  /// sequence must converge; for it "full" leaves the modes outside the secant space multiplied
  /// by about -F^b (F^a)^-1, small, while the secant estimate of "aitken" follows the few
  /// large eigenvalues the history already captures (a cantilever's bending) and freezes the
  /// rest, so that its count grows with mesh refinement where that of "full" does not
  /// (docs/iteration-study.md, "IQN-ILS mixing on the asymmetric pair"). "aitken" keeps a
  /// truncated history of a badly conditioned sequence convergent where "full" may not
  /// (tests/unit/acceleration_test.cpp).
  QuasiNewtonMixing mixing = QuasiNewtonMixing::full;
  /// "iqn-ils": an independent IQN-ILS on each body's block (true), or one on (g^1, g^2).
  /// Per body is the default: the blocks are independent maps, and an ill-conditioned block
  /// then cannot hold back the other (tests/unit/acceleration_test.cpp measures both).
  bool per_body = true;
};

/// Post-processes the fixed-point map x -> H(x) for the stacked obstacles x = (g^1, g^2)
/// (size n1 + n2, body 1 first). An instance keeps the history of one iteration.
class Acceleration {
 public:
  virtual ~Acceleration() = default;
  /// Given the iterate x_k (the obstacles used in this iteration's contact solves) and
  /// H(x_k), returns x_{k+1}. Both vectors have the size given at construction.
  virtual Eigen::VectorXd next(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped) = 0;
  /// One line for logs, e.g. "aitken omega = (0.31, 0.92)", "iqn-ils 4 columns (1 filtered)".
  virtual std::string state() const = 0;
  /// Forgets the history: the next step is a first step again.
  virtual void restart() = 0;
  /// The history, exactly (checkpoint_encoding.hpp): an instance made with the same options and
  /// sizes, given restore_state(save_state()), continues bit for bit as this one would.
  virtual nlohmann::json save_state() const = 0;
  /// Replaces the history by a saved one. Throws CheckpointFormatError (checkpoint_encoding.hpp)
  /// naming the field when `state` is not one of this method and size.
  virtual void restore_state(const nlohmann::json& state) = 0;
};

/// The method of `options` for blocks of sizes size1 (body 1) and size2 (body 2). Validates the
/// options first (throws InputError as validate does).
std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options, int size1,
                                                int size2);
/// The same for one block (single-sequence algorithms: relaxation1 applies) or one block per
/// body of a contact graph (body 1: relaxation1; every other body: relaxation2).
std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options,
                                                const std::vector<int>& block_sizes);

/// Throws robin::InputError naming the field when an option is out of range, e.g.
/// "acceleration.history_depth must be >= 1, got 0".
void validate(const AccelerationOptions& options);

}  // namespace robin
