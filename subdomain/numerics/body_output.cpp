#include "numerics/body_output.hpp"

#include <stdexcept>

#include <sys/stat.h>
#include <unistd.h>
#include <cstdlib>

#include "numerics/elasticity.hpp"

namespace robin {
namespace {

std::vector<double> to_values(const double* data, Eigen::Index size) {
  return std::vector<double>(data, data + size);
}

/// |(B' lambda) at node k| / m_k at the nodes of the contact boundary (force per unit length in
/// 2D, area in 3D), zero elsewhere; m_k is the node's boundary weight. For node-to-node rows
/// this is lambda_i / m_i.
std::vector<double> nodal_contact_pressure(const BodySolver& body,
                                           const Eigen::VectorXd& contact_force_field) {
  const int dimension = body.mesh().dimension;
  std::vector<double> pressure(body.mesh().node_count(), 0.0);
  for (std::size_t node = 0; node < pressure.size(); ++node) {
    const double weight = body.boundary_weights()[static_cast<Eigen::Index>(node)];
    if (weight > 0) {
      pressure[node] =
          contact_force_field.segment(dimension * static_cast<Eigen::Index>(node), dimension)
              .norm() /
          weight;
    }
  }
  return pressure;
}

/// Symmetric stress tensors in ParaView's order (XX, YY, ZZ, XY, YZ, XZ) from Voigt stresses per
/// column (numerics/material.hpp, stress_tensor: a plane problem has s_yz = s_xz = 0 and its
/// out-of-plane s_zz).
std::vector<double> stress_tensors(const Material& material, const Eigen::MatrixXd& stresses) {
  std::vector<double> values;
  values.reserve(6 * static_cast<std::size_t>(stresses.cols()));
  for (Eigen::Index k = 0; k < stresses.cols(); ++k) {
    const StressTensor tensor = stress_tensor(material, Eigen::VectorXd(stresses.col(k)));
    values.insert(values.end(), tensor.data(), tensor.data() + 6);
  }
  return values;
}

Eigen::Vector3d resultant(const Eigen::VectorXd& nodal_vectors, int dimension) {
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (Eigen::Index node = 0; node < nodal_vectors.size() / dimension; ++node) {
    total.head(dimension) += nodal_vectors.segment(dimension * node, dimension);
  }
  return total;
}

}  // namespace

const std::vector<std::string>& stress_tensor_components() {
  static const std::vector<std::string> names = {"XX", "YY", "ZZ", "XY", "YZ", "XZ"};
  return names;
}

BodyOutput make_body_output(const BodySolver& body, const Eigen::VectorXd& contact_force) {
  return make_body_output(body, contact_force, body.rigid_amplitudes());
}

BodyOutput make_body_output(const BodySolver& body, const Eigen::VectorXd& contact_force,
                            const Eigen::VectorXd& rigid_amplitudes) {
  if (contact_force.size() != body.contact_size()) {
    throw std::invalid_argument(
        "body '" + body.name() + "': " + std::to_string(contact_force.size()) +
        " contact forces for " + std::to_string(body.contact_size()) + " contact constraints");
  }
  const Material& material = body.definition().material;
  const Eigen::VectorXd displacement = body.displacement(contact_force, rigid_amplitudes);
  const StressField stress = recover_stress(body.mesh(), material, displacement);
  const Eigen::VectorXd reaction = body.reactions(displacement);
  const Eigen::VectorXd force_field = body.contact_force_field(contact_force);

  const int dimension = body.mesh().dimension;
  BodyOutput output;
  output.body_name = body.name();
  output.mesh = body.mesh();
  output.point_fields = {
      {"displacement", dimension, to_values(displacement.data(), displacement.size())},
      {"stress", 6, stress_tensors(material, stress.nodal_stress), stress_tensor_components()},
      {"von_mises", 1, to_values(stress.nodal_von_mises.data(), stress.nodal_von_mises.size())},
      {"contact_pressure", 1, nodal_contact_pressure(body, force_field)},
      {"contact_force", dimension, to_values(force_field.data(), force_field.size())},
      {"reaction", dimension, to_values(reaction.data(), reaction.size())}};
  output.cell_fields = {
      {"stress", 6, stress_tensors(material, stress.element_stress), stress_tensor_components()},
      {"von_mises", 1,
       to_values(stress.element_von_mises.data(), stress.element_von_mises.size())}};
  output.reaction_resultant = resultant(reaction, dimension);
  output.applied_force = body.applied_force();
  return output;
}

std::string place_body_output(const std::filesystem::path& directory, const BodyOutput& output) {
  return output.written_file.empty() ? write_body_output(directory, output) : output.written_file;
}

std::string write_body_output(const std::filesystem::path& directory, const BodyOutput& output) {
  const std::string file_name = output.body_name + ".vtu";
  if (output.body_name.empty() || std::filesystem::path(output.body_name).has_parent_path()) {
    throw std::runtime_error("cannot write '" + (directory / file_name).string() +
                             "': body name '" + output.body_name +
                             "' is not usable as a file name");
  }
  std::filesystem::create_directories(directory);
  // A fresh temporary file (mkstemp: O_EXCL, so never through an existing link), renamed into
  // place: a symbolic link at the target is replaced, not followed, and a reader never sees a
  // half-written file. mkstemp creates the file for its owner only; a result file is made
  // readable by everyone (0644, as the Python server writes it).
  std::string temporary = (directory / ("." + file_name + ".XXXXXX")).string();
  const int descriptor = mkstemp(temporary.data());
  if (descriptor < 0) {
    throw std::runtime_error("cannot create a temporary file in '" + directory.string() + "'");
  }
  fchmod(descriptor, S_IRUSR | S_IWUSR | S_IRGRP | S_IROTH);
  close(descriptor);
  try {
    write_vtu(temporary, output.mesh, output.point_fields, output.cell_fields);
    std::filesystem::rename(temporary, directory / file_name);
  } catch (...) {
    std::error_code error;
    std::filesystem::remove(temporary, error);
    throw;
  }
  return file_name;
}

}  // namespace robin
