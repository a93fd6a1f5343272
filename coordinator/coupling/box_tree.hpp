#pragma once
// A static bounding-box tree in three dimensions (median splits along the longest axis): the
// boxes that meet a query box in O(log n + k). The spatial search of mortar coupling
// (coupling/mortar_coupling.cpp, which embeds its 2D boxes with z = 0, and
// coupling/face_mortar.cpp).

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace robin {

using Box = std::pair<Eigen::Vector3d, Eigen::Vector3d>;  // lower and upper corners

/// True when the closed boxes share a point.
bool overlaps(const Box& a, const Box& b);

class BoxTree {
 public:
  explicit BoxTree(std::vector<Box> boxes);
  /// Indices (into the constructor's boxes), ascending, of the boxes that meet `query`.
  std::vector<int> near(const Box& query) const;

 private:
  struct Node {
    Box box;
    int begin = 0, end = 0;     // the boxes order_[begin, end)
    int left = -1, right = -1;  // children; -1 for a leaf
  };
  int build(int begin, int end);

  std::vector<Box> boxes_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace robin
