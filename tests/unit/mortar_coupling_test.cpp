// Mortar coupling rows on hand-made straight contact boundaries, against values known in closed
// form: matching meshes give the node-to-node rows; on non-matching meshes the mortar
// coefficients of a fully covered row sum to one (the mortar side's partition of unity), the
// weights add up to the boundary's length, and the normalized weighted gap of a linear gap field
// is its nodal value (biorthogonality of the dual basis); boundaries that do not face each other
// are errors naming both bodies.

#include <gtest/gtest.h>

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
    side.coordinates.push_back(start + (end - start) * (static_cast<double>(i) / count));
    side.normals.push_back(outward);
    side.weights.push_back(i == 0 || i == count ? 0.5 * length : length);
    side.x_fixed.push_back(false);
    side.y_fixed.push_back(false);
  }
  const Eigen::Vector2d tangent = (end - start).normalized();
  const bool body_on_left = Eigen::Vector2d(tangent.y(), -tangent.x()).dot(outward) > 0.0;
  side.surfaces.emplace_back();
  side.surfaces.back().boundary = "contact";
  for (int i = 0; i < count; ++i) {
    side.surfaces.back().segments.push_back(body_on_left ? i : i + 1);
    side.surfaces.back().segments.push_back(body_on_left ? i + 1 : i);
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

TEST(MortarCoupling, ANonMortarNodeWithPrescribedNormalDisplacementIsExcluded) {
  // The lower edge's first node is clamped (u_x and u_y prescribed), its second has only u_x
  // prescribed, which leaves its normal (y) displacement free.
  InterfaceDescription lower = lower_edge(0.0, 1.0, 4);
  lower.x_fixed[0] = lower.y_fixed[0] = true;
  lower.x_fixed[1] = true;
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
