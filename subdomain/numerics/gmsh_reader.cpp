#include "numerics/gmsh_reader.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "numerics/errors.hpp"
#include "numerics/msh_file.hpp"

namespace robin {

namespace {

void check_options(const std::string& name, const MeshReadOptions& options) {
  if (!std::isfinite(options.size) || options.size < 0.0) {
    throw InputError(name + ": mesh size " + std::to_string(options.size) + " is not >= 0");
  }
  if (options.element_order != 1 && options.element_order != 2) {
    throw InputError(name + ": element order " + std::to_string(options.element_order) +
                     " is not 1 or 2");
  }
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

std::string file_label(const std::filesystem::path& path) {
  return "mesh file '" + path.string() + "'";
}

/// Checks the options, the extension (.msh or .geo) and that `path` is a regular file.
void check_request(const std::filesystem::path& path, const MeshReadOptions& options) {
  const std::string name = file_label(path);
  check_options(name, options);
  const std::string extension = lower_extension(path);
  if (extension != ".msh" && extension != ".geo") {
    throw InputError(name + ": unsupported extension '" + extension +
                     "': give a .msh or .geo file");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(name + ": the file does not exist or is not a regular file");
  }
}

/// The exit status of a child that could not run the mesh reader (the shell's "cannot
/// execute").
constexpr int cannot_execute_status = 126;

/// A .geo being meshed by robin-mesh-reader in a child process: its pid, the pipe that carries
/// its error message (its standard output) and the file it writes.
struct MeshingChild {
  pid_t pid = -1;
  int error_pipe = -1;
  std::filesystem::path output;
};

/// The command line of robin-mesh-reader meshing `request` into `output`.
std::vector<std::string> meshing_command(const std::filesystem::path& reader,
                                         const MeshFileRequest& request,
                                         const std::filesystem::path& output) {
  std::ostringstream size;
  size.precision(17);
  size << request.options.size;
  std::vector<std::string> words = {
      reader.string(), "--mesh-geo",      request.path.string(),
      "--output",      output.string(),   "--size",
      size.str(),      "--element-order", std::to_string(request.options.element_order)};
  if (request.options.recombine) words.emplace_back("--recombine");
  return words;
}

/// In the child, between fork and exec (async-signal-safe calls only): runs `argv` with its
/// standard output on `descriptor`, with the default signal dispositions and no signal
/// blocked; never returns.
[[noreturn]] void run_in_child(char* const* argv, int descriptor) {
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  for (const int signal_number : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGINT, SIGTERM}) {
    sigaction(signal_number, &default_action, nullptr);
  }
  sigset_t no_signals;
  sigemptyset(&no_signals);
  sigprocmask(SIG_SETMASK, &no_signals, nullptr);
  if (dup2(descriptor, STDOUT_FILENO) >= 0) execv(argv[0], argv);
  _exit(cannot_execute_status);
}

MeshingChild start_meshing_child(const MeshFileRequest& request,
                                 const std::filesystem::path& output) {
  std::vector<std::string> words = meshing_command(mesh_reader_executable(), request, output);
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  int pipe_ends[2];
  if (pipe2(pipe_ends, O_CLOEXEC) != 0)
    throw std::runtime_error("cannot create a pipe for meshing");
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    throw std::runtime_error("cannot start a meshing process (fork failed)");
  }
  if (pid == 0) run_in_child(argv.data(), pipe_ends[1]);
  close(pipe_ends[1]);
  return {pid, pipe_ends[0], output};
}

/// Waits for `child`; returns its error message ("" when it succeeded).
std::string finish_meshing_child(const MeshingChild& child, const MeshFileRequest& request) {
  std::string message;
  char buffer[4096];
  for (ssize_t count; (count = read(child.error_pipe, buffer, sizeof buffer)) != 0;) {
    if (count < 0 && errno == EINTR) continue;
    if (count < 0) break;
    message.append(buffer, static_cast<std::size_t>(count));
  }
  close(child.error_pipe);
  int status = 0;
  while (waitpid(child.pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (!message.empty()) return message;
  if (WIFEXITED(status) && WEXITSTATUS(status) == cannot_execute_status) {
    return file_label(request.path) + ": cannot run the mesh reader '" +
           mesh_reader_executable().string() +
           "', which meshes .geo files (robin-mesh-reader, installed next to the tools)";
  }
  return file_label(request.path) + ": the meshing process " +
         (WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                              : "failed");
}

using Clock = std::chrono::steady_clock;

/// Blocks until one of the children `pending` (indices into `children`) has written to or
/// closed its error pipe (it is ending) and returns its index; the first on a poll error.
/// Calls `waiting` (when set) about once a second meanwhile.
std::size_t next_ended_child(const std::vector<std::optional<MeshingChild>>& children,
                             const std::vector<std::size_t>& pending,
                             const std::function<void()>& waiting) {
  std::vector<pollfd> pipes;
  for (const std::size_t k : pending) pipes.push_back({children[k]->error_pipe, POLLIN, 0});
  for (;;) {
    const int ready = poll(pipes.data(), pipes.size(), 1000);
    if (ready == 0) {
      if (waiting) waiting();
      continue;
    }
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return pending.front();
    for (std::size_t i = 0; i < pipes.size(); ++i) {
      if (pipes[i].revents != 0) return pending[i];
    }
  }
}

/// A private directory for the meshes of the children, removed on destruction.
class PrivateDirectory {
 public:
  PrivateDirectory() {
    std::string pattern = (std::filesystem::temp_directory_path() / "robin-mesh-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("cannot create a temporary directory for meshing in '" +
                               std::filesystem::temp_directory_path().string() + "'");
    }
    path_ = pattern;
  }
  ~PrivateDirectory() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  PrivateDirectory(const PrivateDirectory&) = delete;
  PrivateDirectory& operator=(const PrivateDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace

std::filesystem::path mesh_reader_executable() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path beside = self.parent_path() / "robin-mesh-reader";
    if (std::filesystem::is_regular_file(beside, error)) return beside;
  }
  return std::filesystem::path(ROBIN_BUILD_TOOL_DIRECTORY) / "robin-mesh-reader";
}

Mesh read_gmsh_mesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  if (lower_extension(path) == ".geo")
    return std::move(read_gmsh_meshes({{path, options}}).front());
  check_request(path, options);
  return read_msh_file(path);
}

std::vector<Mesh> read_gmsh_meshes(const std::vector<MeshFileRequest>& requests,
                                   const MeshReadObserver& observer) {
  std::vector<Mesh> meshes(requests.size());
  std::vector<std::optional<MeshingChild>> children(requests.size());
  std::vector<Clock::time_point> started(requests.size());
  const PrivateDirectory directory;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    if (lower_extension(requests[k].path) != ".geo") continue;
    check_request(requests[k].path, requests[k].options);
    children[k] =
        start_meshing_child(requests[k], directory.path() / ("body" + std::to_string(k) + ".msh"));
    started[k] = Clock::now();
    if (observer.started) observer.started(k);
  }
  std::string first_error;
  const auto read = [&](std::size_t k) {
    try {
      if (children[k]) {
        meshes[k] = read_msh_file(children[k]->output, requests[k].path.string());
      } else {
        check_request(requests[k].path, requests[k].options);
        meshes[k] = read_msh_file(requests[k].path);
      }
    } catch (const InputError& error) {
      if (first_error.empty()) first_error = error.what();
      return;
    }
    meshes[k].source = requests[k].path.string();
    if (observer.finished) {
      observer.finished(k, meshes[k],
                        std::chrono::duration<double>(Clock::now() - started[k]).count());
    }
  };
  // each child's mesh is read as soon as it ends, in the order they end
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    if (children[k]) pending.push_back(k);
  }
  while (!pending.empty()) {
    const std::size_t k = next_ended_child(children, pending, observer.waiting);
    pending.erase(std::find(pending.begin(), pending.end(), k));
    const std::string error = finish_meshing_child(*children[k], requests[k]);
    if (!error.empty() && first_error.empty()) first_error = error;
    if (error.empty() && first_error.empty()) read(k);
  }
  for (std::size_t k = 0; k < requests.size() && first_error.empty(); ++k) {
    if (children[k]) continue;
    started[k] = Clock::now();
    if (observer.started) observer.started(k);
    read(k);
  }
  if (!first_error.empty()) throw InputError(first_error);
  return meshes;
}

namespace {

/// The script's text without comments (// to the end of the line, /* ... */) and without the
/// contents of double-quoted strings; a string's own text is returned in `strings`.
std::string code_of_geo_script(const std::string& text, std::vector<std::string>& strings) {
  std::string code;
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (text.compare(k, 2, "//") == 0) {
      k = text.find('\n', k);
      if (k == std::string::npos) break;
      code += '\n';
    } else if (text.compare(k, 2, "/*") == 0) {
      k = text.find("*/", k + 2);
      if (k == std::string::npos) break;
      ++k;
      code += ' ';
    } else if (text[k] == '"') {
      std::string value;
      for (++k; k < text.size() && text[k] != '"'; ++k) {
        if (text[k] == '\\' && k + 1 < text.size()) ++k;
        value += text[k];
      }
      strings.push_back(value);
      code += "\"\"";
    } else {
      code += text[k];
    }
  }
  return code;
}

bool is_identifier_character(char character) {
  return std::isalnum(static_cast<unsigned char>(character)) != 0 || character == '_';
}

bool mentions_identifier(const std::string& code, const std::string& name) {
  for (std::size_t at = code.find(name); at != std::string::npos; at = code.find(name, at + 1)) {
    const bool starts = at == 0 || !is_identifier_character(code[at - 1]);
    const std::size_t end = at + name.size();
    const bool ends = end >= code.size() || !is_identifier_character(code[end]);
    if (starts && ends) return true;
  }
  return false;
}

}  // namespace

GeoVariableUse geo_variable_use(const std::filesystem::path& path, const std::string& name) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("mesh file '" + path.string() + "' cannot be read");
  std::ostringstream text;
  text << file.rdbuf();
  std::vector<std::string> strings;
  const std::string code = code_of_geo_script(text.str(), strings);
  if (mentions_identifier(code, name)) return GeoVariableUse::used;
  return mentions_identifier(code, "Include") ? GeoVariableUse::indeterminate
                                              : GeoVariableUse::unused;
}

}  // namespace robin
