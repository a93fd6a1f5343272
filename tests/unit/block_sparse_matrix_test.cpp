// The block layouts and the block storage of rectangular sparse matrices against Eigen's own
// products: y = P x and y = P' x with the scalar matrix, and the Galerkin product P' A P against
// Eigen's sparse products, for full blocks (3 x 6: a node's dofs against an aggregate's rigid
// motions), padded blocks (nodes with a prescribed component, rank-deficient aggregates),
// unknowns of a block spread over the numbering, block sizes without a fixed-size kernel, single
// precision storage, and the refusals of inconsistent sizes.

#include "numerics/block_sparse_matrix.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "numerics/galerkin_product.hpp"

namespace robin {
namespace {

Eigen::VectorXd random_vector(int size, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  return Eigen::VectorXd::NullaryExpr(size, [&] { return value(generator); });
}

/// Blocks of the given sizes (cycled), their unknowns shuffled over the numbering when
/// `scattered`.
std::vector<int> block_numbers(int size, const std::vector<int>& sizes, bool scattered,
                               unsigned seed) {
  std::vector<int> order(static_cast<std::size_t>(size));
  for (int unknown = 0; unknown < size; ++unknown)
    order[static_cast<std::size_t>(unknown)] = unknown;
  if (scattered) std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  std::vector<int> blocks(static_cast<std::size_t>(size));
  int block = 0, filled = 0;
  for (int k = 0; k < size; ++k) {
    blocks[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])] = block;
    if (++filled == sizes[static_cast<std::size_t>(block) % sizes.size()]) {
      ++block;
      filled = 0;
    }
  }
  return blocks;
}

/// A prolongator-like matrix: each row block couples to `width` random column blocks, every
/// entry of a coupled pair of blocks nonzero.
RowMajorSparseMatrix random_block_matrix(const BlockLayout& rows, const BlockLayout& columns,
                                         int width, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::uniform_int_distribution<int> column_block(0, columns.count() - 1);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int row_block = 0; row_block < rows.count(); ++row_block) {
    std::vector<int> coupled;
    for (int k = 0; k < width; ++k) coupled.push_back(column_block(generator));
    std::sort(coupled.begin(), coupled.end());
    coupled.erase(std::unique(coupled.begin(), coupled.end()), coupled.end());
    for (int r = rows.first(row_block); r < rows.first(row_block + 1); ++r) {
      for (int block : coupled) {
        for (int c = columns.first(block); c < columns.first(block + 1); ++c) {
          triplets.emplace_back(rows.members()[static_cast<std::size_t>(r)],
                                columns.members()[static_cast<std::size_t>(c)], value(generator));
        }
      }
    }
  }
  RowMajorSparseMatrix matrix(rows.size(), columns.size());
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

template <typename Value>
void expect_same_products(const RowMajorSparseMatrix& matrix, const BlockLayout& rows,
                          const BlockLayout& columns, double tolerance) {
  const BlockSparseMatrix<Value> stored(matrix, rows, columns);
  ASSERT_EQ(stored.rows(), matrix.rows());
  ASSERT_EQ(stored.cols(), matrix.cols());
  for (unsigned seed = 1; seed <= 2; ++seed) {
    const Eigen::VectorXd x = random_vector(static_cast<int>(matrix.cols()), seed);
    const Eigen::VectorXd expected = matrix * x;
    Eigen::VectorXd product;
    stored.multiply(x, product);
    ASSERT_EQ(product.size(), expected.size());
    EXPECT_LE((product - expected).lpNorm<Eigen::Infinity>(),
              tolerance * expected.lpNorm<Eigen::Infinity>());
    const Eigen::VectorXd z = random_vector(static_cast<int>(matrix.rows()), seed + 10);
    const Eigen::VectorXd expected_transposed = matrix.transpose() * z;
    stored.multiply_transpose(z, product);
    ASSERT_EQ(product.size(), expected_transposed.size());
    EXPECT_LE((product - expected_transposed).lpNorm<Eigen::Infinity>(),
              tolerance * expected_transposed.lpNorm<Eigen::Infinity>());
  }
}

TEST(BlockLayout, SlotsOfPaddedAndScatteredBlocks) {
  // blocks of sizes 3, 2, 3 with unknowns out of order
  const BlockLayout layout({1, 0, 2, 0, 1, 2, 0, 2});
  EXPECT_EQ(layout.size(), 8);
  EXPECT_EQ(layout.count(), 3);
  EXPECT_EQ(layout.block_size(), 3);
  EXPECT_EQ(layout.slot_count(), 9);
  EXPECT_FALSE(layout.identity());
  // block 0 holds 1, 3, 6 in slots 0, 1, 2; block 1 holds 0, 4 in 3, 4 (5 padding)
  EXPECT_EQ(layout.slot_of(1), 0);
  EXPECT_EQ(layout.slot_of(6), 2);
  EXPECT_EQ(layout.slot_of(4), 4);
  EXPECT_EQ(layout.unknown_of_slot(5), -1);
  EXPECT_EQ(layout.slot_of(7), 8);
  const Eigen::VectorXd x = random_vector(8, 3);
  Eigen::VectorXd padded, back;
  layout.to_slots(x, padded);
  EXPECT_EQ(padded[5], 0.0);
  layout.from_slots(padded, back);
  EXPECT_EQ(back, x);
  EXPECT_TRUE(BlockLayout({0, 0, 1, 1}).identity());
  EXPECT_TRUE(BlockLayout::one_per_unknown(5).identity());
  EXPECT_EQ(consecutive_numbers({7, 3, 7, 11, 3}), (std::vector<int>{1, 0, 1, 2, 0}));
}

TEST(BlockLayout, InconsistentBlockNumbersAreRefused) {
  EXPECT_THROW(BlockLayout({0, -1, 0}), std::invalid_argument);
  EXPECT_THROW(BlockLayout({0, 2, 0}), std::invalid_argument);  // block 1 has no unknown
  EXPECT_THROW(BlockLayout({0, 3, 1}), std::invalid_argument);  // beyond the unknowns
  EXPECT_THROW(consecutive_numbers({1, -2}), std::invalid_argument);
}

TEST(BlockSparseMatrix, NodeByAggregateBlocksGiveEigensProducts) {
  const BlockLayout rows(block_numbers(600, {3}, false, 1));     // 200 nodes
  const BlockLayout columns(block_numbers(120, {6}, false, 2));  // 20 aggregates
  const RowMajorSparseMatrix matrix = random_block_matrix(rows, columns, 4, 21);
  expect_same_products<double>(matrix, rows, columns, 1e-14);
  expect_same_products<float>(matrix, rows, columns, 1e-6);
  const BlockSparseMatrix<double> stored(matrix, rows, columns);
  EXPECT_LE(stored.stored_blocks(), 4L * 200);
}

TEST(BlockSparseMatrix, PaddedScatteredAndGeneralBlocksGiveEigensProducts) {
  // nodes of 1-3 dofs spread over the numbering against aggregates of 4-6 coarse unknowns (the
  // fixed 3 x 6 kernel on padded vectors), then 2 x 3 blocks (the general kernel)
  const BlockLayout rows(block_numbers(500, {3, 2, 3, 1}, true, 3));
  const BlockLayout columns(block_numbers(110, {6, 5, 6, 4}, true, 4));
  ASSERT_EQ(rows.block_size(), 3);
  ASSERT_EQ(columns.block_size(), 6);
  expect_same_products<double>(random_block_matrix(rows, columns, 5, 22), rows, columns, 1e-14);
  const BlockLayout plane_rows(block_numbers(300, {2}, true, 5));
  const BlockLayout plane_columns(block_numbers(45, {3}, false, 6));
  expect_same_products<double>(random_block_matrix(plane_rows, plane_columns, 3, 23), plane_rows,
                               plane_columns, 1e-14);
  expect_same_products<float>(random_block_matrix(plane_rows, plane_columns, 3, 23), plane_rows,
                              plane_columns, 1e-6);
}

TEST(BlockSparseMatrix, InconsistentSizesAreRefused) {
  const BlockLayout rows(block_numbers(30, {3}, false, 7));
  const BlockLayout columns(block_numbers(12, {6}, false, 8));
  const RowMajorSparseMatrix matrix = random_block_matrix(rows, columns, 2, 24);
  EXPECT_THROW(BlockSparseMatrix<double>(matrix, columns, rows), std::invalid_argument);
  const BlockSparseMatrix<double> stored(matrix, rows, columns);
  Eigen::VectorXd product;
  EXPECT_THROW(stored.multiply(Eigen::VectorXd::Zero(30), product), std::invalid_argument);
  EXPECT_THROW(stored.multiply_transpose(Eigen::VectorXd::Zero(12), product),
               std::invalid_argument);
}

/// A random symmetric positive definite matrix whose rows couple each block of `layout` to
/// itself and `width` random other blocks, entry by entry (both triangles stored).
RowMajorSparseMatrix random_symmetric_blocks(const BlockLayout& layout, int width, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::uniform_int_distribution<int> other_block(0, layout.count() - 1);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int block = 0; block < layout.count(); ++block) {
    for (int k = 0; k <= width; ++k) {
      const int other = k == 0 ? block : other_block(generator);
      for (int r = layout.first(block); r < layout.first(block + 1); ++r) {
        for (int c = layout.first(other); c < layout.first(other + 1); ++c) {
          const int row = layout.members()[static_cast<std::size_t>(r)];
          const int column = layout.members()[static_cast<std::size_t>(c)];
          if (row == column) {
            triplets.emplace_back(row, row, 40.0 + value(generator));
          } else if (row > column || other != block) {
            const double entry = value(generator);
            triplets.emplace_back(row, column, entry);
            triplets.emplace_back(column, row, entry);
          }
        }
      }
    }
  }
  RowMajorSparseMatrix matrix(layout.size(), layout.size());
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

void expect_galerkin_product(const BlockLayout& fine, const BlockLayout& coarse, unsigned seed) {
  const RowMajorSparseMatrix matrix = random_symmetric_blocks(fine, 4, seed);
  const RowMajorSparseMatrix prolongator = random_block_matrix(fine, coarse, 3, seed + 1);
  const RowMajorSparseMatrix product =
      galerkin_product(matrix, BlockSparseMatrix<double>(prolongator, fine, coarse));
  const Eigen::MatrixXd expected = Eigen::MatrixXd(RowMajorSparseMatrix(prolongator.transpose()) *
                                                   RowMajorSparseMatrix(matrix * prolongator));
  const Eigen::MatrixXd computed(product);
  ASSERT_EQ(computed.rows(), coarse.size());
  ASSERT_EQ(computed.cols(), coarse.size());
  EXPECT_LE((computed - expected).lpNorm<Eigen::Infinity>(),
            1e-13 * expected.lpNorm<Eigen::Infinity>());
  EXPECT_EQ((computed - computed.transpose()).lpNorm<Eigen::Infinity>(), 0.0);  // mirrored
  for (int row = 0; row < product.rows(); ++row) {  // compressed rows, columns increasing
    EXPECT_TRUE(std::is_sorted(product.innerIndexPtr() + product.outerIndexPtr()[row],
                               product.innerIndexPtr() + product.outerIndexPtr()[row + 1]));
  }
}

TEST(GalerkinProduct, EqualsEigensTripleProduct) {
  expect_galerkin_product(BlockLayout(block_numbers(450, {3}, false, 9)),
                          BlockLayout(block_numbers(90, {6}, false, 10)), 31);
}

TEST(GalerkinProduct, PaddedAndScatteredBlocksEqualEigensTripleProduct) {
  // nodes with prescribed components and aggregates of deficient rank, spread over the numbering
  expect_galerkin_product(BlockLayout(block_numbers(400, {3, 2, 3, 1}, true, 11)),
                          BlockLayout(block_numbers(84, {6, 4, 6, 5}, true, 12)), 32);
  // aggregates of aggregates (6 x 6) and plane blocks (2 x 3)
  expect_galerkin_product(BlockLayout(block_numbers(240, {6}, false, 13)),
                          BlockLayout(block_numbers(48, {6}, false, 14)), 33);
  expect_galerkin_product(BlockLayout(block_numbers(200, {2}, true, 15)),
                          BlockLayout(block_numbers(30, {3}, false, 16)), 34);
}

TEST(GalerkinProduct, AProlongatorOfOtherSizeIsRefused) {
  const BlockLayout fine(block_numbers(30, {3}, false, 17));
  const BlockLayout coarse(block_numbers(12, {6}, false, 18));
  const RowMajorSparseMatrix prolongator = random_block_matrix(fine, coarse, 2, 35);
  const BlockLayout other(block_numbers(33, {3}, false, 19));
  EXPECT_THROW(galerkin_product(random_symmetric_blocks(other, 2, 36),
                                BlockSparseMatrix<double>(prolongator, fine, coarse)),
               std::invalid_argument);
}

}  // namespace
}  // namespace robin
