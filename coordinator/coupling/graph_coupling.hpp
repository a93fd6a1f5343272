#pragma once
// The constraint rows of a contact graph (contact_graph.hpp) from its bodies' contact boundaries:
// each interface is discretized on its own (node-to-node pairing or mortar coupling,
// contact_discretization.hpp) between the named boundary of each of its two bodies, and each
// body's operator B^alpha stacks the rows of its interfaces in interface order (body order).

#include <string>
#include <vector>

#include "coupling/contact_discretization.hpp"
#include "coupling/contact_interface.hpp"
#include "coupling/coupling_scheme.hpp"

namespace robin {

struct GraphCoupling {
  std::vector<ContactPairing> pairings;    // per interface, its rows in global order
  std::vector<ContactOperator> operators;  // per body, its rows in body order
  CouplingProblem problem;  // graph, gaps, weights, probe forces (global order), rigid modes
};

/// Discretizes every interface of `interfaces` between the bodies described by `bodies`
/// (their InterfaceDescriptions, with one surface per contact boundary; `names` for messages).
/// `gap` may be null; `options` couples every interface that has no contact options of its own.
/// With one interface, errors are those of discretize_contact. Throws InputError naming the
/// interface, bodies and boundaries (an unknown boundary, unmatched nodes, boundaries that do not
/// face each other).
GraphCoupling couple_contact_graph(const std::vector<InterfaceDescription>& bodies,
                                   const std::vector<std::string>& names,
                                   const std::vector<InterfaceDefinition>& interfaces,
                                   const GapFunction* gap, const ContactOptions& options,
                                   double pairing_tolerance);

}  // namespace robin
