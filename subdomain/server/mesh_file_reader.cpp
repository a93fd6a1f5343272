#include "server/mesh_file_reader.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "numerics/errors.hpp"

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

/// The exit status of a child that could not run the reader (the shell's "cannot execute").
constexpr int cannot_execute_status = 126;

/// In the child, between fork and exec (async-signal-safe calls only): runs `argv` (the reader
/// and the file) with its standard output on `descriptor`; never returns.
[[noreturn]] void run_reader_in_child(char* const* argv, int descriptor) {
  // A crash of the reader ends the child by its signal, which the parent reports: no handler
  // or mask inherited from the server (such as a sanitizer's) survives into the reader.
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  for (const int signal_number : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) {
    sigaction(signal_number, &default_action, nullptr);
  }
  sigset_t no_signals;
  sigemptyset(&no_signals);
  sigprocmask(SIG_SETMASK, &no_signals, nullptr);
  if (dup2(descriptor, STDOUT_FILENO) >= 0) execv(argv[0], argv);
  _exit(cannot_execute_status);
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
  int pipe_ends[2];
  if (pipe2(pipe_ends, O_CLOEXEC) != 0) {
    throw std::runtime_error("cannot create a pipe to read a mesh file");
  }
  const pid_t child = fork();
  if (child < 0) {
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    throw std::runtime_error("cannot start a process to read a mesh file (fork failed)");
  }
  if (child == 0) run_reader_in_child(argv, pipe_ends[1]);
  close(pipe_ends[1]);
  const auto [bytes, status] = collect(child, pipe_ends[0]);
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
