#include "numerics/block_symmetric_matrix.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace robin {
namespace {

/// y += A x on the padded vectors for blocks of the compile-time size B (the file comment of the
/// header): the diagonal block of each row is its first.
template <int B, typename Value>
void multiply_blocks(const int* __restrict starts, const int* __restrict columns,
                     const Value* __restrict values, int block_rows, const double* __restrict x,
                     double* __restrict y) {
  for (int row = 0; row < block_rows; ++row) {
    double x_row[B];
    double sum[B];
    const Value* diagonal = values + static_cast<long>(B) * B * starts[row];
    for (int a = 0; a < B; ++a) x_row[a] = x[B * row + a];
    for (int a = 0; a < B; ++a) {
      double total = 0.0;
      for (int c = 0; c < B; ++c) total += diagonal[a * B + c] * x_row[c];
      sum[a] = total;
    }
    for (int k = starts[row] + 1; k < starts[row + 1]; ++k) {
      const Value* block = values + static_cast<long>(B) * B * k;
      const long column = static_cast<long>(B) * columns[k];
      double x_column[B];
      double y_column[B];
      for (int c = 0; c < B; ++c) {
        x_column[c] = x[column + c];
        y_column[c] = 0.0;
      }
      for (int a = 0; a < B; ++a) {
        for (int c = 0; c < B; ++c) {
          const double value = block[a * B + c];
          sum[a] += value * x_column[c];
          y_column[c] += value * x_row[a];
        }
      }
      for (int c = 0; c < B; ++c) y[column + c] += y_column[c];
    }
    for (int a = 0; a < B; ++a) y[B * row + a] = sum[a];  // the first write of y_R
  }
}

/// The same for a block size known only at run time.
template <typename Value>
void multiply_blocks(int size, const int* starts, const int* columns, const Value* values,
                     int block_rows, const double* x, double* y) {
  const long area = static_cast<long>(size) * size;
  for (int row = 0; row < block_rows; ++row) {
    const double* x_row = x + static_cast<long>(size) * row;
    double* y_row = y + static_cast<long>(size) * row;
    std::fill(y_row, y_row + size, 0.0);  // the first write of y_R
    for (int k = starts[row]; k < starts[row + 1]; ++k) {
      const Value* block = values + area * k;
      const double* x_column = x + static_cast<long>(size) * columns[k];
      double* y_column = y + static_cast<long>(size) * columns[k];
      for (int a = 0; a < size; ++a) {
        for (int c = 0; c < size; ++c) {
          y_row[a] += block[a * size + c] * x_column[c];
          if (columns[k] != row) y_column[c] += block[a * size + c] * x_row[a];
        }
      }
    }
  }
}

}  // namespace

template <typename Value>
BlockSymmetricMatrix<Value>::BlockSymmetricMatrix(const RowMajorSparseMatrix& matrix,
                                                  const std::vector<int>& unknown_blocks)
    : BlockSymmetricMatrix(matrix, unknown_blocks.empty() ? BlockLayout::one_per_unknown(
                                                                static_cast<int>(matrix.rows()))
                                                          : BlockLayout(unknown_blocks)) {}

template <typename Value>
BlockSymmetricMatrix<Value>::BlockSymmetricMatrix(const RowMajorSparseMatrix& matrix,
                                                  BlockLayout layout)
    : layout_(std::move(layout)) {
  if (matrix.rows() != matrix.cols()) {
    throw std::invalid_argument("BlockSymmetricMatrix: not square");
  }
  if (layout_.size() != matrix.rows()) {
    throw std::invalid_argument("BlockSymmetricMatrix: the block numbers do not match the matrix");
  }
  const int block_rows = layout_.count();
  const int b = layout_.block_size();
  // the block pattern of each block row (the diagonal first), then the values
  std::vector<int> position(static_cast<std::size_t>(block_rows), -1);
  std::vector<int> touched;
  starts_.assign(static_cast<std::size_t>(block_rows) + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (int row = 0; row < block_rows; ++row) {
      const int first = pass == 0 ? 0 : starts_[static_cast<std::size_t>(row)];
      int count = 1;
      position[static_cast<std::size_t>(row)] = first;
      if (pass == 1) columns_[static_cast<std::size_t>(first)] = row;
      touched.assign(1, row);
      for (int k = layout_.first(row); k < layout_.first(row + 1); ++k) {
        const int unknown = layout_.members()[static_cast<std::size_t>(k)];
        const int slot_row = layout_.slot_of(unknown) - b * row;
        for (RowMajorSparseMatrix::InnerIterator entry(matrix, unknown); entry; ++entry) {
          const int column_block = layout_.block_of(static_cast<int>(entry.col()));
          if (column_block > row) continue;
          int& place = position[static_cast<std::size_t>(column_block)];
          if (place < 0) {
            place = first + count++;
            touched.push_back(column_block);
            if (pass == 1) columns_[static_cast<std::size_t>(place)] = column_block;
          }
          if (pass == 1) {
            const int slot_column =
                layout_.slot_of(static_cast<int>(entry.col())) - b * column_block;
            values_[static_cast<std::size_t>(place) * b * b +
                    static_cast<std::size_t>(slot_row * b + slot_column)] =
                static_cast<Value>(entry.value());
          }
        }
      }
      for (int block : touched) position[static_cast<std::size_t>(block)] = -1;
      if (pass == 0) starts_[static_cast<std::size_t>(row) + 1] = starts_[row] + count;
    }
    if (pass == 0) {
      columns_.assign(static_cast<std::size_t>(starts_.back()), 0);
      values_.assign(static_cast<std::size_t>(starts_.back()) * b * b, Value(0));
    }
  }
}

template <typename Value>
void BlockSymmetricMatrix<Value>::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  if (x.size() != size()) {
    throw std::invalid_argument("BlockSymmetricMatrix::multiply: the vector's size differs");
  }
  const bool padded = !layout_.identity();
  if (padded) layout_.to_slots(x, padded_x_);
  Eigen::VectorXd& output = padded ? padded_y_ : y;
  output.resize(layout_.slot_count());  // each y_R written first by its own block row
  const double* input = padded ? padded_x_.data() : x.data();
  const int rows = block_rows();
  switch (layout_.block_size()) {
    case 1:
      multiply_blocks<1>(starts_.data(), columns_.data(), values_.data(), rows, input,
                         output.data());
      break;
    case 2:
      multiply_blocks<2>(starts_.data(), columns_.data(), values_.data(), rows, input,
                         output.data());
      break;
    case 3:
      multiply_blocks<3>(starts_.data(), columns_.data(), values_.data(), rows, input,
                         output.data());
      break;
    case 6:
      multiply_blocks<6>(starts_.data(), columns_.data(), values_.data(), rows, input,
                         output.data());
      break;
    default:
      multiply_blocks(layout_.block_size(), starts_.data(), columns_.data(), values_.data(), rows,
                      input, output.data());
  }
  if (padded) layout_.from_slots(padded_y_, y);
}

template <typename Value>
SparseMatrix BlockSymmetricMatrix<Value>::lower_triangle() const {
  const int b = layout_.block_size();
  std::vector<Eigen::Triplet<double>> triplets;
  for (int row = 0; row < block_rows(); ++row) {
    for (int k = starts_[row]; k < starts_[row + 1]; ++k) {
      const int column = columns_[static_cast<std::size_t>(k)];
      for (int a = 0; a < b; ++a) {
        const int unknown_row = layout_.unknown_of_slot(b * row + a);
        for (int c = 0; c < b; ++c) {
          const int unknown_column = layout_.unknown_of_slot(b * column + c);
          const double value =
              values_[static_cast<std::size_t>(k) * b * b + static_cast<std::size_t>(a * b + c)];
          if (unknown_row < 0 || unknown_column < 0 || value == 0.0) continue;
          if (column == row && unknown_column > unknown_row) continue;  // the upper half
          triplets.emplace_back(std::max(unknown_row, unknown_column),
                                std::min(unknown_row, unknown_column), value);
        }
      }
    }
  }
  SparseMatrix lower(size(), size());
  lower.setFromTriplets(triplets.begin(), triplets.end());
  return lower;
}

template class BlockSymmetricMatrix<float>;
template class BlockSymmetricMatrix<double>;

}  // namespace robin
