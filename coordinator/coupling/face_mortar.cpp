#include "coupling/face_mortar.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "coupling/box_tree.hpp"
#include "numerics/finite_element.hpp"

namespace robin {
namespace {

/// Popp et al.'s alpha of the triangle6 basis transformation (face_basis_transformation).
constexpr double triangle6_alpha = 0.2;

/// Gauss rule degrees: on the reference face for mass matrices and supports, and on the
/// integration triangles of the clip polygons. On affine linear faces the integrands are
/// polynomials of degree <= 4 in the plane coordinates (psi phi^mortar, psi g), which the
/// degree-6 symmetric rule (12 points) integrates exactly; with quadratic faces they reach
/// degree 6 on affine faces, and curved geometry (and the initial gap g0) is not polynomial:
/// the degree-10 collapsed Gauss rule (49 points) there.
constexpr int face_degree = 10;
int cell_degree(FacetType nonmortar, FacetType mortar) {
  return nonmortar == FacetType::triangle6 || mortar == FacetType::triangle6 ? 10 : 6;
}

struct FacePoint {
  ShapeValues values;                // shape functions at the point
  Eigen::Vector3d position;          // x(r, s)
  Eigen::Vector3d along_r, along_s;  // dx/dr, dx/ds
};

/// One face of a surface: its nodes, its isoparametric map and its normal field.
class Face {
 public:
  Face(const MortarSurface& surface, int face)
      : surface_(&surface),
        type_(surface.face_type),
        parametrization_(face_parametrization(surface.face_type)),
        count_(nodes_per_facet(surface.face_type)),
        first_(static_cast<std::size_t>(face) * static_cast<std::size_t>(count_)) {}

  int count() const { return count_; }
  FacetType type() const { return type_; }
  ElementType parametrization() const { return parametrization_; }
  /// Node position (into the surface's coordinates) of local node `local`.
  int node(int local) const { return surface_->faces[first_ + static_cast<std::size_t>(local)]; }
  const Eigen::Vector3d& coordinates(int local) const {
    return surface_->coordinates[static_cast<std::size_t>(node(local))];
  }
  std::vector<Eigen::Vector3d> node_coordinates() const {
    std::vector<Eigen::Vector3d> nodes;
    for (int a = 0; a < count_; ++a) nodes.push_back(coordinates(a));
    return nodes;
  }

  FacePoint evaluate(const Eigen::Vector2d& reference) const {
    FacePoint point;
    ShapeGradients gradients;
    shape_functions(parametrization_, Eigen::Vector3d(reference.x(), reference.y(), 0.0),
                    point.values, gradients);
    point.position.setZero();
    point.along_r.setZero();
    point.along_s.setZero();
    for (int a = 0; a < count_; ++a) {
      point.position += point.values[a] * coordinates(a);
      point.along_r += gradients(a, 0) * coordinates(a);
      point.along_s += gradients(a, 1) * coordinates(a);
    }
    return point;
  }

  /// The normal field: the shape-function interpolation of the averaged nodal normals,
  /// normalized.
  Eigen::Vector3d normal_field(const ShapeValues& values) const {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int a = 0; a < count_; ++a) {
      normal += values[a] * surface_->normals[static_cast<std::size_t>(node(a))];
    }
    return normal.normalized();
  }

  /// The geometric (right-hand, outward) unit normal at the reference centroid.
  Eigen::Vector3d outward_normal() const {
    const FacePoint centre = evaluate(reference_centroid(parametrization_).head<2>());
    return centre.along_r.cross(centre.along_s).normalized();
  }

  /// The face's straight-edged pieces as local node lists, counter-clockwise in the reference
  /// plane: the face itself when linear, the 4 sub-triangles of a triangle6 face (corner
  /// triangles at nodes 0, 1, 2 and the middle one).
  std::vector<std::vector<int>> pieces() const {
    if (type_ == FacetType::triangle6) return {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
    if (type_ == FacetType::quadrilateral4) return {{0, 1, 2, 3}};
    return {{0, 1, 2}};
  }

 private:
  const MortarSurface* surface_;
  FacetType type_;
  ElementType parametrization_;
  int count_;
  std::size_t first_;
};

/// The auxiliary plane of a non-mortar face: through the face's centre x0, normal n0 (the
/// normal field at the centre), with an orthonormal in-plane basis (e1, e2, n0) right-handed.
struct AuxiliaryPlane {
  Eigen::Vector3d centre, normal, first, second;

  explicit AuxiliaryPlane(const Face& face) {
    const FacePoint at = face.evaluate(reference_centroid(face.parametrization()).head<2>());
    centre = at.position;
    normal = face.normal_field(at.values);
    // The in-plane axis closest to the face's first tangent (any would do).
    first = (at.along_r - at.along_r.dot(normal) * normal).normalized();
    if (!first.allFinite()) first = normal.unitOrthogonal();
    second = normal.cross(first);
  }

  /// Plane coordinates of the projection of `point` along the normal.
  Eigen::Vector2d coordinates(const Eigen::Vector3d& point) const {
    return {first.dot(point - centre), second.dot(point - centre)};
  }
  Eigen::Vector3d point(const Eigen::Vector2d& plane) const {
    return centre + plane.x() * first + plane.y() * second;
  }
};

using Polygon = std::vector<Eigen::Vector2d>;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

double signed_area(const Polygon& polygon) {
  double twice = 0.0;
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    twice += cross(polygon[k], polygon[(k + 1) % polygon.size()]);
  }
  return 0.5 * twice;
}

/// Sutherland-Hodgman: the part of `subject` inside the convex counter-clockwise polygon
/// `clip`, with vertices closer than `merge` merged.
Polygon clip_polygon(Polygon subject, const Polygon& clip, double merge) {
  for (std::size_t edge = 0; edge < clip.size() && !subject.empty(); ++edge) {
    const Eigen::Vector2d& from = clip[edge];
    const Eigen::Vector2d direction = clip[(edge + 1) % clip.size()] - from;
    const auto side = [&](const Eigen::Vector2d& point) { return cross(direction, point - from); };
    Polygon kept;
    for (std::size_t k = 0; k < subject.size(); ++k) {
      const Eigen::Vector2d& current = subject[k];
      const Eigen::Vector2d& next = subject[(k + 1) % subject.size()];
      const double here = side(current), there = side(next);
      if (here >= 0.0) kept.push_back(current);
      if ((here >= 0.0) != (there >= 0.0)) {
        kept.push_back(current + here / (here - there) * (next - current));
      }
    }
    subject = std::move(kept);
  }
  Polygon merged;
  for (const Eigen::Vector2d& point : subject) {
    if (merged.empty() || (point - merged.back()).norm() > merge) merged.push_back(point);
  }
  while (merged.size() > 1 && (merged.front() - merged.back()).norm() <= merge) merged.pop_back();
  return merged;
}

/// The reference coordinates of the point of `face` whose projection along the plane's normal
/// is `target` (plane coordinates): Newton on (e1, e2) . (x(xi) - x_target) = 0, from the
/// reference centroid; one step on affine faces. Empty when Newton fails (a face seen
/// edge-on, or far outside).
std::optional<Eigen::Vector2d> project_back(const Face& face, const AuxiliaryPlane& plane,
                                            const Eigen::Vector2d& target) {
  Eigen::Vector2d reference = reference_centroid(face.parametrization()).head<2>();
  const Eigen::Vector3d point = plane.point(target);
  for (int step = 0; step < 30; ++step) {
    const FacePoint at = face.evaluate(reference);
    const Eigen::Vector3d difference = at.position - point;
    const Eigen::Vector2d residual(plane.first.dot(difference), plane.second.dot(difference));
    Eigen::Matrix2d jacobian;
    jacobian << plane.first.dot(at.along_r), plane.first.dot(at.along_s),
        plane.second.dot(at.along_r), plane.second.dot(at.along_s);
    const double determinant = jacobian.determinant();
    const double scale = at.along_r.norm() * at.along_s.norm();
    if (!(std::abs(determinant) > 1e-12 * scale)) return std::nullopt;
    const Eigen::Vector2d change = jacobian.inverse() * residual;
    reference -= change;
    // Below 1e-13 or the round-off of the coordinates seen in the reference coordinates.
    const double magnitude = point.cwiseAbs().maxCoeff() + at.position.cwiseAbs().maxCoeff();
    const double tolerance = 1e-13 + 64.0 * std::numeric_limits<double>::epsilon() * magnitude /
                                         std::sqrt(std::abs(determinant));
    if (change.cwiseAbs().maxCoeff() < tolerance) return reference;
    if (reference.cwiseAbs().maxCoeff() > 1e3) return std::nullopt;
  }
  return std::nullopt;
}

/// The local sums over one (non-mortar face, mortar face) pair, added to the rows at the end.
struct PairIntegrals {
  Eigen::MatrixXd dual_nonmortar, standard_nonmortar, dual_mortar, standard_mortar;
  Eigen::VectorXd dual_gap, standard_gap, covered;

  PairIntegrals(int count, int mortar_count)
      : dual_nonmortar(Eigen::MatrixXd::Zero(count, count)),
        standard_nonmortar(Eigen::MatrixXd::Zero(count, count)),
        dual_mortar(Eigen::MatrixXd::Zero(count, mortar_count)),
        standard_mortar(Eigen::MatrixXd::Zero(count, mortar_count)),
        dual_gap(Eigen::VectorXd::Zero(count)),
        standard_gap(Eigen::VectorXd::Zero(count)),
        covered(Eigen::VectorXd::Zero(count)) {}

  void add_to(const Face& face, const Face& other, std::vector<FaceRowIntegrals>& rows) const {
    for (int a = 0; a < face.count(); ++a) {
      FaceRowIntegrals& row = rows[static_cast<std::size_t>(face.node(a))];
      row.covered += covered[a];
      row.dual_gap += dual_gap[a];
      row.standard_gap += standard_gap[a];
      for (int b = 0; b < face.count(); ++b) {
        row.dual_nonmortar[face.node(b)] += dual_nonmortar(a, b);
        row.standard_nonmortar[face.node(b)] += standard_nonmortar(a, b);
      }
      for (int l = 0; l < other.count(); ++l) {
        row.dual_mortar[other.node(l)] += dual_mortar(a, l);
        row.standard_mortar[other.node(l)] += standard_mortar(a, l);
      }
    }
  }
};

/// What one non-mortar face needs for its integrals.
struct NonmortarFace {
  Face face;
  AuxiliaryPlane plane;
  Eigen::MatrixXd transformation;  // phi~ = T phi
  Eigen::MatrixXd dual;            // psi = B phi
  std::vector<Polygon> pieces;     // projected, counter-clockwise
  double size = 0.0;               // the largest extent of the projected pieces

  NonmortarFace(const MortarSurface& surface, int index)
      : face(surface, index),
        plane(face),
        transformation(face_basis_transformation(surface.face_type)),
        dual(face_dual_basis(surface.face_type, face.node_coordinates())) {}
};

/// The projections onto `plane` of a face's straight-edged pieces, counter-clockwise about
/// the plane normal (a mortar face, facing the other way, projects clockwise).
std::vector<Polygon> projected_pieces(const Face& face, const AuxiliaryPlane& plane) {
  std::vector<Polygon> pieces;
  for (const std::vector<int>& piece : face.pieces()) {
    Polygon polygon;
    for (const int local : piece) polygon.push_back(plane.coordinates(face.coordinates(local)));
    if (signed_area(polygon) < 0.0) std::reverse(polygon.begin(), polygon.end());
    pieces.push_back(std::move(polygon));
  }
  return pieces;
}

double extent(const std::vector<Polygon>& pieces) {
  Eigen::Vector2d low = pieces.front().front(), high = low;
  for (const Polygon& polygon : pieces) {
    for (const Eigen::Vector2d& point : polygon) {
      low = low.cwiseMin(point);
      high = high.cwiseMax(point);
    }
  }
  return (high - low).maxCoeff();
}

/// Integrates over the clip polygon `overlap` (plane coordinates of `nonmortar`'s auxiliary
/// plane), cut into triangles from its vertex centroid, mapping each Gauss point back along
/// the auxiliary normal n0 onto both faces. Along n0 rather than along the normal field n(xi):
/// n0 is the direction that cut the polygons, so every point of a cell lands inside both
/// clipped faces and the cells of neighbouring mortar faces tile the face without gaps or
/// overlaps (along n(xi) a point near a cell's edge can land on the neighbouring mortar face,
/// whose shape functions would then be extrapolated). The gap is still measured along n(xi),
/// as in Popp et al.'s dual mortar methods; on a flat non-mortar surface n(xi) = n0 and both
/// choices coincide with the 2D projection.
void integrate_polygon(const NonmortarFace& nonmortar, const Face& other, const Polygon& overlap,
                       const std::vector<QuadraturePoint>& rule, const SpatialGap& gap,
                       PairIntegrals& sums) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& point : overlap) centroid += point;
  centroid /= static_cast<double>(overlap.size());
  const Face& face = nonmortar.face;
  const Eigen::Vector3d& auxiliary = nonmortar.plane.normal;
  for (std::size_t k = 0; k < overlap.size(); ++k) {
    const Eigen::Vector2d first = overlap[k] - centroid;
    const Eigen::Vector2d second = overlap[(k + 1) % overlap.size()] - centroid;
    const double twice_area = cross(first, second);
    if (!(twice_area > 0.0)) continue;
    for (const QuadraturePoint& gauss : rule) {
      const Eigen::Vector2d target =
          centroid + gauss.reference.x() * first + gauss.reference.y() * second;
      const std::optional<Eigen::Vector2d> xi = project_back(face, nonmortar.plane, target);
      const std::optional<Eigen::Vector2d> eta = project_back(other, nonmortar.plane, target);
      if (!xi || !eta) continue;
      const FacePoint at = face.evaluate(*xi);
      const FacePoint onto = other.evaluate(*eta);
      const Eigen::Vector3d normal = face.normal_field(at.values);
      double distance = (onto.position - at.position).dot(normal);
      if (gap) distance += gap(at.position);
      // dA on the non-mortar face = dA on the plane * |x_r x x_s| / |(x_r x x_s) . n0|: the
      // exact change of variables from the plane to the face.
      const Eigen::Vector3d area_normal = at.along_r.cross(at.along_s);
      const double measure =
          gauss.weight * twice_area * area_normal.norm() / std::abs(area_normal.dot(auxiliary));
      const ShapeValues standard = nonmortar.transformation * at.values;
      const ShapeValues dual = nonmortar.dual * at.values;
      sums.covered += measure * standard;
      sums.dual_gap += (measure * distance) * dual;
      sums.standard_gap += (measure * distance) * standard;
      sums.dual_nonmortar += measure * dual * at.values.transpose();
      sums.standard_nonmortar += measure * standard * at.values.transpose();
      sums.dual_mortar += measure * dual * onto.values.transpose();
      sums.standard_mortar += measure * standard * onto.values.transpose();
    }
  }
}

void check_surface(const MortarSurface& surface, const char* role) {
  const std::string name = std::string("integrate_face_mortar: the ") + role + " surface ";
  if (facet_dimension(surface.face_type) != 2) {
    throw std::invalid_argument(name + "has edges (" + to_string(surface.face_type) +
                                "), not faces");
  }
  if (surface.normals.size() != surface.coordinates.size()) {
    throw std::invalid_argument(name + "has " + std::to_string(surface.normals.size()) +
                                " normals for " + std::to_string(surface.coordinates.size()) +
                                " nodes");
  }
  if (surface.faces.size() % static_cast<std::size_t>(nodes_per_facet(surface.face_type)) != 0) {
    throw std::invalid_argument(name + "has a face list that is not a whole number of " +
                                to_string(surface.face_type) + " faces");
  }
  for (const int position : surface.faces) {
    if (position < 0 || static_cast<std::size_t>(position) >= surface.coordinates.size()) {
      throw std::invalid_argument(
          name + "has a face node position out of range: " + std::to_string(position));
    }
  }
}

int face_count(const MortarSurface& surface) {
  return static_cast<int>(surface.faces.size()) / nodes_per_facet(surface.face_type);
}

Box face_box(const Face& face) {
  Eigen::Vector3d low = face.coordinates(0), high = low;
  for (int a = 1; a < face.count(); ++a) {
    low = low.cwiseMin(face.coordinates(a));
    high = high.cwiseMax(face.coordinates(a));
  }
  return {low, high};
}

/// Where to look for the mortar faces of a non-mortar face (as SearchRange in 2D): along the
/// nodal normals out to `reach` on both sides (four of the largest face extents, or a
/// twentieth of the two surfaces' extent if that is larger), widened by one largest face
/// extent in every direction.
struct SearchRange {
  double reach = 0.0;
  double slack = 0.0;

  SearchRange(const MortarSurface& nonmortar, const MortarSurface& mortar) {
    Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d high = -low;
    for (const MortarSurface* surface : {&nonmortar, &mortar}) {
      for (int index = 0; index < face_count(*surface); ++index) {
        const auto [box_low, box_high] = face_box(Face(*surface, index));
        slack = std::max(slack, (box_high - box_low).norm());
        low = low.cwiseMin(box_low);
        high = high.cwiseMax(box_high);
      }
    }
    reach = slack > 0.0 ? std::max(4.0 * slack, 0.05 * (high - low).norm()) : 0.0;
  }

  Box box(const Face& face, const MortarSurface& surface) const {
    Eigen::Vector3d low = face.coordinates(0), high = low;
    for (int a = 0; a < face.count(); ++a) {
      const Eigen::Vector3d& normal = surface.normals[static_cast<std::size_t>(face.node(a))];
      for (const double distance : {-reach, reach}) {
        low = low.cwiseMin(face.coordinates(a) + distance * normal);
        high = high.cwiseMax(face.coordinates(a) + distance * normal);
      }
    }
    const Eigen::Vector3d margin = Eigen::Vector3d::Constant(slack);
    return {low - margin, high + margin};
  }
};

}  // namespace

Eigen::MatrixXd face_basis_transformation(FacetType type) {
  const int count = nodes_per_facet(type);
  Eigen::MatrixXd transformation = Eigen::MatrixXd::Identity(count, count);
  if (type != FacetType::triangle6) return transformation;
  // Mid-edge nodes 3, 4, 5 on edges 01, 12, 20.
  constexpr std::array<std::array<int, 2>, 3> corners_of_edge = {{{0, 1}, {1, 2}, {2, 0}}};
  for (int edge = 0; edge < 3; ++edge) {
    const int middle = 3 + edge;
    for (const int corner : corners_of_edge[static_cast<std::size_t>(edge)]) {
      transformation(corner, middle) = triangle6_alpha;
    }
    transformation(middle, middle) = 1.0 - 2.0 * triangle6_alpha;
  }
  return transformation;
}

Eigen::MatrixXd face_mass_matrix(FacetType type, const std::vector<Eigen::Vector3d>& nodes) {
  const ElementType parametrization = face_parametrization(type);
  const int count = nodes_per_facet(type);
  Eigen::MatrixXd mass = Eigen::MatrixXd::Zero(count, count);
  for (const QuadraturePoint& gauss : element_quadrature(parametrization, face_degree)) {
    ShapeValues values;
    ShapeGradients gradients;
    shape_functions(parametrization, gauss.reference, values, gradients);
    Eigen::Vector3d along_r = Eigen::Vector3d::Zero(), along_s = Eigen::Vector3d::Zero();
    for (int a = 0; a < count; ++a) {
      along_r += gradients(a, 0) * nodes[static_cast<std::size_t>(a)];
      along_s += gradients(a, 1) * nodes[static_cast<std::size_t>(a)];
    }
    mass += gauss.weight * along_r.cross(along_s).norm() * values * values.transpose();
  }
  return mass;
}

Eigen::MatrixXd face_dual_basis(FacetType type, const std::vector<Eigen::Vector3d>& nodes) {
  const Eigen::MatrixXd transformation = face_basis_transformation(type);
  const Eigen::MatrixXd mass =
      transformation * face_mass_matrix(type, nodes) * transformation.transpose();
  const Eigen::VectorXd integrals = mass.rowwise().sum();  // int phi~ (sum phi~ = 1)
  return integrals.asDiagonal() * mass.inverse() * transformation;
}

std::vector<double> support_integrals(const MortarSurface& surface) {
  check_surface(surface, "given");
  std::vector<double> supports(surface.coordinates.size(), 0.0);
  const Eigen::MatrixXd transformation = face_basis_transformation(surface.face_type);
  for (int index = 0; index < face_count(surface); ++index) {
    const Face face(surface, index);
    const Eigen::VectorXd integrals =
        transformation *
        face_mass_matrix(surface.face_type, face.node_coordinates()).rowwise().sum();
    for (int a = 0; a < face.count(); ++a) {
      supports[static_cast<std::size_t>(face.node(a))] += integrals[a];
    }
  }
  return supports;
}

FaceCoupling integrate_face_mortar(const MortarSurface& nonmortar, const MortarSurface& mortar,
                                   const SpatialGap& gap) {
  check_surface(nonmortar, "non-mortar");
  check_surface(mortar, "mortar");
  FaceCoupling coupling;
  coupling.rows.resize(nonmortar.coordinates.size());
  if (face_count(nonmortar) == 0 || face_count(mortar) == 0) return coupling;
  const SearchRange range(nonmortar, mortar);
  std::vector<Box> boxes;
  for (int index = 0; index < face_count(mortar); ++index) {
    boxes.push_back(face_box(Face(mortar, index)));
  }
  const BoxTree tree(std::move(boxes));
  const std::vector<QuadraturePoint> rule = element_quadrature(
      ElementType::triangle3, cell_degree(nonmortar.face_type, mortar.face_type));
  for (int index = 0; index < face_count(nonmortar); ++index) {
    NonmortarFace current(nonmortar, index);
    current.pieces = projected_pieces(current.face, current.plane);
    current.size = extent(current.pieces);
    const Eigen::Vector3d outward = current.face.outward_normal();
    // Slivers below this area are round-off of shared edges, not overlaps.
    const double negligible = 1e-12 * current.size * current.size;
    for (const int other_index : tree.near(range.box(current.face, nonmortar))) {
      const Face other(mortar, other_index);
      if (!(outward.dot(other.outward_normal()) < 0.0)) {
        ++coupling.same_direction_candidates;
        continue;
      }
      ++coupling.facing_candidates;
      const std::vector<Polygon> other_pieces = projected_pieces(other, current.plane);
      PairIntegrals sums(current.face.count(), other.count());
      bool touched = false;
      for (const Polygon& piece : current.pieces) {
        for (const Polygon& other_piece : other_pieces) {
          if (std::abs(signed_area(other_piece)) <= negligible) continue;  // seen edge-on
          const Polygon overlap = clip_polygon(other_piece, piece, 1e-12 * current.size);
          if (overlap.size() < 3 || signed_area(overlap) <= negligible) continue;
          integrate_polygon(current, other, overlap, rule, gap, sums);
          touched = true;
        }
      }
      if (touched) sums.add_to(current.face, other, coupling.rows);
    }
  }
  return coupling;
}

}  // namespace robin
