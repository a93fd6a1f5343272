#pragma once
// One contact interface of a case: body a's contact boundary against body b's, and how the two
// are coupled into constraint rows (node-to-node pairing or mortar, contact_discretization.hpp).
// A case of two bodies without [[interface]] tables has one interface, body 1 against body 2;
// a contact graph (contact_graph.hpp) has one per edge.

#include <optional>
#include <string>

#include "coupling/contact_discretization.hpp"

namespace robin {

/// One contact interface as a case names it: body a's boundary `boundary_a` against body b's
/// `boundary_b` (body indices 0-based). For pairing and mortar, body a plays body 1's part.
struct InterfaceDefinition {
  int body_a = 0;
  int body_b = 1;
  std::string boundary_a;
  std::string boundary_b;
  /// This interface's coupling method and non-mortar side; nothing: the run's [contact] table.
  std::optional<ContactOptions> contact = std::nullopt;
};

}  // namespace robin
