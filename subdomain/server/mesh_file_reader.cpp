#include "server/mesh_file_reader.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "numerics/errors.hpp"
#include "numerics/helper_process.hpp"

namespace robin {
namespace {

// The reader's message: 'M' and the mesh (the layout of mesh_reader_message: its dimension, then
// x, y, z per node whatever the dimension), or 'E' and an error text.

template <typename Value>
void append_vector(std::string& out, const std::vector<Value>& values) {
  static_assert(std::is_trivially_copyable_v<Value>);
  const std::size_t count = values.size();
  out.append(reinterpret_cast<const char*>(&count), sizeof count);
  out.append(reinterpret_cast<const char*>(values.data()), count * sizeof(Value));
}

void append_text(std::string& out, const std::string& text) {
  append_vector(out, std::vector<char>(text.begin(), text.end()));
}

/// Reads what mesh_reader_message wrote; throws std::runtime_error when the bytes end early.
class MeshDecoder {
 public:
  explicit MeshDecoder(const std::string& bytes) : bytes_(bytes) {}

  Mesh mesh() {
    Mesh mesh;
    mesh.source = text();
    mesh.dimension = single<int>();
    if (mesh.dimension != 2 && mesh.dimension != 3) throw std::runtime_error("bad dimension");
    const std::vector<double> coordinates = vector<double>();
    for (std::size_t k = 0; k + 2 < coordinates.size(); k += 3) {
      mesh.nodes.emplace_back(coordinates[k], coordinates[k + 1], coordinates[k + 2]);
    }
    mesh.node_tags = vector<std::size_t>();
    const std::vector<std::size_t> counts = vector<std::size_t>();
    if (counts.size() != 2) throw std::runtime_error("malformed block counts");
    for (std::size_t k = 0; k < counts[0]; ++k) {
      ElementBlock& block = mesh.blocks.emplace_back();
      block.type = static_cast<ElementType>(single<int>());
      block.connectivity = vector<int>();
      block.tags = vector<std::size_t>();
    }
    for (std::size_t k = 0; k < counts[1]; ++k) {
      const std::string name = text();
      BoundaryGroup& group = mesh.boundaries[name];
      group.type = static_cast<FacetType>(single<int>());
      group.connectivity = vector<int>();
    }
    return mesh;
  }

 private:
  template <typename Value>
  std::vector<Value> vector() {
    std::size_t count = 0;
    take(&count, sizeof count);
    if (count > (bytes_.size() - position_) / sizeof(Value)) {
      throw std::runtime_error("the mesh message ends early");
    }
    std::vector<Value> values(count);
    take(values.data(), count * sizeof(Value));
    return values;
  }
  template <typename Value>
  Value single() {
    const std::vector<Value> values = vector<Value>();
    if (values.size() != 1) throw std::runtime_error("malformed mesh message");
    return values.front();
  }
  std::string text() {
    const std::vector<char> characters = vector<char>();
    return std::string(characters.begin(), characters.end());
  }
  void take(void* target, std::size_t size) {
    if (size > bytes_.size() - position_) throw std::runtime_error("the mesh message ends early");
    std::memcpy(target, bytes_.data() + position_, size);
    position_ += size;
  }

  const std::string& bytes_;
  std::size_t position_ = 1;  // after the 'M'
};

/// Everything the child wrote, then its exit status.
std::pair<std::string, int> collect(pid_t child, int descriptor) {
  std::string bytes;
  char buffer[65536];
  for (ssize_t count; (count = read(descriptor, buffer, sizeof buffer)) != 0;) {
    if (count < 0 && errno == EINTR) continue;
    if (count < 0) break;
    bytes.append(buffer, static_cast<std::size_t>(count));
  }
  close(descriptor);
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  return {std::move(bytes), status};
}

}  // namespace

std::string mesh_reader_message(const Mesh& mesh) {
  std::string out = "M";
  append_text(out, mesh.source);
  append_vector(out, std::vector<int>{mesh.dimension});
  std::vector<double> coordinates;  // x, y, z per node (z = 0 in 2D)
  coordinates.reserve(3 * mesh.nodes.size());
  for (const Eigen::Vector3d& node : mesh.nodes)
    coordinates.insert(coordinates.end(), {node.x(), node.y(), node.z()});
  append_vector(out, coordinates);
  append_vector(out, mesh.node_tags);
  append_vector(out, std::vector<std::size_t>{mesh.blocks.size(), mesh.boundaries.size()});
  for (const ElementBlock& block : mesh.blocks) {
    append_vector(out, std::vector<int>{static_cast<int>(block.type)});
    append_vector(out, block.connectivity);
    append_vector(out, block.tags);
  }
  for (const auto& [name, group] : mesh.boundaries) {
    append_text(out, name);
    append_vector(out, std::vector<int>{static_cast<int>(group.type)});
    append_vector(out, group.connectivity);
  }
  return out;
}

std::string mesh_reader_error_message(const std::string& error) {
  return "E" + error;
}

Mesh read_mesh_file_in_child(const std::filesystem::path& path,
                             const std::filesystem::path& reader) {
  std::string reader_word = reader.string(), path_word = path.string();
  char* const argv[] = {reader_word.data(), path_word.data(), nullptr};  // before the fork
  const HelperProcess child =
      start_helper_process(argv, "cannot create a pipe to read a mesh file",
                           "cannot start a process to read a mesh file (fork failed)");
  const auto [bytes, status] = collect(child.pid, child.output);
  if (WIFSIGNALED(status)) {
    throw InputError("the mesh reader (Gmsh) crashed on this file (signal " +
                     std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) +
                     "): refused");
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == cannot_execute_status && bytes.empty()) {
    throw std::runtime_error("cannot run the mesh reader '" + reader.string() + "'");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || bytes.empty()) {
    throw InputError("the mesh reader's process failed");
  }
  if (bytes.front() == 'E') throw InputError(bytes.substr(1));
  try {
    if (bytes.front() != 'M') throw std::runtime_error("unknown message");
    return MeshDecoder(bytes).mesh();
  } catch (const std::runtime_error& error) {
    throw InputError(std::string("the mesh reader's message is malformed (") + error.what() + ")");
  }
}

}  // namespace robin
