#pragma once
// Fixed relaxation per block: x_{k+1} = (1 - delta_b) x_k + delta_b H(x_k) on each block b.
// With the blocks (g^1, g^2) this is the paper's update (13), evaluated with the same
// expression so that it is bit for bit the plain iteration.

#include <string>
#include <vector>

#include "coupling/acceleration.hpp"

namespace robin {

/// A contiguous block of the iterate and its relaxation delta.
struct RelaxationBlock {
  int size = 0;
  double relaxation = 0.5;
};

class FixedRelaxation : public Acceleration {
 public:
  /// The blocks in order; their sizes add up to the size of the iterate.
  explicit FixedRelaxation(std::vector<RelaxationBlock> blocks);
  Eigen::VectorXd next(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped) override;
  /// "relaxation delta = (0.5, 0.5)".
  std::string state() const override;
  void restart() override {}
  /// Stateless: {"method": "none"}.
  nlohmann::json save_state() const override { return {{"method", "none"}}; }
  void restore_state(const nlohmann::json& state) override;

 private:
  std::vector<RelaxationBlock> blocks_;
};

/// Short decimal form of a number for state() lines (up to 3 significant digits).
std::string format_for_state(double value);

}  // namespace robin
