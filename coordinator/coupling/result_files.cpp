#include "coupling/result_files.hpp"

#include <array>
#include <charconv>
#include <fstream>
#include <locale>
#include <stdexcept>
#include <system_error>

#include "numerics/body_output.hpp"
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

}  // namespace

InterfaceState interface_state(const ContactGraph& graph, const CouplingState& state,
                               std::size_t interface) {
  const GraphInterface& edge = graph.interfaces().at(interface);
  const BodyInterfaceState& side_a = state.bodies.at(static_cast<std::size_t>(edge.body_a));
  const BodyInterfaceState& side_b = state.bodies.at(static_cast<std::size_t>(edge.body_b));
  return {side_a.normal_trace.segment(edge.offset_a, edge.rows),
          side_b.normal_trace.segment(edge.offset_b, edge.rows),
          side_a.contact_force.segment(edge.offset_a, edge.rows),
          side_b.contact_force.segment(edge.offset_b, edge.rows)};
}

InterfaceState two_body_interface_state(const CouplingState& state) {
  return interface_state(ContactGraph::two_bodies(state.bodies.at(0).normal_trace.size()), state,
                         0);
}

void write_contact_csv(const std::filesystem::path& path, const ContactPairing& pairing,
                       const InterfaceState& state) {
  const std::string context = "cannot write '" + path.string() + "'";
  check_size(state.normal_trace1, pairing.size(), "normal_trace1", context);
  check_size(state.normal_trace2, pairing.size(), "normal_trace2", context);
  check_size(state.contact_force1, pairing.size(), "contact_force1", context);
  check_size(state.contact_force2, pairing.size(), "contact_force2", context);
  ensure_directory(path.parent_path());
  std::ofstream out = open_for_writing(path);
  // Plane bodies: x, y, nx, ny; solid bodies add z and nz.
  const bool solid = pairing.dimension == 3;
  out << (solid ? "pair,x,y,z,nx,ny,nz,gap0,un1,un2,lambda1,lambda2,pressure\n"
                : "pair,x,y,nx,ny,gap0,un1,un2,lambda1,lambda2,pressure\n");
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
    if (solid) {
      for (double value : {pair.position.x(), pair.position.y(), pair.position.z(), pair.normal.x(),
                           pair.normal.y(), pair.normal.z()}) {
        out << ',' << exact_text(value);
      }
      for (std::size_t c = 4; c < row.size(); ++c) out << ',' << exact_text(row[c]);
      out << '\n';
      continue;
    }
    for (double value : row) out << ',' << exact_text(value);
    out << '\n';
  }
  finish_writing(out, path);
}

std::string write_body_vtu(const std::filesystem::path& directory, const BodySolver& body,
                           const Eigen::VectorXd& contact_force,
                           const Eigen::VectorXd& rigid_amplitudes) {
  const std::filesystem::path path = directory / (body.name() + ".vtu");
  if (contact_force.size() != body.contact_size()) {
    throw std::runtime_error("cannot write '" + path.string() + "': body '" + body.name() +
                             "' has " + std::to_string(body.contact_size()) +
                             " contact nodes but the contact force has " +
                             std::to_string(contact_force.size()) + " entries");
  }
  ensure_directory(directory);
  return write_body_output(directory, rigid_amplitudes.size() > 0
                                          ? make_body_output(body, contact_force, rigid_amplitudes)
                                          : make_body_output(body, contact_force));
}

void write_solution_pvd(const std::filesystem::path& directory,
                        const std::vector<std::string>& files) {
  ensure_directory(directory);
  write_pvd(directory / "solution.pvd", files);
}

void write_pvd_series(const std::filesystem::path& path, const std::vector<PvdDataSet>& datasets) {
  ensure_directory(path.parent_path());
  const auto escaped = [](const std::string& text) {
    std::string result;
    for (const char c : text) {
      switch (c) {
        case '&':
          result += "&amp;";
          break;
        case '<':
          result += "&lt;";
          break;
        case '>':
          result += "&gt;";
          break;
        case '"':
          result += "&quot;";
          break;
        default:
          result += c;
      }
    }
    return result;
  };
  std::ofstream out = open_for_writing(path);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (const PvdDataSet& dataset : datasets) {
    out << "    <DataSet timestep=\"" << exact_text(dataset.timestep) << "\" group=\"\" part=\""
        << dataset.part << "\" file=\"" << escaped(dataset.file) << "\"/>\n";
  }
  out << "  </Collection>\n"
      << "</VTKFile>\n";
  finish_writing(out, path);
}

void write_json(const std::filesystem::path& path, const nlohmann::json& document) {
  ensure_directory(path.parent_path());
  // invalid UTF-8 (e.g. from a path) is replaced rather than thrown after the file is opened
  const std::string text = document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  std::ofstream out = open_for_writing(path);
  out << text << '\n';
  finish_writing(out, path);
}

nlohmann::json vector_json(const Eigen::Vector3d& vector, int dimension) {
  if (dimension == 3) return {vector.x(), vector.y(), vector.z()};
  return {vector.x(), vector.y()};
}

Eigen::Vector3d contact_resultant(const ContactPairing& pairing, const Eigen::VectorXd& force) {
  check_size(force, pairing.size(), "the contact force", "contact_resultant");
  // R = sum_i lambda_i n1_i: lambda_i pushes body 2 along n1_i (from body 1 towards body 2)
  Eigen::Vector3d resultant = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    resultant += force[static_cast<Eigen::Index>(i)] * pairing.pairs[i].normal;
  }
  return resultant;
}

}  // namespace robin
