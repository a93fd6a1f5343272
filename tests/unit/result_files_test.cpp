// Result files: contact.csv, <body>.vtu, solution.pvd, summary.json and the contact resultant,
// checked against hand sums, exact number round-trips and the analytic uniaxial-compression
// solution of a block pressed on its top face.

#include "coupling/result_files.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

#include "numerics/rectangle_mesher.hpp"
#include "vtk_xml_test_reader.hpp"

namespace robin {
namespace {

using nlohmann::json;
using test::find_array;
using test::read_vtk_xml;
using test::TemporaryDirectory;

ContactPair make_pair(Eigen::Vector2d position, Eigen::Vector2d normal, double gap, double weight) {
  ContactPair pair;
  pair.position << position, 0.0;
  pair.normal << normal, 0.0;
  pair.gap = gap;
  pair.weight = weight;
  return pair;
}

/// Runs `write` expecting a std::runtime_error whose message contains every `fragment`.
template <typename Write>
void expect_error_naming(Write write, const std::vector<std::string>& fragments) {
  try {
    write();
    ADD_FAILURE() << "no exception thrown";
  } catch (const std::runtime_error& error) {
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
          << "message '" << error.what() << "' does not name '" << fragment << "'";
    }
  }
}

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> parts;
  std::stringstream stream(line);
  for (std::string part; std::getline(stream, part, separator);) parts.push_back(part);
  return parts;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ContactResultant, EqualsTheHandSumOfForcesAlongBodyOneNormals) {
  ContactPairing pairing;
  pairing.pairs = {make_pair({0, 0}, {0, 1}, 0, 1), make_pair({1, 0}, {0.6, 0.8}, 0, 1),
                   make_pair({2, 0}, {1, 0}, 0, 1)};
  const Eigen::Vector3d resultant = contact_resultant(pairing, Eigen::Vector3d(1, 2, 3));
  // (0*1 + 0.6*2 + 1*3, 1*1 + 0.8*2 + 0*3)
  EXPECT_DOUBLE_EQ(resultant.x(), 4.2);
  EXPECT_DOUBLE_EQ(resultant.y(), 2.6);
  EXPECT_THROW(contact_resultant(pairing, Eigen::Vector2d(1, 2)), std::runtime_error);
}

TEST(ContactResultant, UniformPressureOnAFlatContactGivesPressureTimesLength) {
  // 5 nodes on [0, 2] (h = 0.5, trapezoidal weights), lambda_i = p m_i, n1 = (0, 1)
  const double pressure = 7.0;
  ContactPairing pairing;
  Eigen::VectorXd force(5);
  for (int i = 0; i < 5; ++i) {
    const double weight = (i == 0 || i == 4) ? 0.25 : 0.5;
    pairing.pairs.push_back(make_pair({0.5 * i, 1.0}, {0, 1}, 0, weight));
    force[i] = pressure * weight;
  }
  const Eigen::Vector3d resultant = contact_resultant(pairing, force);
  EXPECT_DOUBLE_EQ(resultant.x(), 0.0);
  EXPECT_DOUBLE_EQ(resultant.y(), pressure * 2.0);
}

TEST(ContactCsv, RoundTripsEveryNumberExactly) {
  const TemporaryDirectory directory("result_files");
  ContactPairing pairing;
  pairing.pairs = {make_pair({0.1, 1.0 / 3.0}, {0.6, -0.8}, -1e-5 / 3.0, 0.125),
                   make_pair({std::numbers::pi, -2.0 / 7.0}, {-1, 0}, 1e-300, 1.0 / 3.0)};
  InterfaceState state;
  state.normal_trace1 = Eigen::Vector2d(1.0 / 7.0, -0.0);
  state.normal_trace2 = Eigen::Vector2d(-1.0 / 11.0, 1e-17);
  state.contact_force1 = Eigen::Vector2d(0.3, 0.0);
  state.contact_force2 = Eigen::Vector2d(0.1 + 0.2, 5e-324);
  const auto path = directory.path() / "new_directory" / "contact.csv";
  write_contact_csv(path, pairing, state);

  std::ifstream in(path);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "pair,x,y,nx,ny,gap0,un1,un2,lambda1,lambda2,pressure");
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::getline(in, line)) << "row " << i;
    const std::vector<std::string> cells = split(line, ',');
    ASSERT_EQ(cells.size(), 11u) << line;
    std::vector<double> numbers;
    for (const std::string& cell : cells) numbers.push_back(std::strtod(cell.c_str(), nullptr));
    const ContactPair& pair = pairing.pairs[i];
    const double lambda1 = state.contact_force1[i], lambda2 = state.contact_force2[i];
    const std::vector<double> expected = {double(i),
                                          pair.position.x(),
                                          pair.position.y(),
                                          pair.normal.x(),
                                          pair.normal.y(),
                                          pair.gap,
                                          state.normal_trace1[i],
                                          state.normal_trace2[i],
                                          lambda1,
                                          lambda2,
                                          (lambda1 + lambda2) / (2.0 * pair.weight)};
    for (std::size_t column = 0; column < 11; ++column) {
      EXPECT_EQ(numbers[column], expected[column]) << "row " << i << " column " << column;
      EXPECT_EQ(std::signbit(numbers[column]), std::signbit(expected[column]));
    }
  }
  EXPECT_FALSE(std::getline(in, line)) << "one row per pair only";
  EXPECT_EQ(split(read_text(path), '\n')[1].substr(0, 2), "0,");  // zero-based pair index
}

TEST(ContactCsv, StateOfTheWrongSizeIsRejectedNamingIt) {
  const TemporaryDirectory directory("result_files");
  ContactPairing pairing;
  pairing.pairs = {make_pair({0, 0}, {0, 1}, 0, 1), make_pair({1, 0}, {0, 1}, 0, 1)};
  InterfaceState state;
  state.normal_trace1 = state.normal_trace2 = state.contact_force1 = Eigen::Vector2d::Zero();
  state.contact_force2 = Eigen::Vector3d::Zero();
  const auto path = directory.path() / "contact.csv";
  expect_error_naming([&] { write_contact_csv(path, pairing, state); },
                      {path.string(), "contact_force2", "3", "2"});
}

TEST(JsonFile, IsPrettyPrintedWithTwoSpacesAndRoundTrips) {
  const TemporaryDirectory directory("result_files");
  const json document = {{"case", "two blocks"},
                         {"iterations", 12},
                         {"residual", 1.0 / 3.0},
                         {"resultant", {{"x", -0.0}, {"y", 1e-300}}}};
  const auto path = directory.path() / "deeper" / "summary.json";
  write_json(path, document);
  const std::string text = read_text(path);
  EXPECT_EQ(json::parse(text), document);
  EXPECT_EQ(json::parse(text)["residual"].get<double>(), 1.0 / 3.0);
  const std::vector<std::string> lines = split(text, '\n');
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines[0], "{");
  EXPECT_EQ(lines[1], "  \"case\": \"two blocks\",");
  EXPECT_NE(text.find("\n    \"x\": -0.0"), std::string::npos) << text;  // nested: 4 spaces
  EXPECT_EQ(text.back(), '\n');
}

TEST(SolutionPvd, NamesBothBodyFilesInANewDirectory) {
  const TemporaryDirectory directory("result_files");
  const auto output = directory.path() / "run" / "output";
  write_solution_pvd(output, {"upper.vtu", "lower.vtu"});
  const json document = read_vtk_xml(output / "solution.pvd");
  EXPECT_EQ(document["root"]["type"], "Collection");
  ASSERT_EQ(document["datasets"].size(), 2u);
  EXPECT_EQ(document["datasets"][0]["file"], "upper.vtu");
  EXPECT_EQ(document["datasets"][0]["part"], "0");
  EXPECT_EQ(document["datasets"][1]["file"], "lower.vtu");
  EXPECT_EQ(document["datasets"][1]["part"], "1");
}

TEST(ResultFiles, UncreatableDirectoryGivesAnErrorNamingIt) {
  const TemporaryDirectory directory("result_files");
  const auto blocker = directory.path() / "a_file";
  std::ofstream(blocker) << "not a directory\n";
  const auto output = blocker / "output";
  expect_error_naming([&] { write_solution_pvd(output, {"a.vtu", "b.vtu"}); }, {output.string()});
  expect_error_naming([&] { write_json(output / "summary.json", json::object()); },
                      {output.string()});
  expect_error_naming([&] { write_contact_csv(output / "contact.csv", {}, {}); },
                      {output.string()});
  // the target itself is a directory: the file cannot be opened
  const auto directory_target = directory.path() / "summary.json";
  std::filesystem::create_directory(directory_target);
  expect_error_naming([&] { write_json(directory_target, json::object()); },
                      {directory_target.string()});
}

/// The block [0, 2] x [0, 1] (4 x 2 bilinear cells, h = 0.5), on rollers at its bottom
/// (u_y = 0) and left (u_x = 0), pressed by nodal contact forces lambda_i = p m_i on its top face
/// (n = (0, 1)). The exact solution is uniaxial compression in the plane, which Q1 reproduces:
///   s_xx = s_xy = 0, s_yy = -p, and
///   plane stress: s_zz = 0,       u_x = nu p x / E,          u_y = -p y / E,
///                 von Mises = p;
///   plane strain: s_zz = -nu p,   u_x = nu (1 + nu) p x / E, u_y = -(1 - nu^2) p y / E,
///                 von Mises = sqrt(((0 + p)^2 + (-p + nu p)^2 + (-nu p - 0)^2) / 2)
///                           = p sqrt(1 - nu + nu^2).
struct CompressedBlock {
  static constexpr double young = 200.0;
  static constexpr double poisson = 0.3;
  static constexpr double pressure = 3.0;
  static constexpr double width = 2.0;
  static constexpr double spacing = 0.5;

  static BodyDefinition definition(PlaneModel model = PlaneModel::plane_stress) {
    BodyDefinition body;
    body.name = "block";
    body.mesh = make_rectangle_mesh(0.0, 0.0, width, 1.0, 4, 2, ElementType::quadrilateral4);
    body.material = make_isotropic_material(young, poisson, model, "test");
    body.dirichlet = {{"bottom", std::nullopt, 0.0, std::nullopt},
                      {"left", 0.0, std::nullopt, std::nullopt}};
    body.contact_boundaries = {"top"};
    return body;
  }
  /// Trapezoidal weight of a node at abscissa x on a face [0, width] of spacing h.
  static double face_weight(double x) { return (x == 0.0 || x == width) ? spacing / 2 : spacing; }
};

class BodyVtuModels : public ::testing::TestWithParam<PlaneModel> {};

INSTANTIATE_TEST_SUITE_P(BodyVtu, BodyVtuModels,
                         ::testing::Values(PlaneModel::plane_stress, PlaneModel::plane_strain),
                         [](const auto& info) {
                           return info.param == PlaneModel::plane_strain ? "PlaneStrain"
                                                                         : "PlaneStress";
                         });

TEST_P(BodyVtuModels, UniaxialCompressionFieldsReadByVtkMatchTheAnalyticSolution) {
  using Block = CompressedBlock;
  const bool plane_strain = GetParam() == PlaneModel::plane_strain;
  BodySolver body(Block::definition(GetParam()));
  const InterfaceDescription top = body.contact_boundary();
  ASSERT_EQ(top.node_ids.size(), 5u);
  body.assign_contact(node_to_node_operator(
      top.node_ids, std::vector<Eigen::Vector3d>(5, Eigen::Vector3d(0, 1, 0)), top.weights));
  Eigen::VectorXd lambda(5);
  for (int i = 0; i < 5; ++i)
    lambda[i] = Block::pressure * Block::face_weight(top.coordinates[i].x());

  const TemporaryDirectory directory("result_files");
  const auto output = directory.path() / "not_yet_created";
  EXPECT_EQ(write_body_vtu(output, body, lambda), "block.vtu");
  using std::filesystem::perms;
  EXPECT_EQ(std::filesystem::status(output / "block.vtu").permissions(),
            perms::owner_read | perms::owner_write | perms::group_read | perms::others_read);
  // The file is binary and compressed, and VTK's reader (ParaView's) reads it.
  EXPECT_EQ(read_vtk_xml(output / "block.vtu")["root"]["compressor"], "vtkZLibDataCompressor");
  const json grid = test::read_vtu_with_vtk(output / "block.vtu");
  ASSERT_EQ(grid["points"].size(), 3u * 15u);
  // 8 quadrilaterals, then the 12 boundary edges (bottom 4, left 2, right 2, top 4)
  ASSERT_EQ(grid["types"].size(), 20u);
  EXPECT_EQ(grid["field_data"]["boundary_names"], json({"bottom", "left", "right", "top"}));

  const double p = Block::pressure, young = Block::young, nu = Block::poisson;
  const double tolerance = 1e-12;
  const double strain_x = plane_strain ? nu * (1 + nu) * p / young : nu * p / young;
  const double strain_y = plane_strain ? -(1 - nu * nu) * p / young : -p / young;
  const double stress_zz = plane_strain ? -nu * p : 0.0;
  const double expected_von_mises = plane_strain ? p * std::sqrt(1 - nu + nu * nu) : p;
  const json& points = grid["points"];
  const json& displacement = grid["point_data"]["displacement"];
  const json& stress = grid["point_data"]["stress"];
  const json& von_mises = grid["point_data"]["von_mises"]["values"];
  const json& contact_pressure = grid["point_data"]["contact_pressure"]["values"];
  const json& contact_force = grid["point_data"]["contact_force"]["values"];
  const json& reaction = grid["point_data"]["reaction"]["values"];
  EXPECT_EQ(displacement["components"], 3);
  EXPECT_EQ(stress["components"], 6);
  EXPECT_EQ(stress["component_names"], json({"XX", "YY", "ZZ", "XY", "YZ", "XZ"}));
  double total_reaction_y = 0.0;
  for (std::size_t k = 0; k < 15; ++k) {
    const double x = points[3 * k].get<double>(), y = points[3 * k + 1].get<double>();
    const bool on_top = y == 1.0, on_bottom = y == 0.0;
    EXPECT_NEAR(displacement["values"][3 * k].get<double>(), strain_x * x, tolerance);
    EXPECT_NEAR(displacement["values"][3 * k + 1].get<double>(), strain_y * y, tolerance);
    EXPECT_EQ(displacement["values"][3 * k + 2].get<double>(), 0.0);
    // (XX, YY, ZZ, XY, YZ, XZ)
    const std::array<double, 6> expected_stress = {0.0, -p, stress_zz, 0.0, 0.0, 0.0};
    for (std::size_t c = 0; c < 6; ++c) {
      EXPECT_NEAR(stress["values"][6 * k + c].get<double>(), expected_stress[c], tolerance * p)
          << "node " << k << " component " << c;
    }
    EXPECT_NEAR(von_mises[k].get<double>(), expected_von_mises, tolerance * p);
    EXPECT_NEAR(contact_pressure[k].get<double>(), on_top ? p : 0.0, tolerance * p);
    // force on the body from the other one: -lambda_i n_i = (0, -p m_i)
    EXPECT_EQ(contact_force[3 * k].get<double>(), 0.0);
    EXPECT_NEAR(contact_force[3 * k + 1].get<double>(), on_top ? -p * Block::face_weight(x) : 0.0,
                tolerance * p);
    // the rollers carry the load: (0, p m_i) on the bottom, nothing sideways (s_xx = 0)
    EXPECT_NEAR(reaction[3 * k].get<double>(), 0.0, tolerance * p);
    EXPECT_NEAR(reaction[3 * k + 1].get<double>(), on_bottom ? p * Block::face_weight(x) : 0.0,
                tolerance * p);
    total_reaction_y += reaction[3 * k + 1].get<double>();
  }
  EXPECT_NEAR(total_reaction_y, p * Block::width, tolerance * p);

  // Cell fields on all 20 cells: the boundary edges carry their quadrilateral's (uniform) values.
  const json& cell_stress = grid["cell_data"]["stress"]["values"];
  const json& cell_von_mises = grid["cell_data"]["von_mises"]["values"];
  ASSERT_EQ(cell_stress.size(), 6u * 20u);
  for (std::size_t e = 0; e < 20; ++e) {
    EXPECT_NEAR(cell_stress[6 * e + 1].get<double>(), -p, tolerance * p);
    EXPECT_NEAR(cell_stress[6 * e + 2].get<double>(), stress_zz, tolerance * p);
    EXPECT_NEAR(cell_von_mises[e].get<double>(), expected_von_mises, tolerance * p);
  }
}

TEST(BodyVtu, VoigtPlaneStrainMaterialHasNoOutOfPlaneStress) {
  // The plane-strain stiffness of (E, nu) given as a Voigt matrix: the same displacements as the
  // isotropic plane-strain block, but a Voigt material carries no out-of-plane relation
  // (numerics/material.hpp: s_zz = 0), so ZZ = 0 and von Mises = sqrt((p^2 + p^2) / 2) = p.
  using Block = CompressedBlock;
  BodyDefinition definition = Block::definition(PlaneModel::plane_strain);
  definition.material =
      make_voigt_material(definition.material.stiffness, PlaneModel::plane_strain, "test");
  BodySolver body(definition);
  const InterfaceDescription top = body.contact_boundary();
  body.assign_contact(node_to_node_operator(
      top.node_ids, std::vector<Eigen::Vector3d>(5, Eigen::Vector3d(0, 1, 0)), top.weights));
  Eigen::VectorXd lambda(5);
  for (int i = 0; i < 5; ++i)
    lambda[i] = Block::pressure * Block::face_weight(top.coordinates[i].x());
  const TemporaryDirectory directory("result_files");
  write_body_vtu(directory.path(), body, lambda);
  const json grid = test::read_vtu_with_vtk(directory.path() / "block.vtu");
  const double p = Block::pressure, nu = Block::poisson, tolerance = 1e-12;
  const json& points = grid["points"];
  const json& displacement = grid["point_data"]["displacement"]["values"];
  const json& stress = grid["point_data"]["stress"]["values"];
  const json& von_mises = grid["point_data"]["von_mises"]["values"];
  for (std::size_t k = 0; k < 15; ++k) {
    const double x = points[3 * k].get<double>(), y = points[3 * k + 1].get<double>();
    EXPECT_NEAR(displacement[3 * k].get<double>(), nu * (1 + nu) * p * x / Block::young, tolerance);
    EXPECT_NEAR(displacement[3 * k + 1].get<double>(), -(1 - nu * nu) * p * y / Block::young,
                tolerance);
    EXPECT_NEAR(stress[6 * k + 1].get<double>(), -p, tolerance * p);
    EXPECT_EQ(stress[6 * k + 2].get<double>(), 0.0);
    EXPECT_NEAR(von_mises[k].get<double>(), p, tolerance * p);
  }
}

TEST(BodyVtu, ContactForceOfTheWrongSizeIsRejectedNamingTheFile) {
  BodySolver body(CompressedBlock::definition());
  const InterfaceDescription top = body.contact_boundary();
  body.assign_contact(node_to_node_operator(
      top.node_ids, std::vector<Eigen::Vector3d>(5, Eigen::Vector3d(0, 1, 0)), top.weights));
  const TemporaryDirectory directory("result_files");
  expect_error_naming([&] { write_body_vtu(directory.path(), body, Eigen::VectorXd::Zero(3)); },
                      {(directory.path() / "block.vtu").string(), "block", "5", "3"});
}

}  // namespace
}  // namespace robin
