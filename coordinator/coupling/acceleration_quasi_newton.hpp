#pragma once
// IQN-ILS (interface quasi-Newton with an inverse least-squares Jacobian model, Degroote et al.
// 2009), i.e. Anderson mixing, on one vector made of blocks (the bodies):
//   r_k = H(x_k) - x_k,  x~_k = H(x_k),
//   V = [r_k - r_{k-1}, r_{k-1} - r_{k-2}, ...],  W = [x~_k - x~_{k-1}, ...]
//   (newest first, at most history_depth columns, kept across iterations),
//   V = Q R (filtered, see acceleration_filtered_qr.hpp; dropped columns leave the history),
//   R alpha = -Q' r_k   (alpha minimises |r_k + V alpha|, the linearised residual),
//   x^_k = x_k + (W - V) alpha,  h^_k = x~_k + W alpha = x^_k + (r_k + V alpha),
//   x_{k+1} = (1 - beta_b) x^_k + beta_b h^_k   on each block b.
// x^_k is the combination of past iterates with the least linearised residual, h^_k its
// predicted image. The mixing beta_b:
//   full        beta = 1: x_{k+1} = x~_k + W alpha, the classical IQN-ILS (preCICE);
//   relaxation  beta = delta_b, the block's relaxation;
//   aitken      beta = -dx_b'dv_b / |dv_b|^2 from the newest column (dv = V_0, dx = W_0 - V_0,
//               restricted to block b): the Aitken / Irons-Tuck factor of that secant step,
//               |beta| clamped to [mixing_minimum, mixing_maximum] keeping its sign (delta_b
//               when dv_b = 0).
// Why mixing matters: on a linear map x -> M x + c, h^ - x^ is exactly the residual of x^, and
// the error of x_{k+1} is (I - beta (I - M)) times that of x^. With beta = 1 that is M, whose
// norm is the compliance ratio c for the stiff body's sequence: a truncated history then
// stalls (tests/unit/acceleration_test.cpp). A beta that makes I - beta (I - M) a contraction
// keeps truncated Anderson convergent (Toth & Kelley 2015); the aitken beta estimates one.
// With a full history the iterates are exact after d + 1 steps for any beta != 0, d the grade of
// r_0 with respect to I - M (Anderson ~ GMRES, Walker & Ni 2011).
// Relaxation steps x_{k+1} = (1 - delta_b) x_k + delta_b H(x_k): the first step, the step after
// restart(), and
//  - safeguard: after a quasi-Newton step with |r_k| > safeguard_growth |r_{k-1}|, the history
//    is cleared (the pair (r_k, x~_k) starts the next one);
//  - when the filter drops every column, the history is cleared.
// With aitken mixing, the relaxation steps of the last two kinds use the last beta_b instead of
// delta_b: it is the learnt scale of the block, where delta_b may blow the residual up (delta =
// 0.5 multiplies the stiff sequence's residual by about c / 2).
// Only differences of (x_k, H(x_k)) pairs are used, so the caller may change the iterate.

#include <deque>
#include <string>
#include <vector>

#include "coupling/acceleration.hpp"
#include "coupling/acceleration_relaxation.hpp"

namespace robin {

struct QuasiNewtonParameters {
  int history_depth = 10;
  double filter_threshold = 1e-10;
  double safeguard_growth = 2.0;
  QuasiNewtonMixing mixing = QuasiNewtonMixing::aitken;
  double mixing_minimum = 1e-4, mixing_maximum = 1.0;  // bounds of |beta| for aitken mixing
};

class IqnIlsAcceleration : public Acceleration {
 public:
  /// The blocks (sizes and relaxations delta_b) cover the iterate in order.
  IqnIlsAcceleration(std::vector<RelaxationBlock> blocks, QuasiNewtonParameters parameters);
  Eigen::VectorXd next(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped) override;
  /// "iqn-ils 4 columns (1 filtered), beta = (0.01, 0.97)", or
  /// "iqn-ils relaxation step (<reason>)".
  std::string state() const override;
  void restart() override;
  /// The secant columns (V, W), the previous pair (r, x~), the counters, the mixing and the
  /// reason of the last relaxation step.
  nlohmann::json save_state() const override;
  void restore_state(const nlohmann::json& state) override;

  /// Columns used by the last step (0 for a relaxation step).
  int columns() const { return columns_; }
  /// Columns dropped by the filter in the last step.
  int filtered() const { return filtered_; }
  /// Whether the last step was a relaxation step.
  bool relaxation_step() const { return columns_ == 0; }
  /// Safeguard restarts since construction.
  int safeguard_restarts() const { return safeguard_restarts_; }
  /// The mixing beta of each block in the last quasi-Newton step.
  const std::vector<double>& mixing() const { return mixing_; }

 private:
  void record_differences(const Eigen::VectorXd& residual, const Eigen::VectorXd& mapped);
  void clear_history();
  /// The least-squares coefficients alpha, after filtering the history; empty when the filter
  /// dropped every column.
  Eigen::VectorXd least_squares_coefficients(const Eigen::VectorXd& residual);
  Eigen::VectorXd quasi_newton_step(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped,
                                    const Eigen::VectorXd& alpha);
  double block_mixing(const RelaxationBlock& block, Eigen::Index start) const;
  /// (1 - beta_b) point + beta_b image on each block b.
  Eigen::VectorXd mixed(const Eigen::VectorXd& point, const Eigen::VectorXd& image,
                        const std::vector<double>& mixing) const;

  int size_ = 0;
  std::vector<RelaxationBlock> blocks_;
  QuasiNewtonParameters parameters_;
  FixedRelaxation relaxation_;
  std::deque<Eigen::VectorXd> residual_differences_;  // columns of V, newest first
  std::deque<Eigen::VectorXd> mapped_differences_;    // columns of W, newest first
  bool has_previous_ = false;
  bool previous_was_quasi_newton_ = false;
  Eigen::VectorXd previous_residual_, previous_mapped_;
  int columns_ = 0, filtered_ = 0, safeguard_restarts_ = 0;
  std::vector<double> mixing_;
  std::string reason_ = "first step";  // why the last step was a relaxation step
};

}  // namespace robin
