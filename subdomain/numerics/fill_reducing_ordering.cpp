#include "numerics/fill_reducing_ordering.hpp"

#include <suitesparse/cholmod.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <stdexcept>

#include "numerics/geometric_dissection.hpp"

namespace robin {
namespace {

/// Column-compressed pattern of a symmetric n x n matrix: the rows of column j are
/// rows[start[j] .. start[j+1]), ascending.
struct SymmetricPattern {
  std::vector<long> start;
  std::vector<int> rows;
};

/// Index of every kept unknown in the leading block (or -1 for a trailing one), checking that
/// `trailing` holds distinct unknowns of the matrix.
std::vector<int> leading_indices(int size, const std::vector<int>& trailing,
                                 const std::string& body_name) {
  std::vector<int> leading_index(static_cast<std::size_t>(size), 0);
  for (int unknown : trailing) {
    if (unknown < 0 || unknown >= size || leading_index[unknown] < 0) {
      throw std::invalid_argument("body '" + body_name + "': trailing unknown " +
                                  std::to_string(unknown) + " is out of range or repeated");
    }
    leading_index[unknown] = -1;
  }
  int count = 0;
  for (int& index : leading_index) {
    if (index == 0) index = count++;
  }
  return leading_index;
}

/// Both triangles of the pattern of the leading block (unknowns with leading_index >= 0,
/// renumbered), built from the lower-triangle entries of `matrix`.
SymmetricPattern leading_pattern(const SparseMatrix& matrix, const std::vector<int>& leading_index,
                                 int leading_count) {
  SymmetricPattern pattern;
  pattern.start.assign(static_cast<std::size_t>(leading_count) + 1, 0);
  const auto for_each_entry = [&](auto&& visit) {
    for (int column = 0; column < matrix.outerSize(); ++column) {
      const int new_column = leading_index[column];
      if (new_column < 0) continue;
      for (SparseMatrix::InnerIterator entry(matrix, column); entry; ++entry) {
        const int row = static_cast<int>(entry.row());
        if (row < column || leading_index[row] < 0) continue;
        visit(leading_index[row], new_column);
      }
    }
  };
  for_each_entry([&](int row, int column) {
    ++pattern.start[column + 1];
    if (row != column) ++pattern.start[row + 1];
  });
  for (int column = 0; column < leading_count; ++column) {
    pattern.start[column + 1] += pattern.start[column];
  }
  pattern.rows.resize(static_cast<std::size_t>(pattern.start.back()));
  std::vector<long> next(pattern.start.begin(), pattern.start.end() - 1);
  for_each_entry([&](int row, int column) {
    pattern.rows[next[column]++] = row;
    if (row != column) pattern.rows[next[row]++] = column;
  });
  for (int column = 0; column < leading_count; ++column) {
    const auto first = pattern.rows.begin() + pattern.start[column];
    const auto last = pattern.rows.begin() + pattern.start[column + 1];
    if (!std::is_sorted(first, last)) std::sort(first, last);
  }
  return pattern;
}

bool same_pattern(const SymmetricPattern& pattern, int left, int right) {
  const long left_size = pattern.start[left + 1] - pattern.start[left];
  const long right_size = pattern.start[right + 1] - pattern.start[right];
  return left_size == right_size && std::equal(pattern.rows.begin() + pattern.start[left],
                                               pattern.rows.begin() + pattern.start[left + 1],
                                               pattern.rows.begin() + pattern.start[right]);
}

/// first[v] .. first[v+1]-1 are the unknowns of supervariable v: maximal runs of consecutive
/// unknowns with identical patterns.
std::vector<int> supervariable_starts(const SymmetricPattern& pattern, int size) {
  std::vector<int> first;
  for (int unknown = 0; unknown < size; ++unknown) {
    if (unknown == 0 || !same_pattern(pattern, unknown - 1, unknown)) first.push_back(unknown);
  }
  first.push_back(size);
  return first;
}

/// The supervariable graph: v and w adjacent when an unknown of v couples to one of w (K's
/// pattern); each vertex's neighbours ascend, itself not among them.
AdjacencyGraph supervariable_adjacency(const SymmetricPattern& pattern,
                                       const std::vector<int>& first) {
  const int count = static_cast<int>(first.size()) - 1;
  std::vector<int> supervariable(static_cast<std::size_t>(first.back()));
  for (int v = 0; v < count; ++v) {
    std::fill(supervariable.begin() + first[v], supervariable.begin() + first[v + 1], v);
  }
  AdjacencyGraph graph;
  graph.start.assign(static_cast<std::size_t>(count) + 1, 0);
  for (int v = 0; v < count; ++v) {
    const int unknown = first[v];
    int last = -1;
    for (long entry = pattern.start[unknown]; entry < pattern.start[unknown + 1]; ++entry) {
      const int neighbour = supervariable[pattern.rows[entry]];
      if (neighbour != v && neighbour != last) graph.neighbours.push_back(neighbour);
      last = neighbour;  // rows ascend, so supervariables ascend: duplicates are adjacent
    }
    graph.start[v + 1] = static_cast<long>(graph.neighbours.size());
  }
  return graph;
}

/// The lower triangle of `graph` with its diagonal as a CHOLMOD pattern matrix (stype -1).
cholmod_sparse* lower_triangle(const AdjacencyGraph& graph, cholmod_common& common) {
  const int count = graph.vertex_count();
  std::vector<int> start(static_cast<std::size_t>(count) + 1, 0);
  std::vector<int> rows;
  rows.reserve(graph.neighbours.size() / 2 + static_cast<std::size_t>(count));
  for (int v = 0; v < count; ++v) {
    rows.push_back(v);
    for (long entry = graph.start[v]; entry < graph.start[v + 1]; ++entry) {
      if (graph.neighbours[entry] > v) rows.push_back(graph.neighbours[entry]);
    }
    start[v + 1] = static_cast<int>(rows.size());
  }
  cholmod_sparse* lower =
      cholmod_allocate_sparse(count, count, rows.size(), 1, 1, -1, CHOLMOD_PATTERN, &common);
  if (lower == nullptr) return nullptr;
  std::memcpy(lower->p, start.data(), start.size() * sizeof(int));
  std::memcpy(lower->i, rows.data(), rows.size() * sizeof(int));
  return lower;
}

/// An elimination order of a graph's vertices and the flops of its (vertex-level) factorization.
struct GraphOrder {
  std::vector<int> order;
  double flops = 0.0;
};

[[noreturn]] void throw_cholmod_failure(const cholmod_common& common, const std::string& body_name,
                                        const std::string& step) {
  if (common.status == CHOLMOD_OUT_OF_MEMORY) throw std::bad_alloc();
  throw std::runtime_error("body '" + body_name + "': CHOLMOD " + step + " failed (status " +
                           std::to_string(common.status) + ")");
}

/// CHOLMOD's symbolic analysis of `graph` with `method` (CHOLMOD_AMD, CHOLMOD_METIS, or
/// CHOLMOD_GIVEN with `given`): the order (CHOLMOD's postordering of it) and its flops.
/// Restores common's settings.
GraphOrder analyze(cholmod_sparse* graph, int method, int* given, cholmod_common& common,
                   const std::string& body_name) {
  const int method_count = common.nmethods;
  const int first_ordering = common.method[0].ordering;
  const int supernodal = common.supernodal;
  common.nmethods = 1;
  common.method[0].ordering = method;
  common.supernodal = CHOLMOD_SIMPLICIAL;  // only the permutation and the flops are wanted
  cholmod_factor* symbolic = cholmod_analyze_p(graph, given, nullptr, 0, &common);
  common.nmethods = method_count;
  common.method[0].ordering = first_ordering;
  common.supernodal = supernodal;
  if (symbolic == nullptr || common.status < CHOLMOD_OK) {
    if (symbolic != nullptr) cholmod_free_factor(&symbolic, &common);
    throw_cholmod_failure(common, body_name, "ordering");
  }
  const auto* permutation = static_cast<const int*>(symbolic->Perm);
  GraphOrder result{std::vector<int>(permutation, permutation + graph->nrow), common.fl};
  cholmod_free_factor(&symbolic, &common);
  return result;
}

/// The geometric nested dissection of `adjacency` (geometric_dissection.hpp), each set ordered
/// by constrained minimum degree (CAMD), and its flops.
GraphOrder order_by_dissection(cholmod_sparse* graph, const AdjacencyGraph& adjacency,
                               const std::vector<Eigen::Vector3d>& points, cholmod_common& common,
                               const std::string& body_name) {
  constexpr int leaf_size = 64;  // docs/benchmarks.md, "Geometric nested dissection"
  DissectionSets sets = geometric_dissection(adjacency, points, leaf_size);
  std::vector<int> order(graph->nrow);
  if (!cholmod_camd(graph, nullptr, 0, sets.set_of_vertex.data(), order.data(), &common)) {
    throw_cholmod_failure(common, body_name, "constrained minimum-degree ordering");
  }
  return analyze(graph, CHOLMOD_GIVEN, order.data(), common, body_name);
}

/// Fill-reducing order of `graph` (its lower triangle; `adjacency` the same graph), whose
/// vertices stand for `unknowns_per_vertex` unknowns each on average and sit at `points` (or
/// empty). First order: the geometric nested dissection when the points are known, else AMD.
/// METIS (nested dissection by multilevel graph partitioning) costs far more, in proportion to
/// the graph's entries, and pays off only through a cheaper numerical factorization: it is
/// tried when the factorization with the first order needs more than a threshold of flops per
/// stored entry of the graph (the flops of the unknowns estimated as unknowns_per_vertex^3
/// times the graph's: a vertex's unknowns form a dense block), and kept when it needs fewer.
/// Thresholds (docs/benchmarks.md): 2e4 after AMD, below which (small and mid-size plane
/// bodies) METIS's cost exceeds what it saves, and after the geometric dissection of a graded
/// mesh (edge_length_spread above 4), whose straight cuts cross the refined zone (15-60 % more
/// flops than METIS on the Hertz meshes); 1e5 after the geometric dissection of a quasi-uniform
/// mesh, whose orders need at most a few percent more flops than METIS's, above which the
/// factorization takes ten times METIS's time (large solid bodies, where METIS saves up to
/// 40 %).
std::vector<int> order_graph(cholmod_sparse* graph, const AdjacencyGraph& adjacency,
                             const std::vector<Eigen::Vector3d>& points, double unknowns_per_vertex,
                             cholmod_common& common, const std::string& body_name) {
  constexpr double graded_spread = 4.0;
  const bool geometric = !points.empty();
  GraphOrder best = geometric ? order_by_dissection(graph, adjacency, points, common, body_name)
                              : analyze(graph, CHOLMOD_AMD, nullptr, common, body_name);
  const bool uniform = geometric && edge_length_spread(adjacency, points) <= graded_spread;
  const double metis_threshold = uniform ? 1e5 : 2e4;
  const double entries = static_cast<double>(static_cast<const int*>(graph->p)[graph->ncol]);
  const double unknown_flops = best.flops * std::pow(unknowns_per_vertex, 3);
  if (unknown_flops > metis_threshold * entries) {
    GraphOrder nested = analyze(graph, CHOLMOD_METIS, nullptr, common, body_name);
    if (nested.flops < best.flops) best = std::move(nested);
  }
  return std::move(best.order);
}

/// The points of the supervariables: each one's first unknown's point (all its unknowns belong
/// to one node), or empty when `unknown_points` is.
std::vector<Eigen::Vector3d> supervariable_points(
    const std::vector<Eigen::Vector3d>& unknown_points, const std::vector<int>& leading_unknown,
    const std::vector<int>& first) {
  std::vector<Eigen::Vector3d> points;
  if (unknown_points.empty()) return points;
  points.reserve(first.size() - 1);
  for (std::size_t v = 0; v + 1 < first.size(); ++v) {
    points.push_back(unknown_points[leading_unknown[first[v]]]);
  }
  return points;
}

}  // namespace

std::vector<int> fill_reducing_ordering(const SparseMatrix& matrix,
                                        const std::vector<int>& trailing,
                                        const std::vector<Eigen::Vector3d>& unknown_points,
                                        cholmod_common_struct& common,
                                        const std::string& body_name) {
  const int size = static_cast<int>(matrix.rows());
  if (!unknown_points.empty() && static_cast<int>(unknown_points.size()) != size) {
    throw std::invalid_argument("body '" + body_name +
                                "': " + std::to_string(unknown_points.size()) +
                                " unknown points for " + std::to_string(size) + " unknowns");
  }
  const std::vector<int> leading_index = leading_indices(size, trailing, body_name);
  const int leading_count = size - static_cast<int>(trailing.size());
  std::vector<int> leading_unknown(static_cast<std::size_t>(leading_count));
  for (int unknown = 0; unknown < size; ++unknown) {
    if (leading_index[unknown] >= 0) leading_unknown[leading_index[unknown]] = unknown;
  }
  std::vector<int> ordering;
  ordering.reserve(static_cast<std::size_t>(size));
  if (leading_count > 0) {
    std::vector<int> first;
    AdjacencyGraph adjacency;
    {
      const SymmetricPattern pattern = leading_pattern(matrix, leading_index, leading_count);
      first = supervariable_starts(pattern, leading_count);
      adjacency = supervariable_adjacency(pattern, first);
    }
    cholmod_sparse* graph = lower_triangle(adjacency, common);
    if (graph == nullptr)
      throw_cholmod_failure(common, body_name, "allocation of the ordering graph");
    std::vector<int> order;
    try {
      const double unknowns_per_vertex =
          static_cast<double>(leading_count) / static_cast<double>(graph->nrow);
      order = order_graph(graph, adjacency,
                          supervariable_points(unknown_points, leading_unknown, first),
                          unknowns_per_vertex, common, body_name);
    } catch (...) {
      cholmod_free_sparse(&graph, &common);
      throw;
    }
    cholmod_free_sparse(&graph, &common);
    for (int v : order) {
      for (int unknown = first[v]; unknown < first[v + 1]; ++unknown) {
        ordering.push_back(leading_unknown[unknown]);
      }
    }
  }
  ordering.insert(ordering.end(), trailing.begin(), trailing.end());
  return ordering;
}

}  // namespace robin
