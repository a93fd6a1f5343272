#include "coupling/acceleration_relaxation.hpp"

#include <cassert>
#include <sstream>
#include <utility>

#include "coupling/checkpoint_encoding.hpp"

namespace robin {

FixedRelaxation::FixedRelaxation(std::vector<RelaxationBlock> blocks)
    : blocks_(std::move(blocks)) {}

Eigen::VectorXd FixedRelaxation::next(const Eigen::VectorXd& iterate,
                                      const Eigen::VectorXd& mapped) {
  assert(iterate.size() == mapped.size());
  Eigen::VectorXd result(iterate.size());
  Eigen::Index start = 0;
  for (const RelaxationBlock& block : blocks_) {
    const double delta = block.relaxation;
    const auto obstacle = iterate.segment(start, block.size);
    const auto update = mapped.segment(start, block.size);
    // g <- (1 - delta) g + delta H(g), paper (13).
    result.segment(start, block.size) = (1.0 - delta) * obstacle + delta * update;
    start += block.size;
  }
  assert(start == iterate.size());
  return result;
}

std::string FixedRelaxation::state() const {
  std::string line = "relaxation delta = (";
  for (std::size_t index = 0; index < blocks_.size(); ++index) {
    if (index > 0) line += ", ";
    line += format_for_state(blocks_[index].relaxation);
  }
  return line + ")";
}

void FixedRelaxation::restore_state(const nlohmann::json& state) {
  if (decode_text(state, "method") != "none") {
    throw CheckpointFormatError("the checkpoint's acceleration is not 'none'");
  }
}

std::string format_for_state(double value) {
  std::ostringstream stream;
  stream.precision(3);
  stream << value;
  return stream.str();
}

}  // namespace robin
