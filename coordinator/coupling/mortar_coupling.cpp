#include "coupling/mortar_coupling.hpp"

#include "coupling/box_tree.hpp"
#include "coupling/face_mortar.hpp"
#include "coupling/mortar_rows.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <utility>

#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"

namespace robin {
namespace {

/// The point (x, y) of a 2D body's point (x, y, 0): the mortar integration is of plane bodies.
Eigen::Vector2d in_plane(const Eigen::Vector3d& point) {
  return point.head<2>();
}

/// A box tree corner (a point in space) from a plane point: embedded at z = 0.
Eigen::Vector3d corner(const Eigen::Vector2d& point) {
  return {point.x(), point.y(), 0.0};
}

/// One contact boundary of a plane body: its interface description (of that one boundary) seen
/// as segments.
struct Side {
  explicit Side(const InterfaceDescription& description) : interface(&description) {
    if (!description.surfaces.empty()) surface = &description.surfaces.front();
  }

  const InterfaceDescription* interface = nullptr;
  const ContactSurfaceDescription* surface = nullptr;  // null: no segments

  FacetType segment_type() const { return surface ? surface->facet_type : FacetType::line2; }
  int nodes_per_segment() const { return nodes_per_facet(segment_type()); }
  int segment_count() const {
    return surface ? static_cast<int>(surface->facets.size()) / nodes_per_segment() : 0;
  }
  /// Position (into node_ids) of local node `local` of `segment`.
  int node(int segment, int local) const {
    return surface->facets[static_cast<std::size_t>(segment * nodes_per_segment() + local)];
  }
  Eigen::Vector2d coordinates(int position) const {
    return in_plane(interface->coordinates[static_cast<std::size_t>(position)]);
  }
  Eigen::Vector2d normal(int position) const {
    return in_plane(interface->normals[static_cast<std::size_t>(position)]);
  }
};

struct SegmentPoint {
  ShapeValues values;  // shape functions at the point
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Vector2d tangent = Eigen::Vector2d::Zero();  // dx/dxi
};

SegmentPoint evaluate(const Side& side, int segment, double reference) {
  SegmentPoint point;
  ShapeValues derivatives;
  edge_shape_functions(side.segment_type(), reference, point.values, derivatives);
  for (int a = 0; a < side.nodes_per_segment(); ++a) {
    point.position += point.values[a] * side.coordinates(side.node(segment, a));
    point.tangent += derivatives[a] * side.coordinates(side.node(segment, a));
  }
  return point;
}

/// The non-mortar normal field: the shape-function interpolation of the averaged nodal
/// normals, normalised.
Eigen::Vector2d normal_field(const Side& side, int segment, const ShapeValues& values) {
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();
  for (int a = 0; a < side.nodes_per_segment(); ++a) {
    normal += values[a] * side.normal(side.node(segment, a));
  }
  return normal.normalized();
}

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Newton steps on a reference coordinate (dimensionless, O(1)) stop below 1e-12 or below the
/// round-off of the coordinates seen in that coordinate (a few ulps of |x| over |dx/dxi|),
/// whichever is larger: small segments far from the origin cannot resolve more.
double parameter_tolerance(const Eigen::Vector2d& point, const SegmentPoint& at) {
  const double magnitude = point.cwiseAbs().maxCoeff() + at.position.cwiseAbs().maxCoeff();
  return 1e-12 + 64.0 * std::numeric_limits<double>::epsilon() * magnitude / at.tangent.norm();
}

/// The parameter eta of the point of the mortar `segment` on the line through `point` along
/// `direction` (Newton on cross(x(eta) - point, direction) = 0, from the midpoint; exact in one
/// step for straight segments). NaN when Newton fails (a segment parallel to the direction).
double project_along(const Side& side, int segment, const Eigen::Vector2d& point,
                     const Eigen::Vector2d& direction) {
  double eta = 0.0;
  for (int step = 0; step < 30; ++step) {
    const SegmentPoint at = evaluate(side, segment, eta);
    const double residual = cross(at.position - point, direction);
    const double slope = cross(at.tangent, direction);
    if (std::abs(slope) < 1e-14 * at.tangent.norm()) return std::nan("");
    const double change = residual / slope;
    eta -= change;
    if (std::abs(change) < parameter_tolerance(point, at)) return eta;
  }
  return std::nan("");
}

/// The parameter xi of the non-mortar `segment` whose normal line passes through `point`
/// (Newton with a central-difference slope on cross(x(xi) - point, n(xi)) = 0).
double project_onto_normal_field(const Side& side, int segment, const Eigen::Vector2d& point) {
  const auto residual = [&](double xi) {
    const SegmentPoint at = evaluate(side, segment, xi);
    return cross(at.position - point, normal_field(side, segment, at.values));
  };
  double xi = 0.0;
  for (int step = 0; step < 40; ++step) {
    constexpr double delta = 1e-7;
    const double slope = (residual(xi + delta) - residual(xi - delta)) / (2.0 * delta);
    if (!(std::abs(slope) > 0.0)) return std::nan("");
    const double change = residual(xi) / slope;
    xi -= change;
    if (std::abs(change) < parameter_tolerance(point, evaluate(side, segment, xi))) return xi;
  }
  return std::nan("");
}

/// Dual basis coefficients A = diag(int phi) M_e^{-1} of a non-mortar segment (psi = A phi).
Eigen::MatrixXd dual_coefficients(const Side& side, int segment) {
  const int count = side.nodes_per_segment();
  Eigen::MatrixXd mass = Eigen::MatrixXd::Zero(count, count);
  for (const QuadraturePoint& gauss : edge_quadrature(8)) {
    const SegmentPoint at = evaluate(side, segment, gauss.reference.x());
    mass += gauss.weight * at.tangent.norm() * at.values * at.values.transpose();
  }
  const Eigen::VectorXd integrals = mass.rowwise().sum();
  return integrals.asDiagonal() * mass.inverse();
}

/// The bounding-box tree of a side's segments (indices = segment numbers).
BoxTree segment_tree(const Side& side);

Box segment_box(const Side& side, int segment) {
  Eigen::Vector2d low = side.coordinates(side.node(segment, 0)), high = low;
  for (int a = 1; a < side.nodes_per_segment(); ++a) {
    low = low.cwiseMin(side.coordinates(side.node(segment, a)));
    high = high.cwiseMax(side.coordinates(side.node(segment, a)));
  }
  return {corner(low), corner(high)};
}

BoxTree segment_tree(const Side& side) {
  std::vector<Box> boxes;
  for (int segment = 0; segment < side.segment_count(); ++segment) {
    boxes.push_back(segment_box(side, segment));
  }
  return BoxTree(std::move(boxes));
}

double segment_length(const Side& side, int segment) {
  double length = 0.0;
  for (const QuadraturePoint& gauss : edge_quadrature(8)) {
    length += gauss.weight * evaluate(side, segment, gauss.reference.x()).tangent.norm();
  }
  return length;
}

double mean_segment_length(const Side& side) {
  double total = 0.0;
  for (int segment = 0; segment < side.segment_count(); ++segment) {
    total += segment_length(side, segment);
  }
  return side.segment_count() > 0 ? total / side.segment_count() : 0.0;
}

/// Where to look for the mortar segments of a non-mortar segment or node: along the normals
/// out to `reach` on both sides (four of the longest segments, or a twentieth of the two
/// boundaries' extent if that is larger), and one longest segment tangentially, so that a query
/// sees the segments near the normal rays only, whatever the boundaries' extent.
struct SearchRange {
  double reach = 0.0;
  double slack = 0.0;  // the longest segment of either side

  SearchRange(const Side& nonmortar, const Side& mortar) {
    Eigen::Vector2d low = nonmortar.coordinates(0), high = low;
    for (const Side* side : {&nonmortar, &mortar}) {
      for (int segment = 0; segment < side->segment_count(); ++segment) {
        const double length = segment_length(*side, segment);
        slack = std::max(slack, length);
        const auto [box_low, box_high] = segment_box(*side, segment);
        low = low.cwiseMin(box_low.head<2>());
        high = high.cwiseMax(box_high.head<2>());
      }
    }
    reach = std::max(4.0 * slack, 0.05 * (high - low).norm());
  }

  /// The box swept by the normal rays of `points` (with their `normals`) out to +-reach, widened
  /// by the slack.
  Box box(const std::vector<Eigen::Vector2d>& points,
          const std::vector<Eigen::Vector2d>& normals) const {
    Eigen::Vector2d low = points.front(), high = low;
    for (std::size_t k = 0; k < points.size(); ++k) {
      for (const double distance : {-reach, reach}) {
        low = low.cwiseMin(points[k] + distance * normals[k]);
        high = high.cwiseMax(points[k] + distance * normals[k]);
      }
    }
    const Eigen::Vector2d margin(slack, slack);
    return {corner(low - margin), corner(high + margin)};
  }
};

/// Segment-to-segment integration over the overlap of non-mortar `segment` and mortar
/// segment `other`, added to `coupling`.
void integrate_overlap(const Side& nonmortar, int segment, const Eigen::MatrixXd& dual,
                       const Side& mortar, int other, const GapFunction* gap,
                       FaceCoupling& coupling) {
  const int ends = 2;  // the endpoints are local nodes 0 and 1 for line2 and line3
  double low = 2.0, high = -2.0;
  for (int end = 0; end < ends; ++end) {
    const double xi =
        project_onto_normal_field(nonmortar, segment, mortar.coordinates(mortar.node(other, end)));
    if (std::isnan(xi)) return;
    low = std::min(low, xi);
    high = std::max(high, xi);
  }
  low = std::max(low, -1.0);
  high = std::min(high, 1.0);
  if (high - low < 1e-12) return;
  const int count = nonmortar.nodes_per_segment();
  for (const QuadraturePoint& gauss : edge_quadrature(10)) {
    const double xi = low + 0.5 * (gauss.reference.x() + 1.0) * (high - low);
    const SegmentPoint at = evaluate(nonmortar, segment, xi);
    const Eigen::Vector2d normal = normal_field(nonmortar, segment, at.values);
    const double eta = project_along(mortar, other, at.position, normal);
    if (std::isnan(eta) || std::abs(eta) > 1.0 + 1e-9) continue;
    const SegmentPoint target = evaluate(mortar, other, eta);
    double distance = (target.position - at.position).dot(normal);
    if (gap != nullptr) distance += (*gap)(at.position.x(), at.position.y());
    const double measure = 0.5 * gauss.weight * (high - low) * at.tangent.norm();
    const ShapeValues dual_values = dual * at.values;
    for (int a = 0; a < count; ++a) {
      FaceRowIntegrals& row = coupling.rows[static_cast<std::size_t>(nonmortar.node(segment, a))];
      row.covered += measure * at.values[a];
      row.dual_gap += measure * dual_values[a] * distance;
      row.standard_gap += measure * at.values[a] * distance;
      for (int b = 0; b < count; ++b) {
        row.dual_nonmortar[nonmortar.node(segment, b)] += measure * dual_values[a] * at.values[b];
        row.standard_nonmortar[nonmortar.node(segment, b)] += measure * at.values[a] * at.values[b];
      }
      for (int l = 0; l < mortar.nodes_per_segment(); ++l) {
        row.dual_mortar[mortar.node(other, l)] += measure * dual_values[a] * target.values[l];
        row.standard_mortar[mortar.node(other, l)] += measure * at.values[a] * target.values[l];
      }
    }
  }
}

/// True when mortar segment `other` faces non-mortar segment `segment`: outward normals
/// opposed (taken at the midpoints; each segment has its body on the left).
bool facing(const Side& nonmortar, int segment, const Side& mortar, int other) {
  const Eigen::Vector2d tangent = evaluate(nonmortar, segment, 0.0).tangent;
  const Eigen::Vector2d other_tangent = evaluate(mortar, other, 0.0).tangent;
  const Eigen::Vector2d outward(tangent.y(), -tangent.x());
  const Eigen::Vector2d other_outward(other_tangent.y(), -other_tangent.x());
  return outward.dot(other_outward) < 0.0;
}

FaceCoupling integrate(const Side& nonmortar, const Side& mortar, const GapFunction* gap) {
  FaceCoupling coupling;
  coupling.rows.resize(nonmortar.interface->node_ids.size());
  const SearchRange range(nonmortar, mortar);
  const BoxTree tree = segment_tree(mortar);
  for (int segment = 0; segment < nonmortar.segment_count(); ++segment) {
    const Eigen::MatrixXd dual = dual_coefficients(nonmortar, segment);
    std::vector<Eigen::Vector2d> points, normals;
    for (int a = 0; a < nonmortar.nodes_per_segment(); ++a) {
      const int position = nonmortar.node(segment, a);
      points.push_back(nonmortar.coordinates(position));
      normals.push_back(nonmortar.normal(position));
    }
    for (const int other : tree.near(range.box(points, normals))) {
      if (!facing(nonmortar, segment, mortar, other)) {
        ++coupling.same_direction_candidates;
        continue;
      }
      ++coupling.facing_candidates;
      integrate_overlap(nonmortar, segment, dual, mortar, other, gap, coupling);
    }
  }
  return coupling;
}

/// Node-to-segment collocation: row j from the projection of node j along n_j.
FaceCoupling collocate(const Side& nonmortar, const Side& mortar, const GapFunction* gap) {
  FaceCoupling coupling;
  coupling.rows.resize(nonmortar.interface->node_ids.size());
  const SearchRange range(nonmortar, mortar);
  const BoxTree tree = segment_tree(mortar);
  for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
    const Eigen::Vector2d point = nonmortar.coordinates(static_cast<int>(j));
    const Eigen::Vector2d normal = nonmortar.normal(static_cast<int>(j));
    double best = std::numeric_limits<double>::infinity();
    for (const int other : tree.near(range.box({point}, {normal}))) {
      const double eta = project_along(mortar, other, point, normal);
      if (std::isnan(eta) || std::abs(eta) > 1.0 + 1e-9) continue;
      const SegmentPoint target = evaluate(mortar, other, eta);
      const double distance = (target.position - point).dot(normal);
      if (std::abs(distance) >= best) continue;
      best = std::abs(distance);
      FaceRowIntegrals row;
      row.covered = nonmortar.interface->weights[j];
      row.dual_nonmortar[static_cast<int>(j)] = row.covered;
      for (int l = 0; l < mortar.nodes_per_segment(); ++l) {
        row.dual_mortar[mortar.node(other, l)] = row.covered * target.values[l];
      }
      row.dual_gap = row.covered * (distance + (gap ? (*gap)(point.x(), point.y()) : 0.0));
      coupling.rows[j] = row;
    }
    if (std::isfinite(best)) ++coupling.facing_candidates;
  }
  return coupling;
}

/// The mortar integrals of two plane bodies' boundaries (segments).
FaceCoupling integrate_segments(const InterfaceDescription& nonmortar_description,
                                const InterfaceDescription& mortar_description,
                                const GapFunction* gap, MortarIntegration integration) {
  const Side nonmortar(nonmortar_description), mortar(mortar_description);
  return integration == MortarIntegration::segment_to_segment ? integrate(nonmortar, mortar, gap)
                                                              : collocate(nonmortar, mortar, gap);
}

/// A solid body's contact boundary (a description of that one boundary) as a MortarSurface: the
/// same node positions, the description's averaged normals and its outward-oriented faces.
MortarSurface mortar_surface(const InterfaceDescription& description) {
  MortarSurface surface;
  surface.coordinates = description.coordinates;
  surface.normals = description.normals;
  if (description.surfaces.empty()) return surface;
  surface.face_type = description.surfaces.front().facet_type;
  surface.faces = description.surfaces.front().facets;
  return surface;
}

/// The mean face size of a solid body's contact boundary: the square root of its mean face
/// area (0 without faces).
double mean_face_size(const InterfaceDescription& description) {
  const MortarSurface surface = mortar_surface(description);
  const std::size_t faces = surface.faces.size() / nodes_per_facet(surface.face_type);
  if (faces == 0) return 0.0;
  const std::vector<double> supports = support_integrals(surface);
  const double area = std::accumulate(supports.begin(), supports.end(), 0.0);
  return std::sqrt(area / static_cast<double>(faces));
}

/// The mortar integrals of two solid bodies' contact surfaces (face_mortar.hpp), the initial
/// gap g0(x, y) evaluated at the non-mortar point's x and y.
FaceCoupling integrate_faces(const InterfaceDescription& nonmortar,
                             const InterfaceDescription& mortar, const GapFunction* gap) {
  SpatialGap spatial_gap;
  if (gap != nullptr) {
    spatial_gap = [gap](const Eigen::Vector3d& point) {
      return (*gap)(point.x(), point.y(), point.z());
    };
  }
  return integrate_face_mortar(mortar_surface(nonmortar), mortar_surface(mortar), spatial_gap);
}

/// Throws InputError unless both bodies are plane or both solid, and node-to-segment
/// collocation is of plane bodies.
void require_supported(const InterfaceDescription& body1, const std::string& name1,
                       const InterfaceDescription& body2, const std::string& name2,
                       MortarIntegration integration) {
  const std::string bodies = "mortar coupling of bodies '" + name1 + "' and '" + name2 + "': ";
  if (body1.dimension != body2.dimension) {
    throw InputError(bodies + "bodies of different dimensions (" + std::to_string(body1.dimension) +
                     " and " + std::to_string(body2.dimension) + ") cannot be in contact");
  }
  if (body1.dimension == 3 && integration == MortarIntegration::node_to_segment) {
    throw InputError(bodies +
                     "node-to-segment collocation is for plane bodies only (use [contact] "
                     "method = \"mortar\" for solid bodies)");
  }
}

/// Throws InputError unless `description` has exactly one contact boundary with facets.
void require_one_boundary(const InterfaceDescription& description, const std::string& name) {
  if (description.surfaces.size() > 1) {
    throw InputError("mortar coupling: body '" + name + "' has " +
                     std::to_string(description.surfaces.size()) +
                     " contact boundaries; couple one boundary of each body "
                     "(restrict_to_boundary)");
  }
  if (description.surfaces.empty() || description.surfaces.front().facets.empty() ||
      description.node_ids.empty()) {
    throw InputError("mortar coupling: the contact boundary of body '" + name + "' has no " +
                     (description.dimension == 3 ? "faces" : "segments"));
  }
}

/// The row assembly's view of one side: the weights of a plane body's nodes, the support
/// integrals of a solid body's faces.
MortarSide mortar_side(const InterfaceDescription& description, const std::string& name, int body) {
  MortarSide side{&description, name, body, description.weights};
  if (description.dimension == 3) side.support = support_integrals(mortar_surface(description));
  return side;
}

}  // namespace

int finer_side(const InterfaceDescription& body1, const InterfaceDescription& body2) {
  if (body1.dimension == 3) return mean_face_size(body2) < mean_face_size(body1) ? 1 : 0;
  const Side first(body1), second(body2);
  return mean_segment_length(second) < mean_segment_length(first) ? 1 : 0;
}

ContactPairing build_mortar_coupling(const InterfaceDescription& body1, const std::string& name1,
                                     const InterfaceDescription& body2, const std::string& name2,
                                     const GapFunction* gap, const MortarOptions& options) {
  require_one_boundary(body1, name1);
  require_one_boundary(body2, name2);
  require_supported(body1, name1, body2, name2, options.integration);
  const int nonmortar_body =
      options.non_mortar_body >= 0 ? options.non_mortar_body : finer_side(body1, body2);
  const MortarSide nonmortar =
      nonmortar_body == 0 ? mortar_side(body1, name1, 0) : mortar_side(body2, name2, 1);
  const MortarSide mortar =
      nonmortar_body == 0 ? mortar_side(body2, name2, 1) : mortar_side(body1, name1, 0);
  const bool solid = body1.dimension == 3;
  const FaceCoupling coupling =
      solid ? integrate_faces(*nonmortar.interface, *mortar.interface, gap)
            : integrate_segments(*nonmortar.interface, *mortar.interface, gap, options.integration);
  const FacetType facet_type = nonmortar.interface->surfaces.front().facet_type;
  return assemble_mortar_rows(nonmortar, mortar, coupling, dual_row_of(facet_type));
}

}  // namespace robin
