#include "numerics/gmsh_reader.hpp"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <functional>
#include <future>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "numerics/errors.hpp"
#include "numerics/helper_process.hpp"
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

/// Where the meshing process writes the mesh of request `k`.
std::filesystem::path meshing_output(const std::filesystem::path& directory, std::size_t k) {
  return directory / ("body" + std::to_string(k) + ".msh");
}

/// robin-mesh-reader meshing the .geo files of one read_gmsh_meshes call (mesh_reader_main.cpp,
/// --mesh-geo-batch): one process, which loads libgmsh once and forks a meshing child per file,
/// all concurrently, and reports each file as its child ends on its standard output: a line
/// "REQUEST LENGTH" then LENGTH bytes of error message (0: the mesh is written), read from its
/// HelperProcess::output.
using MeshingProcess = HelperProcess;

/// The command line of robin-mesh-reader meshing `geo_requests` (indices into `requests`), each
/// into directory/bodyK.msh: --mesh-geo-batch, then per file its request index, .geo path,
/// output path, size, element order and recombination (0 or 1).
std::vector<std::string> meshing_command(const std::vector<MeshFileRequest>& requests,
                                         const std::vector<std::size_t>& geo_requests,
                                         const std::filesystem::path& directory) {
  std::vector<std::string> words = {mesh_reader_executable().string(), "--mesh-geo-batch"};
  for (const std::size_t k : geo_requests) {
    std::ostringstream size;
    size.precision(17);
    size << requests[k].options.size;
    words.insert(words.end(), {std::to_string(k), requests[k].path.string(),
                               meshing_output(directory, k).string(), size.str(),
                               std::to_string(requests[k].options.element_order),
                               requests[k].options.recombine ? "1" : "0"});
  }
  return words;
}

MeshingProcess start_meshing_process(std::vector<std::string> words) {
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  return start_helper_process(argv.data(), "cannot create a pipe for meshing",
                              "cannot start a meshing process (fork failed)");
}

/// The reports of a MeshingProcess as they arrive: each request index with its error message
/// ("" when its mesh is written).
class MeshingReports {
 public:
  explicit MeshingReports(int descriptor) : descriptor_(descriptor) {}

  /// The next report; std::nullopt when the process's output has ended. Calls `waiting` (when
  /// set) about once a second meanwhile.
  std::optional<std::pair<std::size_t, std::string>> next(const std::function<void()>& waiting) {
    for (;;) {
      if (auto report = parse()) return report;
      if (ended_) return std::nullopt;
      pollfd descriptor{descriptor_, POLLIN, 0};
      const int ready = poll(&descriptor, 1, 1000);
      if (ready == 0 && waiting) waiting();
      if (ready <= 0) continue;
      char buffer[4096];
      const ssize_t count = read(descriptor_, buffer, sizeof buffer);
      if (count < 0 && errno == EINTR) continue;
      if (count <= 0) ended_ = true;
      if (count > 0) bytes_.append(buffer, static_cast<std::size_t>(count));
    }
  }

 private:
  /// A complete report at the front of the bytes received, removed from them.
  std::optional<std::pair<std::size_t, std::string>> parse() {
    const std::size_t line_end = bytes_.find('\n');
    if (line_end == std::string::npos) return std::nullopt;
    std::size_t request = 0, length = 0;
    std::istringstream header(bytes_.substr(0, line_end));
    if (!(header >> request >> length)) {
      ended_ = true;  // not a report: the process is not the reader this build expects
      bytes_.clear();
      return std::nullopt;
    }
    if (bytes_.size() - line_end - 1 < length) return std::nullopt;
    std::string message = bytes_.substr(line_end + 1, length);
    bytes_.erase(0, line_end + 1 + length);
    return std::make_pair(request, std::move(message));
  }

  int descriptor_;
  std::string bytes_;
  bool ended_ = false;
};

/// Waits for the meshing process; "" when it exited with 0, else why it failed.
std::string finish_meshing_process(const MeshingProcess& process) {
  close(process.output);
  int status = 0;
  while (waitpid(process.pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (WIFEXITED(status) && WEXITSTATUS(status) == cannot_execute_status) {
    return "cannot run the mesh reader '" + mesh_reader_executable().string() +
           "', which meshes .geo files (robin-mesh-reader, installed next to the tools)";
  }
  return "the meshing process " +
         (WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                              : "failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")");
}

using Clock = std::chrono::steady_clock;

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

/// Hands a read mesh (or the InputError of its reading) to read_gmsh_meshes.
using MeshDelivery = std::function<void(std::size_t request, const std::function<Mesh()>& read)>;

/// Reads the requests that are not .geo files on concurrent threads, at most one per processor
/// at a time, and gives each to `deliver` on the calling thread in request order, as soon as it
/// and those before it are read. Reads nothing when `first_error` is set; after a failure, the
/// readings already started are waited for but not delivered.
void read_msh_requests(const std::vector<MeshFileRequest>& requests,
                       std::vector<Clock::time_point>& started, const MeshReadObserver& observer,
                       const std::string& first_error, const MeshDelivery& deliver) {
  std::vector<std::size_t> files;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    if (lower_extension(requests[k].path) != ".geo") files.push_back(k);
  }
  const std::size_t concurrent = std::max(1u, std::thread::hardware_concurrency());
  std::deque<std::future<Mesh>> readings;
  std::size_t next = 0;
  for (std::size_t delivered = 0; delivered < files.size() && first_error.empty(); ++delivered) {
    while (next < files.size() && readings.size() < concurrent) {
      const std::size_t k = files[next++];
      started[k] = Clock::now();
      if (observer.started) observer.started(k);
      readings.push_back(std::async(std::launch::async, [&request = requests[k]] {
        check_request(request.path, request.options);
        return read_msh_file(request.path, request.path.string());
      }));
    }
    std::future<Mesh> reading = std::move(readings.front());
    readings.pop_front();
    deliver(files[delivered], [&reading] { return reading.get(); });
  }
}

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

void read_gmsh_meshes(const std::vector<MeshFileRequest>& requests, const MeshReceiver& receive,
                      const MeshReadObserver& observer) {
  std::vector<bool> meshed(requests.size(), false);
  std::vector<std::size_t> geo_requests;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    if (lower_extension(requests[k].path) != ".geo") continue;
    check_request(requests[k].path, requests[k].options);
    geo_requests.push_back(k);
  }
  std::vector<Clock::time_point> started(requests.size());
  const PrivateDirectory directory;
  std::string first_error;
  // a read mesh is told to the observer and handed over; a failure is kept, not thrown, so
  // that every meshing child is waited for
  const auto deliver = [&](std::size_t k, const std::function<Mesh()>& read) {
    try {
      Mesh mesh = read();
      mesh.source = requests[k].path.string();
      if (observer.finished) {
        observer.finished(k, mesh,
                          std::chrono::duration<double>(Clock::now() - started[k]).count());
      }
      receive(k, std::move(mesh));
    } catch (const InputError& error) {
      if (first_error.empty()) first_error = error.what();
    }
  };
  if (!geo_requests.empty()) {
    const MeshingProcess process =
        start_meshing_process(meshing_command(requests, geo_requests, directory.path()));
    for (const std::size_t k : geo_requests) {
      started[k] = Clock::now();
      if (observer.started) observer.started(k);
    }
    // each .geo's mesh is read as soon as its child has ended, in the order they end
    MeshingReports reports(process.output);
    while (const auto report = reports.next(observer.waiting)) {
      const auto [k, error] = *report;
      if (k >= requests.size() || meshed[k]) continue;
      meshed[k] = true;
      if (!error.empty() && first_error.empty()) first_error = error;
      if (!error.empty() || !first_error.empty()) continue;
      const std::filesystem::path output = meshing_output(directory.path(), k);
      const std::string label = requests[k].path.string();
      deliver(k, [&output, &label] { return read_msh_file(output, label); });
    }
    const std::string process_error = finish_meshing_process(process);
    for (const std::size_t k : geo_requests) {
      if (meshed[k] || !first_error.empty()) continue;
      first_error =
          file_label(requests[k].path) + ": " +
          (process_error.empty() ? "the meshing process ended without its mesh" : process_error);
    }
  }
  read_msh_requests(requests, started, observer, first_error, deliver);
  if (!first_error.empty()) throw InputError(first_error);
}

std::vector<Mesh> read_gmsh_meshes(const std::vector<MeshFileRequest>& requests,
                                   const MeshReadObserver& observer) {
  std::vector<Mesh> meshes(requests.size());
  read_gmsh_meshes(
      requests, [&](std::size_t k, Mesh&& mesh) { meshes[k] = std::move(mesh); }, observer);
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
