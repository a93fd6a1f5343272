#include "numerics/block_layout.hpp"

#include <algorithm>
#include <stdexcept>

namespace robin {

BlockLayout::BlockLayout(const std::vector<int>& unknown_blocks) : block_of_(unknown_blocks) {
  const int size = static_cast<int>(unknown_blocks.size());
  int count = 0;
  for (int block : unknown_blocks) {
    if (block < 0 || block >= size) {
      throw std::invalid_argument("BlockLayout: a block number out of range");
    }
    count = std::max(count, block + 1);
  }
  start_.assign(static_cast<std::size_t>(count) + 1, 0);
  for (int block : unknown_blocks) ++start_[static_cast<std::size_t>(block) + 1];
  block_size_ = size == 0 ? 1 : 0;
  for (int block = 0; block < count; ++block) {
    const int members = start_[static_cast<std::size_t>(block) + 1];
    if (members == 0) throw std::invalid_argument("BlockLayout: a block number without unknowns");
    block_size_ = std::max(block_size_, members);
    start_[static_cast<std::size_t>(block) + 1] += start_[static_cast<std::size_t>(block)];
  }
  members_.resize(unknown_blocks.size());
  slot_of_.resize(unknown_blocks.size());
  unknown_of_slot_.assign(static_cast<std::size_t>(block_size_) * count, -1);
  std::vector<int> next(start_.begin(), start_.end() - 1);
  for (int unknown = 0; unknown < size; ++unknown) {
    const int block = block_of_[static_cast<std::size_t>(unknown)];
    const int position = next[static_cast<std::size_t>(block)]++;
    members_[static_cast<std::size_t>(position)] = unknown;
    const int slot = block_size_ * block + (position - start_[static_cast<std::size_t>(block)]);
    slot_of_[static_cast<std::size_t>(unknown)] = slot;
    unknown_of_slot_[static_cast<std::size_t>(slot)] = unknown;
    identity_ = identity_ && slot == unknown;
  }
  identity_ = identity_ && slot_count() == size;
  for (int slot = 0; slot < slot_count(); ++slot) {
    if (unknown_of_slot_[static_cast<std::size_t>(slot)] < 0) padding_slots_.push_back(slot);
  }
}

BlockLayout BlockLayout::one_per_unknown(int size) {
  std::vector<int> blocks(static_cast<std::size_t>(std::max(size, 0)));
  for (int unknown = 0; unknown < size; ++unknown)
    blocks[static_cast<std::size_t>(unknown)] = unknown;
  return BlockLayout(blocks);
}

void BlockLayout::to_slots(const Eigen::VectorXd& x, Eigen::VectorXd& padded) const {
  padded.resize(slot_count());
  for (int slot : padding_slots_) padded[slot] = 0.0;
  for (int unknown = 0; unknown < size(); ++unknown) padded[slot_of(unknown)] = x[unknown];
}

void BlockLayout::from_slots(const Eigen::VectorXd& padded, Eigen::VectorXd& x) const {
  x.resize(size());
  for (int unknown = 0; unknown < size(); ++unknown) x[unknown] = padded[slot_of(unknown)];
}

std::vector<int> consecutive_numbers(const std::vector<int>& numbers) {
  int largest = -1;
  for (int number : numbers) {
    if (number < 0) throw std::invalid_argument("consecutive_numbers: a negative number");
    largest = std::max(largest, number);
  }
  std::vector<int> renumbered(static_cast<std::size_t>(largest + 1), -1);
  for (int number : numbers) renumbered[static_cast<std::size_t>(number)] = 0;
  int count = 0;
  for (int& number : renumbered) {
    if (number == 0) number = count++;
  }
  std::vector<int> result;
  result.reserve(numbers.size());
  for (int number : numbers) result.push_back(renumbered[static_cast<std::size_t>(number)]);
  return result;
}

}  // namespace robin
