#include "coupling/acceleration_blockwise.hpp"

#include <cassert>
#include <utility>

#include "coupling/checkpoint_encoding.hpp"

namespace robin {

BlockwiseAcceleration::BlockwiseAcceleration(std::vector<int> sizes,
                                             std::vector<std::unique_ptr<Acceleration>> parts)
    : sizes_(std::move(sizes)), parts_(std::move(parts)) {
  assert(sizes_.size() == parts_.size());
}

Eigen::VectorXd BlockwiseAcceleration::next(const Eigen::VectorXd& iterate,
                                            const Eigen::VectorXd& mapped) {
  assert(iterate.size() == mapped.size());
  Eigen::VectorXd result(iterate.size());
  Eigen::Index start = 0;
  for (std::size_t index = 0; index < parts_.size(); ++index) {
    const int size = sizes_[index];
    result.segment(start, size) =
        parts_[index]->next(iterate.segment(start, size), mapped.segment(start, size));
    start += size;
  }
  assert(start == iterate.size());
  return result;
}

std::string BlockwiseAcceleration::state() const {
  std::string line;
  for (std::size_t index = 0; index < parts_.size(); ++index) {
    if (index > 0) line += "; ";
    line += "body " + std::to_string(index + 1) + ": " + parts_[index]->state();
  }
  return line;
}

void BlockwiseAcceleration::restart() {
  for (auto& part : parts_) part->restart();
}

nlohmann::json BlockwiseAcceleration::save_state() const {
  nlohmann::json parts = nlohmann::json::array();
  for (const auto& part : parts_) parts.push_back(part->save_state());
  return {{"method", "blockwise"}, {"parts", parts}};
}

void BlockwiseAcceleration::restore_state(const nlohmann::json& state) {
  const nlohmann::json& parts = member(state, "parts");
  if (decode_text(state, "method") != "blockwise" || !parts.is_array() ||
      parts.size() != parts_.size()) {
    throw CheckpointFormatError("the checkpoint's acceleration does not have " +
                                std::to_string(parts_.size()) + " blocks");
  }
  for (std::size_t index = 0; index < parts_.size(); ++index) {
    parts_[index]->restore_state(parts[index]);
  }
}

}  // namespace robin
