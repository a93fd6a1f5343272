#include "numerics/mesh_validity.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"

namespace robin {
namespace {

/// The points at which the Jacobian is checked: the element's nodes and its quadrature points.
std::vector<Eigen::Vector3d> check_points(ElementType type) {
  std::vector<Eigen::Vector3d> points = reference_nodes(type);
  for (const QuadraturePoint& point : element_quadrature(type, 4)) {
    points.push_back(point.reference);
  }
  return points;
}

/// The longest distance between two nodes of the element to the power d (its dimension).
double size_power(const Eigen::MatrixXd& coordinates) {
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
         << " is not above 1e-12 times its " << (solid ? "cubed" : "squared") << " size "
         << extent;
  }
  if (!mesh.source.empty()) text << "; mesh '" << mesh.source << "'";
  throw InputError(text.str());
}

}  // namespace

void check_element_validity(const Mesh& mesh, const std::string& context) {
  for (const ElementBlock& block : mesh.blocks) {
    const int count = nodes_per_element(block.type);
    const int dimension = element_dimension(block.type);
    if (dimension != mesh.dimension) {
      throw InputError(context + ": a " + std::to_string(mesh.dimension) + "D mesh has a block of " +
                       to_string(block.type) + " elements (" + std::to_string(dimension) + "D)" +
                       (mesh.source.empty() ? std::string() : "; mesh '" + mesh.source + "'"));
    }
    const std::vector<Eigen::Vector3d> points = check_points(block.type);
    Eigen::VectorXd values;
    Eigen::MatrixXd reference_gradients;
    std::vector<Eigen::MatrixXd> gradients_at_points;
    for (const Eigen::Vector3d& point : points) {
      shape_functions(block.type, point, values, reference_gradients);
      gradients_at_points.push_back(reference_gradients);
    }
    Eigen::MatrixXd coordinates(count, dimension);
    for (std::size_t element = 0; element < block.element_count(); ++element) {
      for (int i = 0; i < count; ++i) {
        coordinates.row(i) =
            mesh.nodes[block.connectivity[element * count + i]].head(dimension).transpose();
      }
      const double extent = size_power(coordinates);
      for (const Eigen::MatrixXd& gradients : gradients_at_points) {
        const double jacobian = (coordinates.transpose() * gradients).determinant();
        if (!(jacobian > 1e-12 * extent)) refuse(mesh, block, element, jacobian, extent, context);
      }
    }
  }
}

}  // namespace robin
