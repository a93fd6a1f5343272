// The bounding-box tree returns exactly the boxes a brute-force scan finds, for random 3D boxes
// and queries, for flat boxes in the plane z = 0 (as 2D mortar coupling uses it), and for the
// empty tree.

#include <gtest/gtest.h>

#include <random>

#include "coupling/box_tree.hpp"

namespace robin {
namespace {

/// A random box in [0, 10]^3 (or in the plane z = 0 when `flat`) with extents up to `size`;
/// `stretch` scales the extents along x, so that the longest axis varies between trees.
Box random_box(std::mt19937& random, double size, bool flat = false, double stretch = 1.0) {
  std::uniform_real_distribution<double> position(0.0, 10.0), extent(0.0, size);
  const Eigen::Vector3d low(position(random), position(random), flat ? 0.0 : position(random));
  const Eigen::Vector3d extents(stretch * extent(random), extent(random),
                                flat ? 0.0 : extent(random));
  return {low, low + extents};
}

void expect_brute_force(const std::vector<Box>& boxes, const std::vector<Box>& queries) {
  const BoxTree tree(boxes);
  for (std::size_t query = 0; query < queries.size(); ++query) {
    std::vector<int> expected;
    for (int k = 0; k < static_cast<int>(boxes.size()); ++k) {
      if (overlaps(boxes[static_cast<std::size_t>(k)], queries[query])) expected.push_back(k);
    }
    EXPECT_EQ(tree.near(queries[query]), expected) << "query " << query;
  }
}

TEST(BoxTree, FindsExactlyTheBoxesABruteForceScanFinds) {
  std::mt19937 random(7);
  for (const double stretch : {1.0, 5.0}) {
    std::vector<Box> boxes, queries;
    for (int k = 0; k < 2000; ++k) boxes.push_back(random_box(random, 0.5, false, stretch));
    for (int k = 0; k < 500; ++k) queries.push_back(random_box(random, 3.0));
    expect_brute_force(boxes, queries);
  }
}

TEST(BoxTree, FlatBoxesInOnePlaneAsTwoDimensionalMortarUsesThem) {
  std::mt19937 random(11);
  std::vector<Box> boxes, queries;
  for (int k = 0; k < 2000; ++k) boxes.push_back(random_box(random, 0.3, true));
  for (int k = 0; k < 500; ++k) queries.push_back(random_box(random, 2.0, true));
  expect_brute_force(boxes, queries);
}

TEST(BoxTree, AQueryOffThePlaneFindsNoFlatBox) {
  const BoxTree tree({{Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 1.0, 0.0)}});
  EXPECT_TRUE(tree.near({Eigen::Vector3d(0.0, 0.0, 0.1), Eigen::Vector3d::Ones()}).empty());
  EXPECT_EQ(tree.near({Eigen::Vector3d(0.5, 0.5, -1.0), Eigen::Vector3d(2.0, 2.0, 0.0)}),
            std::vector<int>{0});
}

TEST(BoxTree, AnEmptyTreeFindsNothing) {
  const BoxTree tree({});
  EXPECT_TRUE(tree.near({Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()}).empty());
}

}  // namespace
}  // namespace robin
