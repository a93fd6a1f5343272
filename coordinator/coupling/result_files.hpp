#pragma once
// Result files of a run, shared by robin-monolithic and robin-coordinator:
//   <body>.vtu per body, solution.pvd, contact.csv, summary.json (and history.csv for DD).

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "coupling/contact_pairing.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

/// The interface state written to contact.csv, one row per pair:
/// x, y, nx, ny (n1), gap0 (d), un1, un2, lambda1, lambda2, pressure, where
/// pressure = (lambda1 + lambda2) / (2 m_i) (force per unit length).
struct InterfaceState {
  Eigen::VectorXd normal_trace1, normal_trace2;
  Eigen::VectorXd contact_force1, contact_force2;
};

void write_contact_csv(const std::filesystem::path& path, const ContactPairing& pairing,
                       const InterfaceState& state);

/// Nodal fields of one body: displacement (2), stress (3: xx, yy, xy, nodal average),
/// von_mises, contact_pressure (lambda_i / m_i on contact nodes, 0 elsewhere), contact_force
/// (2), reaction (2); cell fields: stress, von_mises. Returns the written file name.
std::string write_body_vtu(const std::filesystem::path& directory, const BodySolver& body,
                           const Eigen::VectorXd& contact_force);

/// Writes solution.pvd naming both body files.
void write_solution_pvd(const std::filesystem::path& directory, const std::string& file1,
                        const std::string& file2);

void write_json(const std::filesystem::path& path, const nlohmann::json& document);

/// Contact force resultant sum_i lambda_i n_i acting on body 2 (= minus that on body 1).
Eigen::Vector2d contact_resultant(const ContactPairing& pairing, const Eigen::VectorXd& force);

}  // namespace robin
