// FieldsReply as output travels (protocol 2.1): the server's encode_fields and the coordinator's
// decode_fields, without transport.
//  - the named boundaries of a body's mesh arrive unchanged (FieldsReply.boundaries), and the
//    stress arrives as the 6-component tensor with ParaView's component names;
//  - a reply without boundaries (a 2.0 server) decodes to a mesh without them, and its
//    3-component stress keeps the names xx, yy, xy;
//  - malformed boundaries (index out of range, a segment count that is not a multiple of the
//    nodes per segment, an area cell type, an empty or repeated name) are refused with a
//    MalformedReply naming the boundary.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "../test_bodies.hpp"
#include "numerics/body_output.hpp"
#include "numerics/contact_operator.hpp"
#include "remote/reply_decoding.hpp"
#include "server/reply_encoding.hpp"

namespace robin {
namespace {

/// The block [0, 2] x [0, 1] (4 x 2 cells of two quadratic triangles each), clamped at its
/// bottom, plane strain (nu = 0.25), its top pushed by contact forces of 1.
BodyOutput block_output() {
  BodySolver body(testing::plane_quadratic_block("block"));
  const InterfaceDescription top = body.contact_boundary();
  body.assign_contact(node_to_node_operator(
      top.node_ids, std::vector<Eigen::Vector3d>(top.node_ids.size(), Eigen::Vector3d(0, 1, 0.0)),
      top.weights));
  return make_body_output(body, Eigen::VectorXd::Ones(body.contact_size()));
}

const OutputField& field_named(const std::vector<OutputField>& fields, const std::string& name) {
  for (const OutputField& field : fields) {
    if (field.name == name) return field;
  }
  throw std::runtime_error("no field " + name);
}

TEST(FieldsReplyOutput, BoundariesAndTheStressTensorArriveUnchanged) {
  const BodyOutput sent = block_output();
  ASSERT_EQ(sent.mesh.boundaries.size(), 4u);
  protocol::FieldsReply message;
  encode_fields(sent, message);
  ASSERT_EQ(message.boundaries_size(), 4);
  const BodyOutput received = decode_fields(message, "block");
  ASSERT_EQ(received.mesh.boundaries.size(), 4u);
  for (const auto& [name, group] : sent.mesh.boundaries) {
    ASSERT_EQ(received.mesh.boundaries.count(name), 1u) << name;
    const BoundaryGroup& arrived = received.mesh.boundaries.at(name);
    EXPECT_EQ(arrived.type, FacetType::line3) << name;  // P2 triangles have 3-node edges
    EXPECT_EQ(arrived.connectivity, group.connectivity) << name;
  }
  {
    const OutputField& point = field_named(received.point_fields, "stress");
    const OutputField& cell = field_named(received.cell_fields, "stress");
    EXPECT_EQ(point.components, 6);
    EXPECT_EQ(point.component_names,
              (std::vector<std::string>{"XX", "YY", "ZZ", "XY", "YZ", "XZ"}));
    EXPECT_EQ(cell.component_names, point.component_names);
    EXPECT_EQ(point.values, field_named(sent.point_fields, "stress").values);
    // ZZ = nu (XX + YY) with nu = 0.25, YZ = XZ = 0, at every node
    for (std::size_t k = 0; k < point.values.size() / 6; ++k) {
      const double* tensor = point.values.data() + 6 * k;
      EXPECT_NEAR(tensor[2], 0.25 * (tensor[0] + tensor[1]),
                  1e-15 * (std::abs(tensor[0]) + std::abs(tensor[1])));
      EXPECT_EQ(tensor[4], 0.0);
      EXPECT_EQ(tensor[5], 0.0);
    }
  }
}

TEST(FieldsReplyOutput, ReplyOfAnOlderServerHasNoBoundariesAndThreeStressComponents) {
  protocol::FieldsReply message;
  encode_fields(block_output(), message);
  message.clear_boundaries();
  for (protocol::Field& field : *message.mutable_point_fields()) {
    if (field.name() != "stress") continue;
    google::protobuf::RepeatedField<double> in_plane;  // (xx, yy, xy) of each tensor
    for (int k = 0; k < field.values_size() / 6; ++k) {
      for (const int c : {0, 1, 3}) in_plane.Add(field.values(6 * k + c));
    }
    *field.mutable_values() = in_plane;
    field.set_components(3);
  }
  const BodyOutput received = decode_fields(message, "block");
  EXPECT_TRUE(received.mesh.boundaries.empty());
  const OutputField& stress = field_named(received.point_fields, "stress");
  EXPECT_EQ(stress.components, 3);
  EXPECT_EQ(stress.component_names, (std::vector<std::string>{"xx", "yy", "xy"}));
}

/// The message of the MalformedReply that decoding `message` throws, or "" when it decodes.
std::string refusal(const protocol::FieldsReply& message) {
  try {
    decode_fields(message, "block");
  } catch (const MalformedReply& error) {
    return error.what();
  }
  return "";
}

TEST(FieldsReplyOutput, MalformedBoundariesAreRefusedNamingTheBoundary) {
  protocol::FieldsReply good;
  encode_fields(block_output(), good);
  const int node_count = good.node_coordinates_size() / 2;
  const auto changed = [&](const std::function<void(protocol::NamedBoundary&)>& change) {
    protocol::FieldsReply message = good;
    change(*message.mutable_boundaries(1));
    return refusal(message);
  };
  const std::string name = good.boundaries(1).name();
  std::string text = changed([&](protocol::NamedBoundary& boundary) {
    boundary.mutable_segments()->set_connectivity(0, static_cast<std::uint32_t>(node_count));
  });
  EXPECT_NE(text.find("'" + name + "'"), std::string::npos) << text;
  EXPECT_NE(text.find(std::to_string(node_count)), std::string::npos) << text;
  text = changed([](protocol::NamedBoundary& boundary) {
    boundary.mutable_segments()->add_connectivity(0);  // 3 per LINE3 segment, now one more
  });
  EXPECT_NE(text.find("not a multiple of 3"), std::string::npos) << text;
  text = changed([](protocol::NamedBoundary& boundary) {
    boundary.mutable_segments()->set_type(protocol::TRIANGLE3);
  });
  EXPECT_NE(text.find("not LINE2 or LINE3"), std::string::npos) << text;
  text = changed([](protocol::NamedBoundary& boundary) { boundary.set_name(""); });
  EXPECT_NE(text.find("empty or repeated name"), std::string::npos) << text;
  text = changed(
      [&](protocol::NamedBoundary& boundary) { boundary.set_name(good.boundaries(0).name()); });
  EXPECT_NE(text.find("empty or repeated name"), std::string::npos) << text;
  EXPECT_EQ(refusal(good), "");
}

}  // namespace
}  // namespace robin
