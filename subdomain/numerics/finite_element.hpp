#pragma once
// Isoparametric shape functions and Gauss rules of the supported elements (areas and volumes)
// and facets (edges and faces).

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

/// Fixed maximum sizes of the per-element arrays, so that the element kernels never touch the
/// heap: the 10-node tetrahedron has the most nodes of the ElementType's (a facet has at most
/// 6), elements have at most 3 dimensions, Voigt vectors at most 6 components (material.hpp).
inline constexpr int max_element_nodes = 10;
inline constexpr int max_dimension = 3;
inline constexpr int max_voigt_size = 6;
inline constexpr int max_element_dofs = max_dimension * max_element_nodes;

/// Shape function values N, one per node of an element or facet.
using ShapeValues = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_element_nodes, 1>;
/// One row per node, one column per coordinate: shape gradients dN/dxi or dN/dx (n x d) and
/// node coordinates (n x d, or n x 3 for a facet's points in space).
using ShapeGradients =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_element_nodes, max_dimension>;
using NodeCoordinates = ShapeGradients;
/// The Jacobian dx/dxi of an element (d x d) or a facet (3 x facet dimension), or its inverse.
using JacobianMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_dimension, max_dimension>;
/// Vectors and matrices over an element's d n degrees of freedom (u_x0, u_y0, [u_z0,] u_x1, ...).
using ElementVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_element_dofs, 1>;
using ElementMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_element_dofs, max_element_dofs>;
/// Voigt vectors (3 components in 2D, 6 in 3D), the Voigt stiffness C and the
/// strain-displacement matrix B (Voigt size x d n).
using VoigtVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_voigt_size, 1>;
using VoigtMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_voigt_size, max_voigt_size>;
using StrainDisplacement =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_voigt_size, max_element_dofs>;

struct QuadraturePoint {
  /// Point in the reference element (unused trailing coordinates zero: one for edges, two or
  /// three for faces and elements).
  Eigen::Vector3d reference;
  double weight;  // weight on the reference element
};

/// Gauss rule exact for polynomials of degree `degree` on the reference element
/// (triangle: (0,0),(1,0),(0,1); quadrilateral: [-1,1]^2; tetrahedron: (0,0,0),(1,0,0),(0,1,0),
/// (0,0,1); hexahedron: [-1,1]^3).
std::vector<QuadraturePoint> element_quadrature(ElementType type, int degree);

/// Shape function values N (n) and reference derivatives dN (n x d, d = element_dimension) at
/// `reference`.
void shape_functions(ElementType type, const Eigen::Vector3d& reference, ShapeValues& values,
                     ShapeGradients& reference_gradients);

/// 1D Gauss rule on [-1, 1] exact to `degree` (the point is reference.x(), the rest zero)
/// and edge shape functions in Gmsh order.
std::vector<QuadraturePoint> edge_quadrature(int degree);
void edge_shape_functions(FacetType type, double reference, ShapeValues& values,
                          ShapeValues& reference_derivatives);

/// Rule exact to `degree` on a facet's reference element: [-1, 1] for an edge, the face's
/// parametrization (face_parametrization) for a face.
std::vector<QuadraturePoint> facet_quadrature(FacetType type, int degree);

/// Facet shape functions N (n) and reference derivatives (n x facet_dimension) at `reference`.
void facet_shape_functions(FacetType type, const Eigen::Vector3d& reference, ShapeValues& values,
                           ShapeGradients& reference_gradients);

/// Shape functions of an element type at one reference point, the same for every element of
/// the type: tabulated once per block and mapped per element by ElementGeometry::evaluate.
struct ReferenceShape {
  Eigen::Vector3d reference;
  double weight = 0.0;  // the quadrature weight (zero for a point that is not from a rule)
  ShapeValues values;
  ShapeGradients gradients;  // dN/dxi (n x d)
};
std::vector<ReferenceShape> tabulate_shapes(ElementType type,
                                            const std::vector<QuadraturePoint>& rule);
std::vector<ReferenceShape> tabulate_shapes(ElementType type,
                                            const std::vector<Eigen::Vector3d>& points);

/// For each of `shapes`, the index of the first one with the same reference gradients dN/dxi:
/// points at which every element of the type has the same Jacobian and physical gradients
/// (on an affine element, the 3-node triangle and the 4-node tetrahedron, all of them).
std::vector<std::size_t> first_with_same_gradients(const std::vector<ReferenceShape>& shapes);

/// det(J) of a 2 x 2 or 3 x 3 Jacobian in closed form; invert_jacobian also sets J^-1
/// (infinite or NaN entries when det(J) = 0) and returns det(J).
double jacobian_determinant(const JacobianMatrix& jacobian);
double invert_jacobian(const JacobianMatrix& jacobian, JacobianMatrix& inverse);

/// Reference coordinates of the nodes of an element of `type`, in node order.
std::vector<Eigen::Vector3d> reference_nodes(ElementType type);

/// Reference coordinates of the centroid of the reference element.
Eigen::Vector3d reference_centroid(ElementType type);

/// Reference coordinates of the nodes of a facet of `type`, in node order ([-1, 1] for edges).
std::vector<Eigen::Vector3d> facet_reference_nodes(FacetType type);

/// Reference coordinate in [-1, 1] of each node of an edge of `type`, in node order.
std::vector<double> edge_reference_nodes(FacetType type);

/// The local node numbers of the corners of each facet of the reference element (Gmsh's side
/// numbering; corners only): the edges of an area element, the faces of a volume element,
/// each ordered so that its right-hand normal points out of the element.
std::vector<std::vector<int>> element_facet_corners(ElementType type);

/// Shape functions of an element at one point, with physical gradients dN/dx (n x d, d the
/// element's dimension), the mapped position x and the Jacobian determinant det(dx/dxi).
struct ElementPoint {
  ShapeValues values;
  ShapeGradients gradients;
  Eigen::Vector3d position;
  double jacobian = 0.0;
};

/// Isoparametric map of one element of a mesh (which must outlive it).
class ElementGeometry {
 public:
  ElementGeometry(const Mesh& mesh, std::size_t block, std::size_t element);
  ElementType type() const { return type_; }
  int node_count() const { return static_cast<int>(coordinates_.rows()); }
  /// Mesh index of local node `local`.
  int node(int local) const { return nodes_[local]; }
  /// Mesh indices of the local nodes, node_count() of them.
  const int* nodes() const { return nodes_; }
  /// Throws InputError naming the element when det(dx/dxi) <= 0 at `reference`.
  ElementPoint evaluate(const Eigen::Vector3d& reference) const;
  /// The same at a tabulated point of this element's type.
  ElementPoint evaluate(const ReferenceShape& shape) const;

 private:
  const Mesh* mesh_;
  ElementType type_;
  const int* nodes_;
  NodeCoordinates coordinates_;  // n x d
};

/// The elements (block, element) that contain each node of one boundary group: what orienting
/// its facets needs, in memory proportional to the group, not to the mesh (compressed rows).
class NodeElementMap {
 public:
  using ElementIndex = std::pair<std::size_t, std::size_t>;
  NodeElementMap(const Mesh& mesh, const BoundaryGroup& group);
  /// The first element that contains every one of `nodes`, if any; nodes.front() must be a node
  /// of the group (std::out_of_range otherwise).
  std::optional<ElementIndex> element_with(const std::vector<int>& nodes) const;

 private:
  const Mesh* mesh_;
  std::vector<int> nodes_;          // the group's nodes, ascending
  std::vector<std::size_t> start_;  // elements of nodes_[k]: elements_[start_[k] ...]
  std::vector<ElementIndex> elements_;
};

/// Facet shape functions at one point, the mapped position, the unit outward normal and the
/// measure element (|dx/dt| for an edge, |dx/dr x dx/ds| for a face).
struct FacetPoint {
  ShapeValues values;
  Eigen::Vector3d position;
  Eigen::Vector3d outward_normal;
  double measure_element = 0.0;
};

/// Isoparametric map of one facet of a boundary group. With a NodeElementMap the normal points
/// out of the element that contains the facet's corner nodes (InputError when there is none);
/// without, it is the facet's own orientation: for an edge the tangent turned clockwise,
/// (t_y, -t_x) / |t| (the body on the left), for a face the right-hand normal
/// dx/dr x dx/ds / |dx/dr x dx/ds|.
class FacetGeometry {
 public:
  FacetGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t facet);
  FacetGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t facet,
                const NodeElementMap& adjacency);
  FacetPoint evaluate(const Eigen::Vector3d& reference) const;
  /// Length of an edge or area of a face (possibly curved).
  double measure() const;

 private:
  FacetType type_;
  NodeCoordinates coordinates_;  // n x 3
  double orientation_ = 1.0;     // +1 or -1: flips the facet's own normal outward
};

}  // namespace robin
