#include "numerics/box_mesher.hpp"

#include <Eigen/LU>
#include <array>
#include <map>
#include <stdexcept>
#include <utility>

namespace robin {
namespace {

/// The grid of (cells + 1) nodes per direction, x fastest.
struct Grid {
  Eigen::Vector3i cells;
  int node(int i, int j, int k) const { return i + (cells.x() + 1) * (j + (cells.y() + 1) * k); }
  int node(const Eigen::Vector3i& at) const { return node(at.x(), at.y(), at.z()); }
};

/// The six tetrahedra of Kuhn's triangulation of the unit cube, as corner offsets: for each
/// permutation (a, b, c) of the axes, the path 0, e_a, e_a + e_b, e_a + e_b + e_c.
std::vector<std::array<Eigen::Vector3i, 4>> kuhn_tetrahedra() {
  std::vector<std::array<Eigen::Vector3i, 4>> tetrahedra;
  std::array<int, 3> axes = {0, 1, 2};
  do {
    std::array<Eigen::Vector3i, 4> path;
    path[0] = Eigen::Vector3i::Zero();
    for (int step = 0; step < 3; ++step)
      path[step + 1] = path[step] + Eigen::Vector3i::Unit(axes[step]);
    tetrahedra.push_back(path);
  } while (std::next_permutation(axes.begin(), axes.end()));
  return tetrahedra;
}

double signed_volume(const Mesh& mesh, const int* corners) {
  const Eigen::Vector3d& origin = mesh.nodes[corners[0]];
  Eigen::Matrix3d edges;
  for (int a = 0; a < 3; ++a) edges.col(a) = mesh.nodes[corners[a + 1]] - origin;
  return edges.determinant();
}

/// The two triangles (or the quadrilateral) of the cell face at `corner` spanned by the axes
/// `first` and `second`, split along the diagonal from its lowest to its highest corner (as
/// Kuhn's triangulation splits it).
void add_face(const Grid& grid, const Eigen::Vector3i& corner, int first, int second,
              bool triangles, std::vector<int>& connectivity) {
  const Eigen::Vector3i along_first = Eigen::Vector3i::Unit(first);
  const Eigen::Vector3i along_second = Eigen::Vector3i::Unit(second);
  const int a = grid.node(corner);
  const int b = grid.node(corner + along_first);
  const int c = grid.node(corner + along_first + along_second);
  const int d = grid.node(corner + along_second);
  if (triangles) {
    connectivity.insert(connectivity.end(), {a, b, c, a, c, d});
  } else {
    connectivity.insert(connectivity.end(), {a, b, c, d});
  }
}

/// The faces of the box side where axis `normal` is at its low (`high` false) or high end.
std::vector<int> side_faces(const Grid& grid, int normal, bool high, bool triangles) {
  const int first = (normal + 1) % 3;
  const int second = (normal + 2) % 3;
  std::vector<int> connectivity;
  for (int i = 0; i < grid.cells[first]; ++i) {
    for (int j = 0; j < grid.cells[second]; ++j) {
      Eigen::Vector3i corner = Eigen::Vector3i::Zero();
      corner[normal] = high ? grid.cells[normal] : 0;
      corner[first] = i;
      corner[second] = j;
      add_face(grid, corner, first, second, triangles, connectivity);
    }
  }
  return connectivity;
}

/// Adds a midside node on every edge of the linear tetrahedra and triangles (tetrahedron10 and
/// triangle6 in Gmsh order), shared between the elements that have the edge.
void add_midside_nodes(Mesh& mesh) {
  std::map<std::pair<int, int>, int> midpoint;
  const auto midside = [&](int a, int b) {
    const std::pair<int, int> key = std::minmax(a, b);
    const auto [found, inserted] = midpoint.try_emplace(key, static_cast<int>(mesh.nodes.size()));
    if (inserted) {
      mesh.nodes.push_back(0.5 * (mesh.nodes[a] + mesh.nodes[b]));
      mesh.node_tags.push_back(mesh.nodes.size());
    }
    return found->second;
  };
  constexpr int tetrahedron_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
  ElementBlock& block = mesh.blocks.front();
  std::vector<int> quadratic;
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    const int* corners = &block.connectivity[4 * e];
    quadratic.insert(quadratic.end(), corners, corners + 4);
    for (const auto& [a, b] : tetrahedron_edges)
      quadratic.push_back(midside(corners[a], corners[b]));
  }
  block = {ElementType::tetrahedron10, std::move(quadratic), {}};
  for (auto& [name, group] : mesh.boundaries) {
    std::vector<int> faces;
    for (std::size_t f = 0; f < group.facet_count(); ++f) {
      const int* corners = &group.connectivity[3 * f];
      faces.insert(faces.end(), corners, corners + 3);
      for (int a = 0; a < 3; ++a) faces.push_back(midside(corners[a], corners[(a + 1) % 3]));
    }
    group = {FacetType::triangle6, std::move(faces)};
  }
}

}  // namespace

Mesh make_box_mesh(const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                   const Eigen::Vector3i& cells, ElementType type) {
  if (type != ElementType::hexahedron8 && type != ElementType::tetrahedron4 &&
      type != ElementType::tetrahedron10) {
    throw std::invalid_argument("make_box_mesh: not a volume element type");
  }
  if ((cells.array() < 1).any()) throw std::invalid_argument("make_box_mesh: cells must be >= 1");
  const Grid grid{cells};
  Mesh mesh;
  mesh.dimension = 3;
  for (int k = 0; k <= cells.z(); ++k) {
    for (int j = 0; j <= cells.y(); ++j) {
      for (int i = 0; i <= cells.x(); ++i) {
        const Eigen::Vector3d fraction(double(i) / cells.x(), double(j) / cells.y(),
                                       double(k) / cells.z());
        mesh.nodes.push_back(low + fraction.cwiseProduct(high - low));
        mesh.node_tags.push_back(mesh.nodes.size());
      }
    }
  }
  const bool hexahedra = type == ElementType::hexahedron8;
  ElementBlock block{hexahedra ? ElementType::hexahedron8 : ElementType::tetrahedron4, {}, {}};
  const std::vector<std::array<Eigen::Vector3i, 4>> tetrahedra = kuhn_tetrahedra();
  for (int k = 0; k < cells.z(); ++k) {
    for (int j = 0; j < cells.y(); ++j) {
      for (int i = 0; i < cells.x(); ++i) {
        const Eigen::Vector3i corner(i, j, k);
        if (hexahedra) {
          for (const auto& [x, y, z] : {std::array{0, 0, 0},
                                        {1, 0, 0},
                                        {1, 1, 0},
                                        {0, 1, 0},
                                        {0, 0, 1},
                                        {1, 0, 1},
                                        {1, 1, 1},
                                        {0, 1, 1}}) {
            block.connectivity.push_back(grid.node(corner + Eigen::Vector3i(x, y, z)));
          }
          continue;
        }
        for (const auto& path : tetrahedra) {
          std::array<int, 4> nodes;
          for (int a = 0; a < 4; ++a) nodes[a] = grid.node(corner + path[a]);
          if (signed_volume(mesh, nodes.data()) < 0.0) std::swap(nodes[1], nodes[2]);
          block.connectivity.insert(block.connectivity.end(), nodes.begin(), nodes.end());
        }
      }
    }
  }
  mesh.blocks.push_back(std::move(block));
  const FacetType face = hexahedra ? FacetType::quadrilateral4 : FacetType::triangle3;
  const std::pair<const char*, std::pair<int, bool>> sides[] = {
      {"left", {0, false}}, {"right", {0, true}},   {"front", {1, false}},
      {"back", {1, true}},  {"bottom", {2, false}}, {"top", {2, true}}};
  for (const auto& [name, side] : sides) {
    mesh.boundaries[name] = {face, side_faces(grid, side.first, side.second, !hexahedra)};
  }
  if (type == ElementType::tetrahedron10) add_midside_nodes(mesh);
  return mesh;
}

}  // namespace robin
