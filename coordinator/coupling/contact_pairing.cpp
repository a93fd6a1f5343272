#include "coupling/contact_pairing.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "coupling/case_file_body.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

/// "(x, y)" in 2D, "(x, y, z)" in 3D.
std::string format_point(const Eigen::Vector3d& point, int dimension) {
  std::ostringstream stream;
  stream.precision(10);
  stream << "(" << point.x() << ", " << point.y();
  if (dimension == 3) stream << ", " << point.z();
  stream << ")";
  return stream.str();
}

/// Shortest distance between two distinct contact nodes of one side: the length scale of the
/// matching tolerance.
double shortest_spacing(const std::vector<Eigen::Vector3d>& points) {
  double shortest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); ++j) {
      const double distance = (points[i] - points[j]).norm();
      if (distance > 0) shortest = std::min(shortest, distance);
    }
  }
  return std::isfinite(shortest) ? shortest : 1.0;
}

/// Index of the body-2 node whose offset from `point`, less its component along `normal`, is
/// the shortest and below `tolerance`; -1 if none.
int find_partner(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                 const InterfaceDescription& other, double tolerance) {
  int best = -1;
  double best_offset = tolerance;
  for (std::size_t j = 0; j < other.coordinates.size(); ++j) {
    const Eigen::Vector3d offset = other.coordinates[j] - point;
    const double tangential = (offset - offset.dot(normal) * normal).norm();
    if (tangential <= best_offset) {
      best_offset = tangential;
      best = static_cast<int>(j);
    }
  }
  return best;
}

/// Orders pairs along the principal direction of the contact zone.
void order_pairs_along_zone(std::vector<ContactPair>& pairs) {
  std::vector<Eigen::Vector3d> points;
  for (const ContactPair& pair : pairs) points.push_back(pair.position);
  std::vector<ContactPair> ordered;
  for (const std::size_t k : order_along_zone(points)) ordered.push_back(pairs[k]);
  pairs = std::move(ordered);
}

std::string describe_node(const std::string& body, std::size_t tag, const Eigen::Vector3d& point,
                          int dimension) {
  return "body '" + body + "' contact node (tag " + std::to_string(tag) + ") at " +
         format_point(point, dimension);
}

/// Throws InputError when the outward normals of paired nodes do not oppose each other
/// (n1 . n2 >= 0): the bodies would lie on the same side of the contact boundary, and the pair's
/// normal n1 - n2 would be meaningless.
void require_facing(const InterfaceDescription& body1, std::size_t i, const std::string& name1,
                    const InterfaceDescription& body2, std::size_t j, const std::string& name2) {
  if (body1.normals[i].dot(body2.normals[j]) < 0.0) return;
  throw InputError("contact pairing: the contact boundaries of bodies '" + name1 + "' and '" +
                   name2 + "' do not face each other: their outward normals point the same way (" +
                   describe_node(name1, body1.node_tags[i], body1.coordinates[i], body1.dimension) +
                   " has the outward normal " + format_point(body1.normals[i], body1.dimension) +
                   " and its partner, " +
                   describe_node(name2, body2.node_tags[j], body2.coordinates[j], body2.dimension) +
                   ", the outward normal " + format_point(body2.normals[j], body2.dimension) +
                   "); each contact boundary must be the side of its body that touches the other "
                   "body: check which side of each body the contact boundary is on");
}

}  // namespace

std::string overlap_warning(const ContactPairing& pairing) {
  // Gaps computed from coordinates carry their round-off: on an inclined or curved boundary a
  // touching pair's gap is +-1e-16 rather than 0. Below 1e-12 of the zone's length (the sum of
  // the weights) an overlap is round-off, not an interference fit, and is not reported (it is
  // solved all the same).
  double zone_length = 0.0;
  for (const ContactPair& pair : pairing.pairs) zone_length += pair.weight;
  const double round_off = 1e-12 * zone_length;
  int overlapping = 0;
  const ContactPair* deepest = nullptr;
  for (const ContactPair& pair : pairing.pairs) {
    if (pair.gap >= -round_off) continue;
    ++overlapping;
    if (deepest == nullptr || pair.gap < deepest->gap) deepest = &pair;
  }
  if (deepest == nullptr) return "";
  std::ostringstream text;
  text << overlapping << " of " << pairing.size()
       << " contact pairs overlap initially (negative gap; the largest overlap is " << -deepest->gap
       << " at " << format_point(deepest->position, pairing.dimension)
       << "): the bodies are pushed apart, as in an interference fit; if that is not intended, "
          "check the meshes and the [gap] expression";
  return text.str();
}

ExcludedPairClearance excluded_pair_clearance(const ContactPairing& pairing,
                                              const PairDisplacement& displacement_of,
                                              double included_scale) {
  std::vector<double> normal1, normal2;  // u1.n1 and u2.n1 at the excluded pairs
  double scale = std::max(included_scale, std::numeric_limits<double>::min());
  for (const ContactPair& pair : pairing.excluded_pairs) {
    normal1.push_back(displacement_of(0, pair).dot(pair.normal));
    normal2.push_back(displacement_of(1, pair).dot(pair.normal));
    scale =
        std::max({scale, std::abs(pair.gap), std::abs(normal1.back()), std::abs(normal2.back())});
  }
  ExcludedPairClearance clearance;
  for (std::size_t k = 0; k < pairing.excluded_pairs.size(); ++k) {
    const double penetration = normal1[k] - normal2[k] - pairing.excluded_pairs[k].gap;
    if (penetration / scale <= clearance.relative_penetration) continue;
    clearance.relative_penetration = penetration / scale;
    clearance.description = pairing.excluded[k] +
                            ": the prescribed displacements drive the bodies into each other by " +
                            format_number(penetration) +
                            " there (an excluded pair is not a contact constraint; do not "
                            "prescribe the normal displacement of contact nodes)";
  }
  return clearance;
}

bool normal_is_prescribed(const std::array<bool, 3>& fixed, const Eigen::Vector3d& normal) {
  // In 2D (u_z free, n_z = 0): both components prescribed, or one and the normal along it.
  constexpr double aligned = 1e-12;
  bool any = false;
  for (int component = 0; component < 3; ++component) {
    const bool prescribed = fixed[static_cast<std::size_t>(component)];
    any = any || prescribed;
    if (!prescribed && !(std::abs(normal[component]) < aligned)) return false;
  }
  return any;
}

void require_constraints_left(const ContactPairing& pairing, const std::string& method,
                              const std::string& rows, const std::string& name1,
                              const std::string& name2) {
  if (!pairing.pairs.empty()) return;
  throw InputError(method + " of bodies '" + name1 + "' and '" + name2 + "': all " +
                   std::to_string(pairing.excluded.size()) + " " + rows +
                   " have their normal displacement prescribed by Dirichlet conditions (first: " +
                   pairing.excluded.front() +
                   "), so no contact is left to solve; the contact boundary must not be a "
                   "Dirichlet boundary (check contact_boundary and dirichlet of both bodies)");
}

namespace {

/// The principal direction of `points`' spread (their mean in `mean`), signed so that its first
/// nonzero component is positive.
template <int Size>
Eigen::Matrix<double, Size, 1> principal_direction(
    const std::vector<Eigen::Matrix<double, Size, 1>>& points,
    Eigen::Matrix<double, Size, 1>& mean) {
  using Vector = Eigen::Matrix<double, Size, 1>;
  using Matrix = Eigen::Matrix<double, Size, Size>;
  mean = Vector::Zero();
  for (const Vector& point : points) mean += point;
  mean /= static_cast<double>(points.size());
  Matrix scatter = Matrix::Zero();
  for (const Vector& point : points) scatter += (point - mean) * (point - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Matrix> eigen(scatter);
  Vector direction = eigen.eigenvectors().col(Size - 1);
  for (int component = 0; component < Size; ++component) {
    if (direction[component] == 0) continue;
    if (direction[component] < 0) direction = -direction;
    break;
  }
  return direction;
}

template <int Size>
std::vector<std::size_t> order_along_principal_direction(
    const std::vector<Eigen::Matrix<double, Size, 1>>& points) {
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  if (points.size() < 2) return order;
  Eigen::Matrix<double, Size, 1> mean;
  const Eigen::Matrix<double, Size, 1> direction = principal_direction<Size>(points, mean);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return (points[a] - mean).dot(direction) < (points[b] - mean).dot(direction);
  });
  return order;
}

}  // namespace

std::vector<std::size_t> order_along_zone(const std::vector<Eigen::Vector3d>& points) {
  const bool planar = std::all_of(points.begin(), points.end(),
                                  [](const Eigen::Vector3d& point) { return point.z() == 0.0; });
  if (!planar) return order_along_principal_direction<3>(points);
  std::vector<Eigen::Vector2d> plane;
  plane.reserve(points.size());
  for (const Eigen::Vector3d& point : points) plane.emplace_back(point.head<2>());
  return order_along_principal_direction<2>(plane);
}

ContactOperator ContactPairing::assignment(int body_index) const {
  if (operators[static_cast<std::size_t>(body_index)].row_count() > 0) {
    return operators[static_cast<std::size_t>(body_index)];
  }
  const double sign = body_index == 0 ? 1.0 : -1.0;
  std::vector<int> nodes;
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> weights;
  for (const ContactPair& pair : pairs) {
    nodes.push_back(body_index == 0 ? pair.node1 : pair.node2);
    normals.push_back(sign * pair.normal);
    weights.push_back(pair.weight);
  }
  return node_to_node_operator(nodes, normals, weights);
}

Eigen::VectorXd ContactPairing::gaps() const {
  Eigen::VectorXd values(static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t i = 0; i < pairs.size(); ++i) values[i] = pairs[i].gap;
  return values;
}

Eigen::VectorXd ContactPairing::weights() const {
  Eigen::VectorXd values(static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t i = 0; i < pairs.size(); ++i) values[i] = pairs[i].weight;
  return values;
}

ContactPairing pair_contact_nodes(const InterfaceDescription& body1, const std::string& name1,
                                  const InterfaceDescription& body2, const std::string& name2,
                                  const GapFunction* gap, double relative_tolerance) {
  if (body1.node_ids.empty() || body2.node_ids.empty()) {
    throw InputError("contact pairing: body '" + (body1.node_ids.empty() ? name1 : name2) +
                     "' has no contact nodes");
  }
  const double tolerance = relative_tolerance * std::min(shortest_spacing(body1.coordinates),
                                                         shortest_spacing(body2.coordinates));
  if (body1.dimension != body2.dimension) {
    throw InputError("contact pairing: body '" + name1 + "' is " + std::to_string(body1.dimension) +
                     "-dimensional and body '" + name2 + "' " + std::to_string(body2.dimension) +
                     "-dimensional: bodies in contact must have the same dimension");
  }
  std::vector<int> partner_of_second(body2.node_ids.size(), -1);
  ContactPairing pairing;
  pairing.dimension = body1.dimension;
  for (std::size_t i = 0; i < body1.node_ids.size(); ++i) {
    const Eigen::Vector3d& point = body1.coordinates[i];
    const int j = find_partner(point, body1.normals[i], body2, tolerance);
    if (j < 0 || partner_of_second[j] >= 0) {
      throw UnmatchedContactNodes(
          "contact pairing: " + describe_node(name1, body1.node_tags[i], point, body1.dimension) +
          " has no matching node on body '" + name2 + "' within " + format_number(tolerance) +
          " (node-to-node pairing needs matching meshes: use [contact] method = \"mortar\" or "
          "\"auto\" for non-matching ones)");
    }
    partner_of_second[j] = static_cast<int>(i);
    ContactPair pair;
    pair.node1 = body1.node_ids[i];
    pair.node2 = body2.node_ids[j];
    pair.position = point;
    pair.position2 = body2.coordinates[j];
    pair.normal = (body1.normals[i] - body2.normals[j]).normalized();
    pair.gap = (body2.coordinates[j] - point).dot(pair.normal);
    if (gap != nullptr) pair.gap += (*gap)(point.x(), point.y(), point.z());
    pair.weight = 0.5 * (body1.weights[i] + body2.weights[j]);
    const bool fixed1 = normal_is_prescribed(body1.fixed[i], pair.normal);
    const bool fixed2 = normal_is_prescribed(body2.fixed[static_cast<std::size_t>(j)], pair.normal);
    if (fixed1 || fixed2) {
      pairing.excluded.push_back(
          describe_node(fixed1 ? name1 : name2, fixed1 ? body1.node_tags[i] : body2.node_tags[j],
                        point, pairing.dimension) +
          ": normal displacement prescribed by a Dirichlet condition; pair excluded from contact");
      pairing.excluded_pairs.push_back(pair);
      continue;
    }
    // After the exclusions: a contact boundary held entirely by Dirichlet conditions is
    // reported as such (require_constraints_left), whichever way its normals point.
    require_facing(body1, i, name1, body2, static_cast<std::size_t>(j), name2);
    pairing.pairs.push_back(pair);
  }
  require_constraints_left(pairing, "contact pairing", "node pairs", name1, name2);
  for (std::size_t j = 0; j < body2.node_ids.size(); ++j) {
    if (partner_of_second[j] < 0) {
      throw UnmatchedContactNodes(
          "contact pairing: " +
          describe_node(name2, body2.node_tags[j], body2.coordinates[j], body2.dimension) +
          " has no matching node on body '" + name1 + "'");
    }
  }
  order_pairs_along_zone(pairing.pairs);
  return pairing;
}

}  // namespace robin
