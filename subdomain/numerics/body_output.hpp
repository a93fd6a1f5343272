#pragma once
// A body's result fields for output (ParaView files), computed from its final contact forces.
// Mirrors FieldsReply of proto/robin.proto.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "numerics/body_solver.hpp"
#include "numerics/vtu_writer.hpp"

namespace robin {

struct BodyOutput {
  std::string body_name;
  Mesh mesh;
  /// displacement (d = mesh.dimension components), stress (6: XX, YY, ZZ, XY, YZ, XZ; nodal
  /// average), von_mises, contact_pressure (|B' lambda| / m_k at contact boundary nodes, 0
  /// elsewhere), contact_force (d: -B' lambda), reaction (d)
  std::vector<OutputField> point_fields;
  /// stress (6, at element centroids), von_mises
  std::vector<OutputField> cell_fields;
  Eigen::Vector3d reaction_resultant = Eigen::Vector3d::Zero();  // sum of reactions (z = 0 in 2D)
  Eigen::Vector3d applied_force = Eigen::Vector3d::Zero();       // body forces + tractions
  /// The file's name, "<body_name>.vtu", when the body's server wrote it itself
  /// (FieldsReply.written_file); the mesh and fields may then be empty (protocol 2.5,
  /// FieldsRequest.omit_fields_from_reply). Empty: the coordinator writes the file.
  std::string written_file;
};

/// The body's file name in its result directory: `written_file` when its server wrote it
/// there, otherwise the file write_body_output writes into `directory`.
std::string place_body_output(const std::filesystem::path& directory, const BodyOutput& output);

/// The stress field's component names in ParaView's symmetric-tensor order: XX, YY, ZZ, XY, YZ,
/// XZ. The stress of a plane problem has YZ = XZ = 0 and ZZ = nu (XX + YY) for an isotropic
/// plane-strain material, 0 in plane stress and for a Voigt material (stress_tensor,
/// numerics/material.hpp); von_mises is of the same three-dimensional tensor.
const std::vector<std::string>& stress_tensor_components();

/// Fields of `body` under contact forces lambda (constraint order of its assignment); a floating
/// body (body_solver.hpp) with the rigid amplitudes of its last contact solve.
BodyOutput make_body_output(const BodySolver& body, const Eigen::VectorXd& contact_force);
/// The same with given rigid amplitudes alpha (k values, empty for k = 0), e.g. the monolithic
/// reference's (MonolithicResult::rigid_amplitudes).
BodyOutput make_body_output(const BodySolver& body, const Eigen::VectorXd& contact_force,
                            const Eigen::VectorXd& rigid_amplitudes);

/// Writes <directory>/<body_name>.vtu (numerics/vtu_writer.hpp: binary zlib-compressed, with the
/// mesh's named boundaries as line cells); returns the file name.
std::string write_body_output(const std::filesystem::path& directory, const BodyOutput& output);

/// Where a field's values live: one tuple per mesh node (a VTK point field) or per element
/// (a VTK cell field).
enum class FieldLocation { point, cell };
/// "point" or "cell", VTK's names of the two locations (for messages).
const char* field_location_name(FieldLocation location);

/// Looks at a field's values before they are written: its location, its name and its values
/// (components per node or element, as OutputField::values); throws to abandon the file.
using FieldCheck = std::function<void(FieldLocation location, const std::string& name,
                                      const std::vector<double>& values)>;

/// Writes <directory>/<body_name>.vtu: the file write_body_output writes of
/// make_body_output(body, contact_force), byte for byte, made from the body's own mesh (not a
/// copy) with one field's values in memory at a time, each given to `check` (when set) before
/// it is written. Returns the output without its mesh and fields: body_name, mesh.dimension, the
/// resultants and written_file (the file's name). Throws as write_body_output does, and what
/// `check` throws; the file is then not left behind.
BodyOutput write_body_fields(const std::filesystem::path& directory, const BodySolver& body,
                             const Eigen::VectorXd& contact_force, const FieldCheck& check = {});

}  // namespace robin
