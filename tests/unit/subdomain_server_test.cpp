// SubdomainServer::handle, in process: a whole run (Hello, SetupBody, AssignContact, contact
// and correction solves, fields, EndRun, a second run) compared with a BodySolver built
// directly from the same body definition, the equilibrium of the returned fields, and every
// error reply of the state machine. The Neumann solve of protocol 1.1 (NeumannSolveRequest)
// against the normal trace of BodySolver::displacement, its refusals, and a server that
// withholds it (as a protocol 1.0 server would not know it). The run rule of protocol 1.2
// (Envelope.run_id): requests of another run than the body's are WRONG_STATE and change nothing,
// the body's run and requests without run_id are served, and a server playing 1.1 ignores it.

#include "server/subdomain_server.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "numerics/body_output.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/material.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

const std::filesystem::path lower_geo =
    std::filesystem::path(ROBIN_EXAMPLES) / "meshes/block_lower.geo";

std::string file_text(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

/// Body 1 of examples/two_blocks.toml: block_lower.geo with h = 0.1, plane strain, E = 1000,
/// nu = 0.3, clamped bottom, contact boundary "contact".
protocol::SetupBody lower_block_setup() {
  protocol::SetupBody setup;
  setup.set_body_name("lower");
  setup.set_mesh_content(file_text(lower_geo));
  setup.set_mesh_extension(".geo");
  setup.set_mesh_size(0.1);
  setup.set_model(protocol::PLANE_STRAIN);
  setup.set_young_modulus(1000.0);
  setup.set_poisson_ratio(0.3);
  protocol::Dirichlet& bottom = *setup.add_dirichlet();
  bottom.set_boundary("bottom");
  bottom.set_x(0.0);
  bottom.set_y(0.0);
  setup.set_contact_boundary("contact");
  return setup;
}

/// The same body built without the server.
BodyDefinition lower_block_definition() {
  BodyDefinition definition;
  definition.name = "lower";
  MeshReadOptions options;
  options.size = 0.1;
  definition.mesh = read_gmsh_mesh(lower_geo, options);
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.0, 0.0});
  definition.contact_boundary = "contact";
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

/// Every contact boundary node of `interface`, with the normal (0, 1), in ascending id order.
protocol::Envelope assign_all_request(std::uint64_t id, const InterfaceDescription& interface) {
  protocol::Envelope envelope = request(id);
  for (int node : interface.node_ids) {
    envelope.mutable_assign_contact()->add_node_ids(node);
    envelope.mutable_assign_contact()->add_normals(0.0);
    envelope.mutable_assign_contact()->add_normals(1.0);
  }
  return envelope;
}

/// NeumannSolveRequest (protocol 1.1) with the contact force `force`.
protocol::Envelope neumann_solve_request(std::uint64_t id, const Eigen::VectorXd& force) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_neumann_solve()->set_iteration(static_cast<unsigned>(id));
  envelope.mutable_neumann_solve()->mutable_contact_force()->Assign(force.begin(), force.end());
  return envelope;
}

ContactAssignment assign_all(const InterfaceDescription& interface) {
  ContactAssignment assignment;
  assignment.node_ids = interface.node_ids;
  assignment.normals.assign(interface.node_ids.size(), Eigen::Vector2d(0.0, 1.0));
  return assignment;
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
  return settings;
}

/// Checks the InterfaceDescription against the directly built solver, and against the
/// geometry of block_lower.geo: 21 nodes on y = 0 from x = -1 to 1, normals (0, 1), weights
/// summing to the edge length 2, none of them fixed (only the bottom is clamped).
void expect_interface(const protocol::InterfaceDescription& message,
                      const InterfaceDescription& expected, const BodySolver& reference) {
  EXPECT_EQ(message.body_name(), "lower");
  ASSERT_EQ(message.node_ids_size(), 21);
  ASSERT_EQ(expected.node_ids.size(), 21u);
  double weight_sum = 0.0;
  for (int i = 0; i < 21; ++i) {
    EXPECT_EQ(message.node_ids(i), expected.node_ids[i]);
    EXPECT_EQ(message.node_tags(i), static_cast<std::int64_t>(expected.node_tags[i]));
    EXPECT_NEAR(message.coordinates(2 * i), expected.coordinates[i].x(), 1e-12);
    EXPECT_NEAR(message.coordinates(2 * i + 1), 0.0, 1e-12);
    EXPECT_NEAR(message.normals(2 * i), 0.0, 1e-12);
    EXPECT_NEAR(message.normals(2 * i + 1), 1.0, 1e-12);
    EXPECT_NEAR(message.weights(i), expected.weights[i], 1e-12);
    EXPECT_FALSE(message.x_fixed(i));
    EXPECT_FALSE(message.y_fixed(i));
    weight_sum += message.weights(i);
  }
  EXPECT_NEAR(weight_sum, 2.0, 1e-12);
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

/// A correction (r_i = 1 + x_i) and the fields for `contact_force`, written to a temporary
/// directory, compared with `reference`.
void expect_correction_and_fields(SubdomainServer& server, const BodySolver& reference,
                                  const InterfaceDescription& interface,
                                  const Eigen::VectorXd& contact_force) {
  protocol::Envelope correction = request(5);
  Eigen::VectorXd interface_force(21);
  for (int i = 0; i < 21; ++i) interface_force[i] = 1.0 + interface.coordinates[i].x();
  correction.mutable_correction()->mutable_interface_force()->Assign(interface_force.begin(),
                                                                     interface_force.end());
  protocol::Envelope reply = exchange(server, correction);
  ASSERT_TRUE(reply.has_correction_result()) << reply.DebugString();
  expect_equal_vectors(to_vector(reply.correction_result().normal_trace()),
                       reference.solve_correction(interface_force));

  const std::filesystem::path directory = std::filesystem::temp_directory_path() /
                                          ("subdomain_server_test_" + std::to_string(getpid()));
  protocol::Envelope fields = request(6);
  fields.mutable_fields()->mutable_contact_force()->Assign(contact_force.begin(),
                                                           contact_force.end());
  fields.mutable_fields()->set_write_directory(directory.string());
  reply = exchange(server, fields);
  ASSERT_TRUE(reply.has_fields_reply()) << reply.DebugString();
  expect_fields(reply.fields_reply(), reference, contact_force);
  EXPECT_EQ(reply.fields_reply().written_file(), (directory / "lower.vtu").string());
  EXPECT_TRUE(std::filesystem::is_regular_file(directory / "lower.vtu"));
  std::filesystem::remove_all(directory);
}

TEST(SubdomainServer, FullRunMatchesADirectlyBuiltBodySolver) {
  SubdomainServer server(quiet_settings());
  BodySolver reference(lower_block_definition());
  const InterfaceDescription interface = reference.contact_boundary();

  protocol::Envelope hello = request(1);
  hello.mutable_hello()->set_client_name("subdomain_server_test");
  protocol::Envelope reply = exchange(server, hello);
  ASSERT_TRUE(reply.has_hello_reply()) << reply.DebugString();
  EXPECT_EQ(reply.hello_reply().state(), "awaiting_setup");
  EXPECT_NE(reply.hello_reply().server_name().find("unit test"), std::string::npos);
  EXPECT_EQ(
      std::vector<std::string>(reply.hello_reply().capabilities().begin(),
                               reply.hello_reply().capabilities().end()),
      (std::vector<std::string>{"contact_solve", "correction_solve", "fields", "neumann_solve"}));

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

  expect_correction_and_fields(server, reference, interface, expected.contact_force);

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
  const protocol::Envelope reply = exchange(server, hello_request(9, 2));
  expect_error(reply, protocol::VERSION_MISMATCH, "awaiting_setup");
  EXPECT_NE(reply.error().message().find("2.0"), std::string::npos) << reply.error().message();
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
  EXPECT_NE(reply.error().message().find("20 values for the 21 contact nodes of body 'lower'"),
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
                                         "21 contact nodes of body 'lower'"),
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

TEST(SubdomainServer, ServerPlayingProtocol11IgnoresRunId) {
  ServerSettings settings = quiet_settings();
  settings.protocol_minor = 1;
  SubdomainServer server(settings);
  const InterfaceDescription interface = BodySolver(lower_block_definition()).contact_boundary();
  const auto handle = [&server](const protocol::Envelope& envelope) {
    protocol::Envelope reply;
    EXPECT_TRUE(reply.ParseFromString(server.handle(envelope.SerializeAsString())));
    EXPECT_EQ(reply.version().minor(), 1u);
    return reply;
  };
  ASSERT_TRUE(handle(of_run(setup_request(1, lower_block_setup()), "a")).has_interface());
  ASSERT_TRUE(handle(of_run(assign_all_request(2, interface), "b")).has_acknowledge());
  EXPECT_TRUE(handle(of_run(contact_solve_request(3, Eigen::VectorXd::Ones(21)), "b"))
                  .has_contact_result());
}

TEST_F(ReadyServer, BadAssignmentsAreInvalidAndKeepThePreviousAssignment) {
  protocol::Envelope unknown = assign_all_request(3, interface);
  unknown.mutable_assign_contact()->set_node_ids(0, 1000000);
  protocol::Envelope repeated = assign_all_request(4, interface);
  repeated.mutable_assign_contact()->set_node_ids(1, interface.node_ids[0]);
  protocol::Envelope not_unit = assign_all_request(5, interface);
  not_unit.mutable_assign_contact()->set_normals(1, 1.1);
  protocol::Envelope short_normals = assign_all_request(6, interface);
  short_normals.mutable_assign_contact()->mutable_normals()->RemoveLast();
  for (const protocol::Envelope& bad : {unknown, repeated, not_unit, short_normals}) {
    const protocol::Envelope reply = exchange(server, bad);
    expect_error(reply, protocol::INVALID_ARGUMENT, "ready");
    EXPECT_NE(reply.error().message().find("body 'lower'"), std::string::npos);
  }
  EXPECT_NE(exchange(server, unknown).error().message().find("node id 1000000"), std::string::npos);
  EXPECT_TRUE(
      exchange(server, contact_solve_request(7, Eigen::VectorXd::Zero(21))).has_contact_result());
}

TEST(SubdomainServer, BadBodyDefinitionsAreBadInputNamingTheBodyAndField) {
  SubdomainServer server(quiet_settings());
  protocol::SetupBody bad_mesh = lower_block_setup();
  bad_mesh.set_mesh_content("this is not a mesh");
  bad_mesh.set_mesh_extension(".msh");
  protocol::SetupBody unknown_boundary = lower_block_setup();
  unknown_boundary.mutable_dirichlet(0)->set_boundary("botom");
  protocol::SetupBody short_voigt = lower_block_setup();
  short_voigt.clear_young_modulus();
  short_voigt.clear_poisson_ratio();
  for (double value : {1.0, 0.0, 0.0, 1.0}) short_voigt.add_voigt(value);
  protocol::SetupBody no_model = lower_block_setup();
  no_model.clear_model();
  const std::vector<std::pair<protocol::SetupBody, std::string>> cases = {
      {bad_mesh, "SetupBody.mesh_content"},
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

// A .geo sent over the protocol is a Gmsh script: one that would run a shell command on the
// server is refused before Gmsh sees it, and the command does not run (the file it would create
// does not appear). The same script with the command only in a comment and a string meshes.
TEST(SubdomainServer, GeoScriptThatRunsACommandIsRefusedUnrun) {
  SubdomainServer server(quiet_settings());
  const std::filesystem::path witness =
      std::filesystem::temp_directory_path() / ("robin-geo-witness-" + std::to_string(::getpid()));
  std::filesystem::remove(witness);
  protocol::SetupBody hostile = lower_block_setup();
  hostile.set_mesh_content(hostile.mesh_content() + "\nSystemCall \"touch " + witness.string() +
                           "\";\n");
  const protocol::Envelope reply = exchange(server, setup_request(1, hostile));
  expect_error(reply, protocol::BAD_INPUT, "awaiting_setup");
  const std::string& message = reply.error().message();
  EXPECT_NE(message.find("body 'lower': SetupBody.mesh_content line"), std::string::npos)
      << message;
  EXPECT_NE(message.find("'SystemCall' is refused"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(witness));

  protocol::SetupBody harmless = lower_block_setup();
  harmless.set_mesh_content(harmless.mesh_content() +
                            "\n// SystemCall \"touch x\";\nDummy = StrCat(\"Include\");\n");
  EXPECT_TRUE(exchange(server, setup_request(2, harmless)).has_interface());
}

TEST(SubdomainServer, FailedSetupDiscardsThePreviousBody) {
  SubdomainServer server(quiet_settings());
  ASSERT_TRUE(exchange(server, setup_request(1, lower_block_setup())).has_interface());
  protocol::SetupBody bad = lower_block_setup();
  bad.set_contact_boundary("nowhere");
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
