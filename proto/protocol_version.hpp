#pragma once
// The protocol version this build speaks (see proto/robin.proto "Version" and
// docs/protocol.md "Versioning"). Peers are compatible when the major versions are equal.

namespace robin::protocol {

inline constexpr unsigned protocol_major = 2;
/// 2.0: meshes as data (no scripts from the wire), the general constraint operator B in
/// AssignContact, contact surfaces in InterfaceDescription. Within 1.x, 1.1 added
/// NeumannSolveRequest and 1.2 Envelope.run_id. 2.1: SetLoadFactor (quasi-static load steps
/// reuse the body's factor and F; a coordinator sends it only to servers of minor >= 1) and
/// StatusRequest (heartbeat and setup progress, capability "status"). 2.2: the stage times of
/// SetupBody, AssignContact and FieldsRequest in their replies (StageTime), for the profile.
/// 2.3: floating bodies, SetupBody.floating and InterfaceDescription.rigid_modes. 2.4:
/// three-dimensional (solid) bodies: MeshData.dimension 3 with tetrahedra and hexahedra (CellType
/// TETRAHEDRON4, TETRAHEDRON10, HEXAHEDRON8) and triangular or quadrilateral boundary faces, 6x6
/// Voigt materials, 3 components per node in every vector, Dirichlet.z, FieldsReply.dimension; a
/// plane body's messages are those of 2.3. 2.5: FieldsRequest.omit_fields_from_reply (a server
/// that wrote the body's file sends a reply without mesh and fields) and peak_resident_bytes in
/// InterfaceDescription, Acknowledge and FieldsReply.
inline constexpr unsigned protocol_minor = 5;

}  // namespace robin::protocol
