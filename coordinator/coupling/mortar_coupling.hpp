#pragma once
// Mortar coupling of two non-matching contact boundaries, segment to segment in 2D and face to
// face in 3D (below; docs/method.md, "Mortar contact"). One side is the non-mortar side (its
// nodes carry the multipliers); the other, the mortar side, is projected onto it along the
// non-mortar normal field. On the overlap of every pair of segments the products of the
// non-mortar multiplier basis psi_j with both sides' shape functions and with the normal gap are
// integrated by Gauss rules (exact for flat boundaries):
//   D_jk = int psi_j phi_k,   M_jl = int psi_j phi^mortar_l,   G_j = int psi_j gap,
// with psi the dual (biorthogonal) basis psi_j = sum_k A_jk phi_k, A = diag(int phi) M_e^{-1}
// per segment, so that D is diagonal (D_jj = int phi_j) on segments the mortar side covers
// entirely. Row j of the constraint, divided by its weight m_j = D_jj so that lambda_j stays a
// nodal force and the gap a length, is
//   u(x_j) . n_j - sum_l (M_jl / m_j) u^mortar(x_l) . n_j <= G_j / m_j,
// n_j the averaged outward normal of the non-mortar node j. Matching flat meshes give exactly
// the node-to-node rows. A node whose support the mortar side covers only in part gets the
// standard basis instead (psi_j = phi_j: a positively weighted average of the gap over the
// covered part, with rows coupling its non-mortar neighbours); a node it does not cover at all
// carries no constraint (it faces no part of the other body).
//
// Node-to-segment collocation (the classic NTS) is available for comparison: row j is
// u(x_j) . n_j - sum_l phi^mortar_l(eta_j) u^mortar(x_l) . n_j <= gap(x_j), eta_j the projection
// of node j. It fails the contact patch test on non-matching meshes; it is not a default, and
// plane bodies only.
//
// Solid (3D) bodies: their contact faces (triangle3, triangle6, quadrilateral4) are integrated
// face to face by integrate_face_mortar (coupling/face_mortar.hpp), the initial gap g0 taken at
// the non-mortar point's (x, y), and the rows assembled by the same rules
// (coupling/mortar_rows.hpp). On triangle6 faces the multipliers live on the transformed basis
// phi~ (face_basis_transformation): m_j = int phi~_j = sum_k D_jk and the dual row of a mid-edge
// node couples it to its edge's corners.

#include <string>

#include "coupling/contact_pairing.hpp"
#include "coupling/gap_function.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

enum class MortarIntegration {
  segment_to_segment,  // mortar, dual multipliers (the default for non-matching meshes)
  node_to_segment,     // collocation at the non-mortar nodes (comparison only)
};

struct MortarOptions {
  MortarIntegration integration = MortarIntegration::segment_to_segment;
  /// The body (0 or 1) whose boundary carries the multipliers; -1: the finer side (finer_side).
  int non_mortar_body = -1;
};

/// The mortar coupling of the contact boundaries of two bodies (both plane or both solid): one
/// row (ContactPair) per constrained non-mortar node, ordered along the zone, with its position,
/// the normal n1 (outward from body 1), the normalized weighted gap (plus g0 integrated the same
/// way), the weight m_j, and both bodies' constraint operators (ContactPairing::operators). Rows
/// whose normal displacement is prescribed go to `excluded`, as in node-to-node pairing.
/// Throws InputError naming both bodies when no non-mortar node faces the mortar side (the
/// boundaries do not face each other, or their outward normals point the same way), when a
/// boundary has no segments (faces), when a description has several contact boundaries
/// (surfaces): couple one boundary of each body, restrict_to_boundary() gives its description,
/// when the bodies' dimensions differ, and for node-to-segment collocation of solid bodies.
ContactPairing build_mortar_coupling(const InterfaceDescription& body1, const std::string& name1,
                                     const InterfaceDescription& body2, const std::string& name2,
                                     const GapFunction* gap, const MortarOptions& options);

/// The body (0 or 1) with the shorter mean segment length, in 3D the smaller mean face size (the
/// square root of the mean face area); body 0 on a tie.
int finer_side(const InterfaceDescription& body1, const InterfaceDescription& body2);

}  // namespace robin
