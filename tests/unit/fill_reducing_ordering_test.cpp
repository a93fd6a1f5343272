// The node-graph fill-reducing ordering: a permutation with the trailing unknowns last, each
// node's components kept together, and a factor no fuller than CHOLMOD's own choice (AMD or
// METIS on the graph of the unknowns, computed independently by cholmod_analyze).

#include "numerics/fill_reducing_ordering.hpp"

#include <gtest/gtest.h>
#include <suitesparse/cholmod.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace robin {
namespace {

/// Lower triangle of a grid stiffness with `components` unknowns per node: nodes (i, j, k) of a
/// side^3 grid (side^2 when `three_dimensional` is false) couple to every node of their
/// surrounding cells, all components with all components (as a Q1 element matrix does), unknown
/// = components * node + component. `dropped`: a node whose last component is removed (a
/// Dirichlet component), so that node has one unknown fewer.
SparseMatrix grid_stiffness(int side, bool three_dimensional, int components, int dropped = -1) {
  const int depth = three_dimensional ? side : 1;
  const auto node = [&](int i, int j, int k) { return (k * side + j) * side + i; };
  const int node_count = side * side * depth;
  std::vector<int> first_unknown(static_cast<std::size_t>(node_count) + 1, 0);
  for (int n = 0; n < node_count; ++n) {
    first_unknown[n + 1] = first_unknown[n] + components - (n == dropped ? 1 : 0);
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < depth; ++k) {
    for (int j = 0; j < side; ++j) {
      for (int i = 0; i < side; ++i) {
        const int a = node(i, j, k);
        for (int dk = -1; dk <= 1; ++dk) {
          for (int dj = -1; dj <= 1; ++dj) {
            for (int di = -1; di <= 1; ++di) {
              const int ii = i + di, jj = j + dj, kk = k + dk;
              if (ii < 0 || jj < 0 || kk < 0 || ii >= side || jj >= side || kk >= depth) continue;
              const int b = node(ii, jj, kk);
              for (int p = first_unknown[a]; p < first_unknown[a + 1]; ++p) {
                for (int q = first_unknown[b]; q < first_unknown[b + 1]; ++q) {
                  if (p >= q) entries.emplace_back(p, q, p == q ? 30.0 : -0.5);
                }
              }
            }
          }
        }
      }
    }
  }
  const int size = first_unknown.back();
  SparseMatrix lower(size, size);
  lower.setFromTriplets(entries.begin(), entries.end());
  return lower;
}

/// The position of each unknown of grid_stiffness(side, three_dimensional, components): node
/// (i, j, k) at (i, j, k) (spacing 1, z = 0 for a plane grid).
std::vector<Eigen::Vector3d> grid_points(int side, bool three_dimensional, int components) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < (three_dimensional ? side : 1); ++k) {
    for (int j = 0; j < side; ++j) {
      for (int i = 0; i < side; ++i) {
        for (int c = 0; c < components; ++c) points.emplace_back(i, j, k);
      }
    }
  }
  return points;
}

/// Entries of L for the given elimination order (nullptr: CHOLMOD's own choice, or the method
/// `method` when given), from CHOLMOD's symbolic analysis of the lower-triangle pattern.
double factor_entries(const SparseMatrix& lower, const std::vector<int>* ordering,
                      int method = -1) {
  cholmod_common common;
  cholmod_start(&common);
  SparseMatrix copy = lower;
  copy.makeCompressed();
  cholmod_sparse view{};
  view.nrow = view.ncol = static_cast<std::size_t>(copy.rows());
  view.nzmax = static_cast<std::size_t>(copy.nonZeros());
  view.p = copy.outerIndexPtr();
  view.i = copy.innerIndexPtr();
  view.x = copy.valuePtr();
  view.stype = -1;
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  if (ordering != nullptr || method >= 0) {
    common.nmethods = 1;
    common.method[0].ordering = ordering != nullptr ? CHOLMOD_GIVEN : method;
  }
  std::vector<int> given = ordering != nullptr ? *ordering : std::vector<int>();
  cholmod_factor* symbolic =
      cholmod_analyze_p(&view, ordering != nullptr ? given.data() : nullptr, nullptr, 0, &common);
  EXPECT_NE(symbolic, nullptr);
  const double entries = common.lnz;
  cholmod_free_factor(&symbolic, &common);
  cholmod_finish(&common);
  return entries;
}

std::vector<int> order_of(const SparseMatrix& lower, const std::vector<int>& trailing,
                          const std::vector<Eigen::Vector3d>& points = {}) {
  cholmod_common common;
  cholmod_start(&common);
  std::vector<int> ordering = fill_reducing_ordering(lower, trailing, points, common, "block");
  cholmod_finish(&common);
  return ordering;
}

bool is_permutation_of_all(const std::vector<int>& ordering, int size) {
  std::vector<int> sorted = ordering;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> all(static_cast<std::size_t>(size));
  std::iota(all.begin(), all.end(), 0);
  return sorted == all;
}

TEST(FillReducingOrdering, SolidGridKeepsNodesTogetherAndFillsNoMoreThanCholmod) {
  const int side = 12;
  const SparseMatrix lower = grid_stiffness(side, true, 3);
  const std::vector<int> ordering = order_of(lower, {});
  ASSERT_TRUE(is_permutation_of_all(ordering, static_cast<int>(lower.rows())));
  for (std::size_t k = 0; k < ordering.size(); k += 3) {
    EXPECT_EQ(ordering[k] % 3, 0);  // a node's x, y, z follow each other
    EXPECT_EQ(ordering[k + 1], ordering[k] + 1);
    EXPECT_EQ(ordering[k + 2], ordering[k] + 2);
  }
  const double ours = factor_entries(lower, &ordering);
  const double cholmod_choice = factor_entries(lower, nullptr);
  EXPECT_LE(ours, 1.05 * cholmod_choice) << "ours " << ours << ", CHOLMOD " << cholmod_choice;
  std::vector<int> natural(ordering.size());
  std::iota(natural.begin(), natural.end(), 0);
  EXPECT_LT(ours, factor_entries(lower, &natural));
}

TEST(FillReducingOrdering, TrailingUnknownsComeLastInTheirGivenOrder) {
  const int side = 9;
  const SparseMatrix lower = grid_stiffness(side, true, 3);
  std::vector<int> trailing;  // the face z = 0, components z, y, x in descending node order
  for (int node = side * side - 1; node >= 0; --node) {
    for (int component = 2; component >= 0; --component) trailing.push_back(3 * node + component);
  }
  const std::vector<int> ordering = order_of(lower, trailing);
  ASSERT_TRUE(is_permutation_of_all(ordering, static_cast<int>(lower.rows())));
  EXPECT_TRUE(std::equal(trailing.begin(), trailing.end(), ordering.end() - trailing.size()));
  // The leading part is as good as CHOLMOD's own order of the leading block, trailing appended.
  std::vector<int> is_trailing(lower.rows(), 0);
  for (int unknown : trailing) is_trailing[unknown] = 1;
  std::vector<int> leading;
  for (int unknown = 0; unknown < lower.rows(); ++unknown) {
    if (!is_trailing[unknown]) leading.push_back(unknown);
  }
  std::vector<Eigen::Triplet<double>> block_entries;
  std::vector<int> new_index(lower.rows(), -1);
  for (std::size_t k = 0; k < leading.size(); ++k) new_index[leading[k]] = static_cast<int>(k);
  for (int column = 0; column < lower.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(lower, column); entry; ++entry) {
      if (new_index[entry.row()] >= 0 && new_index[column] >= 0) {
        block_entries.emplace_back(new_index[entry.row()], new_index[column], entry.value());
      }
    }
  }
  SparseMatrix block(static_cast<Eigen::Index>(leading.size()),
                     static_cast<Eigen::Index>(leading.size()));
  block.setFromTriplets(block_entries.begin(), block_entries.end());
  const std::vector<int> leading_order(ordering.begin(), ordering.end() - trailing.size());
  std::vector<int> leading_in_block;
  for (int unknown : leading_order) leading_in_block.push_back(new_index[unknown]);
  EXPECT_LE(factor_entries(block, &leading_in_block), 1.05 * factor_entries(block, nullptr));
}

TEST(FillReducingOrdering, PlaneGridWithADroppedComponentIsAPermutation) {
  const SparseMatrix lower = grid_stiffness(20, false, 2, 37);  // node 37 keeps only its x
  const std::vector<int> ordering = order_of(lower, {5, 4});
  ASSERT_TRUE(is_permutation_of_all(ordering, static_cast<int>(lower.rows())));
  EXPECT_EQ(ordering[ordering.size() - 2], 5);
  EXPECT_EQ(ordering.back(), 4);
  const double ours = factor_entries(lower, &ordering);
  std::vector<int> natural(ordering.size());
  std::iota(natural.begin(), natural.end(), 0);
  EXPECT_LT(ours, factor_entries(lower, &natural));
}

TEST(FillReducingOrdering, EveryUnknownTrailingKeepsTheGivenOrder) {
  const SparseMatrix lower = grid_stiffness(3, false, 2);
  std::vector<int> trailing(static_cast<std::size_t>(lower.rows()));
  std::iota(trailing.rbegin(), trailing.rend(), 0);
  EXPECT_EQ(order_of(lower, trailing), trailing);
}

TEST(FillReducingOrdering, WithPointsAPlaneGridFillsAsLittleAsMetisOnTheUnknowns) {
  const int side = 60;
  const SparseMatrix lower = grid_stiffness(side, false, 2);
  const std::vector<int> ordering = order_of(lower, {}, grid_points(side, false, 2));
  ASSERT_TRUE(is_permutation_of_all(ordering, static_cast<int>(lower.rows())));
  for (std::size_t k = 0; k < ordering.size(); k += 2) {
    EXPECT_EQ(ordering[k] % 2, 0);  // a node's x and y follow each other
    EXPECT_EQ(ordering[k + 1], ordering[k] + 1);
  }
  const double ours = factor_entries(lower, &ordering);
  const double metis = factor_entries(lower, nullptr, CHOLMOD_METIS);
  const double amd = factor_entries(lower, nullptr, CHOLMOD_AMD);
  EXPECT_LE(ours, 1.05 * metis) << "ours " << ours << ", METIS " << metis;
  EXPECT_LT(ours, amd) << "ours " << ours << ", AMD " << amd;
}

TEST(FillReducingOrdering, WithPointsASolidGridFillsAsLittleAsCholmodsChoice) {
  const int side = 14;
  const SparseMatrix lower = grid_stiffness(side, true, 3);
  std::vector<int> trailing;  // the face z = 0
  for (int node = 0; node < side * side; ++node) {
    for (int component = 0; component < 3; ++component) trailing.push_back(3 * node + component);
  }
  const std::vector<int> ordering = order_of(lower, trailing, grid_points(side, true, 3));
  ASSERT_TRUE(is_permutation_of_all(ordering, static_cast<int>(lower.rows())));
  EXPECT_TRUE(std::equal(trailing.begin(), trailing.end(), ordering.end() - trailing.size()));
  const std::vector<int> plain = order_of(lower, {}, grid_points(side, true, 3));
  const double ours = factor_entries(lower, &plain);
  const double cholmod_choice = factor_entries(lower, nullptr);
  EXPECT_LE(ours, 1.05 * cholmod_choice) << "ours " << ours << ", CHOLMOD " << cholmod_choice;
}

TEST(FillReducingOrdering, PointsMustBeOnePerUnknown) {
  const SparseMatrix lower = grid_stiffness(4, false, 2);
  std::vector<Eigen::Vector3d> points = grid_points(4, false, 2);
  points.pop_back();
  try {
    order_of(lower, {}, points);
    ADD_FAILURE() << "accepted too few points";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("body 'block': 31 unknown points for 32 unknowns"),
              std::string::npos)
        << error.what();
  }
}

TEST(FillReducingOrdering, OutOfRangeOrRepeatedTrailingUnknownNamesTheBody) {
  const SparseMatrix lower = grid_stiffness(3, false, 2);
  for (const std::vector<int>& trailing :
       {std::vector<int>{18}, std::vector<int>{-1}, std::vector<int>{3, 3}}) {
    try {
      order_of(lower, trailing);
      ADD_FAILURE() << "accepted a bad trailing list";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("body 'block': trailing unknown"), std::string::npos)
          << error.what();
    }
  }
}

}  // namespace
}  // namespace robin
