#pragma once
// Face-to-face mortar integration of two non-matching contact surfaces in 3D: the
// three-dimensional counterpart of the segment-to-segment integration of
// coupling/mortar_coupling.cpp (docs/method.md, "Mortar contact" and "Mortar contact in 3D:
// segmentation"), on plain data.
//
// One surface is the non-mortar side (its nodes carry the multipliers), the other the mortar
// side. For every non-mortar face and every mortar face near it whose outward normal opposes
// its own, both faces are projected along the auxiliary normal n0 (the non-mortar normal field
// at the face's centre) onto the auxiliary plane (through the face's centre, normal n0); their
// projections are clipped (Sutherland-Hodgman), the clip polygon is cut into triangles from
// its centroid, and on each triangle a Gauss rule's points are mapped back along n0 onto the
// non-mortar face (reference coordinates xi) and onto the mortar face (eta). With phi_k the
// non-mortar shape functions, phi^mortar_l the mortar ones, phi~ = T phi the non-mortar basis
// the multipliers are built on (phi~ = phi except for triangle6, see
// face_basis_transformation) and psi = A phi~ the dual basis, the integrals over the part of
// the non-mortar surface the mortar side covers are
//   D_jk = int psi_j phi_k,    M_jl = int psi_j phi^mortar_l(eta),    G_j = int psi_j g,
// and the same with psi_j replaced by the standard basis phi~_j, and covered_j = int phi~_j,
// with the normal gap g = (x^mortar(eta) - x(xi)) . n(xi) + g0(x(xi)), n the non-mortar normal
// field. On a node whose support the mortar side covers entirely, D_jk = delta_jk m_j with
// m_j = int phi~_j = sum_k D_jk for linear faces (triangle3, quadrilateral4); for triangle6
// faces D couples a mid-edge node to the edge's two corners (face_basis_transformation).

#include <Eigen/Core>
#include <functional>
#include <map>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

/// One contact surface of one body, in 3D.
struct MortarSurface {
  std::vector<Eigen::Vector3d> coordinates;    // position of each node
  std::vector<Eigen::Vector3d> normals;        // averaged unit outward normal of each node
  FacetType face_type = FacetType::triangle3;  // triangle3, triangle6 or quadrilateral4
  /// nodes_per_facet(face_type) node positions (indices into coordinates) per face, in Gmsh
  /// order, oriented so that the right-hand normal (dx/dr x dx/ds) points out of the body.
  /// Every face's projection onto its auxiliary plane must be convex (true of the faces of
  /// any mesh that is not badly warped).
  std::vector<int> faces;
};

/// The integrals of one non-mortar node's row, by node position (index into coordinates), with
/// phi~_j (the transformed basis, = phi_j for linear faces) as the standard basis. The 2D
/// segment integration of coupling/mortar_coupling.cpp fills the same struct (segments for
/// faces), and coupling/mortar_rows.hpp assembles the rows of both.
struct FaceRowIntegrals {
  std::map<int, double> dual_nonmortar;      // D_jk = int psi_j phi_k
  std::map<int, double> standard_nonmortar;  // int phi~_j phi_k
  std::map<int, double> dual_mortar;         // M_jl = int psi_j phi^mortar_l
  std::map<int, double> standard_mortar;     // int phi~_j phi^mortar_l
  double dual_gap = 0.0;                     // int psi_j g
  double standard_gap = 0.0;                 // int phi~_j g
  double covered = 0.0;                      // int over the covered part of phi~_j
};

struct FaceCoupling {
  std::vector<FaceRowIntegrals> rows;  // by non-mortar node position
  int facing_candidates = 0;           // (non-mortar, mortar) face pairs in reach, normals opposed
  int same_direction_candidates = 0;   // pairs in reach whose outward normals do not oppose
};

/// The initial gap g0(x), added to the geometric gap; may be empty (no initial gap).
using SpatialGap = std::function<double(const Eigen::Vector3d&)>;

/// The mortar integrals of `nonmortar` against `mortar` (see the file comment). Candidate
/// mortar faces come from a bounding-box tree queried with the box swept by each non-mortar
/// face's nodal normal rays: O(n log n + overlaps) in all. Throws std::invalid_argument on
/// inconsistent data (sizes, an edge type, a node position out of range).
FaceCoupling integrate_face_mortar(const MortarSurface& nonmortar, const MortarSurface& mortar,
                                   const SpatialGap& gap);

/// The transformation T of a non-mortar face's basis, phi~ = T phi (rows: local nodes).
/// Identity for triangle3 and quadrilateral4. For triangle6 the corner shape functions of an
/// affine face integrate to zero, so the dual basis A = diag(int phi) M_e^{-1} of Wohlmuth
/// would vanish at the corners (D_jj = 0: no multiplier there). As Popp, Wohlmuth, Gee and
/// Wall (dual quadratic mortar, 2012) do, the multipliers are built on
///   phi~_c = phi_c + alpha (phi_m + phi_m')  (c a corner, m, m' its two mid-edge nodes),
///   phi~_m = (1 - 2 alpha) phi_m,            alpha = 1/5,
/// a partition of unity whose integrals on an affine face of area S are 2S/15 at the corners
/// and S/5 at the mid-edge nodes, all positive. The transformed displacement values
/// u~ = T^{-T} u are u~_c = u_c at a corner and u~_m = (u_m - alpha (u_c + u_c')) / (1 - 2 alpha)
/// at a mid-edge node: a corner's dual row is still the node alone, a mid-edge node's row
/// couples its edge's corners (D_mc = -alpha D_mm, with D_mm = m_m / (1 - 2 alpha)).
Eigen::MatrixXd face_basis_transformation(FacetType type);

/// The consistent mass matrix int phi_a phi_b dA of one face (standard shape functions) whose
/// nodes are at `nodes` (Gmsh order).
Eigen::MatrixXd face_mass_matrix(FacetType type, const std::vector<Eigen::Vector3d>& nodes);

/// The dual basis of one non-mortar face as psi = B phi (rows: the multipliers), B = A T with
/// A = diag(int phi~) M~^{-1}, M~ = T M T^T the mass matrix of phi~: int psi_j phi~_k =
/// delta_jk int phi~_j over the face.
Eigen::MatrixXd face_dual_basis(FacetType type, const std::vector<Eigen::Vector3d>& nodes);

/// int phi~_j over the whole surface for each node (the `covered` of a node whose support the
/// mortar side covers entirely, up to the quadrature error of non-affine faces: exactly for
/// triangle3 faces, parallelogram quadrilateral4 faces and straight-edged triangle6 faces).
std::vector<double> support_integrals(const MortarSurface& surface);

}  // namespace robin
