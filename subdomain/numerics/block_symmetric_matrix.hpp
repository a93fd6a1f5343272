#pragma once
// A symmetric sparse matrix stored by blocks of unknowns, for the products of the algebraic
// multigrid (algebraic_multigrid.hpp) and of conjugate gradients.
//
// The unknowns are grouped into blocks (the free dofs of one mesh node, the coarse unknowns of
// one aggregate) with their slots as block_layout.hpp says; b is the size of the largest block.
// The matrix is held as the b x b blocks A_RC, C <= R, of its block lower triangle in
// compressed block rows (the diagonal block first in each row, stored whole), each block's
// entries row by row, padded with zeros where a block has fewer than b unknowns (a node with a
// prescribed component, a rank-deficient aggregate). Then, block row by block row,
//   y_R = A_RR x_R + sum_{C < R} A_RC x_C,   and for C < R:  y_C += A_RC' x_R,
// reads each stored block once for both triangles, on padded copies of x and y (none when every
// block is full and the slots are the unknowns' own numbers); y_R is first written by its own
// block row (the rows before it touch only blocks C < R), so y needs no zeroing. Against compressed
// rows of the scalar lower triangle it stores one column index per block instead of one per entry
// and its b x b kernel runs in registers: the product is bound by memory traffic, which both
// reduce.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "numerics/block_layout.hpp"
#include "numerics/elasticity.hpp"

namespace robin {

using RowMajorSparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// Value: float or double (the storage; products are summed in double).
template <typename Value>
class BlockSymmetricMatrix {
 public:
  BlockSymmetricMatrix() = default;
  /// A from the symmetric `matrix` (both triangles stored) and `unknown_blocks` (the block of
  /// each unknown, numbered 0 .. count - 1, each number used; empty: every unknown a block of its
  /// own). Throws std::invalid_argument when the sizes differ or a block number is negative,
  /// unused or too large.
  BlockSymmetricMatrix(const RowMajorSparseMatrix& matrix, const std::vector<int>& unknown_blocks);
  /// A from `matrix` and the blocks of `layout`; throws std::invalid_argument when the sizes
  /// differ.
  BlockSymmetricMatrix(const RowMajorSparseMatrix& matrix, BlockLayout layout);
  /// The same blocks with their entries rounded to Value.
  template <typename Other>
  explicit BlockSymmetricMatrix(const BlockSymmetricMatrix<Other>& other)
      : layout_(other.layout_),
        starts_(other.starts_),
        columns_(other.columns_),
        values_(other.values_.begin(), other.values_.end()) {}

  int size() const { return layout_.size(); }
  int block_size() const { return layout_.block_size(); }
  int block_rows() const { return static_cast<int>(starts_.size()) - 1; }
  /// Stored blocks (the block lower triangle, diagonal blocks included).
  long stored_blocks() const { return static_cast<long>(columns_.size()); }

  /// y = A x (y resized). Not for concurrent use: the padded copies are members.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// The scalar lower triangle of A (diagonal included, column-major, the explicit zeros of the
  /// padding left out).
  SparseMatrix lower_triangle() const;

 private:
  template <typename Other>
  friend class BlockSymmetricMatrix;

  BlockLayout layout_;
  std::vector<int> starts_;    // block rows + 1
  std::vector<int> columns_;   // block column of each stored block
  std::vector<Value> values_;  // b x b per stored block, row by row
  mutable Eigen::VectorXd padded_x_, padded_y_;
};

extern template class BlockSymmetricMatrix<float>;
extern template class BlockSymmetricMatrix<double>;

}  // namespace robin
