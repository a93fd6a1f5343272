#include "numerics/msh_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"

namespace robin {

namespace {

// ---------------------------------------------------------------------------------------------
// Element types of the MSH format

/// An MSH element type: its dimension, node count and Gmsh's name.
struct MshElementKind {
  int dimension;
  int node_count;
  const char* name;
};

/// The MSH element types Gmsh reads into a model (points to 125-node hexahedra); nullptr for
/// any other number.
const MshElementKind* msh_element_kind(std::int64_t type) {
  static const std::map<std::int64_t, MshElementKind> kinds = {
      {1, {1, 2, "Line 2"}},           {2, {2, 3, "Triangle 3"}},
      {3, {2, 4, "Quadrilateral 4"}},  {4, {3, 4, "Tetrahedron 4"}},
      {5, {3, 8, "Hexahedron 8"}},     {6, {3, 6, "Prism 6"}},
      {7, {3, 5, "Pyramid 5"}},        {8, {1, 3, "Line 3"}},
      {9, {2, 6, "Triangle 6"}},       {10, {2, 9, "Quadrilateral 9"}},
      {11, {3, 10, "Tetrahedron 10"}}, {12, {3, 27, "Hexahedron 27"}},
      {13, {3, 18, "Prism 18"}},       {14, {3, 14, "Pyramid 14"}},
      {15, {0, 1, "Point"}},           {16, {2, 8, "Quadrilateral 8"}},
      {17, {3, 20, "Hexahedron 20"}},  {18, {3, 15, "Prism 15"}},
      {19, {3, 13, "Pyramid 13"}},     {20, {2, 9, "Triangle 9"}},
      {21, {2, 10, "Triangle 10"}},    {22, {2, 12, "Triangle 12"}},
      {23, {2, 15, "Triangle 15"}},    {24, {2, 15, "Triangle 15I"}},
      {25, {2, 21, "Triangle 21"}},    {26, {1, 4, "Line 4"}},
      {27, {1, 5, "Line 5"}},          {28, {1, 6, "Line 6"}},
      {29, {3, 20, "Tetrahedron 20"}}, {30, {3, 35, "Tetrahedron 35"}},
      {31, {3, 56, "Tetrahedron 56"}}, {92, {3, 64, "Hexahedron 64"}},
      {93, {3, 125, "Hexahedron 125"}}};
  const auto found = kinds.find(type);
  return found == kinds.end() ? nullptr : &found->second;
}

std::string msh_element_name(int type) {
  const MshElementKind* kind = msh_element_kind(type);
  return std::string(kind ? kind->name : "unknown") + " (Gmsh type " + std::to_string(type) + ")";
}

// ---------------------------------------------------------------------------------------------
// The file's contents, as Gmsh's model holds them

/// The elements of one type in one entity, in file order: their tags and node tags.
struct MshElementList {
  std::vector<std::size_t> element_tags;
  std::vector<std::size_t> node_tags;
};

/// The elements of one entity by MSH type (ascending, as Gmsh's getElements lists them).
using MshEntityElements = std::map<int, MshElementList>;

struct MshModel {
  /// Per dimension (0 to 3): entity tag -> its physical tags.
  std::array<std::map<int, std::vector<int>>, 4> entities;
  std::map<std::pair<int, int>, std::string> physical_names;  // (dimension, tag) -> name
  std::vector<std::size_t> node_tags;                         // file order
  std::vector<double> coordinates;                            // x, y, z per node
  /// (dimension, entity tag) -> its elements.
  std::map<std::pair<int, int>, MshEntityElements> elements;
  /// MSH 2.2: Gmsh keeps only the nodes some element uses (4.1 keeps every node).
  bool only_used_nodes = false;
};

// ---------------------------------------------------------------------------------------------
// The byte scanner

/// A file's bytes mapped read-only: the page cache's pages, neither copied nor zeroed first
/// (reading into a buffer costs a fresh zeroed page and a copy per 4 KiB). Like every mapping,
/// it assumes the file is not truncated while it is read.
class MappedFile {
 public:
  /// How much of the file will be read: all of it (its pages are mapped at once) or its
  /// beginning (pages mapped as they are read).
  enum class Reading { whole, beginning };

  /// Throws InputError naming `shown` when the file cannot be opened, sized or mapped.
  MappedFile(const std::filesystem::path& path, const std::string& shown,
             Reading reading = Reading::whole) {
    const int descriptor = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (descriptor < 0) throw InputError("mesh file '" + shown + "': the file cannot be opened");
    struct stat status {};
    const bool sized = fstat(descriptor, &status) == 0 && S_ISREG(status.st_mode);
    size_ = sized ? static_cast<std::size_t>(status.st_size) : 0;
    if (sized && size_ > 0) {
      const int populate = reading == Reading::whole ? MAP_POPULATE : 0;
      void* mapped = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | populate, descriptor, 0);
      data_ = mapped == MAP_FAILED ? nullptr : static_cast<const char*>(mapped);
    }
    close(descriptor);
    if (!sized || (size_ > 0 && data_ == nullptr)) {
      throw InputError("mesh file '" + shown + "': the file cannot be read");
    }
  }
  ~MappedFile() {
    if (data_ != nullptr) munmap(const_cast<char*>(data_), size_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view bytes() const { return {data_ != nullptr ? data_ : "", size_}; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

/// Reads the file's bytes: ASCII tokens (whitespace-separated, as Gmsh's fscanf reads them) and
/// little-endian binary values; every error names the file and the line (ASCII) or byte offset
/// (binary files) where it was found.
class MshScanner {
 public:
  MshScanner(std::string_view bytes, std::string name) : bytes_(bytes), name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& problem) const { fail_at(position_, problem); }
  [[noreturn]] void fail_at(std::size_t position, const std::string& problem) const {
    throw InputError(name_ + " " + location(position) + ": " + problem);
  }
  std::string location(std::size_t position) const {
    if (binary_) return "byte " + std::to_string(position);
    const auto end = bytes_.begin() + static_cast<std::ptrdiff_t>(position);
    return "line " + std::to_string(1 + std::count(bytes_.begin(), end, '\n'));
  }

  /// Where the next value begins: whitespace skipped in ASCII (never in binary data).
  std::size_t next_position() {
    if (!binary_) skip_space();
    return position_;
  }

  void set_binary(bool binary) { binary_ = binary; }
  bool binary() const { return binary_; }
  std::size_t bytes_left() const { return bytes_.size() - position_; }
  std::size_t position() const { return position_; }

  /// Skips whitespace; true when bytes remain.
  bool skip_space() {
    while (position_ < bytes_.size() && is_space(bytes_[position_])) ++position_;
    return position_ < bytes_.size();
  }
  /// The next whitespace-separated word ("" at the end of the file).
  std::string_view word() {
    skip_space();
    const std::size_t begin = position_;
    while (position_ < bytes_.size() && !is_space(bytes_[position_])) ++position_;
    return bytes_.substr(begin, position_ - begin);
  }
  /// Skips the rest of the current line, its end included.
  void next_line() {
    const std::size_t end = bytes_.find('\n', position_);
    position_ = end == std::string::npos ? bytes_.size() : end + 1;
  }

  /// The next ASCII integer, within [minimum, maximum]; `what` names it in messages.
  std::int64_t integer(const char* what, std::int64_t minimum, std::int64_t maximum) {
    skip_space();
    const std::size_t begin = position_;
    std::int64_t value = 0;
    const auto [end, error] =
        std::from_chars(bytes_.data() + begin, bytes_.data() + bytes_.size(), value);
    if (error != std::errc() || !ends_word(end) || value < minimum || value > maximum) {
      const std::string_view text = word();  // for the message
      if (text.empty()) fail_at(begin, std::string("the file ends where ") + what + " is expected");
      fail_at(begin, std::string(what) + " '" + std::string(text.substr(0, 40)) +
                         "' is not an integer in [" + std::to_string(minimum) + ", " +
                         std::to_string(maximum) + "]");
    }
    position_ = static_cast<std::size_t>(end - bytes_.data());
    return value;
  }
  /// The next ASCII real number, finite.
  double real(const char* what) {
    skip_space();
    const std::size_t begin = position_;
    const bool plus = begin < bytes_.size() && bytes_[begin] == '+';
    double value = 0.0;
    const auto [end, error] = std::from_chars(bytes_.data() + begin + (plus ? 1 : 0),
                                              bytes_.data() + bytes_.size(), value);
    if (error != std::errc() || !ends_word(end) || !std::isfinite(value)) {
      const std::string_view text = word();  // for the message
      if (text.empty()) fail_at(begin, std::string("the file ends where ") + what + " is expected");
      fail_at(begin, std::string(what) + " '" + std::string(text.substr(0, 40)) +
                         "' is not a finite real number");
    }
    position_ = static_cast<std::size_t>(end - bytes_.data());
    return value;
  }

  /// The next binary value of type Value (little-endian).
  template <typename Value>
  Value binary_value(const char* what) {
    Value value{};
    if (bytes_left() < sizeof value) {
      fail(std::string("the file ends where ") + what + " is expected");
    }
    std::memcpy(&value, bytes_.data() + position_, sizeof value);
    position_ += sizeof value;
    return value;
  }

  /// Checks that `count` items of at least `item_bytes` bytes each fit in the rest of the file;
  /// `items` names them ("nodes").
  void check_count(std::uint64_t count, std::size_t item_bytes, const std::string& where,
                   const std::string& items) const {
    if (count > bytes_left() / item_bytes) {
      fail(where + " declares " + std::to_string(count) + " " + items + " but the file has " +
           std::to_string(bytes_left()) + " bytes left");
    }
  }

  /// Expects the word `marker` (e.g. "$EndNodes") next.
  void expect(std::string_view marker) {
    skip_space();
    const std::size_t begin = position_;
    const std::string_view found = word();
    if (found != marker) {
      fail_at(begin, "expected " + std::string(marker) + ", found " +
                         (found.empty() ? std::string("the end of the file")
                                        : "'" + std::string(found.substr(0, 40)) + "'"));
    }
  }

  /// Skips to the line after the line "$End<section>".
  void skip_section(std::string_view section) {
    const std::string marker = "$End" + std::string(section.substr(1));
    for (std::size_t at = bytes_.find(marker, position_); at != std::string::npos;
         at = bytes_.find(marker, at + 1)) {
      const std::size_t end = at + marker.size();
      const bool line_start = at == 0 || bytes_[at - 1] == '\n';
      if (line_start && (end == bytes_.size() || is_space(bytes_[end]))) {
        position_ = end;
        return;
      }
    }
    fail("section " + std::string(section) + " has no " + marker);
  }

  /// The next double-quoted text on the current line.
  std::string quoted(const char* what) {
    skip_space();
    const std::size_t begin = position_;
    if (position_ >= bytes_.size() || bytes_[position_] != '"') {
      fail(std::string("expected ") + what + " in double quotes");
    }
    const std::size_t end = bytes_.find_first_of("\"\n", position_ + 1);
    if (end == std::string::npos || bytes_[end] != '"') {
      fail_at(begin, std::string(what) + " has no closing double quote on its line");
    }
    position_ = end + 1;
    return std::string(bytes_.substr(begin + 1, end - begin - 1));
  }

 private:
  /// True when a number parsed up to `end` is a whole word: whitespace or the end follows.
  bool ends_word(const char* end) const {
    return end == bytes_.data() + bytes_.size() || is_space(*end);
  }
  static bool is_space(char character) {
    return character == ' ' || character == '\n' || character == '\r' || character == '\t' ||
           character == '\v' || character == '\f';
  }

  std::string_view bytes_;
  std::string name_;
  std::size_t position_ = 0;
  bool binary_ = false;
};

// ---------------------------------------------------------------------------------------------
// Section readers

constexpr std::int64_t int_maximum = std::numeric_limits<int>::max();
constexpr std::int64_t int64_maximum = std::numeric_limits<std::int64_t>::max();

/// Reads an integer field written as a 4-byte int in binary files.
int read_int(MshScanner& scanner, const char* what, std::int64_t minimum = -int_maximum) {
  if (!scanner.binary()) return static_cast<int>(scanner.integer(what, minimum, int_maximum));
  const std::size_t at = scanner.next_position();
  const std::int32_t value = scanner.binary_value<std::int32_t>(what);
  if (value < minimum) {
    scanner.fail_at(at, std::string(what) + " " + std::to_string(value) + " is below " +
                            std::to_string(minimum));
  }
  return value;
}

/// Reads a count or tag written as an 8-byte size_t in MSH 4.1 binary files.
std::uint64_t read_size(MshScanner& scanner, const char* what) {
  if (!scanner.binary()) return static_cast<std::uint64_t>(scanner.integer(what, 0, int64_maximum));
  return scanner.binary_value<std::uint64_t>(what);
}

double read_real(MshScanner& scanner, const char* what) {
  if (!scanner.binary()) return scanner.real(what);
  const std::size_t at = scanner.next_position();
  const double value = scanner.binary_value<double>(what);
  if (!std::isfinite(value)) scanner.fail_at(at, std::string(what) + " is not finite");
  return value;
}

/// After the count line of an MSH 2.2 binary section: its binary data starts on the next line.
void start_binary_data(MshScanner& scanner) {
  if (scanner.binary()) scanner.next_line();
}

/// Adds a node (tag >= 1) with its coordinates.
void add_node(MshScanner& scanner, MshModel& model, std::uint64_t tag, std::size_t at) {
  if (tag == 0 || tag > static_cast<std::uint64_t>(int64_maximum)) {
    scanner.fail_at(at, "node tag " + std::to_string(tag) + " is not a positive integer");
  }
  model.node_tags.push_back(tag);
  for (const char* what : {"node x", "node y", "node z"}) {
    model.coordinates.push_back(read_real(scanner, what));
  }
}

void read_physical_names(MshScanner& scanner, MshModel& model) {
  const std::int64_t count = scanner.integer("the number of physical names", 0, int64_maximum);
  scanner.check_count(static_cast<std::uint64_t>(count), 7, "$PhysicalNames", "names");
  for (std::int64_t k = 0; k < count; ++k) {
    const int dimension = static_cast<int>(scanner.integer("a physical name's dimension", 0, 3));
    const int tag = static_cast<int>(scanner.integer("a physical tag", 1, int_maximum));
    model.physical_names[{dimension, tag}] = scanner.quoted("a physical name");
  }
  scanner.expect("$EndPhysicalNames");
}

/// MSH 4.1 $Entities: every entity and its physical tags (the bounding box and bounding
/// entities are skipped).
void read_entities(MshScanner& scanner, MshModel& model) {
  std::array<std::uint64_t, 4> counts{};
  for (std::uint64_t& count : counts) count = read_size(scanner, "an entity count");
  const std::size_t entity_bytes = scanner.binary() ? 4 + 24 + 8 : 10;
  static const char* const kinds[4] = {"points", "curves", "surfaces", "volumes"};
  for (int dimension = 0; dimension < 4; ++dimension) {
    scanner.check_count(counts[dimension], entity_bytes, "$Entities", kinds[dimension]);
  }
  scanner.check_count(counts[0] + counts[1] + counts[2] + counts[3], entity_bytes, "$Entities",
                      "entities");  // each below the file's size: no overflow
  const std::size_t tag_bytes = scanner.binary() ? 4 : 2;
  for (int dimension = 0; dimension < 4; ++dimension) {
    for (std::uint64_t k = 0; k < counts[dimension]; ++k) {
      const int tag = read_int(scanner, "an entity tag", 1);
      for (int c = 0; c < (dimension == 0 ? 3 : 6); ++c) read_real(scanner, "an entity's box");
      const std::uint64_t physical_count = read_size(scanner, "a physical tag count");
      scanner.check_count(physical_count, tag_bytes, "entity " + std::to_string(tag),
                          "physical tags");
      std::vector<int>& physicals = model.entities[dimension][tag];
      for (std::uint64_t p = 0; p < physical_count; ++p) {
        physicals.push_back(std::abs(read_int(scanner, "a physical tag")));
      }
      if (dimension == 0) continue;
      const std::uint64_t bounding_count = read_size(scanner, "a bounding entity count");
      scanner.check_count(bounding_count, tag_bytes, "entity " + std::to_string(tag),
                          "bounding entities");
      for (std::uint64_t b = 0; b < bounding_count; ++b) read_int(scanner, "a bounding entity");
    }
  }
  scanner.expect("$EndEntities");
}

void read_nodes_22(MshScanner& scanner, MshModel& model) {
  const std::int64_t count = scanner.integer("the number of nodes", 0, int64_maximum);
  start_binary_data(scanner);
  scanner.check_count(static_cast<std::uint64_t>(count), scanner.binary() ? 4 + 24 : 8, "$Nodes",
                      "nodes");
  model.node_tags.reserve(static_cast<std::size_t>(count));
  model.coordinates.reserve(3 * static_cast<std::size_t>(count));
  for (std::int64_t k = 0; k < count; ++k) {
    const std::size_t at = scanner.next_position();
    add_node(scanner, model, static_cast<std::uint64_t>(read_int(scanner, "a node tag", 1)), at);
  }
  scanner.expect("$EndNodes");
}

/// The element list of `type` in entity (dimension, tag), created when absent.
MshElementList& element_list(MshModel& model, int dimension, int entity, int type) {
  model.entities[dimension].try_emplace(entity);
  return model.elements[{dimension, entity}][type];
}

/// One MSH 2.2 element after its type and tag count: tags (physical, elementary, partitions)
/// then nodes.
void read_element_22(MshScanner& scanner, MshModel& model, std::size_t tag, int type,
                     std::int64_t tag_count) {
  const MshElementKind& kind = *msh_element_kind(type);
  int physical = 0, elementary = 0;
  for (std::int64_t t = 0; t < tag_count; ++t) {
    const int value = read_int(scanner, "an element's tag");
    if (t == 0) physical = value;
    if (t == 1) elementary = value;
  }
  MshElementList& list = element_list(model, kind.dimension, elementary, type);
  std::vector<int>& physicals = model.entities[kind.dimension][elementary];
  if (physical != 0 && std::find(physicals.begin(), physicals.end(), physical) == physicals.end()) {
    physicals.push_back(physical);
  }
  list.element_tags.push_back(tag);
  for (int n = 0; n < kind.node_count; ++n) {
    const std::size_t at = scanner.next_position();
    const int node = read_int(scanner, "a node tag of an element");
    if (node < 1)
      scanner.fail_at(at, "element " + std::to_string(tag) + " has node tag " +
                              std::to_string(node) + " (not a positive integer)");
    list.node_tags.push_back(static_cast<std::size_t>(node));
  }
}

int element_type(MshScanner& scanner, std::size_t at, std::int64_t type) {
  if (msh_element_kind(type) == nullptr) {
    scanner.fail_at(at, "unknown element type " + std::to_string(type));
  }
  return static_cast<int>(type);
}

void read_elements_22(MshScanner& scanner, MshModel& model) {
  const std::int64_t count = scanner.integer("the number of elements", 0, int64_maximum);
  start_binary_data(scanner);
  scanner.check_count(static_cast<std::uint64_t>(count), scanner.binary() ? 4 * 4 : 8, "$Elements",
                      "elements");
  for (std::int64_t read = 0; read < count;) {
    if (!scanner.binary()) {
      const std::size_t tag = static_cast<std::size_t>(read_int(scanner, "an element tag", 1));
      const std::size_t at = scanner.next_position();
      const int type = element_type(scanner, at, scanner.integer("an element type", 0, 1000));
      const std::int64_t tag_count = scanner.integer("an element's tag count", 0, 1000);
      read_element_22(scanner, model, tag, type, tag_count);
      ++read;
      continue;
    }
    const std::size_t at = scanner.next_position();
    const int type = element_type(scanner, at, read_int(scanner, "an element type"));
    const int following = read_int(scanner, "an element count", 0);
    const int tag_count = read_int(scanner, "an element's tag count", 0);
    const std::size_t element_bytes =
        4 * (1 + static_cast<std::size_t>(tag_count) +
             static_cast<std::size_t>(msh_element_kind(type)->node_count));
    if (following > count - read) {
      scanner.fail_at(at, "an element block of " + std::to_string(following) +
                              " elements exceeds the declared count");
    }
    scanner.check_count(static_cast<std::uint64_t>(following), element_bytes, "an element block",
                        "elements");
    for (int k = 0; k < following; ++k) {
      const std::size_t tag = static_cast<std::size_t>(read_int(scanner, "an element tag", 1));
      read_element_22(scanner, model, tag, type, tag_count);
    }
    read += following;
  }
  scanner.expect("$EndElements");
}

/// An MSH 4.1 entity block header: entity dimension and tag, and a third int (parametric or
/// element type).
struct MshBlockHeader {
  int dimension;
  int entity;
  int third;
  std::uint64_t count;
  std::size_t at;
};

MshBlockHeader read_block_header(MshScanner& scanner, const char* third) {
  MshBlockHeader header{};
  header.at = scanner.next_position();
  header.dimension = read_int(scanner, "an entity dimension", 0);
  if (header.dimension > 3) scanner.fail_at(header.at, "entity dimension is not 0 to 3");
  header.entity = read_int(scanner, "an entity tag");
  header.third = read_int(scanner, third);
  header.count = read_size(scanner, "a block's item count");
  return header;
}

/// Reads the four counts of a 4.1 $Nodes or $Elements header; returns the number of blocks and
/// of items after checking both against the bytes left.
std::pair<std::uint64_t, std::uint64_t> read_header_41(MshScanner& scanner, const char* section,
                                                       const char* items_name,
                                                       std::size_t block_bytes,
                                                       std::size_t item_bytes) {
  const std::uint64_t blocks = read_size(scanner, "a block count");
  const std::uint64_t items = read_size(scanner, "an item count");
  read_size(scanner, "a minimum tag");
  read_size(scanner, "a maximum tag");
  scanner.check_count(blocks, block_bytes, section, "entity blocks");
  scanner.check_count(items, item_bytes, section, items_name);
  return {blocks, items};
}

void check_block_total(MshScanner& scanner, const MshBlockHeader& header, std::uint64_t read,
                       std::uint64_t declared) {
  if (header.count > declared - read) {
    scanner.fail_at(header.at, "an entity block of " + std::to_string(header.count) +
                                   " items exceeds the declared total " + std::to_string(declared));
  }
}

void read_nodes_41(MshScanner& scanner, MshModel& model) {
  const std::size_t node_bytes = scanner.binary() ? 8 + 24 : 8;
  const auto [blocks, total] =
      read_header_41(scanner, "$Nodes", "nodes", scanner.binary() ? 20 : 8, node_bytes);
  model.node_tags.reserve(total);
  model.coordinates.reserve(3 * total);
  std::uint64_t read = 0;
  std::vector<std::uint64_t> tags;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const MshBlockHeader header = read_block_header(scanner, "a parametric flag");
    check_block_total(scanner, header, read, total);
    scanner.check_count(header.count, node_bytes, "a node block", "nodes");
    model.entities[header.dimension].try_emplace(header.entity);
    tags.resize(header.count);
    std::vector<std::size_t> positions(header.count);
    for (std::uint64_t k = 0; k < header.count; ++k) {
      positions[k] = scanner.next_position();
      tags[k] = read_size(scanner, "a node tag");
    }
    const int parametric = header.third != 0 ? header.dimension : 0;
    for (std::uint64_t k = 0; k < header.count; ++k) {
      add_node(scanner, model, tags[k], positions[k]);
      for (int p = 0; p < parametric; ++p) read_real(scanner, "a parametric coordinate");
    }
    read += header.count;
  }
  if (read != total)
    scanner.fail("$Nodes declares " + std::to_string(total) + " nodes but its blocks hold " +
                 std::to_string(read));
  scanner.expect("$EndNodes");
}

void read_elements_41(MshScanner& scanner, MshModel& model) {
  const std::size_t number_bytes = scanner.binary() ? 8 : 2;
  const auto [blocks, total] =
      read_header_41(scanner, "$Elements", "elements", scanner.binary() ? 20 : 8, 2 * number_bytes);
  std::uint64_t read = 0;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const MshBlockHeader header = read_block_header(scanner, "an element type");
    const int type = element_type(scanner, header.at, header.third);
    const MshElementKind& kind = *msh_element_kind(type);
    if (kind.dimension != header.dimension) {
      scanner.fail_at(header.at, msh_element_name(type) + " elements in an entity of dimension " +
                                     std::to_string(header.dimension));
    }
    check_block_total(scanner, header, read, total);
    scanner.check_count(header.count, number_bytes * (1 + kind.node_count), "an element block",
                        "elements");
    MshElementList& list = element_list(model, header.dimension, header.entity, type);
    list.element_tags.reserve(list.element_tags.size() + header.count);
    list.node_tags.reserve(list.node_tags.size() + header.count * kind.node_count);
    for (std::uint64_t k = 0; k < header.count; ++k) {
      list.element_tags.push_back(read_size(scanner, "an element tag"));
      for (int n = 0; n < kind.node_count; ++n) {
        const std::size_t at = scanner.next_position();
        const std::uint64_t node = read_size(scanner, "a node tag of an element");
        if (node == 0) scanner.fail_at(at, "an element has node tag 0");
        list.node_tags.push_back(node);
      }
    }
    read += header.count;
  }
  if (read != total)
    scanner.fail("$Elements declares " + std::to_string(total) + " elements but its blocks hold " +
                 std::to_string(read));
  scanner.expect("$EndElements");
}

/// $MeshFormat: returns the major version (2 or 4) and sets the scanner's binary mode.
int read_mesh_format(MshScanner& scanner) {
  scanner.skip_space();
  const std::size_t start = scanner.position();
  if (scanner.word() != "$MeshFormat") {
    scanner.fail_at(start, "the file does not begin with $MeshFormat: not a Gmsh MSH file");
  }
  const std::size_t version_at = scanner.next_position();
  const std::string version(scanner.word());
  if (version != "2.2" && version != "4.1") {
    scanner.fail_at(version_at, "MSH version '" + version.substr(0, 40) +
                                    "' is not supported: write the mesh as MSH 4.1 or 2.2");
  }
  const bool binary = scanner.integer("the file type", 0, 1) == 1;
  const std::size_t size_at = scanner.next_position();
  const std::int64_t data_size = scanner.integer("the data size", 0, 64);
  if (data_size != 8) {
    scanner.fail_at(size_at, "data size " + std::to_string(data_size) + " is not 8");
  }
  if (binary) {
    scanner.next_line();
    scanner.set_binary(true);
    const std::size_t at = scanner.next_position();
    const std::int32_t one = scanner.binary_value<std::int32_t>("the endianness word");
    if (one == 0x01000000) {
      scanner.fail_at(at,
                      "the binary file was written on a big-endian machine (endianness word "
                      "1 byte-swapped): write it as ASCII");
    }
    if (one != 1) {
      scanner.fail_at(at, "the endianness word is " + std::to_string(one) + ", not 1");
    }
  }
  scanner.expect("$EndMeshFormat");
  return version == "2.2" ? 2 : 4;
}

/// The name of the section that begins next ("$Nodes"), after which the scanner stands at its
/// first value.
std::string next_section(MshScanner& scanner) {
  const std::size_t at = scanner.next_position();
  const std::string section(scanner.word());
  if (section.empty() || section.front() != '$') {
    scanner.fail_at(at, "expected a section such as $Nodes, found '" + section.substr(0, 40) + "'");
  }
  if (scanner.binary()) scanner.next_line();  // binary data or a count line follows
  return section;
}

MshModel read_model(MshScanner& scanner) {
  MshModel model;
  const int version = read_mesh_format(scanner);
  model.only_used_nodes = version == 2;
  bool nodes_read = false, elements_read = false;
  while (scanner.skip_space()) {
    const std::size_t at = scanner.next_position();
    const std::string section = next_section(scanner);
    const bool repeated =
        (section == "$Nodes" && nodes_read) || (section == "$Elements" && elements_read);
    if (repeated) scanner.fail_at(at, "a second " + section + " section");
    if (section == "$PhysicalNames") {
      read_physical_names(scanner, model);
    } else if (section == "$Entities" && version == 4) {
      read_entities(scanner, model);
    } else if (section == "$Nodes") {
      version == 2 ? read_nodes_22(scanner, model) : read_nodes_41(scanner, model);
      nodes_read = true;
    } else if (section == "$Elements") {
      version == 2 ? read_elements_22(scanner, model) : read_elements_41(scanner, model);
      elements_read = true;
    } else {
      scanner.skip_section(section);
    }
  }
  return model;
}

// ---------------------------------------------------------------------------------------------
// From the model to the body's Mesh (what gmsh_reader.cpp extracted through Gmsh's API)

/// Domain elements of one type: node tags, and each element's tag and entity.
struct DomainList {
  std::vector<std::size_t> node_tags;
  std::vector<std::size_t> element_tags;
  std::vector<int> entities;
};

struct BodyElements {
  std::map<ElementType, DomainList> domain;
  std::map<std::string, std::pair<FacetType, std::vector<std::size_t>>> facets;
};

/// Physical tag -> its entities (ascending tags) in dimension `dimension`.
std::map<int, std::vector<int>> physical_groups(const MshModel& model, int dimension) {
  std::map<int, std::vector<int>> groups;
  for (const auto& [entity, physicals] : model.entities[dimension]) {
    for (const int physical : physicals) groups[physical].push_back(entity);
  }
  return groups;
}

std::optional<ElementType> domain_element_type(int dimension, int type) {
  static const std::map<int, ElementType> plane = {
      {2, ElementType::triangle3}, {9, ElementType::triangle6}, {3, ElementType::quadrilateral4}};
  static const std::map<int, ElementType> solid = {{4, ElementType::tetrahedron4},
                                                   {11, ElementType::tetrahedron10},
                                                   {5, ElementType::hexahedron8}};
  const std::map<int, ElementType>& known = dimension == 3 ? solid : plane;
  const auto found = known.find(type);
  if (found == known.end()) return std::nullopt;
  return found->second;
}

std::optional<FacetType> boundary_facet_type(int dimension, int type) {
  static const std::map<int, FacetType> edges = {{1, FacetType::line2}, {8, FacetType::line3}};
  static const std::map<int, FacetType> faces = {
      {2, FacetType::triangle3}, {9, FacetType::triangle6}, {3, FacetType::quadrilateral4}};
  const std::map<int, FacetType>& known = dimension == 3 ? faces : edges;
  const auto found = known.find(type);
  if (found == known.end()) return std::nullopt;
  return found->second;
}

const MshEntityElements* entity_elements(const MshModel& model, int dimension, int entity) {
  const auto found = model.elements.find({dimension, entity});
  return found == model.elements.end() ? nullptr : &found->second;
}

/// Appends `from` to `to`, taking its storage when `to` is empty (the usual single entity per
/// element type: no copy).
template <typename Value>
void append_taking(std::vector<Value>& from, std::vector<Value>& to) {
  if (to.empty()) {
    to = std::move(from);
  } else {
    to.insert(to.end(), from.begin(), from.end());
  }
  std::vector<Value>().swap(from);
}

/// The elements of the physical groups of the body's dimension (of every entity of it when it
/// has no physical group), entity by entity in ascending tags, taken out of `model`.
void collect_domain(MshModel& model, const std::string& name, int dimension, BodyElements& body) {
  std::vector<int> entities;
  for (const auto& [group, members] : physical_groups(model, dimension)) {
    entities.insert(entities.end(), members.begin(), members.end());
  }
  if (entities.empty()) {
    for (const auto& [entity, physicals] : model.entities[dimension]) entities.push_back(entity);
  }
  std::sort(entities.begin(), entities.end());
  entities.erase(std::unique(entities.begin(), entities.end()), entities.end());
  for (const int entity : entities) {
    const auto found = model.elements.find({dimension, entity});
    if (found == model.elements.end()) continue;
    for (auto& [msh_type, list] : found->second) {
      const std::optional<ElementType> type = domain_element_type(dimension, msh_type);
      if (!type) {
        throw InputError(name + ": unsupported " + std::to_string(dimension) + "D element " +
                         msh_element_name(msh_type) +
                         (dimension == 3
                              ? "; use 4-node or 10-node tetrahedra or 8-node hexahedra"
                              : "; use 3-node or 6-node triangles or 4-node quadrilaterals"));
      }
      DomainList& domain = body.domain[*type];
      domain.entities.insert(domain.entities.end(), list.element_tags.size(), entity);
      append_taking(list.node_tags, domain.node_tags);
      append_taking(list.element_tags, domain.element_tags);
    }
  }
  if (body.domain.empty()) {
    throw InputError(name + (dimension == 3
                                 ? ": contains no 3D elements (is the volume meshed, with a "
                                   "Physical Volume?)"
                                 : ": contains no 2D elements (is the surface meshed, with a "
                                   "Physical Surface?)"));
  }
}

/// The name of physical group `group` of dimension `dimension`: its $PhysicalNames name, its
/// tag when it has none.
std::string group_name(const MshModel& model, int dimension, int group) {
  const auto named = model.physical_names.find({dimension, group});
  return named == model.physical_names.end() || named->second.empty() ? std::to_string(group)
                                                                      : named->second;
}

/// Every physical group of dimension `dimension` - 1 as a named boundary of facets.
void collect_boundaries(const MshModel& model, const std::string& name, int dimension,
                        BodyElements& body) {
  const int facet_dimension = dimension - 1;
  for (const auto& [group, members] : physical_groups(model, facet_dimension)) {
    const std::string boundary = group_name(model, facet_dimension, group);
    for (const int member : members) {
      const MshEntityElements* elements = entity_elements(model, facet_dimension, member);
      if (elements == nullptr) continue;
      for (const auto& [msh_type, list] : *elements) {
        const std::optional<FacetType> type = boundary_facet_type(dimension, msh_type);
        if (!type) {
          throw InputError(
              name + ": boundary '" + boundary + "': unsupported " +
              std::to_string(facet_dimension) + "D element " + msh_element_name(msh_type) +
              (dimension == 3 ? "; use 3-node or 6-node triangles or 4-node quadrilaterals"
                              : "; use 2-node or 3-node lines"));
        }
        auto [entry, inserted] =
            body.facets.try_emplace(boundary, *type, std::vector<std::size_t>{});
        if (entry->second.first != *type) {
          throw InputError(name + ": boundary '" + boundary + "' mixes " +
                           to_string(entry->second.first) + " and " + to_string(*type) + " facets");
        }
        entry->second.second.insert(entry->second.second.end(), list.node_tags.begin(),
                                    list.node_tags.end());
      }
    }
  }
}

/// Node tag -> compact index of a set of tags, in ascending tag order: a table when the largest
/// tag is at most 4 times the file's node count (plus 1024), so that it stays within a multiple
/// of the file's size, a hash map otherwise.
class NodeIndex {
 public:
  /// The tags `for_each_tag(visit)` visits (repeats allowed); `file_nodes` is the file's count.
  template <typename ForEachTag>
  NodeIndex(ForEachTag&& for_each_tag, std::size_t file_nodes) {
    std::size_t largest = 0;
    for_each_tag([&](std::size_t tag) { largest = std::max(largest, tag); });
    if (largest <= 4 * file_nodes + 1024) {
      table_.assign(largest + 1, -1);
      for_each_tag([&](std::size_t tag) { table_[tag] = 0; });
      for (std::size_t tag = 0; tag < table_.size(); ++tag) {
        if (table_[tag] < 0) continue;
        table_[tag] = static_cast<int>(tags_.size());
        tags_.push_back(tag);
      }
      return;
    }
    for_each_tag([&](std::size_t tag) { tags_.push_back(tag); });
    std::sort(tags_.begin(), tags_.end());
    tags_.erase(std::unique(tags_.begin(), tags_.end()), tags_.end());
    hashed_ = true;
    map_.reserve(tags_.size());
    for (std::size_t i = 0; i < tags_.size(); ++i) map_.emplace(tags_[i], static_cast<int>(i));
  }
  /// The compact index of `tag`; -1 when it is not in the set.
  int find(std::size_t tag) const {
    if (!hashed_) return tag < table_.size() ? table_[tag] : -1;
    const auto found = map_.find(tag);
    return found == map_.end() ? -1 : found->second;
  }
  /// The tags, ascending.
  const std::vector<std::size_t>& tags() const { return tags_; }
  std::size_t size() const { return tags_.size(); }

 private:
  std::vector<int> table_;
  std::unordered_map<std::size_t, int> map_;
  std::vector<std::size_t> tags_;
  bool hashed_ = false;
};

/// The nodes the body's elements and facets use.
NodeIndex compact_nodes(const BodyElements& body, std::size_t file_nodes) {
  const auto for_each_tag = [&](auto&& visit) {
    for (const auto& [type, domain] : body.domain) {
      for (const std::size_t tag : domain.node_tags) visit(tag);
    }
    for (const auto& [boundary, facets] : body.facets) {
      for (const std::size_t tag : facets.second) visit(tag);
    }
  };
  return NodeIndex(for_each_tag, file_nodes);
}

/// The largest |coordinate| of the nodes Gmsh keeps: every node of a 4.1 file, the nodes some
/// element uses in a 2.2 file.
double model_extent(const MshModel& model) {
  double extent = 0.0;
  if (!model.only_used_nodes) {
    for (const double value : model.coordinates) extent = std::max(extent, std::abs(value));
    return extent;
  }
  const auto for_each_tag = [&](auto&& visit) {
    for (const auto& [key, lists] : model.elements) {
      for (const auto& [type, list] : lists) {
        for (const std::size_t tag : list.node_tags) visit(tag);
      }
    }
  };
  const NodeIndex used(for_each_tag, model.node_tags.size());
  for (std::size_t k = 0; k < model.node_tags.size(); ++k) {
    if (used.find(model.node_tags[k]) < 0) continue;
    for (int c = 0; c < 3; ++c) extent = std::max(extent, std::abs(model.coordinates[3 * k + c]));
  }
  return extent;
}

void fill_nodes(const MshModel& model, const std::string& name, const NodeIndex& index,
                Mesh& mesh) {
  mesh.nodes.assign(index.size(), Eigen::Vector3d::Zero());
  mesh.node_tags.assign(index.size(), 0);
  const double extent = mesh.dimension == 2 ? model_extent(model) : 0.0;
  for (std::size_t k = 0; k < model.node_tags.size(); ++k) {
    const std::size_t tag = model.node_tags[k];
    const int position = index.find(tag);
    if (position < 0) continue;
    if (mesh.node_tags[position] != 0) {
      throw InputError(name + ": node tag " + std::to_string(tag) + " is defined twice");
    }
    const double* xyz = &model.coordinates[3 * k];
    if (mesh.dimension == 2 && std::abs(xyz[2]) > 1e-10 * extent) {
      throw InputError(name + ": node " + std::to_string(tag) +
                       " has z = " + std::to_string(xyz[2]) +
                       ": a mesh without volumes is a plane body and must lie in the z = 0 plane");
    }
    mesh.nodes[position] = {xyz[0], xyz[1], mesh.dimension == 2 ? 0.0 : xyz[2]};
    mesh.node_tags[position] = tag;
  }
  for (std::size_t position = 0; position < index.size(); ++position) {
    const std::size_t tag = index.tags()[position];
    if (mesh.node_tags[position] == 0) {
      throw InputError(name + ": an element uses node tag " + std::to_string(tag) +
                       ", which $Nodes does not define");
    }
  }
}

/// The compact indices of `tags`, every one of which is in `index`.
std::vector<int> to_indices(const std::vector<std::size_t>& tags, const NodeIndex& index) {
  std::vector<int> indices(tags.size());
  std::transform(tags.begin(), tags.end(), indices.begin(),
                 [&](std::size_t tag) { return index.find(tag); });
  return indices;
}

/// Twice the signed area of the element's corner polygon (positive when counter-clockwise).
double twice_signed_area(const Mesh& mesh, ElementType type, const int* nodes) {
  const int corners = type == ElementType::quadrilateral4 ? 4 : 3;
  double sum = 0.0;
  for (int i = 0; i < corners; ++i) {
    const Eigen::Vector3d& a = mesh.nodes[nodes[i]];
    const Eigen::Vector3d& b = mesh.nodes[nodes[(i + 1) % corners]];
    sum += a.x() * b.y() - b.x() * a.y();
  }
  return sum;
}

/// The element's signed measure: in 2D twice the signed area of its corner polygon (positive
/// when counter-clockwise), in 3D det(dx/dxi) at the reference centroid (positive when the
/// element has Gmsh's orientation).
double signed_measure(const Mesh& mesh, ElementType type, const int* nodes) {
  if (element_dimension(type) == 2) return twice_signed_area(mesh, type, nodes);
  ShapeValues values;
  ShapeGradients gradients;
  shape_functions(type, reference_centroid(type), values, gradients);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
  for (int i = 0; i < nodes_per_element(type); ++i) {
    jacobian += mesh.nodes[nodes[i]] * gradients.row(i);
  }
  return jacobian.determinant();
}

}  // namespace

void orient_elements_positively(const std::string& name, const Mesh& mesh, ElementBlock& block,
                                const std::vector<int>& entities) {
  // Reverse the orientation: the corner order (midside nodes follow their edges); a
  // tetrahedron swaps corners 1 and 2, a hexahedron its faces' corner order.
  static const std::map<ElementType, std::vector<int>> reversed = {
      {ElementType::triangle3, {0, 2, 1}},
      {ElementType::triangle6, {0, 2, 1, 5, 4, 3}},
      {ElementType::quadrilateral4, {0, 3, 2, 1}},
      {ElementType::tetrahedron4, {0, 2, 1, 3}},
      {ElementType::tetrahedron10, {0, 2, 1, 3, 6, 5, 4, 7, 9, 8}},
      {ElementType::hexahedron8, {0, 3, 2, 1, 4, 7, 6, 5}}};
  const int count = nodes_per_element(block.type);
  // each element's measure once; the entity's sum looked up again only when the entity changes
  // (the elements of an entity come together)
  std::vector<double> measures(block.element_count());
  std::map<int, double> entity_measure;
  auto entity = entity_measure.end();
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    measures[e] = signed_measure(mesh, block.type, &block.connectivity[e * count]);
    if (entity == entity_measure.end() || entity->first != entities[e]) {
      entity = entity_measure.try_emplace(entities[e], 0.0).first;
    }
    entity->second += measures[e];
  }
  const std::vector<int>& order = reversed.at(block.type);
  const bool solid = element_dimension(block.type) == 3;
  entity = entity_measure.end();
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    int* nodes = &block.connectivity[e * count];
    const double measure = measures[e];
    if (entity == entity_measure.end() || entity->first != entities[e]) {
      entity = entity_measure.find(entities[e]);
    }
    const double orientation = entity->second < 0.0 ? -1.0 : 1.0;
    if (measure * orientation <= 0.0) {
      throw InputError(name + ": " + block.element_label(e) + " (" + to_string(block.type) +
                       " at node tag " + std::to_string(mesh.node_tags[nodes[0]]) + ") " +
                       (measure == 0.0
                            ? (solid ? "has zero volume" : "has zero area")
                            : "is inverted against the other elements of " +
                                  std::string(solid ? "volume " : "surface ") +
                                  std::to_string(entities[e]) + " (a folded or tangled mesh)"));
    }
    if (orientation > 0.0) continue;
    const std::vector<int> original(nodes, nodes + count);
    for (int i = 0; i < count; ++i) nodes[i] = original[order[i]];
  }
}

namespace {

bool has_physical_group(const MshModel& model) {
  for (const auto& entities : model.entities) {
    for (const auto& [entity, physicals] : entities) {
      if (!physicals.empty()) return true;
    }
  }
  return false;
}

Mesh body_mesh(MshModel&& model, const std::string& name) {
  if (!has_physical_group(model)) {
    throw InputError(
        name +
        ": defines no physical groups: add a Physical Surface for the body and Physical Curves "
        "for its boundaries (in 3D a Physical Volume and Physical Surfaces)");
  }
  const int dimension = model.entities[3].empty() ? 2 : 3;
  BodyElements body;
  collect_domain(model, name, dimension, body);
  collect_boundaries(model, name, dimension, body);
  const NodeIndex index = compact_nodes(body, model.node_tags.size());
  Mesh mesh;
  mesh.dimension = dimension;
  fill_nodes(model, name, index, mesh);
  for (auto& [type, domain] : body.domain) {
    ElementBlock block{type, to_indices(domain.node_tags, index), std::move(domain.element_tags)};
    orient_elements_positively(name, mesh, block, domain.entities);
    mesh.blocks.push_back(std::move(block));
  }
  for (const auto& [boundary, facets] : body.facets) {
    mesh.boundaries[boundary] = BoundaryGroup{facets.first, to_indices(facets.second, index)};
  }
  return mesh;
}

}  // namespace

Mesh parse_msh_file(std::string_view bytes, const std::string& name) {
  const std::string label = "mesh file '" + name + "'";
  MshScanner scanner(bytes, label);
  return body_mesh(read_model(scanner), label);
}

namespace {

/// The summary of a file whose head up to $Nodes is in `model`, its $Nodes count `node_count`.
std::optional<MshSummary> summary_of(const MshModel& model, int version, std::uint64_t node_count) {
  MshSummary summary;
  summary.node_count = node_count;
  if (version == 4) {  // the entities and their groups, as body_mesh decides
    if (!has_physical_group(model)) return std::nullopt;
    summary.dimension = model.entities[3].empty() ? 2 : 3;
    for (const auto& [group, members] : physical_groups(model, summary.dimension - 1)) {
      summary.boundary_names.push_back(group_name(model, summary.dimension - 1, group));
    }
    return summary;
  }
  if (model.physical_names.empty()) return std::nullopt;  // 2.2: groups known from elements only
  for (const auto& [group, name] : model.physical_names) {
    if (group.first == 3) summary.dimension = 3;
  }
  for (const auto& [group, name] : model.physical_names) {
    if (group.first == summary.dimension - 1) {
      summary.boundary_names.push_back(group_name(model, group.first, group.second));
    }
  }
  return summary;
}

}  // namespace

std::optional<MshSummary> summarize_msh_file(const std::filesystem::path& path,
                                             const std::string& name) {
  const std::string shown = name.empty() ? path.string() : name;
  const MappedFile file(path, shown, MappedFile::Reading::beginning);
  MshScanner scanner(file.bytes(), "mesh file '" + shown + "'");
  MshModel model;
  const int version = read_mesh_format(scanner);
  while (scanner.skip_space()) {
    const std::string section = next_section(scanner);
    if (section == "$PhysicalNames") {
      read_physical_names(scanner, model);
    } else if (section == "$Entities" && version == 4) {
      read_entities(scanner, model);
    } else if (section == "$Nodes") {
      if (version == 2) {
        return summary_of(
            model, version,
            static_cast<std::uint64_t>(scanner.integer("the number of nodes", 0, int64_maximum)));
      }
      read_size(scanner, "a block count");
      return summary_of(model, version, read_size(scanner, "a node count"));
    } else {
      scanner.skip_section(section);
    }
  }
  return std::nullopt;  // no $Nodes: read_msh_file names the problem
}

Mesh read_msh_file(const std::filesystem::path& path, const std::string& name) {
  const std::string shown = name.empty() ? path.string() : name;
  const MappedFile file(path, shown);
  Mesh mesh = parse_msh_file(file.bytes(), shown);
  mesh.source = path.string();
  return mesh;
}

}  // namespace robin
