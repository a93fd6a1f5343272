// Protocol 2.4, solid (three-dimensional) bodies, without a server process:
//  - MeshData of a tetrahedron with a triangular boundary face travels both ways, dimension 3,
//    and cells or faces of the other dimension are refused naming the field;
//  - SetupBody of a solid body carries 36 Voigt values, three-component loads and Dirichlet.z,
//    and the server's decoding rebuilds the same definition;
//  - a solid InterfaceDescription carries three coordinates, normals and fixed flags per node;
//  - a FieldsReply of a quadratic tetrahedron carries dimension 3, VTK's node order on the wire
//    and decodes back to Gmsh's.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mesh_codec.hpp"
#include "numerics/errors.hpp"
#include "remote/reply_decoding.hpp"
#include "remote/setup_encoding.hpp"
#include "server/reply_encoding.hpp"
#include "server/setup_decoding.hpp"

namespace robin {
namespace {

/// The unit tetrahedron (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), positively oriented, with
/// its face z = 0 as the boundary "base" (oriented outward, -z) and x = 0 as "side".
Mesh unit_tetrahedron() {
  Mesh mesh;
  mesh.dimension = 3;
  mesh.source = "tetrahedron.msh";
  mesh.nodes = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  mesh.node_tags = {11, 12, 13, 14};
  mesh.blocks.push_back({ElementType::tetrahedron4, {0, 1, 2, 3}, {7}});
  mesh.boundaries["base"] = {FacetType::triangle3, {0, 2, 1}};
  mesh.boundaries["side"] = {FacetType::triangle3, {0, 3, 2}};
  return mesh;
}

std::string input_error(const std::function<void()>& call) {
  try {
    call();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SolidMeshData, TetrahedronTravelsBothWays) {
  const Mesh mesh = unit_tetrahedron();
  const protocol::MeshData data = encode_mesh(mesh);
  EXPECT_EQ(data.dimension(), 3u);
  ASSERT_EQ(data.coordinates_size(), 12);
  EXPECT_EQ(data.coordinates(11), 1.0);
  ASSERT_EQ(data.cells_size(), 1);
  EXPECT_EQ(data.cells(0).type(), protocol::TETRAHEDRON4);
  ASSERT_EQ(data.boundaries_size(), 2);
  EXPECT_EQ(data.boundaries(0).segments().type(), protocol::TRIANGLE3);
  const Mesh decoded = decode_mesh(data, "body 'ball'");
  EXPECT_EQ(decoded.dimension, 3);
  EXPECT_EQ(decoded.nodes, mesh.nodes);
  EXPECT_EQ(decoded.node_tags, mesh.node_tags);
  ASSERT_EQ(decoded.blocks.size(), 1u);
  EXPECT_EQ(decoded.blocks[0].type, ElementType::tetrahedron4);
  EXPECT_EQ(decoded.blocks[0].connectivity, mesh.blocks[0].connectivity);
  EXPECT_EQ(decoded.boundary("base").type, FacetType::triangle3);
  EXPECT_EQ(decoded.boundary("base").connectivity, mesh.boundary("base").connectivity);
}

TEST(SolidMeshData, CellsOfTheOtherDimensionAreRefused) {
  protocol::MeshData solid = encode_mesh(unit_tetrahedron());
  protocol::MeshData wrong_face = solid;
  wrong_face.mutable_boundaries(0)->mutable_segments()->set_type(protocol::LINE2);
  std::string text = input_error([&] { decode_mesh(wrong_face, "body 'ball'"); });
  EXPECT_NE(text.find("SetupBody.mesh.boundaries[0].segments.type is LINE2"), std::string::npos)
      << text;
  EXPECT_NE(text.find("TRIANGLE3, TRIANGLE6 or QUADRILATERAL4"), std::string::npos) << text;

  protocol::MeshData plane_cells = solid;
  plane_cells.mutable_cells(0)->set_type(protocol::QUADRILATERAL4);
  text = input_error([&] { decode_mesh(plane_cells, "body 'ball'"); });
  EXPECT_NE(text.find("SetupBody.mesh.cells[0].type is QUADRILATERAL4"), std::string::npos) << text;

  protocol::MeshData short_coordinates = solid;
  short_coordinates.mutable_coordinates()->RemoveLast();
  text = input_error([&] { decode_mesh(short_coordinates, "body 'ball'"); });
  EXPECT_NE(text.find("SetupBody.mesh.coordinates has 11 values, expected a positive multiple "
                      "of 3 (x, y, z per node)"),
            std::string::npos)
      << text;

  protocol::MeshData solid_in_plane = solid;
  solid_in_plane.set_dimension(2);
  solid_in_plane.clear_coordinates();
  for (const double value : {0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0}) {
    solid_in_plane.add_coordinates(value);
  }
  text = input_error([&] { decode_mesh(solid_in_plane, "body 'ball'"); });
  EXPECT_NE(text.find("SetupBody.mesh.cells[0].type is TETRAHEDRON4: expected TRIANGLE3"),
            std::string::npos)
      << text;

  protocol::MeshData four = solid;
  four.set_dimension(4);
  text = input_error([&] { decode_mesh(four, "body 'ball'"); });
  EXPECT_NE(text.find("SetupBody.mesh.dimension is 4"), std::string::npos) << text;
}

TEST(SolidSetup, SolidBodyTravelsAndDecodesToItsDefinition) {
  BodyDefinition definition;
  definition.name = "ball";
  definition.mesh = unit_tetrahedron();
  definition.material = make_isotropic_solid_material(1000.0, 0.3, "ball");
  definition.body_force = {1.0, -2.0, 3.5};
  definition.dirichlet.push_back({"base", std::nullopt, std::nullopt, 0.25});
  TractionCondition traction;
  traction.boundary = "side";
  traction.vector = {0.5, 0.0, -1.5};
  definition.tractions.push_back(traction);
  definition.contact_boundaries = {"side"};
  const protocol::SetupBody message = encode_setup_body(definition, "ball", SolverOptions{});
  EXPECT_EQ(message.model(), protocol::PLANE_MODEL_UNSPECIFIED);
  EXPECT_EQ(message.voigt_size(), 36);
  EXPECT_EQ(message.body_force_size(), 3);
  ASSERT_EQ(message.dirichlet_size(), 1);
  EXPECT_TRUE(message.dirichlet(0).has_z());
  EXPECT_FALSE(message.dirichlet(0).has_x());
  ASSERT_EQ(message.traction_size(), 1);
  EXPECT_EQ(message.traction(0).vector_size(), 3);

  const DecodedSetup decoded = decode_setup_body(message, MeshFiles{});
  EXPECT_EQ(decoded.definition.mesh.dimension, 3);
  EXPECT_EQ(decoded.definition.material.stiffness, definition.material.stiffness);
  EXPECT_EQ(decoded.definition.body_force, definition.body_force);
  ASSERT_EQ(decoded.definition.dirichlet.size(), 1u);
  EXPECT_EQ(decoded.definition.dirichlet[0].z, 0.25);
  EXPECT_FALSE(decoded.definition.dirichlet[0].x.has_value());
  EXPECT_EQ(decoded.definition.tractions.at(0).vector, traction.vector);

  // The isotropic constants give the isotropic solid.
  protocol::SetupBody isotropic = message;
  isotropic.clear_voigt();
  isotropic.set_young_modulus(1000.0);
  isotropic.set_poisson_ratio(0.3);
  EXPECT_EQ(decode_setup_body(isotropic, MeshFiles{}).definition.material.stiffness,
            definition.material.stiffness);

  protocol::SetupBody nine = message;
  nine.mutable_voigt()->Truncate(9);
  std::string text = input_error([&] { decode_setup_body(nine, MeshFiles{}); });
  EXPECT_NE(text.find("SetupBody.voigt has 9 values, expected 36 (row-major 6x6"),
            std::string::npos)
      << text;
  protocol::SetupBody plane_force = message;
  plane_force.mutable_body_force()->RemoveLast();
  text = input_error([&] { decode_setup_body(plane_force, MeshFiles{}); });
  EXPECT_NE(text.find("SetupBody.body_force has 2 values, expected 3 (x, y, z)"), std::string::npos)
      << text;
}

TEST(SolidInterface, ThreeValuesPerNode) {
  InterfaceDescription interface;
  interface.dimension = 3;
  interface.node_ids = {0, 2, 3};
  interface.node_tags = {11, 13, 14};
  interface.coordinates = {{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  interface.normals.assign(3, Eigen::Vector3d(-1.0, 0.0, 0.0));
  interface.weights.assign(3, 1.0 / 6.0);
  interface.fixed = {{false, false, true}, {false, false, true}, {false, false, false}};
  ContactSurfaceDescription surface;
  surface.boundary = "side";
  surface.facet_type = FacetType::triangle3;
  surface.facets = {0, 2, 1};
  interface.surfaces.push_back(surface);
  interface.rigid_modes = 5;
  protocol::InterfaceDescription message;
  encode_interface("ball", interface, message);
  EXPECT_EQ(message.dimension(), 3u);
  EXPECT_EQ(message.coordinates_size(), 9);
  EXPECT_EQ(message.normals_size(), 9);
  ASSERT_EQ(message.fixed_size(), 9);
  EXPECT_TRUE(message.fixed(2));
  EXPECT_FALSE(message.fixed(8));
  EXPECT_EQ(message.surfaces(0).segment_type(), protocol::TRIANGLE3);

  const InterfaceDescription decoded = decode_interface(message);
  EXPECT_EQ(decoded.dimension, 3);
  EXPECT_EQ(decoded.coordinates, interface.coordinates);
  EXPECT_EQ(decoded.normals, interface.normals);
  EXPECT_EQ(decoded.fixed, interface.fixed);
  EXPECT_EQ(decoded.rigid_modes, 5);
  ASSERT_EQ(decoded.surfaces.size(), 1u);
  EXPECT_EQ(decoded.surfaces[0].facet_type, FacetType::triangle3);
  EXPECT_EQ(decoded.surfaces[0].facets, surface.facets);

  protocol::InterfaceDescription seven = message;
  seven.set_rigid_modes(7);
  EXPECT_THROW(decode_interface(seven), MalformedReply);
  protocol::InterfaceDescription plane_faces = message;
  plane_faces.mutable_surfaces(0)->set_segment_type(protocol::LINE2);
  EXPECT_THROW(decode_interface(plane_faces), MalformedReply);
}

TEST(SolidFields, QuadraticTetrahedronTravelsInVtkOrder) {
  BodyOutput output;
  output.body_name = "ball";
  output.mesh.dimension = 3;
  output.mesh.nodes = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0},
                       {0.5, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.0, 0.5, 0.0}, {0.0, 0.0, 0.5},
                       {0.0, 0.5, 0.5}, {0.5, 0.0, 0.5}};
  output.mesh.node_tags = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  output.mesh.blocks.push_back({ElementType::tetrahedron10, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, {}});
  output.mesh.boundaries["base"] = {FacetType::triangle6, {0, 2, 1, 6, 5, 4}};
  output.point_fields.push_back({"displacement", 3, std::vector<double>(30, 0.125)});
  output.cell_fields.push_back({"stress", 6, {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}});
  output.reaction_resultant = {1.5, -2.5, 3.5};
  output.applied_force = {0.0, 0.0, -1.0};
  protocol::FieldsReply message;
  encode_fields(output, message);
  EXPECT_EQ(message.dimension(), 3u);
  EXPECT_EQ(message.node_coordinates_size(), 30);
  ASSERT_EQ(message.cell_types_size(), 1);
  EXPECT_EQ(message.cell_types(0), 24u);
  ASSERT_EQ(message.connectivity_size(), 10);
  EXPECT_EQ(message.connectivity(8), 9);  // VTK: the midpoint of edge 1-3 (Gmsh's node 9)
  EXPECT_EQ(message.connectivity(9), 8);
  EXPECT_EQ(message.reaction_resultant_size(), 3);
  EXPECT_EQ(message.boundaries(0).segments().type(), protocol::TRIANGLE6);

  const BodyOutput decoded = decode_fields(message, "ball");
  EXPECT_EQ(decoded.mesh.dimension, 3);
  EXPECT_EQ(decoded.mesh.nodes, output.mesh.nodes);
  ASSERT_EQ(decoded.mesh.blocks.size(), 1u);
  EXPECT_EQ(decoded.mesh.blocks[0].type, ElementType::tetrahedron10);
  EXPECT_EQ(decoded.mesh.blocks[0].connectivity, output.mesh.blocks[0].connectivity);
  EXPECT_EQ(decoded.mesh.boundary("base").type, FacetType::triangle6);
  EXPECT_EQ(decoded.reaction_resultant, output.reaction_resultant);
  EXPECT_EQ(decoded.applied_force, output.applied_force);

  protocol::FieldsReply plane_cell = message;
  plane_cell.set_cell_types(0, 22);
  EXPECT_THROW(decode_fields(plane_cell, "ball"), MalformedReply);
}

}  // namespace
}  // namespace robin
