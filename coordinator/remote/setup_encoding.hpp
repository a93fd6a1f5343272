#pragma once
// Encoding of one body of a case into the SetupBody request of proto/robin.proto, and of the
// contact assignment into AssignContact (part of robin_remote's protocol module: generated
// types stay inside robin_remote).

#include <string>

#include "coupling/case_file.hpp"
#include "robin.pb.h"

namespace robin {

/// The SetupBody request for `definition` (its mesh loaded): the mesh as MeshData (the server
/// needs no access to the coordinator's files and runs no script; `dimension` 2 or 3), the
/// plane model (plane bodies only), the material (see encode_material), body force, Dirichlet
/// conditions, tractions, the contact boundary, the body solver settings of `solver` and whether
/// the body is `floating` (held by contact alone). `context` names the body for errors.
protocol::SetupBody encode_setup_body(const BodyDefinition& definition, const std::string& context,
                                      const SolverOptions& solver, bool floating = false);

/// The SetupBody request of `body` as its mesh_delivery says: encode_setup_body of its
/// definition (MeshDelivery::data), or (file_on_server) the same with mesh_path, the file's name
/// under the server's data directory, instead of the mesh, the case's dimension and the file's
/// node count standing for the mesh's.
protocol::SetupBody encode_setup_body(const BodyCase& body, const SolverOptions& solver);

/// Writes `material` into `message` exactly (the server rebuilds the same Material bit for bit):
///  - an isotropic plane-strain material (the only kind with out_of_plane_poisson != 0) is sent
///    as young_modulus/poisson_ratio, because the server can only recover the out-of-plane
///    stress s_zz = nu (s_xx + s_yy) (von Mises) from the isotropic constants; nu is
///    out_of_plane_poisson and E is chosen so that the server's C equals ours to the last bit;
///  - every other material (plane stress, or a general Voigt matrix) is sent as the row-major
///    3x3 `voigt` matrix C, which is exact: for those s_zz is zero on both sides;
///  - a solid material (6x6, three-dimensional bodies) is sent as its row-major 6x6 `voigt`.
/// `context` names the body for the InputError thrown when a hand-built Material cannot be
/// expressed in the protocol (s_zz factor without an isotropic C).
void encode_material(const Material& material, const std::string& context,
                     protocol::SetupBody& message);

/// The AssignContact request: the constraint operator B in compressed rows.
protocol::AssignContact encode_contact_operator(const ContactOperator& contact);

}  // namespace robin
