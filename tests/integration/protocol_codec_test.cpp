// The coordinator's protocol module without any server:
//  - materials travel exactly: an isotropic plane-strain material as (E, nu) from which the
//    server's make_isotropic_material rebuilds the same C bit for bit; any other material as
//    its row-major C;
//  - SetupBody of examples/two_blocks.toml carries the mesh as MeshData (protocol 2.0: never the
//    file's bytes or a script), which decodes to the mesh read from the file, and the case's
//    values; AssignContact carries the constraint operator B in compressed rows;
//  - a hand-written two-triangle FieldsReply decodes to the expected mesh and fields, and
//    inconsistent replies are refused.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "mesh_codec.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/material.hpp"
#include "remote/reply_decoding.hpp"
#include "remote/setup_encoding.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;

TEST(MaterialEncoding, IsotropicPlaneStrainIsRebuiltBitForBit) {
  for (const auto& [young, poisson] : std::vector<std::pair<double, double>>{
           {1000.0, 0.3}, {210e3, 0.29}, {70.0, 0.33}, {1.0, -0.5}, {3.7e-3, 0.4999}}) {
    const Material material =
        make_isotropic_material(young, poisson, PlaneModel::plane_strain, "test");
    protocol::SetupBody message;
    encode_material(material, "test", message);
    EXPECT_EQ(message.voigt_size(), 0);
    EXPECT_EQ(message.poisson_ratio(), poisson);
    const Material rebuilt = make_isotropic_material(
        message.young_modulus(), message.poisson_ratio(), PlaneModel::plane_strain, "server");
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        EXPECT_EQ(rebuilt.stiffness(i, j), material.stiffness(i, j))
            << "E " << young << ", nu " << poisson << ", C(" << i << ", " << j << ")";
      }
    }
    EXPECT_EQ(rebuilt.out_of_plane_poisson, material.out_of_plane_poisson);
  }
}

TEST(MaterialEncoding, PlaneStressAndVoigtMaterialsTravelAsTheirMatrix) {
  Eigen::Matrix3d general;
  general << 200.0, 50.0, 10.0, 50.0, 100.0, 5.0, 10.0, 5.0, 40.0;
  for (const Material& material :
       {make_isotropic_material(1000.0, 0.3, PlaneModel::plane_stress, "test"),
        make_voigt_material(general, PlaneModel::plane_strain, "test")}) {
    protocol::SetupBody message;
    encode_material(material, "test", message);
    ASSERT_EQ(message.voigt_size(), 9);
    EXPECT_EQ(message.young_modulus(), 0.0);
    for (int k = 0; k < 9; ++k) EXPECT_EQ(message.voigt(k), material.stiffness(k / 3, k % 3));
  }
  EXPECT_EQ(general(0, 2), 10.0);  // row-major: voigt[2] is C_02
}

TEST(MaterialEncoding, OutOfPlaneFactorWithoutIsotropyIsRefused) {
  Material material;
  material.stiffness << 200.0, 50.0, 0.0, 50.0, 100.0, 0.0, 0.0, 0.0, 40.0;
  material.out_of_plane_poisson = 0.25;
  protocol::SetupBody message;
  EXPECT_THROW(encode_material(material, "case.toml: body 'upper'", message), InputError);
}

TEST(SetupEncoding, TwoBlocksBodiesCarryTheCaseValues) {
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);
  const BodyCase& upper = definition.bodies[1];
  const protocol::SetupBody message =
      encode_setup_body(upper.definition, upper.context, definition.solver);
  EXPECT_EQ(message.body_name(), "upper");
  // The mesh as data: the mesh Gmsh makes of block_upper.geo with the case's h = 0.1, node for
  // node and element for element; the 1.x fields (mesh_content, mesh_extension) are gone.
  const Mesh file_mesh = read_gmsh_mesh(example("meshes/block_upper.geo"), {.size = 0.1});
  ASSERT_TRUE(message.has_mesh());
  EXPECT_EQ(message.mesh().dimension(), 2u);
  EXPECT_EQ(message.mesh().source(), example("meshes/block_upper.geo").string());
  EXPECT_TRUE(message.GetReflection()->GetUnknownFields(message).empty());
  EXPECT_EQ(message.mesh_path(), "");
  const Mesh sent = decode_mesh(message.mesh(), "test");
  EXPECT_EQ(sent.nodes, file_mesh.nodes);
  EXPECT_EQ(sent.node_tags, file_mesh.node_tags);
  ASSERT_EQ(sent.blocks.size(), file_mesh.blocks.size());
  for (std::size_t b = 0; b < sent.blocks.size(); ++b) {
    EXPECT_EQ(sent.blocks[b].type, file_mesh.blocks[b].type);
    EXPECT_EQ(sent.blocks[b].connectivity, file_mesh.blocks[b].connectivity);
    EXPECT_EQ(sent.blocks[b].tags, file_mesh.blocks[b].tags);
  }
  ASSERT_EQ(sent.boundaries.size(), file_mesh.boundaries.size());
  for (const auto& [name, group] : file_mesh.boundaries) {
    EXPECT_EQ(sent.boundary(name).type, group.type) << name;
    EXPECT_EQ(sent.boundary(name).connectivity, group.connectivity) << name;
  }
  EXPECT_EQ(message.model(), protocol::PLANE_STRAIN);
  EXPECT_EQ(message.young_modulus(), 1000.0);
  EXPECT_EQ(message.poisson_ratio(), 0.3);
  ASSERT_EQ(message.contact_boundaries_size(), 1);
  EXPECT_EQ(message.contact_boundaries(0), "contact");
  ASSERT_EQ(message.dirichlet_size(), 1);
  EXPECT_EQ(message.dirichlet(0).boundary(), "top");
  EXPECT_EQ(message.dirichlet(0).x(), 0.0);
  EXPECT_EQ(message.dirichlet(0).y(), -0.01);
  EXPECT_EQ(message.traction_size(), 0);
  ASSERT_EQ(message.body_force_size(), 2);
  EXPECT_EQ(message.body_force(1), 0.0);
  EXPECT_EQ(message.solver().qp_tolerance(), definition.solver.qp.relative_tolerance);
}

// The solver hints travel as the strings of docs/protocol.md (SolverSettings).
TEST(SetupEncoding, SolverHintsTravelAsTheirProtocolStrings) {
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);
  const BodyCase& upper = definition.bodies[1];
  SolverOptions solver = definition.solver;
  protocol::SetupBody message = encode_setup_body(upper.definition, upper.context, solver);
  EXPECT_EQ(message.solver().interface_operator(), "auto");
  EXPECT_EQ(message.solver().linear_solver(), "direct");
  solver.body.interface_operator = InterfaceOperatorKind::factor;
  solver.body.linear_solver = LinearSolverKind::multigrid;
  message = encode_setup_body(upper.definition, upper.context, solver);
  EXPECT_EQ(message.solver().interface_operator(), "factor");
  EXPECT_EQ(message.solver().linear_solver(), "multigrid");
}

// "auto" never travels: the coordinator resolves it by the body's size (resolve_linear_solver),
// so that every server, whatever it knows of the hint, gets "direct" or "multigrid". A plane body
// and a small solid get "direct", a solid of more than automatic_multigrid_dofs "multigrid",
// unless it is floating.
TEST(SetupEncoding, AutomaticLinearSolverIsResolvedByTheBodysSize) {
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);
  SolverOptions solver = definition.solver;
  solver.body.linear_solver = LinearSolverKind::automatic;
  const BodyCase& plane = definition.bodies[1];
  EXPECT_EQ(encode_setup_body(plane.definition, plane.context, solver).solver().linear_solver(),
            "direct");
  BodyDefinition solid = plane.definition;
  solid.material = make_isotropic_solid_material(1000.0, 0.3, "solid");
  solid.dirichlet.clear();
  solid.tractions.clear();
  solid.contact_boundaries = {"top"};
  solid.mesh =
      make_box_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, {10, 10, 10}, ElementType::hexahedron8);
  EXPECT_LE(solid.mesh.dof_count(), automatic_multigrid_dofs);
  EXPECT_EQ(encode_setup_body(solid, "small", solver).solver().linear_solver(), "direct");
  solid.mesh =
      make_box_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, {37, 37, 37}, ElementType::hexahedron8);
  EXPECT_GT(solid.mesh.dof_count(), automatic_multigrid_dofs);
  EXPECT_EQ(encode_setup_body(solid, "large", solver).solver().linear_solver(), "multigrid");
  EXPECT_EQ(encode_setup_body(solid, "floating", solver, true).solver().linear_solver(), "direct");
}

TEST(SetupEncoding, ConstraintOperatorTravelsInCompressedRows) {
  ContactOperator contact;
  contact.add_entry(4, 0, 0.6);
  contact.add_entry(4, 1, -0.8);
  contact.finish_row(0.25);
  contact.add_entry(7, 1, 0.5);
  contact.add_entry(9, 1, 0.5);
  contact.add_entry(9, 0, 1e-3);
  contact.finish_row(0.5);
  const protocol::AssignContact message = encode_contact_operator(contact);
  EXPECT_EQ(std::vector<std::uint64_t>(message.row_offsets().begin(), message.row_offsets().end()),
            (std::vector<std::uint64_t>{0, 2, 5}));
  EXPECT_EQ(std::vector<std::int64_t>(message.node_ids().begin(), message.node_ids().end()),
            (std::vector<std::int64_t>{4, 4, 7, 9, 9}));
  EXPECT_EQ(std::vector<std::uint32_t>(message.components().begin(), message.components().end()),
            (std::vector<std::uint32_t>{0, 1, 1, 1, 0}));
  EXPECT_EQ(std::vector<double>(message.values().begin(), message.values().end()),
            (std::vector<double>{0.6, -0.8, 0.5, 0.5, 1e-3}));
  EXPECT_EQ(std::vector<double>(message.weights().begin(), message.weights().end()),
            (std::vector<double>{0.25, 0.5}));
}

/// Two linear triangles on the unit square: nodes (0,0), (1,0), (1,1), (0,1).
protocol::FieldsReply unit_square_reply() {
  protocol::FieldsReply reply;
  for (double value : {0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0}) reply.add_node_coordinates(value);
  for (long tag : {11, 12, 13, 14}) reply.add_node_tags(tag);
  reply.add_cell_types(5);
  reply.add_cell_offsets(0);
  reply.add_cell_offsets(6);
  for (long node : {0, 1, 2, 0, 2, 3}) reply.add_connectivity(node);
  protocol::Field& displacement = *reply.add_point_fields();
  displacement.set_name("displacement");
  displacement.set_components(2);
  for (int k = 0; k < 8; ++k) displacement.add_values(0.5 * k);
  protocol::Field& stress = *reply.add_cell_fields();
  stress.set_name("stress");
  stress.set_components(3);
  for (int k = 0; k < 6; ++k) stress.add_values(k);
  reply.add_reaction_resultant(1.5);
  reply.add_reaction_resultant(-2.5);
  return reply;
}

TEST(FieldsDecoding, UnitSquareDecodesToItsMeshAndFields) {
  const BodyOutput output = decode_fields(unit_square_reply(), "square");
  EXPECT_EQ(output.body_name, "square");
  ASSERT_EQ(output.mesh.nodes.size(), 4u);
  EXPECT_EQ(output.mesh.nodes[2], Eigen::Vector3d(1.0, 1.0, 0.0));
  EXPECT_EQ(output.mesh.node_tags[3], 14u);
  ASSERT_EQ(output.mesh.blocks.size(), 1u);
  EXPECT_EQ(output.mesh.blocks[0].type, ElementType::triangle3);
  EXPECT_EQ(output.mesh.blocks[0].connectivity, (std::vector<int>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(output.point_fields.size(), 1u);
  EXPECT_EQ(output.point_fields[0].values[7], 3.5);
  ASSERT_EQ(output.cell_fields.size(), 1u);
  EXPECT_EQ(output.cell_fields[0].component_names, (std::vector<std::string>{"xx", "yy", "xy"}));
  EXPECT_EQ(output.reaction_resultant, Eigen::Vector3d(1.5, -2.5, 0.0));
  EXPECT_EQ(output.applied_force, Eigen::Vector3d::Zero());
}

TEST(FieldsDecoding, InconsistentRepliesAreRefused) {
  protocol::FieldsReply bad_index = unit_square_reply();
  bad_index.set_connectivity(5, 4);  // node 4 of 4
  EXPECT_THROW(decode_fields(bad_index, "square"), MalformedReply);
  protocol::FieldsReply bad_field = unit_square_reply();
  bad_field.mutable_point_fields(0)->add_values(1.0);  // 9 values for 4 nodes x 2
  EXPECT_THROW(decode_fields(bad_field, "square"), MalformedReply);
  protocol::FieldsReply bad_type = unit_square_reply();
  bad_type.set_cell_types(0, 10);  // VTK tetrahedron
  EXPECT_THROW(decode_fields(bad_type, "square"), MalformedReply);
  EXPECT_EQ(element_type_of_vtk_cell(22), ElementType::triangle6);
  EXPECT_EQ(element_type_of_vtk_cell(9), ElementType::quadrilateral4);
}

TEST(ContactDecoding, SizesAreChecked) {
  protocol::ContactSolveResult message;
  message.set_status(protocol::CONVERGED);
  for (double value : {0.1, 0.2}) message.add_normal_trace(value);
  for (double value : {0.0, 3.0}) message.add_contact_force(value);
  const ContactSolveResult result = decode_contact_result(message, 2);
  EXPECT_EQ(result.active, (std::vector<bool>{false, true}));  // lambda_i > 0 without flags
  EXPECT_EQ(result.status, QpStatus::converged);
  EXPECT_THROW(decode_contact_result(message, 3), MalformedReply);
}

/// The message of the MalformedReply that decoding `message` throws, or "" when it decodes.
template <typename Decode>
std::string malformed_message(Decode decode) {
  try {
    decode();
  } catch (const MalformedReply& error) {
    return error.what();
  }
  return "";
}

TEST(ContactDecoding, NonFiniteValuesAndTensileForcesAreRefused) {
  protocol::ContactSolveResult message;
  message.set_status(protocol::CONVERGED);
  for (double value : {0.1, std::nan("")}) message.add_normal_trace(value);
  for (double value : {0.0, 3.0}) message.add_contact_force(value);
  const auto decode = [&] { decode_contact_result(message, 2); };
  EXPECT_NE(malformed_message(decode).find("normal_trace[1]"), std::string::npos)
      << malformed_message(decode);
  message.set_normal_trace(1, 0.2);
  message.set_contact_force(0, -1e-3);  // beyond round-off of the largest force 3
  EXPECT_NE(malformed_message(decode).find("contact_force[0]"), std::string::npos);
  EXPECT_NE(malformed_message(decode).find("compressive"), std::string::npos);
  message.set_contact_force(0, -1e-13);  // round-off: accepted
  EXPECT_EQ(malformed_message(decode), "");

  protocol::CorrectionResult correction;
  correction.add_normal_trace(std::numeric_limits<double>::infinity());
  EXPECT_NE(malformed_message([&] { decode_correction_result(correction, 1); }).find("finite"),
            std::string::npos);
}

}  // namespace
}  // namespace robin
