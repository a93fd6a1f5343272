#include "numerics/finite_element.hpp"

#include <Eigen/Geometry>
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
    rule[i] = {Eigen::Vector3d(x, 0.0, 0.0), 2.0 / ((1.0 - x * x) * derivative * derivative)};
  }
  return rule;
}

void add_triangle_orbit(std::vector<QuadraturePoint>& rule, double a, double weight) {
  // Orbit of (a, a, 1 - 2a) in barycentric coordinates.
  rule.push_back({Eigen::Vector3d(a, a, 0.0), weight});
  rule.push_back({Eigen::Vector3d(1.0 - 2.0 * a, a, 0.0), weight});
  rule.push_back({Eigen::Vector3d(a, 1.0 - 2.0 * a, 0.0), weight});
}

void add_triangle_orbit(std::vector<QuadraturePoint>& rule, double a, double b, double weight) {
  // Orbit of (a, b, 1 - a - b) in barycentric coordinates: its 6 permutations.
  const double c = 1.0 - a - b;
  for (const auto& [r, s] : {std::pair{a, b}, {b, a}, {b, c}, {c, b}, {a, c}, {c, a}}) {
    rule.push_back({Eigen::Vector3d(r, s, 0.0), weight});
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
      rule.push_back({Eigen::Vector3d(u * (1.0 - v), v, 0.0), weight});
    }
  }
  return rule;
}

/// Symmetric rules with positive weights (Strang-Fix degree 3, Dunavant degrees 4-6);
/// the weights sum to the reference area 1/2.
std::vector<QuadraturePoint> triangle_quadrature(int degree) {
  std::vector<QuadraturePoint> rule;
  if (degree <= 1) {
    rule.push_back({Eigen::Vector3d(1.0 / 3.0, 1.0 / 3.0, 0.0), 0.5});
  } else if (degree == 2) {
    add_triangle_orbit(rule, 1.0 / 6.0, 1.0 / 6.0);
  } else if (degree == 3) {
    add_triangle_orbit(rule, 0.659027622374092, 0.231933368553031, 1.0 / 12.0);
  } else if (degree == 4) {
    add_triangle_orbit(rule, 0.4459484909159648, 0.11169079483900567);
    add_triangle_orbit(rule, 0.09157621350977078, 0.054975871827661);
  } else if (degree == 5) {
    const double root = std::sqrt(15.0);
    rule.push_back({Eigen::Vector3d(1.0 / 3.0, 1.0 / 3.0, 0.0), 9.0 / 80.0});
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
      rule.push_back({Eigen::Vector3d(along_xi.reference.x(), along_eta.reference.x(), 0.0),
                      along_xi.weight * along_eta.weight});
    }
  }
  return rule;
}

/// Collapsed (Stroud conical) Gauss rule on the tetrahedron for any degree: x = u (1 - v)(1 - w),
/// y = v (1 - w), z = w on the unit cube, Jacobian (1 - v)(1 - w)^2; positive weights.
std::vector<QuadraturePoint> collapsed_tetrahedron_rule(int degree) {
  const std::vector<QuadraturePoint> line = gauss_legendre(degree / 2 + 2);
  std::vector<QuadraturePoint> rule;
  for (const QuadraturePoint& along_u : line) {
    for (const QuadraturePoint& along_v : line) {
      for (const QuadraturePoint& along_w : line) {
        const double u = 0.5 * (along_u.reference.x() + 1.0);
        const double v = 0.5 * (along_v.reference.x() + 1.0);
        const double w = 0.5 * (along_w.reference.x() + 1.0);
        const double weight = 0.125 * along_u.weight * along_v.weight * along_w.weight * (1.0 - v) *
                              (1.0 - w) * (1.0 - w);
        rule.push_back({Eigen::Vector3d(u * (1.0 - v) * (1.0 - w), v * (1.0 - w), w), weight});
      }
    }
  }
  return rule;
}

/// The centroid rule (degree 1), the symmetric 4-point rule (degree 2), the collapsed rule
/// above; the weights sum to the reference volume 1/6.
std::vector<QuadraturePoint> tetrahedron_quadrature(int degree) {
  if (degree <= 1) return {{Eigen::Vector3d(0.25, 0.25, 0.25), 1.0 / 6.0}};
  if (degree == 2) {
    // Orbit of (a, a, a, b) in barycentric coordinates, a = (5 - sqrt 5) / 20, b = 1 - 3a.
    const double a = (5.0 - std::sqrt(5.0)) / 20.0;
    const double b = 1.0 - 3.0 * a;
    return {{Eigen::Vector3d(a, a, a), 1.0 / 24.0},
            {Eigen::Vector3d(b, a, a), 1.0 / 24.0},
            {Eigen::Vector3d(a, b, a), 1.0 / 24.0},
            {Eigen::Vector3d(a, a, b), 1.0 / 24.0}};
  }
  return collapsed_tetrahedron_rule(degree);
}

std::vector<QuadraturePoint> hexahedron_quadrature(int degree) {
  const std::vector<QuadraturePoint> line = gauss_legendre(degree / 2 + 1);
  std::vector<QuadraturePoint> rule;
  for (const QuadraturePoint& along_zeta : line) {
    for (const QuadraturePoint& along_eta : line) {
      for (const QuadraturePoint& along_xi : line) {
        rule.push_back({Eigen::Vector3d(along_xi.reference.x(), along_eta.reference.x(),
                                        along_zeta.reference.x()),
                        along_xi.weight * along_eta.weight * along_zeta.weight});
      }
    }
  }
  return rule;
}

void check_degree(int degree) {
  if (degree < 0) throw std::invalid_argument("quadrature degree must be >= 0");
}

/// The local corners of the six edges of a tetrahedron10, in the order of its midside nodes 4..9
/// (Gmsh: 01, 12, 20, 30, 32, 31).
constexpr int tetrahedron_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};

/// The corners (xi_i, eta_i) of the reference quadrilateral [-1, 1]^2 and
/// (xi_i, eta_i, zeta_i) of the reference hexahedron [-1, 1]^3, in node order.
constexpr double quadrilateral_corners[4][2] = {{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}};
constexpr double hexahedron_corners[8][3] = {
    {-1.0, -1.0, -1.0}, {1.0, -1.0, -1.0}, {1.0, 1.0, -1.0}, {-1.0, 1.0, -1.0},
    {-1.0, -1.0, 1.0},  {1.0, -1.0, 1.0},  {1.0, 1.0, 1.0},  {-1.0, 1.0, 1.0}};

/// Quadratic tetrahedron: barycentric L0 = 1 - r - s - t, L1 = r, L2 = s, L3 = t; corners
/// L_i (2 L_i - 1), the midside node of edge ij 4 L_i L_j.
void quadratic_tetrahedron_functions(const Eigen::Vector3d& reference, ShapeValues& values,
                                     ShapeGradients& reference_gradients) {
  const Eigen::Vector4d barycentric(1.0 - reference.sum(), reference.x(), reference.y(),
                                    reference.z());
  Eigen::Matrix<double, 4, 3> barycentric_gradients;
  barycentric_gradients << -1.0, -1.0, -1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0;
  values.resize(10);
  reference_gradients.resize(10, 3);
  for (int i = 0; i < 4; ++i) {
    values(i) = barycentric(i) * (2.0 * barycentric(i) - 1.0);
    reference_gradients.row(i) = (4.0 * barycentric(i) - 1.0) * barycentric_gradients.row(i);
  }
  for (int edge = 0; edge < 6; ++edge) {
    const int a = tetrahedron_edges[edge][0];
    const int b = tetrahedron_edges[edge][1];
    values(4 + edge) = 4.0 * barycentric(a) * barycentric(b);
    reference_gradients.row(4 + edge) = 4.0 * (barycentric(b) * barycentric_gradients.row(a) +
                                               barycentric(a) * barycentric_gradients.row(b));
  }
}

}  // namespace

std::vector<QuadraturePoint> element_quadrature(ElementType type, int degree) {
  check_degree(degree);
  switch (type) {
    case ElementType::triangle3:
    case ElementType::triangle6:
      return triangle_quadrature(degree);
    case ElementType::quadrilateral4:
      return quadrilateral_quadrature(degree);
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
      return tetrahedron_quadrature(degree);
    case ElementType::hexahedron8:
      return hexahedron_quadrature(degree);
  }
  throw std::invalid_argument("element_quadrature: unknown element type");
}

std::vector<QuadraturePoint> facet_quadrature(FacetType type, int degree) {
  if (facet_dimension(type) == 1) return edge_quadrature(degree);
  return element_quadrature(face_parametrization(type), degree);
}

std::vector<QuadraturePoint> edge_quadrature(int degree) {
  check_degree(degree);
  return gauss_legendre(degree / 2 + 1);
}

void shape_functions(ElementType type, const Eigen::Vector3d& reference, ShapeValues& values,
                     ShapeGradients& reference_gradients) {
  const double r = reference.x();
  const double s = reference.y();
  const double t = reference.z();
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
      for (int i = 0; i < 4; ++i) {
        const auto [xi, eta] = quadrilateral_corners[i];
        const double along_xi = 1.0 + xi * r;
        const double along_eta = 1.0 + eta * s;
        values(i) = 0.25 * along_xi * along_eta;
        reference_gradients(i, 0) = 0.25 * xi * along_eta;
        reference_gradients(i, 1) = 0.25 * eta * along_xi;
      }
      return;
    }
    case ElementType::tetrahedron4:
      values.resize(4);
      reference_gradients.resize(4, 3);
      values << 1.0 - r - s - t, r, s, t;
      reference_gradients << -1.0, -1.0, -1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0;
      return;
    case ElementType::tetrahedron10:
      quadratic_tetrahedron_functions(reference, values, reference_gradients);
      return;
    case ElementType::hexahedron8: {
      // N_i = (1 + xi_i xi)(1 + eta_i eta)(1 + zeta_i zeta) / 8 at the corners of [-1, 1]^3.
      values.resize(8);
      reference_gradients.resize(8, 3);
      for (int i = 0; i < 8; ++i) {
        const auto [xi, eta, zeta] = hexahedron_corners[i];
        const double along_xi = 1.0 + xi * r;
        const double along_eta = 1.0 + eta * s;
        const double along_zeta = 1.0 + zeta * t;
        values(i) = 0.125 * along_xi * along_eta * along_zeta;
        reference_gradients(i, 0) = 0.125 * xi * along_eta * along_zeta;
        reference_gradients(i, 1) = 0.125 * eta * along_xi * along_zeta;
        reference_gradients(i, 2) = 0.125 * zeta * along_xi * along_eta;
      }
      return;
    }
  }
  throw std::invalid_argument("shape_functions: unknown element type");
}

void edge_shape_functions(FacetType type, double reference, ShapeValues& values,
                          ShapeValues& reference_derivatives) {
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

std::vector<Eigen::Vector3d> reference_nodes(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
    case ElementType::triangle6:
      return {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0},
              {0.5, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.0, 0.5, 0.0}};
    case ElementType::quadrilateral4: {
      std::vector<Eigen::Vector3d> nodes;
      for (const auto [xi, eta] : quadrilateral_corners) nodes.emplace_back(xi, eta, 0.0);
      return nodes;
    }
    case ElementType::tetrahedron4:
      return {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    case ElementType::tetrahedron10: {
      std::vector<Eigen::Vector3d> nodes = reference_nodes(ElementType::tetrahedron4);
      for (const auto& [a, b] : tetrahedron_edges) nodes.push_back(0.5 * (nodes[a] + nodes[b]));
      return nodes;
    }
    case ElementType::hexahedron8: {
      std::vector<Eigen::Vector3d> nodes;
      for (const auto [xi, eta, zeta] : hexahedron_corners) nodes.emplace_back(xi, eta, zeta);
      return nodes;
    }
  }
  throw std::invalid_argument("reference_nodes: unknown element type");
}

Eigen::Vector3d reference_centroid(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
    case ElementType::triangle6:
      return Eigen::Vector3d(1.0 / 3.0, 1.0 / 3.0, 0.0);
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
      return Eigen::Vector3d(0.25, 0.25, 0.25);
    case ElementType::quadrilateral4:
    case ElementType::hexahedron8:
      return Eigen::Vector3d::Zero();
  }
  throw std::invalid_argument("reference_centroid: unknown element type");
}

void facet_shape_functions(FacetType type, const Eigen::Vector3d& reference, ShapeValues& values,
                           ShapeGradients& reference_gradients) {
  if (facet_dimension(type) == 2) {
    shape_functions(face_parametrization(type), reference, values, reference_gradients);
    return;
  }
  ShapeValues derivatives;
  edge_shape_functions(type, reference.x(), values, derivatives);
  reference_gradients = derivatives;
}

std::vector<ReferenceShape> tabulate_shapes(ElementType type,
                                            const std::vector<QuadraturePoint>& rule) {
  std::vector<ReferenceShape> shapes(rule.size());
  for (std::size_t k = 0; k < rule.size(); ++k) {
    shapes[k].reference = rule[k].reference;
    shapes[k].weight = rule[k].weight;
    shape_functions(type, rule[k].reference, shapes[k].values, shapes[k].gradients);
  }
  return shapes;
}

std::vector<ReferenceShape> tabulate_shapes(ElementType type,
                                            const std::vector<Eigen::Vector3d>& points) {
  std::vector<ReferenceShape> shapes(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    shapes[k].reference = points[k];
    shape_functions(type, points[k], shapes[k].values, shapes[k].gradients);
  }
  return shapes;
}

std::vector<std::size_t> first_with_same_gradients(const std::vector<ReferenceShape>& shapes) {
  std::vector<std::size_t> first(shapes.size());
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    first[k] = k;
    for (std::size_t earlier = 0; earlier < k; ++earlier) {
      if (shapes[earlier].gradients == shapes[k].gradients) {
        first[k] = earlier;
        break;
      }
    }
  }
  return first;
}

double jacobian_determinant(const JacobianMatrix& jacobian) {
  if (jacobian.rows() == 2) return Eigen::Matrix2d(jacobian).determinant();
  return Eigen::Matrix3d(jacobian).determinant();
}

double invert_jacobian(const JacobianMatrix& jacobian, JacobianMatrix& inverse) {
  if (jacobian.rows() == 2) {
    const Eigen::Matrix2d fixed = jacobian;
    inverse = fixed.inverse();
    return fixed.determinant();
  }
  const Eigen::Matrix3d fixed = jacobian;
  inverse = fixed.inverse();
  return fixed.determinant();
}

std::vector<Eigen::Vector3d> facet_reference_nodes(FacetType type) {
  if (facet_dimension(type) == 2) return reference_nodes(face_parametrization(type));
  std::vector<Eigen::Vector3d> nodes;
  for (const double t : edge_reference_nodes(type)) nodes.emplace_back(t, 0.0, 0.0);
  return nodes;
}

std::vector<std::vector<int>> element_facet_corners(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
    case ElementType::triangle6:
      return {{0, 1}, {1, 2}, {2, 0}};
    case ElementType::quadrilateral4:
      return {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
      return {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    case ElementType::hexahedron8:
      return {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  }
  throw std::invalid_argument("element_facet_corners: unknown element type");
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
  const int dimension = element_dimension(type_);
  nodes_ = &mesh.blocks[block].connectivity[element * count];
  coordinates_.resize(count, dimension);
  for (int i = 0; i < count; ++i) {
    coordinates_.row(i) = mesh.nodes[nodes_[i]].head(dimension).transpose();
  }
}

ElementPoint ElementGeometry::evaluate(const Eigen::Vector3d& reference) const {
  ReferenceShape shape;
  shape.reference = reference;
  shape_functions(type_, reference, shape.values, shape.gradients);
  return evaluate(shape);
}

ElementPoint ElementGeometry::evaluate(const ReferenceShape& shape) const {
  ElementPoint point;
  point.values = shape.values;
  // J_ij = dx_i / dxi_j = sum_k x_k,i dN_k / dxi_j (closed-form determinant and inverse).
  const JacobianMatrix jacobian = coordinates_.transpose() * shape.gradients;
  JacobianMatrix inverse;
  point.jacobian = invert_jacobian(jacobian, inverse);
  if (!(point.jacobian > 0.0)) {
    const Eigen::Vector3d& reference = shape.reference;
    std::ostringstream text;
    text << describe_element(*mesh_, type_, nodes_) << " has a non-positive Jacobian "
         << point.jacobian << " at reference point (" << reference.x() << ", " << reference.y();
    if (jacobian.rows() == 3) text << ", " << reference.z();
    text << "): the element is degenerate or tangled; fix the mesh";
    throw InputError(text.str());
  }
  // dN/dx = dN/dxi J^-1
  point.gradients.noalias() = shape.gradients * inverse;
  point.position.setZero();
  point.position.head(jacobian.rows()).noalias() = coordinates_.transpose() * point.values;
  return point;
}

NodeElementMap::NodeElementMap(const Mesh& mesh, const BoundaryGroup& group)
    : mesh_(&mesh), nodes_(group.nodes()), start_(nodes_.size() + 1, 0) {
  std::vector<int> position(mesh.node_count(), -1);  // of each group node in nodes_
  for (std::size_t k = 0; k < nodes_.size(); ++k) position[nodes_[k]] = static_cast<int>(k);
  const auto for_each_incidence = [&](const auto& visit) {
    for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
      const ElementBlock& block = mesh.blocks[b];
      const int count = nodes_per_element(block.type);
      for (std::size_t e = 0; e < block.element_count(); ++e) {
        for (int i = 0; i < count; ++i) {
          const int k = position[block.connectivity[e * count + i]];
          if (k >= 0) visit(static_cast<std::size_t>(k), ElementIndex(b, e));
        }
      }
    }
  };
  for_each_incidence([&](std::size_t k, const ElementIndex&) { ++start_[k + 1]; });
  for (std::size_t k = 0; k < nodes_.size(); ++k) start_[k + 1] += start_[k];
  elements_.resize(start_.back());
  std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
  for_each_incidence(
      [&](std::size_t k, const ElementIndex& element) { elements_[next[k]++] = element; });
}

std::optional<NodeElementMap::ElementIndex> NodeElementMap::element_with(
    const std::vector<int>& nodes) const {
  if (nodes.empty()) return std::nullopt;
  const auto found = std::lower_bound(nodes_.begin(), nodes_.end(), nodes.front());
  if (found == nodes_.end() || *found != nodes.front()) {
    throw std::out_of_range("NodeElementMap: node " + std::to_string(nodes.front()) +
                            " is not a node of its boundary group");
  }
  const auto k = static_cast<std::size_t>(found - nodes_.begin());
  for (std::size_t entry = start_[k]; entry < start_[k + 1]; ++entry) {
    const ElementIndex& candidate = elements_[entry];
    const ElementBlock& block = mesh_->blocks[candidate.first];
    const int count = nodes_per_element(block.type);
    const auto begin = block.connectivity.begin() + candidate.second * count;
    const auto contains = [&](int node) {
      return std::find(begin, begin + count, node) != begin + count;
    };
    if (std::all_of(nodes.begin() + 1, nodes.end(), contains)) return candidate;
  }
  return std::nullopt;
}

namespace {

/// The facet's own (not yet oriented) normal direction and measure element from the columns of
/// dx/dxi: an edge's tangent turned clockwise, a face's dx/dr x dx/ds.
Eigen::Vector3d facet_normal_direction(const JacobianMatrix& derivatives) {
  if (derivatives.cols() == 1) {
    return Eigen::Vector3d(derivatives(1, 0), -derivatives(0, 0), 0.0);
  }
  return Eigen::Vector3d(derivatives.col(0)).cross(Eigen::Vector3d(derivatives.col(1)));
}

/// The reference coordinates of a facet's centre.
Eigen::Vector3d facet_centre(FacetType type) {
  if (facet_dimension(type) == 1) return Eigen::Vector3d::Zero();
  return reference_centroid(face_parametrization(type));
}

std::string facet_label(const Mesh& mesh, const BoundaryGroup& group, std::size_t facet) {
  const int count = nodes_per_facet(group.type);
  std::string tags;
  for (int i = 0; i < facet_corner_count(group.type); ++i) {
    tags += (i == 0 ? "" : ", ") +
            std::to_string(mesh.node_tags[group.connectivity[facet * count + i]]);
  }
  return "boundary " + mesh.boundary_label(group) + ": the " +
         (facet_dimension(group.type) == 1 ? "edge" : "face") + " with corner node tags (" + tags +
         ")";
}

}  // namespace

FacetGeometry::FacetGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t facet)
    : type_(group.type) {
  const int count = nodes_per_facet(type_);
  coordinates_.resize(count, 3);
  for (int i = 0; i < count; ++i) {
    coordinates_.row(i) = mesh.nodes[group.connectivity[facet * count + i]].transpose();
  }
  const double extent =
      (coordinates_.colwise().maxCoeff() - coordinates_.colwise().minCoeff()).norm();
  const double scale = facet_dimension(type_) == 1 ? extent : extent * extent;
  if (!(evaluate(facet_centre(type_)).measure_element > 1e-14 * scale)) {
    throw InputError(facet_label(mesh, group, facet) +
                     (facet_dimension(type_) == 1 ? " has zero length" : " has zero area") +
                     "; fix the mesh");
  }
}

FacetGeometry::FacetGeometry(const Mesh& mesh, const BoundaryGroup& group, std::size_t facet,
                             const NodeElementMap& adjacency)
    : FacetGeometry(mesh, group, facet) {
  const int count = nodes_per_facet(type_);
  std::vector<int> corners;
  for (int i = 0; i < facet_corner_count(type_); ++i) {
    corners.push_back(group.connectivity[facet * count + i]);
  }
  const std::optional<NodeElementMap::ElementIndex> element = adjacency.element_with(corners);
  if (!element) {
    throw InputError(facet_label(mesh, group, facet) + " is not a side of any " +
                     (facet_dimension(type_) == 1 ? "area" : "volume") +
                     " element, so it has no outward normal");
  }
  // Outward: the facet's own normal at its centre points away from the element's centroid.
  const ElementBlock& block = mesh.blocks[element->first];
  const int* nodes = &block.connectivity[element->second * nodes_per_element(block.type)];
  const int corner_count = element_corner_count(block.type);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < corner_count; ++i) centroid += mesh.nodes[nodes[i]];
  centroid /= corner_count;
  Eigen::Vector3d middle = Eigen::Vector3d::Zero();
  for (const int corner : corners)
    middle += mesh.nodes[corner] / static_cast<double>(corners.size());
  orientation_ = 1.0;
  const FacetPoint at_centre = evaluate(facet_centre(type_));
  orientation_ = at_centre.outward_normal.dot(middle - centroid) >= 0.0 ? 1.0 : -1.0;
}

FacetPoint FacetGeometry::evaluate(const Eigen::Vector3d& reference) const {
  FacetPoint point;
  ShapeGradients reference_gradients;
  facet_shape_functions(type_, reference, point.values, reference_gradients);
  point.position.noalias() = coordinates_.transpose() * point.values;
  // dx/dxi (3 x facet dimension); the normal is orientation (t_y, -t_x, 0) / |t| for an edge,
  // orientation (x_r x x_s) / |x_r x x_s| for a face.
  const JacobianMatrix derivatives = coordinates_.transpose() * reference_gradients;
  const Eigen::Vector3d direction = facet_normal_direction(derivatives);
  point.measure_element = direction.norm();
  point.outward_normal = orientation_ * direction / point.measure_element;
  return point;
}

double FacetGeometry::measure() const {
  double measure = 0.0;
  for (const QuadraturePoint& point : facet_quadrature(type_, 6)) {
    measure += evaluate(point.reference).measure_element * point.weight;
  }
  return measure;
}

}  // namespace robin
