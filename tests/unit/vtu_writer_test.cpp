// write_vtu / write_pvd: the files are parsed back by an independent reader (Python's xml.etree
// and its own decoder of the appended zlib blocks) and by VTK's own reader (the one ParaView
// uses), and checked against hand-computed counts, cell types, offsets, geometry and values.

#include "numerics/vtu_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>

#include "numerics/rectangle_mesher.hpp"
#include "vtk_xml_test_reader.hpp"

namespace robin {
namespace {

using nlohmann::json;
using test::find_array;
using test::read_vtk_xml;
using test::TemporaryDirectory;

/// Written point k of a piece as (x, y, z).
Eigen::Vector3d written_point(const json& piece, std::size_t k) {
  const json& values = find_array(piece["Points"], "Points")["values"];
  return {values[3 * k].get<double>(), values[3 * k + 1].get<double>(),
          values[3 * k + 2].get<double>()};
}

/// Shoelace area of cell `cell` from the written points, connectivity and offsets, using its
/// first `corners` nodes (positive when counter-clockwise).
double written_signed_area(const json& piece, std::size_t cell, int corners) {
  const json& connectivity = find_array(piece["Cells"], "connectivity")["values"];
  const json& offsets = find_array(piece["Cells"], "offsets")["values"];
  const std::size_t begin = cell == 0 ? 0 : offsets[cell - 1].get<std::size_t>();
  double twice_area = 0.0;
  for (int a = 0; a < corners; ++a) {
    const Eigen::Vector3d p = written_point(piece, connectivity[begin + a].get<std::size_t>());
    const Eigen::Vector3d q =
        written_point(piece, connectivity[begin + (a + 1) % corners].get<std::size_t>());
    twice_area += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice_area;
}

/// One triangle3 block, one quadrilateral4 block and one triangle6 block, side by side:
/// [0,1]^2 split into two triangles, the square [1,2]x[0,1], and the right triangle
/// (2,0), (3,0), (2,1) with its edge midpoints.
Mesh make_mixed_mesh() {
  Mesh mesh;
  mesh.nodes = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0},   {0, 1, 0},     {2, 0, 0},
                {2, 1, 0}, {3, 0, 0}, {2.5, 0, 0}, {2.5, 0.5, 0}, {2, 0.5, 0}};
  mesh.blocks.push_back({ElementType::triangle3, {0, 1, 2, 0, 2, 3}, {}});
  mesh.blocks.push_back({ElementType::quadrilateral4, {1, 4, 5, 2}, {}});
  mesh.blocks.push_back({ElementType::triangle6, {4, 6, 5, 7, 8, 9}, {}});
  return mesh;
}

TEST(VtuWriter, QuadrilateralRectangleWritesPointsCellsAndFields) {
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 2, 1, ElementType::quadrilateral4);
  ASSERT_EQ(mesh.node_count(), 6u);
  OutputField temperature{"temperature", 1, {}};
  OutputField displacement{"displacement", 2, {}};
  for (const Eigen::Vector3d& node : mesh.nodes) {
    temperature.values.push_back(node.x() + 10.0 * node.y());
    displacement.values.insert(displacement.values.end(), {node.x(), -node.y()});
  }
  const OutputField cell_index{"index", 1, {0.0, 1.0}};
  const auto path = directory.path() / "rectangle.vtu";
  write_vtu(path, mesh, {temperature, displacement}, {cell_index});

  const json document = read_vtk_xml(path);
  EXPECT_EQ(document["root"]["type"], "UnstructuredGrid");
  EXPECT_EQ(document["root"]["version"], "1.0");
  EXPECT_EQ(document["root"]["header_type"], "UInt64");
  EXPECT_EQ(document["root"]["compressor"], "vtkZLibDataCompressor");
  ASSERT_EQ(document["pieces"].size(), 1u);
  const json& piece = document["pieces"][0];
  EXPECT_EQ(piece["attributes"]["NumberOfPoints"], "6");
  // 2 quadrilaterals, then the 6 boundary edges: bottom (2), left (1), right (1), top (2)
  EXPECT_EQ(piece["attributes"]["NumberOfCells"], "8");
  EXPECT_EQ(find_array(piece["Points"], "Points")["attributes"]["type"], "Float64");
  EXPECT_EQ(find_array(piece["Points"], "Points")["attributes"]["format"], "appended");

  // every grid point of [0,2]x[0,1] with unit spacing appears, in the plane z = 0
  for (double x : {0.0, 1.0, 2.0}) {
    for (double y : {0.0, 1.0}) {
      int found = 0;
      for (std::size_t k = 0; k < 6; ++k)
        found += written_point(piece, k) == Eigen::Vector3d(x, y, 0);
      EXPECT_EQ(found, 1) << "grid point (" << x << ", " << y << ")";
    }
  }
  EXPECT_EQ(find_array(piece["Cells"], "types")["values"], json({9, 9, 3, 3, 3, 3, 3, 3}));
  EXPECT_EQ(find_array(piece["Cells"], "offsets")["values"], json({4, 8, 10, 12, 14, 16, 18, 20}));
  const json& connectivity = find_array(piece["Cells"], "connectivity")["values"];
  EXPECT_EQ(std::vector<int>(connectivity.begin(), connectivity.begin() + 8),
            mesh.blocks[0].connectivity);
  for (std::size_t cell = 0; cell < 2; ++cell) {
    EXPECT_DOUBLE_EQ(written_signed_area(piece, cell, 4), 1.0) << "cell " << cell;
  }
  // Boundary edges: boundary_id k names boundary_names[k - 1]; each edge lies on its side of
  // [0,2]x[0,1], has unit length, and carries the cell field of the quadrilateral it bounds
  // (the one containing its midpoint: index = floor(x of the midpoint)).
  ASSERT_EQ(document["field_data"].size(), 1u);
  EXPECT_EQ(document["field_data"][0]["attributes"]["Name"], "boundary_names");
  const json& names = document["field_data"][0]["values"];
  EXPECT_EQ(names, json({"bottom", "left", "right", "top"}));
  const json& boundary_id = find_array(piece["CellData"], "boundary_id");
  EXPECT_EQ(boundary_id["attributes"]["type"], "Int32");
  EXPECT_EQ(boundary_id["values"], json({0, 0, 1, 1, 2, 3, 4, 4}));
  const json& written_index = find_array(piece["CellData"], "index")["values"];
  for (std::size_t cell = 2; cell < 8; ++cell) {
    const Eigen::Vector3d a =
        written_point(piece, connectivity[8 + 2 * (cell - 2)].get<std::size_t>());
    const Eigen::Vector3d b =
        written_point(piece, connectivity[8 + 2 * (cell - 2) + 1].get<std::size_t>());
    const Eigen::Vector3d middle = 0.5 * (a + b);
    EXPECT_DOUBLE_EQ((b - a).norm(), 1.0) << "cell " << cell;
    const std::string side = names[boundary_id["values"][cell].get<int>() - 1];
    const double on_side = side == "bottom" ? middle.y()
                           : side == "top"  ? middle.y() - 1.0
                           : side == "left" ? middle.x()
                                            : middle.x() - 2.0;
    EXPECT_EQ(on_side, 0.0) << "cell " << cell << " on " << side;
    EXPECT_EQ(written_index[cell].get<double>(), std::floor(std::min(middle.x(), 1.5)))
        << "cell " << cell;
  }

  const json& written_temperature = find_array(piece["PointData"], "temperature");
  const json& written_displacement = find_array(piece["PointData"], "displacement");
  EXPECT_EQ(written_temperature["attributes"]["NumberOfComponents"], "1");
  EXPECT_EQ(written_displacement["attributes"]["NumberOfComponents"], "3");
  for (std::size_t k = 0; k < 6; ++k) {
    const Eigen::Vector3d point = written_point(piece, k);
    EXPECT_EQ(written_temperature["values"][k].get<double>(), point.x() + 10.0 * point.y());
    EXPECT_EQ(written_displacement["values"][3 * k].get<double>(), point.x());
    EXPECT_EQ(written_displacement["values"][3 * k + 1].get<double>(), -point.y());
    EXPECT_EQ(written_displacement["values"][3 * k + 2].get<double>(), 0.0);
  }
  EXPECT_EQ(written_index[0], 0.0);
  EXPECT_EQ(written_index[1], 1.0);
}

TEST(VtuWriter, TriangleRectangleHasCounterClockwiseTrianglesCoveringTheArea) {
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 3.0, 2.0, 3, 2, ElementType::triangle3);
  const auto path = directory.path() / "triangles.vtu";
  write_vtu(path, mesh, {}, {}, {.boundary_cells = false});

  const json piece = read_vtk_xml(path)["pieces"][0];
  EXPECT_EQ(piece["attributes"]["NumberOfPoints"], "12");
  EXPECT_EQ(piece["attributes"]["NumberOfCells"], "12");
  const json& types = find_array(piece["Cells"], "types")["values"];
  const json& offsets = find_array(piece["Cells"], "offsets")["values"];
  ASSERT_EQ(types.size(), 12u);
  double total_area = 0.0;
  for (std::size_t cell = 0; cell < 12; ++cell) {
    EXPECT_EQ(types[cell], 5);
    EXPECT_EQ(offsets[cell], 3 * (cell + 1));
    const double area = written_signed_area(piece, cell, 3);
    EXPECT_DOUBLE_EQ(area, 0.5) << "cell " << cell;  // half of a unit cell, counter-clockwise
    total_area += area;
  }
  EXPECT_DOUBLE_EQ(total_area, 6.0);
}

TEST(VtuWriter, MixedBlocksGetTheirCellTypesInBlockOrder) {
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_mixed_mesh();
  const OutputField stress{
      "stress", 3, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}, {"xx", "yy", "xy"}};
  const auto path = directory.path() / "mixed.vtu";
  write_vtu(path, mesh, {}, {stress});

  const json piece = read_vtk_xml(path)["pieces"][0];
  EXPECT_EQ(piece["attributes"]["NumberOfCells"], "4");
  EXPECT_EQ(find_array(piece["Cells"], "types")["values"], json({5, 5, 9, 22}));
  EXPECT_EQ(find_array(piece["Cells"], "offsets")["values"], json({3, 6, 10, 16}));
  EXPECT_EQ(find_array(piece["Cells"], "connectivity")["values"],
            json({0, 1, 2, 0, 2, 3, 1, 4, 5, 2, 4, 6, 5, 7, 8, 9}));
  EXPECT_DOUBLE_EQ(written_signed_area(piece, 2, 4), 1.0);
  EXPECT_DOUBLE_EQ(written_signed_area(piece, 3, 3), 0.5);

  // VTK_QUADRATIC_TRIANGLE: nodes 3, 4, 5 are the midpoints of edges 01, 12, 20
  const json& connectivity = find_array(piece["Cells"], "connectivity")["values"];
  const auto node = [&](int local) {
    return written_point(piece, connectivity[10 + local].get<std::size_t>());
  };
  EXPECT_EQ(node(3), 0.5 * (node(0) + node(1)));
  EXPECT_EQ(node(4), 0.5 * (node(1) + node(2)));
  EXPECT_EQ(node(5), 0.5 * (node(2) + node(0)));

  const json& written_stress = find_array(piece["CellData"], "stress");
  EXPECT_EQ(written_stress["attributes"]["NumberOfComponents"], "3");
  EXPECT_EQ(written_stress["attributes"]["ComponentName0"], "xx");
  EXPECT_EQ(written_stress["attributes"]["ComponentName2"], "xy");
  EXPECT_EQ(written_stress["values"], json(stress.values));
}

class VtuEncodings : public ::testing::TestWithParam<VtuEncoding> {};

INSTANTIATE_TEST_SUITE_P(VtuWriter, VtuEncodings,
                         ::testing::Values(VtuEncoding::binary_zlib, VtuEncoding::ascii),
                         [](const auto& info) {
                           return info.param == VtuEncoding::ascii ? "Ascii" : "BinaryZlib";
                         });

TEST_P(VtuEncodings, NumbersRoundTripExactly) {
  const TemporaryDirectory directory("vtu_writer");
  Mesh mesh;
  mesh.nodes = {{0.1, 0.7, 0}, {1.0 / 3.0, -2.0 / 7.0, 0}, {std::numbers::pi, 1e-17, 0}};
  mesh.blocks.push_back({ElementType::triangle3, {0, 1, 2}, {}});
  const std::vector<double> values = {0.1,
                                      1.0 / 3.0,
                                      -2.0 / 7.0,
                                      1e-300,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::max(),
                                      -0.0,
                                      123456789.12345679,
                                      std::numbers::e * 1e22,
                                      -1.0 - std::numeric_limits<double>::epsilon(),
                                      6.02214076e23,
                                      42.0};
  const auto path = directory.path() / "numbers.vtu";
  write_vtu(path, mesh, {{"four", 4, values}}, {{"single", 1, {std::numbers::sqrt2}}},
            {.encoding = GetParam()});

  const json piece = read_vtk_xml(path)["pieces"][0];
  const json& written = find_array(piece["PointData"], "four");
  EXPECT_EQ(written["attributes"]["format"],
            GetParam() == VtuEncoding::ascii ? "ascii" : "appended");
  EXPECT_EQ(written["attributes"]["NumberOfComponents"], "4");
  ASSERT_EQ(written["values"].size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double value = written["values"][i].get<double>();
    EXPECT_EQ(value, values[i]) << "value " << i;
    EXPECT_EQ(std::signbit(value), std::signbit(values[i])) << "value " << i;
  }
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(written_point(piece, k), Eigen::Vector3d(mesh.nodes[k].x(), mesh.nodes[k].y(), 0));
  }
  EXPECT_EQ(find_array(piece["CellData"], "single")["values"][0].get<double>(),
            std::numbers::sqrt2);
}

TEST(VtuWriter, NamesWithXmlCharactersAreEscaped) {
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_mixed_mesh();
  const std::string name = "a<b & \"c\" 'd'>";
  const auto path = directory.path() / "escaped.vtu";
  write_vtu(path, mesh, {{name, 1, std::vector<double>(10, 2.5)}}, {});
  const json piece = read_vtk_xml(path)["pieces"][0];
  EXPECT_EQ(find_array(piece["PointData"], name)["values"], json(std::vector<double>(10, 2.5)));
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

TEST(VtuWriter, MalformedFieldIsRejectedNamingFieldAndPath) {
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_mixed_mesh();  // 10 nodes, 4 cells
  const auto path = directory.path() / "bad.vtu";
  expect_error_naming(
      [&] {
        write_vtu(path, mesh, {{"pressure", 1, std::vector<double>(9)}}, {});
      },
      {"pressure", path.string(), "10", "9"});
  expect_error_naming(
      [&] {
        write_vtu(path, mesh, {}, {{"cell_stress", 3, std::vector<double>(4)}});
      },
      {"cell_stress", path.string(), "12"});
  expect_error_naming(
      [&] {
        write_vtu(path, mesh, {{"nothing", 0, {}}}, {});
      },
      {"nothing", path.string()});
  expect_error_naming(
      [&] {
        write_vtu(path, mesh, {{"", 1, std::vector<double>(10)}}, {});
      },
      {path.string()});
  EXPECT_FALSE(std::filesystem::exists(path)) << "nothing is written for a malformed field";
}

TEST(VtuWriter, UnwritablePathGivesAnErrorNamingIt) {
  const TemporaryDirectory directory("vtu_writer");
  const auto vtu_path = directory.path() / "no_such_directory" / "mesh.vtu";
  expect_error_naming([&] { write_vtu(vtu_path, make_mixed_mesh(), {}, {}); }, {vtu_path.string()});
  const auto pvd_path = directory.path() / "no_such_directory" / "solution.pvd";
  expect_error_naming([&] { write_pvd(pvd_path, {"a.vtu"}); }, {pvd_path.string()});
}

TEST(VtuWriter, CollectionListsEachDatasetAsAPart) {
  const TemporaryDirectory directory("vtu_writer");
  const auto path = directory.path() / "solution.pvd";
  write_pvd(path, {"upper.vtu", "lower & base.vtu"});
  const json document = read_vtk_xml(path);
  EXPECT_EQ(document["root"]["type"], "Collection");
  ASSERT_EQ(document["datasets"].size(), 2u);
  EXPECT_EQ(document["datasets"][0]["part"], "0");
  EXPECT_EQ(document["datasets"][0]["file"], "upper.vtu");
  EXPECT_EQ(document["datasets"][1]["part"], "1");
  EXPECT_EQ(document["datasets"][1]["file"], "lower & base.vtu");
}

TEST(VtuWriter, CellTypeNumbersAreVtks) {
  EXPECT_EQ(vtk_cell_type(ElementType::triangle3), 5);
  EXPECT_EQ(vtk_cell_type(ElementType::triangle6), 22);
  EXPECT_EQ(vtk_cell_type(ElementType::quadrilateral4), 9);
  EXPECT_EQ(vtk_cell_type(FacetType::line2), 3);
  EXPECT_EQ(vtk_cell_type(FacetType::line3), 21);
}

/// A P2 mesh of [0,4]x[0,3] (4 x 3 cells, 2 triangle6 each) with its line3 boundaries,
/// the point field f = (x + 2y, x y, x^2) and the cell field "cell" = its index.
struct QuadraticCase {
  Mesh mesh = make_rectangle_mesh(0.0, 0.0, 4.0, 3.0, 4, 3, ElementType::triangle6);
  OutputField point_field{"f", 3, {}};
  OutputField cell_field{"cell", 1, {}};
  QuadraticCase() {
    for (const Eigen::Vector3d& node : mesh.nodes) {
      point_field.values.insert(
          point_field.values.end(),
          {node.x() + 2 * node.y(), node.x() * node.y(), node.x() * node.x()});
    }
    for (std::size_t e = 0; e < mesh.element_count(); ++e) {
      cell_field.values.push_back(static_cast<double>(e));
    }
  }
};

TEST_P(VtuEncodings, VtkReadsQuadraticCellsBoundariesAndFields) {
  const TemporaryDirectory directory("vtu_writer");
  const QuadraticCase data;
  ASSERT_EQ(data.mesh.element_count(), 24u);
  const auto path = directory.path() / "quadratic.vtu";
  write_vtu(path, data.mesh, {data.point_field}, {data.cell_field}, {.encoding = GetParam()});

  const json grid = test::read_vtu_with_vtk(path);
  // 24 quadratic triangles, then 4 + 3 + 3 + 4 quadratic edges (bottom, left, right, top)
  const json& types = grid["types"];
  ASSERT_EQ(types.size(), 38u);
  for (std::size_t cell = 0; cell < 38; ++cell) EXPECT_EQ(types[cell], cell < 24 ? 22 : 21);
  const json& boundary_id = grid["cell_data"]["boundary_id"]["values"];
  EXPECT_EQ(grid["field_data"]["boundary_names"], json({"bottom", "left", "right", "top"}));
  const std::vector<int> edges_per_boundary = {4, 3, 3, 4};
  std::size_t cell = 24;
  for (int id = 1; id <= 4; ++id) {
    for (int k = 0; k < edges_per_boundary[id - 1]; ++k, ++cell) EXPECT_EQ(boundary_id[cell], id);
  }
  const json& points = grid["points"];
  const json& connectivity = grid["connectivity"];
  const json& offsets = grid["offsets"];
  const auto point = [&](std::size_t index) {
    const std::size_t node = connectivity[index].get<std::size_t>();
    return Eigen::Vector3d(points[3 * node].get<double>(), points[3 * node + 1].get<double>(),
                           points[3 * node + 2].get<double>());
  };
  const json& cell_values = grid["cell_data"]["cell"]["values"];
  for (std::size_t edge = 24; edge < 38; ++edge) {
    // VTK_QUADRATIC_EDGE: the endpoints, then the midpoint; unit length on the boundary
    const std::size_t begin = offsets[edge].get<std::size_t>() - 3;
    EXPECT_EQ(point(begin + 2), 0.5 * (point(begin) + point(begin + 1))) << "edge " << edge;
    EXPECT_DOUBLE_EQ((point(begin + 1) - point(begin)).norm(), 1.0) << "edge " << edge;
    // the cell value of the adjacent triangle: one whose corners include both endpoints
    const auto element = static_cast<std::size_t>(cell_values[edge].get<double>());
    ASSERT_LT(element, 24u) << "edge " << edge;
    int shared = 0;
    for (int a = 0; a < 3; ++a) {
      const std::size_t corner = offsets[element].get<std::size_t>() - 6 + a;
      shared += point(corner) == point(begin) || point(corner) == point(begin + 1);
    }
    EXPECT_EQ(shared, 2) << "edge " << edge;
  }
  // the point field, against its formula at the read points
  const json& f = grid["point_data"]["f"]["values"];
  ASSERT_EQ(f.size(), 3 * data.mesh.node_count());
  for (std::size_t node = 0; node < data.mesh.node_count(); ++node) {
    const double x = points[3 * node].get<double>(), y = points[3 * node + 1].get<double>();
    EXPECT_EQ(f[3 * node].get<double>(), x + 2 * y);
    EXPECT_EQ(f[3 * node + 1].get<double>(), x * y);
    EXPECT_EQ(f[3 * node + 2].get<double>(), x * x);
  }
}

TEST(VtuWriter, SixComponentFieldIsParaViewsSymmetricTensor) {
  // A uniform symmetric tensor with distinct entries (XX, YY, ZZ, XY, YZ, XZ) =
  // (1, 2, 3, 4, 5, 6) on every node: VTK reads it as 6 components in that order, with names.
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 1.0, 1.0, 1, 1, ElementType::triangle3);
  OutputField tensor{"stress", 6, {}, {"XX", "YY", "ZZ", "XY", "YZ", "XZ"}};
  for (std::size_t node = 0; node < mesh.node_count(); ++node) {
    tensor.values.insert(tensor.values.end(), {1, 2, 3, 4, 5, 6});
  }
  const auto path = directory.path() / "tensor.vtu";
  write_vtu(path, mesh, {tensor}, {});
  const json grid = test::read_vtu_with_vtk(path);
  const json& stress = grid["point_data"]["stress"];
  EXPECT_EQ(stress["components"], 6);
  EXPECT_EQ(stress["component_names"], json({"XX", "YY", "ZZ", "XY", "YZ", "XZ"}));
  for (std::size_t node = 0; node < mesh.node_count(); ++node) {
    for (int c = 0; c < 6; ++c) EXPECT_EQ(stress["values"][6 * node + c], c + 1.0);
  }
}

TEST(VtuWriter, CompressedArraysSpanSeveralBlocksAndAreSmallerThanText) {
  // 61 x 41 nodes: the points alone are 60024 bytes, two zlib blocks of 32768 bytes.
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_rectangle_mesh(0.0, 0.0, 6.0, 4.0, 60, 40, ElementType::quadrilateral4);
  OutputField field{"sine", 1, {}};
  for (const Eigen::Vector3d& node : mesh.nodes) {
    field.values.push_back(std::sin(node.x()) * std::cos(node.y()));
  }
  const auto binary = directory.path() / "binary.vtu";
  const auto ascii = directory.path() / "ascii.vtu";
  write_vtu(binary, mesh, {field}, {});
  write_vtu(ascii, mesh, {field}, {}, {.encoding = VtuEncoding::ascii});
  EXPECT_LT(std::filesystem::file_size(binary), std::filesystem::file_size(ascii) / 2);

  const json independent = read_vtk_xml(binary)["pieces"][0];
  const json from_text = read_vtk_xml(ascii)["pieces"][0];
  const json vtk = test::read_vtu_with_vtk(binary);
  const json& points = find_array(independent["Points"], "Points")["values"];
  ASSERT_EQ(points.size(), 3 * mesh.node_count());
  EXPECT_EQ(points, find_array(from_text["Points"], "Points")["values"]);
  EXPECT_EQ(points, vtk["points"]);
  const json& values = find_array(independent["PointData"], "sine")["values"];
  EXPECT_EQ(values, json(field.values));
  EXPECT_EQ(vtk["point_data"]["sine"]["values"], json(field.values));
  EXPECT_EQ(find_array(independent["Cells"], "connectivity")["values"], vtk["connectivity"]);
}

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The source of `field`, appending its values and recording its name in `calls`.
FieldSource recorded_source(const OutputField& field, std::vector<std::string>& calls) {
  return {field.name, field.components, field.component_names,
          [&field, &calls](std::vector<double>& values) {
            calls.push_back(field.name);
            values.insert(values.end(), field.values.begin(), field.values.end());
          }};
}

TEST_P(VtuEncodings, StreamedFieldsWriteTheFileOfTheFieldsAtHand) {
  const TemporaryDirectory directory("vtu_writer");
  const QuadraticCase data;  // with its boundary edges as cells
  OutputField vector_field{"v", 2, {}}, cell_vector{"w", 2, {}, {"a", "b"}};
  for (std::size_t k = 0; k < data.mesh.node_count(); ++k) {
    vector_field.values.insert(vector_field.values.end(), {0.5 * k, -1.0 * k});
  }
  for (std::size_t e = 0; e < data.mesh.element_count(); ++e) {
    cell_vector.values.insert(cell_vector.values.end(), {1.0 + e, 2.0 - e});
  }
  const auto at_hand = directory.path() / "at_hand.vtu";
  const auto streamed = directory.path() / "streamed.vtu";
  const VtuOptions options{.encoding = GetParam()};
  write_vtu(at_hand, data.mesh, {data.point_field, vector_field}, {data.cell_field, cell_vector},
            options);
  std::vector<std::string> calls;
  write_streamed_vtu(
      streamed, data.mesh,
      {recorded_source(data.point_field, calls), recorded_source(vector_field, calls)},
      {recorded_source(data.cell_field, calls), recorded_source(cell_vector, calls)}, options);
  EXPECT_EQ(calls, std::vector<std::string>({"f", "v", "cell", "w"}));
  const std::string bytes = file_bytes(at_hand);
  ASSERT_GT(bytes.size(), 1000u);
  EXPECT_TRUE(bytes == file_bytes(streamed));
  // the two-component fields padded to three, the cell field copied to the boundary edges
  const json piece = read_vtk_xml(streamed)["pieces"][0];
  const json& v = find_array(piece["PointData"], "v")["values"];
  ASSERT_EQ(v.size(), 3 * data.mesh.node_count());
  EXPECT_EQ(v[3 * 5].get<double>(), 2.5);
  EXPECT_EQ(v[3 * 5 + 1].get<double>(), -5.0);
  EXPECT_EQ(v[3 * 5 + 2].get<double>(), 0.0);
  const json& w = find_array(piece["CellData"], "w")["values"];
  const json& cell = find_array(piece["CellData"], "cell")["values"];
  ASSERT_EQ(w.size(), 3u * 38u);
  for (std::size_t edge = 24; edge < 38; ++edge) {
    const double element = cell[edge].get<double>();
    EXPECT_EQ(w[3 * edge].get<double>(), 1.0 + element) << "edge " << edge;
    EXPECT_EQ(w[3 * edge + 1].get<double>(), 2.0 - element) << "edge " << edge;
    EXPECT_EQ(w[3 * edge + 2].get<double>(), 0.0) << "edge " << edge;
  }
}

TEST(VtuWriter, StreamedFieldOfTheWrongSizeIsRejectedNamingFieldAndPath) {
  const TemporaryDirectory directory("vtu_writer");
  const Mesh mesh = make_mixed_mesh();  // 10 nodes, 4 cells
  const auto path = directory.path() / "bad.vtu";
  const auto values_of_size = [](std::size_t size) {
    return [size](std::vector<double>& values) { values.resize(size, 1.0); };
  };
  expect_error_naming(
      [&] {
        write_streamed_vtu(path, mesh, {{"pressure", 1, {}, values_of_size(9)}}, {});
      },
      {"pressure", path.string(), "10", "9"});
  expect_error_naming(
      [&] {
        write_streamed_vtu(path, mesh, {}, {{"cell_stress", 3, {}, values_of_size(4)}});
      },
      {"cell_stress", path.string(), "12"});
  expect_error_naming(
      [&] {
        write_streamed_vtu(path, mesh, {{"nothing", 0, {}, values_of_size(0)}}, {});
      },
      {"nothing", path.string()});
}

TEST(VtuWriter, FacetOfTwoElementsTakesTheFirstElementsCellValues) {
  const TemporaryDirectory directory("vtu_writer");
  Mesh mesh = make_mixed_mesh();  // triangles 0 (0, 1, 2) and 1 (0, 2, 3) share the edge 0-2
  mesh.boundaries["diagonal"] = {FacetType::line2, {2, 0}};
  mesh.boundaries["loose"] = {FacetType::line2, {0, 4}};  // a side of no element
  const auto path = directory.path() / "shared.vtu";
  write_vtu(path, mesh, {}, {{"index", 1, {10.0, 20.0, 30.0, 40.0}}});
  const json piece = read_vtk_xml(path)["pieces"][0];
  const json& index = find_array(piece["CellData"], "index")["values"];
  ASSERT_EQ(index.size(), 6u);
  EXPECT_EQ(index[4].get<double>(), 10.0);
  EXPECT_TRUE(index[5].is_null()) << "NaN on a side of no element, got " << index[5];
}

}  // namespace
}  // namespace robin
