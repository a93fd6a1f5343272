// robin-run CASE --output DIR [options]
// The one-command launcher: starts one robin-subdomain server per body (found next to this
// executable) on tcp://127.0.0.1 with ephemeral ports, logs of the servers in
// DIR/logs/server-<body>.log, runs the coordinator against them and stops them. SIGINT/SIGTERM stop
// everything cleanly. These servers get --output-root DIR and write their bodies' .vtu files
// themselves, in parallel (FieldsRequest.write_directory, docs/outputs.md), and read their
// bodies' .msh files themselves (--data-directory, the file's directory; SetupBody.mesh_path);
// with any --server-* option below the coordinator writes the files and sends the meshes.
// --curve encrypts the local connections with CurveZMQ, with keys made for this run only
// (curve_options.hpp); without it the loopback connections are not encrypted.
// Servers on other hosts: --server-command "ssh HOST" (or "srun -N1 -n1 ...", "ip netns exec
// NS") puts words before the server's command line, --server-listen the address it binds, and
// --server-executable its path there; each is given once for every server or once per body
// (body order). The prefix must pass the server's standard output through (its "listening on
// ENDPOINT" line gives the endpoint the coordinator connects to) and forward SIGTERM.
// Threads: the servers' factorizations run on a multithreaded BLAS (and OpenMP). Servers on
// this machine share its processors, max(1, processors / local servers) threads each
// (OPENBLAS_NUM_THREADS, OMP_NUM_THREADS and OMP_THREAD_LIMIT in their environment: Debian's
// CHOLMOD 3.0 runs its supernodal factorization on a team of four OpenMP threads even with
// OMP_NUM_THREADS=1, which only the limit caps), unless robin-run's own environment sets those
// variables;
// --threads-per-server N gives every server N.
// A server that dies mid-run is restarted (--max-server-restarts times per body, default 2):
// its body is set up again and the run carries on from its last checkpoint.
// Exit codes: coordinator_application.hpp.

#include <sched.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "remote/coordinator_application.hpp"
#include "remote/curve_options.hpp"
#include "remote/run_interruption.hpp"
#include "remote/server_launcher.hpp"

namespace {

/// Where and how the servers are started (the --server-* options).
struct ServerPlacement {
  std::vector<std::string> commands;  // command prefixes, split at spaces
  std::vector<std::string> listens;   // bind endpoints
  std::vector<std::string> executables;
  int threads_per_server = 0;  // --threads-per-server; 0: shared out among the local servers
};

/// The environment variables that set the thread counts of the BLAS (OpenBLAS) and OpenMP
/// libraries under the servers' factorizations.
constexpr std::array<const char*, 3> thread_variables = {"OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                                         "OMP_THREAD_LIMIT"};

/// The processors this process may run on (its affinity mask), at least 1.
int available_processors() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
  return std::max(1, CPU_COUNT(&set));
}

/// Sets each server's thread variables: `threads_per_server` when given; otherwise, for the
/// servers started on this machine (no command prefix), an equal share of its processors,
/// for each variable that robin-run's own environment does not set.
void set_server_threads(std::vector<robin::ServerLaunchOptions>& options, int threads_per_server) {
  const auto local = [](const robin::ServerLaunchOptions& server) {
    return server.command_prefix.empty();
  };
  const long local_count = std::count_if(options.begin(), options.end(), local);
  for (robin::ServerLaunchOptions& server : options) {
    if (threads_per_server == 0 && !local(server)) continue;
    const int threads = threads_per_server > 0
                            ? threads_per_server
                            : std::max(1, available_processors() / static_cast<int>(local_count));
    for (const char* variable : thread_variables) {
      if (threads_per_server == 0 && std::getenv(variable) != nullptr) continue;
      server.environment.emplace_back(variable, std::to_string(threads));
    }
  }
}

/// Splits a command prefix at runs of spaces ("ssh -p 2222 node1").
std::vector<std::string> split_words(const std::string& text) {
  std::vector<std::string> words;
  std::istringstream stream(text);
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

/// The value of a once-or-per-body option for body `index` (empty: not given).
std::string per_body(const std::vector<std::string>& values, int index) {
  if (values.empty()) return "";
  return values.size() == 1 ? values[0] : values[static_cast<std::size_t>(index)];
}

std::vector<robin::ServerLaunchOptions> placed(const robin::ServerLaunchOptions& launch,
                                               const ServerPlacement& placement,
                                               std::size_t body_count) {
  std::vector<robin::ServerLaunchOptions> options(body_count, launch);
  for (int index = 0; index < static_cast<int>(body_count); ++index) {
    options[index].command_prefix = split_words(per_body(placement.commands, index));
    if (const std::string listen = per_body(placement.listens, index); !listen.empty()) {
      options[index].listen = listen;
    }
    if (const std::string executable = per_body(placement.executables, index);
        !executable.empty()) {
      options[index].executable = executable;
    }
  }
  return options;
}

/// Whether the servers are this build's robin-subdomain on this machine, sharing the output
/// directory with the coordinator: no --server-command, --server-listen or --server-executable
/// (a server elsewhere, or another implementation, gets its files written by the coordinator).
bool writes_own_files(const ServerPlacement& placement) {
  return placement.commands.empty() && placement.listens.empty() && placement.executables.empty();
}

/// Lets the server of every body whose mesh is a .msh file read it itself
/// (MeshDelivery::file_on_server): the file's real directory is its --data-directory, the
/// file's name there its SetupBody.mesh_path. Only for this build's servers on this machine
/// (writes_own_files), which see the same files.
void let_servers_read_mesh_files(robin::CaseDefinition& definition,
                                 std::vector<robin::ServerLaunchOptions>& options) {
  for (std::size_t k = 0; k < definition.bodies.size(); ++k) {
    robin::BodyCase& body = definition.bodies[k];
    std::string extension = body.mesh_path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    std::error_code error;
    const std::filesystem::path real = std::filesystem::canonical(body.mesh_path, error);
    if (extension != ".msh" || error) continue;  // a .geo, or a file the coordinator's read names
    options[k].extra_arguments.push_back("--data-directory");
    options[k].extra_arguments.push_back(real.parent_path().string());
    body.mesh_delivery = robin::MeshDelivery::file_on_server;
    body.server_mesh_path = real.filename().string();
  }
}

/// Starts the servers, runs the case against them and stops them; returns the exit code.
int run_with_local_servers(const robin::CaseDefinition& definition,
                           robin::CoordinatorSettings settings, bool curve,
                           const ServerPlacement& placement) {
  robin::ServerLaunchOptions launch;
  launch.log_directory = settings.output_directory / "logs";
  launch.log_level = settings.log_level;
  int code = 1;
  try {
    std::optional<robin::EphemeralCurveKeys> keys;
    if (curve) {
      keys.emplace();
      launch.extra_arguments = keys->server_arguments();
      launch.curve_client = keys->client_keys();
      spdlog::info("CurveZMQ with keys made for this run (servers' public key {})",
                   keys->client_keys().server_public_key);
    }
    launch.executable = robin::sibling_executable("robin-subdomain");
    if (writes_own_files(placement)) {
      // the servers write their bodies' files into the output directory (FieldsRequest.
      // write_directory), as the coordinator would, each in parallel with the others
      launch.extra_arguments.push_back("--output-root");
      launch.extra_arguments.push_back(
          std::filesystem::absolute(settings.output_directory).string());
    }
    std::vector<robin::ServerLaunchOptions> options =
        placed(launch, placement, definition.bodies.size());
    set_server_threads(options, placement.threads_per_server);
    robin::CaseDefinition served = definition;
    if (writes_own_files(placement)) let_servers_read_mesh_files(served, options);
    robin::LocalServers servers(robin::body_names(definition), options);
    servers.await_listening(robin::throw_if_stop_requested);
    if (keys) keys->remove_files();  // read by the servers; the coordinator's are in memory
    std::vector<robin::ChannelOptions> channels(servers.size());
    for (int index = 0; index < static_cast<int>(servers.size()); ++index) {
      robin::SubdomainServer& server = servers.server(index);
      spdlog::info("{} listening on {} (log: {})", server.label(), server.endpoint(),
                   server.log_file().string());
      robin::ChannelOptions& channel = channels[static_cast<std::size_t>(index)];
      channel.on_wait = robin::throw_if_stop_requested;
      // the server of the body now: a restart replaces it
      channel.server_failure = [&servers, index] { return servers.server(index).failure(); };
      channel.curve = launch.curve_client;
    }
    robin::ServerRestart restart;
    restart.lost = [&servers](int body, bool connection_lost) {
      return servers.server(body).exited_within(connection_lost ? 2.0 : 0.0);
    };
    restart.restart = [&servers](int body) {
      servers.restart(body, robin::throw_if_stop_requested);
      const robin::SubdomainServer& server = servers.server(body);
      spdlog::info("{} listening on {} (log: {})", server.label(), server.endpoint(),
                   server.log_file().string());
      return server.endpoint();
    };
    // Stopped as soon as the coordinator is done with them, while it writes the result files;
    // the future's destructor waits for the stop also when run_coordinator throws.
    std::future<void> stopping;
    const auto stop_in_background = [&servers, &stopping] {
      try {
        stopping = std::async(std::launch::async, [&servers] { servers.stop(); });
      } catch (const std::system_error&) {  // no thread to spare: stop them in this one
        servers.stop();
      }
    };
    settings.servers_write_fields = writes_own_files(placement);
    code = robin::run_coordinator(served, settings, servers.endpoints(), channels, restart,
                                  stop_in_background);
    if (stopping.valid()) stopping.get();
    servers.stop();  // idempotent: stops them here when the run never started
    spdlog::info("servers stopped");
  } catch (const std::exception& error) {
    code = robin::failure_exit_code(error);
  }
  return code;
}

/// The --server-* and --threads-per-server options, into `placement`.
void add_server_options(CLI::App& app, ServerPlacement& placement) {
  app.add_option("--server-command", placement.commands,
                 "words put before each server's command line to start it elsewhere, e.g. "
                 "\"ssh node1\" or \"srun -N1 -n1\"; once for every server or once per body")
      ->type_name("WORDS");
  app.add_option("--server-listen", placement.listens,
                 "endpoint each server binds (default tcp://127.0.0.1:*), e.g. "
                 "tcp://10.0.0.2:5555 for a server on another host; once or per body")
      ->type_name("ENDPOINT");
  app.add_option("--server-executable", placement.executables,
                 "robin-subdomain's path where the servers run (default: next to robin-run); "
                 "once or per body")
      ->type_name("PATH");
  app.add_option("--threads-per-server", placement.threads_per_server,
                 "BLAS and OpenMP threads of every server (OPENBLAS_NUM_THREADS, "
                 "OMP_NUM_THREADS, OMP_THREAD_LIMIT); default: this machine's processors shared "
                 "out among the "
                 "servers started on it, unless those variables are set in this environment")
      ->type_name("N")
      ->check(CLI::Range(1, 4096));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "robin-run: solve a contact case by Robin domain decomposition, with one local "
      "robin-subdomain server per body"};
  robin::CoordinatorSettings settings;
  settings.tool = "robin-run";
  robin::add_coordinator_options(app, settings);
  robin::add_version_option(app, "robin-run");
  bool curve = false;
  app.add_flag("--curve", curve,
               "encrypt the connections to the local servers with CurveZMQ, with keys made for "
               "this run (off by default: the connections stay on this machine's loopback)");
  ServerPlacement placement;
  add_server_options(app, placement);
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  // --quiet quietens this terminal; the servers' log files keep --log-level.
  settings.display = std::make_shared<robin::ProgressDisplay>(
      robin::progress_output_of_this_process(settings.quiet));
  robin::make_coordinator_logger(settings.quiet ? "warn" : settings.log_level,
                                 settings.display.get());
  robin::install_stop_signal_handlers();
  auto definition = robin::load_case(settings);
  if (!definition) return 1;
  for (const auto* values : {&placement.commands, &placement.listens, &placement.executables}) {
    if (values->size() > 1 && values->size() != definition->bodies.size()) {
      std::fprintf(stderr,
                   "robin-run: --server-command, --server-listen and --server-executable "
                   "are given once for every server or once per body (the case has %zu bodies, "
                   "in body order); got %zu\n",
                   definition->bodies.size(), values->size());
      return 2;
    }
  }
  return run_with_local_servers(*definition, settings, curve, placement);
}
