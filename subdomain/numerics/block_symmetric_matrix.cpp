#include "numerics/block_symmetric_matrix.hpp"

#include <algorithm>
#include <stdexcept>

namespace robin {
namespace {

/// y += A x on the padded vectors for blocks of the compile-time size B (the file comment of the
/// header): the diagonal block of each row is its first.
template <int B, typename Value>
void multiply_blocks(const int* starts, const int* columns, const Value* values, int block_rows,
                     const double* x, double* y) {
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
      const double* x_column = x + static_cast<long>(B) * columns[k];
      double* y_column = y + static_cast<long>(B) * columns[k];
      for (int a = 0; a < B; ++a) {
        double total = 0.0;
        for (int c = 0; c < B; ++c) {
          total += block[a * B + c] * x_column[c];
          y_column[c] += block[a * B + c] * x_row[a];
        }
        sum[a] += total;
      }
    }
    for (int a = 0; a < B; ++a) y[B * row + a] += sum[a];
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

/// The blocks of the unknowns: per block its unknowns in increasing order.
struct UnknownsOfBlocks {
  std::vector<int> start;     // blocks + 1
  std::vector<int> unknowns;  // n values
};

UnknownsOfBlocks group_unknowns(const std::vector<int>& unknown_blocks, int size) {
  if (static_cast<int>(unknown_blocks.size()) != size) {
    throw std::invalid_argument("BlockSymmetricMatrix: the block numbers do not match the matrix");
  }
  UnknownsOfBlocks groups;
  int count = 0;
  for (int block : unknown_blocks) {
    if (block < 0 || block >= size) {
      throw std::invalid_argument("BlockSymmetricMatrix: a block number out of range");
    }
    count = std::max(count, block + 1);
  }
  groups.start.assign(static_cast<std::size_t>(count) + 1, 0);
  for (int block : unknown_blocks) ++groups.start[static_cast<std::size_t>(block) + 1];
  for (int block = 0; block < count; ++block) {
    if (groups.start[static_cast<std::size_t>(block) + 1] == 0) {
      throw std::invalid_argument("BlockSymmetricMatrix: a block number without unknowns");
    }
    groups.start[static_cast<std::size_t>(block) + 1] +=
        groups.start[static_cast<std::size_t>(block)];
  }
  groups.unknowns.resize(unknown_blocks.size());
  std::vector<int> next(groups.start.begin(), groups.start.end() - 1);
  for (int unknown = 0; unknown < size; ++unknown) {
    groups.unknowns[static_cast<std::size_t>(
        next[static_cast<std::size_t>(unknown_blocks[static_cast<std::size_t>(unknown)])]++)] =
        unknown;
  }
  return groups;
}

std::vector<int> one_block_each(int size) {
  std::vector<int> blocks(static_cast<std::size_t>(size));
  for (int unknown = 0; unknown < size; ++unknown)
    blocks[static_cast<std::size_t>(unknown)] = unknown;
  return blocks;
}

}  // namespace

template <typename Value>
BlockSymmetricMatrix<Value>::BlockSymmetricMatrix(const RowMajorSparseMatrix& matrix,
                                                  const std::vector<int>& unknown_blocks) {
  const int size = static_cast<int>(matrix.rows());
  if (matrix.cols() != size) throw std::invalid_argument("BlockSymmetricMatrix: not square");
  size_ = size;
  const std::vector<int>& blocks = unknown_blocks.empty() ? one_block_each(size) : unknown_blocks;
  const UnknownsOfBlocks groups = group_unknowns(blocks, size);
  const int block_rows = static_cast<int>(groups.start.size()) - 1;
  block_size_ = 1;
  for (int row = 0; row < block_rows; ++row) {
    block_size_ = std::max(block_size_, groups.start[row + 1] - groups.start[row]);
  }
  const int b = block_size_;
  slot_of_unknown_.assign(static_cast<std::size_t>(size), 0);
  unknown_of_slot_.assign(static_cast<std::size_t>(b) * block_rows, -1);
  for (int row = 0; row < block_rows; ++row) {
    for (int k = groups.start[row]; k < groups.start[row + 1]; ++k) {
      const int unknown = groups.unknowns[static_cast<std::size_t>(k)];
      const int slot = b * row + (k - groups.start[row]);
      slot_of_unknown_[static_cast<std::size_t>(unknown)] = slot;
      unknown_of_slot_[static_cast<std::size_t>(slot)] = unknown;
      identity_slots_ = identity_slots_ && slot == unknown;
    }
  }
  padding_ = static_cast<long>(unknown_of_slot_.size()) - size;
  identity_slots_ = identity_slots_ && padding_ == 0;

  // the block pattern of each block row (the diagonal first), then the values
  const RowMajorSparseMatrix& a = matrix;
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
      for (int k = groups.start[row]; k < groups.start[row + 1]; ++k) {
        const int unknown = groups.unknowns[static_cast<std::size_t>(k)];
        const int slot_row = slot_of_unknown_[static_cast<std::size_t>(unknown)] - b * row;
        for (RowMajorSparseMatrix::InnerIterator entry(a, unknown); entry; ++entry) {
          const int column_block = blocks[static_cast<std::size_t>(entry.col())];
          if (column_block > row) continue;
          int& place = position[static_cast<std::size_t>(column_block)];
          if (place < 0) {
            place = first + count++;
            touched.push_back(column_block);
            if (pass == 1) columns_[static_cast<std::size_t>(place)] = column_block;
          }
          if (pass == 1) {
            const int slot_column =
                slot_of_unknown_[static_cast<std::size_t>(entry.col())] - b * column_block;
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
  const bool padded = !identity_slots_;
  if (padded) {
    padded_x_.setZero(static_cast<Eigen::Index>(unknown_of_slot_.size()));
    for (Eigen::Index unknown = 0; unknown < x.size(); ++unknown) {
      padded_x_[slot_of_unknown_[static_cast<std::size_t>(unknown)]] = x[unknown];
    }
  }
  Eigen::VectorXd& output = padded ? padded_y_ : y;
  output.setZero(static_cast<Eigen::Index>(unknown_of_slot_.size()));
  const double* input = padded ? padded_x_.data() : x.data();
  const int rows = block_rows();
  switch (block_size_) {
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
      multiply_blocks(block_size_, starts_.data(), columns_.data(), values_.data(), rows, input,
                      output.data());
  }
  if (padded) {
    y.resize(x.size());
    for (Eigen::Index unknown = 0; unknown < x.size(); ++unknown) {
      y[unknown] = padded_y_[slot_of_unknown_[static_cast<std::size_t>(unknown)]];
    }
  }
}

template <typename Value>
SparseMatrix BlockSymmetricMatrix<Value>::lower_triangle() const {
  const int b = block_size_;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int row = 0; row < block_rows(); ++row) {
    for (int k = starts_[row]; k < starts_[row + 1]; ++k) {
      const int column = columns_[static_cast<std::size_t>(k)];
      for (int a = 0; a < b; ++a) {
        const int unknown_row = unknown_of_slot_[static_cast<std::size_t>(b * row + a)];
        for (int c = 0; c < b; ++c) {
          const int unknown_column = unknown_of_slot_[static_cast<std::size_t>(b * column + c)];
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
