#include "server/mesh_file_reader.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

// The child's message: 'M' and the mesh (the layout of encoded_mesh: its dimension, then x, y, z
// per node whatever the dimension), or 'E' and an error text.

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

std::string encoded_mesh(const Mesh& mesh) {
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

/// Reads what encoded_mesh wrote; throws std::runtime_error when the bytes end early.
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

/// Address space the child may add to what it inherited: a fixed part for Gmsh's own start-up,
/// plus a multiple of the file's size, well above what Gmsh and the conversion need for a file
/// whose counts are true (a few times its size), far below what a header claiming billions of
/// nodes in a small file would make Gmsh reserve.
constexpr std::uint64_t base_allowance_bytes = std::uint64_t{256} << 20;
constexpr std::uint64_t allowance_per_file_byte = 32;

/// The child's address space now (the first field of /proc/self/statm, in pages), 0 if unknown.
std::uint64_t address_space_bytes() {
  const int file = open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
  if (file < 0) return 0;
  char text[64] = {};
  const ssize_t count = read(file, text, sizeof text - 1);
  close(file);
  if (count <= 0) return 0;
  return std::strtoull(text, nullptr, 10) * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
}

/// Caps the child's address space (RLIMIT_AS) at what it has plus `allowance`, so that an
/// allocation the file's counts ask for beyond that fails (std::bad_alloc) instead of taking
/// the host's memory. An existing lower limit is kept. Returns the allowance in force.
std::uint64_t limit_address_space(std::uint64_t allowance) {
  const std::uint64_t current = address_space_bytes();
  rlimit limit{};
  if (current == 0 || getrlimit(RLIMIT_AS, &limit) != 0) return 0;
  const std::uint64_t wanted = current + allowance;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur <= wanted) return limit.rlim_cur - current;
  limit.rlim_cur = wanted;
  if (limit.rlim_max != RLIM_INFINITY && limit.rlim_max < wanted) limit.rlim_cur = limit.rlim_max;
  setrlimit(RLIMIT_AS, &limit);
  return limit.rlim_cur - current;
}

/// Set in the child when operator new found no memory (read_gmsh_mesh turns the exception into
/// its own error, so the handler records it).
bool allocation_refused = false;

void refuse_allocation() {
  allocation_refused = true;
  std::set_new_handler(nullptr);
  throw std::bad_alloc();
}

std::string memory_refusal(std::uint64_t allowance, std::uintmax_t file_bytes) {
  return "Ethe mesh reader ran out of the memory it is allowed for this file (" +
         std::to_string(allowance >> 20) + " MiB for " + std::to_string(file_bytes) +
         " bytes): does a header claim more nodes or elements than the file holds? refused";
}

/// In the child: reads the mesh and writes the message to `descriptor`; never returns.
[[noreturn]] void read_in_child(const std::filesystem::path& path, int descriptor) {
  // A crash of the reader ends the child by its signal, which the parent reports (no handler
  // inherited from the parent, such as a sanitizer's, runs in the child).
  for (const int signal_number : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) {
    std::signal(signal_number, SIG_DFL);
  }
  std::error_code size_error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, size_error);
  const std::uint64_t allowance = limit_address_space(
      base_allowance_bytes + allowance_per_file_byte * (size_error ? 0 : file_bytes));
  std::set_new_handler(refuse_allocation);
  std::string message;
  try {
    message = encoded_mesh(read_gmsh_mesh(path));
  } catch (const std::exception& error) {
    message = allocation_refused ? memory_refusal(allowance, file_bytes)
                                 : std::string("E") + error.what();
  } catch (...) {
    message = allocation_refused ? memory_refusal(allowance, file_bytes)
                                 : std::string("Ethe mesh reader failed");
  }
  for (std::size_t written = 0; written < message.size();) {
    const ssize_t count = write(descriptor, message.data() + written, message.size() - written);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) _exit(2);
    written += static_cast<std::size_t>(count);
  }
  _exit(0);
}

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

Mesh read_mesh_file_in_child(const std::filesystem::path& path) {
  int pipe_ends[2];
  if (pipe(pipe_ends) != 0) throw std::runtime_error("cannot create a pipe to read a mesh file");
  const pid_t child = fork();
  if (child < 0) {
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    throw std::runtime_error("cannot start a process to read a mesh file (fork failed)");
  }
  if (child == 0) {
    close(pipe_ends[0]);
    read_in_child(path, pipe_ends[1]);
  }
  close(pipe_ends[1]);
  const auto [bytes, status] = collect(child, pipe_ends[0]);
  if (WIFSIGNALED(status)) {
    throw InputError("the mesh reader (Gmsh) crashed on this file (signal " +
                     std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) +
                     "): refused");
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
