#pragma once
// Result files of a run, shared by robin-monolithic and robin-coordinator:
//   <body>.vtu per body, solution.pvd, contact.csv, summary.json (and history.csv for DD).
// Every writer creates the missing directories of its target and throws std::runtime_error
// naming the path when a directory cannot be created or a file cannot be written. Numbers are
// written as the shortest decimal text that reads back to the same double.

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "coupling/contact_graph.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/coupling_scheme.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

/// The interface state written to contact.csv, one row per pair:
/// x, y, nx, ny (n1), gap0 (d), un1, un2, lambda1, lambda2, pressure, where
/// pressure = (lambda1 + lambda2) / (2 m_i) (force per unit length).
/// 1 and 2 are the interface's two sides, bodies a and b of its graph edge.
struct InterfaceState {
  Eigen::VectorXd normal_trace1, normal_trace2;
  Eigen::VectorXd contact_force1, contact_force2;
};

/// The two sides of interface `interface` of `graph` in a coupled state.
InterfaceState interface_state(const ContactGraph& graph, const CouplingState& state,
                               std::size_t interface);
/// The same for two bodies and one interface (body order = pair order).
InterfaceState two_body_interface_state(const CouplingState& state);

/// Header line "pair,x,y,nx,ny,gap0,un1,un2,lambda1,lambda2,pressure" ("pair,x,y,z,nx,ny,nz,
/// gap0,..." for solid bodies, pairing.dimension = 3), then one row per pair (pair = zero-based
/// index). Throws std::runtime_error when a state vector is not of the
/// pairing's size.
void write_contact_csv(const std::filesystem::path& path, const ContactPairing& pairing,
                       const InterfaceState& state);

/// Nodal fields of one body: displacement (2), stress (6: XX, YY, ZZ, XY, YZ, XZ, nodal
/// average; ZZ from the material's plane model), von_mises, contact_pressure (lambda_i / m_i on
/// contact nodes, 0 elsewhere), contact_force (2), reaction (2); cell fields: stress, von_mises,
/// boundary_id. The file is "<body name>.vtu" in `directory`, binary and zlib-compressed, with
/// the named boundaries as line cells; contact_force is lambda in the body's assignment order
/// (size contact_size()). 2-component fields are written with a zero z component (see
/// numerics/vtu_writer.hpp).
/// The fields are those of make_body_output (numerics/body_output.hpp), shared with the
/// remote subdomain path.
/// A floating body's rigid motion has the amplitudes `rigid_amplitudes` (k values; empty: none,
/// or those of the body's last contact solve).
/// Returns the written file name (relative to `directory`).
std::string write_body_vtu(const std::filesystem::path& directory, const BodySolver& body,
                           const Eigen::VectorXd& contact_force,
                           const Eigen::VectorXd& rigid_amplitudes = {});

/// Writes solution.pvd naming every body's file (part k: body k + 1).
void write_solution_pvd(const std::filesystem::path& directory,
                        const std::vector<std::string>& files);

/// One dataset of a ParaView collection: `file` (relative to the .pvd) at `timestep` as part
/// `part` (the body: 0 for body 1, 1 for body 2, ...).
struct PvdDataSet {
  double timestep = 0.0;
  int part = 0;
  std::string file;
};

/// Writes a time series as the collection `path` (solution.pvd of a run with load steps): one
/// <DataSet timestep part file/> per entry, in the given order, timesteps as exact decimal text.
void write_pvd_series(const std::filesystem::path& path, const std::vector<PvdDataSet>& datasets);

/// Pretty-printed JSON (2-space indent) followed by a newline.
void write_json(const std::filesystem::path& path, const nlohmann::json& document);

/// A vector for summary.json: [x, y] for plane bodies (dimension 2), [x, y, z] for solid ones.
nlohmann::json vector_json(const Eigen::Vector3d& vector, int dimension);

/// Contact force resultant sum_i lambda_i n1_i acting on body 2 (= minus that on body 1):
/// lambda is compressive and n1 points from body 1 towards body 2. Throws std::runtime_error
/// when force is not of the pairing's size.
Eigen::Vector3d contact_resultant(const ContactPairing& pairing, const Eigen::VectorXd& force);

}  // namespace robin
