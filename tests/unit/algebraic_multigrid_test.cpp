// Smoothed-aggregation AMG as the preconditioner of conjugate gradients on clamped elastic
// bodies: the PCG solution against CHOLMOD's (an independent direct solve), iteration counts
// under mesh refinement, on a graded mesh (distance-Laplacian against block-norm strength) and
// against plain CG, and the symmetry and positivity of the V-cycle.

#include "numerics/algebraic_multigrid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "numerics/box_mesher.hpp"
#include "numerics/cholesky.hpp"
#include "numerics/conjugate_gradient.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

/// The free-free stiffness (lower triangle) of `mesh` with every dof of boundary `clamped`
/// prescribed (zero), the AMG's near-null space, dof nodes and node positions (empty: the
/// block-norm strength of connection), and a load.
struct ClampedBody {
  SparseMatrix lower;
  Eigen::MatrixXd near_null_space;
  std::vector<int> dof_nodes;
  std::vector<Eigen::Vector3d> positions;
  Eigen::VectorXd load;
};

/// `components` (a subset of 0 .. d-1) of every node on `clamped` are prescribed.
ClampedBody clamp(const Mesh& mesh, const Material& material, const std::string& clamped,
                  const std::vector<int>& components) {
  std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
  for (int node : mesh.boundary(clamped).nodes()) {
    for (int component : components) prescribed[mesh.dimension * node + component] = 0.0;
  }
  const DofMap dofs(prescribed);
  ClampedBody body;
  body.lower = dofs.reduce_matrix_lower(assemble_stiffness(mesh, material));
  body.near_null_space = free_rigid_body_modes(mesh, dofs);
  body.dof_nodes = free_dof_nodes(mesh, dofs);
  body.positions = mesh.nodes;
  // a smooth body force plus a random part, so that every mode of the error is excited
  std::mt19937 generator(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Eigen::VectorXd full = assemble_body_force(mesh, [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(1.0 + x.y(), -2.0 + x.z(), 0.5 - x.x());
  });
  body.load = dofs.restrict(full);
  for (Eigen::Index k = 0; k < body.load.size(); ++k) {
    body.load[k] += 0.1 * body.load.cwiseAbs().maxCoeff() * uniform(generator);
  }
  return body;
}

ClampedBody clamped_box(const Eigen::Vector3d& high, const Eigen::Vector3i& cells,
                        ElementType type) {
  const Mesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), high, cells, type);
  return clamp(mesh, make_isotropic_solid_material(210.0, 0.3, "test"), "left", {0, 1, 2});
}

/// The tests' hierarchy coarsens down to a few dozen unknowns, so that even the small meshes
/// get several levels (the default limit would solve most of them directly).
AlgebraicMultigridOptions test_options() {
  AlgebraicMultigridOptions options;
  options.coarse_size_limit = 64;
  return options;
}

struct PcgRun {
  ConjugateGradientResult result;
  Eigen::VectorXd solution;
};

PcgRun solve_with_multigrid(const ClampedBody& body,
                            const AlgebraicMultigridOptions& options = test_options(),
                            double tolerance = 1e-10) {
  const AlgebraicMultigrid multigrid(body.lower, body.near_null_space, body.dof_nodes,
                                     body.positions, options);
  PcgRun run;
  ConjugateGradientOptions parameters;
  parameters.relative_tolerance = tolerance;
  parameters.maximum_iterations = 500;
  run.result = solve_conjugate_gradient(multigrid.fine_operator(), multigrid, body.load,
                                        run.solution, parameters);
  std::cout << "  " << body.lower.rows() << " unknowns, " << multigrid.levels().size()
            << " levels (coarsest " << multigrid.levels().back().unknowns
            << "), operator complexity " << multigrid.operator_complexity() << ", "
            << run.result.iterations << " iterations, relative residual "
            << run.result.relative_residual << "\n";
  return run;
}

/// PCG + AMG to 1e-10 against CHOLMOD: relative difference of the solutions.
double difference_from_cholmod(const ClampedBody& body, const PcgRun& run) {
  const CholeskyFactor factor(body.lower, "body");
  const Eigen::VectorXd direct = factor.solve(body.load);
  return (run.solution - direct).norm() / direct.norm();
}

void expect_matches_cholmod(const ClampedBody& body,
                            const AlgebraicMultigridOptions& options = test_options()) {
  const PcgRun run = solve_with_multigrid(body, options);
  EXPECT_EQ(run.result.status, ConjugateGradientStatus::converged);
  // the residual independently of the solver's report
  const SparseMatrixOperator matrix(body.lower);
  Eigen::VectorXd product;
  matrix.apply(run.solution, product);
  EXPECT_LE((body.load - product).norm(), 1e-10 * body.load.norm());
  const double difference = difference_from_cholmod(body, run);
  std::cout << "  relative difference from CHOLMOD " << difference << "\n";
  EXPECT_LE(difference, 1e-8);
}

TEST(AlgebraicMultigrid, HexahedralCubeMatchesCholmod) {
  expect_matches_cholmod(clamped_box({1.0, 1.0, 1.0}, {8, 8, 8}, ElementType::hexahedron8));
}

TEST(AlgebraicMultigrid, StretchedHexahedralBoxMatchesCholmod) {
  expect_matches_cholmod(clamped_box({4.0, 1.0, 1.0}, {16, 4, 4}, ElementType::hexahedron8));
}

TEST(AlgebraicMultigrid, QuadraticChebyshevSmootherMatchesCholmod) {
  AlgebraicMultigridOptions options = test_options();
  options.smoother_degree = 2;
  expect_matches_cholmod(clamped_box({4.0, 1.0, 1.0}, {16, 4, 4}, ElementType::hexahedron8),
                         options);
}

TEST(AlgebraicMultigrid, GaussSeidelSmootherMatchesCholmod) {
  AlgebraicMultigridOptions options = test_options();
  options.smoother = MultigridSmoother::symmetric_gauss_seidel;
  expect_matches_cholmod(clamped_box({4.0, 1.0, 1.0}, {16, 4, 4}, ElementType::hexahedron8),
                         options);
}

TEST(AlgebraicMultigrid, LinearTetrahedraMatchCholmod) {
  expect_matches_cholmod(clamped_box({1.0, 1.0, 1.0}, {8, 8, 8}, ElementType::tetrahedron4));
}

TEST(AlgebraicMultigrid, QuadraticTetrahedraMatchCholmod) {
  expect_matches_cholmod(clamped_box({4.0, 1.0, 1.0}, {16, 4, 4}, ElementType::tetrahedron10));
}

TEST(AlgebraicMultigrid, PlaneStrainRectangleMatchesCholmod) {
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 3.0, 1.0, 96, 32, ElementType::quadrilateral4);
  const Material material = make_isotropic_material(70.0, 0.3, PlaneModel::plane_strain, "test");
  expect_matches_cholmod(clamp(mesh, material, "left", {0, 1}));
}

/// Nodes with some of their dofs prescribed: x and z on the left face, y on the bottom face (no
/// rigid motion left). Such nodes have fewer free unknowns, and so have their aggregates.
TEST(AlgebraicMultigrid, PartlyPrescribedNodesMatchCholmod) {
  const Mesh mesh =
      make_box_mesh(Eigen::Vector3d::Zero(), {2.0, 1.0, 1.0}, {12, 6, 6}, ElementType::hexahedron8);
  const Material material = make_isotropic_solid_material(210.0, 0.3, "test");
  ClampedBody body;
  std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
  for (int node : mesh.boundary("left").nodes()) {
    prescribed[3 * node] = prescribed[3 * node + 2] = 0.0;
  }
  for (int node : mesh.boundary("bottom").nodes()) prescribed[3 * node + 1] = 0.0;
  const DofMap dofs(prescribed);
  ASSERT_TRUE(removes_rigid_motions(mesh, dofs));
  body.lower = dofs.reduce_matrix_lower(assemble_stiffness(mesh, material));
  body.near_null_space = free_rigid_body_modes(mesh, dofs);
  body.dof_nodes = free_dof_nodes(mesh, dofs);
  body.positions = mesh.nodes;
  body.load = Eigen::VectorXd::LinSpaced(dofs.free_count(), -1.0, 1.0);
  expect_matches_cholmod(body);
}

TEST(AlgebraicMultigrid, BlockNormStrengthWithoutPositionsMatchesCholmod) {
  ClampedBody body = clamped_box({4.0, 1.0, 1.0}, {16, 4, 4}, ElementType::hexahedron8);
  body.positions.clear();
  expect_matches_cholmod(body);
}

/// A cube of 12^3 hexahedra graded towards the corner x = y = z = 0: along each axis the cells
/// grow geometrically, the last 8 times the first, so cells far along one axis and near the
/// origin along another have aspect ratios up to 8 (the grading of
/// benchmarks/meshes/solid_scale_block.geo); clamped on its bottom face z = 0.
TEST(AlgebraicMultigrid, DistanceStrengthOnAGradedMeshMatchesCholmodInFewerIterations) {
  const int cells = 12;
  Mesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), {1.0, 1.0, 1.0}, {cells, cells, cells},
                            ElementType::hexahedron8);
  const double ratio = std::pow(8.0, 1.0 / (cells - 1));  // of neighbouring cells
  const auto graded = [&](double coordinate) {            // maps k / cells to the graded node k
    const double k = std::round(coordinate * cells);
    return (std::pow(ratio, k) - 1.0) / (std::pow(ratio, cells) - 1.0);
  };
  for (Eigen::Vector3d& node : mesh.nodes) node = node.unaryExpr(graded);
  ClampedBody body =
      clamp(mesh, make_isotropic_solid_material(210.0, 0.3, "test"), "bottom", {0, 1, 2});
  AlgebraicMultigridOptions options = test_options();
  options.coarse_size_limit = 200;
  expect_matches_cholmod(body, options);
  const PcgRun distance = solve_with_multigrid(body, options, 1e-12);
  body.positions.clear();
  const PcgRun block_norm = solve_with_multigrid(body, options, 1e-12);
  ASSERT_EQ(distance.result.status, ConjugateGradientStatus::converged);
  ASSERT_EQ(block_norm.result.status, ConjugateGradientStatus::converged);
  EXPECT_LT(distance.result.iterations, block_norm.result.iterations);
}

/// Iterations on the cube at 8^3 and 16^3 cells (8 times the unknowns, h halved).
TEST(AlgebraicMultigrid, IterationCountStaysBoundedUnderRefinement) {
  const PcgRun coarse =
      solve_with_multigrid(clamped_box({1.0, 1.0, 1.0}, {8, 8, 8}, ElementType::hexahedron8));
  const PcgRun fine =
      solve_with_multigrid(clamped_box({1.0, 1.0, 1.0}, {16, 16, 16}, ElementType::hexahedron8));
  ASSERT_EQ(coarse.result.status, ConjugateGradientStatus::converged);
  ASSERT_EQ(fine.result.status, ConjugateGradientStatus::converged);
  EXPECT_LE(fine.result.iterations, 1.6 * coarse.result.iterations);
}

TEST(AlgebraicMultigrid, PlainConjugateGradientsNeedManyMoreIterations) {
  const ClampedBody body = clamped_box({1.0, 1.0, 1.0}, {16, 16, 16}, ElementType::hexahedron8);
  const PcgRun preconditioned = solve_with_multigrid(body, test_options(), 1e-8);
  const SparseMatrixOperator matrix(body.lower);
  ConjugateGradientOptions parameters;
  parameters.relative_tolerance = 1e-8;
  parameters.maximum_iterations = 20000;
  Eigen::VectorXd solution;
  const ConjugateGradientResult plain = solve_conjugate_gradient(
      matrix, IdentityPreconditioner(matrix.size()), body.load, solution, parameters);
  std::cout << "  plain CG " << plain.iterations << " iterations, AMG "
            << preconditioned.result.iterations << "\n";
  ASSERT_EQ(plain.status, ConjugateGradientStatus::converged);
  // measured: more than 10 times as many (the ratio grows as the mesh is refined)
  EXPECT_GE(plain.iterations, 5 * preconditioned.result.iterations);
}

/// x'M^{-1}y = y'M^{-1}x and x'M^{-1}x > 0 for random x, y.
void expect_symmetric_positive(const ClampedBody& body, const AlgebraicMultigridOptions& options) {
  const AlgebraicMultigrid multigrid(body.lower, body.near_null_space, body.dof_nodes,
                                     body.positions, options);
  std::mt19937 generator(99);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd x =
        Eigen::VectorXd::NullaryExpr(multigrid.size(), [&] { return normal(generator); });
    const Eigen::VectorXd y =
        Eigen::VectorXd::NullaryExpr(multigrid.size(), [&] { return normal(generator); });
    Eigen::VectorXd applied_x, applied_y;
    multigrid.apply(x, applied_x);
    multigrid.apply(y, applied_y);
    const double forward = x.dot(applied_y), backward = y.dot(applied_x);
    // relative to the Cauchy-Schwarz bound of both products in the M^{-1} inner product
    const double scale = std::sqrt(x.dot(applied_x) * y.dot(applied_y));
    EXPECT_LE(std::abs(forward - backward), 1e-12 * scale) << forward << " vs " << backward;
    EXPECT_GT(x.dot(applied_x), 0.0);
    EXPECT_GT(y.dot(applied_y), 0.0);
  }
}

TEST(AlgebraicMultigrid, VCycleIsSymmetricPositiveDefinite) {
  const ClampedBody body = clamped_box({2.0, 1.0, 1.0}, {12, 6, 6}, ElementType::hexahedron8);
  expect_symmetric_positive(body, test_options());
  AlgebraicMultigridOptions cubic = test_options();
  cubic.smoother_degree = 3;
  expect_symmetric_positive(body, cubic);
  AlgebraicMultigridOptions gauss_seidel = test_options();
  gauss_seidel.smoother = MultigridSmoother::symmetric_gauss_seidel;
  expect_symmetric_positive(body, gauss_seidel);
}

TEST(AlgebraicMultigrid, InconsistentInputIsRefused) {
  const ClampedBody body = clamped_box({1.0, 1.0, 1.0}, {3, 3, 3}, ElementType::hexahedron8);
  const Eigen::MatrixXd short_modes = body.near_null_space.topRows(body.lower.rows() - 1);
  EXPECT_THROW(AlgebraicMultigrid(body.lower, short_modes, body.dof_nodes), std::invalid_argument);
  std::vector<int> nodes = body.dof_nodes;
  nodes.pop_back();
  EXPECT_THROW(AlgebraicMultigrid(body.lower, body.near_null_space, nodes), std::invalid_argument);
  nodes = body.dof_nodes;
  nodes[0] = -1;
  EXPECT_THROW(AlgebraicMultigrid(body.lower, body.near_null_space, nodes), std::invalid_argument);
  std::vector<Eigen::Vector3d> positions(body.positions.begin(), body.positions.end() - 1);
  EXPECT_THROW(AlgebraicMultigrid(body.lower, body.near_null_space, body.dof_nodes, positions),
               std::invalid_argument);
  const AlgebraicMultigrid multigrid(body.lower, body.near_null_space, body.dof_nodes);
  Eigen::VectorXd correction;
  EXPECT_THROW(multigrid.apply(Eigen::VectorXd::Ones(3), correction), std::invalid_argument);
}

TEST(ConjugateGradient, InitialGuessAndZeroLoad) {
  const ClampedBody body = clamped_box({1.0, 1.0, 1.0}, {4, 4, 4}, ElementType::hexahedron8);
  const SparseMatrixOperator matrix(body.lower);
  const IdentityPreconditioner identity(matrix.size());
  Eigen::VectorXd solution;
  const ConjugateGradientResult first =
      solve_conjugate_gradient(matrix, identity, body.load, solution);
  ASSERT_EQ(first.status, ConjugateGradientStatus::converged);
  // the solution as initial guess: converged without an iteration
  const ConjugateGradientResult again =
      solve_conjugate_gradient(matrix, identity, body.load, solution);
  EXPECT_EQ(again.status, ConjugateGradientStatus::converged);
  EXPECT_EQ(again.iterations, 0);
  Eigen::VectorXd zero = Eigen::VectorXd::Ones(matrix.size());
  const ConjugateGradientResult none =
      solve_conjugate_gradient(matrix, identity, Eigen::VectorXd::Zero(matrix.size()), zero);
  EXPECT_EQ(none.status, ConjugateGradientStatus::converged);
  EXPECT_EQ(zero.norm(), 0.0);
}

TEST(ConjugateGradient, IterationLimitAndIndefiniteMatrix) {
  const ClampedBody body = clamped_box({1.0, 1.0, 1.0}, {4, 4, 4}, ElementType::hexahedron8);
  const SparseMatrixOperator matrix(body.lower);
  const IdentityPreconditioner identity(matrix.size());
  Eigen::VectorXd solution;
  ConjugateGradientOptions parameters;
  parameters.maximum_iterations = 3;
  const ConjugateGradientResult limited =
      solve_conjugate_gradient(matrix, identity, body.load, solution, parameters);
  EXPECT_EQ(limited.status, ConjugateGradientStatus::iteration_limit);
  EXPECT_EQ(limited.iterations, 3);
  // -K: (p, A p) < 0 at the first step
  const SparseMatrixOperator negative(SparseMatrix(-body.lower));
  Eigen::VectorXd other;
  EXPECT_EQ(solve_conjugate_gradient(negative, identity, body.load, other).status,
            ConjugateGradientStatus::breakdown);
}

}  // namespace
}  // namespace robin
