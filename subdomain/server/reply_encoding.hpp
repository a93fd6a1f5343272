#pragma once
// Encoding of the numerics' results into the server's replies, and decoding of the repeated
// fields of requests (part of the server's protocol module: the generated types stop here).

#include <Eigen/Core>
#include <string>

#include "numerics/body_output.hpp"
#include "numerics/body_solver.hpp"
#include "robin.pb.h"

namespace robin {

/// The contact boundaries as InterfaceDescription: per-node values in the order of
/// interface.node_ids, interleaved (x, y) vectors; one ContactSurface per contact boundary, in
/// the order of interface.surfaces.
void encode_interface(const std::string& body_name, const InterfaceDescription& interface,
                      protocol::InterfaceDescription& message);

/// A contact solve result; compute_seconds = result.seconds.
void encode_contact_result(const ContactSolveResult& result, protocol::ContactSolveResult& message);

protocol::SolveStatus to_protocol(QpStatus status);

/// The body's mesh and fields: node coordinates and tags, one cell block per element block
/// (VTK types 5, 22, 9; cell_offsets has blocks + 1 entries into connectivity), point and cell
/// fields, reaction resultant and applied force, and the mesh's named boundaries (their segments
/// as node indices, for the line cells of the output).
void encode_fields(const BodyOutput& output, protocol::FieldsReply& message);

/// Only the reaction resultant, the applied force and the dimension (3 for a solid body, absent
/// for a plane one): the reply of a server that wrote the fields file itself (protocol 2.5,
/// FieldsRequest.omit_fields_from_reply).
void encode_resultants(const BodyOutput& output, protocol::FieldsReply& message);

/// A repeated double field as a vector.
Eigen::VectorXd to_vector(const google::protobuf::RepeatedField<double>& values);

}  // namespace robin
