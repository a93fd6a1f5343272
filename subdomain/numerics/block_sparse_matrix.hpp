#pragma once
// A rectangular sparse matrix stored by blocks, for the prolongator P of the algebraic multigrid
// (algebraic_multigrid.hpp): its products y = P x and y = P' x, and the Galerkin product P' A P
// (galerkin_product.hpp).
//
// The rows are grouped by one block layout (block_layout.hpp: the fine level's nodes), the
// columns by another (the aggregates' coarse unknowns); with br and bc the two block sizes, P is
// held as the br x bc blocks P_iJ of its block pattern in compressed block rows, each block's
// entries row by row, padded with zeros where a block has fewer unknowns. A prolongator's rows
// of one node share their aggregates, so against compressed scalar rows the storage needs one
// column index per block instead of one per entry, and the products run br x bc kernels.

#include <Eigen/Core>
#include <vector>

#include "numerics/block_layout.hpp"
#include "numerics/block_symmetric_matrix.hpp"

namespace robin {

/// Value: float or double (the storage; products are summed in double).
template <typename Value>
class BlockSparseMatrix {
 public:
  BlockSparseMatrix() = default;
  /// P from `matrix` (rows x columns, compressed rows), its rows grouped by `row_layout` and its
  /// columns by `column_layout`. Throws std::invalid_argument when a layout's size differs from
  /// the matrix's.
  BlockSparseMatrix(const RowMajorSparseMatrix& matrix, BlockLayout row_layout,
                    BlockLayout column_layout);
  /// The same blocks with their entries rounded to Value.
  template <typename Other>
  explicit BlockSparseMatrix(const BlockSparseMatrix<Other>& other)
      : rows_(other.row_layout()),
        columns_(other.column_layout()),
        starts_(other.block_starts()),
        block_columns_(other.block_columns()),
        values_(other.values().begin(), other.values().end()) {}

  int rows() const { return rows_.size(); }
  int cols() const { return columns_.size(); }
  long stored_blocks() const { return static_cast<long>(block_columns_.size()); }

  /// y = P x (y resized). Not for concurrent use: the padded copies are members.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// y = P' x (y resized). Not for concurrent use.
  void multiply_transpose(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;

  const BlockLayout& row_layout() const { return rows_; }
  const BlockLayout& column_layout() const { return columns_; }
  /// The stored blocks of block row i are k = block_starts()[i] .. block_starts()[i + 1] - 1,
  /// in increasing block column block_columns()[k], entries values()[k br bc ..] row by row.
  const std::vector<int>& block_starts() const { return starts_; }
  const std::vector<int>& block_columns() const { return block_columns_; }
  const std::vector<Value>& values() const { return values_; }

 private:
  /// y = P x, or y = P' x when `transposed`, on padded copies where a layout is not the identity.
  void product(const Eigen::VectorXd& x, Eigen::VectorXd& y, bool transposed) const;

  BlockLayout rows_, columns_;
  std::vector<int> starts_;         // block rows + 1
  std::vector<int> block_columns_;  // per stored block
  std::vector<Value> values_;       // br bc per stored block
  // vectors in the row and in the column slots, each of one size: no allocation per product
  mutable Eigen::VectorXd padded_rows_, padded_columns_;
};

extern template class BlockSparseMatrix<float>;
extern template class BlockSparseMatrix<double>;

}  // namespace robin
