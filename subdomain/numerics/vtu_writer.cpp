#include "numerics/vtu_writer.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <variant>

#include "numerics/finite_element.hpp"
#include "numerics/zero_run_deflate.hpp"

namespace robin {
namespace {

/// Uncompressed bytes per zlib block (vtkZLibDataCompressor's default block size).
constexpr std::size_t compression_block_size = 32768;
/// libdeflate's fastest level. Its blocks are ordinary zlib streams (RFC 1950), as VTK's
/// vtkZLibDataCompressor reads them; at its level 1 it is faster than zlib's fastest setting
/// (level 1 with run-length matching only) and its output smaller (docs/benchmarks.md).
constexpr int compression_level = 1;

/// One libdeflate compressor, reused for every block of a file.
class BlockCompressor {
 public:
  explicit BlockCompressor(const std::filesystem::path& path)
      : path_(path), compressor_(libdeflate_alloc_compressor(compression_level)) {
    if (compressor_ == nullptr) {
      throw std::runtime_error("cannot write '" + path_.string() +
                               "': no memory for the compressor");
    }
  }
  ~BlockCompressor() { libdeflate_free_compressor(compressor_); }
  BlockCompressor(const BlockCompressor&) = delete;
  BlockCompressor& operator=(const BlockCompressor&) = delete;

  /// The zlib stream of `size` bytes at `data` in `buffer` (resized as needed); returns its size.
  /// Floating-point values go through zero_run_deflate (their bytes compress little beyond
  /// their zero runs, which it keeps at a fraction of libdeflate's time), the rest through
  /// libdeflate.
  std::size_t compress(const char* data, std::size_t size, std::vector<std::uint8_t>& buffer,
                       bool floating_point) {
    if (floating_point) {
      return zero_run_deflate(reinterpret_cast<const std::uint8_t*>(data), size, buffer);
    }
    const std::size_t bound = libdeflate_zlib_compress_bound(compressor_, size);
    if (buffer.size() < bound) buffer.resize(bound);
    const std::size_t written =
        libdeflate_zlib_compress(compressor_, data, size, buffer.data(), buffer.size());
    if (written == 0) {
      throw std::runtime_error("cannot write '" + path_.string() + "': compression failed");
    }
    return written;
  }

 private:
  const std::filesystem::path& path_;
  libdeflate_compressor* compressor_;
};

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

/// "<location> field '<name>' of '<path>'", the start of a message about a field.
std::string field_description(const std::string& name, const char* location,
                              const std::filesystem::path& path) {
  return std::string(location) + " field '" + name + "' of '" + path.string() + "'";
}

/// Refuses an empty name, fewer than one component or more component names than components.
void check_field_attributes(const FieldSource& field, const char* location,
                            const std::filesystem::path& path) {
  if (field.name.empty()) {
    throw std::runtime_error(std::string("a ") + location + " field of '" + path.string() +
                             "' has an empty name");
  }
  const std::string where = field_description(field.name, location, path);
  if (field.components < 1) {
    throw std::runtime_error(where + ": components must be at least 1, got " +
                             std::to_string(field.components));
  }
  if (field.component_names.size() > static_cast<std::size_t>(field.components)) {
    throw std::runtime_error(where + ": more component names than components");
  }
}

/// Refuses a field whose number of values is not components x count.
void check_value_count(const FieldSource& field, std::size_t value_count, std::size_t count,
                       const char* location, const std::filesystem::path& path) {
  const std::size_t expected = count * static_cast<std::size_t>(field.components);
  if (value_count != expected) {
    throw std::runtime_error(field_description(field.name, location, path) + ": expected " +
                             std::to_string(expected) + " values (" +
                             std::to_string(field.components) + " x " + std::to_string(count) +
                             "), got " + std::to_string(value_count));
  }
}

/// The source of a field whose values are at hand (appends a copy of them).
FieldSource source_of(const OutputField& field) {
  return {field.name, field.components, field.component_names,
          [&field](std::vector<double>& values) {
            values.insert(values.end(), field.values.begin(), field.values.end());
          }};
}

void check_connectivity(const std::vector<int>& connectivity, int nodes_per_cell,
                        const std::string& what, const Mesh& mesh,
                        const std::filesystem::path& path) {
  if (connectivity.size() % static_cast<std::size_t>(nodes_per_cell) != 0) {
    throw std::runtime_error("cannot write '" + path.string() + "': " + what +
                             " has a connectivity size that is not a multiple of " +
                             std::to_string(nodes_per_cell));
  }
  for (int node : connectivity) {
    if (node < 0 || static_cast<std::size_t>(node) >= mesh.node_count()) {
      throw std::runtime_error("cannot write '" + path.string() + "': " + what +
                               " has the node index " + std::to_string(node) + ", outside the " +
                               std::to_string(mesh.node_count()) + " nodes");
    }
  }
}

void check_mesh(const Mesh& mesh, bool boundary_cells, const std::filesystem::path& path) {
  for (const ElementBlock& block : mesh.blocks) {
    check_connectivity(block.connectivity, nodes_per_element(block.type),
                       "a " + to_string(block.type) + " block", mesh, path);
  }
  if (!boundary_cells) return;
  for (const auto& [name, group] : mesh.boundaries) {
    check_connectivity(group.connectivity, nodes_per_facet(group.type), "boundary '" + name + "'",
                       mesh, path);
  }
}

/// One DataArray: its XML attributes and its values.
struct DataArray {
  std::string type;  // Float64, Int64, Int32, UInt8 or String
  std::string name;
  int components = 1;
  std::vector<std::string> component_names;
  std::variant<std::vector<double>, std::vector<std::int64_t>, std::vector<std::int32_t>,
               std::vector<std::uint8_t>, std::vector<std::string>>
      values;
};

/// Storage reused by the arrays of one file, made one after another: an array's values are made
/// in the vector of their type taken from here and given back once written (emptied, their
/// capacity kept), so that the pages of a file's arrays are touched in once rather than once
/// per array (a block above the mapping threshold is a fresh mapping each time: heap_memory.hpp).
class ValueStorage {
 public:
  /// The vector for values of type Value, empty, with the capacity of the largest given back.
  template <typename Value>
  std::vector<Value> take() {
    std::vector<Value> values = std::move(std::get<std::vector<Value>>(vectors_));
    values.clear();
    return values;
  }

  /// Makes room for `count` values of type Value (the largest array of that type, made first, so
  /// that the later ones do not reallocate).
  template <typename Value>
  void reserve(std::size_t count) {
    std::get<std::vector<Value>>(vectors_).reserve(count);
  }

  /// Keeps the vector of `array`'s values (a string array's are dropped).
  void give_back(DataArray&& array) {
    std::visit(
        [this](auto& values) {
          using Vector = std::decay_t<decltype(values)>;
          if constexpr (!std::is_same_v<typename Vector::value_type, std::string>) {
            Vector& kept = std::get<Vector>(vectors_);
            if (values.capacity() >= kept.capacity()) kept = std::move(values);
          }
        },
        array.values);
  }

 private:
  std::tuple<std::vector<double>, std::vector<std::int64_t>, std::vector<std::int32_t>,
             std::vector<std::uint8_t>>
      vectors_;
};

/// Makes `values` (`count` items of `components` values) the array as written, in place: 2
/// components padded to 3 (the third zero), then one item per entry of `source`, a copy of
/// item source[j] (NaN where source[j] is -1).
void lay_out_items(std::vector<double>& values, std::size_t count, int components,
                   const std::vector<std::int64_t>& source) {
  const auto given = static_cast<std::size_t>(components);
  const auto written = static_cast<std::size_t>(written_components(components));
  values.resize((count + source.size()) * written, 0.0);
  if (written != given) {  // from the last item down, so that no item is overwritten unread
    for (std::size_t k = count; k-- > 0;) {
      for (std::size_t c = given; c-- > 0;) values[k * written + c] = values[k * given + c];
      for (std::size_t c = given; c < written; ++c) values[k * written + c] = 0.0;
    }
  }
  for (std::size_t j = 0; j < source.size(); ++j) {
    for (std::size_t c = 0; c < written; ++c) {
      values[(count + j) * written + c] =
          source[j] >= 0 ? values[static_cast<std::size_t>(source[j]) * written + c]
                         : std::numeric_limits<double>::quiet_NaN();
    }
  }
}

/// Where a field goes: its location ("point" or "cell"), its item count, the items copied
/// after them (cell fields on boundary facets: adjacent_elements) and the file, for messages.
struct FieldPlace {
  const char* location;
  std::size_t count;
  const std::vector<std::int64_t>& source;
  const std::filesystem::path& path;
};

/// The array of `field` as written (lay_out_items), its values made by the field's source.
DataArray field_array(const FieldSource& field, const FieldPlace& place, ValueStorage& storage) {
  const int written = written_components(field.components);
  std::vector<double> values = storage.take<double>();
  values.reserve((place.count + place.source.size()) * static_cast<std::size_t>(written));
  field.append_values(values);
  check_value_count(field, values.size(), place.count, place.location, place.path);
  lay_out_items(values, place.count, field.components, place.source);
  return {"Float64", field.name, written, field.component_names, std::move(values)};
}

/// The attributes of a field's array (as field_array writes it), without its values.
DataArray attributes_of(const FieldSource& field) {
  return {"Float64", field.name, written_components(field.components), field.component_names, {}};
}

/// Key of a facet by its corner nodes, whatever their order: the sorted corners, -1 padded.
using FacetKey = std::array<int, 4>;

FacetKey facet_key(const int* corners, int count) {
  FacetKey key = {-1, -1, -1, -1};
  std::copy(corners, corners + count, key.begin());
  // Insertion sort of at most four entries (std::sort here draws a false -Warray-bounds from
  // GCC 12 in the sanitizer build).
  for (int i = 1; i < count; ++i) {
    for (int j = i; j > 0 && key[j - 1] > key[j]; --j) std::swap(key[j - 1], key[j]);
  }
  return key;
}

struct FacetKeyHash {
  std::size_t operator()(const FacetKey& key) const {
    std::uint64_t hash = 1469598103934665603ULL;  // FNV-1a over the four corners
    for (const int corner : key) {
      hash ^= static_cast<std::uint64_t>(static_cast<std::uint32_t>(corner));
      hash *= 1099511628211ULL;
    }
    return static_cast<std::size_t>(hash);
  }
};

using FacetElements = std::unordered_map<FacetKey, std::int64_t, FacetKeyHash>;

/// The keys of the facets of every boundary (name order), facet after facet.
std::vector<FacetKey> boundary_facet_keys(const Mesh& mesh) {
  std::vector<FacetKey> keys;
  for (const auto& [name, group] : mesh.boundaries) {
    const auto nodes = static_cast<std::size_t>(nodes_per_facet(group.type));
    const int corners = facet_corner_count(group.type);
    for (std::size_t k = 0; k < group.facet_count(); ++k) {
      keys.push_back(facet_key(&group.connectivity[k * nodes], corners));
    }
  }
  return keys;
}

/// Sets each facet of `elements` still without an element (-1) to the flat index of the first
/// element, in the element order of mesh.blocks, that has it as a side. Only the sides whose
/// corners are all boundary-facet corners are looked up.
void find_first_elements(const Mesh& mesh, FacetElements& elements) {
  std::vector<bool> facet_corner(mesh.node_count(), false);
  for (const auto& [key, element] : elements) {
    for (const int corner : key) {
      if (corner >= 0) facet_corner[static_cast<std::size_t>(corner)] = true;
    }
  }
  std::int64_t flat = 0;
  for (const ElementBlock& block : mesh.blocks) {
    const int nodes = nodes_per_element(block.type);
    const std::vector<std::vector<int>> sides = element_facet_corners(block.type);
    for (std::size_t e = 0; e < block.element_count(); ++e, ++flat) {
      const int* element = block.connectivity.data() + e * static_cast<std::size_t>(nodes);
      for (const std::vector<int>& side : sides) {
        int corners[4];
        bool candidate = true;
        for (std::size_t a = 0; a < side.size(); ++a) {
          corners[a] = element[side[a]];
          candidate = candidate && facet_corner[static_cast<std::size_t>(corners[a])];
        }
        if (!candidate) continue;
        const auto found = elements.find(facet_key(corners, static_cast<int>(side.size())));
        if (found != elements.end() && found->second < 0) found->second = flat;
      }
    }
  }
}

/// For every facet of every boundary (name order), the flat index of the first element that has
/// it as a side (matched by its corner nodes), -1 when none has. Only the boundary facets are
/// kept in a table, not the sides of every element.
std::vector<std::int64_t> adjacent_elements(const Mesh& mesh) {
  const std::vector<FacetKey> keys = boundary_facet_keys(mesh);
  FacetElements elements;
  for (const FacetKey& key : keys) elements.emplace(key, -1);
  find_first_elements(mesh, elements);
  std::vector<std::int64_t> adjacent;
  adjacent.reserve(keys.size());
  for (const FacetKey& key : keys) adjacent.push_back(elements.at(key));
  return adjacent;
}

/// VTK's type number of the quadratic tetrahedron.
constexpr int quadratic_tetrahedron_type = 24;

/// Puts the quadratic tetrahedron at the end of `connectivity` into VTK's node order: Gmsh's,
/// except the last two midside nodes (Gmsh: on edges 3-2 and 3-1), which VTK numbers the other
/// way (edges 1-3, 2-3).
template <typename Index>
void to_vtk_node_order(std::vector<Index>& connectivity) {
  const std::size_t size = connectivity.size();
  std::swap(connectivity[size - 2], connectivity[size - 1]);
}

/// The points (x, y, z per node).
DataArray points_array(const Mesh& mesh, ValueStorage& storage) {
  std::vector<double> points = storage.take<double>();
  points.reserve(3 * mesh.node_count());
  for (const Eigen::Vector3d& node : mesh.nodes)
    points.insert(points.end(), {node.x(), node.y(), node.z()});
  return {"Float64", "Points", 3, {}, std::move(points)};
}

/// Which array of the Cells section.
enum class CellArray { connectivity, offsets, types };

/// The length of the connectivity array: every area (volume) element's nodes, and with
/// boundary cells every boundary facet's.
std::size_t connectivity_length(const Mesh& mesh, bool boundary_cells) {
  std::size_t length = 0;
  for (const ElementBlock& block : mesh.blocks) length += block.connectivity.size();
  if (boundary_cells) {
    for (const auto& [name, group] : mesh.boundaries) length += group.connectivity.size();
  }
  return length;
}

/// Whether connectivity and offsets are written as Int32 (half the bytes to compress and
/// store): when every offset fits, as node indices always do. Int64 otherwise.
bool narrow_cell_indices(const Mesh& mesh, bool boundary_cells) {
  return connectivity_length(mesh, boundary_cells) <=
         static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
}

/// One array of the cells: connectivity, offsets (end of each cell in connectivity) or types,
/// over the area elements block after block, then (with boundary cells) the boundary facets in
/// name order; connectivity and offsets as Index (std::int32_t or std::int64_t).
template <typename Index>
DataArray cell_array(const Mesh& mesh, bool boundary_cells, CellArray which,
                     ValueStorage& storage) {
  std::vector<Index> connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::size_t cell_count = mesh.element_count();
  if (boundary_cells) {
    for (const auto& [name, group] : mesh.boundaries) cell_count += group.facet_count();
  }
  if (which == CellArray::connectivity) {
    connectivity = storage.take<Index>();
    connectivity.reserve(connectivity_length(mesh, boundary_cells));
  } else if (which == CellArray::offsets) {
    offsets = storage.take<Index>();
    offsets.reserve(cell_count);
  } else {
    types = storage.take<std::uint8_t>();
    types.reserve(cell_count);
  }
  Index end = 0;
  const auto add_cells = [&](const std::vector<int>& nodes, int per_cell, int type) {
    for (std::size_t k = 0; k < nodes.size(); k += static_cast<std::size_t>(per_cell)) {
      end += static_cast<Index>(per_cell);
      if (which == CellArray::connectivity) {
        connectivity.insert(connectivity.end(), nodes.begin() + static_cast<std::ptrdiff_t>(k),
                            nodes.begin() + static_cast<std::ptrdiff_t>(k) + per_cell);
        if (type == quadratic_tetrahedron_type) to_vtk_node_order(connectivity);
      } else if (which == CellArray::offsets) {
        offsets.push_back(end);
      } else {
        types.push_back(static_cast<std::uint8_t>(type));
      }
    }
  };
  for (const ElementBlock& block : mesh.blocks) {
    add_cells(block.connectivity, nodes_per_element(block.type), vtk_cell_type(block.type));
  }
  if (boundary_cells) {
    for (const auto& [name, group] : mesh.boundaries) {
      add_cells(group.connectivity, nodes_per_facet(group.type), vtk_cell_type(group.type));
    }
  }
  const std::string index_type = sizeof(Index) == 4 ? "Int32" : "Int64";
  switch (which) {
    case CellArray::connectivity:
      return {index_type, "connectivity", 1, {}, std::move(connectivity)};
    case CellArray::offsets:
      return {index_type, "offsets", 1, {}, std::move(offsets)};
    case CellArray::types:
      break;
  }
  return {"UInt8", "types", 1, {}, std::move(types)};
}

/// The array's values as bytes in the machine's byte order: a view of its own storage, or for
/// strings (each followed by '\0') of `storage`.
std::string_view value_bytes(const DataArray& array, std::string& storage) {
  return std::visit(
      [&storage](const auto& values) {
        using Value = typename std::decay_t<decltype(values)>::value_type;
        if constexpr (std::is_same_v<Value, std::string>) {
          for (const std::string& text : values) {
            storage += text;
            storage.push_back('\0');
          }
          return std::string_view(storage);
        } else {
          return std::string_view(reinterpret_cast<const char*>(values.data()),
                                  values.size() * sizeof(Value));
        }
      },
      array.values);
}

void append_header_word(std::string& blob, std::uint64_t word) {
  std::array<char, sizeof word> bytes;
  std::memcpy(bytes.data(), &word, sizeof word);
  blob.append(bytes.data(), bytes.size());
}

/// Writes the array's values as text: numbers separated by spaces; a string as the codes of
/// its characters followed by 0 (VTK's ASCII form of a string array).
void write_ascii_values(std::ofstream& out, const DataArray& array) {
  std::visit(
      [&](const auto& values) {
        using Value = typename std::decay_t<decltype(values)>::value_type;
        const std::size_t per_line = static_cast<std::size_t>(array.components);
        for (std::size_t k = 0; k < values.size(); ++k) {
          out << (k % per_line == 0 ? "\n          " : " ");
          if constexpr (std::is_same_v<Value, std::string>) {
            for (char character : values[k]) {
              write_number(out, std::int64_t{static_cast<unsigned char>(character)});
              out << ' ';
            }
            out << '0';
          } else if constexpr (std::is_same_v<Value, double>) {
            write_number(out, values[k]);
          } else {
            write_number(out, static_cast<std::int64_t>(values[k]));
          }
        }
        out << "\n        ";
      },
      array.values);
}

/// Width reserved for an offset in the XML (a uint64 has at most 20 digits) and its closing quote.
constexpr std::size_t offset_width = 21;

/// Writes the DataArray elements as they come. ASCII: each with its values. Binary: each with
/// room for its offset into the appended data; finish() then makes the arrays again one at a
/// time, streams their compressed records after the XML and writes every offset into its room
/// ("123" followed by spaces up to the element's end). So only one array's values are in memory
/// at a time, and one compressed block, never the whole appended block.
class ArrayWriter {
 public:
  ArrayWriter(std::ofstream& out, VtuEncoding encoding, const std::filesystem::path& path)
      : out_(out), encoding_(encoding), compressor_(path) {}

  /// `array` holds the attributes (and a string array's values); `make` makes its values when
  /// they are written (called once, after the XML in binary mode).
  void write(const DataArray& array, std::function<DataArray(ValueStorage&)> make) {
    out_ << "        <DataArray type=\"" << array.type << "\" Name=\"" << escape_xml(array.name)
         << '"';
    if (const auto* strings = std::get_if<std::vector<std::string>>(&array.values)) {
      out_ << " NumberOfTuples=\"" << strings->size() << '"';
    } else {
      out_ << " NumberOfComponents=\"" << array.components << '"';
    }
    for (std::size_t c = 0; c < array.component_names.size(); ++c) {
      out_ << " ComponentName" << c << "=\"" << escape_xml(array.component_names[c]) << '"';
    }
    if (encoding_ == VtuEncoding::ascii) {
      out_ << " format=\"ascii\">";
      DataArray values = make(storage_);
      write_ascii_values(out_, values);
      storage_.give_back(std::move(values));
      out_ << "</DataArray>\n";
      return;
    }
    out_ << " format=\"appended\" offset=\"";
    pending_.push_back({out_.tellp(), std::move(make)});
    out_ << std::string(offset_width, ' ') << "/>\n";
  }

  /// Room for the largest floating-point array (ValueStorage::reserve).
  void reserve_floating_point_values(std::size_t count) { storage_.reserve<double>(count); }

  /// A small array whose values are at hand.
  void write(DataArray array) {
    auto values = std::make_shared<DataArray>(std::move(array));
    write(*values, [values](ValueStorage&) { return std::move(*values); });
  }

  /// Binary: the appended data (every record, in the order of the elements), then the offsets.
  void finish() {
    if (encoding_ == VtuEncoding::ascii) return;
    out_ << "  <AppendedData encoding=\"raw\">\n   _";
    std::uint64_t offset = 0;
    std::vector<std::uint64_t> offsets;
    for (PendingArray& pending : pending_) {
      offsets.push_back(offset);
      std::string storage;
      DataArray array = pending.make(storage_);
      const bool floating_point = std::holds_alternative<std::vector<double>>(array.values);
      offset += write_compressed_record(value_bytes(array, storage), floating_point);
      storage_.give_back(std::move(array));
      pending.make = nullptr;
    }
    out_ << "\n  </AppendedData>\n"
         << "</VTKFile>\n";
    for (std::size_t k = 0; k < pending_.size(); ++k) {
      out_.seekp(pending_[k].position);
      out_ << offsets[k] << '"';
    }
    out_.seekp(0, std::ios::end);
  }

 private:
  struct PendingArray {
    std::streampos position;  // of the offset's room
    std::function<DataArray(ValueStorage&)> make;
  };

  /// Writes the appended-data record of `bytes` in vtkZLibDataCompressor's layout (see the
  /// header), each block as it is compressed, its size written afterwards into the record's
  /// header; returns the record's size in bytes.
  std::uint64_t write_compressed_record(std::string_view bytes, bool floating_point) {
    const std::size_t full_blocks = bytes.size() / compression_block_size;
    const std::size_t last_block = bytes.size() % compression_block_size;
    const std::size_t block_count = full_blocks + (last_block != 0 ? 1 : 0);
    std::string header;
    append_header_word(header, block_count);
    append_header_word(header, compression_block_size);
    append_header_word(header, last_block);
    const std::streampos sizes_position = out_.tellp() + std::streamoff(header.size());
    header.append(block_count * sizeof(std::uint64_t), '\0');  // the sizes, written below
    out_.write(header.data(), static_cast<std::streamsize>(header.size()));
    std::string sizes;
    std::uint64_t record_size = header.size();
    for (std::size_t block = 0; block < block_count; ++block) {
      const std::size_t begin = block * compression_block_size;
      const std::size_t size = std::min(compression_block_size, bytes.size() - begin);
      const std::size_t compressed_size =
          compressor_.compress(bytes.data() + begin, size, buffer_, floating_point);
      out_.write(reinterpret_cast<const char*>(buffer_.data()),
                 static_cast<std::streamsize>(compressed_size));
      append_header_word(sizes, compressed_size);
      record_size += compressed_size;
    }
    out_.seekp(sizes_position);
    out_.write(sizes.data(), static_cast<std::streamsize>(sizes.size()));
    out_.seekp(0, std::ios::end);
    return record_size;
  }

  std::ofstream& out_;
  VtuEncoding encoding_;
  std::vector<PendingArray> pending_;
  BlockCompressor compressor_;
  std::vector<std::uint8_t> buffer_;  // one compressed block
  ValueStorage storage_;
};

/// The Cells section's arrays, Int32 or Int64 as narrow_cell_indices says.
void write_cell_arrays(ArrayWriter& writer, const Mesh& mesh, bool boundary_cells) {
  const bool narrow = narrow_cell_indices(mesh, boundary_cells);
  const std::string index_type = narrow ? "Int32" : "Int64";
  for (const auto& [which, name] : {std::pair{CellArray::connectivity, "connectivity"},
                                    std::pair{CellArray::offsets, "offsets"}}) {
    writer.write({index_type, name, 1, {}, {}},
                 [&mesh, boundary_cells, narrow, which = which](ValueStorage& storage) {
                   return narrow ? cell_array<std::int32_t>(mesh, boundary_cells, which, storage)
                                 : cell_array<std::int64_t>(mesh, boundary_cells, which, storage);
                 });
  }
  writer.write({"UInt8", "types", 1, {}, {}}, [&mesh, boundary_cells](ValueStorage& storage) {
    return cell_array<std::int32_t>(mesh, boundary_cells, CellArray::types, storage);
  });
}

/// The Piece element: its PointData, CellData (with boundary_id when `boundary_cells`), Points
/// and Cells.
void write_piece(std::ofstream& out, ArrayWriter& writer, const Mesh& mesh,
                 const std::vector<FieldSource>& point_fields,
                 const std::vector<FieldSource>& cell_fields,
                 const std::vector<std::int64_t>& adjacent, std::vector<std::int32_t> boundary_id,
                 bool boundary_cells, const std::filesystem::path& path) {
  static const std::vector<std::int64_t> no_items;
  const FieldPlace points{"point", mesh.node_count(), no_items, path};
  const FieldPlace cells{"cell", mesh.element_count(), adjacent, path};
  std::size_t largest = 3 * points.count;  // the points
  for (const FieldSource& field : point_fields) {
    largest = std::max(largest, points.count * written_components(field.components));
  }
  for (const FieldSource& field : cell_fields) {
    largest =
        std::max(largest, (cells.count + adjacent.size()) * written_components(field.components));
  }
  writer.reserve_floating_point_values(largest);
  out << "    <Piece NumberOfPoints=\"" << points.count << "\" NumberOfCells=\""
      << boundary_id.size() << "\">\n"
      << "      <PointData>\n";
  for (const FieldSource& field : point_fields) {
    writer.write(attributes_of(field), [&field, points](ValueStorage& storage) {
      return field_array(field, points, storage);
    });
  }
  out << "      </PointData>\n"
      << "      <CellData>\n";
  for (const FieldSource& field : cell_fields) {
    writer.write(attributes_of(field), [&field, cells](ValueStorage& storage) {
      return field_array(field, cells, storage);
    });
  }
  if (boundary_cells) writer.write({"Int32", "boundary_id", 1, {}, std::move(boundary_id)});
  out << "      </CellData>\n"
      << "      <Points>\n";
  writer.write({"Float64", "Points", 3, {}, {}},
               [&mesh](ValueStorage& storage) { return points_array(mesh, storage); });
  out << "      </Points>\n"
      << "      <Cells>\n";
  write_cell_arrays(writer, mesh, boundary_cells);
  out << "      </Cells>\n"
      << "    </Piece>\n";
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
    case ElementType::tetrahedron4:
      return 10;
    case ElementType::tetrahedron10:
      return 24;
    case ElementType::hexahedron8:
      return 12;
  }
  throw std::invalid_argument("vtk_cell_type: unknown element type");
}

int vtk_cell_type(FacetType type) {
  switch (type) {
    case FacetType::line2:
      return 3;
    case FacetType::line3:
      return 21;
    case FacetType::triangle3:
      return 5;
    case FacetType::triangle6:
      return 22;
    case FacetType::quadrilateral4:
      return 9;
  }
  throw std::invalid_argument("vtk_cell_type: unknown facet type");
}

namespace {

/// write_streamed_vtu once the mesh and every field's attributes are checked.
void write_checked_vtu(const std::filesystem::path& path, const Mesh& mesh,
                       const std::vector<FieldSource>& point_fields,
                       const std::vector<FieldSource>& cell_fields, const VtuOptions& options) {
  const std::vector<std::int64_t> adjacent =
      options.boundary_cells ? adjacent_elements(mesh) : std::vector<std::int64_t>{};
  std::vector<std::int32_t> boundary_id(mesh.element_count(), 0);
  std::vector<std::string> boundary_names;
  if (options.boundary_cells) {
    for (const auto& [name, group] : mesh.boundaries) {
      boundary_names.push_back(name);
      boundary_id.insert(boundary_id.end(), group.facet_count(),
                         static_cast<std::int32_t>(boundary_names.size()));
    }
  }

  std::ofstream out = open_for_writing(path);
  const bool binary = options.encoding == VtuEncoding::binary_zlib;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
      << (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian")
      << "\" header_type=\"UInt64\"" << (binary ? " compressor=\"vtkZLibDataCompressor\"" : "")
      << ">\n"
      << "  <UnstructuredGrid>\n";
  ArrayWriter writer(out, options.encoding, path);
  if (!boundary_names.empty()) {
    out << "    <FieldData>\n";
    writer.write({"String", "boundary_names", 1, {}, boundary_names});
    out << "    </FieldData>\n";
  }
  write_piece(out, writer, mesh, point_fields, cell_fields, adjacent, std::move(boundary_id),
              options.boundary_cells, path);
  out << "  </UnstructuredGrid>\n";
  if (binary) {
    writer.finish();
  } else {
    out << "</VTKFile>\n";
  }
  finish_writing(out, path);
}

std::vector<FieldSource> sources_of(const std::vector<OutputField>& fields) {
  std::vector<FieldSource> sources;
  sources.reserve(fields.size());
  for (const OutputField& field : fields) sources.push_back(source_of(field));
  return sources;
}

}  // namespace

void write_vtu(const std::filesystem::path& path, const Mesh& mesh,
               const std::vector<OutputField>& point_fields,
               const std::vector<OutputField>& cell_fields, const VtuOptions& options) {
  check_mesh(mesh, options.boundary_cells, path);
  const std::vector<FieldSource> points = sources_of(point_fields);
  const std::vector<FieldSource> cells = sources_of(cell_fields);
  for (std::size_t k = 0; k < points.size(); ++k) {
    check_field_attributes(points[k], "point", path);
    check_value_count(points[k], point_fields[k].values.size(), mesh.node_count(), "point", path);
  }
  for (std::size_t k = 0; k < cells.size(); ++k) {
    check_field_attributes(cells[k], "cell", path);
    check_value_count(cells[k], cell_fields[k].values.size(), mesh.element_count(), "cell", path);
  }
  write_checked_vtu(path, mesh, points, cells, options);
}

void write_streamed_vtu(const std::filesystem::path& path, const Mesh& mesh,
                        const std::vector<FieldSource>& point_fields,
                        const std::vector<FieldSource>& cell_fields, const VtuOptions& options) {
  check_mesh(mesh, options.boundary_cells, path);
  for (const FieldSource& field : point_fields) check_field_attributes(field, "point", path);
  for (const FieldSource& field : cell_fields) check_field_attributes(field, "cell", path);
  write_checked_vtu(path, mesh, point_fields, cell_fields, options);
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
