#include "coupling/result_files.hpp"

#include <array>
#include <charconv>
#include <fstream>
#include <locale>
#include <stdexcept>
#include <system_error>

#include "numerics/elasticity.hpp"
#include "numerics/vtu_writer.hpp"

namespace robin {
namespace {

void ensure_directory(const std::filesystem::path& directory) {
  if (directory.empty()) return;
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error || !std::filesystem::is_directory(directory)) {
    throw std::runtime_error("cannot create the output directory '" + directory.string() + "'" +
                             (error ? ": " + error.message() : ": not a directory"));
  }
}

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw std::runtime_error("cannot open '" + path.string() +
                             "' for writing: check that its directory is writable");
  }
  out.imbue(std::locale::classic());
  return out;
}

void finish_writing(std::ofstream& out, const std::filesystem::path& path) {
  out.close();
  if (!out) throw std::runtime_error("error while writing '" + path.string() + "' (disk full?)");
}

/// Shortest decimal text that parses back to the same double.
std::string exact_text(double value) {
  std::array<char, 32> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

void check_size(const Eigen::VectorXd& vector, std::size_t expected, const std::string& what,
                const std::string& context) {
  if (static_cast<std::size_t>(vector.size()) != expected) {
    throw std::runtime_error(context + ": " + what + " has " + std::to_string(vector.size()) +
                             " entries, expected " + std::to_string(expected) +
                             " (one per contact pair)");
  }
}

std::vector<double> to_values(const double* data, Eigen::Index size) {
  return std::vector<double>(data, data + size);
}

/// p_node = lambda_i / m_i on the assigned contact nodes, zero elsewhere.
std::vector<double> nodal_contact_pressure(const BodySolver& body,
                                           const Eigen::VectorXd& contact_force) {
  std::vector<double> pressure(body.mesh().node_count(), 0.0);
  const std::vector<int>& nodes = body.contact_nodes();
  const Eigen::VectorXd& weights = body.contact_weights();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto index = static_cast<Eigen::Index>(i);
    pressure[nodes[i]] = contact_force[index] / weights[index];
  }
  return pressure;
}

}  // namespace

void write_contact_csv(const std::filesystem::path& path, const ContactPairing& pairing,
                       const InterfaceState& state) {
  const std::string context = "cannot write '" + path.string() + "'";
  check_size(state.normal_trace1, pairing.size(), "normal_trace1", context);
  check_size(state.normal_trace2, pairing.size(), "normal_trace2", context);
  check_size(state.contact_force1, pairing.size(), "contact_force1", context);
  check_size(state.contact_force2, pairing.size(), "contact_force2", context);
  ensure_directory(path.parent_path());
  std::ofstream out = open_for_writing(path);
  out << "pair,x,y,nx,ny,gap0,un1,un2,lambda1,lambda2,pressure\n";
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    const ContactPair& pair = pairing.pairs[i];
    const auto k = static_cast<Eigen::Index>(i);
    const double lambda1 = state.contact_force1[k];
    const double lambda2 = state.contact_force2[k];
    // pressure = (lambda1 + lambda2) / (2 m_i): the mean nodal force per unit length
    const double pressure = (lambda1 + lambda2) / (2.0 * pair.weight);
    const std::array<double, 10> row = {
        pair.position.x(),      pair.position.y(),      pair.normal.x(), pair.normal.y(), pair.gap,
        state.normal_trace1[k], state.normal_trace2[k], lambda1,         lambda2,         pressure};
    out << i;
    for (double value : row) out << ',' << exact_text(value);
    out << '\n';
  }
  finish_writing(out, path);
}

std::string write_body_vtu(const std::filesystem::path& directory, const BodySolver& body,
                           const Eigen::VectorXd& contact_force) {
  const std::string file_name = body.name() + ".vtu";
  const std::filesystem::path path = directory / file_name;
  if (body.name().empty() || std::filesystem::path(body.name()).has_parent_path()) {
    throw std::runtime_error("cannot write '" + path.string() + "': body name '" + body.name() +
                             "' is not usable as a file name");
  }
  if (contact_force.size() != body.contact_size()) {
    throw std::runtime_error("cannot write '" + path.string() + "': body '" + body.name() +
                             "' has " + std::to_string(body.contact_size()) +
                             " contact nodes but the contact force has " +
                             std::to_string(contact_force.size()) + " entries");
  }
  const Mesh& mesh = body.mesh();
  const Eigen::VectorXd displacement = body.displacement(contact_force);
  const StressField stress = recover_stress(mesh, body.definition().material, displacement);
  const Eigen::VectorXd reaction = body.reactions(displacement);
  const Eigen::VectorXd force_field = body.contact_force_field(contact_force);
  const std::vector<std::string> stress_components = {"xx", "yy", "xy"};

  const std::vector<OutputField> point_fields = {
      {"displacement", 2, to_values(displacement.data(), displacement.size())},
      {"stress", 3, to_values(stress.nodal_stress.data(), stress.nodal_stress.size()),
       stress_components},
      {"von_mises", 1, to_values(stress.nodal_von_mises.data(), stress.nodal_von_mises.size())},
      {"contact_pressure", 1, nodal_contact_pressure(body, contact_force)},
      {"contact_force", 2, to_values(force_field.data(), force_field.size())},
      {"reaction", 2, to_values(reaction.data(), reaction.size())}};
  const std::vector<OutputField> cell_fields = {
      {"stress", 3, to_values(stress.element_stress.data(), stress.element_stress.size()),
       stress_components},
      {"von_mises", 1,
       to_values(stress.element_von_mises.data(), stress.element_von_mises.size())}};
  ensure_directory(directory);
  write_vtu(path, mesh, point_fields, cell_fields);
  return file_name;
}

void write_solution_pvd(const std::filesystem::path& directory, const std::string& file1,
                        const std::string& file2) {
  ensure_directory(directory);
  write_pvd(directory / "solution.pvd", {file1, file2});
}

void write_json(const std::filesystem::path& path, const nlohmann::json& document) {
  ensure_directory(path.parent_path());
  // invalid UTF-8 (e.g. from a path) is replaced rather than thrown after the file is opened
  const std::string text = document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  std::ofstream out = open_for_writing(path);
  out << text << '\n';
  finish_writing(out, path);
}

Eigen::Vector2d contact_resultant(const ContactPairing& pairing, const Eigen::VectorXd& force) {
  check_size(force, pairing.size(), "the contact force", "contact_resultant");
  // R = sum_i lambda_i n1_i: lambda_i pushes body 2 along n1_i (from body 1 towards body 2)
  Eigen::Vector2d resultant = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    resultant += force[static_cast<Eigen::Index>(i)] * pairing.pairs[i].normal;
  }
  return resultant;
}

}  // namespace robin
