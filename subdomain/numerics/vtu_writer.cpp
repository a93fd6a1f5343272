#include "numerics/vtu_writer.hpp"

#include <array>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <locale>
#include <stdexcept>
#include <system_error>

namespace robin {
namespace {

/// Text escaped for an XML attribute value.
std::string escape_xml(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char character : text) {
    switch (character) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&apos;";
        break;
      default:
        escaped += character;
    }
  }
  return escaped;
}

/// Shortest decimal text of `value` that parses back to the same double (locale independent).
void write_number(std::ofstream& out, double value) {
  std::array<char, 32> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.write(buffer.data(), result.ptr - buffer.data());
}

void write_number(std::ofstream& out, std::int64_t value) {
  std::array<char, 24> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.write(buffer.data(), result.ptr - buffer.data());
}

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw std::runtime_error("cannot open '" + path.string() +
                             "' for writing: check that its directory exists and is writable");
  }
  return out;
}

void finish_writing(std::ofstream& out, const std::filesystem::path& path) {
  out.close();
  if (!out) throw std::runtime_error("error while writing '" + path.string() + "' (disk full?)");
}

/// The components written for a field: 2 become 3 (z = 0) so ParaView sees a vector.
int written_components(int components) {
  return components == 2 ? 3 : components;
}

void check_field(const OutputField& field, std::size_t count, const char* location,
                 const std::filesystem::path& path) {
  const std::string where =
      std::string(location) + " field '" + field.name + "' of '" + path.string() + "'";
  if (field.name.empty()) {
    throw std::runtime_error(std::string("a ") + location + " field of '" + path.string() +
                             "' has an empty name");
  }
  if (field.components < 1) {
    throw std::runtime_error(where + ": components must be at least 1, got " +
                             std::to_string(field.components));
  }
  const std::size_t expected = count * static_cast<std::size_t>(field.components);
  if (field.values.size() != expected) {
    throw std::runtime_error(where + ": expected " + std::to_string(expected) + " values (" +
                             std::to_string(field.components) + " x " + std::to_string(count) +
                             "), got " + std::to_string(field.values.size()));
  }
  if (field.component_names.size() > static_cast<std::size_t>(field.components)) {
    throw std::runtime_error(where + ": more component names than components");
  }
}

void write_field(std::ofstream& out, const OutputField& field, std::size_t count) {
  const int components = written_components(field.components);
  out << "        <DataArray type=\"Float64\" Name=\"" << escape_xml(field.name)
      << "\" NumberOfComponents=\"" << components << '"';
  for (std::size_t c = 0; c < field.component_names.size(); ++c) {
    out << " ComponentName" << c << "=\"" << escape_xml(field.component_names[c]) << '"';
  }
  out << " format=\"ascii\">\n";
  for (std::size_t k = 0; k < count; ++k) {
    out << "         ";
    for (int c = 0; c < components; ++c) {
      const bool padding = c >= field.components;
      out << ' ';
      write_number(out, padding ? 0.0 : field.values[k * field.components + c]);
    }
    out << '\n';
  }
  out << "        </DataArray>\n";
}

void write_field_section(std::ofstream& out, const char* section,
                         const std::vector<OutputField>& fields, std::size_t count) {
  out << "      <" << section << ">\n";
  for (const OutputField& field : fields) write_field(out, field, count);
  out << "      </" << section << ">\n";
}

void write_points(std::ofstream& out, const Mesh& mesh) {
  out << "      <Points>\n"
      << "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (const Eigen::Vector2d& node : mesh.nodes) {
    out << "          ";
    write_number(out, node.x());
    out << ' ';
    write_number(out, node.y());
    out << " 0\n";
  }
  out << "        </DataArray>\n"
      << "      </Points>\n";
}

/// Connectivity, offsets (end of each cell in connectivity) and types, block after block.
void write_cells(std::ofstream& out, const Mesh& mesh) {
  out << "      <Cells>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const ElementBlock& block : mesh.blocks) {
    const std::size_t nodes = nodes_per_element(block.type);
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      out << "         ";
      for (std::size_t a = 0; a < nodes; ++a) {
        out << ' ';
        write_number(out, std::int64_t{block.connectivity[e * nodes + a]});
      }
      out << '\n';
    }
  }
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  std::int64_t offset = 0;
  for (const ElementBlock& block : mesh.blocks) {
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      offset += nodes_per_element(block.type);
      out << "          ";
      write_number(out, offset);
      out << '\n';
    }
  }
  out << "        </DataArray>\n"
      << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (const ElementBlock& block : mesh.blocks) {
    const int type = vtk_cell_type(block.type);
    for (std::size_t e = 0; e < block.element_count(); ++e) out << "          " << type << '\n';
  }
  out << "        </DataArray>\n"
      << "      </Cells>\n";
}

void check_connectivity(const Mesh& mesh, const std::filesystem::path& path) {
  for (const ElementBlock& block : mesh.blocks) {
    if (block.connectivity.size() % nodes_per_element(block.type) != 0) {
      throw std::runtime_error("cannot write '" + path.string() + "': a " + to_string(block.type) +
                               " block has a connectivity size that is not a multiple of " +
                               std::to_string(nodes_per_element(block.type)));
    }
    for (int node : block.connectivity) {
      if (node < 0 || static_cast<std::size_t>(node) >= mesh.node_count()) {
        throw std::runtime_error("cannot write '" + path.string() + "': element node index " +
                                 std::to_string(node) + " is outside the " +
                                 std::to_string(mesh.node_count()) + " nodes");
      }
    }
  }
}

}  // namespace

int vtk_cell_type(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return 5;
    case ElementType::triangle6:
      return 22;
    case ElementType::quadrilateral4:
      return 9;
  }
  throw std::invalid_argument("vtk_cell_type: unknown element type");
}

void write_vtu(const std::filesystem::path& path, const Mesh& mesh,
               const std::vector<OutputField>& point_fields,
               const std::vector<OutputField>& cell_fields) {
  const std::size_t node_count = mesh.node_count();
  std::size_t element_count = 0;
  for (const ElementBlock& block : mesh.blocks) element_count += block.element_count();
  check_connectivity(mesh, path);
  for (const OutputField& field : point_fields) check_field(field, node_count, "point", path);
  for (const OutputField& field : cell_fields) check_field(field, element_count, "cell", path);

  std::ofstream out = open_for_writing(path);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << node_count << "\" NumberOfCells=\"" << element_count
      << "\">\n";
  write_field_section(out, "PointData", point_fields, node_count);
  write_field_section(out, "CellData", cell_fields, element_count);
  write_points(out, mesh);
  write_cells(out, mesh);
  out << "    </Piece>\n"
      << "  </UnstructuredGrid>\n"
      << "</VTKFile>\n";
  finish_writing(out, path);
}

void write_pvd(const std::filesystem::path& path, const std::vector<std::string>& datasets) {
  std::ofstream out = open_for_writing(path);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (std::size_t part = 0; part < datasets.size(); ++part) {
    out << "    <DataSet timestep=\"0\" group=\"\" part=\"" << part << "\" file=\""
        << escape_xml(datasets[part]) << "\"/>\n";
  }
  out << "  </Collection>\n"
      << "</VTKFile>\n";
  finish_writing(out, path);
}

}  // namespace robin
