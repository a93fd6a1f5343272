#include "numerics/body_output.hpp"

#include <functional>
#include <stdexcept>

#include <sys/stat.h>
#include <unistd.h>
#include <cstdlib>

#include "numerics/elasticity.hpp"
#include "numerics/finite_element.hpp"

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
    const StressTensor tensor = stress_tensor(material, stresses.col(k));
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

/// Voigt stress per node (columns): the average over the elements touching the node of the
/// element's stress at the node, as recover_stress's nodal_stress. The same pass stores each
/// element's stress at its centroid in `element_stresses` (columns in element order).
Eigen::MatrixXd nodal_stresses(const Mesh& mesh, const Material& material,
                               const Eigen::VectorXd& displacement,
                               Eigen::MatrixXd& element_stresses) {
  Eigen::MatrixXd nodal =
      Eigen::MatrixXd::Zero(material.voigt_size(), static_cast<Eigen::Index>(mesh.node_count()));
  Eigen::VectorXd touching = Eigen::VectorXd::Zero(mesh.node_count());
  element_stresses.resize(material.voigt_size(), static_cast<Eigen::Index>(mesh.element_count()));
  Eigen::Index element = 0;
  for_each_element_stress(mesh, material, displacement,
                          [&](const int* nodes, int count, const VoigtVector* stresses) {
                            for (int i = 0; i < count; ++i) {
                              nodal.col(nodes[i]) += stresses[i + 1];
                              touching(nodes[i]) += 1.0;
                            }
                            element_stresses.col(element++) = stresses[0];
                          });
  for (Eigen::Index node = 0; node < touching.size(); ++node) {
    if (touching(node) > 0.0) nodal.col(node) /= touching(node);
  }
  return nodal;
}

/// Appends the stress tensor of every column of Voigt stresses (6 values each, ParaView's
/// order) to `tensors` and its von Mises stress to `von_mises_values`.
void append_stress_tensors(const Material& material, const Eigen::MatrixXd& stresses,
                           std::vector<double>& tensors, std::vector<double>& von_mises_values) {
  for (Eigen::Index k = 0; k < stresses.cols(); ++k) {
    const StressTensor tensor = stress_tensor(material, stresses.col(k));
    tensors.insert(tensors.end(), tensor.data(), tensor.data() + 6);
    von_mises_values.push_back(von_mises(tensor));
  }
}

/// Moves `from` into the end of `values` and frees it.
void append_and_free(std::vector<double>& from, std::vector<double>& values) {
  values.insert(values.end(), from.begin(), from.end());
  std::vector<double>().swap(from);
}

/// Appends a vector's values.
void append_vector(const Eigen::VectorXd& vector, std::vector<double>& values) {
  values.insert(values.end(), vector.data(), vector.data() + vector.size());
}

/// The fields of a body made one at a time while its file is written (write_streamed_vtu):
/// what several fields share (the displacement, the contact forces, the reactions) is made
/// once; the stresses are evaluated element by element as each stress field is written, their
/// von Mises values kept for the von_mises field that follows.
class StreamedFields {
 public:
  StreamedFields(const BodySolver& body, const Eigen::VectorXd& contact_force, FieldCheck check)
      : body_(body),
        material_(body.definition().material),
        displacement_(body.displacement(contact_force, body.rigid_amplitudes())),
        force_field_(body.contact_force_field(contact_force)),
        reaction_(body.reactions(displacement_)),
        check_(std::move(check)) {}

  const Eigen::VectorXd& reaction() const { return reaction_; }

  std::vector<FieldSource> point_sources() {
    const int dimension = body_.mesh().dimension;
    return {source(FieldLocation::point, "displacement", dimension,
                   &StreamedFields::append_displacement),
            source(FieldLocation::point, "stress", 6, &StreamedFields::append_nodal_stress,
                   stress_tensor_components()),
            source(FieldLocation::point, "von_mises", 1, &StreamedFields::append_nodal_von_mises),
            source(FieldLocation::point, "contact_pressure", 1,
                   &StreamedFields::append_contact_pressure),
            source(FieldLocation::point, "contact_force", dimension,
                   &StreamedFields::append_contact_force),
            source(FieldLocation::point, "reaction", dimension, &StreamedFields::append_reaction)};
  }

  std::vector<FieldSource> cell_sources() {
    return {source(FieldLocation::cell, "stress", 6, &StreamedFields::append_element_stress,
                   stress_tensor_components()),
            source(FieldLocation::cell, "von_mises", 1, &StreamedFields::append_element_von_mises)};
  }

 private:
  using Append = void (StreamedFields::*)(std::vector<double>& values);

  /// The source of a field whose values `append` makes, given to check_ (when set) once made.
  FieldSource source(FieldLocation location, const std::string& name, int components, Append append,
                     const std::vector<std::string>& component_names = {}) {
    return {name, components, component_names,
            [this, location, name, append](std::vector<double>& values) {
              (this->*append)(values);
              if (check_) check_(location, name, values);
            }};
  }

  void append_displacement(std::vector<double>& values) { append_vector(displacement_, values); }
  void append_contact_force(std::vector<double>& values) { append_vector(force_field_, values); }
  void append_reaction(std::vector<double>& values) { append_vector(reaction_, values); }

  void append_contact_pressure(std::vector<double>& values) {
    const std::vector<double> pressure = nodal_contact_pressure(body_, force_field_);
    values.insert(values.end(), pressure.begin(), pressure.end());
  }

  void append_nodal_stress(std::vector<double>& values) {
    const Eigen::MatrixXd nodal =
        nodal_stresses(body_.mesh(), material_, displacement_, element_stresses_);
    nodal_von_mises_.clear();
    nodal_von_mises_.reserve(static_cast<std::size_t>(nodal.cols()));
    append_stress_tensors(material_, nodal, values, nodal_von_mises_);
  }

  void append_nodal_von_mises(std::vector<double>& values) {
    if (nodal_von_mises_.size() != body_.mesh().node_count()) {  // not made with the stress
      std::vector<double> tensors;
      append_nodal_stress(tensors);
    }
    append_and_free(nodal_von_mises_, values);
  }

  void append_element_stress(std::vector<double>& values) {
    if (element_stresses_.cols() != static_cast<Eigen::Index>(body_.mesh().element_count())) {
      nodal_stresses(body_.mesh(), material_, displacement_, element_stresses_);  // not made yet
    }
    element_von_mises_.clear();
    element_von_mises_.reserve(body_.mesh().element_count());
    append_stress_tensors(material_, element_stresses_, values, element_von_mises_);
    Eigen::MatrixXd().swap(element_stresses_);
  }

  void append_element_von_mises(std::vector<double>& values) {
    if (element_von_mises_.size() != body_.mesh().element_count()) {  // not made with the stress
      std::vector<double> tensors;
      append_element_stress(tensors);
    }
    append_and_free(element_von_mises_, values);
  }

  const BodySolver& body_;
  const Material& material_;
  const Eigen::VectorXd displacement_;
  const Eigen::VectorXd force_field_;  // -B' lambda per node
  const Eigen::VectorXd reaction_;
  const FieldCheck check_;
  Eigen::MatrixXd element_stresses_;       // Voigt, at the centroids: made with the nodal stress
  std::vector<double> nodal_von_mises_;    // made with the nodal stress tensors
  std::vector<double> element_von_mises_;  // made with the element stress tensors
};

/// Refuses contact forces of the wrong size (std::invalid_argument naming the body).
void check_contact_force_size(const BodySolver& body, const Eigen::VectorXd& contact_force) {
  if (contact_force.size() != body.contact_size()) {
    throw std::invalid_argument(
        "body '" + body.name() + "': " + std::to_string(contact_force.size()) +
        " contact forces for " + std::to_string(body.contact_size()) + " contact constraints");
  }
}

/// Writes <directory>/<body_name>.vtu with `write` (given the path of a fresh temporary file in
/// `directory`, renamed into place once written, removed if `write` throws); returns the file's
/// name.
std::string write_into_place(const std::filesystem::path& directory, const std::string& body_name,
                             const std::function<void(const std::string& temporary)>& write) {
  const std::string file_name = body_name + ".vtu";
  if (body_name.empty() || std::filesystem::path(body_name).has_parent_path()) {
    throw std::runtime_error("cannot write '" + (directory / file_name).string() +
                             "': body name '" + body_name + "' is not usable as a file name");
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
    write(temporary);
    std::filesystem::rename(temporary, directory / file_name);
  } catch (...) {
    std::error_code error;
    std::filesystem::remove(temporary, error);
    throw;
  }
  return file_name;
}

}  // namespace

const std::vector<std::string>& stress_tensor_components() {
  static const std::vector<std::string> names = {"XX", "YY", "ZZ", "XY", "YZ", "XZ"};
  return names;
}

const char* field_location_name(FieldLocation location) {
  return location == FieldLocation::point ? "point" : "cell";
}

BodyOutput make_body_output(const BodySolver& body, const Eigen::VectorXd& contact_force) {
  return make_body_output(body, contact_force, body.rigid_amplitudes());
}

BodyOutput make_body_output(const BodySolver& body, const Eigen::VectorXd& contact_force,
                            const Eigen::VectorXd& rigid_amplitudes) {
  check_contact_force_size(body, contact_force);
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
  return write_into_place(directory, output.body_name, [&output](const std::string& temporary) {
    write_vtu(temporary, output.mesh, output.point_fields, output.cell_fields);
  });
}

BodyOutput write_body_fields(const std::filesystem::path& directory, const BodySolver& body,
                             const Eigen::VectorXd& contact_force, const FieldCheck& check) {
  check_contact_force_size(body, contact_force);
  StreamedFields fields(body, contact_force, check);
  BodyOutput output;
  output.body_name = body.name();
  output.mesh.dimension = body.mesh().dimension;
  output.reaction_resultant = resultant(fields.reaction(), body.mesh().dimension);
  output.applied_force = body.applied_force();
  output.written_file = write_into_place(directory, body.name(), [&](const std::string& temporary) {
    write_streamed_vtu(temporary, body.mesh(), fields.point_sources(), fields.cell_sources());
  });
  return output;
}

}  // namespace robin
