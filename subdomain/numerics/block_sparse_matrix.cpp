#include "numerics/block_sparse_matrix.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace robin {
namespace {

/// y_i = sum_J P_iJ x_J on padded vectors, blocks R x C known at compile time.
template <int R, int C, typename Value>
void multiply_rows(const int* __restrict starts, const int* __restrict columns,
                   const Value* __restrict values, int block_rows, const double* __restrict x,
                   double* __restrict y) {
  for (int row = 0; row < block_rows; ++row) {
    double sum[R] = {};
    for (int k = starts[row]; k < starts[row + 1]; ++k) {
      const Value* block = values + static_cast<long>(R) * C * k;
      const double* x_column = x + static_cast<long>(C) * columns[k];
      for (int a = 0; a < R; ++a) {
        for (int c = 0; c < C; ++c) sum[a] += block[a * C + c] * x_column[c];
      }
    }
    for (int a = 0; a < R; ++a) y[static_cast<long>(R) * row + a] = sum[a];
  }
}

/// y_J += P_iJ' x_i on padded vectors (y zeroed before), blocks R x C known at compile time.
template <int R, int C, typename Value>
void multiply_transposed_rows(const int* __restrict starts, const int* __restrict columns,
                              const Value* __restrict values, int block_rows,
                              const double* __restrict x, double* __restrict y) {
  for (int row = 0; row < block_rows; ++row) {
    double x_row[R];
    for (int a = 0; a < R; ++a) x_row[a] = x[static_cast<long>(R) * row + a];
    for (int k = starts[row]; k < starts[row + 1]; ++k) {
      const Value* block = values + static_cast<long>(R) * C * k;
      double* y_column = y + static_cast<long>(C) * columns[k];
      double sum[C] = {};
      for (int a = 0; a < R; ++a) {
        for (int c = 0; c < C; ++c) sum[c] += block[a * C + c] * x_row[a];
      }
      for (int c = 0; c < C; ++c) y_column[c] += sum[c];
    }
  }
}

/// Both products for block sizes known only at run time.
template <typename Value>
void multiply_rows(int r, int c, const int* starts, const int* columns, const Value* values,
                   int block_rows, const double* x, double* y, bool transposed) {
  const long area = static_cast<long>(r) * c;
  for (int row = 0; row < block_rows; ++row) {
    double* y_row = y + static_cast<long>(r) * row;
    const double* x_row = x + static_cast<long>(r) * row;
    if (!transposed) std::fill(y_row, y_row + r, 0.0);
    for (int k = starts[row]; k < starts[row + 1]; ++k) {
      const Value* block = values + area * k;
      for (int a = 0; a < r; ++a) {
        for (int b = 0; b < c; ++b) {
          if (transposed) {
            y[static_cast<long>(c) * columns[k] + b] += block[a * c + b] * x_row[a];
          } else {
            y_row[a] += block[a * c + b] * x[static_cast<long>(c) * columns[k] + b];
          }
        }
      }
    }
  }
}

template <typename Value>
void dispatch(int r, int c, const int* starts, const int* columns, const Value* values,
              int block_rows, const double* x, double* y, bool transposed) {
  if (r == 3 && c == 6) {
    transposed ? multiply_transposed_rows<3, 6>(starts, columns, values, block_rows, x, y)
               : multiply_rows<3, 6>(starts, columns, values, block_rows, x, y);
  } else if (r == 6 && c == 6) {
    transposed ? multiply_transposed_rows<6, 6>(starts, columns, values, block_rows, x, y)
               : multiply_rows<6, 6>(starts, columns, values, block_rows, x, y);
  } else {
    multiply_rows(r, c, starts, columns, values, block_rows, x, y, transposed);
  }
}

}  // namespace

template <typename Value>
BlockSparseMatrix<Value>::BlockSparseMatrix(const RowMajorSparseMatrix& matrix,
                                            BlockLayout row_layout, BlockLayout column_layout)
    : rows_(std::move(row_layout)), columns_(std::move(column_layout)) {
  if (rows_.size() != matrix.rows() || columns_.size() != matrix.cols()) {
    throw std::invalid_argument("BlockSparseMatrix: the block layouts do not match the matrix");
  }
  const int r = rows_.block_size(), c = columns_.block_size();
  const long area = static_cast<long>(r) * c;
  std::vector<int> position(static_cast<std::size_t>(columns_.count()), -1);
  std::vector<int> touched;
  starts_.assign(static_cast<std::size_t>(rows_.count()) + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (int row = 0; row < rows_.count(); ++row) {
      touched.clear();
      for (int k = rows_.first(row); k < rows_.first(row + 1); ++k) {
        const int unknown = rows_.members()[static_cast<std::size_t>(k)];
        for (RowMajorSparseMatrix::InnerIterator entry(matrix, unknown); entry; ++entry) {
          const int column = static_cast<int>(entry.col());
          const int block = columns_.block_of(column);
          if (position[static_cast<std::size_t>(block)] < 0) {
            position[static_cast<std::size_t>(block)] = 0;
            touched.push_back(block);
          }
        }
      }
      std::sort(touched.begin(), touched.end());
      const int first = starts_[static_cast<std::size_t>(row)];
      for (std::size_t t = 0; t < touched.size(); ++t) {
        position[static_cast<std::size_t>(touched[t])] = first + static_cast<int>(t);
        if (pass == 1) block_columns_[static_cast<std::size_t>(first) + t] = touched[t];
      }
      if (pass == 1) {
        for (int k = rows_.first(row); k < rows_.first(row + 1); ++k) {
          const int unknown = rows_.members()[static_cast<std::size_t>(k)];
          const int slot_row = rows_.slot_of(unknown) - r * row;
          for (RowMajorSparseMatrix::InnerIterator entry(matrix, unknown); entry; ++entry) {
            const int column = static_cast<int>(entry.col());
            const int block = columns_.block_of(column);
            const int slot_column = columns_.slot_of(column) - c * block;
            values_[static_cast<std::size_t>(position[static_cast<std::size_t>(block)] * area +
                                             slot_row * c + slot_column)] =
                static_cast<Value>(entry.value());
          }
        }
      } else {
        starts_[static_cast<std::size_t>(row) + 1] = first + static_cast<int>(touched.size());
      }
      for (int block : touched) position[static_cast<std::size_t>(block)] = -1;
    }
    if (pass == 0) {
      block_columns_.assign(static_cast<std::size_t>(starts_.back()), 0);
      values_.assign(static_cast<std::size_t>(starts_.back() * area), Value(0));
    }
  }
}

template <typename Value>
void BlockSparseMatrix<Value>::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  if (x.size() != cols()) {
    throw std::invalid_argument("BlockSparseMatrix::multiply: the vector's size differs");
  }
  product(x, y, false);
}

template <typename Value>
void BlockSparseMatrix<Value>::multiply_transpose(const Eigen::VectorXd& x,
                                                  Eigen::VectorXd& y) const {
  if (x.size() != rows()) {
    throw std::invalid_argument("BlockSparseMatrix::multiply_transpose: the vector's size differs");
  }
  product(x, y, true);
}

template <typename Value>
void BlockSparseMatrix<Value>::product(const Eigen::VectorXd& x, Eigen::VectorXd& y,
                                       bool transposed) const {
  const BlockLayout& input = transposed ? rows_ : columns_;
  const BlockLayout& output = transposed ? columns_ : rows_;
  Eigen::VectorXd& input_slots = transposed ? padded_rows_ : padded_columns_;
  Eigen::VectorXd& output_slots = transposed ? padded_columns_ : padded_rows_;
  if (!input.identity()) input.to_slots(x, input_slots);
  Eigen::VectorXd& result = output.identity() ? y : output_slots;
  if (transposed) {
    result.setZero(output.slot_count());  // scattered into
  } else {
    result.resize(output.slot_count());  // each block row written once
  }
  dispatch(rows_.block_size(), columns_.block_size(), starts_.data(), block_columns_.data(),
           values_.data(), rows_.count(), input.identity() ? x.data() : input_slots.data(),
           result.data(), transposed);
  if (!output.identity()) output.from_slots(output_slots, y);
}

template class BlockSparseMatrix<float>;
template class BlockSparseMatrix<double>;

}  // namespace robin
