#include "mesh_codec.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <optional>

#include "numerics/errors.hpp"
#include "numerics/mesh_validity.hpp"

namespace robin {
namespace {

constexpr std::size_t maximum_name_length = 64;

protocol::CellType to_protocol(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return protocol::TRIANGLE3;
    case ElementType::triangle6:
      return protocol::TRIANGLE6;
    case ElementType::quadrilateral4:
      return protocol::QUADRILATERAL4;
    case ElementType::tetrahedron4:
      return protocol::TETRAHEDRON4;
    case ElementType::tetrahedron10:
      return protocol::TETRAHEDRON10;
    case ElementType::hexahedron8:
      return protocol::HEXAHEDRON8;
  }
  return protocol::CELL_TYPE_UNSPECIFIED;
}

/// The domain cell types of a mesh of `dimension` (2 or 3).
std::optional<ElementType> element_type(protocol::CellType type, unsigned dimension) {
  if (dimension == 2) {
    switch (type) {
      case protocol::TRIANGLE3:
        return ElementType::triangle3;
      case protocol::TRIANGLE6:
        return ElementType::triangle6;
      case protocol::QUADRILATERAL4:
        return ElementType::quadrilateral4;
      default:
        return std::nullopt;
    }
  }
  switch (type) {
    case protocol::TETRAHEDRON4:
      return ElementType::tetrahedron4;
    case protocol::TETRAHEDRON10:
      return ElementType::tetrahedron10;
    case protocol::HEXAHEDRON8:
      return ElementType::hexahedron8;
    default:
      return std::nullopt;
  }
}

/// The boundary cell (facet) types of a mesh of `dimension`: edges in 2D, faces in 3D.
std::optional<FacetType> facet_type(protocol::CellType type, unsigned dimension) {
  if (dimension == 2) {
    if (type == protocol::LINE2) return FacetType::line2;
    if (type == protocol::LINE3) return FacetType::line3;
    return std::nullopt;
  }
  switch (type) {
    case protocol::TRIANGLE3:
      return FacetType::triangle3;
    case protocol::TRIANGLE6:
      return FacetType::triangle6;
    case protocol::QUADRILATERAL4:
      return FacetType::quadrilateral4;
    default:
      return std::nullopt;
  }
}

/// Builds "<context>: SetupBody.mesh.<field> <problem> (mesh '<source>')" errors.
struct MeshErrors {
  std::string context;
  std::string source;
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw InputError(context + ": SetupBody.mesh." + field + " " + problem +
                     (source.empty() ? "" : " (mesh '" + source + "')"));
  }
};

std::string cell_type_name(protocol::CellType type) {
  const std::string& name = protocol::CellType_Name(type);
  return name.empty() ? std::to_string(static_cast<int>(type)) : name;
}

/// Zero-based node indices of a block, checked against the node count.
std::vector<int> decode_connectivity(const protocol::CellBlock& block, int nodes_per_cell,
                                     std::size_t node_count, const MeshErrors& errors,
                                     const std::string& field) {
  const auto& connectivity = block.connectivity();
  if (connectivity.empty() || connectivity.size() % nodes_per_cell != 0) {
    errors.fail(field + ".connectivity", "has " + std::to_string(connectivity.size()) +
                                             " entries, expected a positive " + "multiple of " +
                                             std::to_string(nodes_per_cell) + " (nodes per " +
                                             cell_type_name(block.type()) + ")");
  }
  for (int k = 0; k < connectivity.size(); ++k) {
    if (connectivity[k] >= node_count) {
      errors.fail(field + ".connectivity[" + std::to_string(k) + "]",
                  "= " + std::to_string(connectivity[k]) + " is not a node index (the mesh has " +
                      std::to_string(node_count) + " nodes)");
    }
  }
  return std::vector<int>(connectivity.begin(), connectivity.end());
}

std::vector<std::size_t> decode_cell_tags(const protocol::CellBlock& block, std::size_t cell_count,
                                          const MeshErrors& errors, const std::string& field) {
  if (block.tags_size() != 0 && static_cast<std::size_t>(block.tags_size()) != cell_count) {
    errors.fail(field + ".tags", "has " + std::to_string(block.tags_size()) + " tags for " +
                                     std::to_string(cell_count) +
                                     " cells (give one per cell or none)");
  }
  return std::vector<std::size_t>(block.tags().begin(), block.tags().end());
}

void decode_nodes(const protocol::MeshData& data, const MeshErrors& errors, Mesh& mesh) {
  if (data.dimension() != 2 && data.dimension() != 3) {
    errors.fail("dimension", "is " + std::to_string(data.dimension()) +
                                 ": robin-subdomain solves plane (2) and solid (3) problems");
  }
  const int dimension = static_cast<int>(data.dimension());
  mesh.dimension = dimension;
  const auto& coordinates = data.coordinates();
  if (coordinates.empty() || coordinates.size() % dimension != 0) {
    errors.fail("coordinates", "has " + std::to_string(coordinates.size()) +
                                   " values, expected a positive multiple of " +
                                   std::to_string(dimension) +
                                   (dimension == 2 ? " (x, y per node)" : " (x, y, z per node)"));
  }
  const std::size_t node_count =
      static_cast<std::size_t>(coordinates.size()) / static_cast<std::size_t>(dimension);
  if (data.node_tags_size() != 0 && static_cast<std::size_t>(data.node_tags_size()) != node_count) {
    errors.fail("node_tags", "has " + std::to_string(data.node_tags_size()) + " tags for " +
                                 std::to_string(node_count) + " nodes (give one per node or none)");
  }
  mesh.nodes.resize(node_count);
  mesh.node_tags.resize(node_count);
  for (std::size_t node = 0; node < node_count; ++node) {
    const std::size_t first = static_cast<std::size_t>(dimension) * node;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  // z = 0 in 2D
    for (int component = 0; component < dimension; ++component) {
      point[component] = coordinates[static_cast<int>(first) + component];
    }
    if (!point.allFinite()) {
      errors.fail("coordinates[" + std::to_string(first) + "]",
                  "(node " + std::to_string(node) + ") is not a finite number");
    }
    mesh.nodes[node] = point;
    mesh.node_tags[node] =
        data.node_tags_size() == 0 ? node + 1 : data.node_tags(static_cast<int>(node));
  }
}

void decode_cells(const protocol::MeshData& data, const MeshErrors& errors, Mesh& mesh) {
  if (data.cells_size() == 0) errors.fail("cells", "is empty: the mesh has no elements");
  for (int b = 0; b < data.cells_size(); ++b) {
    const protocol::CellBlock& block = data.cells(b);
    const std::string field = "cells[" + std::to_string(b) + "]";
    const std::optional<ElementType> type = element_type(block.type(), data.dimension());
    if (!type) {
      errors.fail(
          field + ".type",
          "is " + cell_type_name(block.type()) +
              (data.dimension() == 2
                   ? ": expected TRIANGLE3, TRIANGLE6 or QUADRILATERAL4"
                   : ": expected TETRAHEDRON4, TETRAHEDRON10 or HEXAHEDRON8 (dimension 3)"));
    }
    ElementBlock decoded;
    decoded.type = *type;
    decoded.connectivity =
        decode_connectivity(block, nodes_per_element(*type), mesh.node_count(), errors, field);
    decoded.tags = decode_cell_tags(block, decoded.element_count(), errors, field);
    mesh.blocks.push_back(std::move(decoded));
  }
}

void check_boundary_name(const std::string& name, const MeshErrors& errors,
                         const std::string& field) {
  const bool valid = !name.empty() && name.size() <= maximum_name_length &&
                     std::all_of(name.begin(), name.end(), [](unsigned char c) {
                       return std::isalnum(c) != 0 || c == '_' || c == '-' || c == '.';
                     });
  if (!valid) {
    errors.fail(field, "is not a boundary name (1 to 64 of the characters A-Z a-z 0-9 _ . -)");
  }
}

void decode_boundaries(const protocol::MeshData& data, const MeshErrors& errors, Mesh& mesh) {
  for (int g = 0; g < data.boundaries_size(); ++g) {
    const protocol::NamedBoundary& boundary = data.boundaries(g);
    const std::string field = "boundaries[" + std::to_string(g) + "]";
    check_boundary_name(boundary.name(), errors, field + ".name");
    if (mesh.boundaries.count(boundary.name()) != 0) {
      errors.fail(field + ".name", "'" + boundary.name() + "' names two boundaries");
    }
    const std::optional<FacetType> type = facet_type(boundary.segments().type(), data.dimension());
    if (!type) {
      errors.fail(field + ".segments.type",
                  "is " + cell_type_name(boundary.segments().type()) +
                      (data.dimension() == 2
                           ? ": expected LINE2 or LINE3"
                           : ": expected TRIANGLE3, TRIANGLE6 or QUADRILATERAL4 (dimension 3)"));
    }
    mesh.boundaries[boundary.name()] =
        BoundaryGroup{*type, decode_connectivity(boundary.segments(), nodes_per_facet(*type),
                                                 mesh.node_count(), errors, field + ".segments")};
  }
}

/// Every node must belong to an element: a free node would make the stiffness singular.
void check_nodes_used(const Mesh& mesh, const MeshErrors& errors) {
  std::vector<bool> used(mesh.node_count(), false);
  for (const ElementBlock& block : mesh.blocks) {
    for (int node : block.connectivity) used[node] = true;
  }
  const auto unused = std::find(used.begin(), used.end(), false);
  if (unused != used.end()) {
    const std::size_t node = static_cast<std::size_t>(unused - used.begin());
    errors.fail("cells", "use no element at node " + std::to_string(node) + " (tag " +
                             std::to_string(mesh.node_tags[node]) +
                             "): send only the nodes of the elements");
  }
}

}  // namespace

protocol::CellType to_protocol(FacetType type) {
  switch (type) {
    case FacetType::line2:
      return protocol::LINE2;
    case FacetType::line3:
      return protocol::LINE3;
    case FacetType::triangle3:
      return protocol::TRIANGLE3;
    case FacetType::triangle6:
      return protocol::TRIANGLE6;
    case FacetType::quadrilateral4:
      return protocol::QUADRILATERAL4;
  }
  return protocol::CELL_TYPE_UNSPECIFIED;
}

protocol::MeshData encode_mesh(const Mesh& mesh) {
  protocol::MeshData data;
  data.set_dimension(static_cast<std::uint32_t>(mesh.dimension));
  data.mutable_coordinates()->Reserve(mesh.dof_count());
  for (const Eigen::Vector3d& node : mesh.nodes) {
    for (int component = 0; component < mesh.dimension; ++component) {
      data.add_coordinates(node[component]);
    }
  }
  data.mutable_node_tags()->Assign(mesh.node_tags.begin(), mesh.node_tags.end());
  for (const ElementBlock& block : mesh.blocks) {
    protocol::CellBlock& cells = *data.add_cells();
    cells.set_type(to_protocol(block.type));
    cells.mutable_connectivity()->Assign(block.connectivity.begin(), block.connectivity.end());
    cells.mutable_tags()->Assign(block.tags.begin(), block.tags.end());
  }
  for (const auto& [name, group] : mesh.boundaries) {
    protocol::NamedBoundary& boundary = *data.add_boundaries();
    boundary.set_name(name);
    boundary.mutable_segments()->set_type(to_protocol(group.type));
    boundary.mutable_segments()->mutable_connectivity()->Assign(group.connectivity.begin(),
                                                                group.connectivity.end());
  }
  data.set_source(mesh.source);
  return data;
}

Mesh decode_mesh(const protocol::MeshData& data, const std::string& context) {
  const MeshErrors errors{context, data.source().substr(0, 256)};
  Mesh mesh;
  mesh.source = errors.source;
  decode_nodes(data, errors, mesh);
  decode_cells(data, errors, mesh);
  decode_boundaries(data, errors, mesh);
  check_nodes_used(mesh, errors);
  check_element_validity(mesh, context + ": SetupBody.mesh");
  return mesh;
}

}  // namespace robin
