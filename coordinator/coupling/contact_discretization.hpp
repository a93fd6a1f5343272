#pragma once
// How the two contact boundaries are coupled into constraint rows B1 u1 + B2 u2 <= d: node-to-
// node pairing (matching meshes, coupling/contact_pairing.hpp) or mortar coupling
// (non-matching meshes, coupling/mortar_coupling.hpp). The Robin iteration, the monolithic
// reference and the servers only see the rows.

#include <string>

#include "coupling/contact_pairing.hpp"
#include "coupling/gap_function.hpp"
#include "coupling/mortar_coupling.hpp"

namespace robin {

enum class ContactMethod {
  automatic,        // node-to-node when every node has a partner, mortar otherwise
  node_to_node,     // matching meshes only; an unmatched node is an error
  mortar,           // segment-to-segment mortar, dual multipliers
  node_to_segment,  // collocation at the non-mortar nodes: for comparison, fails the patch test
};

/// The case file's [contact] table (docs/case-format.md).
struct ContactOptions {
  ContactMethod method = ContactMethod::automatic;
  /// The body whose contact boundary carries the multipliers (mortar, node-to-segment); empty:
  /// the finer side.
  std::string non_mortar;
};

/// The constraint rows of the two bodies' contact boundaries by `options.method`
/// (`pairing_tolerance`: the node-to-node matching tolerance, [solver] pairing_tolerance). Throws
/// InputError naming the bodies (unmatched nodes for node_to_node, boundaries that do not
/// face each other for mortar, an unknown non_mortar body name).
ContactPairing discretize_contact(const InterfaceDescription& body1, const std::string& name1,
                                  const InterfaceDescription& body2, const std::string& name2,
                                  const GapFunction* gap, const ContactOptions& options,
                                  double pairing_tolerance);

/// One line for logs and summary.json: "node-to-node pairing, 43 pairs" or "mortar coupling
/// (non-mortar side: body 'x'), 61 constraints, 2 nodes of 'x' face no part of 'y'".
std::string describe_contact(const ContactPairing& pairing, const std::string& name1,
                             const std::string& name2);

}  // namespace robin
