// Gmsh reader: .msh 2.2 and 4.1 files, .geo scripts meshed on the fly (also several at once,
// in child processes), element orientation and refusal of inverted elements, boundary names and the
// errors for bad input. Expected numbers come from the geometry (areas, lengths) or from the files
// themselves.

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
    const Eigen::Vector3d& a = mesh.nodes[block.connectivity[e * count + i]];
    const Eigen::Vector3d& b = mesh.nodes[block.connectivity[e * count + (i + 1) % corners]];
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
  const int count = nodes_per_facet(group.type);
  double length = 0.0;
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
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
std::map<std::size_t, Eigen::Vector3d> nodes_of_msh22(const std::filesystem::path& path) {
  std::ifstream stream(path);
  std::string line;
  while (std::getline(stream, line) && line != "$Nodes") {
  }
  std::size_t count = 0;
  stream >> count;
  std::map<std::size_t, Eigen::Vector3d> nodes;
  for (std::size_t k = 0; k < count; ++k) {
    std::size_t tag = 0;
    double x = 0, y = 0, z = 0;
    stream >> tag >> x >> y >> z;
    nodes[tag] = {x, y, 0.0};
  }
  return nodes;
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
  for (const Eigen::Vector3d& node : mesh.nodes) {
    EXPECT_TRUE(node.x() >= 0.0 && node.x() <= 1.0 && node.y() >= 0.0 && node.y() <= 1.0);
  }
}

TEST(MeshReader, ReadsMsh22WithTagsCoordinatesAndBoundaries) {
  const std::filesystem::path path = data_directory / "mesh_square_v22.msh";
  const Mesh mesh = read_gmsh_mesh(path);
  ASSERT_EQ(mesh.blocks.size(), 1u);
  EXPECT_EQ(mesh.blocks[0].type, ElementType::triangle3);
  expect_unit_square_with_named_sides(mesh);
  const std::map<std::size_t, Eigen::Vector3d> file_nodes = nodes_of_msh22(path);
  ASSERT_EQ(mesh.node_count(), file_nodes.size());
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    ASSERT_EQ(file_nodes.count(mesh.node_tags[i]), 1u);
    EXPECT_EQ(mesh.nodes[i], file_nodes.at(mesh.node_tags[i]));
  }
  // The bottom side y = 0 holds nodes at x = 0 and x = 1 (the square's corners).
  const BoundaryGroup& bottom = mesh.boundary("bottom");
  EXPECT_EQ(bottom.type, FacetType::line2);
  for (const int node : bottom.nodes()) EXPECT_EQ(mesh.nodes[node].y(), 0.0);
}

TEST(MeshReader, Msh41GivesTheSameMeshAsMsh22) {
  const Mesh old_format = read_gmsh_mesh(data_directory / "mesh_square_v22.msh");
  const Mesh new_format = read_gmsh_mesh(data_directory / "mesh_square_v41.msh");
  expect_unit_square_with_named_sides(new_format);
  ASSERT_EQ(new_format.node_count(), old_format.node_count());
  EXPECT_EQ(new_format.element_count(), old_format.element_count());
  std::map<std::size_t, Eigen::Vector3d> old_nodes;
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
      const Eigen::Vector3d expected = 0.5 * (mesh.nodes[nodes[a]] + mesh.nodes[nodes[b]]);
      EXPECT_NEAR((mesh.nodes[nodes[middle]] - expected).norm(), 0.0, 1e-12);
    }
  }
  const BoundaryGroup& boundary = mesh.boundary("boundary");
  ASSERT_EQ(boundary.type, FacetType::line3);
  for (std::size_t e = 0; e < boundary.facet_count(); ++e) {
    const int* nodes = &boundary.connectivity[3 * e];
    const Eigen::Vector3d expected = 0.5 * (mesh.nodes[nodes[0]] + mesh.nodes[nodes[1]]);
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

/// A private directory under the temporary directory, removed on destruction.
class ScratchDirectory {
 public:
  explicit ScratchDirectory(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("robin-mesh-reader-test-" + name + "-" + std::to_string(std::random_device{}()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchDirectory() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }
  /// Writes `content` to <directory>/<name>; returns the path.
  std::filesystem::path write(const std::string& name, const std::string& content) const {
    const std::filesystem::path file = path_ / name;
    std::ofstream stream(file, std::ios::binary);
    stream << content;
    return file;
  }

 private:
  std::filesystem::path path_;
};

TEST(MeshReader, HandWrittenMeshIsCompactedAndReoriented) {
  const ScratchDirectory directory("hand");
  const Mesh mesh = read_gmsh_mesh(directory.write("hand.msh", small_msh22(7)));
  ASSERT_EQ(mesh.node_count(), 4u);  // node 9 is in no element
  EXPECT_EQ(mesh.node_tags, (std::vector<std::size_t>{1, 2, 3, 4}));
  EXPECT_EQ(mesh.nodes[1], Eigen::Vector3d(2.0, 0.0, 0.0));
  ASSERT_EQ(mesh.blocks.size(), 1u);
  // Both triangles, (1, 3, 2) and (2, 3, 4), are clockwise, like their surface: each is
  // reordered, to (1, 2, 3) and (2, 4, 3).
  EXPECT_EQ(mesh.blocks[0].connectivity, (std::vector<int>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(mesh.blocks[0].tags, (std::vector<std::size_t>{2, 3}));
  EXPECT_NEAR(checked_area(mesh), 2.0, 1e-15);
  EXPECT_EQ(mesh.boundary("5").connectivity, (std::vector<int>{0, 1}));
}

TEST(MeshReader, WithoutSurfaceGroupsTheHandWrittenTrianglesAreStillRead) {
  const ScratchDirectory directory("no-groups");
  const Mesh mesh = read_gmsh_mesh(directory.write("hand.msh", small_msh22(0)));
  EXPECT_EQ(mesh.element_count(), 2u);
  EXPECT_NEAR(checked_area(mesh), 2.0, 1e-15);
}

TEST(MeshReader, HandWrittenMeshErrors) {
  const ScratchDirectory directory("errors");
  // Physical tag 0 everywhere means no physical group at all.
  const std::filesystem::path ungrouped = directory.write("upper.msh", small_msh22(0, 0.0, 0));
  std::string message = input_error_message([&] { read_gmsh_mesh(ungrouped); });
  EXPECT_EQ(message.rfind("mesh file '" + ungrouped.string() + "'", 0), 0u) << message;
  EXPECT_NE(message.find("physical"), std::string::npos) << message;
  const std::filesystem::path tilted = directory.write("tilted.msh", small_msh22(7, 0.5));
  message = input_error_message([&] { read_gmsh_mesh(tilted); });
  EXPECT_NE(message.find("z = 0"), std::string::npos) << message;
  EXPECT_NE(message.find(tilted.string()), std::string::npos) << message;
  EXPECT_THROW(read_gmsh_mesh(directory.write("label.vtk", small_msh22(7))), InputError);
}

// Issue 11 (e): mesh_square_inverted_v22.msh is mesh_square_v22.msh with two nodes of
// triangle 13 swapped (5 2 12 -> 2 5 12), so that it is inverted against the other triangles of
// its surface (a tangled mesh). The reader refuses it naming the element tag; before 2.0 it
// silently reoriented the triangle, folding it over its neighbours.
TEST(MeshReader, TriangleInvertedAgainstItsSurfaceIsRefusedNamingItsTag) {
  const std::filesystem::path path = data_directory / "mesh_square_inverted_v22.msh";
  std::string message = input_error_message([&] { read_gmsh_mesh(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("element tag 13 "), std::string::npos) << message;
  EXPECT_NE(message.find("inverted"), std::string::npos) << message;
  // The file it was made from is read, every element counter-clockwise, with its tag.
  const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_square_v22.msh");
  ASSERT_EQ(mesh.blocks.size(), 1u);
  ASSERT_EQ(mesh.blocks[0].tags.size(), mesh.blocks[0].element_count());
  EXPECT_EQ(mesh.blocks[0].tags.front(), 9u);
  EXPECT_NEAR(checked_area(mesh), 1.0, 1e-12);
  // read_gmsh_meshes refuses it in the same way.
  message = input_error_message([&] { read_gmsh_meshes({{path, {}}}); });
  EXPECT_NE(message.find("element tag 13 "), std::string::npos) << message;
}

TEST(MeshReader, ZeroAreaTriangleIsRefusedNamingItsTag) {
  // small_msh22 with node 3 moved onto the line through nodes 1 and 2: triangle 2 has zero area.
  std::string text = small_msh22(7);
  const std::string node3 = "3 0 1 " + std::to_string(0.0);
  ASSERT_NE(text.find(node3), std::string::npos);
  text.replace(text.find(node3), node3.size(), "3 1 0 " + std::to_string(0.0));
  const ScratchDirectory directory("zero-area");
  const std::string message =
      input_error_message([&] { read_gmsh_mesh(directory.write("flat.msh", text)); });
  EXPECT_NE(message.find("element tag 2 "), std::string::npos) << message;
  EXPECT_NE(message.find("zero area"), std::string::npos) << message;
}

// read_gmsh_meshes, which replaced the reading of mesh text (a server no longer meshes what it
// receives: the coordinator meshes its user's .geo files, each in a child process), gives the
// meshes read_gmsh_mesh gives, and names the file of the first failure.
TEST(MeshReader, ReadGmshMeshesMatchesReadGmshMeshAndErrorsNameTheFile) {
  const std::filesystem::path msh = data_directory / "mesh_square_v22.msh";
  const std::filesystem::path geo = data_directory / "mesh_square.geo";
  const std::vector<Mesh> meshes =
      read_gmsh_meshes({{msh, {}}, {geo, {.size = 0.25}}, {geo, {.size = 0.5}}});
  ASSERT_EQ(meshes.size(), 3u);
  const Mesh from_file = read_gmsh_mesh(msh);
  EXPECT_EQ(meshes[0].node_tags, from_file.node_tags);
  EXPECT_EQ(meshes[0].nodes, from_file.nodes);
  EXPECT_EQ(meshes[0].blocks[0].connectivity, from_file.blocks[0].connectivity);
  EXPECT_EQ(meshes[0].source, msh.string());
  for (const auto& [index, size] : {std::pair{1, 0.25}, std::pair{2, 0.5}}) {
    const Mesh& meshed = meshes[static_cast<std::size_t>(index)];
    expect_unit_square_with_named_sides(meshed);
    EXPECT_EQ(meshed.source, geo.string());
    const Mesh direct = read_gmsh_mesh(geo, {.size = size});
    EXPECT_EQ(meshed.node_count(), direct.node_count()) << size;
    EXPECT_EQ(meshed.element_count(), direct.element_count()) << size;
    EXPECT_EQ(boundary_names(meshed), boundary_names(direct)) << size;
  }
  EXPECT_GT(meshes[1].node_count(), meshes[2].node_count());

  const std::filesystem::path broken = data_directory / "mesh_syntax_error.geo";
  const std::string message = input_error_message([&] {
    read_gmsh_meshes({{geo, {}}, {broken, {}}});
  });
  EXPECT_EQ(message.rfind("mesh file '" + broken.string() + "'", 0), 0u) << message;
  EXPECT_NE(message.find("line 3"), std::string::npos) << message;
  EXPECT_EQ(message.find("robin-mesh-"), std::string::npos) << message;
}

// The observer hears each request begin once and end once, with the mesh that is returned.
TEST(MeshReader, ReadGmshMeshesTellsWhenEachMeshBeginsAndIsRead) {
  const std::filesystem::path msh = data_directory / "mesh_square_v22.msh";
  const std::filesystem::path geo = data_directory / "mesh_square.geo";
  std::vector<std::size_t> started;
  std::vector<std::pair<std::size_t, std::size_t>> finished;  // request, node count
  MeshReadObserver observer;
  observer.started = [&](std::size_t request) { started.push_back(request); };
  observer.finished = [&](std::size_t request, const Mesh& mesh, double seconds) {
    EXPECT_EQ(std::count(started.begin(), started.end(), request), 1) << request;
    EXPECT_GE(seconds, 0.0);
    finished.emplace_back(request, mesh.node_count());
  };
  const std::vector<Mesh> meshes =
      read_gmsh_meshes({{geo, {.size = 0.25}}, {msh, {}}, {geo, {.size = 0.5}}}, observer);
  std::sort(started.begin(), started.end());
  EXPECT_EQ(started, (std::vector<std::size_t>{0, 1, 2}));
  ASSERT_EQ(finished.size(), 3u);
  EXPECT_EQ(finished.back().first, 1u);  // the .msh is read once the children have ended
  for (const auto& [request, nodes] : finished) EXPECT_EQ(nodes, meshes[request].node_count());
}

// The receiver gets every mesh once, as read_gmsh_mesh reads it: several .msh files (read on
// threads of their own) in request order, after the observer heard of each; after a failing
// request no later mesh is handed over, and the failure names its file.
TEST(MeshReader, ReadGmshMeshesHandsEachMeshOverOnceInRequestOrder) {
  const std::filesystem::path v22 = data_directory / "mesh_square_v22.msh";
  const std::filesystem::path v41 = data_directory / "mesh_square_v41.msh";
  const std::vector<MeshFileRequest> requests = {{v22, {}}, {v41, {}}, {v22, {}}, {v41, {}}};
  std::vector<std::size_t> finished;
  std::vector<std::size_t> received;
  std::vector<Mesh> meshes(requests.size());
  MeshReadObserver observer;
  observer.finished = [&](std::size_t request, const Mesh&, double) {
    finished.push_back(request);
  };
  read_gmsh_meshes(
      requests,
      [&](std::size_t request, Mesh&& mesh) {
        EXPECT_EQ(finished.size(), received.size() + 1) << request;
        received.push_back(request);
        meshes[request] = std::move(mesh);
      },
      observer);
  EXPECT_EQ(received, (std::vector<std::size_t>{0, 1, 2, 3}));
  for (std::size_t k = 0; k < requests.size(); ++k) {
    const Mesh direct = read_gmsh_mesh(requests[k].path);
    EXPECT_EQ(meshes[k].nodes, direct.nodes) << k;
    EXPECT_EQ(meshes[k].blocks[0].connectivity, direct.blocks[0].connectivity) << k;
    EXPECT_EQ(meshes[k].source, requests[k].path.string()) << k;
  }

  const std::filesystem::path garbage = data_directory / "mesh_garbage.msh";
  received.clear();
  const std::string message = input_error_message([&] {
    read_gmsh_meshes({{v22, {}}, {garbage, {}}, {v41, {}}},
                     [&](std::size_t request, Mesh&&) { received.push_back(request); });
  });
  EXPECT_EQ(received, (std::vector<std::size_t>{0}));
  EXPECT_NE(message.find(garbage.string()), std::string::npos) << message;

  // an InputError of the receiver is that request's failure
  const std::string refused = input_error_message([&] {
    read_gmsh_meshes({{v22, {}}, {v41, {}}}, [&](std::size_t request, Mesh&&) {
      if (request == 0) throw InputError("request 0 refused by its receiver");
      ADD_FAILURE() << "request " << request << " handed over after a failure";
    });
  });
  EXPECT_EQ(refused, "request 0 refused by its receiver");
}

TEST(MeshReader, ReadGmshMeshesLeavesNoTemporaryFile) {
  // A private temporary directory (through TMPDIR) so that other processes do not interfere.
  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() /
      ("robin-mesh-reader-test-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(directory);
  const char* previous = std::getenv("TMPDIR");
  const std::string saved = previous ? previous : "";
  ::setenv("TMPDIR", directory.c_str(), 1);
  const std::filesystem::path geo = data_directory / "mesh_square.geo";
  read_gmsh_meshes({{geo, {}}, {data_directory / "mesh_square_v41.msh", {}}});
  EXPECT_THROW(read_gmsh_meshes({{geo, {}}, {data_directory / "mesh_syntax_error.geo", {}}}),
               InputError);
  EXPECT_THROW(read_gmsh_meshes({{geo, {}}, {data_directory / "mesh_garbage.msh", {}}}),
               InputError);
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
