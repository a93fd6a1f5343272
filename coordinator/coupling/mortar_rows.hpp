#pragma once
// The constraint rows of a mortar coupling from its integrals (docs/method.md, "Mortar
// contact" and "Mortar contact in 3D: the rows"): one code path for 2D segments and 3D faces.
//
// Row j of a non-mortar node whose support the mortar side covers entirely uses the dual basis:
//   sum_k (D_jk / m_j) u_k . n_j - sum_l (M_jl / m_j) u^mortar_l . n_j <= G_j / m_j,
// with the weight m_j = sum_k D_jk (= int phi~_j). D is diagonal there for every basis but the
// transformed triangle6 basis (face_basis_transformation in face_mortar.hpp), whose mid-edge rows
// couple the edge's corners: DualRow says which. A node covered in part gets the standard basis
// phi~_j instead (its weight the covered integral int phi~_j, its row coupling the non-mortar
// neighbours); a node covered over less than a thousandth of its support carries no row.
// The integrals come as a FaceCoupling (face_mortar.hpp): from integrate_face_mortar in 3D, from
// the segment integration of mortar_coupling.cpp in 2D.

#include <string>
#include <vector>

#include "coupling/contact_pairing.hpp"
#include "coupling/face_mortar.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

/// One side of a mortar coupling as the row assembly sees it.
struct MortarSide {
  const InterfaceDescription* interface = nullptr;  // of its one contact boundary
  std::string name;                                 // the body's, for messages
  int body = 0;                                     // 0 or 1
  /// Per node (position into the description), int phi~_j over its whole support: the
  /// `covered` integral of a node the other side covers entirely (the description's weights in
  /// 2D; support_integrals() of the faces in 3D, which differ on triangle6 faces). Read on the
  /// non-mortar side only.
  std::vector<double> support;
};

/// Which non-mortar entries the dual row of a fully covered node keeps.
enum class DualRow {
  node_alone,  // D is diagonal by construction (segments, triangle3, quadrilateral4): D_jj only
  full_row,    // D_jk as integrated (triangle6: a mid-edge node couples its edge's corners)
};

/// node_alone for every facet type but triangle6.
DualRow dual_row_of(FacetType nonmortar_facet_type);

/// The rows of `coupling` (rows by non-mortar position) as a ContactPairing: the covered
/// non-mortar nodes ordered along the zone (order_along_zone), those whose normal displacement a
/// Dirichlet condition prescribes in `excluded`. The operators' rows are divided by the weights,
/// so that lambda_j is a nodal force and the gap a length. non_mortar_body and uncovered are set.
/// Throws InputError naming both bodies when no node has a row (the boundaries do not face each
/// other; `coupling`'s candidate counts say why) or when every row is excluded.
ContactPairing assemble_mortar_rows(const MortarSide& nonmortar, const MortarSide& mortar,
                                    const FaceCoupling& coupling, DualRow dual_row);

}  // namespace robin
