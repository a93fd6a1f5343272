#pragma once
// Isoparametric shape functions and Gauss rules for the supported elements.

#include <Eigen/Core>
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

/// 1D Gauss rule on [-1, 1] exact to `degree` and edge shape functions in Gmsh order.
std::vector<QuadraturePoint> edge_quadrature(int degree);
void edge_shape_functions(EdgeType type, double reference, Eigen::VectorXd& values,
                          Eigen::VectorXd& reference_derivatives);

}  // namespace robin
