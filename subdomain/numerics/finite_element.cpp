#include "numerics/finite_element.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "numerics/errors.hpp"

namespace robin {

namespace {

/// n-point Gauss-Legendre rule on [-1, 1] (exact to degree 2n - 1): the points are the
/// roots of the Legendre polynomial P_n, found by Newton's method from Chebyshev guesses;
/// w_i = 2 / ((1 - x_i^2) P_n'(x_i)^2).
std::vector<QuadraturePoint> gauss_legendre(int point_count) {
  std::vector<QuadraturePoint> rule(point_count);
  for (int i = 0; i < point_count; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (point_count + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      // Three-term recurrence: k P_k = (2k - 1) x P_{k-1} - (k - 1) P_{k-2}.
      double current = 1.0;
      double previous = 0.0;
      for (int k = 1; k <= point_count; ++k) {
        const double older = previous;
        previous = current;
        current = ((2.0 * k - 1.0) * x * previous - (k - 1.0) * older) / k;
      }
      derivative = point_count * (x * current - previous) / (x * x - 1.0);
      const double step = current / derivative;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    rule[i] = {Eigen::Vector2d(x, 0.0), 2.0 / ((1.0 - x * x) * derivative * derivative)};
  }
  return rule;
}

void add_triangle_orbit(std::vector<QuadraturePoint>& rule, double a, double weight) {
  // Orbit of (a, a, 1 - 2a) in barycentric coordinates.
  rule.push_back({Eigen::Vector2d(a, a), weight});
  rule.push_back({Eigen::Vector2d(1.0 - 2.0 * a, a), weight});
  rule.push_back({Eigen::Vector2d(a, 1.0 - 2.0 * a), weight});
}

void add_triangle_orbit(std::vector<QuadraturePoint>& rule, double a, double b, double weight) {
  // Orbit of (a, b, 1 - a - b) in barycentric coordinates: its 6 permutations.
  const double c = 1.0 - a - b;
  for (const auto& [r, s] : {std::pair{a, b}, {b, a}, {b, c}, {c, b}, {a, c}, {c, a}}) {
    rule.push_back({Eigen::Vector2d(r, s), weight});
  }
}

/// Collapsed (Duffy) Gauss rule on the triangle for any degree: x = u (1 - v), y = v on the
/// unit square, Jacobian 1 - v; a degree-p polynomial becomes degree p in u and p + 1 in v.
std::vector<QuadraturePoint> collapsed_triangle_rule(int degree) {
  const std::vector<QuadraturePoint> line = gauss_legendre(degree / 2 + 2);
  std::vector<QuadraturePoint> rule;
  for (const QuadraturePoint& along_u : line) {
    for (const QuadraturePoint& along_v : line) {
      const double u = 0.5 * (along_u.reference.x() + 1.0);
      const double v = 0.5 * (along_v.reference.x() + 1.0);
      const double weight = 0.25 * along_u.weight * along_v.weight * (1.0 - v);
      rule.push_back({Eigen::Vector2d(u * (1.0 - v), v), weight});
    }
  }
  return rule;
}

/// Symmetric rules with positive weights (Strang-Fix degree 3, Dunavant degrees 4-6);
/// the weights sum to the reference area 1/2.
std::vector<QuadraturePoint> triangle_quadrature(int degree) {
  std::vector<QuadraturePoint> rule;
  if (degree <= 1) {
    rule.push_back({Eigen::Vector2d(1.0 / 3.0, 1.0 / 3.0), 0.5});
  } else if (degree == 2) {
    add_triangle_orbit(rule, 1.0 / 6.0, 1.0 / 6.0);
  } else if (degree == 3) {
    add_triangle_orbit(rule, 0.659027622374092, 0.231933368553031, 1.0 / 12.0);
  } else if (degree == 4) {
    add_triangle_orbit(rule, 0.4459484909159648, 0.11169079483900567);
    add_triangle_orbit(rule, 0.09157621350977078, 0.054975871827661);
  } else if (degree == 5) {
    const double root = std::sqrt(15.0);
    rule.push_back({Eigen::Vector2d(1.0 / 3.0, 1.0 / 3.0), 9.0 / 80.0});
    add_triangle_orbit(rule, (6.0 + root) / 21.0, (155.0 + root) / 2400.0);
    add_triangle_orbit(rule, (6.0 - root) / 21.0, (155.0 - root) / 2400.0);
  } else if (degree == 6) {
    add_triangle_orbit(rule, 0.24928674517087898, 0.058393137863215934);
    add_triangle_orbit(rule, 0.06308901449150855, 0.02542245318510794);
    add_triangle_orbit(rule, 0.053145049844795136, 0.31035245103380815, 0.041425537809171395);
  } else {
    rule = collapsed_triangle_rule(degree);
  }
  return rule;
}

std::vector<QuadraturePoint> quadrilateral_quadrature(int degree) {
  const std::vector<QuadraturePoint> line = gauss_legendre(degree / 2 + 1);
  std::vector<QuadraturePoint> rule;
  for (const QuadraturePoint& along_eta : line) {
    for (const QuadraturePoint& along_xi : line) {
      rule.push_back({Eigen::Vector2d(along_xi.reference.x(), along_eta.reference.x()),
                      along_xi.weight * along_eta.weight});
    }
  }
  return rule;
}

void check_degree(int degree) {
  if (degree < 0) throw std::invalid_argument("quadrature degree must be >= 0");
}

}  // namespace

std::vector<QuadraturePoint> element_quadrature(ElementType type, int degree) {
  check_degree(degree);
  if (type == ElementType::quadrilateral4) return quadrilateral_quadrature(degree);
  return triangle_quadrature(degree);
}

std::vector<QuadraturePoint> edge_quadrature(int degree) {
  check_degree(degree);
  return gauss_legendre(degree / 2 + 1);
}

void shape_functions(ElementType type, const Eigen::Vector2d& reference, Eigen::VectorXd& values,
                     Eigen::MatrixXd& reference_gradients) {
  const double r = reference.x();
  const double s = reference.y();
  switch (type) {
    case ElementType::triangle3:
      values.resize(3);
      reference_gradients.resize(3, 2);
      values << 1.0 - r - s, r, s;
      reference_gradients << -1.0, -1.0, 1.0, 0.0, 0.0, 1.0;
      return;
    case ElementType::triangle6: {
      // Barycentric l0 = 1 - r - s, l1 = r, l2 = s; corners l_i (2 l_i - 1), midpoints of
      // edges 01, 12, 20: 4 l0 l1, 4 l1 l2, 4 l2 l0.
      const double l0 = 1.0 - r - s;
      values.resize(6);
      reference_gradients.resize(6, 2);
      values << l0 * (2.0 * l0 - 1.0), r * (2.0 * r - 1.0), s * (2.0 * s - 1.0), 4.0 * l0 * r,
          4.0 * r * s, 4.0 * s * l0;
      reference_gradients << 1.0 - 4.0 * l0, 1.0 - 4.0 * l0,  //
          4.0 * r - 1.0, 0.0,                                 //
          0.0, 4.0 * s - 1.0,                                 //
          4.0 * (l0 - r), -4.0 * r,                           //
          4.0 * s, 4.0 * r,                                   //
          -4.0 * s, 4.0 * (l0 - s);
      return;
    }
    case ElementType::quadrilateral4: {
      // N_i = (1 + xi_i xi)(1 + eta_i eta) / 4 with corners (-1,-1), (1,-1), (1,1), (-1,1).
      values.resize(4);
      reference_gradients.resize(4, 2);
      const std::vector<Eigen::Vector2d> corners = reference_nodes(type);
      for (int i = 0; i < 4; ++i) {
        const double along_xi = 1.0 + corners[i].x() * r;
        const double along_eta = 1.0 + corners[i].y() * s;
        values(i) = 0.25 * along_xi * along_eta;
        reference_gradients(i, 0) = 0.25 * corners[i].x() * along_eta;
        reference_gradients(i, 1) = 0.25 * corners[i].y() * along_xi;
      }
      return;
    }
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
    case ElementType::hexahedron8:
      break;
  }
  throw std::invalid_argument("shape_functions: unknown element type");
}

void edge_shape_functions(FacetType type, double reference, Eigen::VectorXd& values,
                          Eigen::VectorXd& reference_derivatives) {
  const double t = reference;
  if (type == FacetType::line2) {
    values.resize(2);
    reference_derivatives.resize(2);
    values << 0.5 * (1.0 - t), 0.5 * (1.0 + t);
    reference_derivatives << -0.5, 0.5;
    return;
  }
  // line3: endpoints t = -1, 1 then the midpoint t = 0.
  values.resize(3);
  reference_derivatives.resize(3);
  values << 0.5 * t * (t - 1.0), 0.5 * t * (t + 1.0), 1.0 - t * t;
  reference_derivatives << t - 0.5, t + 0.5, -2.0 * t;
}

std::vector<Eigen::Vector2d> reference_nodes(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
    case ElementType::triangle6:
      return {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {0.5, 0.0}, {0.5, 0.5}, {0.0, 0.5}};
    case ElementType::quadrilateral4:
      return {{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}};
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
    case ElementType::hexahedron8:
      break;
  }
  throw std::invalid_argument("reference_nodes: unknown element type");
}

Eigen::Vector2d reference_centroid(ElementType type) {
  if (type == ElementType::quadrilateral4) return Eigen::Vector2d::Zero();
  return Eigen::Vector2d(1.0 / 3.0, 1.0 / 3.0);
}

std::vector<double> edge_reference_nodes(FacetType type) {
  if (type == FacetType::line2) return {-1.0, 1.0};
  return {-1.0, 1.0, 0.0};
}

namespace {

std::string describe_element(const Mesh& mesh, ElementType type, const int* nodes) {
  std::ostringstream text;
  text << "mesh element " << to_string(type) << " with node tags (";
  for (int i = 0; i < nodes_per_element(type); ++i) {
    text << (i == 0 ? "" : ", ") << mesh.node_tags[nodes[i]];
  }
  text << ")";
  return text.str();
}

}  // namespace

ElementGeometry::ElementGeometry(const Mesh& mesh, std::size_t block, std::size_t element)
    : mesh_(&mesh), type_(mesh.blocks[block].type) {
  const int count = nodes_per_element(type_);
  nodes_ = &mesh.blocks[block].connectivity[element * count];
  coordinates_.resize(count, 2);
  for (int i = 0; i < count; ++i) coordinates_.row(i) = mesh.nodes[nodes_[i]].transpose();
}

ElementPoint ElementGeometry::evaluate(const Eigen::Vector2d& reference) const {
  ElementPoint point;
  Eigen::MatrixXd reference_gradients;
  shape_functions(type_, reference, point.values, reference_gradients);
  // J_ij = dx_i / dxi_j = sum_k x_k,i dN_k / dxi_j
  const Eigen::Matrix2d jacobian = coordinates_.transpose() * reference_gradients;
  point.jacobian = jacobian.determinant();
  if (!(point.jacobian > 0.0)) {
    std::ostringstream text;
    text << describe_element(*mesh_, type_, nodes_) << " has a non-positive Jacobian "
         << point.jacobian << " at reference point (" << reference.x() << ", " << reference.y()
         << "): the element is degenerate or tangled; fix the mesh";
    throw InputError(text.str());
  }
  // dN/dx = dN/dxi J^-1
  point.gradients = reference_gradients * jacobian.inverse();
  point.position = coordinates_.transpose() * point.values;
  return point;
}

NodeElementMap::NodeElementMap(const Mesh& mesh) : mesh_(&mesh), elements_(mesh.node_count()) {
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const int count = nodes_per_element(block.type);
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      for (int i = 0; i < count; ++i)
        elements_[block.connectivity[e * count + i]].emplace_back(b, e);
    }
  }
}

std::optional<NodeElementMap::ElementIndex> NodeElementMap::element_with(int first_node,
                                                                         int second_node) const {
  for (const ElementIndex& candidate : elements_[first_node]) {
    const ElementBlock& block = mesh_->blocks[candidate.first];
    const int count = nodes_per_element(block.type);
    const auto begin = block.connectivity.begin() + candidate.second * count;
    if (std::find(begin, begin + count, second_node) != begin + count) return candidate;
  }
  return std::nullopt;
}

EdgeGeometry::EdgeGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t edge)
    : type_(group.type) {
  const int count = nodes_per_facet(type_);
  coordinates_.resize(count, 2);
  for (int i = 0; i < count; ++i) {
    coordinates_.row(i) = mesh.nodes[group.connectivity[edge * count + i]].transpose();
  }
  if (coordinates_.row(0) == coordinates_.row(1)) {
    throw InputError("boundary " + mesh.boundary_label(group) + ": an edge at node tag " +
                     std::to_string(mesh.node_tags[group.connectivity[edge * count]]) +
                     " has zero length; fix the mesh");
  }
}

EdgeGeometry::EdgeGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t edge,
                           const NodeElementMap& adjacency)
    : EdgeGeometry(mesh, group, edge) {
  const int count = nodes_per_facet(type_);
  const int first = group.connectivity[edge * count];
  const int second = group.connectivity[edge * count + 1];
  const std::optional<NodeElementMap::ElementIndex> element = adjacency.element_with(first, second);
  if (!element) {
    throw InputError("boundary " + mesh.boundary_label(group) + ": the edge from node tag " +
                     std::to_string(mesh.node_tags[first]) + " to node tag " +
                     std::to_string(mesh.node_tags[second]) +
                     " is not a side of any area element, so it has no outward normal");
  }
  // Outward: the chord's clockwise-turned tangent points away from the element's centroid.
  const ElementBlock& block = mesh.blocks[element->first];
  const int corner_count = block.type == ElementType::quadrilateral4 ? 4 : 3;
  const int* nodes = &block.connectivity[element->second * nodes_per_element(block.type)];
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i = 0; i < corner_count; ++i) centroid += mesh.nodes[nodes[i]] / corner_count;
  const Eigen::Vector2d chord = mesh.nodes[second] - mesh.nodes[first];
  const Eigen::Vector2d middle = 0.5 * (mesh.nodes[first] + mesh.nodes[second]);
  orientation_ = Eigen::Vector2d(chord.y(), -chord.x()).dot(middle - centroid) >= 0.0 ? 1.0 : -1.0;
}

EdgePoint EdgeGeometry::evaluate(double reference) const {
  EdgePoint point;
  Eigen::VectorXd derivatives;
  edge_shape_functions(type_, reference, point.values, derivatives);
  point.position = coordinates_.transpose() * point.values;
  // t = dx/dt; outward normal = orientation (t_y, -t_x) / |t|
  const Eigen::Vector2d tangent = coordinates_.transpose() * derivatives;
  point.length_element = tangent.norm();
  point.outward_normal =
      orientation_ * Eigen::Vector2d(tangent.y(), -tangent.x()) / point.length_element;
  return point;
}

double EdgeGeometry::length() const {
  double length = 0.0;
  for (const QuadraturePoint& point : edge_quadrature(6)) {
    length += evaluate(point.reference.x()).length_element * point.weight;
  }
  return length;
}

}  // namespace robin
