#pragma once
// The constraint rows of a contact graph (contact_graph.hpp) from its bodies' contact boundaries:
// each interface is discretized on its own (node-to-node pairing or mortar coupling,
// contact_discretization.hpp) between the named boundary of each of its two bodies, and each
// body's operator B^alpha stacks the rows of its interfaces in interface order (body order).

#include <string>
#include <vector>

#include "coupling/contact_discretization.hpp"
#include "coupling/coupling_scheme.hpp"

namespace robin {

/// One contact interface as a case names it: body a's boundary `boundary_a` against body b's
/// `boundary_b` (body indices 0-based). For pairing and mortar, body a plays body 1's part.
struct InterfaceDefinition {
  int body_a = 0;
  int body_b = 1;
  std::string boundary_a;
  std::string boundary_b;
};

struct GraphCoupling {
  std::vector<ContactPairing> pairings;    // per interface, its rows in global order
  std::vector<ContactOperator> operators;  // per body, its rows in body order
  CouplingProblem problem;  // graph, gaps, weights, probe forces (global order), rigid modes
};

/// Discretizes every interface of `interfaces` between the bodies described by `bodies`
/// (their InterfaceDescriptions, with one surface per contact boundary; `names` for messages).
/// `gap` may be null. Throws InputError naming the interface, bodies and boundaries (an unknown
/// boundary, unmatched nodes, boundaries that do not face each other).
GraphCoupling couple_contact_graph(const std::vector<InterfaceDescription>& bodies,
                                   const std::vector<std::string>& names,
                                   const std::vector<InterfaceDefinition>& interfaces,
                                   const GapFunction* gap, const ContactOptions& options,
                                   double pairing_tolerance);

}  // namespace robin
