// Mortar contact of solid (three-dimensional) bodies against numbers from outside the code:
//  - matching meshes (the same structured box mesh on both sides, 0.01 apart): the mortar rows
//    are the node-to-node rows (pair_contact_nodes), for 8-node hexahedra and 4-node tetrahedra:
//    the same operator entries, weights and gap 0.01; for 10-node tetrahedra (triangle6 faces)
//    the rows of Popp et al.'s transformed basis with alpha = 1/5: a corner's row is the corner
//    alone with weight sum 2S/15 over its faces, a mid-edge node's row is (5/3) u_m - (1/3)(u_c +
//    u_c') with weight sum S/5, on both sides;
//  - partial coverage: a non-mortar face larger than the mortar one; each node's covered integral
//    (the product of its hat functions' 1D integrals over the overlap) is its weight, the two
//    fully covered nodes keep the node-alone dual rows, every row's coefficients sum to 1 and -1,
//    and a linear field continuous across the interface closes every row;
//  - the contact patch test: two blocks with non-matching meshes (tetrahedra against
//    hexahedra), the lower one fixed at its bottom, the upper one pushed down by delta at its top,
//    lateral symmetry supports (u_x = 0 on x = const, u_y = 0 on y = const): uniform uniaxial
//    strain, whose pressure from Hooke's law is p = delta / (H1 / M1 + H2 / M2) with M = E (1 -
//    nu) / ((1 + nu) (1 - 2 nu)) the P-wave modulus of each block. Every row's lambda_j / m_j
//    equals p to 1e-10 relative in the monolithic solution, with either side as the non-mortar
//    side, for 4- and 10-node tetrahedra; the Robin iteration on in-process ports (4-node
//    tetrahedra) converges to the monolithic contact forces (1e-8 relative) and to p (1e-8).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <utility>

#include "coupling/case_file.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/mortar_coupling.hpp"
#include "coupling/robin_iteration.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/errors.hpp"
#include "numerics/material.hpp"
#include "pressure_error.hpp"

namespace robin {
namespace {

/// One block [0, 1] x [0, 1] x [bottom, top] of a contact test (or [low, high] in x and y).
struct Block {
  double bottom = 0.0, top = 1.0;
  Eigen::Vector3i cells{1, 1, 1};
  ElementType type = ElementType::hexahedron8;
  double young = 1.0, poisson = 0.3;
  Eigen::Vector2d low{0.0, 0.0}, high{1.0, 1.0};
};

/// The block as a body: lateral symmetry supports (u_x = 0 on left and right, u_y = 0 on front
/// and back), u_z = `bottom_z` on its bottom and/or `top_z` on its top when given, contact on
/// `contact` ("top" or "bottom").
BodyDefinition block_body(const std::string& name, const Block& block, const std::string& contact,
                          std::optional<double> bottom_z, std::optional<double> top_z) {
  BodyDefinition body;
  body.name = name;
  body.mesh = make_box_mesh({block.low.x(), block.low.y(), block.bottom},
                            {block.high.x(), block.high.y(), block.top}, block.cells, block.type);
  body.material = make_isotropic_solid_material(block.young, block.poisson, name);
  body.dirichlet = {{"left", 0.0, std::nullopt, std::nullopt},
                    {"right", 0.0, std::nullopt, std::nullopt},
                    {"front", std::nullopt, 0.0, std::nullopt},
                    {"back", std::nullopt, 0.0, std::nullopt}};
  if (bottom_z) body.dirichlet.push_back({"bottom", std::nullopt, std::nullopt, bottom_z});
  if (top_z) body.dirichlet.push_back({"top", std::nullopt, std::nullopt, top_z});
  body.contact_boundaries = {contact};
  return body;
}

using RowEntries = std::map<std::pair<int, int>, double>;  // (node, component) -> coefficient

RowEntries row_entries(const ContactOperator& contact, std::size_t row) {
  RowEntries entries;
  for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
    entries[{contact.nodes[k], contact.components[k]}] += contact.values[k];
  }
  return entries;
}

/// Largest |a - b| over the union of both rows' entries (a missing entry is zero).
double row_difference(const RowEntries& first, const RowEntries& second) {
  double difference = 0.0;
  for (const auto& [key, value] : first) {
    const auto other = second.find(key);
    difference =
        std::max(difference, std::abs(value - (other == second.end() ? 0.0 : other->second)));
  }
  for (const auto& [key, value] : second) {
    if (first.find(key) == first.end()) difference = std::max(difference, std::abs(value));
  }
  return difference;
}

/// The row of `pairing` whose constraint sits at `position` (SIZE_MAX when none).
std::size_t row_at(const ContactPairing& pairing, const Eigen::Vector3d& position) {
  for (std::size_t j = 0; j < pairing.size(); ++j) {
    if ((pairing.pairs[j].position - position).norm() < 1e-12) return j;
  }
  return static_cast<std::size_t>(-1);
}

/// Two copies of the same box mesh, the upper one 0.01 above the lower one.
struct MatchingBlocks {
  explicit MatchingBlocks(ElementType type)
      : lower(block_body("lower", {0.0, 0.5, {3, 2, 2}, type, 1.0, 0.3}, "top", 0.0, std::nullopt)),
        upper(block_body("upper", {0.51, 1.01, {3, 2, 2}, type, 1.0, 0.3}, "bottom", std::nullopt,
                         0.0)) {}
  BodySolver lower, upper;
};

class MatchingLinearMeshes : public ::testing::TestWithParam<ElementType> {};

TEST_P(MatchingLinearMeshes, GiveTheNodeToNodeRows) {
  const MatchingBlocks blocks(GetParam());
  const InterfaceDescription lower = blocks.lower.contact_boundary();
  const InterfaceDescription upper = blocks.upper.contact_boundary();
  const ContactPairing nodes = pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
  const ContactPairing mortar = build_mortar_coupling(lower, "lower", upper, "upper", nullptr, {});
  ASSERT_EQ(mortar.non_mortar_body, 0);  // a tie: body 0
  EXPECT_EQ(mortar.dimension, 3);
  EXPECT_EQ(mortar.uncovered, 0);
  ASSERT_EQ(mortar.size(), nodes.size());
  ASSERT_EQ(mortar.size(), 12u);  // the 4 x 3 nodes of the top face
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    const std::size_t row = row_at(mortar, nodes.pairs[j].position);
    ASSERT_LT(row, mortar.size()) << "node " << nodes.pairs[j].node1;
    const ContactPair& pair = mortar.pairs[row];
    EXPECT_NEAR(pair.weight, nodes.pairs[j].weight, 1e-14);
    EXPECT_NEAR(pair.gap, 0.01, 1e-14);
    EXPECT_NEAR(nodes.pairs[j].gap, 0.01, 1e-14);
    EXPECT_LT((pair.normal - nodes.pairs[j].normal).norm(), 1e-14);
    for (int body = 0; body < 2; ++body) {
      EXPECT_LT(row_difference(row_entries(mortar.assignment(body), row),
                               row_entries(nodes.assignment(body), j)),
                1e-12)
          << to_string(GetParam()) << " body " << body << " node " << nodes.pairs[j].node1;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SolidMortar, MatchingLinearMeshes,
                         ::testing::Values(ElementType::hexahedron8, ElementType::tetrahedron4),
                         [](const auto& info) { return to_string(info.param); });

/// The rows expected from the transformed triangle6 basis (alpha = 1/5) on matching meshes,
/// by the non-mortar node's position: weight and the coefficients of the non-mortar side's
/// nodes (positions), from the faces' areas alone.
struct QuadraticRow {
  double weight = 0.0;
  std::map<int, double> coefficients;
};

std::map<int, QuadraticRow> expected_quadratic_rows(const InterfaceDescription& side) {
  std::map<int, QuadraticRow> rows;
  const std::vector<int>& facets = side.surfaces.front().facets;
  const int edges[3][2] = {{0, 1}, {1, 2}, {2, 0}};  // mid-edge nodes 3, 4, 5 (Gmsh order)
  for (std::size_t face = 0; face + 6 <= facets.size(); face += 6) {
    const auto point = [&](int local) { return side.coordinates[facets[face + local]]; };
    const double area = 0.5 * (point(1) - point(0)).cross(point(2) - point(0)).norm();
    for (int corner = 0; corner < 3; ++corner) {
      QuadraticRow& row = rows[facets[face + corner]];
      row.weight += 2.0 * area / 15.0;
      row.coefficients[facets[face + corner]] = 1.0;
    }
    for (int edge = 0; edge < 3; ++edge) {
      QuadraticRow& row = rows[facets[face + 3 + edge]];
      row.weight += area / 5.0;
      row.coefficients[facets[face + 3 + edge]] = 5.0 / 3.0;  // 1 / (1 - 2 alpha)
      for (const int end : edges[edge]) {
        row.coefficients[facets[face + end]] = -1.0 / 3.0;  // -alpha / (1 - 2 alpha)
      }
    }
  }
  return rows;
}

/// `coefficients` (by position of `side`) times the z normal `sign`, as operator entries.
RowEntries z_entries(const InterfaceDescription& side, const std::map<int, double>& coefficients,
                     double sign) {
  RowEntries entries;
  for (const auto& [position, value] : coefficients) {
    entries[{side.node_ids[static_cast<std::size_t>(position)], 2}] = sign * value;
  }
  return entries;
}

TEST(SolidMortar, MatchingQuadraticTetrahedraGiveTheTransformedBasisRows) {
  const MatchingBlocks blocks(ElementType::tetrahedron10);
  const InterfaceDescription lower = blocks.lower.contact_boundary();
  const InterfaceDescription upper = blocks.upper.contact_boundary();
  const ContactPairing mortar = build_mortar_coupling(lower, "lower", upper, "upper", nullptr, {});
  ASSERT_EQ(mortar.non_mortar_body, 0);  // a tie: body 0
  ASSERT_EQ(mortar.size(), lower.node_ids.size());
  ASSERT_EQ(mortar.size(), 35u);  // the 7 x 5 nodes of the top face
  const std::map<int, QuadraticRow> expected = expected_quadratic_rows(lower);
  for (std::size_t j = 0; j < mortar.size(); ++j) {
    const Eigen::Vector3d& position = mortar.pairs[j].position;
    int own = -1;
    for (std::size_t k = 0; k < lower.node_ids.size(); ++k) {
      if ((lower.coordinates[k] - position).norm() < 1e-12) own = static_cast<int>(k);
    }
    ASSERT_GE(own, 0);
    const QuadraticRow& row = expected.at(own);
    EXPECT_NEAR(mortar.pairs[j].weight, row.weight, 1e-14) << "row " << j;
    EXPECT_NEAR(mortar.pairs[j].gap, 0.01, 1e-13) << "row " << j;
    EXPECT_LT(row_difference(row_entries(mortar.operators[0], j),
                             z_entries(lower, row.coefficients, 1.0)),
              1e-12)
        << "row " << j;
    // On the mortar side the same coefficients at the upper nodes 0.01 above those nodes.
    std::map<int, double> mortar_coefficients;
    for (const auto& [position_in_lower, value] : row.coefficients) {
      for (std::size_t k = 0; k < upper.node_ids.size(); ++k) {
        if ((upper.coordinates[k] - lower.coordinates[position_in_lower]).head<2>().norm() <
            1e-12) {
          mortar_coefficients[static_cast<int>(k)] = value;
        }
      }
    }
    EXPECT_LT(row_difference(row_entries(mortar.operators[1], j),
                             z_entries(upper, mortar_coefficients, -1.0)),
              1e-12)
        << "row " << j;
  }
}

/// The contact patch test: lower block (H1 = 0.5) fixed at its bottom, upper block (H2 = 0.4)
/// pushed down by delta at its top, both on lateral symmetry supports.
struct PatchTest {
  static constexpr double delta = 0.01;
  Block lower{0.0, 0.5, {3, 3, 2}, ElementType::tetrahedron4, 1000.0, 0.3};
  Block upper{0.5, 0.9, {4, 5, 2}, ElementType::hexahedron8, 400.0, 0.25};

  /// p = delta / (H1 / M1 + H2 / M2), M = E (1 - nu) / ((1 + nu) (1 - 2 nu)).
  double exact_pressure() const {
    const auto modulus = [](const Block& block) {
      return block.young * (1.0 - block.poisson) /
             ((1.0 + block.poisson) * (1.0 - 2.0 * block.poisson));
    };
    return delta / ((lower.top - lower.bottom) / modulus(lower) +
                    (upper.top - upper.bottom) / modulus(upper));
  }
};

struct PatchResult {
  ContactPairing pairing;
  MonolithicResult solution;
};

PatchResult solve_patch_test(const PatchTest& test, int non_mortar_body) {
  BodySolver lower(block_body("lower", test.lower, "top", 0.0, std::nullopt));
  BodySolver upper(block_body("upper", test.upper, "bottom", std::nullopt, -PatchTest::delta));
  MortarOptions options;
  options.non_mortar_body = non_mortar_body;
  PatchResult result;
  result.pairing = build_mortar_coupling(lower.contact_boundary(), "lower",
                                         upper.contact_boundary(), "upper", nullptr, options);
  lower.assign_contact(result.pairing.assignment(0));
  upper.assign_contact(result.pairing.assignment(1));
  MprgpParameters parameters;
  parameters.relative_tolerance = 1e-14;
  result.solution = solve_monolithic(lower, upper, result.pairing, parameters);
  return result;
}

class SolidMortarPatchTest : public ::testing::TestWithParam<std::tuple<ElementType, int>> {};

TEST_P(SolidMortarPatchTest, MonolithicPressureIsExactAtEveryMultiplierNode) {
  const auto [type, non_mortar_body] = GetParam();
  PatchTest test;
  test.lower.type = type;
  const PatchResult result = solve_patch_test(test, non_mortar_body);
  const int expected_side = non_mortar_body >= 0 ? non_mortar_body : 1;  // the finer: hexahedra
  EXPECT_EQ(result.pairing.non_mortar_body, expected_side);
  // Every node of the non-mortar face carries a row: (3+1)^2 = 16 tetrahedron4 corners,
  // (2*3+1)^2 = 49 tetrahedron10 nodes, (4+1)(5+1) = 30 hexahedron nodes.
  const std::size_t lower_nodes = type == ElementType::tetrahedron4 ? 16u : 49u;
  EXPECT_EQ(result.pairing.size(), expected_side == 0 ? lower_nodes : 30u);
  EXPECT_EQ(result.pairing.uncovered, 0);
  ASSERT_EQ(result.solution.qp.status, QpStatus::converged);
  const double error =
      largest_pressure_error(result.pairing, result.solution.contact_force, test.exact_pressure());
  std::printf(
      "3D patch test, %s against hexahedra, non-mortar body %d: largest pressure error "
      "%.3e\n",
      to_string(type).c_str(), expected_side, error);
  EXPECT_LE(error, 1e-10);
}

INSTANTIATE_TEST_SUITE_P(NonMortarSide, SolidMortarPatchTest,
                         ::testing::Combine(::testing::Values(ElementType::tetrahedron4,
                                                              ElementType::tetrahedron10),
                                            ::testing::Values(-1, 0, 1)),
                         [](const auto& info) {
                           const int side = std::get<1>(info.param);
                           return to_string(std::get<0>(info.param)) +
                                  (side < 0 ? std::string("_finer")
                                            : "_body" + std::to_string(side));
                         });

class SolidMortarRobinTest : public ::testing::TestWithParam<int> {};

TEST_P(SolidMortarRobinTest, InProcessRobinIterationConvergesToTheMonolithicSolution) {
  // The patch test (4-node tetrahedra against hexahedra) with each body behind an in-process
  // port, iterated by the Robin iteration (default options, tolerance 1e-8).
  const PatchTest test;
  const PatchResult reference = solve_patch_test(test, GetParam());
  ASSERT_EQ(reference.solution.qp.status, QpStatus::converged);
  BodyCase lower_case, upper_case;
  lower_case.definition = block_body("lower", test.lower, "top", 0.0, std::nullopt);
  upper_case.definition =
      block_body("upper", test.upper, "bottom", std::nullopt, -PatchTest::delta);
  SolverOptions solver;
  solver.qp.relative_tolerance = 1e-14;
  InProcessPort lower, upper;
  const InterfaceDescription lower_side = lower.setup(lower_case, solver);
  const InterfaceDescription upper_side = upper.setup(upper_case, solver);
  MortarOptions options;
  options.non_mortar_body = GetParam();
  const ContactPairing pairing =
      build_mortar_coupling(lower_side, "lower", upper_side, "upper", nullptr, options);
  lower.assign_contact(pairing.assignment(0));
  upper.assign_contact(pairing.assignment(1));
  const CouplingOptions coupling;
  const RobinResult robin = run_robin_iteration(lower, upper, pairing, coupling);
  ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
  const Eigen::VectorXd& expected = reference.solution.contact_force;
  const double scale = expected.lpNorm<Eigen::Infinity>();
  double largest_error = 0.0;
  for (const BodyInterfaceState& body : robin.state.bodies) {
    largest_error =
        std::max(largest_error, (body.contact_force - expected).lpNorm<Eigen::Infinity>());
  }
  const double pressure_error =
      largest_pressure_error(pairing, robin.state.bodies[0].contact_force, test.exact_pressure());
  std::printf(
      "3D patch test, Robin iteration, non-mortar body %d: %zu iterations, contact force "
      "%.3e from the monolithic one (relative), largest pressure error %.3e\n",
      GetParam(), robin.history.size(), largest_error / scale, pressure_error);
  EXPECT_LE(largest_error, 1e-8 * scale);
  EXPECT_LE(pressure_error, 1e-8);
}

INSTANTIATE_TEST_SUITE_P(NonMortarSide, SolidMortarRobinTest, ::testing::Values(0, 1));

/// The integral over [a, b] of the hat function of the node at `node` of a uniform mesh of
/// [0, 1] with `spacing`: the trapezoidal rule on its linear pieces (exact).
double hat_integral(double node, double spacing, double a, double b) {
  const auto hat = [&](double t) { return std::max(0.0, 1.0 - std::abs(t - node) / spacing); };
  a = std::max(a, 0.0);
  b = std::min(b, 1.0);
  if (b <= a) return 0.0;
  std::vector<double> points = {a, b};
  for (const double kink : {node - spacing, node, node + spacing}) {
    if (kink > a && kink < b) points.push_back(kink);
  }
  std::sort(points.begin(), points.end());
  double integral = 0.0;
  for (std::size_t k = 0; k + 1 < points.size(); ++k) {
    integral += 0.5 * (points[k + 1] - points[k]) * (hat(points[k]) + hat(points[k + 1]));
  }
  return integral;
}

/// sum over the row's entries of coefficient * field component at the entry's node.
double apply_row(const ContactOperator& contact, std::size_t row,
                 const std::map<int, Eigen::Vector3d>& field) {
  double value = 0.0;
  for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
    value += contact.values[k] * field.at(contact.nodes[k])[contact.components[k]];
  }
  return value;
}

/// A linear displacement field at the contact nodes of `side`, added to `field`.
void add_linear_field(const InterfaceDescription& side, std::map<int, Eigen::Vector3d>& field) {
  for (std::size_t k = 0; k < side.node_ids.size(); ++k) {
    const Eigen::Vector3d& x = side.coordinates[k];
    field[side.node_ids[k]] = Eigen::Vector3d(0.02 - 0.01 * x.y(), 0.01 * x.x() + 0.03 * x.z(),
                                              0.3 + 0.7 * x.x() - 0.4 * x.y());
  }
}

TEST(SolidMortar, PartlyCoveredNodesGetTheStandardRowsOverTheCoveredPart) {
  // Non-mortar: the top of a 5 x 5 hexahedron block on [0, 1]^2 (nodes every 0.2). Mortar: the
  // bottom of a tetrahedron block on [0.3, 0.95] x [0.2, 0.9], 0.01 above. The covered integral
  // of node (x_j, y_j) is the product of its hat functions' integrals over the two intervals.
  const Block lower_block{0.0, 0.5, {5, 5, 1}, ElementType::hexahedron8, 1.0, 0.3};
  const Block upper_block{0.51, 0.8, {3, 4, 1},  ElementType::tetrahedron4,
                          1.0,  0.3, {0.3, 0.2}, {0.95, 0.9}};
  const BodySolver lower(block_body("lower", lower_block, "top", 0.0, std::nullopt));
  const BodySolver upper(block_body("upper", upper_block, "bottom", std::nullopt, 0.0));
  const InterfaceDescription lower_side = lower.contact_boundary();
  const InterfaceDescription upper_side = upper.contact_boundary();
  MortarOptions options;
  options.non_mortar_body = 0;
  const ContactPairing mortar =
      build_mortar_coupling(lower_side, "lower", upper_side, "upper", nullptr, options);
  std::map<int, Eigen::Vector3d> field;
  add_linear_field(lower_side, field);
  add_linear_field(upper_side, field);
  int covered_nodes = 0, fully_covered_nodes = 0;
  for (std::size_t k = 0; k < lower_side.node_ids.size(); ++k) {
    const Eigen::Vector3d& x = lower_side.coordinates[k];
    const double support = hat_integral(x.x(), 0.2, 0.0, 1.0) * hat_integral(x.y(), 0.2, 0.0, 1.0);
    const double covered = hat_integral(x.x(), 0.2, 0.3, 0.95) * hat_integral(x.y(), 0.2, 0.2, 0.9);
    const std::size_t row = row_at(mortar, x);
    if (covered == 0.0) {
      EXPECT_EQ(row, static_cast<std::size_t>(-1)) << "node at " << x.transpose();
      continue;
    }
    ++covered_nodes;
    ASSERT_LT(row, mortar.size()) << "node at " << x.transpose();
    const bool full = std::abs(covered - support) <= 1e-12 * support;
    fully_covered_nodes += full ? 1 : 0;
    EXPECT_NEAR(mortar.pairs[row].weight, covered, 1e-14) << "node at " << x.transpose();
    EXPECT_NEAR(mortar.pairs[row].gap, 0.01, 1e-13) << "node at " << x.transpose();
    const RowEntries own = row_entries(mortar.operators[0], row);
    // The dual row of a fully covered node is the node alone; a standard row has neighbours.
    EXPECT_EQ(own.size() == 1u, full) << "node at " << x.transpose();
    double own_sum = 0.0, mortar_sum = 0.0;
    for (const auto& [key, value] : own) own_sum += value;
    for (const auto& [key, value] : row_entries(mortar.operators[1], row)) mortar_sum += value;
    EXPECT_NEAR(own_sum, 1.0, 1e-12) << "node at " << x.transpose();
    EXPECT_NEAR(mortar_sum, -1.0, 1e-12) << "node at " << x.transpose();
    // A linear field continuous across the interface closes every row exactly.
    EXPECT_NEAR(
        apply_row(mortar.operators[0], row, field) + apply_row(mortar.operators[1], row, field),
        0.0, 1e-13)
        << "node at " << x.transpose();
  }
  EXPECT_EQ(covered_nodes, 25);       // the 6 x 6 nodes but those on x = 0 or y = 0
  EXPECT_EQ(fully_covered_nodes, 2);  // (0.6, 0.4) and (0.6, 0.6)
  EXPECT_EQ(static_cast<int>(mortar.size()), covered_nodes);
  EXPECT_EQ(mortar.uncovered, 11);
}

TEST(SolidMortar, NodeToSegmentCollocationIsRefusedIn3D) {
  const MatchingBlocks blocks(ElementType::hexahedron8);
  MortarOptions options;
  options.integration = MortarIntegration::node_to_segment;
  EXPECT_THROW(build_mortar_coupling(blocks.lower.contact_boundary(), "lower",
                                     blocks.upper.contact_boundary(), "upper", nullptr, options),
               InputError);
}

/// The message of the InputError `action` throws ("" when it throws none).
std::string input_error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SolidMortar, BoundariesThatDoNotFaceEachOtherAreErrorsNamingBothBodies) {
  // The upper block's top (outward normal +z) against the lower block's top (+z).
  const BodySolver lower(block_body("lower", {0.0, 0.5, {3, 2, 1}}, "top", 0.0, std::nullopt));
  const BodySolver upper(block_body("upper", {0.6, 1.0, {2, 2, 1}}, "top", 0.0, std::nullopt));
  const InterfaceDescription lower_side = lower.contact_boundary();
  const InterfaceDescription upper_side = upper.contact_boundary();
  const std::string message = input_error_of(
      [&] { build_mortar_coupling(lower_side, "lower", upper_side, "upper", nullptr, {}); });
  EXPECT_NE(message.find("'lower' and 'upper' do not face each other"), std::string::npos)
      << message;
  EXPECT_NE(message.find("outward normals point the same way"), std::string::npos) << message;
  InterfaceDescription plane = upper_side;
  plane.dimension = 2;
  const std::string dimensions = input_error_of(
      [&] { build_mortar_coupling(lower_side, "lower", plane, "upper", nullptr, {}); });
  EXPECT_NE(dimensions.find("bodies 'lower' and 'upper'"), std::string::npos) << dimensions;
  EXPECT_NE(dimensions.find("different dimensions"), std::string::npos) << dimensions;
}

}  // namespace
}  // namespace robin
