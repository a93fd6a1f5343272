#pragma once
// Nested dissection of a mesh graph by coordinate bisection.
//
// A vertex set V is cut at the median of one coordinate: the vertices at or below it form one
// part, those above the other. The vertices of the smaller of the two boundary layers (those of
// one part with a neighbour in the other) form a separator S: no edge joins the rest of one part
// to the rest of the other. Each axis is tried and the cut with the smallest separator kept.
// The parts are dissected recursively down to leaves of at most `leaf_size` vertices.
// Eliminating the vertices of a leaf or of a part before its separator, and each separator after
// both parts it separates, creates fill only inside the parts and their separators: on a
// quasi-uniform mesh the top separators have O(n^(1/2)) vertices in 2D and O(n^(2/3)) in 3D, the
// optimal orders of nested dissection (George 1973; Miller, Teng, Thurston and Vavasis 1997).
// The sets are the constraints of a constrained minimum-degree order (CAMD) that orders the
// vertices inside each set.
//
// Cost: O(n log n) work in all (each level scans its vertices and their edges once per axis).

#include <Eigen/Core>
#include <vector>

namespace robin {

/// An undirected graph in compressed rows: the neighbours of vertex v are
/// neighbours[start[v] .. start[v+1]) (both directions stored; a vertex need not list itself).
struct AdjacencyGraph {
  std::vector<long> start;
  std::vector<int> neighbours;
  int vertex_count() const { return static_cast<int>(start.size()) - 1; }
};

/// A partition of the vertices into sets numbered in a valid nested-dissection elimination
/// order: every separator's number is larger than the numbers of all the sets inside the two
/// parts it separates.
struct DissectionSets {
  std::vector<int> set_of_vertex;
  int set_count = 0;
};

/// Vertices whose edges edge_length_spread reads at most (about: a systematic sample).
constexpr int spread_sample_vertices = 20000;

/// How graded the mesh is: the 90th over the 10th percentile of the lengths of the graph's edges
/// (each edge once; above spread_sample_vertices vertices, the edges of every k-th vertex, k the
/// vertex count over that). About 1 to 2 on quasi-uniform meshes (diagonals of squares and cubes
/// included), far more where a zone is refined (the Hertz meshes: 10). Infinity when a tenth of
/// the edges have length zero; 1 for a graph without edges.
double edge_length_spread(const AdjacencyGraph& graph, const std::vector<Eigen::Vector3d>& points);

/// The nested dissection (file comment) of `graph` whose vertex v sits at points[v].
/// Throws std::invalid_argument when the sizes disagree, leaf_size < 1 or a point is not finite.
DissectionSets geometric_dissection(const AdjacencyGraph& graph,
                                    const std::vector<Eigen::Vector3d>& points, int leaf_size);

}  // namespace robin
