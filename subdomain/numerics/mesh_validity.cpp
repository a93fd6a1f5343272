#include "numerics/mesh_validity.hpp"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"

namespace robin {
namespace {

/// The reference gradients dN/dxi at which the Jacobian is checked: at the element's nodes and
/// its quadrature points, each distinct gradient once (the same gradients give the same
/// Jacobian: one check for an affine element), in the order of their first point.
std::vector<ShapeGradients> check_gradients(ElementType type) {
  std::vector<Eigen::Vector3d> points = reference_nodes(type);
  for (const QuadraturePoint& point : element_quadrature(type, 4)) {
    points.push_back(point.reference);
  }
  const std::vector<ReferenceShape> shapes = tabulate_shapes(type, points);
  const std::vector<std::size_t> same = first_with_same_gradients(shapes);
  std::vector<ShapeGradients> gradients;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    if (same[k] == k) gradients.push_back(shapes[k].gradients);
  }
  return gradients;
}

/// The longest distance between two nodes of the element to the power d (its dimension).
double size_power(const NodeCoordinates& coordinates) {
  double extent = 0.0;
  for (Eigen::Index i = 0; i < coordinates.rows(); ++i) {
    for (Eigen::Index j = i + 1; j < coordinates.rows(); ++j) {
      extent = std::max(extent, (coordinates.row(i) - coordinates.row(j)).norm());
    }
  }
  return std::pow(extent, static_cast<double>(coordinates.cols()));
}

[[noreturn]] void refuse(const Mesh& mesh, const ElementBlock& block, std::size_t element,
                         double jacobian, double extent, const std::string& context) {
  const int count = nodes_per_element(block.type);
  std::ostringstream text;
  text << context << ": " << block.element_label(element) << " (" << to_string(block.type)
       << " at node tags";
  for (int i = 0; i < count; ++i) {
    text << (i == 0 ? " " : ", ") << mesh.node_tags[block.connectivity[element * count + i]];
  }
  text << ")";
  const bool solid = element_dimension(block.type) == 3;
  if (jacobian < 0.0) {
    text << " is inverted or folded: its Jacobian determinant is " << jacobian
         << (solid ? " (its nodes must be in Gmsh's order with a positive volume"
                   : " (its nodes must be counter-clockwise")
         << " and the element must not overlap itself)";
  } else {
    text << " is degenerate: its Jacobian determinant " << jacobian
         << " is not above 1e-12 times its " << (solid ? "cubed" : "squared") << " size " << extent;
  }
  if (!mesh.source.empty()) text << "; mesh '" << mesh.source << "'";
  throw InputError(text.str());
}

/// The checks of check_element_validity on a block of affine simplices (3-node triangles in 2D,
/// 4-node tetrahedra in 3D), in fixed size: J = [x_1 - x_0, ..., x_d - x_0] at every point.
template <int Dimension>
void check_affine_block(const Mesh& mesh, const ElementBlock& block, const std::string& context) {
  constexpr int count = Dimension + 1;
  for (std::size_t element = 0; element < block.element_count(); ++element) {
    const int* nodes = &block.connectivity[element * count];
    Eigen::Matrix<double, Dimension, count> corners;
    for (int i = 0; i < count; ++i) {
      corners.col(i) = mesh.nodes[nodes[i]].template head<Dimension>();
    }
    Eigen::Matrix<double, Dimension, Dimension> jacobian;
    for (int j = 0; j < Dimension; ++j) jacobian.col(j) = corners.col(j + 1) - corners.col(0);
    double longest = 0.0;  // the longest corner distance, squared
    for (int i = 0; i < count; ++i) {
      for (int j = i + 1; j < count; ++j) {
        longest = std::max(longest, (corners.col(i) - corners.col(j)).squaredNorm());
      }
    }
    const double extent = Dimension == 2 ? longest : longest * std::sqrt(longest);
    const double determinant = jacobian.determinant();
    if (!(determinant > 1e-12 * extent)) refuse(mesh, block, element, determinant, extent, context);
  }
}

}  // namespace

void check_element_validity(const Mesh& mesh, const std::string& context) {
  for (const ElementBlock& block : mesh.blocks) {
    const int count = nodes_per_element(block.type);
    const int dimension = element_dimension(block.type);
    if (dimension != mesh.dimension) {
      throw InputError(context + ": a " + std::to_string(mesh.dimension) +
                       "D mesh has a block of " + to_string(block.type) + " elements (" +
                       std::to_string(dimension) + "D)" +
                       (mesh.source.empty() ? std::string() : "; mesh '" + mesh.source + "'"));
    }
    if (block.type == ElementType::triangle3) {
      check_affine_block<2>(mesh, block, context);
      continue;
    }
    if (block.type == ElementType::tetrahedron4) {
      check_affine_block<3>(mesh, block, context);
      continue;
    }
    const std::vector<ShapeGradients> gradients_at_points = check_gradients(block.type);
    NodeCoordinates coordinates(count, dimension);
    for (std::size_t element = 0; element < block.element_count(); ++element) {
      for (int i = 0; i < count; ++i) {
        coordinates.row(i) =
            mesh.nodes[block.connectivity[element * count + i]].head(dimension).transpose();
      }
      const double extent = size_power(coordinates);
      for (const ShapeGradients& gradients : gradients_at_points) {
        const double jacobian =
            jacobian_determinant(JacobianMatrix(coordinates.transpose() * gradients));
        if (!(jacobian > 1e-12 * extent)) refuse(mesh, block, element, jacobian, extent, context);
      }
    }
  }
}

}  // namespace robin
