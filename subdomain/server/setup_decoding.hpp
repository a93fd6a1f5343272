#pragma once
// Decoding of a SetupBody request (proto/robin.proto) into the numerics' body definition and
// solver settings. Part of the server's protocol module: the generated types stop here.

#include <cstdint>
#include <filesystem>

#include "numerics/body_definition.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/mprgp.hpp"
#include "robin.pb.h"

namespace robin {

/// The longest SetupBody.body_name, in characters.
constexpr std::size_t maximum_body_name_length = 64;

/// The most contact boundaries a SetupBody may name (checked before anything is allocated).
constexpr int maximum_contact_boundaries = 64;

/// Everything a SetupBody defines: the body and how to solve its contact problems.
struct DecodedSetup {
  BodyDefinition definition;
  MprgpParameters qp;
  BodySolverOptions body;
};

/// Where SetupBody.mesh_path may be read: under `data_directory` (empty: nowhere), files of at
/// most `maximum_bytes` (0: no limit; robin-subdomain --max-mesh-file-size), read by the
/// executable `reader` (robin-mesh-reader, read_mesh_file_in_child).
struct MeshFiles {
  std::filesystem::path data_directory;
  std::uintmax_t maximum_bytes = 0;
  std::filesystem::path reader;
};

/// Decodes and checks `message`: body name ([A-Za-z0-9_-]+, at most 64), mesh (MeshData,
/// checked by decode_mesh; or mesh_path, a file under `files.data_directory` of at most
/// `files.maximum_bytes`, refused when that directory is empty), plane model (must be given for
/// a plane body, ignored for a solid one), material (young_modulus/poisson_ratio, or 9 `voigt`
/// values in 2D and 36 in 3D, not both; isotropic solid materials from
/// make_isotropic_solid_material), body force (0 or `dimension` values), Dirichlet (at least
/// one of x/y, and z in 3D only) and traction conditions (`dimension` values), 1 to
/// maximum_contact_boundaries distinct contact boundaries (a repeated one is refused naming its
/// field, "SetupBody.contact_boundaries[1] repeats 'top'"), and the solver settings (0 or empty =
/// server default). Every boundary name is checked against the mesh. Throws InputError naming the
/// body and the field, e.g. "body 'upper': SetupBody.voigt has 4 values, expected 9".
DecodedSetup decode_setup_body(const protocol::SetupBody& message, const MeshFiles& files);

}  // namespace robin
