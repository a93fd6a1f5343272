#pragma once
// How the unknowns of a vector are grouped into blocks (the free dofs of one mesh node, the
// coarse unknowns of one aggregate), for the block storage of matrices
// (block_symmetric_matrix.hpp, block_sparse_matrix.hpp) and the algebraic multigrid.
//
// n unknowns in `count` blocks, b the size of the largest block: unknown k (counted in increasing
// order) of block R has the slot b R + k, so that a vector in slots holds every block in b
// consecutive entries; the slots past the unknowns of a smaller block (a node with a prescribed
// component, a rank-deficient aggregate) are padding, zero in every product.

#include <Eigen/Core>
#include <vector>

namespace robin {

class BlockLayout {
 public:
  BlockLayout() = default;
  /// From the block of each unknown, numbered 0 .. count - 1 with every number used. Throws
  /// std::invalid_argument for a negative, unused or too large number (a number is too large
  /// when it is not smaller than the number of unknowns).
  explicit BlockLayout(const std::vector<int>& unknown_blocks);
  /// Every unknown a block of its own (b = 1, the slots are the unknowns).
  static BlockLayout one_per_unknown(int size);

  int size() const { return static_cast<int>(block_of_.size()); }
  int count() const { return static_cast<int>(start_.size()) - 1; }
  int block_size() const { return block_size_; }
  int slot_count() const { return block_size_ * count(); }
  /// The slots are the unknowns' own numbers (every block full and consecutive, in order).
  bool identity() const { return identity_; }

  int block_of(int unknown) const { return block_of_[static_cast<std::size_t>(unknown)]; }
  int slot_of(int unknown) const { return slot_of_[static_cast<std::size_t>(unknown)]; }
  /// The unknown in `slot`, -1 for padding.
  int unknown_of_slot(int slot) const { return unknown_of_slot_[static_cast<std::size_t>(slot)]; }
  /// The unknowns of block R, in increasing order, are members()[first(R) .. first(R + 1)).
  int first(int block) const { return start_[static_cast<std::size_t>(block)]; }
  const std::vector<int>& members() const { return members_; }
  const std::vector<int>& blocks() const { return block_of_; }

  /// padded = x in slots (padding zero; the writes are one per unknown and one per padding
  /// slot); x has size() entries.
  void to_slots(const Eigen::VectorXd& x, Eigen::VectorXd& padded) const;
  /// x = the unknowns' entries of `padded`.
  void from_slots(const Eigen::VectorXd& padded, Eigen::VectorXd& x) const;

 private:
  std::vector<int> block_of_;         // n values
  std::vector<int> start_;            // count + 1
  std::vector<int> members_;          // n values, block by block
  std::vector<int> slot_of_;          // n values
  std::vector<int> unknown_of_slot_;  // b count values
  std::vector<int> padding_slots_;
  int block_size_ = 1;
  bool identity_ = true;
};

/// Any non-negative numbers renumbered 0 .. count - 1 in increasing order of the number (a
/// node's dofs by node numbers that skip the nodes without free dofs). Throws
/// std::invalid_argument for a negative number.
std::vector<int> consecutive_numbers(const std::vector<int>& numbers);

}  // namespace robin
