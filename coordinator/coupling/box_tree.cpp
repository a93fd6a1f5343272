#include "coupling/box_tree.hpp"

#include <algorithm>
#include <numeric>

namespace robin {

bool overlaps(const Box& a, const Box& b) {
  return (a.first.array() <= b.second.array()).all() && (b.first.array() <= a.second.array()).all();
}

BoxTree::BoxTree(std::vector<Box> boxes) : boxes_(std::move(boxes)), order_(boxes_.size()) {
  std::iota(order_.begin(), order_.end(), 0);
  if (!order_.empty()) build(0, static_cast<int>(order_.size()));
}

std::vector<int> BoxTree::near(const Box& query) const {
  std::vector<int> found;
  if (nodes_.empty()) return found;
  std::vector<int> pending{0};
  while (!pending.empty()) {
    const Node& node = nodes_[static_cast<std::size_t>(pending.back())];
    pending.pop_back();
    if (!overlaps(node.box, query)) continue;
    if (node.left < 0) {
      for (int k = node.begin; k < node.end; ++k) {
        const int index = order_[static_cast<std::size_t>(k)];
        if (overlaps(boxes_[static_cast<std::size_t>(index)], query)) found.push_back(index);
      }
      continue;
    }
    pending.push_back(node.left);
    pending.push_back(node.right);
  }
  std::sort(found.begin(), found.end());
  return found;
}

int BoxTree::build(int begin, int end) {
  Node node;
  node.begin = begin;
  node.end = end;
  node.box = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(begin)])];
  for (int k = begin + 1; k < end; ++k) {
    const Box& box = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])];
    node.box = {node.box.first.cwiseMin(box.first), node.box.second.cwiseMax(box.second)};
  }
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(node);
  constexpr int leaf_size = 4;
  if (end - begin <= leaf_size) return index;
  const Eigen::Vector3d extent = node.box.second - node.box.first;
  int axis = 0;
  extent.maxCoeff(&axis);  // the longest axis (the first of equal ones)
  const int middle = begin + (end - begin) / 2;
  const auto centre = [&](int box) {
    return boxes_[static_cast<std::size_t>(box)].first[axis] +
           boxes_[static_cast<std::size_t>(box)].second[axis];
  };
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int a, int b) { return centre(a) < centre(b); });
  const int left = build(begin, middle);
  const int right = build(middle, end);
  nodes_[static_cast<std::size_t>(index)].left = left;
  nodes_[static_cast<std::size_t>(index)].right = right;
  return index;
}

}  // namespace robin
