// Gmsh reader: .msh 2.2 and 4.1 files, .geo scripts meshed on the fly, meshes given as
// text, element orientation, boundary names and the errors for bad input. Expected
// numbers come from the geometry (areas, lengths) or from the files themselves.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

const std::filesystem::path data_directory = ROBIN_TEST_DATA;

/// Twice the signed area of the corner polygon of element e (shoelace formula).
double twice_signed_area(const Mesh& mesh, const ElementBlock& block, std::size_t e) {
  const int count = nodes_per_element(block.type);
  const int corners = block.type == ElementType::quadrilateral4 ? 4 : 3;
  double sum = 0.0;
  for (int i = 0; i < corners; ++i) {
    const Eigen::Vector2d& a = mesh.nodes[block.connectivity[e * count + i]];
    const Eigen::Vector2d& b = mesh.nodes[block.connectivity[e * count + (i + 1) % corners]];
    sum += a.x() * b.y() - b.x() * a.y();
  }
  return sum;
}

/// Total area; every element must be counter-clockwise.
double checked_area(const Mesh& mesh) {
  double area = 0.0;
  for (const ElementBlock& block : mesh.blocks) {
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      const double twice = twice_signed_area(mesh, block, e);
      EXPECT_GT(twice, 0.0) << to_string(block.type) << " element " << e << " is clockwise";
      area += 0.5 * twice;
    }
  }
  return area;
}

/// Sum of the chord lengths of a group's edges (exact for straight boundaries).
double boundary_length(const Mesh& mesh, const BoundaryGroup& group) {
  const int count = nodes_per_edge(group.type);
  double length = 0.0;
  for (std::size_t e = 0; e < group.edge_count(); ++e) {
    length +=
        (mesh.nodes[group.connectivity[e * count + 1]] - mesh.nodes[group.connectivity[e * count]])
            .norm();
  }
  return length;
}

std::set<std::string> boundary_names(const Mesh& mesh) {
  std::set<std::string> names;
  for (const auto& [name, group] : mesh.boundaries) names.insert(name);
  return names;
}

/// Node tag -> coordinates from the $Nodes section of a .msh 2.2 file, parsed here.
std::map<std::size_t, Eigen::Vector2d> nodes_of_msh22(const std::filesystem::path& path) {
  std::ifstream stream(path);
  std::string line;
  while (std::getline(stream, line) && line != "$Nodes") {
  }
  std::size_t count = 0;
  stream >> count;
  std::map<std::size_t, Eigen::Vector2d> nodes;
  for (std::size_t k = 0; k < count; ++k) {
    std::size_t tag = 0;
    double x = 0, y = 0, z = 0;
    stream >> tag >> x >> y >> z;
    nodes[tag] = {x, y};
  }
  return nodes;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream stream(path);
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

/// The message of the InputError thrown by `call`, or "" when nothing is thrown.
template <typename Call>
std::string input_error_message(Call&& call) {
  try {
    call();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

void expect_unit_square_with_named_sides(const Mesh& mesh) {
  EXPECT_NEAR(checked_area(mesh), 1.0, 1e-12);
  EXPECT_EQ(boundary_names(mesh), (std::set<std::string>{"14", "bottom", "right", "top"}));
  for (const auto& [name, group] : mesh.boundaries) {
    EXPECT_NEAR(boundary_length(mesh, group), 1.0, 1e-12) << name;
  }
  for (const Eigen::Vector2d& node : mesh.nodes) {
    EXPECT_TRUE(node.x() >= 0.0 && node.x() <= 1.0 && node.y() >= 0.0 && node.y() <= 1.0);
  }
}

TEST(MeshReader, ReadsMsh22WithTagsCoordinatesAndBoundaries) {
  const std::filesystem::path path = data_directory / "mesh_square_v22.msh";
  const Mesh mesh = read_gmsh_mesh(path);
  ASSERT_EQ(mesh.blocks.size(), 1u);
  EXPECT_EQ(mesh.blocks[0].type, ElementType::triangle3);
  expect_unit_square_with_named_sides(mesh);
  const std::map<std::size_t, Eigen::Vector2d> file_nodes = nodes_of_msh22(path);
  ASSERT_EQ(mesh.node_count(), file_nodes.size());
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    ASSERT_EQ(file_nodes.count(mesh.node_tags[i]), 1u);
    EXPECT_EQ(mesh.nodes[i], file_nodes.at(mesh.node_tags[i]));
  }
  // The bottom side y = 0 holds nodes at x = 0 and x = 1 (the square's corners).
  const BoundaryGroup& bottom = mesh.boundary("bottom");
  EXPECT_EQ(bottom.type, EdgeType::line2);
  for (const int node : bottom.nodes()) EXPECT_EQ(mesh.nodes[node].y(), 0.0);
}

TEST(MeshReader, Msh41GivesTheSameMeshAsMsh22) {
  const Mesh old_format = read_gmsh_mesh(data_directory / "mesh_square_v22.msh");
  const Mesh new_format = read_gmsh_mesh(data_directory / "mesh_square_v41.msh");
  expect_unit_square_with_named_sides(new_format);
  ASSERT_EQ(new_format.node_count(), old_format.node_count());
  EXPECT_EQ(new_format.element_count(), old_format.element_count());
  std::map<std::size_t, Eigen::Vector2d> old_nodes;
  for (std::size_t i = 0; i < old_format.node_count(); ++i) {
    old_nodes[old_format.node_tags[i]] = old_format.nodes[i];
  }
  for (std::size_t i = 0; i < new_format.node_count(); ++i) {
    ASSERT_EQ(old_nodes.count(new_format.node_tags[i]), 1u);
    EXPECT_NEAR((new_format.nodes[i] - old_nodes.at(new_format.node_tags[i])).norm(), 0.0, 1e-12);
  }
}

TEST(MeshReader, GeoSizeParameterControlsTheMeshAndStrayNodesAreDropped) {
  const std::filesystem::path path = data_directory / "mesh_square.geo";
  const Mesh coarse = read_gmsh_mesh(path, {.size = 0.5});
  const Mesh fine = read_gmsh_mesh(path, {.size = 0.1});
  expect_unit_square_with_named_sides(coarse);
  expect_unit_square_with_named_sides(fine);
  // Node count grows like 1/h^2: 25 times more area per node at h = 0.5 than at 0.1.
  EXPECT_GT(fine.node_count(), 10 * coarse.node_count());
  EXPECT_LT(fine.node_count(), 60 * coarse.node_count());
  // Compact numbering: the stray Point(9) at (3, 3) is in no element, so it is dropped.
  std::set<std::size_t> tags(fine.node_tags.begin(), fine.node_tags.end());
  EXPECT_EQ(tags.size(), fine.node_count());
}

TEST(MeshReader, UnknownBoundaryNameListsTheKnownNames) {
  const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_square_v41.msh");
  const std::string message = input_error_message([&] { mesh.boundary("contact"); });
  EXPECT_NE(message.find("'contact'"), std::string::npos) << message;
  EXPECT_NE(message.find("'bottom', 'right', 'top'"), std::string::npos) << message;
  EXPECT_NE(message.find("'14'"), std::string::npos) << message;
}

TEST(MeshReader, MissingFileIsAnInputErrorNamingTheFile) {
  const std::filesystem::path path = data_directory / "mesh_does_not_exist.msh";
  const std::string message = input_error_message([&] { read_gmsh_mesh(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(MeshReader, GarbageFileIsAnInputErrorNamingTheFile) {
  const std::filesystem::path path = data_directory / "mesh_garbage.msh";
  const std::string message = input_error_message([&] { read_gmsh_mesh(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(MeshReader, GeoSyntaxErrorNamesTheFileAndLineAndLaterReadsStillWork) {
  const std::filesystem::path path = data_directory / "mesh_syntax_error.geo";
  const std::string message = input_error_message([&] { read_gmsh_mesh(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("line 3"), std::string::npos) << message;
  // Gmsh's parser is global state: a failed parse must not break the next one.
  expect_unit_square_with_named_sides(read_gmsh_mesh(data_directory / "mesh_square.geo"));
}

TEST(MeshReader, UnsupportedExtensionAndBadOptionsAreInputErrors) {
  EXPECT_THROW(read_gmsh_mesh(data_directory / "case_full.toml"), InputError);
  const std::filesystem::path path = data_directory / "mesh_square.geo";
  EXPECT_THROW(read_gmsh_mesh(path, {.element_order = 3}), InputError);
  EXPECT_THROW(read_gmsh_mesh(path, {.size = -1.0}), InputError);
}

TEST(MeshReader, ClockwiseGeometryGivesCounterClockwiseElementsOfEveryType) {
  const std::filesystem::path path = data_directory / "mesh_clockwise.geo";
  for (const MeshReadOptions& options : {MeshReadOptions{}, MeshReadOptions{.element_order = 2},
                                         MeshReadOptions{.recombine = true}}) {
    const Mesh mesh = read_gmsh_mesh(path, options);
    EXPECT_NEAR(checked_area(mesh), 1.5, 1e-12);  // triangle with legs 2 and 1.5
    EXPECT_NEAR(boundary_length(mesh, mesh.boundary("boundary")), 2.0 + 1.5 + 2.5, 1e-12);
  }
}

TEST(MeshReader, SecondOrderGivesTriangle6WithGmshMidpointOrder) {
  const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_clockwise.geo", {.element_order = 2});
  ASSERT_EQ(mesh.blocks.size(), 1u);
  const ElementBlock& block = mesh.blocks[0];
  ASSERT_EQ(block.type, ElementType::triangle6);
  // Straight sides: node 3 is the middle of corners 0-1, node 4 of 1-2, node 5 of 2-0.
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    const int* nodes = &block.connectivity[6 * e];
    for (const auto& [middle, a, b] : {std::tuple{3, 0, 1}, {4, 1, 2}, {5, 2, 0}}) {
      const Eigen::Vector2d expected = 0.5 * (mesh.nodes[nodes[a]] + mesh.nodes[nodes[b]]);
      EXPECT_NEAR((mesh.nodes[nodes[middle]] - expected).norm(), 0.0, 1e-12);
    }
  }
  const BoundaryGroup& boundary = mesh.boundary("boundary");
  ASSERT_EQ(boundary.type, EdgeType::line3);
  for (std::size_t e = 0; e < boundary.edge_count(); ++e) {
    const int* nodes = &boundary.connectivity[3 * e];
    const Eigen::Vector2d expected = 0.5 * (mesh.nodes[nodes[0]] + mesh.nodes[nodes[1]]);
    EXPECT_NEAR((mesh.nodes[nodes[2]] - expected).norm(), 0.0, 1e-12);
  }
}

TEST(MeshReader, RecombineGivesQuadrilaterals) {
  const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_irregular.geo", {.recombine = true});
  std::size_t quadrilaterals = 0;
  for (const ElementBlock& block : mesh.blocks) {
    if (block.type == ElementType::quadrilateral4) quadrilaterals += block.element_count();
  }
  EXPECT_GT(quadrilaterals, mesh.element_count() / 2);
  EXPECT_NEAR(checked_area(mesh), 3.135, 1e-12);
  EXPECT_EQ(boundary_names(mesh),
            (std::set<std::string>{"bottom", "left", "notch", "right", "top"}));
}

TEST(MeshReader, MixedTrianglesAndQuadrilateralsMakeTwoBlocks) {
  const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_mixed.geo");
  std::set<ElementType> types;
  for (const ElementBlock& block : mesh.blocks) types.insert(block.type);
  EXPECT_EQ(types, (std::set<ElementType>{ElementType::triangle3, ElementType::quadrilateral4}));
  // Shoelace area of the outer hexagon (0,0) (1.1,0.1) (2,-0.1) (2.2,1) (0.9,1.2) (0.1,0.9).
  EXPECT_NEAR(checked_area(mesh), 2.17, 1e-12);
}

TEST(MeshReader, WithoutPhysicalSurfaceEverySurfaceIsRead) {
  const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_no_surface_group.geo");
  EXPECT_NEAR(checked_area(mesh), 1.0, 1e-12);
  EXPECT_EQ(boundary_names(mesh), (std::set<std::string>{"bottom"}));
}

// A hand-written .msh 2.2: four nodes, a clockwise triangle, a counter-clockwise one, and a
// boundary edge; node 9 is unused. `physical` is the physical tag of the triangles and
// `edge_physical` the one of the edge (0: none).
std::string small_msh22(int physical, double z = 0.0, int edge_physical = 5) {
  const std::string p = std::to_string(physical);
  const std::string q = std::to_string(edge_physical);
  return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n"
         "1 0 0 0\n2 2 0 0\n3 0 1 " +
         std::to_string(z) +
         "\n4 2 1 0\n9 7 7 0\n$EndNodes\n"
         "$Elements\n3\n"
         "1 1 2 " +
         q +
         " 1 1 2\n"
         "2 2 2 " +
         p +
         " 1 1 3 2\n"
         "3 2 2 " +
         p + " 1 2 3 4\n$EndElements\n";
}

TEST(MeshReader, HandWrittenMeshIsCompactedAndReoriented) {
  const Mesh mesh = read_gmsh_mesh_from_text(small_msh22(7), ".msh", "hand mesh");
  ASSERT_EQ(mesh.node_count(), 4u);  // node 9 is in no element
  EXPECT_EQ(mesh.node_tags, (std::vector<std::size_t>{1, 2, 3, 4}));
  EXPECT_EQ(mesh.nodes[1], Eigen::Vector2d(2.0, 0.0));
  ASSERT_EQ(mesh.blocks.size(), 1u);
  // Element (1, 3, 2) is clockwise: reordered to (1, 2, 3); (2, 3, 4) is counter-clockwise.
  EXPECT_EQ(mesh.blocks[0].connectivity, (std::vector<int>{0, 1, 2, 1, 3, 2}));
  EXPECT_NEAR(checked_area(mesh), 2.0, 1e-15);
  EXPECT_EQ(mesh.boundary("5").connectivity, (std::vector<int>{0, 1}));
}

TEST(MeshReader, WithoutSurfaceGroupsTheHandWrittenTrianglesAreStillRead) {
  const Mesh mesh = read_gmsh_mesh_from_text(small_msh22(0), ".msh", "hand mesh");
  EXPECT_EQ(mesh.element_count(), 2u);
  EXPECT_NEAR(checked_area(mesh), 2.0, 1e-15);
}

TEST(MeshReader, HandWrittenMeshErrors) {
  // Physical tag 0 everywhere means no physical group at all.
  std::string message = input_error_message(
      [] { read_gmsh_mesh_from_text(small_msh22(0, 0.0, 0), ".msh", "body 'upper': mesh"); });
  EXPECT_EQ(message.rfind("body 'upper': mesh", 0), 0u) << message;
  EXPECT_NE(message.find("physical"), std::string::npos) << message;
  message =
      input_error_message([] { read_gmsh_mesh_from_text(small_msh22(7, 0.5), ".msh", "tilted"); });
  EXPECT_NE(message.find("z = 0"), std::string::npos) << message;
  EXPECT_THROW(read_gmsh_mesh_from_text(small_msh22(7), ".vtk", "label"), InputError);
}

TEST(MeshReader, TextInputMatchesFileInputAndErrorsNameTheLabel) {
  const std::filesystem::path path = data_directory / "mesh_square_v22.msh";
  const Mesh from_file = read_gmsh_mesh(path);
  const Mesh from_text = read_gmsh_mesh_from_text(read_text(path), ".msh", "upper mesh");
  EXPECT_EQ(from_text.node_tags, from_file.node_tags);
  EXPECT_EQ(from_text.blocks[0].connectivity, from_file.blocks[0].connectivity);
  const Mesh geo = read_gmsh_mesh_from_text(read_text(data_directory / "mesh_square.geo"), ".geo",
                                            "upper geo", {.size = 0.25});
  expect_unit_square_with_named_sides(geo);
  const std::string message = input_error_message([&] {
    read_gmsh_mesh_from_text(read_text(data_directory / "mesh_syntax_error.geo"), ".geo",
                             "case.toml: body 'lower'");
  });
  EXPECT_EQ(message.rfind("case.toml: body 'lower'", 0), 0u) << message;
  EXPECT_EQ(message.find("robin-mesh-"), std::string::npos) << message;
}

TEST(MeshReader, TextInputLeavesNoTemporaryFile) {
  // A private temporary directory (through TMPDIR) so that other processes do not interfere.
  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() /
      ("robin-mesh-reader-test-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(directory);
  const char* previous = std::getenv("TMPDIR");
  const std::string saved = previous ? previous : "";
  ::setenv("TMPDIR", directory.c_str(), 1);
  read_gmsh_mesh_from_text(read_text(data_directory / "mesh_square_v41.msh"), ".msh", "mesh");
  EXPECT_THROW(read_gmsh_mesh_from_text("garbage", ".msh", "mesh"), InputError);
  const bool empty = std::filesystem::is_empty(directory);
  if (previous) {
    ::setenv("TMPDIR", saved.c_str(), 1);
  } else {
    ::unsetenv("TMPDIR");
  }
  std::filesystem::remove_all(directory);
  EXPECT_TRUE(empty);
}

}  // namespace
}  // namespace robin
