#pragma once
// Node-to-node pairing of the two contact boundaries (matching meshes on the contact zone).
// For each pair i: the body-1 normal n1_i (unit; body 2 uses n2_i = -n1_i), taken as the
// normalised average of body 1's outward normal and minus body 2's; the initial normal gap
//   d_i = (x2_i - x1_i) . n1_i + g0(x1_i)
// and the boundary weight m_i (average of both sides). A pair whose normal displacement is
// prescribed on either side by Dirichlet conditions is excluded (reported in `excluded`): its
// normal displacement is data, not an unknown of the contact problem (typically the corner
// where a clamped side meets the contact boundary). Its clearance is checked on the solution
// (excluded_pair_clearance): a prescribed displacement that drives one body into the other is
// reported, never solved silently. A negative gap d_i < 0 is an initial overlap (an
// interference fit): legal, solved by pushing the bodies apart, and reported (overlap_warning).

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "coupling/gap_function.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/errors.hpp"

namespace robin {

/// One contact constraint (a row of B1 u1 + B2 u2 <= d): a node pair for node-to-node
/// pairing, a non-mortar node's weighted constraint for mortar coupling.
struct ContactPair {
  int node1 = -1;  // mesh node index in body 1 (node-to-node; mortar: the non-mortar node or -1)
  int node2 = -1;  // mesh node index in body 2 (node-to-node; mortar: the non-mortar node or -1)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();   // body-1 node (z = 0 in 2D)
  Eigen::Vector3d position2 = Eigen::Vector3d::Zero();  // body-2 node
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();     // n1 (unit, outward from body 1)
  double gap = 0.0;                                     // d_i (length)
  double weight = 0.0;                                  // m_i (length in 2D, area in 3D)
};

struct ContactPairing {
  std::vector<ContactPair> pairs;
  std::vector<std::string> excluded;        // one line per excluded pair, with the reason
  std::vector<ContactPair> excluded_pairs;  // the same pairs, in the same order
  /// The constraint operators B1, B2 (one row per pair, in pair order) when they are not the
  /// node-to-node rows of `pairs` (mortar coupling); empty for node-to-node pairing.
  std::array<ContactOperator, 2> operators;
  /// Mortar coupling: the body (0 or 1) carrying the multipliers, and how many of its contact
  /// nodes face no part of the other body (no constraint). -1 and 0 for node-to-node pairing.
  int non_mortar_body = -1;
  int uncovered = 0;
  /// The bodies' dimension (2 or 3): how many coordinates the messages give.
  int dimension = 2;

  std::size_t size() const { return pairs.size(); }
  /// The constraint operator of body 0 or 1: `operators` when set, otherwise the node-to-node
  /// rows (n1 at node1 for body 0, -n1 at node2 for body 1), weights m_i.
  ContactOperator assignment(int body_index) const;
  Eigen::VectorXd gaps() const;
  Eigen::VectorXd weights() const;
};

/// Some contact node has no partner on the other side (the meshes do not match there).
class UnmatchedContactNodes : public InputError {
 public:
  using InputError::InputError;
};

/// Pairs the two interfaces. `gap` may be null. A body-1 node matches the body-2 node whose
/// offset from it is, up to the normal component, shorter than relative_tolerance times the
/// shortest contact edge; every node of both sides must be matched. Throws
/// UnmatchedContactNodes naming the first unmatched node (body, mesh node tag, coordinates), or
/// when every pair is excluded (the contact boundary is a Dirichlet boundary: nothing is left for
/// contact).
ContactPairing pair_contact_nodes(const InterfaceDescription& body1, const std::string& name1,
                                  const InterfaceDescription& body2, const std::string& name2,
                                  const GapFunction* gap, double relative_tolerance);

/// True when the prescribed components of a contact node (`fixed`: u_x, u_y, u_z, as in
/// InterfaceDescription::fixed) fix its displacement along `normal`: some component is
/// prescribed and every component of `normal` (up to 1e-12) is along a prescribed one. Its
/// normal displacement is then data, not a contact unknown.
bool normal_is_prescribed(const std::array<bool, 3>& fixed, const Eigen::Vector3d& normal);

/// Throws InputError "<method> of bodies 'a' and 'b': all N <rows> have their normal
/// displacement prescribed ..." when every constraint of `pairing` was excluded.
void require_constraints_left(const ContactPairing& pairing, const std::string& method,
                              const std::string& rows, const std::string& name1,
                              const std::string& name2);

/// The order of `points` along the principal direction of their spread (a curve parameter for
/// flat and gently curved zones, so that contact.csv reads as a profile): indices into points.
/// Points all at z = 0 (every 2D zone) are ordered in the plane, others by the principal
/// direction of their spread in space.
std::vector<std::size_t> order_along_zone(const std::vector<Eigen::Vector3d>& points);

/// "" when every gap d_i >= 0 (up to round-off: -1e-12 of the contact zone's length); otherwise
/// one line for the log and summary.json: how many pairs overlap initially, the largest overlap
/// and where.
std::string overlap_warning(const ContactPairing& pairing);

/// The clearance of the excluded pairs in a solution: the largest penetration
/// u1.n1 + u2.n2 - d_i over them, relative to the displacement scale: the larger of
/// `included_scale` (the caller's largest |d_i| and |u.n| over the included pairs) and the
/// largest |d_i| and |u.n| at the excluded pairs. `displacement_of(body_index, pair)` is the
/// displacement vector of body `body_index`'s (0 or 1) node of an excluded pair.
struct ExcludedPairClearance {
  double relative_penetration = 0.0;  // 0 when no excluded pair penetrates
  std::string description;            // the worst pair, "" when none penetrates
};
using PairDisplacement = std::function<Eigen::Vector3d(int body_index, const ContactPair& pair)>;
ExcludedPairClearance excluded_pair_clearance(const ContactPairing& pairing,
                                              const PairDisplacement& displacement_of,
                                              double included_scale);
/// Largest relative penetration of an excluded pair that still counts as touching (round-off
/// of the solution); above it the tools report an error.
inline constexpr double excluded_pair_penetration_limit = 1e-6;

}  // namespace robin
