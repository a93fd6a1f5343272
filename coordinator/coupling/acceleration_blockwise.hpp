#pragma once
// Independent accelerations of contiguous blocks: block b of x_{k+1} is the next step of the
// b-th acceleration on block b of (x_k, H(x_k)). Used per body, since the obstacle sequences
// g^1 and g^2 are independent iterations.

#include <memory>
#include <string>
#include <vector>

#include "coupling/acceleration.hpp"

namespace robin {

class BlockwiseAcceleration : public Acceleration {
 public:
  /// `sizes[b]` entries go to `parts[b]`, in order; both vectors have the same length.
  BlockwiseAcceleration(std::vector<int> sizes, std::vector<std::unique_ptr<Acceleration>> parts);
  Eigen::VectorXd next(const Eigen::VectorXd& iterate, const Eigen::VectorXd& mapped) override;
  /// "body 1: <state of part 1>; body 2: <state of part 2>".
  std::string state() const override;
  void restart() override;
  /// {"method": "blockwise", "parts": [state of part 1, ...]}.
  nlohmann::json save_state() const override;
  void restore_state(const nlohmann::json& state) override;
  /// The acceleration of block `index` (0-based), for inspection.
  const Acceleration& part(int index) const { return *parts_.at(index); }

 private:
  std::vector<int> sizes_;
  std::vector<std::unique_ptr<Acceleration>> parts_;
};

}  // namespace robin
