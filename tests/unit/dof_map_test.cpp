// DofMap: reduction of a 4 x 4 system checked by hand, the expand/restrict round trip, and
// the rigid-motion test on small structured meshes.

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include "numerics/dof_map.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

SparseMatrix from_dense(const Eigen::MatrixXd& dense) {
  return dense.sparseView();
}

// K = [[4, -1, 0, -1], [-1, 4, -1, 0], [0, -1, 4, -1], [-1, 0, -1, 4]] with u_1 = 2, u_3 = -1.
class SmallSystem : public testing::Test {
 protected:
  Eigen::Matrix4d dense_{{4, -1, 0, -1}, {-1, 4, -1, 0}, {0, -1, 4, -1}, {-1, 0, -1, 4}};
  SparseMatrix stiffness_ = from_dense(dense_);
  DofMap dofs_{{std::nullopt, 2.0, std::nullopt, -1.0}};
};

TEST_F(SmallSystem, IndicesAndPrescribedValues) {
  EXPECT_EQ(dofs_.total_count(), 4);
  EXPECT_EQ(dofs_.free_count(), 2);
  EXPECT_EQ(dofs_.free_index(0), 0);
  EXPECT_EQ(dofs_.free_index(1), -1);
  EXPECT_EQ(dofs_.free_index(2), 1);
  EXPECT_EQ(dofs_.free_index(3), -1);
  EXPECT_TRUE(dofs_.is_prescribed(3));
  EXPECT_FALSE(dofs_.is_prescribed(2));
  EXPECT_EQ(dofs_.prescribed_values(), Eigen::Vector4d(0.0, 2.0, 0.0, -1.0));
}

TEST_F(SmallSystem, ReducedMatrixAndLoadByHand) {
  // K_ff = rows/columns {0, 2} = [[4, 0], [0, 4]]: two stored entries.
  const SparseMatrix reduced = dofs_.reduce_matrix(stiffness_);
  EXPECT_EQ(reduced.nonZeros(), 2);
  EXPECT_EQ(Eigen::MatrixXd(reduced), Eigen::Matrix2d({{4.0, 0.0}, {0.0, 4.0}}));
  // f_f - K_fp u_p = (1 - (-1 * 2 + -1 * -1), 3 - (-1 * 2 + -1 * -1)) = (2, 4).
  const Eigen::VectorXd load = dofs_.reduce_load(stiffness_, Eigen::Vector4d(1.0, 2.0, 3.0, 4.0));
  EXPECT_EQ(load, Eigen::Vector2d(2.0, 4.0));
}

TEST_F(SmallSystem, LowerTriangleOfTheReducedMatrix) {
  // A non-symmetric K shows which triangle is taken: K_ff = rows/columns {0, 2}.
  Eigen::Matrix4d dense = dense_;
  dense(2, 0) = -0.5;
  const SparseMatrix reduced = dofs_.reduce_matrix_lower(from_dense(dense));
  EXPECT_EQ(reduced.nonZeros(), 3);
  EXPECT_EQ(Eigen::MatrixXd(reduced), Eigen::Matrix2d({{4.0, 0.0}, {-0.5, 4.0}}));
}

TEST_F(SmallSystem, PrescribedPartGivesTheSameLoadAndReactions) {
  // Every entry in row or column 1 or 3 is kept; the free-free entries (0, 0), (2, 2) are not.
  const SparseMatrix part = dofs_.prescribed_part(stiffness_);
  EXPECT_EQ(part.nonZeros(), stiffness_.nonZeros() - 2);
  const Eigen::Vector4d load(1.0, 2.0, 3.0, 4.0);
  EXPECT_EQ(dofs_.reduce_load(part, load), dofs_.reduce_load(stiffness_, load));
  const Eigen::Vector4d displacement(0.5, 2.0, 1.0, -1.0);
  const Eigen::Vector4d full = stiffness_ * displacement;
  const Eigen::Vector4d from_part = part * displacement;
  EXPECT_EQ(from_part(1), full(1));
  EXPECT_EQ(from_part(3), full(3));
}

TEST_F(SmallSystem, ExpandAndRestrictRoundTrip) {
  EXPECT_EQ(dofs_.expand(Eigen::Vector2d(0.5, 1.0)), Eigen::Vector4d(0.5, 2.0, 1.0, -1.0));
  EXPECT_EQ(dofs_.restrict(Eigen::Vector4d(10.0, 20.0, 30.0, 40.0)), Eigen::Vector2d(10.0, 30.0));
  const Eigen::Vector2d free_values(-3.5, 7.25);
  EXPECT_EQ(dofs_.restrict(dofs_.expand(free_values)), free_values);
}

TEST_F(SmallSystem, ReducedSolutionSatisfiesTheFullFreeEquations) {
  const Eigen::Vector4d load(1.0, 2.0, 3.0, 4.0);
  Eigen::SimplicialLDLT<SparseMatrix> factorization(dofs_.reduce_matrix(stiffness_));
  const Eigen::VectorXd full =
      dofs_.expand(factorization.solve(dofs_.reduce_load(stiffness_, load)));
  // Free rows 0 and 2 of K u = f; by hand u_0 = 2 / 4, u_2 = 4 / 4.
  EXPECT_NEAR((dense_ * full - load)(0), 0.0, 1e-14);
  EXPECT_NEAR((dense_ * full - load)(2), 0.0, 1e-14);
  EXPECT_NEAR(full(0), 0.5, 1e-15);
  EXPECT_NEAR(full(2), 1.0, 1e-15);
}

/// Prescribes zero x and/or y displacement on the nodes of `boundary`.
std::vector<std::optional<double>> fix_boundary(const Mesh& mesh, const std::string& boundary,
                                                bool fix_x, bool fix_y) {
  std::vector<std::optional<double>> prescribed(2 * mesh.node_count());
  for (const int node : mesh.boundary(boundary).nodes()) {
    if (fix_x) prescribed[2 * node] = 0.0;
    if (fix_y) prescribed[2 * node + 1] = 0.0;
  }
  return prescribed;
}

TEST(RigidMotions, ClampedEdgeRemovesThem) {
  for (const double scale : {1e-6, 1.0, 1e6}) {
    const Mesh mesh =
        make_rectangle_mesh(1e3, -2e3, 1e3 + 4 * scale, -2e3 + scale, 4, 2, ElementType::triangle3);
    EXPECT_TRUE(removes_rigid_motions(mesh, DofMap(fix_boundary(mesh, "left", true, true))))
        << scale;
    // Only u_y on the bottom edge: the x translation is free.
    EXPECT_FALSE(removes_rigid_motions(mesh, DofMap(fix_boundary(mesh, "bottom", false, true))))
        << scale;
  }
}

TEST(RigidMotions, OneFixedNodeLeavesTheRotation) {
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 2, 1, ElementType::quadrilateral4);
  std::vector<std::optional<double>> prescribed(2 * mesh.node_count());
  prescribed[0] = 0.0;
  prescribed[1] = 0.0;
  EXPECT_FALSE(removes_rigid_motions(mesh, DofMap(prescribed)));
  // A second node with u_y fixed, away from the first along x, stops the rotation.
  prescribed[2 * 2 + 1] = 0.0;  // node 2 is (2, 0)
  EXPECT_TRUE(removes_rigid_motions(mesh, DofMap(prescribed)));
  // Nothing prescribed.
  EXPECT_FALSE(removes_rigid_motions(
      mesh, DofMap(std::vector<std::optional<double>>(2 * mesh.node_count()))));
}

TEST(RigidMotions, SymmetrySupportsRemoveThem) {
  // u_x = 0 on the left edge and u_y = 0 on the bottom edge.
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 3.0, 1.0, 3, 2, ElementType::triangle6);
  std::vector<std::optional<double>> prescribed = fix_boundary(mesh, "left", true, false);
  for (const int node : mesh.boundary("bottom").nodes()) prescribed[2 * node + 1] = 0.0;
  EXPECT_TRUE(removes_rigid_motions(mesh, DofMap(prescribed)));
}

}  // namespace
}  // namespace robin
