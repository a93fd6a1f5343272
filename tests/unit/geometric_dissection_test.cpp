// Geometric nested dissection: the sets partition the vertices, leaves stay small, the top
// separator of a grid is one grid line (the smallest separator a straight cut can give), and
// degenerate point sets (all equal, many equal coordinates) end in valid sets.

#include "numerics/geometric_dissection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace robin {
namespace {

/// A side x side grid of points (i, j) with spacing 1, each vertex adjacent to its up to eight
/// neighbours (the node graph of a mesh of squares); vertex j * side + i.
struct Grid {
  AdjacencyGraph graph;
  std::vector<Eigen::Vector3d> points;
};

Grid plane_grid(int side) {
  Grid grid;
  grid.graph.start.push_back(0);
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      grid.points.emplace_back(i, j, 0.0);
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int ii = i + di, jj = j + dj;
          if ((di == 0 && dj == 0) || ii < 0 || jj < 0 || ii >= side || jj >= side) continue;
          grid.graph.neighbours.push_back(jj * side + ii);
        }
      }
      grid.graph.start.push_back(static_cast<long>(grid.graph.neighbours.size()));
    }
  }
  return grid;
}

/// Checks that every vertex has a set in 0 .. set_count - 1 and every set is used; returns the
/// size of each set.
std::vector<int> set_sizes(const DissectionSets& sets, int vertex_count) {
  EXPECT_EQ(static_cast<int>(sets.set_of_vertex.size()), vertex_count);
  std::vector<int> sizes(static_cast<std::size_t>(sets.set_count), 0);
  for (int set : sets.set_of_vertex) {
    EXPECT_GE(set, 0);
    EXPECT_LT(set, sets.set_count);
    if (set >= 0 && set < sets.set_count) ++sizes[static_cast<std::size_t>(set)];
  }
  for (int size : sizes) EXPECT_GT(size, 0);
  return sizes;
}

TEST(GeometricDissection, TopSeparatorOfAGridIsOneGridLine) {
  const int side = 31;
  const Grid grid = plane_grid(side);
  const DissectionSets sets = geometric_dissection(grid.graph, grid.points, 16);
  const std::vector<int> sizes = set_sizes(sets, side * side);
  // The last set is eliminated last: the top separator, a full line x = 15 or y = 15.
  std::vector<Eigen::Vector3d> top;
  for (int v = 0; v < side * side; ++v) {
    if (sets.set_of_vertex[v] == sets.set_count - 1) top.push_back(grid.points[v]);
  }
  ASSERT_EQ(static_cast<int>(top.size()), side);
  const bool vertical =
      std::all_of(top.begin(), top.end(), [](const Eigen::Vector3d& p) { return p.x() == 15.0; });
  const bool horizontal =
      std::all_of(top.begin(), top.end(), [](const Eigen::Vector3d& p) { return p.y() == 15.0; });
  EXPECT_TRUE(vertical || horizontal);
}

TEST(GeometricDissection, SeparatorsSeparateAndLeavesStaySmall) {
  const int side = 40;
  const Grid grid = plane_grid(side);
  const int leaf_size = 20;
  const DissectionSets sets = geometric_dissection(grid.graph, grid.points, leaf_size);
  set_sizes(sets, side * side);
  // A separator is numbered after the two parts it separates and touches both: it has a
  // neighbour in a lower-numbered set. A leaf has none (its neighbours outside it lie in the
  // separators that cut it out). Leaves hold at most leaf_size vertices, and no two leaves
  // are adjacent: that is what the separators are for.
  std::vector<int> set_size(static_cast<std::size_t>(sets.set_count), 0);
  for (int set : sets.set_of_vertex) ++set_size[static_cast<std::size_t>(set)];
  std::vector<char> is_leaf(static_cast<std::size_t>(sets.set_count), 1);
  for (int v = 0; v < side * side; ++v) {
    for (long e = grid.graph.start[v]; e < grid.graph.start[v + 1]; ++e) {
      const int w = grid.graph.neighbours[e];
      if (sets.set_of_vertex[w] < sets.set_of_vertex[v]) is_leaf[sets.set_of_vertex[v]] = 0;
    }
  }
  for (int set = 0; set < sets.set_count; ++set) {
    if (is_leaf[set]) {
      EXPECT_LE(set_size[set], leaf_size) << "leaf set " << set;
    }
  }
  for (int v = 0; v < side * side; ++v) {
    for (long e = grid.graph.start[v]; e < grid.graph.start[v + 1]; ++e) {
      const int a = sets.set_of_vertex[v], b = sets.set_of_vertex[grid.graph.neighbours[e]];
      if (a != b) {
        EXPECT_FALSE(is_leaf[a] && is_leaf[b]) << "leaves " << a << " and " << b;
      }
    }
  }
}

TEST(GeometricDissection, EqualPointsFormOneSetAndTiesStillSplit) {
  Grid grid = plane_grid(12);
  std::vector<Eigen::Vector3d> same(grid.points.size(), Eigen::Vector3d(1.0, 2.0, 3.0));
  const DissectionSets one = geometric_dissection(grid.graph, same, 4);
  EXPECT_EQ(one.set_count, 1);
  set_sizes(one, 144);
  // Most points share x = 0 and y = 0: the cut falls back to an exact half.
  std::vector<Eigen::Vector3d> ties(grid.points.size(), Eigen::Vector3d::Zero());
  ties[7] = Eigen::Vector3d(1.0, 0.0, 0.0);
  const DissectionSets split = geometric_dissection(grid.graph, ties, 4);
  EXPECT_GT(split.set_count, 1);
  set_sizes(split, 144);
}

TEST(EdgeLengthSpread, IsSmallOnAUniformGridAndLargeOnAGradedOne) {
  Grid grid = plane_grid(30);
  // Edges of length 1 (sides) and sqrt(2) (diagonals): the 90th percentile is a diagonal's.
  EXPECT_NEAR(edge_length_spread(grid.graph, grid.points), std::sqrt(2.0), 1e-12);
  // Columns at x = 1.2^i: the spacing grows 1.2 times per column, about 200 times across.
  for (Eigen::Vector3d& point : grid.points) point.x() = std::pow(1.2, point.x());
  EXPECT_GT(edge_length_spread(grid.graph, grid.points), 10.0);
  std::fill(grid.points.begin(), grid.points.end(), grid.points[0]);  // every length zero
  EXPECT_EQ(edge_length_spread(grid.graph, grid.points), std::numeric_limits<double>::infinity());
}

/// The spread from every edge once, sorted: the definition, independently of the sampling.
double every_edge_spread(const Grid& grid) {
  std::vector<double> lengths;
  for (int v = 0; v < grid.graph.vertex_count(); ++v) {
    for (long entry = grid.graph.start[v]; entry < grid.graph.start[v + 1]; ++entry) {
      const int w = grid.graph.neighbours[entry];
      if (w > v) lengths.push_back((grid.points[w] - grid.points[v]).norm());
    }
  }
  std::sort(lengths.begin(), lengths.end());
  const auto at = [&lengths](double fraction) {
    return lengths[static_cast<std::size_t>(fraction * static_cast<double>(lengths.size() - 1))];
  };
  return at(0.9) / at(0.1);
}

TEST(EdgeLengthSpread, ASampleOfTheVerticesOfALargeGraphGivesTheSpreadOfEveryEdge) {
  // 300 x 300 = 90 000 vertices, above spread_sample_vertices: every 4th vertex's edges
  Grid grid = plane_grid(300);
  ASSERT_GT(grid.graph.vertex_count(), 2 * spread_sample_vertices);
  EXPECT_NEAR(edge_length_spread(grid.graph, grid.points), every_edge_spread(grid), 1e-12);
  // spacing growing 1.01 times per column: about 20 times across, graded
  for (Eigen::Vector3d& point : grid.points) point.x() = std::pow(1.01, point.x());
  const double exact = every_edge_spread(grid);
  EXPECT_GT(exact, 4.0);
  EXPECT_NEAR(edge_length_spread(grid.graph, grid.points), exact, 0.05 * exact);
}

TEST(GeometricDissection, RefusesMismatchedSizesAndPointsThatAreNotFinite) {
  const Grid grid = plane_grid(3);
  std::vector<Eigen::Vector3d> short_points(grid.points.begin(), grid.points.end() - 1);
  EXPECT_THROW(geometric_dissection(grid.graph, short_points, 4), std::invalid_argument);
  EXPECT_THROW(geometric_dissection(grid.graph, grid.points, 0), std::invalid_argument);
  std::vector<Eigen::Vector3d> not_finite = grid.points;
  not_finite[4].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(geometric_dissection(grid.graph, not_finite, 4), std::invalid_argument);
}

}  // namespace
}  // namespace robin
