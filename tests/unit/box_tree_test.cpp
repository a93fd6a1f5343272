// The bounding-box tree returns exactly the boxes a brute-force scan finds, for random boxes and
// queries (and for the empty tree).

#include <gtest/gtest.h>

#include <random>

#include "coupling/box_tree.hpp"

namespace robin {
namespace {

Box random_box(std::mt19937& random, double size) {
  std::uniform_real_distribution<double> position(0.0, 10.0), extent(0.0, size);
  const Eigen::Vector2d low(position(random), position(random));
  return {low, low + Eigen::Vector2d(extent(random), extent(random))};
}

TEST(BoxTree, FindsExactlyTheBoxesABruteForceScanFinds) {
  std::mt19937 random(7);
  std::vector<Box> boxes;
  for (int k = 0; k < 2000; ++k) boxes.push_back(random_box(random, 0.3));
  const BoxTree tree(boxes);
  for (int query = 0; query < 500; ++query) {
    const Box box = random_box(random, 2.0);
    std::vector<int> expected;
    for (int k = 0; k < static_cast<int>(boxes.size()); ++k) {
      if (overlaps(boxes[static_cast<std::size_t>(k)], box)) expected.push_back(k);
    }
    EXPECT_EQ(tree.near(box), expected) << "query " << query;
  }
}

TEST(BoxTree, AnEmptyTreeFindsNothing) {
  const BoxTree tree({});
  EXPECT_TRUE(tree.near({Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones()}).empty());
}

}  // namespace
}  // namespace robin
