// The block storage of a symmetric sparse matrix against Eigen's own products: y = A x with the
// scalar matrix (Eigen's sparse product, both triangles), the rebuilt lower triangle equal to
// the original, for full blocks, padded blocks (blocks of fewer unknowns, as a node with a
// prescribed component), unknowns of a block that are not consecutive, one block per unknown,
// and the refusals of inconsistent block numbers.

#include "numerics/block_symmetric_matrix.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

namespace robin {
namespace {

/// A random symmetric matrix of `size` unknowns in which unknown i couples to i and to `width`
/// random others (both triangles stored), row-major.
RowMajorSparseMatrix random_symmetric(int size, int width, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::uniform_int_distribution<int> unknown(0, size - 1);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int row = 0; row < size; ++row) {
    triplets.emplace_back(row, row, 4.0 + value(generator));
    for (int k = 0; k < width; ++k) {
      const int column = unknown(generator);
      if (column == row) continue;
      const double entry = value(generator);
      triplets.emplace_back(row, column, entry);
      triplets.emplace_back(column, row, entry);
    }
  }
  RowMajorSparseMatrix matrix(size, size);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

Eigen::VectorXd random_vector(int size, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  return Eigen::VectorXd::NullaryExpr(size, [&] { return value(generator); });
}

/// The product and the rebuilt lower triangle of the block storage against Eigen's.
template <typename Value>
void expect_same_matrix(const RowMajorSparseMatrix& matrix, const std::vector<int>& blocks,
                        double tolerance) {
  const BlockSymmetricMatrix<Value> stored(matrix, blocks);
  ASSERT_EQ(stored.size(), matrix.rows());
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Eigen::VectorXd x = random_vector(static_cast<int>(matrix.rows()), seed);
    const Eigen::VectorXd expected = matrix * x;
    Eigen::VectorXd product;
    stored.multiply(x, product);
    ASSERT_EQ(product.size(), expected.size());
    EXPECT_LE((product - expected).lpNorm<Eigen::Infinity>(),
              tolerance * expected.lpNorm<Eigen::Infinity>());
  }
  const SparseMatrix lower = stored.lower_triangle();
  const SparseMatrix expected_lower = SparseMatrix(matrix).triangularView<Eigen::Lower>();
  EXPECT_LE(Eigen::MatrixXd(lower - expected_lower).lpNorm<Eigen::Infinity>(),
            tolerance * Eigen::MatrixXd(expected_lower).lpNorm<Eigen::Infinity>());
}

TEST(BlockSymmetricMatrix, FullBlocksOfThreeGiveEigensProduct) {
  const RowMajorSparseMatrix matrix = random_symmetric(300, 6, 11);
  std::vector<int> blocks(300);
  for (int unknown = 0; unknown < 300; ++unknown) blocks[unknown] = unknown / 3;
  expect_same_matrix<double>(matrix, blocks, 1e-14);
  const BlockSymmetricMatrix<double> stored(matrix, blocks);
  EXPECT_EQ(stored.block_size(), 3);
  EXPECT_EQ(stored.block_rows(), 100);
}

TEST(BlockSymmetricMatrix, PaddedAndScatteredBlocksGiveEigensProduct) {
  // blocks of 1 to 6 unknowns, the unknowns of a block spread over the numbering
  const int size = 420;
  const RowMajorSparseMatrix matrix = random_symmetric(size, 8, 12);
  std::vector<int> order(size);
  for (int unknown = 0; unknown < size; ++unknown) order[unknown] = unknown;
  std::shuffle(order.begin(), order.end(), std::mt19937(5));
  std::vector<int> blocks(size);
  int block = 0, filled = 0;
  for (int k = 0; k < size; ++k) {
    blocks[order[k]] = block;
    if (++filled == 1 + block % 6) {
      ++block;
      filled = 0;
    }
  }
  if (filled == 0) --block;
  expect_same_matrix<double>(matrix, blocks, 1e-14);
  const BlockSymmetricMatrix<double> stored(matrix, blocks);
  EXPECT_EQ(stored.block_size(), 6);
  EXPECT_EQ(stored.block_rows(), block + 1);
  // single precision storage: the entries rounded to float, the sums in double
  expect_same_matrix<float>(matrix, blocks, 1e-6);
}

TEST(BlockSymmetricMatrix, OneBlockPerUnknownWithoutBlockNumbers) {
  const RowMajorSparseMatrix matrix = random_symmetric(150, 5, 13);
  expect_same_matrix<double>(matrix, {}, 1e-14);
  EXPECT_EQ(BlockSymmetricMatrix<double>(matrix, std::vector<int>{}).block_size(), 1);
}

TEST(BlockSymmetricMatrix, BlocksOfSevenUseTheGeneralKernel) {
  const RowMajorSparseMatrix matrix = random_symmetric(140, 7, 14);
  std::vector<int> blocks(140);
  for (int unknown = 0; unknown < 140; ++unknown) blocks[unknown] = (unknown * 37 % 140) / 7;
  expect_same_matrix<double>(matrix, blocks, 1e-14);
  EXPECT_EQ(BlockSymmetricMatrix<double>(matrix, blocks).block_size(), 7);
}

TEST(BlockSymmetricMatrix, InconsistentBlockNumbersAreRefused) {
  const RowMajorSparseMatrix matrix = random_symmetric(10, 2, 15);
  EXPECT_THROW(BlockSymmetricMatrix<double>(matrix, std::vector<int>(9, 0)), std::invalid_argument);
  std::vector<int> negative(10, 0);
  negative[3] = -1;
  EXPECT_THROW(BlockSymmetricMatrix<double>(matrix, negative), std::invalid_argument);
  std::vector<int> unused(10, 0);
  unused[4] = 2;  // block 1 has no unknown
  EXPECT_THROW(BlockSymmetricMatrix<double>(matrix, unused), std::invalid_argument);
  const BlockSymmetricMatrix<double> stored(matrix, std::vector<int>{});
  Eigen::VectorXd product;
  EXPECT_THROW(stored.multiply(Eigen::VectorXd::Zero(9), product), std::invalid_argument);
}

}  // namespace
}  // namespace robin
