// Finite elements and elasticity assembly, against closed-form values: quadrature of
// monomials, shape-function identities, a stiffness computed by hand, rigid-body modes,
// consistent loads, boundary weights and normals, stress recovery and the L2 error.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "numerics/elasticity.hpp"
#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

const std::filesystem::path data_directory = ROBIN_TEST_DATA;

double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

/// Integral of x^i on [-1, 1].
double line_moment(int i) {
  return i % 2 == 1 ? 0.0 : 2.0 / (i + 1);
}

TEST(Quadrature, TriangleRulesIntegrateMonomialsExactly) {
  for (int degree = 0; degree <= 10; ++degree) {
    const std::vector<QuadraturePoint> rule = element_quadrature(ElementType::triangle3, degree);
    for (int i = 0; i <= degree; ++i) {
      for (int j = 0; i + j <= degree; ++j) {
        // Integral of x^i y^j over the reference triangle: i! j! / (i + j + 2)!.
        const double exact = factorial(i) * factorial(j) / factorial(i + j + 2);
        double sum = 0.0;
        for (const QuadraturePoint& point : rule) {
          sum += point.weight * std::pow(point.reference.x(), i) * std::pow(point.reference.y(), j);
        }
        EXPECT_NEAR(sum, exact, 1e-15) << "degree " << degree << " x^" << i << " y^" << j;
      }
    }
  }
}

TEST(Quadrature, QuadrilateralAndEdgeRulesIntegrateMonomialsExactly) {
  for (int degree = 0; degree <= 11; ++degree) {
    for (int i = 0; i <= degree; ++i) {
      double edge_sum = 0.0;
      for (const QuadraturePoint& point : edge_quadrature(degree)) {
        edge_sum += point.weight * std::pow(point.reference.x(), i);
      }
      EXPECT_NEAR(edge_sum, line_moment(i), 1e-14) << "degree " << degree << " t^" << i;
      for (int j = 0; j <= degree; ++j) {  // tensor rule: x^i y^j with i, j <= degree
        double sum = 0.0;
        for (const QuadraturePoint& point :
             element_quadrature(ElementType::quadrilateral4, degree)) {
          sum += point.weight * std::pow(point.reference.x(), i) * std::pow(point.reference.y(), j);
        }
        EXPECT_NEAR(sum, line_moment(i) * line_moment(j), 1e-14);
      }
    }
  }
}

class ShapeFunctions : public testing::TestWithParam<ElementType> {};

TEST_P(ShapeFunctions, KroneckerPartitionOfUnityAndGradients) {
  const ElementType type = GetParam();
  const std::vector<Eigen::Vector3d> nodes = reference_nodes(type);
  ShapeValues values;
  ShapeGradients gradients;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    shape_functions(type, nodes[k], values, gradients);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      EXPECT_NEAR(values(i), i == k ? 1.0 : 0.0, 1e-15);
  }
  const Eigen::Vector3d point(0.21, 0.37, 0.0);
  shape_functions(type, point, values, gradients);
  EXPECT_NEAR(values.sum(), 1.0, 1e-15);
  EXPECT_NEAR(gradients.colwise().sum().norm(), 0.0, 1e-14);
  // Central differences of the values.
  const double step = 1e-6;
  for (int direction = 0; direction < 2; ++direction) {
    ShapeValues plus, minus;
    ShapeGradients unused;
    const Eigen::Vector3d offset = step * Eigen::Vector3d::Unit(direction);
    shape_functions(type, point + offset, plus, unused);
    shape_functions(type, point - offset, minus, unused);
    EXPECT_NEAR(((plus - minus) / (2 * step) - gradients.col(direction)).norm(), 0.0, 1e-8);
  }
}

INSTANTIATE_TEST_SUITE_P(AllTypes, ShapeFunctions,
                         testing::Values(ElementType::triangle3, ElementType::triangle6,
                                         ElementType::quadrilateral4),
                         [](const testing::TestParamInfo<ElementType>& info) {
                           return to_string(info.param);
                         });

TEST(EdgeShapeFunctions, KroneckerAndDerivatives) {
  for (const FacetType type : {FacetType::line2, FacetType::line3}) {
    const std::vector<double> nodes = edge_reference_nodes(type);
    ShapeValues values, derivatives, plus, minus;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      edge_shape_functions(type, nodes[k], values, derivatives);
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        EXPECT_NEAR(values(i), i == k ? 1.0 : 0.0, 1e-15);
      }
    }
    ShapeValues unused;
    edge_shape_functions(type, 0.3, values, derivatives);
    edge_shape_functions(type, 0.3 + 1e-6, plus, unused);
    edge_shape_functions(type, 0.3 - 1e-6, minus, unused);
    EXPECT_NEAR(((plus - minus) / 2e-6 - derivatives).norm(), 0.0, 1e-8);
  }
}

/// One unit right triangle (0,0), (1,0), (0,1).
Mesh unit_triangle() {
  Mesh mesh;
  mesh.nodes = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  mesh.node_tags = {1, 2, 3};
  mesh.blocks.push_back({ElementType::triangle3, {0, 1, 2}, {}});
  mesh.boundaries["bottom"] = {FacetType::line2, {0, 1}};
  return mesh;
}

TEST(Stiffness, UnitRightTriangleWithIdentityMaterialByHand) {
  // With C = I, K = A B^T B, A = 1/2, B columns (u_x0, u_y0, u_x1, u_y1, u_x2, u_y2):
  // (-1, 0, -1), (0, -1, -1), (1, 0, 0), (0, 0, 1), (0, 0, 1), (0, 1, 0).
  const Material material =
      make_voigt_material(Eigen::Matrix3d::Identity(), PlaneModel::plane_stress, "identity");
  const Eigen::MatrixXd stiffness = assemble_stiffness(unit_triangle(), material);
  Eigen::MatrixXd expected(6, 6);
  expected << 2, 1, -1, -1, -1, 0,  //
      1, 2, 0, -1, -1, -1,          //
      -1, 0, 1, 0, 0, 0,            //
      -1, -1, 0, 1, 1, 0,           //
      -1, -1, 0, 1, 1, 0,           //
      0, -1, 0, 0, 0, 1;
  expected *= 0.5;
  EXPECT_LT((stiffness - expected).norm(), 1e-15);
}

class RectangleMeshes : public testing::TestWithParam<ElementType> {
 protected:
  Mesh mesh_ = make_rectangle_mesh(-1.0, 0.5, 2.0, 2.5, 3, 2, GetParam());
  Material material_ = make_isotropic_material(100.0, 0.25, PlaneModel::plane_strain, "m");
};

TEST_P(RectangleMeshes, StiffnessIsSymmetricWithRigidModesInItsKernel) {
  const SparseMatrix stiffness = assemble_stiffness(mesh_, material_);
  const Eigen::MatrixXd dense = stiffness;
  EXPECT_LT((dense - dense.transpose()).norm(), 1e-12 * dense.norm());
  // Translations (1, 0), (0, 1) and the rotation (-y, x) produce no force.
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(dense.rows(), 3);
  for (std::size_t i = 0; i < mesh_.node_count(); ++i) {
    modes(2 * i, 0) = 1.0;
    modes(2 * i + 1, 1) = 1.0;
    modes(2 * i, 2) = -mesh_.nodes[i].y();
    modes(2 * i + 1, 2) = mesh_.nodes[i].x();
  }
  EXPECT_LT((stiffness * modes).norm(), 1e-12 * dense.norm());
  // Positive on a non-rigid field: u = (x^2, x y).
  Eigen::VectorXd bending(dense.rows());
  for (std::size_t i = 0; i < mesh_.node_count(); ++i) {
    bending.segment<2>(2 * i) << std::pow(mesh_.nodes[i].x(), 2), mesh_.nodes[i].prod();
  }
  EXPECT_GT(bending.dot(stiffness * bending), 0.0);
}

TEST_P(RectangleMeshes, ConstantLoadsSumToTheirResultants) {
  // Body force (2, -3) on the 3 x 2 rectangle: resultant 6 (2, -3).
  const Eigen::VectorXd body = assemble_body_force(
      mesh_, [](const Eigen::Vector3d&) { return Eigen::Vector3d(2.0, -3.0, 0.0); });
  EXPECT_NEAR(body(Eigen::seq(0, Eigen::last, 2)).sum(), 12.0, 1e-12);
  EXPECT_NEAR(body(Eigen::seq(1, Eigen::last, 2)).sum(), -18.0, 1e-12);
  // Pressure 5 on the right side (length 2): t = -5 n with n = (1, 0); resultant (-10, 0).
  const Eigen::VectorXd traction = assemble_boundary_traction(
      mesh_, mesh_.boundary("right"), [](const Eigen::Vector3d&, const Eigen::Vector3d& normal) {
        return Eigen::Vector3d(-5.0 * normal);
      });
  EXPECT_NEAR(traction(Eigen::seq(0, Eigen::last, 2)).sum(), -10.0, 1e-12);
  EXPECT_NEAR(traction(Eigen::seq(1, Eigen::last, 2)).norm(), 0.0, 1e-12);
  // Boundary weights of the top side sum to its length 3.
  EXPECT_NEAR(boundary_weights(mesh_, mesh_.boundary("top")).sum(), 3.0, 1e-12);
}

TEST_P(RectangleMeshes, NormalsPointOutOfEverySide) {
  const std::map<std::string, Eigen::Vector3d> outward = {{"bottom", {0.0, -1.0, 0.0}},
                                                          {"right", {1.0, 0.0, 0.0}},
                                                          {"top", {0.0, 1.0, 0.0}},
                                                          {"left", {-1.0, 0.0, 0.0}}};
  for (const auto& [name, expected] : outward) {
    for (const Eigen::Vector3d& normal : boundary_node_normals(mesh_, mesh_.boundary(name))) {
      EXPECT_NEAR((normal - expected).norm(), 0.0, 1e-15) << name;
    }
  }
}

TEST_P(RectangleMeshes, LinearFieldGivesExactStressAndZeroError) {
  // u = (0.1 + 0.02 x - 0.01 y, -0.3 + 0.03 x + 0.04 y): strain (0.02, 0.04, 0.02).
  const auto field = [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(0.1 + 0.02 * x.x() - 0.01 * x.y(), -0.3 + 0.03 * x.x() + 0.04 * x.y(),
                           0.0);
  };
  Eigen::VectorXd displacement(2 * mesh_.node_count());
  for (std::size_t i = 0; i < mesh_.node_count(); ++i) {
    displacement.segment<2>(2 * i) = field(mesh_.nodes[i]).head<2>();
  }
  const Eigen::Vector3d exact = material_.stiffness * Eigen::Vector3d(0.02, 0.04, 0.02);
  const StressField stress = recover_stress(mesh_, material_, displacement);
  ASSERT_EQ(stress.element_stress.cols(), static_cast<Eigen::Index>(mesh_.element_count()));
  EXPECT_LT((stress.element_stress.colwise() - exact).norm(), 1e-12 * exact.norm());
  EXPECT_LT((stress.nodal_stress.colwise() - exact).norm(), 1e-12 * exact.norm());
  // Plane strain: s_zz = nu (s_xx + s_yy).
  const double s_zz = 0.25 * (exact(0) + exact(1));
  const double expected_von_mises =
      std::sqrt(0.5 * (std::pow(exact(0) - exact(1), 2) + std::pow(exact(1) - s_zz, 2) +
                       std::pow(s_zz - exact(0), 2)) +
                3 * exact(2) * exact(2));
  EXPECT_NEAR(stress.nodal_von_mises.maxCoeff(), expected_von_mises, 1e-12 * expected_von_mises);
  EXPECT_NEAR(stress.element_von_mises.minCoeff(), expected_von_mises, 1e-12 * expected_von_mises);
  EXPECT_NEAR(l2_displacement_error(mesh_, displacement, field), 0.0, 1e-14);
  // u_h = 0 against u = (x^2, 0) on [-1, 2] x [0.5, 2.5]: ||u||^2 = (2^5 + 1) / 5 * 2.
  const double error = l2_displacement_error(
      mesh_, Eigen::VectorXd::Zero(displacement.size()),
      [](const Eigen::Vector3d& x) { return Eigen::Vector3d(x.x() * x.x(), 0.0, 0.0); });
  EXPECT_NEAR(error, std::sqrt(33.0 / 5.0 * 2.0), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(AllTypes, RectangleMeshes,
                         testing::Values(ElementType::triangle3, ElementType::triangle6,
                                         ElementType::quadrilateral4),
                         [](const testing::TestParamInfo<ElementType>& info) {
                           return to_string(info.param);
                         });

TEST(Loads, LinearBodyForceOnTheUnitTriangleByHand) {
  // b = (x, 0): f_i = int N_i x with N = (1 - x - y, x, y): (1/24, 1/12, 1/24).
  const Eigen::VectorXd load = assemble_body_force(
      unit_triangle(), [](const Eigen::Vector3d& x) { return Eigen::Vector3d(x.x(), 0.0, 0.0); });
  EXPECT_NEAR(load(0), 1.0 / 24.0, 1e-15);
  EXPECT_NEAR(load(2), 1.0 / 12.0, 1e-15);
  EXPECT_NEAR(load(4), 1.0 / 24.0, 1e-15);
  EXPECT_NEAR(load(Eigen::seq(1, 5, 2)).norm(), 0.0, 1e-15);
}

TEST(Loads, QuadraticEdgeWeightsAreSimpsonWeights) {
  // line3 edges of length L: endpoint weights L / 6, midpoint 2 L / 3; line2: L / 2.
  const Mesh quadratic = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 1, 1, ElementType::triangle6);
  const Eigen::VectorXd weights = boundary_weights(quadratic, quadratic.boundary("bottom"));
  const std::vector<int> nodes = quadratic.boundary("bottom").nodes();  // x = 0, 1, 2
  ASSERT_EQ(nodes.size(), 3u);
  EXPECT_NEAR(weights(nodes[0]), 2.0 / 6.0, 1e-15);
  EXPECT_NEAR(weights(nodes[1]), 4.0 / 3.0, 1e-15);
  EXPECT_NEAR(weights(nodes[2]), 2.0 / 6.0, 1e-15);
  const Mesh linear = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 2, 1, ElementType::triangle3);
  const Eigen::VectorXd linear_weights = boundary_weights(linear, linear.boundary("bottom"));
  EXPECT_NEAR(linear_weights(0), 0.5, 1e-15);
  EXPECT_NEAR(linear_weights(1), 1.0, 1e-15);
  EXPECT_NEAR(linear_weights(2), 0.5, 1e-15);
  EXPECT_NEAR(linear_weights(3), 0.0, 1e-15);  // off the group
}

TEST(Normals, ClockwiseGmshTriangleHasOutwardNormalsOnEachSide) {
  // Domain (0,0), (0,1.5), (2,0): outward normals (-1, 0) on x = 0, (0, -1) on y = 0 and
  // (1.5, 2) / 2.5 on the hypotenuse. At the corners: the length-weighted average.
  for (const int order : {1, 2}) {
    const Mesh mesh =
        read_gmsh_mesh(data_directory / "mesh_clockwise.geo", {.element_order = order});
    const BoundaryGroup& boundary = mesh.boundary("boundary");
    const std::vector<int> nodes = boundary.nodes();
    const std::vector<Eigen::Vector3d> normals = boundary_node_normals(mesh, boundary);
    int checked = 0;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const Eigen::Vector3d& x = mesh.nodes[nodes[k]];
      Eigen::Vector3d expected;
      if (x.norm() < 1e-12 || (x - Eigen::Vector3d(0, 1.5, 0.0)).norm() < 1e-12 ||
          (x - Eigen::Vector3d(2, 0, 0.0)).norm() < 1e-12) {
        continue;
      } else if (std::abs(x.x()) < 1e-12) {
        expected = {-1.0, 0.0, 0.0};
      } else if (std::abs(x.y()) < 1e-12) {
        expected = {0.0, -1.0, 0.0};
      } else {
        expected = {0.6, 0.8, 0.0};
      }
      EXPECT_NEAR((normals[k] - expected).norm(), 0.0, 1e-12) << x.transpose();
      ++checked;
    }
    EXPECT_GT(checked, 6);
  }
}

TEST(Normals, CornerOfTwoSidesInOneGroupAveragesByLength) {
  // Group "corner": the bottom edge (0,0)-(2,0) and the right edge (2,0)-(2,1) of one
  // triangle; the shared node gets (2 (0, -1) + 1 (1, 0)) / |...| = (1, -2) / sqrt(5).
  Mesh mesh;
  mesh.nodes = {{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {2.0, 1.0, 0.0}};
  mesh.node_tags = {1, 2, 3};
  mesh.blocks.push_back({ElementType::triangle3, {0, 1, 2}, {}});
  mesh.boundaries["corner"] = {FacetType::line2, {0, 1, 1, 2}};
  const std::vector<Eigen::Vector3d> normals = boundary_node_normals(mesh, mesh.boundary("corner"));
  ASSERT_EQ(normals.size(), 3u);
  EXPECT_NEAR((normals[0] - Eigen::Vector3d(0.0, -1.0, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((normals[1] - Eigen::Vector3d(1.0, -2.0, 0.0) / std::sqrt(5.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((normals[2] - Eigen::Vector3d(1.0, 0.0, 0.0)).norm(), 0.0, 1e-15);
}

TEST(Stress, RightTriangleAndTetrahedronByHand) {
  // On the right simplex with legs a, b (, c) along the axes, du/dx = (u_1 - u_0) / a,
  // du/dy = (u_2 - u_0) / b (, du/dz = (u_3 - u_0) / c); with C = I the stress is the Voigt
  // strain (e_xx, e_yy, [e_zz, 2 e_yz, 2 e_xz,] 2 e_xy), the same at the centroid and nodes.
  Mesh plane;
  plane.nodes = {{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {0.0, 0.5, 0.0}};
  plane.blocks.push_back({ElementType::triangle3, {0, 1, 2}, {}});
  Eigen::VectorXd u(6);
  u << 0.1, -0.2, 0.5, 0.3, -0.4, 0.25;  // u_0, u_1, u_2
  const Eigen::Vector2d dudx = (u.segment<2>(2) - u.segment<2>(0)) / 2.0;
  const Eigen::Vector2d dudy = (u.segment<2>(4) - u.segment<2>(0)) / 0.5;
  const Material plane_identity =
      make_voigt_material(Eigen::Matrix3d::Identity(), PlaneModel::plane_stress, "identity");
  const StressField plane_stress = recover_stress(plane, plane_identity, u);
  const Eigen::Vector3d plane_expected(dudx(0), dudy(1), dudy(0) + dudx(1));
  EXPECT_LT((plane_stress.element_stress.col(0) - plane_expected).norm(), 1e-15);
  EXPECT_LT((plane_stress.nodal_stress.colwise() - plane_expected).norm(), 1e-15);

  Mesh solid;
  solid.dimension = 3;
  solid.nodes = {{0.0, 0.0, 0.0}, {0.5, 0.0, 0.0}, {0.0, 2.0, 0.0}, {0.0, 0.0, 4.0}};
  solid.blocks.push_back({ElementType::tetrahedron4, {0, 1, 2, 3}, {}});
  Eigen::VectorXd v(12);
  v << 0.1, -0.2, 0.3, 0.5, 0.3, -0.1, -0.4, 0.25, 0.2, 0.05, 0.15, -0.35;
  Eigen::Matrix3d gradient;  // gradient(a, c) = du_a / dx_c
  gradient.col(0) = (v.segment<3>(3) - v.segment<3>(0)) / 0.5;
  gradient.col(1) = (v.segment<3>(6) - v.segment<3>(0)) / 2.0;
  gradient.col(2) = (v.segment<3>(9) - v.segment<3>(0)) / 4.0;
  Eigen::Matrix<double, 6, 1> solid_expected;
  solid_expected << gradient(0, 0), gradient(1, 1), gradient(2, 2), gradient(1, 2) + gradient(2, 1),
      gradient(0, 2) + gradient(2, 0), gradient(0, 1) + gradient(1, 0);
  const Material solid_identity =
      make_voigt_material(Eigen::MatrixXd::Identity(6, 6), PlaneModel::plane_strain, "identity");
  const StressField solid_stress = recover_stress(solid, solid_identity, v);
  EXPECT_LT((solid_stress.element_stress.col(0) - solid_expected).norm(), 1e-15);
  EXPECT_LT((solid_stress.nodal_stress.colwise() - solid_expected).norm(), 1e-15);
}

TEST(Errors, InvertedTriangleHasNoStress) {
  Mesh mesh = unit_triangle();
  mesh.blocks[0].connectivity = {0, 2, 1};  // clockwise
  const Material material = make_isotropic_material(1.0, 0.3, PlaneModel::plane_strain, "m");
  try {
    recover_stress(mesh, material, Eigen::VectorXd::Zero(6));
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("non-positive Jacobian"), std::string::npos)
        << error.what();
  }
}

TEST(Errors, InvertedElementAndDetachedEdgeAreInputErrors) {
  Mesh mesh = unit_triangle();
  mesh.blocks[0].connectivity = {0, 2, 1};  // clockwise
  const Material material = make_isotropic_material(1.0, 0.3, PlaneModel::plane_strain, "m");
  EXPECT_THROW(assemble_stiffness(mesh, material), InputError);
  Mesh detached = unit_triangle();
  detached.nodes.push_back({5.0, 5.0, 0.0});
  detached.node_tags.push_back(4);
  detached.boundaries["far"] = {FacetType::line2, {2, 3}};
  try {
    boundary_node_normals(detached, detached.boundary("far"));
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("'far'"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace robin
