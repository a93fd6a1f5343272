#pragma once
// A finite-element mesh of a body in two or three dimensions: nodes, elements of the body's
// dimension (areas in 2D, volumes in 3D) in blocks of one type, and named boundary groups
// (Gmsh physical curves in 2D, physical surfaces in 3D) made of facets, the elements of one
// dimension less: edges in 2D, faces in 3D.

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
  tetrahedron4,    // linear tetrahedron (P1), Gmsh node order
  tetrahedron10,   // quadratic tetrahedron (P2), Gmsh node order
  hexahedron8,     // trilinear hexahedron (Q1), Gmsh node order
};

/// The boundary elements: edges of 2D bodies, faces of 3D bodies.
enum class FacetType {
  line2,           // linear edge, endpoints
  line3,           // quadratic edge: two endpoints then the midpoint (Gmsh order)
  triangle3,       // linear triangular face
  triangle6,       // quadratic triangular face, Gmsh node order
  quadrilateral4,  // bilinear quadrilateral face
};

int nodes_per_element(ElementType type);
int nodes_per_facet(FacetType type);
/// The corner (vertex) count: the first nodes of every element and facet are its corners,
/// midside nodes follow (3 for triangles, 4 for quadrilaterals and tetrahedra, 8 for
/// hexahedra; 2 for edges).
int element_corner_count(ElementType type);
int facet_corner_count(FacetType type);
/// 2 for the area elements, 3 for the volume elements.
int element_dimension(ElementType type);
/// 1 for edges, 2 for faces.
int facet_dimension(FacetType type);
/// The element type whose reference element and shape functions a face uses (a triangle3 face
/// is parametrized like a triangle3 element); InputError-free: throws std::invalid_argument
/// for an edge type.
ElementType face_parametrization(FacetType type);
std::string to_string(ElementType type);
std::string to_string(FacetType type);

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

/// A named boundary (a Gmsh physical curve in 2D, a physical surface in 3D): its facets.
struct BoundaryGroup {
  FacetType type = FacetType::line2;
  std::vector<int> connectivity;  // nodes_per_facet(type) entries per facet
  std::size_t facet_count() const { return connectivity.size() / nodes_per_facet(type); }
  /// Distinct node indices of the group, sorted ascending.
  std::vector<int> nodes() const;
};

struct Mesh {
  std::string source;  // the file the mesh came from, for messages ("" when unknown)
  /// 2: a plane body (area elements, edges as facets, every node at z = 0); 3: a solid body
  /// (volume elements, faces as facets). Degree of freedom `dimension * node + component`.
  int dimension = 2;
  /// Node positions; the z coordinate is zero in two dimensions.
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::size_t> node_tags;  // original (Gmsh) tag of each node, for output
  std::vector<ElementBlock> blocks;
  std::map<std::string, BoundaryGroup> boundaries;

  std::size_t node_count() const { return nodes.size(); }
  /// dimension * node_count(): the body's displacement components.
  int dof_count() const { return dimension * static_cast<int>(nodes.size()); }
  std::size_t element_count() const;
  /// The boundary group called `name`; throws InputError listing the known names.
  const BoundaryGroup& boundary(const std::string& name) const;
  /// "'name'" of a group of this mesh (found by address), "(unnamed boundary)" otherwise;
  /// for messages.
  std::string boundary_label(const BoundaryGroup& group) const;
};

}  // namespace robin
