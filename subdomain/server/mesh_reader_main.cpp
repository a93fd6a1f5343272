// robin-mesh-reader: the only executable that links libgmsh; the tools run it, it is not a tool
// of its own. Two modes:
//  - robin-mesh-reader --mesh-geo-batch [REQUEST GEO OUTPUT SIZE ORDER RECOMBINE]...: meshes each
//    .geo script GEO with Gmsh (mesh_geo_file; h = SIZE when > 0, element order ORDER,
//    quadrilaterals when RECOMBINE is 1) in a child process of its own, all concurrently, into
//    OUTPUT as binary MSH 4.1, for read_gmsh_meshes (gmsh_reader.hpp) of robin-run,
//    robin-coordinator, robin-monolithic, ...; libgmsh is loaded once for all of them. Reports
//    each script as its child ends on the standard output: "REQUEST LENGTH", a newline, and
//    LENGTH bytes of error message (0 when the mesh is written).
//  - robin-mesh-reader --mesh-geo GEO --output OUT [--size H] [--element-order K] [--recombine]:
//    the same for one script in this process; on failure it writes the error message on its
//    standard output and exits with 1.
//  - robin-mesh-reader FILE: robin-subdomain's reader of a SetupBody.mesh_path .geo file
//    (mesh_file_reader.hpp). Reads FILE with read_gmsh_mesh and writes one message on its
//    standard output: mesh_reader_message (the mesh) or mesh_reader_error_message (why the file
//    is refused); exits with 0 after writing it. Only the server runs it, on a file it has
//    already checked (under its --data-directory, at most --max-mesh-file-size bytes). It caps
//    its own address space (RLIMIT_AS) before reading, which the meshing process it starts
//    inherits: Gmsh's memory is not bounded by the script's size.
// Exit codes: 2 for a bad command line or when the message cannot be written; a crash of Gmsh
// ends the process by its signal.

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "gmsh/geo_mesher.hpp"
#include "numerics/gmsh_reader.hpp"
#include "server/mesh_file_reader.hpp"

namespace {

/// Address space the reader may add to what it has at start: a fixed part for Gmsh's own
/// work, plus a multiple of the file's size.
constexpr std::uint64_t base_allowance_bytes = std::uint64_t{256} << 20;
constexpr std::uint64_t allowance_per_file_byte = 32;

/// The process's address space now (the first field of /proc/self/statm, in pages), 0 if
/// unknown.
std::uint64_t address_space_bytes() {
  const int file = open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
  if (file < 0) return 0;
  char text[64] = {};
  const ssize_t count = read(file, text, sizeof text - 1);
  close(file);
  if (count <= 0) return 0;
  return std::strtoull(text, nullptr, 10) * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
}

/// Caps the address space (RLIMIT_AS) at what the process has plus `allowance`, so that an
/// allocation beyond it fails (std::bad_alloc) instead of taking the host's memory; an existing
/// lower limit is kept. Returns the allowance in force (0 when the size cannot be read).
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

/// Set when operator new found no memory: read_gmsh_mesh turns the exception into its own
/// error, so the new-handler records it.
bool allocation_refused = false;

void refuse_allocation() {
  allocation_refused = true;
  std::set_new_handler(nullptr);
  throw std::bad_alloc();
}

std::string memory_refusal(std::uint64_t allowance, std::uintmax_t file_bytes) {
  return "the mesh reader ran out of the memory it is allowed for this file (" +
         std::to_string(allowance >> 20) + " MiB for " + std::to_string(file_bytes) +
         " bytes): does a header claim more nodes or elements than the file holds? refused";
}

/// The message for the file at `path` (a refusal when read_gmsh_mesh throws), read within the
/// memory allowance of that file.
std::string message_for(const std::string& path) {
  std::error_code size_error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, size_error);
  const std::uint64_t allowance = limit_address_space(
      base_allowance_bytes + allowance_per_file_byte * (size_error ? 0 : file_bytes));
  std::set_new_handler(refuse_allocation);
  std::string refusal;
  try {
    return robin::mesh_reader_message(robin::read_gmsh_mesh(path));
  } catch (const std::exception& error) {
    refusal = error.what();
  } catch (...) {
    refusal = "the mesh reader failed";
  }
  if (allocation_refused) refusal = memory_refusal(allowance, file_bytes);
  return robin::mesh_reader_error_message(refusal);
}

/// Writes all of `message` to `descriptor` (the standard output by default); false when it
/// cannot.
bool write_all(const std::string& message, int descriptor = STDOUT_FILENO) {
  for (std::size_t written = 0; written < message.size();) {
    const ssize_t count = write(descriptor, message.data() + written, message.size() - written);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) return false;
    written += static_cast<std::size_t>(count);
  }
  return true;
}

/// Meshes `geo` into `output`; returns the exit status (1 with the message written to
/// `descriptor` when Gmsh refuses the script).
int mesh_geo(const std::string& geo, const robin::MeshReadOptions& options,
             const std::string& output, int descriptor = STDOUT_FILENO) {
  std::string message;
  try {
    robin::mesh_geo_file(geo, options, output);
    return 0;
  } catch (const std::exception& error) {
    message = error.what();
  } catch (...) {
    message = "mesh file '" + geo + "': meshing failed";
  }
  return write_all(message, descriptor) ? 1 : 2;
}

/// One .geo of --mesh-geo-batch and the child process meshing it.
struct MeshingJob {
  std::string request;  // the caller's index of the file, echoed in its report
  std::string geo, output;
  robin::MeshReadOptions options;
  pid_t pid = -1;
  int messages = -1;  // the read end of the pipe of the child's error message
};

/// The jobs of `--mesh-geo-batch REQUEST GEO OUTPUT SIZE ORDER RECOMBINE ...`; false when the
/// words are not groups of six with numbers where numbers belong.
bool parse_jobs(int argc, char** argv, std::vector<MeshingJob>& jobs) {
  if ((argc - 2) % 6 != 0) return false;
  for (int k = 2; k + 5 < argc; k += 6) {
    MeshingJob job;
    job.request = argv[k];
    job.geo = argv[k + 1];
    job.output = argv[k + 2];
    char* end = nullptr;
    job.options.size = std::strtod(argv[k + 3], &end);
    if (*end != '\0') return false;
    job.options.element_order = static_cast<int>(std::strtol(argv[k + 4], &end, 10));
    if (*end != '\0') return false;
    job.options.recombine = std::string(argv[k + 5]) == "1";
    jobs.push_back(std::move(job));
  }
  return true;
}

/// Forks the child that meshes `job`: its error message goes to a pipe of its own, its standard
/// output (Gmsh's, if any) to /dev/null, away from the reports.
bool start_job(MeshingJob& job) {
  int ends[2];
  if (pipe2(ends, O_CLOEXEC) != 0) return false;
  const pid_t pid = fork();
  if (pid < 0) {
    close(ends[0]);
    close(ends[1]);
    return false;
  }
  if (pid == 0) {
    // the child ends with this process (a tool ending on a signal kills its own children only)
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() == 1) _exit(2);
    close(ends[0]);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (null >= 0) dup2(null, STDOUT_FILENO);
    _exit(mesh_geo(job.geo, job.options, job.output, ends[1]));
  }
  close(ends[1]);
  job.pid = pid;
  job.messages = ends[0];
  return true;
}

/// Waits for the child of `job`; returns its error message ("" when it wrote the mesh).
std::string finish_job(const MeshingJob& job) {
  std::string message;
  char buffer[4096];
  for (ssize_t count; (count = read(job.messages, buffer, sizeof buffer)) != 0;) {
    if (count < 0 && errno == EINTR) continue;
    if (count < 0) break;
    message.append(buffer, static_cast<std::size_t>(count));
  }
  close(job.messages);
  int status = 0;
  while (waitpid(job.pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (!message.empty()) return message;
  return "mesh file '" + job.geo + "': the meshing process " +
         (WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                              : "failed");
}

/// --mesh-geo-batch: meshes every job in a child of its own, all concurrently (libgmsh is loaded
/// once, in this process), and reports each as its child ends: "REQUEST LENGTH\n" and LENGTH
/// bytes of error message (0: the mesh is written). Returns the exit status.
int mesh_geo_batch(int argc, char** argv) {
  prctl(PR_SET_PDEATHSIG, SIGKILL);  // this process ends with the tool that started it
  std::vector<MeshingJob> jobs;
  if (!parse_jobs(argc, argv, jobs)) {
    std::fputs(
        "robin-mesh-reader: --mesh-geo-batch takes groups of REQUEST GEO OUTPUT SIZE "
        "ORDER RECOMBINE\n",
        stderr);
    return 2;
  }
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    if (!start_job(jobs[k])) return 3;
    pending.push_back(k);
  }
  while (!pending.empty()) {
    std::vector<pollfd> pipes;
    for (const std::size_t k : pending) pipes.push_back({jobs[k].messages, POLLIN, 0});
    if (poll(pipes.data(), pipes.size(), -1) < 0 && errno != EINTR) return 3;
    for (std::size_t i = pipes.size(); i-- > 0;) {
      if (pipes[i].revents == 0) continue;
      const MeshingJob& job = jobs[pending[i]];
      const std::string message = finish_job(job);
      if (!write_all(job.request + " " + std::to_string(message.size()) + "\n" + message)) {
        return 2;
      }
      pending.erase(pending.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "--mesh-geo-batch") _exit(mesh_geo_batch(argc, argv));
  CLI::App app{
      "robin-mesh-reader: meshes a .geo script with Gmsh for the tools (--mesh-geo), or reads a "
      "mesh file for robin-subdomain (SetupBody.mesh_path) and writes it on standard output; "
      "run by the tools, not by hand"};
  std::string file, geo, output;
  robin::MeshReadOptions options;
  app.add_option("file", file, "the mesh file (.msh or .geo) to send to robin-subdomain");
  auto* geo_option = app.add_option("--mesh-geo", geo, "the .geo script to mesh into --output");
  auto* output_option =
      app.add_option("--output", output, "the binary MSH 4.1 file --mesh-geo writes");
  app.add_option("--size", options.size, "the value of the .geo variable h (0: the script's)");
  app.add_option("--element-order", options.element_order, "1 or 2");
  app.add_flag("--recombine", options.recombine, "generate quadrilaterals (Mesh.RecombineAll)");
  geo_option->needs(output_option);
  output_option->needs(geo_option);
  geo_option->excludes("file");
  robin::add_version_option(app, "robin-mesh-reader");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  if (!geo.empty()) _exit(mesh_geo(geo, options, output));
  if (file.empty()) {
    std::fputs("robin-mesh-reader: give FILE or --mesh-geo GEO --output OUT\n", stderr);
    return 2;
  }
  const bool written = write_all(message_for(file));
  // As in the forked reader before this executable: nothing runs after the message is out (no
  // exit handlers, no teardown of Gmsh's static state, no sanitizer's leak check of Gmsh), so a
  // problem there cannot turn a file read into a failure; the server reads only the status.
  _exit(written ? 0 : 2);
}
