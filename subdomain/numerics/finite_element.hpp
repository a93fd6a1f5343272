#pragma once
// Isoparametric shape functions and Gauss rules for the supported elements.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

struct QuadraturePoint {
  Eigen::Vector2d reference;  // point in the reference element
  double weight;              // weight on the reference element
};

/// Gauss rule exact for polynomials of degree `degree` on the reference element
/// (triangle: (0,0),(1,0),(0,1); quadrilateral: [-1,1]^2).
std::vector<QuadraturePoint> element_quadrature(ElementType type, int degree);

/// Shape function values N (n) and reference derivatives dN (n x 2) at `reference`.
void shape_functions(ElementType type, const Eigen::Vector2d& reference, Eigen::VectorXd& values,
                     Eigen::MatrixXd& reference_gradients);

/// 1D Gauss rule on [-1, 1] exact to `degree` (the point is reference.x(), reference.y() = 0)
/// and edge shape functions in Gmsh order.
std::vector<QuadraturePoint> edge_quadrature(int degree);
void edge_shape_functions(FacetType type, double reference, Eigen::VectorXd& values,
                          Eigen::VectorXd& reference_derivatives);

/// Reference coordinates of the nodes of an element of `type`, in node order.
std::vector<Eigen::Vector2d> reference_nodes(ElementType type);

/// Reference coordinates of the centroid of the reference element.
Eigen::Vector2d reference_centroid(ElementType type);

/// Reference coordinate in [-1, 1] of each node of an edge of `type`, in node order.
std::vector<double> edge_reference_nodes(FacetType type);

/// Shape functions of an element at one point, with physical gradients dN/dx (n x 2),
/// the mapped position x and the Jacobian determinant det(dx/dxi).
struct ElementPoint {
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  Eigen::Vector2d position;
  double jacobian = 0.0;
};

/// Isoparametric map of one area element of a mesh (which must outlive it).
class ElementGeometry {
 public:
  ElementGeometry(const Mesh& mesh, std::size_t block, std::size_t element);
  ElementType type() const { return type_; }
  int node_count() const { return static_cast<int>(coordinates_.rows()); }
  /// Mesh index of local node `local`.
  int node(int local) const { return nodes_[local]; }
  /// Throws InputError naming the element when det(dx/dxi) <= 0 at `reference`.
  ElementPoint evaluate(const Eigen::Vector2d& reference) const;

 private:
  const Mesh* mesh_;
  ElementType type_;
  const int* nodes_;
  Eigen::MatrixX2d coordinates_;  // n x 2 node coordinates
};

/// The area elements (block, element) that contain each node.
class NodeElementMap {
 public:
  using ElementIndex = std::pair<std::size_t, std::size_t>;
  explicit NodeElementMap(const Mesh& mesh);
  const std::vector<ElementIndex>& elements_of(int node) const { return elements_[node]; }
  /// The first area element that contains both nodes, if any.
  std::optional<ElementIndex> element_with(int first_node, int second_node) const;

 private:
  const Mesh* mesh_;
  std::vector<std::vector<ElementIndex>> elements_;
};

/// Edge shape functions at one point, the mapped position, the unit normal and the
/// length element |dx/dt|.
struct EdgePoint {
  Eigen::VectorXd values;
  Eigen::Vector2d position;
  Eigen::Vector2d outward_normal;
  double length_element = 0.0;
};

/// Isoparametric map of one boundary edge. With a NodeElementMap the normal points out of
/// the area element that contains the edge's end nodes (InputError when there is none);
/// without, the normal is the tangent turned clockwise, (t_y, -t_x) / |t|.
class EdgeGeometry {
 public:
  EdgeGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t edge);
  EdgeGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t edge,
               const NodeElementMap& adjacency);
  EdgePoint evaluate(double reference) const;
  /// Length of the (possibly curved) edge.
  double length() const;

 private:
  FacetType type_;
  Eigen::MatrixX2d coordinates_;
  double orientation_ = 1.0;  // +1 or -1: flips the clockwise-turned tangent outward
};

}  // namespace robin
