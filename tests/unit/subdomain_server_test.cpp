// SubdomainServer::handle, in process: a whole run (Hello, SetupBody, AssignContact, contact
// and correction solves, fields, EndRun, a second run) compared with a BodySolver built
// directly from the same body definition, the equilibrium of the returned fields, and every
// error reply of the state machine. The Neumann solve of protocol 1.1 (NeumannSolveRequest)
// against the normal trace of BodySolver::displacement, its refusals, and a server that
// withholds it (as a protocol 1.0 server would not know it). The run rule of protocol 1.2
// (Envelope.run_id): requests of another run than the body's are WRONG_STATE and change nothing,
// the body's run and requests without run_id are served, and a server playing 1.1 ignores it.
// Protocol 2.0: the mesh travels as MeshData, AssignContact carries a general constraint
// operator B (rows over (node, component) pairs), InterfaceDescription describes the contact
// surface with its segments. The attacks of issue 11 each fail to run or read anything, and the
// server answers a Hello after each: a 1.x .geo script in the removed mesh_content field (a
// command that would create a file), mesh_path outside the data directory (absolute, "..", a
// symbolic link), write_directory outside the output root (absolute, "..", a symbolic link, a
// link at the target file), a huge body name, inverted and degenerate cells, and results that
// overflow to infinities (SOLVER_FAILURE, never a reply carrying NaN or Inf).

#include "server/subdomain_server.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <google/protobuf/unknown_field_set.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "../hostile_geo_scripts.hpp"
#include "../test_files.hpp"
#include "mesh_codec.hpp"
#include "numerics/body_output.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/material.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

const std::filesystem::path lower_geo =
    std::filesystem::path(ROBIN_EXAMPLES) / "meshes/block_lower.geo";

using testing::file_text;
using testing::TemporaryDirectory;
using testing::write_text;

/// block_lower.geo meshed with h = 0.1, once per process.
const Mesh& lower_mesh() {
  static const Mesh mesh = read_gmsh_mesh(lower_geo, {.size = 0.1});
  return mesh;
}

/// Body 1 of examples/two_blocks.toml: block_lower.geo with h = 0.1 (sent as MeshData), plane
/// strain, E = 1000, nu = 0.3, clamped bottom, contact boundary "contact".
protocol::SetupBody lower_block_setup() {
  protocol::SetupBody setup;
  setup.set_body_name("lower");
  *setup.mutable_mesh() = encode_mesh(lower_mesh());
  setup.set_model(protocol::PLANE_STRAIN);
  setup.set_young_modulus(1000.0);
  setup.set_poisson_ratio(0.3);
  protocol::Dirichlet& bottom = *setup.add_dirichlet();
  bottom.set_boundary("bottom");
  bottom.set_x(0.0);
  bottom.set_y(0.0);
  setup.add_contact_boundaries("contact");
  return setup;
}

/// The same body built without the server.
BodyDefinition lower_block_definition() {
  BodyDefinition definition;
  definition.name = "lower";
  definition.mesh = lower_mesh();
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  definition.contact_boundaries = {"contact"};
  return definition;
}

protocol::Envelope request(std::uint64_t id, unsigned major = protocol::protocol_major) {
  protocol::Envelope envelope;
  envelope.mutable_version()->set_major(major);
  envelope.mutable_version()->set_minor(0);
  envelope.set_request_id(id);
  return envelope;
}

/// Sends `envelope` through handle() and parses the reply; checks the echoed id and version.
protocol::Envelope exchange(SubdomainServer& server, const protocol::Envelope& envelope,
                            unsigned major = protocol::protocol_major) {
  protocol::Envelope reply;
  EXPECT_TRUE(reply.ParseFromString(server.handle(envelope.SerializeAsString())));
  EXPECT_EQ(reply.request_id(), envelope.request_id());
  EXPECT_EQ(reply.version().major(), major);
  EXPECT_EQ(reply.version().minor(), protocol::protocol_minor);
  return reply;
}

protocol::Envelope setup_request(std::uint64_t id, const protocol::SetupBody& setup) {
  protocol::Envelope envelope = request(id);
  *envelope.mutable_setup_body() = setup;
  return envelope;
}

protocol::Envelope contact_solve_request(std::uint64_t id, const Eigen::VectorXd& obstacle) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_contact_solve()->set_iteration(static_cast<unsigned>(id));
  envelope.mutable_contact_solve()->mutable_obstacle()->Assign(obstacle.begin(), obstacle.end());
  return envelope;
}

/// AssignContact with the constraint operator `contact`, written here field by field.
protocol::Envelope assign_request(std::uint64_t id, const ContactOperator& contact) {
  protocol::Envelope envelope = request(id);
  protocol::AssignContact& assign = *envelope.mutable_assign_contact();
  for (const std::size_t offset : contact.row_offsets) assign.add_row_offsets(offset);
  for (std::size_t k = 0; k < contact.entry_count(); ++k) {
    assign.add_node_ids(contact.nodes[k]);
    assign.add_components(static_cast<std::uint32_t>(contact.components[k]));
    assign.add_values(contact.values[k]);
  }
  for (const double weight : contact.weights) assign.add_weights(weight);
  return envelope;
}

ContactOperator assign_all(const InterfaceDescription& interface) {
  return node_to_node_operator(
      interface.node_ids, std::vector<Eigen::Vector3d>(interface.node_ids.size(), {0.0, 1.0, 0.0}),
      interface.weights);
}

/// Every contact boundary node of `interface`, with the normal (0, 1), in ascending id order:
/// one row per node, entries (node, x) = 0 and (node, y) = 1, weight m_i.
protocol::Envelope assign_all_request(std::uint64_t id, const InterfaceDescription& interface) {
  return assign_request(id, assign_all(interface));
}

/// NeumannSolveRequest (protocol 1.1) with the contact force `force`.
protocol::Envelope neumann_solve_request(std::uint64_t id, const Eigen::VectorXd& force) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_neumann_solve()->set_iteration(static_cast<unsigned>(id));
  envelope.mutable_neumann_solve()->mutable_contact_force()->Assign(force.begin(), force.end());
  return envelope;
}

Eigen::VectorXd to_vector(const google::protobuf::RepeatedField<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
}

/// |a_i - b_i| <= 1e-12 (1 + |b_i|) for all i, with equal sizes.
void expect_equal_vectors(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  ASSERT_EQ(a.size(), b.size());
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i], b[i], 1e-12 * (1.0 + std::abs(b[i]))) << "entry " << i;
  }
}

void expect_error(const protocol::Envelope& reply, protocol::ErrorCode code,
                  const std::string& state) {
  ASSERT_TRUE(reply.has_error()) << reply.DebugString();
  EXPECT_EQ(protocol::ErrorCode_Name(reply.error().code()), protocol::ErrorCode_Name(code))
      << reply.error().message();
  EXPECT_EQ(reply.error().state(), state);
}

/// An obstacle that presses the right half of the contact edge down (g = -0.002 x) and leaves
/// the left half free, so that the active set is a proper subset.
Eigen::VectorXd sloped_obstacle(const InterfaceDescription& interface) {
  Eigen::VectorXd obstacle(static_cast<Eigen::Index>(interface.node_ids.size()));
  for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
    obstacle[static_cast<Eigen::Index>(i)] = -0.002 * interface.coordinates[i].x();
  }
  return obstacle;
}

ServerSettings quiet_settings() {
  ServerSettings settings;
  settings.name = "unit test";
  settings.mesh_reader = ROBIN_MESH_READER;
  return settings;
}

/// Checks the InterfaceDescription against the directly built solver, and against the
/// geometry of block_lower.geo: 21 nodes on y = 0 from x = -1 to 1, normals (0, 1), weights
/// summing to the edge length 2, none of them fixed (only the bottom is clamped), and the
/// contact surface "contact": 20 segments covering the edge, each oriented with the body on its
/// left (the block lies below the edge, so each segment runs towards -x).
void expect_interface(const protocol::InterfaceDescription& message,
                      const InterfaceDescription& expected, const BodySolver& reference) {
  EXPECT_EQ(message.body_name(), "lower");
  EXPECT_EQ(message.dimension(), 2u);
  ASSERT_EQ(message.node_ids_size(), 21);
  ASSERT_EQ(expected.node_ids.size(), 21u);
  ASSERT_EQ(message.fixed_size(), 42);
  double weight_sum = 0.0;
  for (int i = 0; i < 21; ++i) {
    EXPECT_EQ(message.node_ids(i), expected.node_ids[i]);
    EXPECT_EQ(message.node_tags(i), static_cast<std::int64_t>(expected.node_tags[i]));
    EXPECT_NEAR(message.coordinates(2 * i), expected.coordinates[i].x(), 1e-12);
    EXPECT_NEAR(message.coordinates(2 * i + 1), 0.0, 1e-12);
    EXPECT_NEAR(message.normals(2 * i), 0.0, 1e-12);
    EXPECT_NEAR(message.normals(2 * i + 1), 1.0, 1e-12);
    EXPECT_NEAR(message.weights(i), expected.weights[i], 1e-12);
    EXPECT_FALSE(message.fixed(2 * i));
    EXPECT_FALSE(message.fixed(2 * i + 1));
    weight_sum += message.weights(i);
  }
  EXPECT_NEAR(weight_sum, 2.0, 1e-12);
  ASSERT_EQ(message.surfaces_size(), 1);
  const protocol::ContactSurface& surface = message.surfaces(0);
  EXPECT_EQ(surface.boundary(), "contact");
  EXPECT_EQ(surface.segment_type(), protocol::LINE2);
  ASSERT_EQ(surface.segments_size(), 40);
  EXPECT_EQ(std::vector<int>(surface.segments().begin(), surface.segments().end()),
            expected.surfaces.at(0).facets);
  std::set<std::uint32_t> covered;
  double length = 0.0;
  for (int e = 0; e < 20; ++e) {
    const std::uint32_t first = surface.segments(2 * e), second = surface.segments(2 * e + 1);
    ASSERT_LT(first, 21u);
    ASSERT_LT(second, 21u);
    const double from = message.coordinates(static_cast<int>(2 * first));
    const double to = message.coordinates(static_cast<int>(2 * second));
    EXPECT_LT(to, from) << "segment " << e << " is not oriented with the body on its left";
    length += from - to;
    covered.insert(first);
    covered.insert(second);
  }
  EXPECT_EQ(covered.size(), 21u);
  EXPECT_NEAR(length, 2.0, 1e-12);
  EXPECT_EQ(message.dof_count(), static_cast<std::uint64_t>(reference.free_dof_count()));
  EXPECT_GT(message.setup_seconds(), 0.0);
}

/// The contact result equals the reference solve, and satisfies the Signorini conditions.
void expect_contact_result(const protocol::ContactSolveResult& message,
                           const ContactSolveResult& expected, const Eigen::VectorXd& obstacle) {
  EXPECT_EQ(message.status(), protocol::CONVERGED) << message.message();
  EXPECT_EQ(static_cast<int>(message.qp_iterations()), expected.iterations);
  expect_equal_vectors(to_vector(message.normal_trace()), expected.normal_trace);
  expect_equal_vectors(to_vector(message.contact_force()), expected.contact_force);
  ASSERT_EQ(message.active_size(), obstacle.size());
  int active_count = 0;
  for (int i = 0; i < obstacle.size(); ++i) {
    EXPECT_EQ(message.active(i), static_cast<bool>(expected.active[i]));
    EXPECT_GE(message.contact_force(i), 0.0);
    EXPECT_LE(message.normal_trace(i), obstacle[i] + 1e-10);
    active_count += message.active(i) ? 1 : 0;
  }
  EXPECT_GT(active_count, 0);
  EXPECT_LT(active_count, obstacle.size());
  EXPECT_NEAR(message.penetration(), expected.penetration, 1e-15);
  EXPECT_NEAR(message.complementarity(), expected.complementarity, 1e-15);
  EXPECT_GE(message.compute_seconds(), 0.0);
}

/// The fields equal make_body_output of the reference, and the body is in equilibrium: the
/// reactions balance the contact forces -lambda_i (0, 1) (no other load).
void expect_fields(const protocol::FieldsReply& message, const BodySolver& reference,
                   const Eigen::VectorXd& contact_force) {
  const BodyOutput expected = make_body_output(reference, contact_force);
  const Mesh& mesh = reference.mesh();
  ASSERT_EQ(message.node_coordinates_size(), 2 * static_cast<int>(mesh.node_count()));
  for (std::size_t k = 0; k < mesh.node_count(); ++k) {
    EXPECT_EQ(message.node_coordinates(2 * k), mesh.nodes[k].x());
    EXPECT_EQ(message.node_coordinates(2 * k + 1), mesh.nodes[k].y());
    EXPECT_EQ(message.node_tags(k), static_cast<std::int64_t>(mesh.node_tags[k]));
  }
  ASSERT_EQ(message.cell_types_size(), static_cast<int>(mesh.blocks.size()));
  ASSERT_EQ(message.cell_offsets_size(), message.cell_types_size() + 1);
  std::vector<std::int64_t> connectivity;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    EXPECT_EQ(message.cell_types(b), 5u);  // linear triangles from the .geo
    connectivity.insert(connectivity.end(), mesh.blocks[b].connectivity.begin(),
                        mesh.blocks[b].connectivity.end());
    EXPECT_EQ(message.cell_offsets(b + 1), connectivity.size());
  }
  EXPECT_EQ(std::vector<std::int64_t>(message.connectivity().begin(), message.connectivity().end()),
            connectivity);
  ASSERT_EQ(message.point_fields_size(), static_cast<int>(expected.point_fields.size()));
  for (int f = 0; f < message.point_fields_size(); ++f) {
    EXPECT_EQ(message.point_fields(f).name(), expected.point_fields[f].name);
    EXPECT_EQ(static_cast<int>(message.point_fields(f).components()),
              expected.point_fields[f].components);
    EXPECT_EQ(std::vector<double>(message.point_fields(f).values().begin(),
                                  message.point_fields(f).values().end()),
              expected.point_fields[f].values);
  }
  ASSERT_EQ(message.cell_fields_size(), static_cast<int>(expected.cell_fields.size()));
  EXPECT_EQ(message.cell_fields(1).name(), "von_mises");
  ASSERT_EQ(message.reaction_resultant_size(), 2);
  ASSERT_EQ(message.applied_force_size(), 2);
  EXPECT_EQ(message.applied_force(0), 0.0);
  EXPECT_EQ(message.applied_force(1), 0.0);
  const double total_contact_force = contact_force.sum();
  EXPECT_GT(total_contact_force, 0.0);
  EXPECT_NEAR(message.reaction_resultant(0), 0.0, 1e-9 * total_contact_force);
  EXPECT_NEAR(message.reaction_resultant(1), total_contact_force, 1e-9 * total_contact_force);
}

/// A correction (r_i = 1 + x_i) and the fields for `contact_force`, written to the directory
/// "fields/run" under the server's output root `output_root`, compared with `reference`.
void expect_correction_and_fields(SubdomainServer& server, const BodySolver& reference,
                                  const InterfaceDescription& interface,
                                  const Eigen::VectorXd& contact_force,
                                  const std::filesystem::path& output_root) {
  protocol::Envelope correction = request(5);
  Eigen::VectorXd interface_force(21);
  for (int i = 0; i < 21; ++i) interface_force[i] = 1.0 + interface.coordinates[i].x();
  correction.mutable_correction()->mutable_interface_force()->Assign(interface_force.begin(),
                                                                     interface_force.end());
  protocol::Envelope reply = exchange(server, correction);
  ASSERT_TRUE(reply.has_correction_result()) << reply.DebugString();
  expect_equal_vectors(to_vector(reply.correction_result().normal_trace()),
                       reference.solve_correction(interface_force));

  const std::filesystem::path directory = std::filesystem::canonical(output_root) / "fields/run";
  protocol::Envelope fields = request(6);
  fields.mutable_fields()->mutable_contact_force()->Assign(contact_force.begin(),
                                                           contact_force.end());
  fields.mutable_fields()->set_write_directory("fields/run");
  reply = exchange(server, fields);
  ASSERT_TRUE(reply.has_fields_reply()) << reply.DebugString();
  expect_fields(reply.fields_reply(), reference, contact_force);
  EXPECT_EQ(reply.fields_reply().written_file(), (directory / "lower.vtu").string());
  EXPECT_TRUE(std::filesystem::is_regular_file(directory / "lower.vtu"));
  // Written to a temporary name and renamed: nothing else is left in the directory.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(directory),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(SubdomainServer, FullRunMatchesADirectlyBuiltBodySolver) {
  const TemporaryDirectory output_root("output");
  ServerSettings settings = quiet_settings();
  settings.output_root = output_root.path();
  SubdomainServer server(settings);
  BodySolver reference(lower_block_definition());
  const InterfaceDescription interface = reference.contact_boundary();

  protocol::Envelope hello = request(1);
  hello.mutable_hello()->set_client_name("subdomain_server_test");
  protocol::Envelope reply = exchange(server, hello);
  ASSERT_TRUE(reply.has_hello_reply()) << reply.DebugString();
  EXPECT_EQ(reply.hello_reply().state(), "awaiting_setup");
  EXPECT_NE(reply.hello_reply().server_name().find("unit test"), std::string::npos);
  EXPECT_EQ(std::vector<std::string>(reply.hello_reply().capabilities().begin(),
                                     reply.hello_reply().capabilities().end()),
            (std::vector<std::string>{"contact_solve", "correction_solve", "fields",
                                      "neumann_solve", "status"}));

  reply = exchange(server, setup_request(2, lower_block_setup()));
  ASSERT_TRUE(reply.has_interface()) << reply.DebugString();
  expect_interface(reply.interface(), interface, reference);
  EXPECT_EQ(server.state(), ServerState::awaiting_assignment);

  reply = exchange(server, assign_all_request(3, interface));
  ASSERT_TRUE(reply.has_acknowledge()) << reply.DebugString();
  EXPECT_EQ(reply.acknowledge().state(), "ready");
  reference.assign_contact(assign_all(interface));

  // Two solves: the second is warm-started from the first on both sides.
  const Eigen::VectorXd first_obstacle = sloped_obstacle(interface);
  const Eigen::VectorXd second_obstacle = 0.5 * first_obstacle.array() - 0.0002;
  ContactSolveResult expected;
  for (const Eigen::VectorXd& obstacle : {first_obstacle, second_obstacle}) {
    reply = exchange(server, contact_solve_request(4, obstacle));
    ASSERT_TRUE(reply.has_contact_result()) << reply.DebugString();
    expected = reference.solve_contact(obstacle);
    expect_contact_result(reply.contact_result(), expected, obstacle);
  }

  expect_correction_and_fields(server, reference, interface, expected.contact_force,
                               output_root.path());

  protocol::Envelope end_run = request(7);
  end_run.mutable_end_run();
  reply = exchange(server, end_run);
  ASSERT_TRUE(reply.has_acknowledge());
  EXPECT_EQ(reply.acknowledge().state(), "awaiting_setup");
  expect_error(exchange(server, contact_solve_request(8, first_obstacle)), protocol::WRONG_STATE,
               "awaiting_setup");

  // A second run on the same server starts without the previous warm start.
  ASSERT_TRUE(exchange(server, setup_request(9, lower_block_setup())).has_interface());
  ASSERT_TRUE(exchange(server, assign_all_request(10, interface)).has_acknowledge());
  reference.assign_contact(assign_all(interface));  // resets the reference's warm start
  reply = exchange(server, contact_solve_request(11, second_obstacle));
  ASSERT_TRUE(reply.has_contact_result());
  expect_contact_result(reply.contact_result(), reference.solve_contact(second_obstacle),
                        second_obstacle);
}

protocol::Envelope hello_request(std::uint64_t id, unsigned major = protocol::protocol_major) {
  protocol::Envelope envelope = request(id, major);
  envelope.mutable_hello()->set_client_name("subdomain_server_test");
  return envelope;
}

/// A server with the lower block set up and every contact node assigned.
class ReadyServer : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
    ASSERT_TRUE(exchange(server, assign_all_request(2, interface)).has_acknowledge());
    ASSERT_EQ(server.state(), ServerState::ready);
  }

  SubdomainServer server{quiet_settings()};
  BodySolver reference{lower_block_definition()};
  InterfaceDescription interface = reference.contact_boundary();
};

TEST(SubdomainServer, GarbageBytesGetMalformedMessageAndTheNextRequestWorks) {
  SubdomainServer server(quiet_settings());
  protocol::Envelope reply;
  ASSERT_TRUE(reply.ParseFromString(server.handle("\xff\xff\xff this is not a protobuf")));
  expect_error(reply, protocol::MALFORMED_MESSAGE, "awaiting_setup");
  EXPECT_EQ(reply.request_id(), 0u);
  EXPECT_EQ(reply.version().major(), protocol::protocol_major);
  const protocol::Envelope hello = exchange(server, hello_request(7));
  ASSERT_TRUE(hello.has_hello_reply());
  EXPECT_EQ(hello.hello_reply().state(), "awaiting_setup");
}

TEST(SubdomainServer, EnvelopeWithoutVersionOrContentIsMalformed) {
  SubdomainServer server(quiet_settings());
  protocol::Envelope no_version;
  no_version.set_request_id(3);
  no_version.mutable_hello();
  expect_error(exchange(server, no_version), protocol::MALFORMED_MESSAGE, "awaiting_setup");
  expect_error(exchange(server, request(4)), protocol::MALFORMED_MESSAGE, "awaiting_setup");
}

TEST(SubdomainServer, ReplyTypeSentAsRequestIsUnsupported) {
  SubdomainServer server(quiet_settings());
  protocol::Envelope envelope = request(5);
  envelope.mutable_acknowledge()->set_state("ready");
  const protocol::Envelope reply = exchange(server, envelope);
  expect_error(reply, protocol::UNSUPPORTED, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("Acknowledge is a reply"), std::string::npos);
}

TEST(SubdomainServer, RequestTypeUnknownToThisVersionIsUnsupported) {
  SubdomainServer server(quiet_settings());
  // An Envelope whose content is a field this version does not know (number 40, empty bytes),
  // as a newer minor version could send: tag (40 << 3 | 2) = 322 = varint C2 02, length 0.
  const std::string bytes = request(8).SerializeAsString() + std::string("\xc2\x02\x00", 3);
  protocol::Envelope reply;
  ASSERT_TRUE(reply.ParseFromString(server.handle(bytes)));
  EXPECT_EQ(reply.request_id(), 8u);
  expect_error(reply, protocol::UNSUPPORTED, "awaiting_setup");
}

TEST(SubdomainServer, OtherMajorVersionIsAMismatchNamingBothVersions) {
  SubdomainServer server(quiet_settings());
  ASSERT_EQ(protocol::protocol_major, 2u);
  const protocol::Envelope reply = exchange(server, hello_request(9, 1));  // a 1.x coordinator
  expect_error(reply, protocol::VERSION_MISMATCH, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("the request speaks 1.0"), std::string::npos)
      << reply.error().message();
  const std::string ours =
      std::to_string(protocol::protocol_major) + "." + std::to_string(protocol::protocol_minor);
  EXPECT_NE(reply.error().message().find("this server " + ours), std::string::npos)
      << reply.error().message();
  EXPECT_TRUE(exchange(server, hello_request(10)).has_hello_reply());  // still serving
}

TEST(SubdomainServer, ConfiguredMajorVersionIsAnnouncedAndRequired) {
  ServerSettings settings = quiet_settings();
  settings.protocol_major = 7;
  SubdomainServer server(settings);
  expect_error(exchange(server, hello_request(1), 7), protocol::VERSION_MISMATCH, "awaiting_setup");
  EXPECT_TRUE(exchange(server, hello_request(2, 7), 7).has_hello_reply());
}

TEST(SubdomainServer, SolveBeforeSetupOrAssignmentIsWrongState) {
  SubdomainServer server(quiet_settings());
  protocol::Envelope reply = exchange(server, contact_solve_request(1, Eigen::VectorXd::Zero(21)));
  expect_error(reply, protocol::WRONG_STATE, "awaiting_setup");
  EXPECT_EQ(reply.error().message(), "ContactSolveRequest before SetupBody: send SetupBody first");
  protocol::Envelope assign = request(2);
  assign.mutable_assign_contact();
  expect_error(exchange(server, assign), protocol::WRONG_STATE, "awaiting_setup");

  ASSERT_TRUE(exchange(server, setup_request(3, lower_block_setup())).has_interface());
  reply = exchange(server, contact_solve_request(4, Eigen::VectorXd::Zero(21)));
  expect_error(reply, protocol::WRONG_STATE, "awaiting_assignment");
  EXPECT_NE(reply.error().message().find("before AssignContact"), std::string::npos);
  protocol::Envelope fields = request(5);
  fields.mutable_fields();
  expect_error(exchange(server, fields), protocol::WRONG_STATE, "awaiting_assignment");
}

TEST_F(ReadyServer, ObstacleOfWrongLengthIsInvalidAndTheStateIsKept) {
  const protocol::Envelope reply =
      exchange(server, contact_solve_request(3, Eigen::VectorXd::Zero(20)));
  expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
  EXPECT_NE(
      reply.error().message().find("20 values for the 21 contact constraints of body 'lower'"),
      std::string::npos)
      << reply.error().message();
  Eigen::VectorXd not_finite = Eigen::VectorXd::Zero(21);
  not_finite[4] = std::numeric_limits<double>::quiet_NaN();
  expect_error(exchange(server, contact_solve_request(4, not_finite)), protocol::INVALID_ARGUMENT,
               "ready");

  // The next valid solve is the reference's first solve (no warm start was touched).
  reference.assign_contact(assign_all(interface));
  const Eigen::VectorXd obstacle = sloped_obstacle(interface);
  const protocol::Envelope solved = exchange(server, contact_solve_request(5, obstacle));
  ASSERT_TRUE(solved.has_contact_result());
  expect_contact_result(solved.contact_result(), reference.solve_contact(obstacle), obstacle);
}

TEST_F(ReadyServer, CorrectionAndFieldsOfWrongLengthAreInvalid) {
  protocol::Envelope correction = request(3);
  correction.mutable_correction()->add_interface_force(1.0);
  expect_error(exchange(server, correction), protocol::INVALID_ARGUMENT, "ready");
  protocol::Envelope fields = request(4);
  fields.mutable_fields()->add_contact_force(1.0);
  expect_error(exchange(server, fields), protocol::INVALID_ARGUMENT, "ready");
}

/// CorrectionRequest.relative_accuracy is a hint in [0, 1): other values are invalid, and this
/// body's direct solver answers a hinted correction exactly like a full one.
TEST_F(ReadyServer, CorrectionAccuracyHintOutsideZeroToOneIsInvalid) {
  for (const double accuracy : {-0.5, 1.0, std::numeric_limits<double>::quiet_NaN()}) {
    protocol::Envelope correction = request(3);
    correction.mutable_correction()->mutable_interface_force()->Resize(21, 1.0);
    correction.mutable_correction()->set_relative_accuracy(accuracy);
    const protocol::Envelope reply = exchange(server, correction);
    expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
    EXPECT_NE(reply.error().message().find("CorrectionRequest.relative_accuracy of body 'lower'"),
              std::string::npos)
        << reply.error().message();
  }
  protocol::Envelope correction = request(4);
  correction.mutable_correction()->mutable_interface_force()->Resize(21, 1.0);
  correction.mutable_correction()->set_relative_accuracy(1e-3);
  const protocol::Envelope reply = exchange(server, correction);
  ASSERT_TRUE(reply.has_correction_result()) << reply.DebugString();
  reference.assign_contact(assign_all(interface));
  expect_equal_vectors(to_vector(reply.correction_result().normal_trace()),
                       reference.solve_correction(Eigen::VectorXd::Ones(21)));
}

TEST_F(ReadyServer, NeumannSolveIsTheNormalTraceOfTheDisplacement) {
  Eigen::VectorXd force(21);  // compressive, varying along the edge (x in [-1, 1])
  for (int i = 0; i < 21; ++i) force[i] = 2.0 + interface.coordinates[i].x();
  const protocol::Envelope reply = exchange(server, neumann_solve_request(3, force));
  ASSERT_TRUE(reply.has_neumann_result()) << reply.DebugString();
  EXPECT_GE(reply.neumann_result().compute_seconds(), 0.0);
  EXPECT_EQ(server.state(), ServerState::ready);
  reference.assign_contact(assign_all(interface));
  const Eigen::VectorXd displacement = reference.displacement(force);
  Eigen::VectorXd expected(21);  // u(node_i) . (0, 1)
  for (int i = 0; i < 21; ++i) expected[i] = displacement[2 * interface.node_ids[i] + 1];
  EXPECT_LT(expected.maxCoeff(), 0.0);  // the clamped, unloaded block is pushed down
  expect_equal_vectors(to_vector(reply.neumann_result().normal_trace()), expected);
}

TEST_F(ReadyServer, NeumannSolveOfWrongLengthOrNonFiniteIsInvalidAndTheStateIsKept) {
  protocol::Envelope reply = exchange(server, neumann_solve_request(3, Eigen::VectorXd::Ones(22)));
  expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
  EXPECT_NE(reply.error().message().find("NeumannSolveRequest.contact_force has 22 values for the "
                                         "21 contact constraints of body 'lower'"),
            std::string::npos)
      << reply.error().message();
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity()}) {
    Eigen::VectorXd force = Eigen::VectorXd::Ones(21);
    force[6] = bad;
    reply = exchange(server, neumann_solve_request(4, force));
    expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
    EXPECT_NE(reply.error().message().find("NeumannSolveRequest.contact_force[6] of body 'lower' "
                                           "is not a finite number"),
              std::string::npos)
        << reply.error().message();
  }
  EXPECT_TRUE(
      exchange(server, neumann_solve_request(5, Eigen::VectorXd::Ones(21))).has_neumann_result());
}

TEST(SubdomainServer, NeumannSolveBeforeSetupOrAssignmentIsWrongState) {
  SubdomainServer server(quiet_settings());
  protocol::Envelope reply = exchange(server, neumann_solve_request(1, Eigen::VectorXd::Zero(21)));
  expect_error(reply, protocol::WRONG_STATE, "awaiting_setup");
  EXPECT_EQ(reply.error().message(), "NeumannSolveRequest before SetupBody: send SetupBody first");
  ASSERT_TRUE(exchange(server, setup_request(2, lower_block_setup())).has_interface());
  reply = exchange(server, neumann_solve_request(3, Eigen::VectorXd::Zero(21)));
  expect_error(reply, protocol::WRONG_STATE, "awaiting_assignment");
  EXPECT_NE(reply.error().message().find("NeumannSolveRequest before AssignContact"),
            std::string::npos);
}

TEST(SubdomainServer, WithheldNeumannCapabilityIsNeitherAnnouncedNorServed) {
  ServerSettings settings = quiet_settings();
  settings.protocol_minor = 0;  // as a protocol 1.0 server
  settings.withheld_capabilities = {"neumann_solve"};
  SubdomainServer server(settings);
  const auto handle = [&server](const protocol::Envelope& envelope) {
    protocol::Envelope reply;
    EXPECT_TRUE(reply.ParseFromString(server.handle(envelope.SerializeAsString())));
    EXPECT_EQ(reply.version().major(), protocol::protocol_major);
    EXPECT_EQ(reply.version().minor(), 0u);
    return reply;
  };
  const protocol::Envelope hello = handle(hello_request(1));
  ASSERT_TRUE(hello.has_hello_reply());
  EXPECT_EQ(hello.hello_reply().capabilities_size(), 3);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  ASSERT_TRUE(handle(setup_request(2, lower_block_setup())).has_interface());
  ASSERT_TRUE(handle(assign_all_request(3, interface)).has_acknowledge());
  const protocol::Envelope reply = handle(neumann_solve_request(4, Eigen::VectorXd::Ones(21)));
  expect_error(reply, protocol::UNSUPPORTED, "ready");
  EXPECT_NE(reply.error().message().find("'neumann_solve'"), std::string::npos);
  EXPECT_TRUE(handle(contact_solve_request(5, Eigen::VectorXd::Ones(21))).has_contact_result());
}

/// `envelope` with Envelope.run_id `run_id` (protocol 1.2).
protocol::Envelope of_run(protocol::Envelope envelope, const std::string& run_id) {
  envelope.set_run_id(run_id);
  return envelope;
}

/// A WRONG_STATE reply in `state` whose message says the body belongs to another run.
void expect_other_run(const protocol::Envelope& reply, const std::string& state) {
  expect_error(reply, protocol::WRONG_STATE, state);
  EXPECT_NE(reply.error().message().find("body 'lower' now belongs to another run"),
            std::string::npos)
      << reply.error().message();
}

TEST(SubdomainServer, RequestsOfAnotherRunAreWrongStateAndChangeNothing) {
  SubdomainServer server(quiet_settings());
  BodySolver reference(lower_block_definition());
  const InterfaceDescription interface = reference.contact_boundary();
  const std::string run = "0123456789abcdef0123456789abcdef", other = "another-coordinator";
  protocol::Envelope reply = exchange(server, of_run(setup_request(1, lower_block_setup()), run));
  ASSERT_TRUE(reply.has_interface()) << reply.DebugString();
  EXPECT_EQ(reply.run_id(), run);  // echoed

  // Before the assignment: the other run's AssignContact and EndRun are refused.
  expect_other_run(exchange(server, of_run(assign_all_request(2, interface), other)),
                   "awaiting_assignment");
  protocol::Envelope end_run = request(3);
  end_run.mutable_end_run();
  expect_other_run(exchange(server, of_run(end_run, other)), "awaiting_assignment");
  ASSERT_TRUE(exchange(server, of_run(assign_all_request(4, interface), run)).has_acknowledge());
  reference.assign_contact(assign_all(interface));

  // In ready: every request of the other run is refused, the state and warm start kept.
  const Eigen::VectorXd obstacle = sloped_obstacle(interface);
  reply = exchange(server, of_run(contact_solve_request(5, obstacle), other));
  expect_other_run(reply, "ready");
  EXPECT_EQ(reply.error().message(),
            "ContactSolveRequest of run '" + other +
                "': this server's body 'lower' now belongs to another run (run_id '" + run +
                "'): another coordinator set it up; this run's state is lost");
  EXPECT_EQ(reply.run_id(), other);
  protocol::Envelope correction = request(6);
  correction.mutable_correction()->mutable_interface_force()->Resize(21, 1.0);
  expect_other_run(exchange(server, of_run(correction, other)), "ready");
  expect_other_run(
      exchange(server, of_run(neumann_solve_request(7, Eigen::VectorXd::Ones(21)), other)),
      "ready");
  protocol::Envelope fields = request(8);
  fields.mutable_fields()->mutable_contact_force()->Resize(21, 0.0);
  expect_other_run(exchange(server, of_run(fields, other)), "ready");
  expect_other_run(exchange(server, of_run(end_run, other)), "ready");
  expect_other_run(exchange(server, of_run(assign_all_request(9, interface), other)), "ready");
  EXPECT_EQ(server.state(), ServerState::ready);

  // The run's own requests, and requests without run_id (a 1.1 coordinator), are served from
  // its body as if nothing had happened.
  reply = exchange(server, of_run(contact_solve_request(10, obstacle), run));
  ASSERT_TRUE(reply.has_contact_result()) << reply.DebugString();
  expect_contact_result(reply.contact_result(), reference.solve_contact(obstacle), obstacle);
  const Eigen::VectorXd second_obstacle = 0.5 * obstacle.array() - 0.0002;
  reply = exchange(server, contact_solve_request(11, second_obstacle));
  ASSERT_TRUE(reply.has_contact_result()) << reply.DebugString();
  EXPECT_EQ(reply.run_id(), "");
  expect_contact_result(reply.contact_result(), reference.solve_contact(second_obstacle),
                        second_obstacle);

  // Another run may always take the server over with SetupBody; the first run is then refused.
  ASSERT_TRUE(
      exchange(server, of_run(setup_request(12, lower_block_setup()), other)).has_interface());
  expect_other_run(exchange(server, of_run(contact_solve_request(13, obstacle), run)),
                   "awaiting_assignment");
  expect_other_run(exchange(server, of_run(end_run, run)), "awaiting_assignment");
  reply = exchange(server, of_run(end_run, other));
  ASSERT_TRUE(reply.has_acknowledge()) << reply.DebugString();
  EXPECT_EQ(reply.acknowledge().state(), "awaiting_setup");

  // Without a body no run owns the server: a request of any run gets the plain state refusal.
  reply = exchange(server, of_run(contact_solve_request(14, obstacle), run));
  expect_error(reply, protocol::WRONG_STATE, "awaiting_setup");
  EXPECT_EQ(reply.error().message(), "ContactSolveRequest before SetupBody: send SetupBody first");
}

TEST(SubdomainServer, BodySetUpWithoutRunIdServesEveryRun) {
  SubdomainServer server(quiet_settings());
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
  ASSERT_TRUE(exchange(server, of_run(assign_all_request(2, interface), "b")).has_acknowledge());
  EXPECT_TRUE(exchange(server, of_run(contact_solve_request(3, Eigen::VectorXd::Ones(21)), "c"))
                  .has_contact_result());
}

/// `envelope` sent as protocol `major`.`minor`.
protocol::Envelope as_version(protocol::Envelope envelope, unsigned major, unsigned minor) {
  envelope.mutable_version()->set_major(major);
  envelope.mutable_version()->set_minor(minor);
  return envelope;
}

TEST(SubdomainServer, ServerPlayingProtocol11IgnoresRunId) {
  ServerSettings settings = quiet_settings();
  settings.protocol_major = 1;
  settings.protocol_minor = 1;
  SubdomainServer server(settings);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  const auto handle = [&server](const protocol::Envelope& envelope) {
    protocol::Envelope reply;
    EXPECT_TRUE(
        reply.ParseFromString(server.handle(as_version(envelope, 1, 1).SerializeAsString())));
    EXPECT_EQ(reply.version().major(), 1u);
    EXPECT_EQ(reply.version().minor(), 1u);
    return reply;
  };
  ASSERT_TRUE(handle(of_run(setup_request(1, lower_block_setup()), "a")).has_interface());
  ASSERT_TRUE(handle(of_run(assign_all_request(2, interface), "b")).has_acknowledge());
  EXPECT_TRUE(handle(of_run(contact_solve_request(3, Eigen::VectorXd::Ones(21)), "b"))
                  .has_contact_result());
}

// run_id is honoured from 1.2 on: a server playing 1.2 refuses another run's requests as a 2.0
// server does.
TEST(SubdomainServer, ServerPlayingProtocol12HonoursRunId) {
  ServerSettings settings = quiet_settings();
  settings.protocol_major = 1;
  settings.protocol_minor = 2;
  SubdomainServer server(settings);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  const auto handle = [&server](const protocol::Envelope& envelope) {
    protocol::Envelope reply;
    EXPECT_TRUE(
        reply.ParseFromString(server.handle(as_version(envelope, 1, 2).SerializeAsString())));
    return reply;
  };
  ASSERT_TRUE(handle(of_run(setup_request(1, lower_block_setup()), "a")).has_interface());
  expect_other_run(handle(of_run(assign_all_request(2, interface), "b")), "awaiting_assignment");
  ASSERT_TRUE(handle(of_run(assign_all_request(3, interface), "a")).has_acknowledge());
  expect_other_run(handle(of_run(contact_solve_request(4, Eigen::VectorXd::Ones(21)), "b")),
                   "ready");
  EXPECT_TRUE(handle(of_run(contact_solve_request(5, Eigen::VectorXd::Ones(21)), "a"))
                  .has_contact_result());
}

// Protocol 2.0 checks the structure of B instead of node ids and unit normals (a general row
// need not be a unit normal): every malformed operator is INVALID_ARGUMENT naming the body and
// the field, and keeps the state and the previous assignment (21 rows).
TEST_F(ReadyServer, BadAssignmentsAreInvalidAndKeepThePreviousAssignment) {
  const auto modified = [this](std::uint64_t id, const auto& change) {
    protocol::Envelope envelope = assign_all_request(id, interface);
    change(*envelope.mutable_assign_contact());
    return envelope;
  };
  using Assign = protocol::AssignContact;
  const std::vector<std::pair<protocol::Envelope, std::string>> cases = {
      {modified(3, [](Assign& a) { a.set_node_ids(0, 1000000); }),
       "AssignContact.node_ids[0] = 1000000 is not a node of the contact boundary"},
      {modified(4, [](Assign& a) { a.set_node_ids(0, -5); }), "AssignContact.node_ids[0]"},
      {modified(5, [](Assign& a) { a.set_components(0, 1); }),
       "AssignContact constraint 0 names component 1 of node id " +
           std::to_string(interface.node_ids[0]) + " twice"},
      {modified(6, [](Assign& a) { a.set_components(1, 2); }),
       "AssignContact.components[1] = 2, expected 0 (x) or 1 (y)"},
      {modified(7, [](Assign& a) { a.set_values(1, std::numeric_limits<double>::quiet_NaN()); }),
       "AssignContact.values[1] is not a finite number"},
      {modified(8, [](Assign& a) { a.set_values(1, std::numeric_limits<double>::infinity()); }),
       "AssignContact.values[1] is not a finite number"},
      {modified(9, [](Assign& a) { a.set_weights(3, 0.0); }),
       "AssignContact.weights[3] is not a finite positive number"},
      {modified(10, [](Assign& a) { a.set_weights(3, -1.0); }), "AssignContact.weights[3]"},
      {modified(11, [](Assign& a) { a.mutable_values()->RemoveLast(); }),
       "42 node_ids, 42 components and 41 values"},
      {modified(12, [](Assign& a) { a.mutable_weights()->RemoveLast(); }),
       "22 row_offsets and 20 weights"},
      {modified(13, [](Assign& a) { a.set_row_offsets(1, 0); }),
       "AssignContact.row_offsets[1] leaves constraint 0 without entries"},
      {modified(14, [](Assign& a) { a.set_row_offsets(0, 1); }),
       "AssignContact.row_offsets must start with 0"},
      {modified(15, [](Assign& a) { a.set_row_offsets(21, 40); }),
       "AssignContact.row_offsets ends at 40, expected the entry count 42"},
      {modified(16, [](Assign& a) { a.set_row_offsets(5, 1000); }), "AssignContact.row_offsets"},
      {modified(17, [](Assign& a) { a.Clear(); }), "AssignContact"}};
  for (const auto& [bad, expected] : cases) {
    const protocol::Envelope reply = exchange(server, bad);
    expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
    EXPECT_NE(reply.error().message().find("body 'lower'"), std::string::npos)
        << reply.error().message();
    EXPECT_NE(reply.error().message().find(expected), std::string::npos) << reply.error().message();
    EXPECT_EQ(server.state(), ServerState::ready) << expected;
  }
  // The previous assignment (21 rows) still holds.
  expect_error(exchange(server, contact_solve_request(18, Eigen::VectorXd::Zero(20))),
               protocol::INVALID_ARGUMENT, "ready");
  EXPECT_TRUE(
      exchange(server, contact_solve_request(19, Eigen::VectorXd::Zero(21))).has_contact_result());
  // A row that is not a unit normal is a valid general row (protocol 2.0), e.g. (0, 1.1).
  protocol::Envelope scaled = assign_all_request(20, interface);
  scaled.mutable_assign_contact()->set_values(1, 1.1);
  EXPECT_TRUE(exchange(server, scaled).has_acknowledge());
}

TEST(SubdomainServer, BadBodyDefinitionsAreBadInputNamingTheBodyAndField) {
  SubdomainServer server(quiet_settings());
  protocol::SetupBody bad_mesh = lower_block_setup();
  bad_mesh.mutable_mesh()->mutable_coordinates()->RemoveLast();  // an odd number of values
  protocol::SetupBody unknown_boundary = lower_block_setup();
  unknown_boundary.mutable_dirichlet(0)->set_boundary("botom");
  protocol::SetupBody short_voigt = lower_block_setup();
  short_voigt.clear_young_modulus();
  short_voigt.clear_poisson_ratio();
  for (double value : {1.0, 0.0, 0.0, 1.0}) short_voigt.add_voigt(value);
  protocol::SetupBody no_model = lower_block_setup();
  no_model.clear_model();
  const std::vector<std::pair<protocol::SetupBody, std::string>> cases = {
      {bad_mesh, "SetupBody.mesh.coordinates has"},
      {unknown_boundary, "SetupBody.dirichlet[0].boundary 'botom' is not a boundary of the mesh"},
      {short_voigt, "SetupBody.voigt has 4 values, expected 9"},
      {no_model, "SetupBody.model is unspecified"}};
  for (const auto& [setup, field] : cases) {
    const protocol::Envelope reply = exchange(server, setup_request(1, setup));
    expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
    EXPECT_EQ(reply.error().message().rfind("body 'lower': ", 0), 0u) << reply.error().message();
    EXPECT_NE(reply.error().message().find(field), std::string::npos) << reply.error().message();
  }
}

/// Hello still gets its reply: the server is up and serving.
void expect_hello(SubdomainServer& server, std::uint64_t id) {
  const protocol::Envelope reply = exchange(server, hello_request(id));
  EXPECT_TRUE(reply.has_hello_reply()) << reply.DebugString();
}

/// `setup` with the 1.x fields 2 (mesh_content) = `script` and 3 (mesh_extension) = ".geo",
/// which 2.0 reserves: written as unknown fields, as a 1.x coordinator would send them.
protocol::SetupBody with_1x_script(protocol::SetupBody setup, const std::string& script) {
  google::protobuf::UnknownFieldSet& unknown = *setup.GetReflection()->MutableUnknownFields(&setup);
  unknown.AddLengthDelimited(2, script);
  unknown.AddLengthDelimited(3, ".geo");
  unknown.AddFixed64(5, 0x3fb999999999999aULL);  // 1.x mesh_size = 0.1
  return setup;
}

/// A path for a witness file that must never appear.
std::filesystem::path witness_path(const std::string& label) {
  static int counter = 0;
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("robin-witness-" + label + "-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove(path);
  return path;
}

/// The lines of /etc/passwd (none when it cannot be read).
std::vector<std::string> passwd_lines() {
  std::ifstream stream("/etc/passwd");
  std::vector<std::string> lines;
  for (std::string line; std::getline(stream, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

/// Expects `reply_bytes` to show no line of /etc/passwd and not `directory` (the working
/// directory).
void expect_nothing_read(const std::string& reply_bytes, const std::string& directory) {
  for (const std::string& line : passwd_lines()) {
    EXPECT_EQ(reply_bytes.find(line), std::string::npos) << "the reply shows '" << line << "'";
  }
  EXPECT_EQ(reply_bytes.find(directory), std::string::npos) << "the reply shows " << directory;
}

// Issue 11 (a), remote command execution and file reads: a 1.x SetupBody carrying a .geo
// script in mesh_content (field 2) with mesh_extension ".geo" (field 3), the script holding one
// of the attacks of hostile_geo_scripts.hpp (SystemCall, an ExternalProcess mesh size field, the
// five keyword-filter bypasses, ListFromFile("/etc/passwd"), CurrentDirectory). A 2.0 server
// does not know these fields, runs no script and, with no MeshData and no mesh_path, refuses
// the body as BAD_INPUT; the command's file does not appear and no reply shows a line of
// /etc/passwd or the working directory. Sent together with a valid MeshData, the script is
// ignored as well: the body is set up from the MeshData and nothing runs.
TEST(SubdomainServer, Version1GeoScriptInMeshContentIsNeverRun) {
  SubdomainServer server(quiet_settings());
  const std::string working_directory = std::filesystem::current_path().string();
  ASSERT_GT(working_directory.size(), 1u);
  std::uint64_t id = 1;
  const std::filesystem::path witness = witness_path("geo");
  for (const testing::HostileGeoScript& attack : testing::hostile_geo_scripts(witness)) {
    SCOPED_TRACE(attack.label);
    const std::string script = file_text(lower_geo) + attack.text;
    protocol::SetupBody without_mesh = lower_block_setup();
    without_mesh.clear_mesh();
    const protocol::SetupBody hostile = with_1x_script(without_mesh, script);
    // The bytes do carry the script (fields 2 and 3), as a 1.x coordinator sends it.
    const std::string bytes = setup_request(id, hostile).SerializeAsString();
    ASSERT_NE(bytes.find(attack.text), std::string::npos);
    const std::string reply_bytes = server.handle(bytes);
    protocol::Envelope reply;
    ASSERT_TRUE(reply.ParseFromString(reply_bytes));
    expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
    EXPECT_NE(reply.error().message().find(
                  "body 'lower': SetupBody.mesh and SetupBody.mesh_path are both absent"),
              std::string::npos)
        << reply.error().message();
    expect_nothing_read(reply_bytes, working_directory);
    expect_hello(server, ++id);

    const std::string with_mesh_bytes = server.handle(
        setup_request(++id, with_1x_script(lower_block_setup(), script)).SerializeAsString());
    protocol::Envelope with_mesh;
    ASSERT_TRUE(with_mesh.ParseFromString(with_mesh_bytes));
    EXPECT_TRUE(with_mesh.has_interface()) << with_mesh.DebugString();
    expect_nothing_read(with_mesh_bytes, working_directory);
    expect_hello(server, ++id);
    ++id;
    EXPECT_FALSE(std::filesystem::exists(witness)) << "the script ran";
  }
}

/// A body on the unit square of tests/data/mesh_square_v41.msh read from `mesh_path`: clamped
/// "bottom", contact boundary "top".
protocol::SetupBody square_path_setup(const std::string& mesh_path) {
  protocol::SetupBody setup;
  setup.set_body_name("square");
  setup.set_mesh_path(mesh_path);
  setup.set_model(protocol::PLANE_STRAIN);
  setup.set_young_modulus(1000.0);
  setup.set_poisson_ratio(0.3);
  protocol::Dirichlet& bottom = *setup.add_dirichlet();
  bottom.set_boundary("bottom");
  bottom.set_x(0.0);
  bottom.set_y(0.0);
  setup.add_contact_boundaries("top");
  return setup;
}

const std::filesystem::path square_msh =
    std::filesystem::path(ROBIN_TEST_DATA) / "mesh_square_v41.msh";

/// A BAD_INPUT reply naming SetupBody.mesh_path that contains no line of `secret` (a file's
/// lines) anywhere in its bytes.
void expect_refused_path(const protocol::Envelope& reply, const std::vector<std::string>& secret,
                         const std::string& expected) {
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("body 'square': SetupBody.mesh_path"), std::string::npos)
      << reply.error().message();
  EXPECT_NE(reply.error().message().find(expected), std::string::npos) << reply.error().message();
  const std::string bytes = reply.SerializeAsString();
  for (const std::string& line : secret) {
    EXPECT_EQ(bytes.find(line), std::string::npos) << "the reply shows the line '" << line << "'";
  }
}

// Issue 11 (b), file reads through mesh_path. The data directory holds square.msh, a symbolic
// link to /etc/passwd, a link to a valid mesh outside it and a link to a directory outside it;
// next to it (outside) lies x.msh, also a valid mesh. Absolute paths, "..", and every link that
// leads out are BAD_INPUT, and no reply contains a line of /etc/passwd; the mesh inside is
// read and gives the body built from the same file in this process. Without a data directory
// every mesh_path is refused, also one naming a valid mesh.
TEST(SubdomainServer, MeshPathOutsideTheDataDirectoryIsRefusedUnread) {
  const TemporaryDirectory base("data");
  const std::filesystem::path data = base.path() / "data";
  std::filesystem::create_directories(data / "meshes");
  std::filesystem::copy_file(square_msh, data / "meshes/square.msh");
  std::filesystem::copy_file(square_msh, base.path() / "x.msh");
  std::filesystem::create_symlink("/etc/passwd", data / "passwd.msh");
  std::filesystem::create_symlink(base.path() / "x.msh", data / "outside.msh");
  std::filesystem::create_symlink(base.path(), data / "up");
  const std::vector<std::string> secret = passwd_lines();

  ServerSettings settings = quiet_settings();
  settings.data_directory = data;
  SubdomainServer server(settings);
  std::uint64_t id = 1;
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"/etc/passwd", "is absolute"},
      {(base.path() / "x.msh").string(), "is absolute"},
      {"../x.msh", "contains '..'"},
      {"meshes/../../x.msh", "contains '..'"},
      {"passwd.msh", "leads out of the data directory"},
      {"outside.msh", "leads out of the data directory"},
      {"up/x.msh", "leads out of the data directory"},
      {"up/data/passwd.msh", "leads out of the data directory"},
      {"missing.msh", "does not exist under the data directory"},
      {"meshes", "is not a regular file"}};
  for (const auto& [path, expected] : refused) {
    expect_refused_path(exchange(server, setup_request(id++, square_path_setup(path))), secret,
                        expected);
    expect_hello(server, id++);
  }

  const protocol::Envelope reply =
      exchange(server, setup_request(id++, square_path_setup("meshes/square.msh")));
  ASSERT_TRUE(reply.has_interface()) << reply.DebugString();
  BodyDefinition definition;
  definition.name = "square";
  definition.mesh = read_gmsh_mesh(square_msh);
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  definition.contact_boundaries = {"top"};
  const BodySolver reference(definition);
  const InterfaceDescription expected = reference.contact_boundary();
  ASSERT_EQ(reply.interface().node_ids_size(), static_cast<int>(expected.node_ids.size()));
  for (std::size_t i = 0; i < expected.node_ids.size(); ++i) {
    const int k = static_cast<int>(i);
    EXPECT_EQ(reply.interface().node_ids(k), expected.node_ids[i]);
    EXPECT_EQ(reply.interface().node_tags(k), static_cast<std::int64_t>(expected.node_tags[i]));
    EXPECT_EQ(reply.interface().coordinates(2 * k), expected.coordinates[i].x());
    EXPECT_EQ(reply.interface().coordinates(2 * k + 1), 1.0);
    EXPECT_NEAR(reply.interface().weights(k), expected.weights[i], 1e-15);
  }
  EXPECT_EQ(reply.interface().dof_count(), static_cast<std::uint64_t>(reference.free_dof_count()));

  SubdomainServer without_directory(quiet_settings());
  for (const std::string& path : {std::string("meshes/square.msh"), square_msh.string()}) {
    expect_refused_path(exchange(without_directory, setup_request(id++, square_path_setup(path))),
                        secret, "this server was started without --data-directory");
  }
  expect_hello(without_directory, id++);
}

/// A server with the lower block set up and assigned (node-to-node rows, normal (0, 1)).
std::unique_ptr<SubdomainServer> ready_server(const ServerSettings& settings) {
  auto server = std::make_unique<SubdomainServer>(settings);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  EXPECT_TRUE(exchange(*server, setup_request(1, lower_block_setup())).has_interface());
  EXPECT_TRUE(exchange(*server, assign_all_request(2, interface)).has_acknowledge());
  return server;
}

protocol::Envelope fields_request(std::uint64_t id, const std::string& write_directory) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_fields()->mutable_contact_force()->Resize(21, 0.5);
  envelope.mutable_fields()->set_write_directory(write_directory);
  return envelope;
}

/// The names in `directory` (recursively, relative), for "nothing was created" checks.
std::set<std::string> listing(const std::filesystem::path& directory) {
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(directory)) {
    names.insert(entry.path().lexically_relative(directory).string());
  }
  return names;
}

// Protocol 2.5: FieldsRequest.omit_fields_from_reply. With write_directory the server writes
// the same file as for a full reply (the bytes of out/lower.vtu and full/lower.vtu are equal)
// and replies with the resultants of the full reply and no mesh or fields; without
// write_directory it is INVALID_ARGUMENT. A server playing protocol 2.4 ignores it (a full
// reply) and reports no peak_resident_bytes; a 2.5 server reports a positive one.
TEST(SubdomainServer, OmitFieldsFromReplyKeepsTheFileAndTheResultantsOnly) {
  const TemporaryDirectory root("output");
  ServerSettings settings = quiet_settings();
  settings.output_root = root.path();
  const std::unique_ptr<SubdomainServer> server = ready_server(settings);
  const protocol::Envelope full = exchange(*server, fields_request(3, "full"));
  ASSERT_TRUE(full.has_fields_reply()) << full.DebugString();
  EXPECT_GT(full.fields_reply().node_coordinates_size(), 0);
  EXPECT_GT(full.fields_reply().peak_resident_bytes(), 0u);
  protocol::Envelope request = fields_request(4, "out");
  request.mutable_fields()->set_omit_fields_from_reply(true);
  const protocol::Envelope reply = exchange(*server, request);
  ASSERT_TRUE(reply.has_fields_reply()) << reply.DebugString();
  const protocol::FieldsReply& small = reply.fields_reply();
  EXPECT_EQ(small.node_coordinates_size() + small.node_tags_size() + small.cell_types_size() +
                small.cell_offsets_size() + small.connectivity_size() + small.point_fields_size() +
                small.cell_fields_size() + small.boundaries_size(),
            0);
  EXPECT_EQ(
      std::vector<double>(small.reaction_resultant().begin(), small.reaction_resultant().end()),
      std::vector<double>(full.fields_reply().reaction_resultant().begin(),
                          full.fields_reply().reaction_resultant().end()));
  EXPECT_EQ(std::vector<double>(small.applied_force().begin(), small.applied_force().end()),
            std::vector<double>(full.fields_reply().applied_force().begin(),
                                full.fields_reply().applied_force().end()));
  EXPECT_EQ(small.written_file(),
            (std::filesystem::canonical(root.path()) / "out/lower.vtu").string());
  EXPECT_EQ(small.stage_times_size(), 1);
  EXPECT_GT(small.peak_resident_bytes(), 0u);
  EXPECT_EQ(file_text(root.path() / "out/lower.vtu"), file_text(root.path() / "full/lower.vtu"));
  request = fields_request(5, "");
  request.mutable_fields()->set_omit_fields_from_reply(true);
  expect_error(exchange(*server, request), protocol::INVALID_ARGUMENT, "ready");

  settings.protocol_minor = 4;
  SubdomainServer older(settings);
  const auto handle = [&older](const protocol::Envelope& envelope) {
    protocol::Envelope answer;
    EXPECT_TRUE(answer.ParseFromString(older.handle(envelope.SerializeAsString())));
    EXPECT_EQ(answer.version().minor(), 4u);
    return answer;
  };
  const protocol::Envelope setup = handle(setup_request(6, lower_block_setup()));
  ASSERT_TRUE(setup.has_interface()) << setup.DebugString();
  EXPECT_EQ(setup.interface().peak_resident_bytes(), 0u);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  const protocol::Envelope acknowledge = handle(assign_all_request(7, interface));
  ASSERT_TRUE(acknowledge.has_acknowledge()) << acknowledge.DebugString();
  EXPECT_EQ(acknowledge.acknowledge().peak_resident_bytes(), 0u);
  request = fields_request(8, "older");
  request.mutable_fields()->set_omit_fields_from_reply(true);
  const protocol::Envelope older_reply = handle(request);
  ASSERT_TRUE(older_reply.has_fields_reply()) << older_reply.DebugString();
  EXPECT_EQ(older_reply.fields_reply().node_coordinates_size(),
            full.fields_reply().node_coordinates_size());
  EXPECT_EQ(older_reply.fields_reply().peak_resident_bytes(), 0u);
}

// Issue 11 (c), writes through write_directory. Under the output root, out/lower.vtu is a
// symbolic link to an existing file outside the root: FieldsRequest replaces the link by the
// VTU file and leaves the outside file unchanged. A write_directory that is absolute, contains
// "..", or passes through a symbolically linked directory is INVALID_ARGUMENT and creates
// nothing outside the root; without an output root every write_directory is refused.
TEST(SubdomainServer, WriteDirectoryOutsideTheOutputRootIsRefusedUnwritten) {
  const TemporaryDirectory base("output");
  const std::filesystem::path root = base.path() / "root", outside = base.path() / "outside";
  std::filesystem::create_directories(root / "out");
  std::filesystem::create_directories(outside);
  const std::filesystem::path victim = outside / "victim.txt";
  write_text(victim, "precious\n");
  std::filesystem::create_symlink(victim, root / "out/lower.vtu");
  std::filesystem::create_symlink(outside, root / "linked");

  ServerSettings settings = quiet_settings();
  settings.output_root = root;
  const std::unique_ptr<SubdomainServer> server = ready_server(settings);
  std::uint64_t id = 3;
  protocol::Envelope reply = exchange(*server, fields_request(id++, "out"));
  ASSERT_TRUE(reply.has_fields_reply()) << reply.DebugString();
  EXPECT_EQ(reply.fields_reply().written_file(),
            (std::filesystem::canonical(root) / "out/lower.vtu").string());
  EXPECT_EQ(file_text(victim), "precious\n");
  EXPECT_FALSE(std::filesystem::is_symlink(root / "out/lower.vtu"));
  EXPECT_TRUE(std::filesystem::is_regular_file(root / "out/lower.vtu"));
  EXPECT_NE(file_text(root / "out/lower.vtu").find("<VTKFile"), std::string::npos);
  EXPECT_EQ(listing(root / "out"), (std::set<std::string>{"lower.vtu"}));
  expect_hello(*server, id++);

  const std::vector<std::pair<std::string, std::string>> refused = {
      {outside.string(), "is absolute"},
      {(outside / "sub").string(), "is absolute"},
      {"../outside", "contains '..'"},
      {"out/../../outside/sub", "contains '..'"},
      {"linked", "'linked' is a symbolic link"},
      {"linked/sub", "'linked' is a symbolic link"},
      {"out/lower.vtu", "exists and is not a directory"}};
  for (const auto& [directory, expected] : refused) {
    reply = exchange(*server, fields_request(id++, directory));
    expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
    EXPECT_NE(reply.error().message().find("body 'lower': FieldsRequest.write_directory"),
              std::string::npos)
        << reply.error().message();
    EXPECT_NE(reply.error().message().find(expected), std::string::npos) << reply.error().message();
    expect_hello(*server, id++);
  }
  EXPECT_EQ(listing(outside), (std::set<std::string>{"victim.txt"}));
  EXPECT_EQ(file_text(victim), "precious\n");
  EXPECT_EQ(listing(base.path()),
            (std::set<std::string>{"outside", "outside/victim.txt", "root", "root/linked",
                                   "root/out", "root/out/lower.vtu"}));

  const std::unique_ptr<SubdomainServer> without_root = ready_server(quiet_settings());
  reply = exchange(*without_root, fields_request(id++, "out"));
  expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
  EXPECT_NE(reply.error().message().find("this server was started without --output-root"),
            std::string::npos)
      << reply.error().message();
  // Without write_directory the fields are only returned.
  reply = exchange(*without_root, fields_request(id++, ""));
  EXPECT_TRUE(reply.has_fields_reply());
  EXPECT_EQ(reply.fields_reply().written_file(), "");
  expect_hello(*without_root, id++);
}

// Issue 11 (d): a body name of 100,000 characters is BAD_INPUT (at most 64) and is not echoed
// back; 64 characters are accepted, 65 are not.
TEST(SubdomainServer, HugeBodyNameIsBadInput) {
  SubdomainServer server(quiet_settings());
  protocol::SetupBody huge = lower_block_setup();
  huge.set_body_name(std::string(100000, 'a'));
  protocol::Envelope reply = exchange(server, setup_request(1, huge));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("SetupBody.body_name has 100000 characters: at most 64"),
            std::string::npos)
      << reply.error().message().substr(0, 200);
  EXPECT_LT(reply.ByteSizeLong(), 1000u);
  expect_hello(server, 2);
  protocol::SetupBody longest = lower_block_setup();
  longest.set_body_name(std::string(64, 'b'));
  EXPECT_TRUE(exchange(server, setup_request(3, longest)).has_interface());
  longest.set_body_name(std::string(65, 'b'));
  expect_error(exchange(server, setup_request(4, longest)), protocol::BAD_INPUT, "awaiting_setup");
  expect_hello(server, 5);
}

// SolverSettings.interface_operator and linear_solver are hints, but only their documented
// strings (docs/protocol.md): "" and each value are accepted, any other string is BAD_INPUT
// naming the body, the field and the value.
TEST(SubdomainServer, SolverHintsAcceptTheirValuesAndRefuseOthers) {
  SubdomainServer server(quiet_settings());
  std::uint64_t id = 1;
  for (const char* value : {"", "direct", "multigrid"}) {
    protocol::SetupBody setup = lower_block_setup();
    setup.mutable_solver()->set_linear_solver(value);
    EXPECT_TRUE(exchange(server, setup_request(id++, setup)).has_interface()) << value;
  }
  protocol::SetupBody bad = lower_block_setup();
  bad.mutable_solver()->set_linear_solver("amg");
  protocol::Envelope reply = exchange(server, setup_request(id++, bad));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  EXPECT_NE(reply.error().message().find(
                "body 'lower': SetupBody.solver.linear_solver is 'amg', expected \"direct\" or "
                "\"multigrid\""),
            std::string::npos)
      << reply.error().message();
  bad = lower_block_setup();
  bad.mutable_solver()->set_interface_operator("sparse");
  reply = exchange(server, setup_request(id++, bad));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("body 'lower': SetupBody.solver.interface_operator is "
                                         "'sparse', expected \"auto\", \"dense\" or \"factor\""),
            std::string::npos)
      << reply.error().message();
  expect_hello(server, id++);
}

/// A unit square of two counter-clockwise triangles with tags 7 and 8, boundaries "bottom",
/// "right", "top" and "left", as MeshData built by hand.
protocol::MeshData square_mesh_data() {
  protocol::MeshData mesh;
  mesh.set_dimension(2);
  for (const double value : {0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0}) mesh.add_coordinates(value);
  for (const std::uint64_t tag : {11, 12, 13, 14}) mesh.add_node_tags(tag);
  protocol::CellBlock& cells = *mesh.add_cells();
  cells.set_type(protocol::TRIANGLE3);
  for (const std::uint32_t node : {0, 1, 2, 0, 2, 3}) cells.add_connectivity(node);
  cells.add_tags(7);
  cells.add_tags(8);
  const std::vector<std::pair<std::string, std::pair<int, int>>> sides = {
      {"bottom", {0, 1}}, {"right", {1, 2}}, {"top", {2, 3}}, {"left", {3, 0}}};
  for (const auto& [name, nodes] : sides) {
    protocol::NamedBoundary& boundary = *mesh.add_boundaries();
    boundary.set_name(name);
    boundary.mutable_segments()->set_type(protocol::LINE2);
    boundary.mutable_segments()->add_connectivity(static_cast<std::uint32_t>(nodes.first));
    boundary.mutable_segments()->add_connectivity(static_cast<std::uint32_t>(nodes.second));
  }
  mesh.set_source("square.msh");
  return mesh;
}

protocol::SetupBody square_data_setup(const protocol::MeshData& mesh) {
  protocol::SetupBody setup = square_path_setup("");
  setup.clear_mesh_path();
  *setup.mutable_mesh() = mesh;
  return setup;
}

// Issue 11 (e), tangled meshes: the hand-built square is accepted; with one triangle reversed
// (two nodes swapped: inverted) it is BAD_INPUT naming that cell's tag; with a zero-area
// triangle it is BAD_INPUT naming that cell as degenerate. Through mesh_path, a .msh with one
// triangle reversed against its surface is BAD_INPUT naming its element tag.
TEST(SubdomainServer, InvertedOrDegenerateCellsAreBadInputNamingTheirTag) {
  const TemporaryDirectory data("tangled");
  std::filesystem::copy_file(
      std::filesystem::path(ROBIN_TEST_DATA) / "mesh_square_inverted_v22.msh",
      data.path() / "inverted.msh");
  ServerSettings settings = quiet_settings();
  settings.data_directory = data.path();
  SubdomainServer server(settings);
  EXPECT_TRUE(
      exchange(server, setup_request(1, square_data_setup(square_mesh_data()))).has_interface());

  protocol::MeshData reversed = square_mesh_data();
  reversed.mutable_cells(0)->set_connectivity(4, 3);  // triangle 8: (0, 2, 3) -> (0, 3, 2)
  reversed.mutable_cells(0)->set_connectivity(5, 2);
  protocol::Envelope reply = exchange(server, setup_request(2, square_data_setup(reversed)));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  std::string message = reply.error().message();
  EXPECT_NE(message.find("body 'square': SetupBody.mesh: element tag 8 (triangle3 at node tags "
                         "11, 14, 13) is inverted or folded"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("mesh 'square.msh'"), std::string::npos) << message;
  expect_hello(server, 3);

  protocol::MeshData degenerate = square_mesh_data();
  degenerate.add_coordinates(0.5);  // node 4 at (0.5, 0), on the line through nodes 0 and 1
  degenerate.add_coordinates(0.0);
  degenerate.add_node_tags(15);
  for (const std::uint32_t node : {0, 1, 4}) degenerate.mutable_cells(0)->add_connectivity(node);
  degenerate.mutable_cells(0)->add_tags(9);
  reply = exchange(server, setup_request(4, square_data_setup(degenerate)));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  message = reply.error().message();
  EXPECT_NE(message.find("element tag 9 (triangle3 at node tags 11, 12, 15) is degenerate"),
            std::string::npos)
      << message;
  expect_hello(server, 5);

  reply = exchange(server, setup_request(6, square_path_setup("inverted.msh")));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  message = reply.error().message();
  EXPECT_NE(message.find("body 'square': SetupBody.mesh_path"), std::string::npos) << message;
  EXPECT_NE(message.find("element tag 13 "), std::string::npos) << message;
  EXPECT_NE(message.find("inverted"), std::string::npos) << message;
  expect_hello(server, 7);
}

// A server whose mesh reader (robin-mesh-reader) cannot be run refuses a .geo mesh_path (which
// only the reader meshes) with an INTERNAL error naming the reader, not the client's file, and
// goes on serving; a .msh mesh_path needs no reader (the server reads it itself, msh_file.hpp).
TEST(SubdomainServer, MeshPathWithoutItsReaderIsAnInternalErrorNamingTheReader) {
  const TemporaryDirectory data("no-reader");
  std::filesystem::copy_file(square_msh, data.path() / "square.msh");
  std::filesystem::copy_file(std::filesystem::path(ROBIN_TEST_DATA) / "mesh_square.geo",
                             data.path() / "square.geo");
  ServerSettings settings = quiet_settings();
  settings.data_directory = data.path();
  settings.mesh_reader = data.path() / "no-such-reader";
  SubdomainServer server(settings);
  const protocol::Envelope reply =
      exchange(server, setup_request(1, square_path_setup("square.geo")));
  expect_error(reply, protocol::INTERNAL, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("cannot run the mesh reader '" +
                                         (data.path() / "no-such-reader").string() + "'"),
            std::string::npos)
      << reply.error().message();
  expect_hello(server, 2);
  EXPECT_TRUE(exchange(server, setup_request(3, square_path_setup("square.msh"))).has_interface());
}

/// SOLVER_FAILURE naming `what` and the body: an Error, so no NaN or infinity is sent.
void expect_solver_failure(const protocol::Envelope& reply, const std::string& what) {
  expect_error(reply, protocol::SOLVER_FAILURE, "ready");
  EXPECT_EQ(reply.error().message().rfind(what, 0), 0u) << reply.error().message();
  EXPECT_NE(
      reply.error().message().find(" of body 'lower' has a value that is not a finite number"),
      std::string::npos)
      << reply.error().message();
  EXPECT_FALSE(reply.has_correction_result() || reply.has_neumann_result() ||
               reply.has_fields_reply() || reply.has_contact_result());
}

// Issue 11 (f), non-finite results: two rows on the same u_y with the coefficient 1e300 (finite,
// so accepted) make F = B K^-1 B' overflow (1e600 x compliance): the correction and the Neumann
// solve are then infinite or NaN, and the fields for forces of 1 give stresses near 1e300 whose
// von Mises stress overflows. With moderate coefficients (1e10), forces near 1e300 overflow the
// nodal contact force field. Each reply is SOLVER_FAILURE naming the body, never a reply
// carrying NaN or Inf, and the server stays up and in its state.
TEST(SubdomainServer, NonFiniteResultsAreSolverFailureNamingTheBody) {
  SubdomainServer server(quiet_settings());
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
  const int node = interface.node_ids[10];
  std::uint64_t id = 2;
  for (const double coefficient : {1e300, 1e10}) {
    ContactOperator contact;
    contact.add_entry(node, 1, coefficient);
    contact.finish_row(0.1);
    contact.add_entry(node, 1, coefficient);
    contact.finish_row(0.1);
    ASSERT_TRUE(exchange(server, assign_request(id++, contact)).has_acknowledge());
    const double force = coefficient > 1e100 ? 1.0 : 1e300;

    protocol::Envelope correction = request(id++);
    correction.mutable_correction()->add_interface_force(force);
    correction.mutable_correction()->add_interface_force(force);
    protocol::Envelope neumann = request(id++);
    neumann.mutable_neumann_solve()->add_contact_force(force);
    neumann.mutable_neumann_solve()->add_contact_force(force);
    protocol::Envelope fields = request(id++);
    fields.mutable_fields()->add_contact_force(force);
    fields.mutable_fields()->add_contact_force(force);

    if (coefficient > 1e100) {
      expect_solver_failure(exchange(server, correction), "CorrectionResult.normal_trace");
      expect_solver_failure(exchange(server, neumann), "NeumannSolveResult.normal_trace");
    }
    expect_solver_failure(exchange(server, fields), "FieldsReply point field");
    expect_hello(server, id++);
    EXPECT_EQ(server.state(), ServerState::ready);
  }
  // Finite requests are still served.
  protocol::Envelope fields = request(id++);
  fields.mutable_fields()->add_contact_force(1.0);
  fields.mutable_fields()->add_contact_force(1.0);
  EXPECT_TRUE(exchange(server, fields).has_fields_reply());
}

/// A FieldsRequest for the two contact rows of the test below, forces `force`, the file written
/// into `directory` and left out of the reply (protocol 2.5).
protocol::Envelope written_fields_request(std::uint64_t id, double force,
                                          const std::string& directory) {
  protocol::Envelope fields = request(id);
  fields.mutable_fields()->add_contact_force(force);
  fields.mutable_fields()->add_contact_force(force);
  fields.mutable_fields()->set_write_directory(directory);
  fields.mutable_fields()->set_omit_fields_from_reply(true);
  return fields;
}

// The file a server writes field by field (omit_fields_from_reply): forces near 1e300 on rows
// of coefficient 1e10 overflow the nodal contact force field, a SOLVER_FAILURE as for a full
// reply, and no file (or temporary file) is left behind; the server stays ready and writes the
// same file again for every later FieldsRequest (nothing of the body is released).
TEST(SubdomainServer, FieldsWrittenByTheServerRefuseNonFiniteValuesAndRepeat) {
  const TemporaryDirectory root("output");
  ServerSettings settings = quiet_settings();
  settings.output_root = root.path();
  SubdomainServer server(settings);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
  ContactOperator contact;
  for (int row = 0; row < 2; ++row) {
    contact.add_entry(interface.node_ids[10], 1, 1e10);
    contact.finish_row(0.1);
  }
  ASSERT_TRUE(exchange(server, assign_request(2, contact)).has_acknowledge());
  expect_solver_failure(exchange(server, written_fields_request(3, 1e300, "overflow")),
                        "FieldsReply point field");
  const std::filesystem::path overflow = root.path() / "overflow";
  EXPECT_TRUE(!std::filesystem::exists(overflow) || listing(overflow).empty());
  EXPECT_EQ(server.state(), ServerState::ready);
  std::uint64_t id = 4;
  for (const char* directory : {"first", "second"}) {
    const protocol::Envelope reply = exchange(server, written_fields_request(id++, 1.0, directory));
    ASSERT_TRUE(reply.has_fields_reply()) << reply.DebugString();
  }
  const std::string first = file_text(root.path() / "first/lower.vtu");
  EXPECT_GT(first.size(), 1000u);
  EXPECT_TRUE(first == file_text(root.path() / "second/lower.vtu"));
}

// Issue 11 (g) through the server: AssignContact rows that combine two nodes,
// 0.5 u_y(a) + 0.5 u_y(b) for neighbouring contact nodes, give the correction and the Neumann
// solve of a BodySolver built in this process with the same operator.
TEST(SubdomainServer, GeneralOperatorMatchesADirectlyBuiltBodySolver) {
  SubdomainServer server(quiet_settings());
  BodySolver reference(lower_block_definition());
  const InterfaceDescription interface = reference.contact_boundary();
  ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
  ContactOperator contact;
  for (std::size_t i = 0; i + 1 < interface.node_ids.size(); ++i) {
    contact.add_entry(interface.node_ids[i], 1, 0.5);
    contact.add_entry(interface.node_ids[i + 1], 1, 0.5);
    contact.finish_row(0.5 * (interface.weights[i] + interface.weights[i + 1]));
  }
  ASSERT_TRUE(exchange(server, assign_request(2, contact)).has_acknowledge());
  reference.assign_contact(contact);
  Eigen::VectorXd force(20);
  for (int i = 0; i < 20; ++i) force[i] = 1.0 + 0.5 * std::cos(1.3 * i);

  protocol::Envelope correction = request(3);
  correction.mutable_correction()->mutable_interface_force()->Assign(force.begin(), force.end());
  protocol::Envelope reply = exchange(server, correction);
  ASSERT_TRUE(reply.has_correction_result()) << reply.DebugString();
  expect_equal_vectors(to_vector(reply.correction_result().normal_trace()),
                       reference.solve_correction(force));
  reply = exchange(server, neumann_solve_request(4, force));
  ASSERT_TRUE(reply.has_neumann_result()) << reply.DebugString();
  const Eigen::VectorXd neumann = to_vector(reply.neumann_result().normal_trace());
  expect_equal_vectors(neumann, reference.solve_neumann(force));
  // The same as the average of the node-wise traces of the displacement.
  const Eigen::VectorXd displacement = reference.displacement(force);
  for (int i = 0; i < 20; ++i) {
    const double expected = 0.5 * (displacement[2 * interface.node_ids[i] + 1] +
                                   displacement[2 * interface.node_ids[i + 1] + 1]);
    EXPECT_NEAR(neumann[i], expected, 1e-12 * (1.0 + std::abs(expected))) << i;
  }
}
TEST(SubdomainServer, FailedSetupDiscardsThePreviousBody) {
  SubdomainServer server(quiet_settings());
  ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
  protocol::SetupBody bad = lower_block_setup();
  bad.clear_contact_boundaries();
  bad.add_contact_boundaries("nowhere");
  expect_error(exchange(server, setup_request(2, bad)), protocol::BAD_INPUT, "awaiting_setup");
  protocol::Envelope assign = request(3);
  assign.mutable_assign_contact();
  expect_error(exchange(server, assign), protocol::WRONG_STATE, "awaiting_setup");
}

TEST(SubdomainServer, FloatingBodyIsSingularNamingTheBody) {
  SubdomainServer server(quiet_settings());
  protocol::SetupBody floating = lower_block_setup();
  floating.mutable_dirichlet(0)->clear_x();  // only u_y fixed: the body can slide along x
  const protocol::Envelope reply = exchange(server, setup_request(1, floating));
  expect_error(reply, protocol::SINGULAR_BODY, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("body 'lower'"), std::string::npos);
}

TEST(SubdomainServer, FloatingBodyIsSetUpWhenTheClientSaysContactHoldsIt) {
  // protocol 2.3: SetupBody.floating; the body's supports leave one rigid motion (u_x) free
  SubdomainServer server(quiet_settings());
  protocol::SetupBody floating = lower_block_setup();
  floating.mutable_dirichlet(0)->clear_x();
  floating.set_floating(true);
  const protocol::Envelope reply = exchange(server, setup_request(1, floating));
  ASSERT_TRUE(reply.has_interface()) << reply.DebugString();
  EXPECT_EQ(reply.interface().rigid_modes(), 1u);  // the horizontal translation
  // the same body with every rigid motion removed reports none
  SubdomainServer held(quiet_settings());
  protocol::SetupBody supported = lower_block_setup();
  supported.set_floating(true);
  const protocol::Envelope held_reply = exchange(held, setup_request(2, supported));
  ASSERT_TRUE(held_reply.has_interface()) << held_reply.DebugString();
  EXPECT_EQ(held_reply.interface().rigid_modes(), 0u);
}

TEST(SubdomainServer, ShutdownIsAcknowledgedAndRaisesTheFlag) {
  SubdomainServer server(quiet_settings());
  EXPECT_FALSE(server.shutdown_requested());
  protocol::Envelope shutdown = request(12);
  shutdown.mutable_shutdown();
  const protocol::Envelope reply = exchange(server, shutdown);
  ASSERT_TRUE(reply.has_acknowledge());
  EXPECT_EQ(reply.acknowledge().state(), "awaiting_setup");
  EXPECT_TRUE(server.shutdown_requested());
}

}  // namespace
}  // namespace robin

namespace robin {
namespace {

/// SetLoadFactor (protocol 2.1) with `factor`.
protocol::Envelope load_factor_request(std::uint64_t id, double factor) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_set_load_factor()->set_factor(factor);
  return envelope;
}

TEST(SubdomainServer, SetLoadFactorScalesTheLoadsAndKeepsTheStateAndF) {
  SubdomainServer server(quiet_settings());
  expect_error(exchange(server, load_factor_request(1, 2.0)), protocol::WRONG_STATE,
               "awaiting_setup");
  protocol::SetupBody setup = lower_block_setup();
  setup.mutable_dirichlet(0)->set_y(0.01);  // the bottom lifted: a prescribed displacement
  setup.add_body_force(0.0);
  setup.add_body_force(-5.0);
  const protocol::Envelope described = exchange(server, setup_request(2, setup));
  ASSERT_TRUE(described.has_interface()) << described.DebugString();
  protocol::Envelope reply = exchange(server, load_factor_request(3, 1.0));
  ASSERT_TRUE(reply.has_load_factor_set()) << reply.DebugString();
  EXPECT_EQ(reply.load_factor_set().state(), "awaiting_assignment");
  EXPECT_EQ(reply.load_factor_set().factor(), 1.0);

  // The reference: the same body built directly, at factor 1 (the definition's values).
  BodyDefinition definition = lower_block_definition();
  definition.dirichlet[0].y = 0.01;
  definition.body_force = {0.0, -5.0, 0.0};
  BodySolver reference(definition);
  const InterfaceDescription interface = reference.contact_boundary();
  reference.assign_contact(assign_all(interface));
  ASSERT_TRUE(exchange(server, assign_all_request(4, interface)).has_acknowledge());
  const Eigen::VectorXd far = Eigen::VectorXd::Constant(reference.contact_size(), 1.0);
  const Eigen::VectorXd unit_trace = reference.free_trace();
  ASSERT_GT(unit_trace.lpNorm<Eigen::Infinity>(), 1e-3);

  reply = exchange(server, load_factor_request(5, -1.5));  // a reversed load is a load too
  ASSERT_TRUE(reply.has_load_factor_set()) << reply.DebugString();
  EXPECT_EQ(reply.load_factor_set().state(), "ready");
  EXPECT_EQ(reply.load_factor_set().factor(), -1.5);
  reply = exchange(server, load_factor_request(6, 2.5));
  ASSERT_TRUE(reply.has_load_factor_set());
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity(), 1e7, -2e6}) {
    reply = exchange(server, load_factor_request(7, bad));
    expect_error(reply, protocol::BAD_INPUT, "ready");
    EXPECT_NE(reply.error().message().find("SetLoadFactor.factor"), std::string::npos)
        << reply.error().message();
    EXPECT_NE(reply.error().message().find("body 'lower'"), std::string::npos);
  }
  // Far obstacles: no contact, u_N = e = 2.5 e(1) (the refused factors changed nothing).
  reply = exchange(server, contact_solve_request(8, far));
  ASSERT_TRUE(reply.has_contact_result()) << reply.DebugString();
  const Eigen::VectorXd trace = to_vector(reply.contact_result().normal_trace());
  EXPECT_LE((trace - 2.5 * unit_trace).lpNorm<Eigen::Infinity>(), 1e-14);
  // F does not depend on the loads: the correction is that of the reference at factor 1.
  const Eigen::VectorXd force = Eigen::VectorXd::LinSpaced(reference.contact_size(), 1.0, 2.0);
  protocol::Envelope correction = request(9);
  correction.mutable_correction()->mutable_interface_force()->Assign(force.begin(), force.end());
  reply = exchange(server, correction);
  ASSERT_TRUE(reply.has_correction_result());
  expect_equal_vectors(to_vector(reply.correction_result().normal_trace()),
                       reference.solve_correction(force));
  // Fields: the applied force and the lift scale with the factor.
  protocol::Envelope fields = request(10);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(reference.contact_size());
  fields.mutable_fields()->mutable_contact_force()->Assign(zero.begin(), zero.end());
  reply = exchange(server, fields);
  ASSERT_TRUE(reply.has_fields_reply());
  ASSERT_EQ(reply.fields_reply().applied_force_size(), 2);
  EXPECT_NEAR(reply.fields_reply().applied_force(1), 2.5 * reference.applied_force().y(),
              1e-12 * std::abs(reference.applied_force().y()));
  EXPECT_EQ(server.state(), ServerState::ready);
}

TEST(SubdomainServer, SetLoadFactorIsUnsupportedByAProtocol20Server) {
  ServerSettings settings = quiet_settings();
  settings.protocol_minor = 0;
  SubdomainServer server(settings);
  protocol::Envelope reply;
  EXPECT_TRUE(
      reply.ParseFromString(server.handle(load_factor_request(1, 2.0).SerializeAsString())));
  expect_error(reply, protocol::UNSUPPORTED, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("protocol 2.1"), std::string::npos)
      << reply.error().message();
}

/// The StageTime entries of a reply by stage name; each stage at most once, every time finite
/// and non-negative.
template <typename StageTimes>
std::map<std::string, double> stage_times(const StageTimes& entries) {
  std::map<std::string, double> stages;
  for (const protocol::StageTime& entry : entries) {
    EXPECT_TRUE(stages.emplace(entry.stage(), entry.seconds()).second) << entry.stage();
    EXPECT_TRUE(std::isfinite(entry.seconds()) && entry.seconds() >= 0.0) << entry.stage();
  }
  return stages;
}

/// The names of a stage map.
std::set<std::string> names_of(const std::map<std::string, double>& stages) {
  std::set<std::string> names;
  for (const auto& [name, seconds] : stages) names.insert(name);
  return names;
}

TEST(SubdomainServer, RepliesCarryTheStageTimesOfProtocol22) {
  SubdomainServer server(quiet_settings());
  const auto start = std::chrono::steady_clock::now();
  const protocol::Envelope setup = exchange(server, setup_request(1, lower_block_setup()));
  const double measured =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(setup.has_interface());
  const protocol::InterfaceDescription& interface = setup.interface();
  const std::map<std::string, double> stages = stage_times(interface.stage_times());
  EXPECT_EQ(names_of(stages),
            (std::set<std::string>{"mesh", "assembly", "ordering", "factorization"}));
  double sum = 0.0;
  for (const auto& [name, seconds] : stages) sum += seconds;
  // the stages lie within the request, the request within the test's own measurement of it
  EXPECT_LE(sum, interface.request_seconds());
  EXPECT_LE(interface.request_seconds(), measured);
  EXPECT_DOUBLE_EQ(interface.setup_seconds(),
                   stages.at("assembly") + stages.at("ordering") + stages.at("factorization"));

  const InterfaceDescription body_interface =
      BodySolver(lower_block_definition()).contact_boundary();
  const protocol::Envelope acknowledge = exchange(server, assign_all_request(2, body_interface));
  ASSERT_TRUE(acknowledge.has_acknowledge());
  EXPECT_EQ(names_of(stage_times(acknowledge.acknowledge().stage_times())),
            std::set<std::string>{"interface operator"});
  const protocol::Envelope fields = exchange(server, fields_request(3, ""));
  ASSERT_TRUE(fields.has_fields_reply());
  EXPECT_EQ(names_of(stage_times(fields.fields_reply().stage_times())),
            std::set<std::string>{"fields"});
}

TEST(SubdomainServer, AProtocol21ServerSendsNoStageTimes) {
  ServerSettings settings = quiet_settings();
  settings.protocol_minor = 1;
  SubdomainServer server(settings);
  const auto handle = [&server](const protocol::Envelope& envelope) {
    protocol::Envelope reply;
    EXPECT_TRUE(reply.ParseFromString(server.handle(envelope.SerializeAsString())));
    return reply;
  };
  const protocol::Envelope setup = handle(setup_request(1, lower_block_setup()));
  ASSERT_TRUE(setup.has_interface());
  EXPECT_EQ(setup.interface().stage_times_size(), 0);
  EXPECT_EQ(setup.interface().request_seconds(), 0.0);
  EXPECT_GT(setup.interface().setup_seconds(), 0.0);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  EXPECT_EQ(handle(assign_all_request(2, interface)).acknowledge().stage_times_size(), 0);
  EXPECT_EQ(handle(fields_request(3, "")).fields_reply().stage_times_size(), 0);
}

}  // namespace
}  // namespace robin
