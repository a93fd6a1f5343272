#include "numerics/geometric_dissection.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace robin {
namespace {

/// A cut of a vertex set: the two parts without the separator, and the separator.
struct Cut {
  std::vector<int> first;
  std::vector<int> second;
  std::vector<int> separator;
};

class Dissection {
 public:
  Dissection(const AdjacencyGraph& graph, const std::vector<Eigen::Vector3d>& points, int leaf_size)
      : graph_(graph),
        points_(points),
        leaf_size_(leaf_size),
        side_(points.size(), Side::outside),
        sets_{std::vector<int>(points.size(), -1), 0} {}

  /// Numbers the sets of `vertices` (consumed) after those numbered so far.
  void dissect(std::vector<int> vertices) {
    if (vertices.empty()) return;
    if (static_cast<int>(vertices.size()) > leaf_size_) {
      Cut cut = best_cut(vertices);
      if (!cut.first.empty() && !cut.second.empty()) {
        std::vector<int>().swap(vertices);
        dissect(std::move(cut.first));
        dissect(std::move(cut.second));
        number_set(cut.separator);
        return;
      }
    }
    number_set(vertices);
  }

  DissectionSets result() && { return std::move(sets_); }

 private:
  enum class Side : char { outside, first, second };

  void number_set(const std::vector<int>& vertices) {
    if (vertices.empty()) return;
    for (int vertex : vertices) sets_.set_of_vertex[vertex] = sets_.set_count;
    ++sets_.set_count;
  }

  /// The cut with the smallest separator over the axes along which the vertices spread.
  Cut best_cut(std::vector<int>& vertices) {
    Eigen::Vector3d lowest = points_[vertices.front()];
    Eigen::Vector3d highest = lowest;
    for (int vertex : vertices) {
      lowest = lowest.cwiseMin(points_[vertex]);
      highest = highest.cwiseMax(points_[vertex]);
    }
    Cut best;
    bool found = false;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(highest[axis] > lowest[axis])) continue;  // a plane body's z, or a line of points
      Cut cut = cut_along(vertices, axis);
      if (cut.first.empty() || cut.second.empty()) continue;
      if (!found || cut.separator.size() < best.separator.size()) {
        best = std::move(cut);
        found = true;
      }
    }
    return best;
  }

  /// Splits at the median coordinate along `axis`: the vertices at or below it first, unless
  /// that leaves less than a quarter on either side (many equal coordinates), in which case
  /// exactly half, ties broken by vertex number. The separator is the smaller boundary layer.
  Cut cut_along(std::vector<int>& vertices, int axis) {
    const auto half = vertices.begin() + static_cast<long>(vertices.size() / 2);
    std::nth_element(vertices.begin(), half, vertices.end(), [&](int left, int right) {
      return std::pair(points_[left][axis], left) < std::pair(points_[right][axis], right);
    });
    const double median = points_[*half][axis];
    const long at_or_below = std::count_if(vertices.begin(), vertices.end(),
                                           [&](int v) { return points_[v][axis] <= median; });
    const long size = static_cast<long>(vertices.size());
    const bool by_value = 4 * at_or_below <= 3 * size;
    for (auto vertex = vertices.begin(); vertex != vertices.end(); ++vertex) {
      const bool first = by_value ? points_[*vertex][axis] <= median : vertex <= half;
      side_[*vertex] = first ? Side::first : Side::second;
    }
    Cut cut = split(vertices);
    for (int vertex : vertices) side_[vertex] = Side::outside;
    return cut;
  }

  /// The two sides marked in side_, their boundary layers, and the smaller layer as separator.
  Cut split(const std::vector<int>& vertices) const {
    Cut cut;
    std::vector<int> first_layer;
    std::vector<int> second_layer;
    for (int vertex : vertices) {
      const Side own = side_[vertex];
      const Side other = own == Side::first ? Side::second : Side::first;
      bool on_boundary = false;
      for (long entry = graph_.start[vertex]; entry < graph_.start[vertex + 1]; ++entry) {
        if (side_[graph_.neighbours[entry]] == other) {
          on_boundary = true;
          break;
        }
      }
      if (own == Side::first) {
        (on_boundary ? first_layer : cut.first).push_back(vertex);
      } else {
        (on_boundary ? second_layer : cut.second).push_back(vertex);
      }
    }
    if (first_layer.size() <= second_layer.size()) {
      cut.separator = std::move(first_layer);
      cut.second.insert(cut.second.end(), second_layer.begin(), second_layer.end());
    } else {
      cut.separator = std::move(second_layer);
      cut.first.insert(cut.first.end(), first_layer.begin(), first_layer.end());
    }
    return cut;
  }

  const AdjacencyGraph& graph_;
  const std::vector<Eigen::Vector3d>& points_;
  int leaf_size_;
  std::vector<Side> side_;
  DissectionSets sets_;
};

}  // namespace

double edge_length_spread(const AdjacencyGraph& graph, const std::vector<Eigen::Vector3d>& points) {
  // every edge once (from its lower vertex), or every edge of every stride-th vertex
  const int stride = std::max(1, graph.vertex_count() / spread_sample_vertices);
  std::vector<double> lengths;
  lengths.reserve(graph.neighbours.size() / (2 * static_cast<std::size_t>(stride)) + 1);
  for (int v = 0; v < graph.vertex_count(); v += stride) {
    for (long entry = graph.start[v]; entry < graph.start[v + 1]; ++entry) {
      const int w = graph.neighbours[entry];
      if (stride > 1 || w > v) lengths.push_back((points[w] - points[v]).norm());
    }
  }
  if (lengths.empty()) return 1.0;
  const auto percentile = [&lengths](double fraction) {
    const auto at = lengths.begin() + static_cast<long>(fraction * (lengths.size() - 1));
    std::nth_element(lengths.begin(), at, lengths.end());
    return *at;
  };
  const double low = percentile(0.1);
  const double high = percentile(0.9);
  return low > 0.0 ? high / low : std::numeric_limits<double>::infinity();
}

DissectionSets geometric_dissection(const AdjacencyGraph& graph,
                                    const std::vector<Eigen::Vector3d>& points, int leaf_size) {
  if (graph.start.empty() || graph.vertex_count() != static_cast<int>(points.size()) ||
      graph.start.back() != static_cast<long>(graph.neighbours.size())) {
    throw std::invalid_argument("geometric_dissection: a graph of " +
                                std::to_string(graph.start.size()) + " row starts and " +
                                std::to_string(graph.neighbours.size()) + " neighbours for " +
                                std::to_string(points.size()) + " points");
  }
  if (leaf_size < 1) throw std::invalid_argument("geometric_dissection: leaf size below 1");
  for (std::size_t v = 0; v < points.size(); ++v) {
    if (!points[v].allFinite()) {  // the median cuts compare coordinates
      throw std::invalid_argument("geometric_dissection: point " + std::to_string(v) +
                                  " is not finite");
    }
  }
  Dissection dissection(graph, points, leaf_size);
  std::vector<int> vertices(points.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) vertices[v] = static_cast<int>(v);
  dissection.dissect(std::move(vertices));
  return std::move(dissection).result();
}

}  // namespace robin
