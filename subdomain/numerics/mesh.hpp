#pragma once
// A 2D finite-element mesh: nodes, area elements in blocks of one type, and
// named boundary groups (Gmsh physical curves) made of line elements.

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace robin {

enum class ElementType {
  triangle3,       // linear triangle (P1)
  triangle6,       // quadratic triangle (P2), Gmsh node order
  quadrilateral4,  // bilinear quadrilateral (Q1), counter-clockwise
};

enum class EdgeType {
  line2,  // linear edge, endpoints
  line3,  // quadratic edge: two endpoints then the midpoint (Gmsh order)
};

int nodes_per_element(ElementType type);
int nodes_per_edge(EdgeType type);
std::string to_string(ElementType type);

/// Elements of one type; connectivity is flat, nodes_per_element(type) entries per element,
/// as zero-based indices into Mesh::nodes.
struct ElementBlock {
  ElementType type = ElementType::triangle3;
  std::vector<int> connectivity;
  /// Each element's tag in the mesh file (for messages); empty when unknown.
  std::vector<std::size_t> tags;
  /// "element tag T" (or "element N of the TYPE block", 1-based, when the tags are unknown).
  std::string element_label(std::size_t element) const;
  std::size_t element_count() const { return connectivity.size() / nodes_per_element(type); }
};

/// A named boundary (a Gmsh physical curve): its line elements.
struct BoundaryGroup {
  EdgeType type = EdgeType::line2;
  std::vector<int> connectivity;  // nodes_per_edge(type) entries per edge
  std::size_t edge_count() const { return connectivity.size() / nodes_per_edge(type); }
  /// Distinct node indices of the group, sorted ascending.
  std::vector<int> nodes() const;
};

struct Mesh {
  std::string source;  // the file the mesh came from, for messages ("" when unknown)
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::size_t> node_tags;  // original (Gmsh) tag of each node, for output
  std::vector<ElementBlock> blocks;
  std::map<std::string, BoundaryGroup> boundaries;

  std::size_t node_count() const { return nodes.size(); }
  std::size_t element_count() const;
  /// The boundary group called `name`; throws InputError listing the known names.
  const BoundaryGroup& boundary(const std::string& name) const;
  /// "'name'" of a group of this mesh (found by address), "(unnamed boundary)" otherwise;
  /// for messages.
  std::string boundary_label(const BoundaryGroup& group) const;
};

}  // namespace robin
