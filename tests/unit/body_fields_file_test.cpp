// write_body_fields (numerics/body_output.hpp), the file a server writes field by field from its
// body's own mesh:
//  - it is the file write_body_output writes of make_body_output (all fields at hand, from a
//    copy of the mesh), byte for byte, for a plane body of quadratic triangles and a solid body
//    of quadratic tetrahedra (whose midside nodes VTK numbers differently) and of hexahedra;
//  - the output it returns carries the same resultants as make_body_output's, the file's name
//    and no mesh or fields;
//  - the check sees every field once, in the file's order, with make_body_output's values; a
//    check that throws abandons the file and leaves nothing in the directory.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "../test_bodies.hpp"
#include "../test_files.hpp"
#include "numerics/body_output.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/contact_operator.hpp"

namespace robin {
namespace {

using testing::plane_quadratic_block;
using testing::TemporaryDirectory;

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The contact forces of `body` pushed along `normal` at every contact node, of magnitudes
/// 1, 1.25, 1.5, ... (node after node), once assigned node-to-node.
Eigen::VectorXd assign_contact(BodySolver& body, const Eigen::Vector3d& normal) {
  const InterfaceDescription boundary = body.contact_boundary();
  body.assign_contact(node_to_node_operator(
      boundary.node_ids, std::vector<Eigen::Vector3d>(boundary.node_ids.size(), normal),
      boundary.weights));
  return Eigen::VectorXd::LinSpaced(body.contact_size(), 1.0,
                                    1.0 + 0.25 * (body.contact_size() - 1));
}

/// The box [0, 1] x [0, 0.7] x [0, 0.5] (3 x 2 x 2 cells of `type`), clamped at its bottom,
/// pushed at its top.
BodyDefinition solid_block(ElementType type) {
  BodyDefinition definition;
  definition.name = "solid";
  definition.mesh = make_box_mesh({0.0, 0.0, 0.0}, {1.0, 0.7, 0.5}, {3, 2, 2}, type);
  definition.material = make_isotropic_solid_material(100.0, 0.3, "test");
  definition.dirichlet = {{"bottom", 0.0, 0.0, 0.0}};
  definition.contact_boundaries = {"top"};
  return definition;
}

class BodyFieldsFile : public ::testing::TestWithParam<int> {};

INSTANTIATE_TEST_SUITE_P(Bodies, BodyFieldsFile, ::testing::Values(0, 1, 2));

BodyDefinition definition_of_case(int which) {
  if (which == 0) return plane_quadratic_block("plane");
  return solid_block(which == 1 ? ElementType::tetrahedron10 : ElementType::hexahedron8);
}

TEST_P(BodyFieldsFile, IsTheFileOfTheFieldsAtHandByteForByte) {
  const TemporaryDirectory directory("body-fields-file");
  BodySolver body(definition_of_case(GetParam()));
  const Eigen::Vector3d normal =
      body.mesh().dimension == 2 ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(0, 0, 1);
  const Eigen::VectorXd force = assign_contact(body, normal);
  const BodyOutput at_hand = make_body_output(body, force);
  const std::string expected_name = write_body_output(directory.path() / "at_hand", at_hand);

  std::vector<std::string> checked;
  std::vector<std::vector<double>> checked_values;
  const BodyOutput streamed = write_body_fields(
      directory.path() / "streamed", body, force,
      [&](FieldLocation location, const std::string& name, const std::vector<double>& values) {
        checked.push_back(std::string(field_location_name(location)) + " " + name);
        checked_values.push_back(values);
      });

  EXPECT_EQ(streamed.written_file, expected_name);
  const std::string bytes = file_bytes(directory.path() / "at_hand" / expected_name);
  ASSERT_GT(bytes.size(), 1000u);
  EXPECT_TRUE(bytes == file_bytes(directory.path() / "streamed" / expected_name));
  EXPECT_EQ(streamed.body_name, body.name());
  EXPECT_EQ(streamed.mesh.dimension, body.mesh().dimension);
  EXPECT_EQ(streamed.mesh.node_count(), 0u);
  EXPECT_TRUE(streamed.point_fields.empty() && streamed.cell_fields.empty());
  EXPECT_EQ(streamed.reaction_resultant, at_hand.reaction_resultant);
  EXPECT_EQ(streamed.applied_force, at_hand.applied_force);

  const std::vector<std::string> file_order = {
      "point displacement",  "point stress",   "point von_mises", "point contact_pressure",
      "point contact_force", "point reaction", "cell stress",     "cell von_mises"};
  ASSERT_EQ(checked, file_order);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(checked_values[k], at_hand.point_fields[k].values);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(checked_values[6 + k], at_hand.cell_fields[k].values);
  }
}

TEST(BodyFieldsFile, ACheckThatThrowsLeavesNoFile) {
  const TemporaryDirectory directory("body-fields-file");
  BodySolver body(plane_quadratic_block("plane"));
  const Eigen::VectorXd force = assign_contact(body, {0, 1, 0});
  const auto refuse_stress = [](FieldLocation location, const std::string& name,
                                const std::vector<double>&) {
    if (location == FieldLocation::cell && name == "von_mises") throw std::runtime_error("refused");
  };
  EXPECT_THROW(write_body_fields(directory.path(), body, force, refuse_stress), std::runtime_error);
  EXPECT_TRUE(std::filesystem::is_empty(directory.path()));
}

TEST(BodyFieldsFile, WrongNumberOfContactForcesIsRefusedNamingTheBody) {
  const TemporaryDirectory directory("body-fields-file");
  BodySolver body(plane_quadratic_block("plane"));
  assign_contact(body, {0, 1, 0});
  try {
    write_body_fields(directory.path(), body, Eigen::VectorXd::Ones(body.contact_size() + 1));
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("body 'plane'"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(directory.path()));
}

}  // namespace
}  // namespace robin
