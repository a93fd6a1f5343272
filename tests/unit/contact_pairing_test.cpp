// Node-to-node pairing of two contact boundaries, on hand-built interfaces whose pairs, normals,
// gaps and weights are known by construction.

#include "coupling/contact_pairing.hpp"

#include <gtest/gtest.h>

#include "numerics/errors.hpp"

namespace robin {
namespace {

/// A flat interface y = height with nodes at the given x (tags 100 + i), unit weights,
/// outward normal (0, normal_y).
InterfaceDescription flat_interface(const std::vector<double>& xs, double height, double normal_y) {
  InterfaceDescription interface;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    interface.node_ids.push_back(static_cast<int>(i));
    interface.node_tags.push_back(100 + i);
    interface.coordinates.emplace_back(xs[i], height, 0.0);
    interface.normals.emplace_back(0.0, normal_y, 0.0);
    interface.weights.push_back(1.0 + static_cast<double>(i));
    interface.fixed.push_back({false, false, false});
  }
  return interface;
}

TEST(ContactPairing, MatchingFlatInterfacesWithGeometricAndAnalyticGap) {
  // Body 1 below (outward normal +y), body 2 above at distance 0.1, listed in another order.
  const InterfaceDescription lower = flat_interface({1.0, 0.0, 0.5}, 0.0, 1.0);
  InterfaceDescription upper = flat_interface({0.5, 1.0, 0.0}, 0.1, -1.0);
  const GapFunction parabola("x^2", {}, "test");
  const ContactPairing pairing =
      pair_contact_nodes(lower, "lower", upper, "upper", &parabola, 1e-6);
  ASSERT_EQ(pairing.size(), 3u);
  EXPECT_TRUE(pairing.excluded.empty());
  const std::vector<double> expected_x = {0.0, 0.5, 1.0};  // ordered along the zone
  for (std::size_t i = 0; i < 3; ++i) {
    const ContactPair& pair = pairing.pairs[i];
    EXPECT_DOUBLE_EQ(pair.position.x(), expected_x[i]);
    EXPECT_DOUBLE_EQ(pair.normal.x(), 0.0);
    EXPECT_DOUBLE_EQ(pair.normal.y(), 1.0);
    EXPECT_NEAR(pair.gap, 0.1 + expected_x[i] * expected_x[i], 1e-15);
    EXPECT_DOUBLE_EQ(lower.coordinates[pair.node1].x(), upper.coordinates[pair.node2].x());
    // Weights: lower node k has 1 + k, upper node k has 1 + k; the pair averages both sides.
    EXPECT_DOUBLE_EQ(pair.weight, 0.5 * (lower.weights[pair.node1] + upper.weights[pair.node2]));
  }
  // Body 2's node-to-node operator: one row per pair, (x, y) entries of -n1 at node2.
  const ContactOperator second = pairing.assignment(1);
  ASSERT_EQ(second.row_count(), 3);
  ASSERT_EQ(second.entry_count(), 6u);
  EXPECT_EQ(second.row_offsets, (std::vector<std::size_t>{0, 2, 4, 6}));
  EXPECT_EQ(second.nodes[0], 2);  // upper node at x = 0
  EXPECT_EQ(second.nodes[1], 2);
  EXPECT_EQ(second.components[0], 0);
  EXPECT_EQ(second.components[1], 1);
  EXPECT_DOUBLE_EQ(second.values[0], 0.0);
  EXPECT_DOUBLE_EQ(second.values[1], -1.0);
  for (int row = 0; row < 3; ++row) {
    EXPECT_DOUBLE_EQ(second.weights[row], pairing.pairs[row].weight);
  }
  const ContactOperator first = pairing.assignment(0);
  ASSERT_EQ(first.row_count(), 3);
  EXPECT_EQ(first.nodes[0], 1);  // lower node at x = 0
  EXPECT_DOUBLE_EQ(first.values[1], 1.0);
}

TEST(ContactPairing, NonMatchingMeshesNameTheFirstUnmatchedNode) {
  const InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  const InterfaceDescription upper = flat_interface({0.0, 0.52, 1.0}, 0.0, -1.0);
  try {
    pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
    FAIL() << "no error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("body 'lower'"), std::string::npos) << message;
    EXPECT_NE(message.find("tag 101"), std::string::npos) << message;
    EXPECT_NE(message.find("(0.5, 0)"), std::string::npos) << message;
  }
}

TEST(ContactPairing, MatchingNodesWhoseNormalsPointTheSameWayAreAnError) {
  // Both outward normals +y: the second body lies below the shared edge like the first.
  const InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  const InterfaceDescription overlapping = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  try {
    pair_contact_nodes(lower, "lower", overlapping, "upper", nullptr, 1e-6);
    FAIL() << "no error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("the contact boundaries of bodies 'lower' and 'upper' do not face "
                           "each other: their outward normals point the same way"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("body 'lower' contact node (tag 100) at (0, 0) has the outward normal "
                           "(0, 1) and its partner, body 'upper' contact node (tag 100) at (0, 0), "
                           "the outward normal (0, 1)"),
              std::string::npos)
        << message;
  }
}

TEST(ContactPairing, ExtraNodeOnTheSecondBodyIsNamed) {
  const InterfaceDescription lower = flat_interface({0.0, 1.0}, 0.0, 1.0);
  const InterfaceDescription upper = flat_interface({0.0, 0.5, 1.0}, 0.0, -1.0);
  try {
    pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
    FAIL() << "no error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("body 'upper'"), std::string::npos) << message;
    EXPECT_NE(message.find("(0.5, 0)"), std::string::npos) << message;
  }
}

TEST(ContactPairing, PairsWithAPrescribedNormalDisplacementAreExcluded) {
  InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  InterfaceDescription upper = flat_interface({0.0, 0.5, 1.0}, 0.0, -1.0);
  lower.fixed[0][0] = lower.fixed[0][1] = true;  // clamped: normal displacement prescribed
  upper.fixed[2][1] = true;                      // u_y fixed and the normal is (0, -1)
  lower.fixed[1][0] = true;                      // only the tangential component: stays in contact
  const ContactPairing pairing = pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
  ASSERT_EQ(pairing.size(), 1u);
  EXPECT_DOUBLE_EQ(pairing.pairs[0].position.x(), 0.5);
  ASSERT_EQ(pairing.excluded.size(), 2u);
  EXPECT_NE(pairing.excluded[0].find("body 'lower'"), std::string::npos);
  EXPECT_NE(pairing.excluded[1].find("body 'upper'"), std::string::npos);
}

TEST(ContactPairing, ContactBoundaryThatIsAllDirichletIsAnError) {
  InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  const InterfaceDescription upper = flat_interface({0.0, 0.5, 1.0}, 0.0, -1.0);
  for (std::size_t i = 0; i < 3; ++i) lower.fixed[i][1] = true;
  try {
    pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
    FAIL() << "no error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("bodies 'lower' and 'upper'"), std::string::npos) << message;
    EXPECT_NE(message.find("all 3 node pairs"), std::string::npos) << message;
    EXPECT_NE(message.find("Dirichlet"), std::string::npos) << message;
  }
}

TEST(ContactPairing, InitialOverlapIsReportedWithTheDeepestPair) {
  const InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  const InterfaceDescription upper = flat_interface({0.0, 0.5, 1.0}, 0.0, -1.0);
  const GapFunction dip("0.1 - x", {}, "test");  // d = 0.1, -0.4, -0.9
  const ContactPairing overlapping = pair_contact_nodes(lower, "lower", upper, "upper", &dip, 1e-6);
  const std::string warning = overlap_warning(overlapping);
  EXPECT_NE(warning.find("2 of 3 contact pairs overlap"), std::string::npos) << warning;
  EXPECT_NE(warning.find("0.9 at (1, 0)"), std::string::npos) << warning;
  const ContactPairing touching = pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
  EXPECT_EQ(overlap_warning(touching), "");  // d = 0 exactly is contact, not overlap
  // the round-off of gaps computed from coordinates on an inclined boundary (the zone is 1 long:
  // 1e-12 of it is the threshold) is not an overlap; 1e-9 is
  const GapFunction round_off("-2e-16", {}, "test");
  EXPECT_EQ(overlap_warning(pair_contact_nodes(lower, "lower", upper, "upper", &round_off, 1e-6)),
            "");
  const GapFunction small("-1e-9", {}, "test");
  const std::string small_warning =
      overlap_warning(pair_contact_nodes(lower, "lower", upper, "upper", &small, 1e-6));
  EXPECT_NE(small_warning.find("3 of 3 contact pairs overlap"), std::string::npos) << small_warning;
}

TEST(ContactPairing, ExcludedPairClearanceMeasuresThePenetrationOfPrescribedNodes) {
  // Pair at x = 0 excluded (lower node clamped). Lower normal n1 = (0, 1), upper above.
  InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  const InterfaceDescription upper = flat_interface({0.0, 0.5, 1.0}, 0.0, -1.0);
  lower.fixed[0][0] = lower.fixed[0][1] = true;
  const ContactPairing pairing = pair_contact_nodes(lower, "lower", upper, "upper", nullptr, 1e-6);
  ASSERT_EQ(pairing.excluded_pairs.size(), 1u);
  // Upper node moved down by 0.01 onto a fixed lower node with d = 0: penetration
  // u1.n1 + u2.n2 - d = 0 + 0.01 - 0; scale: the included traces' 0.02.
  const auto pressed = [](int body, const ContactPair&) {
    return body == 0 ? Eigen::Vector3d(0.0, 0.0, 0.0) : Eigen::Vector3d(0.3, -0.01, 0.0);
  };
  const ExcludedPairClearance clearance = excluded_pair_clearance(pairing, pressed, 0.02);
  EXPECT_NEAR(clearance.relative_penetration, 0.01 / 0.02, 1e-15);
  EXPECT_NE(clearance.description.find("tag 100"), std::string::npos) << clearance.description;
  EXPECT_NE(clearance.description.find("0.01"), std::string::npos) << clearance.description;
  // Lifted off instead: no penetration.
  const auto lifted = [](int body, const ContactPair&) {
    return body == 0 ? Eigen::Vector3d(0.0, 0.0, 0.0) : Eigen::Vector3d(0.0, 0.01, 0.0);
  };
  EXPECT_EQ(excluded_pair_clearance(pairing, lifted, 0.02).relative_penetration, 0.0);
}

// The tolerance is relative to the shortest contact edge (0.5 here): a tangential offset of
// 0.9 of the tolerance pairs, 1.1 of it does not; a normal offset of any size (an open gap)
// pairs and enters the gap.
TEST(ContactPairing, TangentialOffsetIsComparedWithTheRelativeTolerance) {
  const double relative_tolerance = 1e-3, edge = 0.5;
  const InterfaceDescription lower = flat_interface({0.0, 0.5, 1.0}, 0.0, 1.0);
  for (const double fraction : {0.9, 1.1}) {
    const double offset = fraction * relative_tolerance * edge;
    const InterfaceDescription upper = flat_interface({0.0, 0.5 + offset, 1.0}, 0.25, -1.0);
    if (fraction < 1.0) {
      const ContactPairing pairing =
          pair_contact_nodes(lower, "lower", upper, "upper", nullptr, relative_tolerance);
      ASSERT_EQ(pairing.size(), 3u);
      for (const ContactPair& pair : pairing.pairs) EXPECT_NEAR(pair.gap, 0.25, 1e-15);
    } else {
      EXPECT_THROW(pair_contact_nodes(lower, "lower", upper, "upper", nullptr, relative_tolerance),
                   InputError);
    }
  }
}

}  // namespace
}  // namespace robin
