#pragma once
// The conformance checker's solid-body checks (protocol 2.4; internal to robin_remote, see
// conformance_check.hpp).
//
// The body: the unit cube [0, 1]^3 as MeshData of 4-node tetrahedra (make_box_mesh, 2 x 2 x 2
// cubes of six tetrahedra each) with its six sides as triangle boundaries, the isotropic solid
// E = 1000, nu = 0.3 sent as its 36 Voigt values (as robin-coordinator sends every solid
// material), the bottom side z = 0 prescribed to u = (0, 0, lift), a body force (0, 0, -2) and a
// traction (1, 0.5, 0) on the side x = 1, the top side z = 1 the contact boundary. Linear
// tetrahedra with these loads have one discrete solution whatever the quadrature, so the
// checker compares every reply with its in-process reference: the same body solved by this
// build's BodySolver (the numerics of robin-subdomain), to the checker's relative tolerance.
//
// The checks, in order, each needing the previous ones:
//   solid_setup_body        the InterfaceDescription: dimension 3, the top side's nodes (matched
//                           to the reference's by position), their normals (0, 0, 1), weights,
//                           no fixed flags, one surface "top" of TRIANGLE3 faces that are
//                           oriented outward (right-hand normal +z) and cover the side's area 1;
//   solid_assign_contact    node-to-node rows with the normal (0, 0, 1) and the reference's
//                           weights, acknowledged with state 'ready';
//   solid_contact_solve     obstacle g_i = e_i + lift (x_i - 1/2), e the reference's free trace
//                           (the nodes with x < 1/2 touch): u_N and lambda as the reference's;
//   solid_correction        F r for a fixed r as the reference's;
//   solid_neumann_solve     (when "neumann_solve" is announced) u_N(lambda) as the reference's;
//   solid_fields            FieldsReply for the contact lambda: dimension 3, the mesh's nodes,
//                           tetrahedra (VTK 10), and every field the reference has that the
//                           server sends (displacement required) and the resultants as the
//                           reference's;
//   solid_end_run           EndRun: Acknowledge 'awaiting_setup'.
//
// A server without solid bodies answers the SetupBody with UNSUPPORTED (a server announcing a
// protocol minor version below 4 may answer BAD_INPUT, as 2.3 servers did): 'solid_setup_body'
// then passes with the note "3D: not supported" and the other solid checks are not run, so a
// plane-only server conforms.

#include "remote/conformance_session.hpp"

namespace robin::conformance {

/// Runs the solid checks (the server in state awaiting_setup; it is left there). `server_minor`
/// is the HelloReply's minor version, `neumann_offered` whether it announced "neumann_solve".
void run_solid_checks(Session& session, unsigned server_minor, bool neumann_offered);

}  // namespace robin::conformance
