// A body with several contact boundaries (the middle block of a stack touches its neighbours
// with its top and its bottom): the InterfaceDescription of the union of their nodes, and
// restrict_to_boundary(), which gives one boundary's description alone.
// The mesh is a real Gmsh mesh of the block [0, 2] x [0, 1] (a .geo meshed here, linear and
// quadratic), its four sides named physical curves split into segments of length 0.25 each
// (transfinite curves: 8 along x, 4 along y). The expected numbers come from that geometry, not
// from the code: the weight of a node is the integral of its shape function over the contact
// boundaries, so on a side of segments of length s = 0.25 it is s/2 at the side's ends and s
// inside (linear), s/6 at the ends, s/3 at the other vertices and 2s/3 at the midpoints
// (quadratic, Simpson), summed over the boundaries at a node they share; the weights add up to
// the boundaries' total length; the outward normals of the sides are the axis directions, and at
// the corner shared by "top" and "right" the length-weighted average of (0, 1) and (1, 0), i.e.
// (1, 1)/sqrt(2). restrict_to_boundary() must give exactly (bit for bit) the description of the
// same body with that one contact boundary, also at the shared corner; with one contact
// boundary the description is bit for bit that of the boundary's own normals and weights
// (numerics/elasticity.hpp), as before several boundaries existed. fill_surface_nodes(), which
// the coordinator uses on a server's reply, recomputes the per-boundary values of a shared node
// from the segments' coordinates alone.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "../test_files.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/interface_description.hpp"
#include "numerics/material.hpp"

namespace robin {
namespace {

constexpr double segment = 0.25;  // every boundary segment's length (transfinite curves)
// Gmsh places the inner nodes of a transfinite curve within about 2e-12 of their positions.
constexpr double placement = 1e-10;

constexpr const char* block_geo = R"(// [0, 2] x [0, 1], sides of segments of length 0.25
Point(1) = {0, 0, 0, 0.25};
Point(2) = {2, 0, 0, 0.25};
Point(3) = {2, 1, 0, 0.25};
Point(4) = {0, 1, 0, 0.25};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Transfinite Curve{1, 3} = 9;
Transfinite Curve{2, 4} = 5;
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
)";

/// The block meshed by Gmsh with elements of `order` (1 or 2), once per order.
const Mesh& block_mesh(int order) {
  static std::map<int, Mesh> meshes;
  auto found = meshes.find(order);
  if (found == meshes.end()) {
    const testing::TemporaryDirectory directory("contact-boundaries");
    const std::filesystem::path path = directory.path() / "block.geo";
    testing::write_text(path, block_geo);
    found = meshes.emplace(order, read_gmsh_mesh(path, {.element_order = order})).first;
  }
  return found->second;
}

/// The block clamped on "left" with the given contact boundaries.
BodyDefinition block(int order, std::vector<std::string> contact_boundaries) {
  BodyDefinition body;
  body.name = "middle";
  body.mesh = block_mesh(order);
  body.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "middle");
  body.dirichlet.push_back({"left", 0.0, 0.0, std::nullopt});
  body.contact_boundaries = std::move(contact_boundaries);
  return body;
}

InterfaceDescription description(int order, const std::vector<std::string>& contact_boundaries) {
  return BodySolver(block(order, contact_boundaries)).contact_boundary();
}

/// The weight of a node at `position` along a side [0, length] of segments of length 0.25.
double side_weight(int order, double position, double length) {
  const bool at_end = std::abs(position) < 1e-12 || std::abs(position - length) < 1e-12;
  if (order == 1) return at_end ? segment / 2 : segment;
  const double steps = position / (segment / 2);  // half-segments from the side's start
  const bool midpoint =
      std::abs(std::round(steps) - steps) < 1e-9 && static_cast<long>(std::round(steps)) % 2 == 1;
  if (midpoint) return 2.0 * segment / 3.0;
  return at_end ? segment / 6.0 : segment / 3.0;
}

void expect_same_surface(const ContactSurfaceDescription& actual,
                         const ContactSurfaceDescription& expected) {
  EXPECT_EQ(actual.boundary, expected.boundary);
  EXPECT_EQ(actual.facet_type, expected.facet_type);
  EXPECT_EQ(actual.facets, expected.facets);
  EXPECT_EQ(actual.positions, expected.positions);
  EXPECT_EQ(actual.normals, expected.normals);
  EXPECT_EQ(actual.weights, expected.weights);
}

/// Every member equal, bit for bit.
void expect_same_description(const InterfaceDescription& actual,
                             const InterfaceDescription& expected) {
  EXPECT_EQ(actual.node_ids, expected.node_ids);
  EXPECT_EQ(actual.node_tags, expected.node_tags);
  EXPECT_EQ(actual.coordinates, expected.coordinates);
  EXPECT_EQ(actual.normals, expected.normals);
  EXPECT_EQ(actual.weights, expected.weights);
  EXPECT_EQ(actual.fixed, expected.fixed);
  EXPECT_EQ(actual.dof_count, expected.dof_count);
  ASSERT_EQ(actual.surfaces.size(), expected.surfaces.size());
  for (std::size_t k = 0; k < actual.surfaces.size(); ++k) {
    SCOPED_TRACE("surface " + std::to_string(k));
    expect_same_surface(actual.surfaces[k], expected.surfaces[k]);
  }
}

TEST(ContactBoundaries, TopAndBottomGiveTheUnionWithTheBoundariesWeightsAndNormals) {
  for (const int order : {1, 2}) {
    SCOPED_TRACE("order " + std::to_string(order));
    const InterfaceDescription interface = description(order, {"top", "bottom"});
    const std::size_t per_side = order == 1 ? 9 : 17;  // nodes on a side of 8 segments
    ASSERT_EQ(interface.node_ids.size(), 2 * per_side);
    EXPECT_TRUE(std::is_sorted(interface.node_ids.begin(), interface.node_ids.end()));
    EXPECT_EQ(std::set<int>(interface.node_ids.begin(), interface.node_ids.end()).size(),
              interface.node_ids.size());
    double total = 0.0;
    for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
      const Eigen::Vector3d& point = interface.coordinates[i];
      const bool top = std::abs(point.y() - 1.0) < 1e-12;
      ASSERT_TRUE(top || std::abs(point.y()) < 1e-12) << point.transpose();
      EXPECT_NEAR(interface.weights[i], side_weight(order, point.x(), 2.0), placement)
          << point.transpose();
      EXPECT_NEAR(interface.normals[i].x(), 0.0, 1e-12);
      EXPECT_NEAR(interface.normals[i].y(), top ? 1.0 : -1.0, 1e-12);
      EXPECT_EQ(interface.fixed[i][0], std::abs(point.x()) < 1e-12);  // "left" is clamped
      total += interface.weights[i];
    }
    EXPECT_NEAR(total, 4.0, 1e-12);  // the two boundaries' total length

    ASSERT_EQ(interface.surfaces.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      const ContactSurfaceDescription& surface = interface.surfaces[k];
      EXPECT_EQ(surface.boundary, k == 0 ? "top" : "bottom");
      EXPECT_EQ(surface.facet_type, order == 1 ? FacetType::line2 : FacetType::line3);
      const int count = order + 1;
      ASSERT_EQ(surface.facets.size(), 8u * static_cast<std::size_t>(count));
      ASSERT_EQ(surface.positions.size(), per_side);
      double length = 0.0;
      for (std::size_t e = 0; e < 8; ++e) {
        const Eigen::Vector3d& from = interface.coordinates[surface.facets[e * count]];
        const Eigen::Vector3d& to = interface.coordinates[surface.facets[e * count + 1]];
        // body on the left: the top is traversed towards -x, the bottom towards +x
        EXPECT_NEAR(to.x() - from.x(), k == 0 ? -segment : segment, placement);
        EXPECT_NEAR(from.y(), k == 0 ? 1.0 : 0.0, 1e-12);
        length += (to - from).norm();
      }
      EXPECT_NEAR(length, 2.0, 1e-12);
      double weight_sum = 0.0;
      for (std::size_t j = 0; j < surface.positions.size(); ++j) {
        const auto position = static_cast<std::size_t>(surface.positions[j]);
        // no node is shared: the boundary's own values are the union's
        EXPECT_EQ(surface.weights[j], interface.weights[position]);
        EXPECT_EQ(surface.normals[j], interface.normals[position]);
        weight_sum += surface.weights[j];
      }
      EXPECT_NEAR(weight_sum, 2.0, 1e-12);
    }
  }
}

TEST(ContactBoundaries, ASharedCornerAppearsOnceWithSummedWeightAndAveragedNormal) {
  for (const int order : {1, 2}) {
    SCOPED_TRACE("order " + std::to_string(order));
    const InterfaceDescription interface = description(order, {"top", "right"});
    const std::size_t top_nodes = order == 1 ? 9 : 17, right_nodes = order == 1 ? 5 : 9;
    ASSERT_EQ(interface.node_ids.size(), top_nodes + right_nodes - 1);
    double total = 0.0;
    int corners = 0;
    for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
      const Eigen::Vector3d& point = interface.coordinates[i];
      total += interface.weights[i];
      if ((point - Eigen::Vector3d(2.0, 1.0, 0.0)).norm() > 1e-12) continue;
      ++corners;
      const double end = order == 1 ? segment / 2 : segment / 6;
      EXPECT_NEAR(interface.weights[i], 2.0 * end, 1e-12);  // an end of both boundaries
      EXPECT_NEAR(interface.normals[i].x(), 1.0 / std::sqrt(2.0), 1e-12);
      EXPECT_NEAR(interface.normals[i].y(), 1.0 / std::sqrt(2.0), 1e-12);
      for (const ContactSurfaceDescription& surface : interface.surfaces) {
        const auto at =
            std::find(surface.positions.begin(), surface.positions.end(), static_cast<int>(i));
        ASSERT_NE(at, surface.positions.end()) << surface.boundary;
        const auto j = static_cast<std::size_t>(at - surface.positions.begin());
        EXPECT_NEAR(surface.weights[j], end, 1e-12) << surface.boundary;
        const Eigen::Vector3d outward = surface.boundary == "top" ? Eigen::Vector3d(0.0, 1.0, 0.0)
                                                                  : Eigen::Vector3d(1.0, 0.0, 0.0);
        EXPECT_NEAR((surface.normals[j] - outward).norm(), 0.0, 1e-12) << surface.boundary;
      }
    }
    EXPECT_EQ(corners, 1);
    EXPECT_NEAR(total, 3.0, 1e-12);  // top (2) + right (1)
  }
}

TEST(ContactBoundaries, RestrictionIsExactlyTheBodyWithThatBoundaryAlone) {
  for (const int order : {1, 2}) {
    for (const std::vector<std::string>& boundaries :
         {std::vector<std::string>{"top", "bottom"}, std::vector<std::string>{"top", "right"},
          std::vector<std::string>{"right", "top", "bottom"}}) {
      const InterfaceDescription interface = description(order, boundaries);
      for (const std::string& boundary : boundaries) {
        SCOPED_TRACE("order " + std::to_string(order) + ", " + std::to_string(boundaries.size()) +
                     " boundaries, restricted to " + boundary);
        expect_same_description(restrict_to_boundary(interface, boundary),
                                description(order, {boundary}));
      }
    }
  }
}

TEST(ContactBoundaries, OneBoundaryIsItsOwnNormalsAndWeightsAndItsOwnRestriction) {
  for (const int order : {1, 2}) {
    SCOPED_TRACE("order " + std::to_string(order));
    const Mesh& mesh = block_mesh(order);
    const BoundaryGroup& group = mesh.boundary("top");
    const InterfaceDescription interface = description(order, {"top"});
    EXPECT_EQ(interface.node_ids, group.nodes());
    EXPECT_EQ(interface.normals, boundary_node_normals(mesh, group));
    const Eigen::VectorXd weights = boundary_weights(mesh, group);
    ASSERT_EQ(interface.weights.size(), interface.node_ids.size());
    for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
      EXPECT_EQ(interface.weights[i], weights[interface.node_ids[i]]);
    }
    ASSERT_EQ(interface.surfaces.size(), 1u);
    const ContactSurfaceDescription& surface = interface.surfaces.front();
    EXPECT_EQ(surface.normals, interface.normals);
    EXPECT_EQ(surface.weights, interface.weights);
    ASSERT_EQ(surface.positions.size(), interface.node_ids.size());
    for (std::size_t i = 0; i < surface.positions.size(); ++i) {
      EXPECT_EQ(surface.positions[i], static_cast<int>(i));
    }
    expect_same_description(restrict_to_boundary(interface, "top"), interface);
  }
}

TEST(ContactBoundaries, PerBoundaryValuesAreRecomputedFromTheSegmentsAlone) {
  // What the coordinator does with a server's reply, which carries the segments only.
  for (const int order : {1, 2}) {
    SCOPED_TRACE("order " + std::to_string(order));
    const InterfaceDescription body = description(order, {"top", "right", "bottom"});
    InterfaceDescription received = body;
    for (ContactSurfaceDescription& surface : received.surfaces) {
      surface.positions.clear();
      surface.normals.clear();
      surface.weights.clear();
    }
    for (std::size_t k = 0; k < received.surfaces.size(); ++k) {
      ContactSurfaceDescription& surface = received.surfaces[k];
      fill_surface_nodes(received, surface);
      const ContactSurfaceDescription& expected = body.surfaces[k];
      EXPECT_EQ(surface.positions, expected.positions) << surface.boundary;
      ASSERT_EQ(surface.normals.size(), expected.normals.size());
      for (std::size_t j = 0; j < surface.positions.size(); ++j) {
        EXPECT_NEAR((surface.normals[j] - expected.normals[j]).norm(), 0.0, 1e-14);
        EXPECT_NEAR(surface.weights[j], expected.weights[j], 1e-15);
      }
    }
    // restrict_to_boundary fills the per-boundary values itself when they are missing
    InterfaceDescription bare = body;
    for (ContactSurfaceDescription& surface : bare.surfaces) surface.positions.clear();
    const InterfaceDescription right = restrict_to_boundary(bare, "right");
    const InterfaceDescription expected = description(order, {"right"});
    EXPECT_EQ(right.node_ids, expected.node_ids);
    ASSERT_EQ(right.weights.size(), expected.weights.size());
    for (std::size_t i = 0; i < right.weights.size(); ++i) {
      EXPECT_NEAR(right.weights[i], expected.weights[i], 1e-15);
      EXPECT_NEAR((right.normals[i] - expected.normals[i]).norm(), 0.0, 1e-14);
    }
    EXPECT_EQ(right.surfaces.front().facets, expected.surfaces.front().facets);
  }
}

TEST(ContactBoundaries, UnknownRepeatedOrMissingBoundariesAreInputErrors) {
  const InterfaceDescription interface = description(1, {"top", "bottom"});
  try {
    restrict_to_boundary(interface, "left");
    ADD_FAILURE() << "no error for a boundary that is not a contact boundary";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("'left' is not a contact boundary"), std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("'top', 'bottom'"), std::string::npos) << error.what();
  }
  try {
    BodySolver solver(block(1, {"top", "bottom", "top"}));
    ADD_FAILURE() << "no error for a repeated contact boundary";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("contact boundary 'top' is named twice"),
              std::string::npos)
        << error.what();
  }
  EXPECT_THROW(BodySolver(block(1, {})), InputError);
  EXPECT_THROW(BodySolver(block(1, {"top", "nowhere"})), InputError);
}

}  // namespace
}  // namespace robin
