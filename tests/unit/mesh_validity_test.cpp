// check_element_validity on single affine simplices whose Jacobians are known by hand: the
// right triangle and tetrahedron with legs along the axes (det J = the product of the legs),
// the same with two nodes swapped (det J negated) and flattened ones (det J = 1e-13 times the
// squared or cubed size, below the 1e-12 threshold).

#include <gtest/gtest.h>

#include <string>

#include "numerics/errors.hpp"
#include "numerics/mesh_validity.hpp"

namespace robin {
namespace {

Mesh simplex(const std::vector<Eigen::Vector3d>& corners, std::vector<int> connectivity) {
  Mesh mesh;
  mesh.dimension = corners.size() == 3 ? 2 : 3;
  mesh.nodes = corners;
  for (std::size_t k = 0; k < corners.size(); ++k) mesh.node_tags.push_back(k + 1);
  const ElementType type = corners.size() == 3 ? ElementType::triangle3 : ElementType::tetrahedron4;
  mesh.blocks.push_back({type, std::move(connectivity), {7}});
  return mesh;
}

/// The message of check_element_validity's InputError ("" when it accepts the mesh).
std::string refusal(const Mesh& mesh) {
  try {
    check_element_validity(mesh, "test");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(ElementValidity, RightTriangleIsValidSwappedIsInvertedFlatIsDegenerate) {
  const std::vector<Eigen::Vector3d> corners = {{0, 0, 0}, {2, 0, 0}, {0, 0.5, 0}};
  EXPECT_EQ(refusal(simplex(corners, {0, 1, 2})), "");
  const std::string inverted = refusal(simplex(corners, {0, 2, 1}));
  EXPECT_NE(inverted.find("element tag 7 (triangle3 at node tags 1, 3, 2) is inverted or folded: "
                          "its Jacobian determinant is -1"),
            std::string::npos)
      << inverted;
  // height 1e-13 over a base of 1: det J = 1e-13 < 1e-12 x (longest side 1)^2
  const std::vector<Eigen::Vector3d> flat = {{0, 0, 0}, {1, 0, 0}, {0.5, 1e-13, 0}};
  const std::string degenerate = refusal(simplex(flat, {0, 1, 2}));
  EXPECT_NE(degenerate.find("is degenerate"), std::string::npos) << degenerate;
}

TEST(ElementValidity, RightTetrahedronIsValidSwappedIsInvertedFlatIsDegenerate) {
  const std::vector<Eigen::Vector3d> corners = {{0, 0, 0}, {2, 0, 0}, {0, 0.5, 0}, {0, 0, 3}};
  EXPECT_EQ(refusal(simplex(corners, {0, 1, 2, 3})), "");
  const std::string inverted = refusal(simplex(corners, {0, 2, 1, 3}));
  EXPECT_NE(inverted.find("element tag 7 (tetrahedron4 at node tags 1, 3, 2, 4) is inverted or "
                          "folded: its Jacobian determinant is -3"),
            std::string::npos)
      << inverted;
  // the unit right tetrahedron's apex lowered to 1e-13: det J = 1e-13 < 1e-12 x (sqrt 2)^3
  const std::vector<Eigen::Vector3d> flat = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1e-13}};
  const std::string degenerate = refusal(simplex(flat, {0, 1, 2, 3}));
  EXPECT_NE(degenerate.find("is degenerate"), std::string::npos) << degenerate;
}

}  // namespace
}  // namespace robin
