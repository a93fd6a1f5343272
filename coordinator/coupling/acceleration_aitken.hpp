#pragma once
// Dynamic relaxation of Irons & Tuck (Aitken's delta-squared for vectors) on one block:
//   r_k = H(x_k) - x_k,
//   omega_0 = initial,
//   omega_k = -omega_{k-1} r_{k-1}'(r_k - r_{k-1}) / |r_k - r_{k-1}|^2      (k >= 1),
//   x_{k+1} = (1 - omega_k) x_k + omega_k H(x_k).
// omega_k is the secant estimate of the optimal relaxation along the last step: for
// H(x) = m x + c it equals 1 / (1 - m) from k = 1 on, and x_2 is the fixed point.
// Bounds (a choice; preCICE's AitkenAcceleration has none): |omega_k| is clamped to
// [minimum, maximum] keeping its sign, so that a wild secant cannot stop the iteration
// (omega ~ 0) or throw it far away. When r_k = r_{k-1} the secant is undefined and
// omega_{k-1} is kept.

#include <string>

#include "coupling/acceleration.hpp"

namespace robin {

struct AitkenParameters {
  double initial = 0.5;
  double minimum = 1e-4;
  double maximum = 1.0;
};

class AitkenAcceleration : public Acceleration {
 public:
  AitkenAcceleration(int size, AitkenParameters parameters);
  Eigen::VectorXd next(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped) override;
  /// "aitken omega = 0.31" (the omega of the last step).
  std::string state() const override;
  void restart() override;
  /// {"omega", "has_previous", "previous_residual"}.
  nlohmann::json save_state() const override;
  void restore_state(const nlohmann::json& state) override;
  /// The relaxation factor of the last step (initial before any step).
  double omega() const { return omega_; }

 private:
  int size_;
  AitkenParameters parameters_;
  double omega_;
  bool has_previous_ = false;
  Eigen::VectorXd previous_residual_;
};

}  // namespace robin
