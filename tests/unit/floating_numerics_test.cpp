// The numerics of floating bodies, each against an independent computation:
//  - rigid_body_modes: the kernel of the assembled reduced stiffness (K R = 0), orthonormal, of
//    the dimension the supports leave (3, 1, 0) and the expected direction;
//  - GeneralizedInverse: K K^+ K = K with dense Eigen products, and K^dagger b against Eigen's
//    dense complete orthogonal decomposition (the Moore-Penrose solution);
//  - SMALBE-M against the KKT point found by enumerating every active set of a tiny QP with
//    dense Eigen solves;
//  - nonnegative least squares against answers worked out by hand.

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/generalized_inverse.hpp"
#include "numerics/material.hpp"
#include "numerics/nonnegative_least_squares.hpp"
#include "numerics/rectangle_mesher.hpp"
#include "numerics/smalbe.hpp"

namespace robin {
namespace {

std::vector<std::optional<double>> fix_boundary(const Mesh& mesh, const std::string& boundary,
                                                bool fix_x, bool fix_y,
                                                std::vector<std::optional<double>> prescribed) {
  for (const int node : mesh.boundary(boundary).nodes()) {
    if (fix_x) prescribed[2 * node] = 0.0;
    if (fix_y) prescribed[2 * node + 1] = 0.0;
  }
  return prescribed;
}

struct Body {
  Mesh mesh;
  DofMap dofs;
  SparseMatrix stiffness;  // reduced
  Eigen::MatrixXd kernel;
};

Body make_body(const std::vector<std::pair<std::string, std::pair<bool, bool>>>& supports) {
  Mesh mesh = make_rectangle_mesh(1.0, 2.0, 3.0, 2.5, 6, 3, ElementType::quadrilateral4);
  std::vector<std::optional<double>> prescribed(2 * mesh.node_count());
  for (const auto& [boundary, fixed] : supports) {
    prescribed = fix_boundary(mesh, boundary, fixed.first, fixed.second, prescribed);
  }
  DofMap dofs(prescribed);
  const Material material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "b");
  SparseMatrix stiffness = dofs.reduce_matrix(assemble_stiffness(mesh, material));
  Eigen::MatrixXd kernel = rigid_body_modes(mesh, dofs);
  return {std::move(mesh), std::move(dofs), std::move(stiffness), std::move(kernel)};
}

void expect_kernel(const Body& body, int dimension) {
  ASSERT_EQ(body.kernel.cols(), dimension);
  ASSERT_EQ(body.kernel.rows(), body.dofs.free_count());
  const Eigen::MatrixXd gram = body.kernel.transpose() * body.kernel;
  EXPECT_LE((gram - Eigen::MatrixXd::Identity(dimension, dimension)).norm(), 1e-13);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(body.stiffness);
  EXPECT_LE((dense * body.kernel).norm(), 1e-11 * dense.norm());
}

TEST(RigidBodyModes, NoSupportLeavesAllThree) {
  expect_kernel(make_body({}), 3);
}

TEST(RigidBodyModes, LateralSupportsLeaveTheVerticalTranslation) {
  const Body body = make_body({{"left", {true, false}}, {"right", {true, false}}});
  expect_kernel(body, 1);
  // (0, 1) on every node: zero on the x dofs, the same value on every y dof
  const double value = 1.0 / std::sqrt(static_cast<double>(body.mesh.node_count()));
  for (int dof = 0; dof < body.dofs.total_count(); ++dof) {
    if (body.dofs.is_prescribed(dof)) continue;
    const double entry = body.kernel(body.dofs.free_index(dof), 0);
    EXPECT_NEAR(std::abs(entry), dof % 2 == 0 ? 0.0 : value, 1e-14) << dof;
  }
}

TEST(RigidBodyModes, RollerSupportLeavesTheHorizontalTranslation) {
  const Body body = make_body({{"bottom", {false, true}}});
  expect_kernel(body, 1);
  for (int dof = 1; dof < body.dofs.total_count(); dof += 2) {
    if (!body.dofs.is_prescribed(dof)) {
      EXPECT_NEAR(body.kernel(body.dofs.free_index(dof), 0), 0.0, 1e-14);
    }
  }
}

TEST(RigidBodyModes, ClampedEdgeLeavesNone) {
  EXPECT_EQ(make_body({{"left", {true, true}}}).kernel.cols(), 0);
}

TEST(GeneralizedInverse, IsAGeneralizedInverseAndGivesTheMoorePenroseSolution) {
  for (const auto& supports :
       std::vector<std::vector<std::pair<std::string, std::pair<bool, bool>>>>{
           {}, {{"left", {true, false}}, {"right", {true, false}}}, {{"bottom", {false, true}}}}) {
    const Body body = make_body(supports);
    const GeneralizedInverse inverse(body.stiffness, body.kernel, "b");
    ASSERT_EQ(inverse.rigid_mode_count(), body.kernel.cols());
    EXPECT_EQ(static_cast<Eigen::Index>(inverse.fixing_dofs().size()), body.kernel.cols());
    const Eigen::MatrixXd dense = Eigen::MatrixXd(body.stiffness);
    const Eigen::Index size = dense.rows();
    const Eigen::MatrixXd pseudo =
        inverse.solve(Eigen::MatrixXd(Eigen::MatrixXd::Identity(size, size)));
    // K K^+ K = K
    EXPECT_LE((dense * pseudo * dense - dense).norm(), 1e-10 * dense.norm());
    // K^dagger b: Eigen's minimum-norm least-squares solution
    Eigen::VectorXd load(size);
    for (Eigen::Index i = 0; i < size; ++i) load[i] = std::sin(0.7 * static_cast<double>(i) + 0.3);
    const Eigen::VectorXd expected = dense.completeOrthogonalDecomposition().solve(load);
    const Eigen::VectorXd solution = inverse.solve_minimum_norm(load);
    EXPECT_LE((solution - expected).norm(), 1e-9 * expected.norm());
  }
}

TEST(GeneralizedInverse, WithoutKernelIsTheCholeskyFactor) {
  const Body body = make_body({{"left", {true, true}}});
  const GeneralizedInverse inverse(body.stiffness, body.kernel, "b");
  const CholeskyFactor factor(body.stiffness, "b");
  const Eigen::VectorXd load = Eigen::VectorXd::LinSpaced(body.stiffness.rows(), -1.0, 2.0);
  EXPECT_EQ(inverse.solve(load), factor.solve(load));  // bit for bit
  EXPECT_EQ(inverse.solve_minimum_norm(load), factor.solve(load));
}

/// The KKT point of min 1/2 x'Ax - b'x s.t. x >= 0, C x = d by enumerating the active sets:
/// for each, the dense KKT system [A_FF C_F'; C_F 0] (x_F; mu) = (b_F; d) with x_A = 0, kept
/// when x_F >= 0 and (A x - b + C'mu)_A >= 0.
std::pair<Eigen::VectorXd, Eigen::VectorXd> enumerate_kkt(const Eigen::MatrixXd& a,
                                                          const Eigen::VectorXd& b,
                                                          const Eigen::MatrixXd& c,
                                                          const Eigen::VectorXd& d) {
  const int n = static_cast<int>(a.rows());
  const int m = static_cast<int>(c.rows());
  for (int mask = 0; mask < (1 << n); ++mask) {
    std::vector<int> free;
    for (int i = 0; i < n; ++i) {
      if ((mask >> i) & 1) free.push_back(i);
    }
    const int f = static_cast<int>(free.size());
    Eigen::MatrixXd system = Eigen::MatrixXd::Zero(f + m, f + m);
    Eigen::VectorXd right(f + m);
    for (int i = 0; i < f; ++i) {
      for (int j = 0; j < f; ++j) system(i, j) = a(free[i], free[j]);
      for (int k = 0; k < m; ++k) system(i, f + k) = system(f + k, i) = c(k, free[i]);
      right[i] = b[free[i]];
    }
    right.tail(m) = d;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(system);
    if (!lu.isInvertible()) continue;
    const Eigen::VectorXd unknowns = lu.solve(right);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < f; ++i) x[free[i]] = unknowns[i];
    const Eigen::VectorXd mu = unknowns.tail(m);
    const Eigen::VectorXd gradient = a * x - b + c.transpose() * mu;
    bool ok = (x.array() >= -1e-12).all();
    for (int i = 0; i < n && ok; ++i) {
      if (!((mask >> i) & 1) && gradient[i] < -1e-12) ok = false;
    }
    if (ok) return {x, mu};
  }
  ADD_FAILURE() << "no KKT point";
  return {};
}

TEST(Smalbe, EqualsTheEnumeratedKktPointOfATinyQp) {
  // A = M M' of rank 5 (semi-definite, like a floating body's F), C two rows.
  const int n = 7;
  Eigen::MatrixXd factor(n, 5);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < 5; ++j) factor(i, j) = std::cos(1.3 * i + 0.7 * j * j + 0.2);
  }
  const Eigen::MatrixXd a = factor * factor.transpose();
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = std::sin(2.1 * i + 0.4);
  Eigen::MatrixXd c(2, n);
  for (int i = 0; i < n; ++i) {
    c(0, i) = -1.0 - 0.1 * i;           // like a vertical translation: all rows see it
    c(1, i) = std::cos(0.9 * i) - 0.3;  // like a rotation: rows on both sides
  }
  const Eigen::Vector2d d(-3.0, 0.2);
  const auto [expected_x, expected_mu] = enumerate_kkt(a, b, c, d);
  ASSERT_GT((expected_x.array() == 0.0).count(), 0);  // some bounds active
  ASSERT_GT((expected_x.array() > 0.0).count(), 2);   // and some free
  const DenseOperator matrix(a);
  const SmalbeResult result = solve_smalbe(matrix, b, Eigen::VectorXd::Zero(n), c, d,
                                           Eigen::VectorXd::Zero(n), Eigen::VectorXd());
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  std::printf("SMALBE: %d outer, %d inner iterations\n", result.outer_iterations,
              result.iterations);
  EXPECT_LE((result.solution - expected_x).norm(), 1e-9 * expected_x.norm());
  EXPECT_LE((result.multiplier - expected_mu).norm(), 1e-8 * expected_mu.norm());
  EXPECT_LE(
      (result.gradient - (a * result.solution - b + c.transpose() * result.multiplier)).norm(),
      1e-10 * b.norm());
  EXPECT_LE(result.equality_residual, 1e-10 * d.norm());
}

TEST(NonnegativeLeastSquares, AnswersWorkedOutByHand) {
  // h in the cone of the columns: exact, residual 0
  Eigen::MatrixXd g(2, 3);
  g << 1.0, 0.0, 1.0, 0.0, 1.0, 1.0;
  const NonnegativeLeastSquaresResult inside =
      solve_nonnegative_least_squares(g, Eigen::Vector2d(2.0, 3.0));
  EXPECT_LE(inside.residual_norm, 1e-14);
  EXPECT_TRUE((inside.solution.array() >= 0.0).all());
  // (1, -2): the best lambda >= 0 is (1, 0, 0), residual 2
  const NonnegativeLeastSquaresResult outside =
      solve_nonnegative_least_squares(g, Eigen::Vector2d(1.0, -2.0));
  EXPECT_NEAR(outside.residual_norm, 2.0, 1e-14);
  EXPECT_NEAR(outside.solution[0], 1.0, 1e-14);
  // one row of positive entries and a negative target: lambda = 0, residual |h|
  Eigen::MatrixXd row(1, 4);
  row << 1.0, 2.0, 0.5, 3.0;
  EXPECT_NEAR(
      solve_nonnegative_least_squares(row, Eigen::VectorXd::Constant(1, -1.5)).residual_norm, 1.5,
      1e-15);
}

}  // namespace
}  // namespace robin
