// Mortar coupling rows on hand-made straight contact boundaries, against values known in closed
// form: matching meshes give the node-to-node rows; on non-matching meshes the mortar
// coefficients of a fully covered row sum to one (the mortar side's partition of unity), the
// weights add up to the boundary's length, and the normalized weighted gap of a linear gap field
// is its nodal value (biorthogonality of the dual basis); a zone that ends inside a non-mortar
// segment gives rows equal to hand-computed integrals (dual and standard basis); boundaries that do
// not face each other are errors naming both bodies.

#include <gtest/gtest.h>

#include <map>
#include <numeric>

#include "coupling/mortar_coupling.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

/// A straight contact boundary from `start` to `end` with `count` segments, `outward` its unit
/// outward normal; segments are oriented with the body on the left, node ids from `first_id`.
InterfaceDescription straight_boundary(const Eigen::Vector2d& start, const Eigen::Vector2d& end,
                                       int count, const Eigen::Vector2d& outward, int first_id) {
  InterfaceDescription side;
  const double length = (end - start).norm() / count;
  for (int i = 0; i <= count; ++i) {
    side.node_ids.push_back(first_id + i);
    side.node_tags.push_back(static_cast<std::size_t>(first_id + i + 1));
    const Eigen::Vector2d point = start + (end - start) * (static_cast<double>(i) / count);
    side.coordinates.emplace_back(point.x(), point.y(), 0.0);
    side.normals.emplace_back(outward.x(), outward.y(), 0.0);
    side.weights.push_back(i == 0 || i == count ? 0.5 * length : length);
    side.fixed.push_back({false, false, false});
  }
  const Eigen::Vector2d tangent = (end - start).normalized();
  const bool body_on_left = Eigen::Vector2d(tangent.y(), -tangent.x()).dot(outward) > 0.0;
  side.surfaces.emplace_back();
  side.surfaces.back().boundary = "contact";
  for (int i = 0; i < count; ++i) {
    side.surfaces.back().facets.push_back(body_on_left ? i : i + 1);
    side.surfaces.back().facets.push_back(body_on_left ? i + 1 : i);
  }
  return side;
}

/// The lower body's top edge y = 0 on [x0, x1] (outward +y) and the upper body's bottom edge
/// y = height(x) (outward -y).
InterfaceDescription lower_edge(double x0, double x1, int count) {
  return straight_boundary({x0, 0.0}, {x1, 0.0}, count, {0.0, 1.0}, 0);
}
InterfaceDescription upper_edge(double x0, double y0, double x1, double y1, int count) {
  const Eigen::Vector2d tangent = Eigen::Vector2d(x1 - x0, y1 - y0).normalized();
  return straight_boundary({x0, y0}, {x1, y1}, count, Eigen::Vector2d(tangent.y(), -tangent.x()),
                           1000);
}

/// The entries of row `row` of `contact` as (node, component) -> value.
std::map<std::pair<int, int>, double> row_entries(const ContactOperator& contact, int row) {
  std::map<std::pair<int, int>, double> entries;
  for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
    entries[{contact.nodes[k], contact.components[k]}] += contact.values[k];
  }
  return entries;
}

TEST(MortarCoupling, MatchingFlatMeshesGiveTheNodeToNodeRows) {
  const InterfaceDescription lower = lower_edge(0.0, 1.0, 4);
  const InterfaceDescription upper = upper_edge(0.0, 0.0, 1.0, 0.0, 4);
  const ContactPairing pairing =
      build_mortar_coupling(lower, "lower", upper, "upper", nullptr, MortarOptions{});
  EXPECT_EQ(pairing.non_mortar_body, 0);
  ASSERT_EQ(pairing.size(), 5u);
  for (int row = 0; row < 5; ++row) {
    const ContactPair& pair = pairing.pairs[static_cast<std::size_t>(row)];
    const int lower_node = static_cast<int>(std::lround(pair.position.x() * 4));
    const auto own = row_entries(pairing.operators[0], row);
    const auto other = row_entries(pairing.operators[1], row);
    ASSERT_EQ(own.size(), 1u);
    EXPECT_NEAR(own.at({lower_node, 1}), 1.0, 1e-14);  // u_y of the node, n = (0, 1)
    ASSERT_EQ(other.size(), 1u) << "row " << row;
    EXPECT_NEAR(other.at({1000 + lower_node, 1}), -1.0, 1e-12);
    EXPECT_NEAR(pair.weight, lower.weights[static_cast<std::size_t>(lower_node)], 1e-14);
    EXPECT_NEAR(pair.gap, 0.0, 1e-14);
  }
}

TEST(MortarCoupling, NonMatchingRowsReproduceLinearFieldsExactly) {
  // Upper edge y = 0.1 + 0.05 x: the normal gap along the lower normal (0, 1) is linear in x.
  const InterfaceDescription lower = lower_edge(0.0, 1.0, 7);
  const InterfaceDescription upper = upper_edge(0.0, 0.1, 1.0, 0.15, 5);
  MortarOptions options;
  options.non_mortar_body = 0;
  const ContactPairing pairing =
      build_mortar_coupling(lower, "lower", upper, "upper", nullptr, options);
  ASSERT_EQ(pairing.size(), 8u);
  double total_weight = 0.0;
  for (int row = 0; row < 8; ++row) {
    const ContactPair& pair = pairing.pairs[static_cast<std::size_t>(row)];
    total_weight += pair.weight;
    EXPECT_NEAR(pair.gap, 0.1 + 0.05 * pair.position.x(), 1e-12) << "row " << row;
    double coefficient_sum = 0.0;
    for (const auto& [key, value] : row_entries(pairing.operators[1], row)) {
      EXPECT_EQ(key.second, 1);  // only u_y: the non-mortar normal is (0, 1)
      coefficient_sum += value;
    }
    EXPECT_NEAR(coefficient_sum, -1.0, 1e-12) << "row " << row;
  }
  EXPECT_NEAR(total_weight, 1.0, 1e-12);
}

TEST(MortarCoupling, SmallSegmentsFarFromTheOriginKeepEveryRow) {
  // 2000 and 2800 segments on [1000, 1001]: a segment is 5e-4 long at coordinates of 1e3, so the
  // projections resolve the reference coordinate only to about 1e-11 (round-off).
  const InterfaceDescription lower =
      straight_boundary({1000.0, 0.0}, {1001.0, 0.0}, 2000, {0.0, 1.0}, 0);
  const InterfaceDescription upper =
      straight_boundary({1000.0, 0.02}, {1001.0, 0.02}, 2800, {0.0, -1.0}, 10000);
  MortarOptions options;
  options.non_mortar_body = 0;
  const ContactPairing pairing =
      build_mortar_coupling(lower, "lower", upper, "upper", nullptr, options);
  ASSERT_EQ(pairing.size(), 2001u);
  EXPECT_EQ(pairing.uncovered, 0);
  double total_weight = 0.0;
  for (const ContactPair& pair : pairing.pairs) {
    total_weight += pair.weight;
    EXPECT_NEAR(pair.gap, 0.02, 1e-10);
  }
  EXPECT_NEAR(total_weight, 1.0, 1e-9);
}

TEST(MortarCoupling, TheFinerSideCarriesTheMultipliersUnlessChosen) {
  const InterfaceDescription lower = lower_edge(0.0, 1.0, 3);
  const InterfaceDescription upper = upper_edge(0.0, 0.0, 1.0, 0.0, 8);
  EXPECT_EQ(finer_side(lower, upper), 1);
  EXPECT_EQ(build_mortar_coupling(lower, "a", upper, "b", nullptr, {}).size(), 9u);
  MortarOptions coarse;
  coarse.non_mortar_body = 0;
  EXPECT_EQ(build_mortar_coupling(lower, "a", upper, "b", nullptr, coarse).size(), 4u);
}

TEST(MortarCoupling, NodesBeyondTheOtherBodyCarryNoConstraint) {
  // The upper edge covers [0.3, 0.7] of the lower edge [0, 1] (10 segments, non-mortar side).
  const InterfaceDescription lower = lower_edge(0.0, 1.0, 10);
  const InterfaceDescription upper = upper_edge(0.3, 0.0, 0.7, 0.0, 3);
  MortarOptions options;
  options.non_mortar_body = 0;
  const ContactPairing pairing =
      build_mortar_coupling(lower, "lower", upper, "upper", nullptr, options);
  // Covered: x = 0.2 .. 0.8 touch the covered part (x = 0.2 and 0.8 only at their support's
  // end: no measure); 0.3 .. 0.7 are constrained, 0.3 and 0.7 in part (standard rows).
  EXPECT_EQ(pairing.size(), 5u);
  EXPECT_EQ(pairing.uncovered, 6);
  for (const ContactPair& pair : pairing.pairs) {
    EXPECT_GE(pair.position.x(), 0.3 - 1e-12);
    EXPECT_LE(pair.position.x(), 0.7 + 1e-12);
    EXPECT_GT(pair.weight, 0.0);
    EXPECT_NEAR(pair.gap, 0.0, 1e-12);
  }
  // A partly covered end node gets a positively weighted average: half its support.
  EXPECT_NEAR(pairing.pairs.front().weight, 0.05, 1e-12);
}

// The upper body's edge ends at x = 0.6, strictly inside the non-mortar segment [0.5, 0.75].
// Non-mortar side: the lower edge y = 0 on [0, 1], nodes x_k = k h (h = 1/4, ids 0..4), hats
// phi_k. Mortar side: y = 0.1 + 0.1 x on [0, 0.6], nodes X_l = l/5 (ids 1000..1003), hats
// phi^_l(x) (the projection along the lower normal (0, 1) is vertical, so the mortar point of x
// has the abscissa x). Normal gap g(x) = 0.1 + 0.1 x. Every integral below is over the part of
// the lower edge the upper one covers, [0, 0.6], computed by hand (exact fractions: the
// integrands are piecewise polynomials of degree <= 2 with breaks at the nodes of both sides).
//  - x = 0 and x = 0.25: supports covered entirely, dual basis psi_j = 2 phi_j - phi_k on each
//    segment (k its other node). Row j: u_y(x_j) - sum_l (M_jl / m_j) u^_y(X_l) <= G_j / m_j
//    with m_j = int psi_j phi_j = int phi_j (1/8, 1/4), M_jl = int psi_j phi^_l,
//    G_j = int psi_j g = g(x_j) m_j (biorthogonality, g linear):
//      M_0 = (3/25, 1/100, -1/200, 0),  M_1 = (-1/50, 17/80, 29/400, -3/200).
//  - x = 0.5 and x = 0.75: supports covered in part, standard basis. Row j:
//    sum_k (D_jk / m_j) u_y(x_k) - sum_l (M_jl / m_j) u^_y(X_l) <= G_j / m_j with
//    D_jk = int phi_j phi_k, M_jl = int phi_j phi^_l, G_j = int phi_j g, m_j = int phi_j:
//      x = 0.5:  m = 41/200, D = (1/24, 223/1500, 11/750) at x = 0.25, 0.5, 0.75,
//                M = (0, 9/800, 91/800, 2/25), G / m = 1203/8200;
//      x = 0.75: m = 1/50, D = (11/750, 2/375) at x = 0.5, 0.75, M = (0, 0, 1/300, 1/60),
//                G / m = 47/300 (the mean of g weighted by phi_3 over [0.5, 0.6]).
//  - x = 1: not covered, no row.
TEST(MortarCoupling, ZoneEndingInsideASegmentGivesTheExactRows) {
  const InterfaceDescription lower = lower_edge(0.0, 1.0, 4);
  const InterfaceDescription upper = upper_edge(0.0, 0.1, 0.6, 0.16, 3);
  MortarOptions options;
  options.non_mortar_body = 0;
  const ContactPairing pairing =
      build_mortar_coupling(lower, "lower", upper, "upper", nullptr, options);
  ASSERT_EQ(pairing.size(), 4u);
  EXPECT_EQ(pairing.uncovered, 1);
  struct ExpectedRow {
    double weight, gap;
    std::map<int, double> own, other;  // by node id: the u_y coefficients
  };
  const std::map<int, ExpectedRow> expected = {
      {0, {1.0 / 8, 0.1, {{0, 1.0}}, {{1000, -0.96}, {1001, -0.08}, {1002, 0.04}}}},
      {1, {1.0 / 4, 0.125, {{1, 1.0}}, {{1000, 0.08}, {1001, -0.85}, {1002, -0.29}, {1003, 0.06}}}},
      {2,
       {41.0 / 200,
        1203.0 / 8200,
        {{1, 25.0 / 123}, {2, 446.0 / 615}, {3, 44.0 / 615}},
        {{1001, -9.0 / 164}, {1002, -91.0 / 164}, {1003, -16.0 / 41}}}},
      {3,
       {1.0 / 50,
        47.0 / 300,
        {{2, 11.0 / 15}, {3, 4.0 / 15}},
        {{1002, -1.0 / 6}, {1003, -5.0 / 6}}}}};
  for (int row = 0; row < 4; ++row) {
    const ContactPair& pair = pairing.pairs[static_cast<std::size_t>(row)];
    const int node = static_cast<int>(std::lround(pair.position.x() * 4));
    SCOPED_TRACE("row of the node at x = " + std::to_string(pair.position.x()));
    ASSERT_EQ(expected.count(node), 1u);
    const ExpectedRow& want = expected.at(node);
    EXPECT_NEAR(pair.weight, want.weight, 1e-14);
    EXPECT_NEAR(pair.gap, want.gap, 1e-13);
    for (const auto& [operator_index, coefficients] :
         {std::pair{0, want.own}, std::pair{1, want.other}}) {
      const auto entries =
          row_entries(pairing.operators[static_cast<std::size_t>(operator_index)], row);
      EXPECT_EQ(entries.size(), coefficients.size());
      for (const auto& [id, value] : coefficients) {
        ASSERT_EQ(entries.count({id, 1}), 1u) << "node id " << id;
        EXPECT_NEAR(entries.at({id, 1}), value, 1e-13) << "node id " << id;
      }
    }
  }
}

TEST(MortarCoupling, ANonMortarNodeWithPrescribedNormalDisplacementIsExcluded) {
  // The lower edge's first node is clamped (u_x and u_y prescribed), its second has only u_x
  // prescribed, which leaves its normal (y) displacement free.
  InterfaceDescription lower = lower_edge(0.0, 1.0, 4);
  lower.fixed[0][0] = lower.fixed[0][1] = true;
  lower.fixed[1][0] = true;
  const InterfaceDescription upper = upper_edge(0.0, 0.0, 1.0, 0.0, 3);
  MortarOptions options;
  options.non_mortar_body = 0;
  const ContactPairing pairing =
      build_mortar_coupling(lower, "lower", upper, "upper", nullptr, options);
  EXPECT_EQ(pairing.size(), 4u);
  ASSERT_EQ(pairing.excluded.size(), 1u);
  EXPECT_NE(pairing.excluded.front().find("body 'lower' contact node (tag 1)"), std::string::npos)
      << pairing.excluded.front();
  EXPECT_NEAR(pairing.excluded_pairs.front().position.x(), 0.0, 1e-15);
  for (const ContactPair& pair : pairing.pairs) EXPECT_GT(pair.position.x(), 0.1);
}

TEST(MortarCoupling, BoundariesThatDoNotFaceEachOtherAreErrors) {
  const InterfaceDescription lower = lower_edge(0.0, 1.0, 4);
  // Outward normals the same way: an "upper" edge whose body lies above... and below.
  const InterfaceDescription same_way =
      straight_boundary({0.0, 0.1}, {1.0, 0.1}, 4, {0.0, 1.0}, 100);
  try {
    build_mortar_coupling(lower, "lower", same_way, "upper", nullptr, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'lower' and 'upper' do not face each other"), std::string::npos)
        << message;
    EXPECT_NE(message.find("outward normals point the same way"), std::string::npos) << message;
  }
  const InterfaceDescription far = upper_edge(5.0, 0.0, 6.0, 0.0, 4);
  try {
    build_mortar_coupling(lower, "lower", far, "upper", nullptr, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("do not face each other"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace robin
