#pragma once
// Decoding of the servers' replies into the coordinator's types (part of robin_remote's
// protocol module). Every function checks the sizes and indices it relies on, that the
// interface vectors are finite and that contact forces are compressive (lambda >= 0), and throws
// MalformedReply saying what is inconsistent; the port adds server, body and step (a NaN from a
// third-party server is named where it arrives, not found later as a diverged iteration).

#include <stdexcept>
#include <string>

#include "coupling/subdomain_port.hpp"
#include "robin.pb.h"

namespace robin {

class MalformedReply : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The body's contact boundaries, of dimension 2 or 3 (`dimension` coordinates, normals and
/// fixed flags per node). Node ids, coordinates, normals, weights and fixed flags must
/// describe the same number of nodes; one surface per contact boundary (at least one, names
/// distinct), its segments' positions in range. Each surface's own nodes, normals and weights
/// are filled in (fill_surface_nodes), so restrict_to_boundary() works on the result.
InterfaceDescription decode_interface(const protocol::InterfaceDescription& message);

/// A contact solve result for `contact_size` contact nodes (pair order). `active` defaults to
/// lambda_i > 0 when the server sends no flags.
ContactSolveResult decode_contact_result(const protocol::ContactSolveResult& message,
                                         long contact_size);

/// A correction result w_N for `contact_size` contact nodes.
CorrectionSolveResult decode_correction_result(const protocol::CorrectionResult& message,
                                               long contact_size);

/// A Neumann solve result u_N (protocol 1.1) for `contact_size` contact nodes.
CorrectionSolveResult decode_neumann_result(const protocol::NeumannSolveResult& message,
                                            long contact_size);

/// The body's mesh (FieldsReply.dimension, 2 when absent; nodes, tags, element blocks from the
/// VTK cell types 5, 22, 9 in 2D and 10, 24, 12 in 3D, the quadratic tetrahedra's nodes back in
/// Gmsh's order, and the named boundaries when the reply has them) and fields. A 6-component stress
/// field gets the component names XX, YY, ZZ, XY, YZ, XZ, a 3-component one (older servers) xx, yy,
/// xy. A reply without mesh and fields (no nodes, cell types or offsets: protocol 2.5,
/// FieldsRequest.omit_fields_from_reply) gives an empty mesh and no fields, with the resultants.
/// Throws MalformedReply for a size, index, cell type or boundary name that does not fit.
BodyOutput decode_fields(const protocol::FieldsReply& message, const std::string& body_name);

/// The element type of a VTK cell type number (5, 22 or 9; 10, 24 or 12 for the solid elements);
/// throws MalformedReply otherwise.
ElementType element_type_of_vtk_cell(unsigned cell_type);

}  // namespace robin
