// robin-subdomain: serves one elastic body of a robin-contact run over ZeroMQ
// (proto/robin.proto). Prints exactly one line on stdout, "listening on ENDPOINT", once bound
// (wildcards and ephemeral ports resolved); logs go to stderr.
// With --curve-secret-key and --curve-allow the transport is CurveZMQ (docs/security.md).
// Exit codes: 0 after Shutdown, SIGINT or SIGTERM (between requests: after the loop's clean
// shutdown; during a request, such as a long setup: at once, the request abandoned, since the
// run it belongs to is being stopped); 1 when the endpoint cannot be bound, the
// transport fails, or the CURVE options or key files are unusable; 2 for a bad command line
// (0 after --help and --version).

#include <spdlog/spdlog.h>
#include <unistd.h>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "command_line.hpp"
#include "curve_keys.hpp"
#include "numerics/heap_memory.hpp"
#include "protocol_version.hpp"
#include "server/server_logging.hpp"
#include "server/server_loop.hpp"
#include "server/subdomain_server.hpp"

namespace {

std::atomic<bool> stop_requested{false};
std::atomic<bool> handling_request{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

/// Between requests: the loop notices the flag within its poll interval and shuts down
/// cleanly. During a request (meshing and factorizing a large body can take minutes): _exit at
/// once, which is async-signal-safe; the coordinator sees the lost connection.
void request_stop(int) {
  if (handling_request.load()) {
    static const char message[] = "robin-subdomain: stopped by a signal during a request\n";
    [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, message, sizeof message - 1);
    _exit(0);
  }
  stop_requested.store(true);
}

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

/// Three quarters of the machine's physical memory in MiB (the default factor memory limit).
double default_factor_memory_mebibytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page_size <= 0) return 0.0;
  return 0.75 * static_cast<double>(pages) * static_cast<double>(page_size) / 1048576.0;
}

/// robin-mesh-reader next to this executable (/proc/self/exe), which reads the
/// SetupBody.mesh_path files; empty when this executable's path cannot be read (a mesh_path
/// then fails with "cannot run the mesh reader").
std::filesystem::path mesh_reader_next_to_this_executable() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path() / "robin-mesh-reader";
}

/// A --testing-stage-delay value, "correction=SECONDS" or "correction@ITERATION=SECONDS".
struct StageDelay {
  unsigned iteration = 0;  // 0: every iteration
  double seconds = 0.0;
};

/// Parses a --testing-stage-delay value; throws std::invalid_argument saying what is wrong.
StageDelay parse_stage_delay(const std::string& text) {
  const std::string usage = "expected correction=SECONDS or correction@ITERATION=SECONDS";
  const auto equals = text.find('=');
  if (equals == std::string::npos) throw std::invalid_argument(usage);
  const std::string stage = text.substr(0, equals);
  const std::string seconds = text.substr(equals + 1);
  StageDelay delay;
  std::size_t used = 0;
  try {
    delay.seconds = std::stod(seconds, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != seconds.size() || !(delay.seconds >= 0.0) || delay.seconds > 3600.0) {
    throw std::invalid_argument("'" + seconds + "' is not a number of seconds from 0 to 3600");
  }
  const std::string name = "correction";
  if (stage == name) return delay;
  if (stage.rfind(name + "@", 0) == 0) {
    const std::string iteration = stage.substr(name.size() + 1);
    if (!iteration.empty() && iteration.size() <= 9 &&
        iteration.find_first_not_of("0123456789") == std::string::npos) {
      delay.iteration = static_cast<unsigned>(std::stoul(iteration));
      if (delay.iteration != 0) return delay;
    }
  }
  throw std::invalid_argument("unknown stage '" + stage + "': " + usage + " (ITERATION from 1)");
}

struct CommandLine {
  robin::ServerLoopOptions loop;
  long maximum_dofs = 20'000'000;
  std::uintmax_t maximum_mesh_file_bytes = std::uintmax_t{1} << 30;
  double maximum_factor_mebibytes = default_factor_memory_mebibytes();
  robin::ServerSettings server;
  std::string log_level = "info";
  std::filesystem::path curve_secret_key;  // empty: no CURVE
  std::filesystem::path curve_allow;
  std::string stage_delay;  // --testing-stage-delay; empty: none
};

void add_options(CLI::App& app, CommandLine& command_line) {
  app.add_option("--listen", command_line.loop.endpoint,
                 "ZeroMQ endpoint to bind: tcp://HOST:PORT, tcp://*:PORT, tcp://127.0.0.1:* "
                 "(ephemeral port) or ipc://PATH")
      ->required();
  app.add_option("--log-level", command_line.log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}))
      ->capture_default_str();
  app.add_option("--max-message-size", command_line.loop.max_message_size,
                 "largest accepted request in bytes; libzmq drops a larger message and "
                 "disconnects its sender, who gets no reply")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--name", command_line.server.name, "label for the logs and HelloReply");
  app.add_option("--max-dofs", command_line.maximum_dofs,
                 "largest body served, in degrees of freedom (2 per node), checked before "
                 "assembly")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-factor-memory", command_line.maximum_factor_mebibytes,
                 "largest Cholesky factor (and dense interface operator) of a body in MiB, "
                 "estimated by the symbolic analysis before the factorization; default: 3/4 of "
                 "the physical memory")
      ->type_name("MIB")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--data-directory", command_line.server.data_directory,
                 "the directory under which SetupBody.mesh_path may name mesh files (relative "
                 "paths; nothing outside it, also through symbolic links); without it every "
                 "mesh_path is refused and meshes come only as data")
      ->type_name("DIR")
      ->check(CLI::ExistingDirectory);
  app.add_option("--max-mesh-file-size", command_line.maximum_mesh_file_bytes,
                 "largest mesh file a SetupBody.mesh_path may name, in bytes, checked before the "
                 "file is read (as large as the largest message by default)")
      ->type_name("BYTES")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--output-root", command_line.server.output_root,
                 "the directory under which FieldsRequest.write_directory may write <body>.vtu "
                 "(relative paths, no symbolic links followed); without it every "
                 "write_directory is refused")
      ->type_name("DIR")
      ->check(CLI::ExistingDirectory);
  app.add_option("--curve-secret-key", command_line.curve_secret_key,
                 "the server's key pair (a robin-keygen .secret file): encrypts the transport "
                 "with CurveZMQ and admits only the clients of --curve-allow")
      ->type_name("FILE");
  app.add_option("--curve-allow", command_line.curve_allow,
                 "allow-list of client public keys for CurveZMQ: one Z85 key per line (bare or "
                 "public-key = \"...\", i.e. concatenated .public files), '#' comments")
      ->type_name("FILE");
  // Testing only: announce and accept another protocol major version, announce another minor
  // (below 2 the server also ignores Envelope.run_id, as a protocol 1.1 server would).
  app.add_option("--protocol-major", command_line.server.protocol_major)->group("");
  app.add_option("--protocol-minor", command_line.server.protocol_minor)->group("");
  app.add_option("--without-capability", command_line.server.withheld_capabilities,
                 "TESTING ONLY: neither announce nor serve the optional capability NAME (it "
                 "then answers its request with UNSUPPORTED, like a protocol 1.0 server); "
                 "repeatable")
      ->type_name("NAME")
      ->check(CLI::IsMember({"neumann_solve"}))
      ->group("Testing only");
  app.add_option("--testing-stage-delay", command_line.stage_delay,
                 "TESTING ONLY: sleep SECONDS at the start of each CorrectionRequest (of "
                 "iteration ITERATION only, when given), after logging 'correction request "
                 "(iteration K)', so that a test can kill the server inside a correction step")
      ->type_name("correction[@ITERATION]=SECONDS")
      ->check(CLI::Validator(
          [](const std::string& value) {
            try {
              parse_stage_delay(value);
            } catch (const std::invalid_argument& error) {
              return std::string(error.what());
            }
            return std::string();
          },
          "", "stage delay"))
      ->group("Testing only");
}

/// The CURVE settings of the command line; throws std::runtime_error or KeyFileError naming the
/// option or the file when they are incomplete or unusable.
std::optional<robin::CurveServerOptions> curve_options(const CommandLine& command_line) {
  const bool has_key = !command_line.curve_secret_key.empty();
  const bool has_allow_list = !command_line.curve_allow.empty();
  if (!has_key && !has_allow_list) return std::nullopt;
  if (!has_allow_list) {
    throw std::runtime_error(
        "--curve-secret-key needs --curve-allow FILE: without an allow-list of client public "
        "keys the server would admit every client (refusing to start)");
  }
  if (!has_key) {
    throw std::runtime_error(
        "--curve-allow needs --curve-secret-key FILE (the server's key pair, from "
        "robin-keygen)");
  }
  if (!robin::curve_available()) {
    throw std::runtime_error("this libzmq is built without CURVE (zmq_has(\"curve\") is false)");
  }
  robin::CurveServerOptions curve;
  curve.key_pair = robin::read_curve_secret_key_file(command_line.curve_secret_key);
  curve.allowed_client_keys = robin::read_curve_allow_list(command_line.curve_allow);
  curve.allow_list = command_line.curve_allow.string();
  const std::string warning =
      robin::secret_key_file_permission_warning(command_line.curve_secret_key);
  if (!warning.empty()) robin::subdomain_logger()->warn("{}", warning);
  return curve;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"robin-subdomain: serves one elastic body of a robin-contact run over ZeroMQ"};
  CommandLine command_line;
  add_options(app, command_line);
  robin::add_version_option(app, "robin-subdomain");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;

  const auto logger = robin::subdomain_logger();
  logger->set_level(spdlog::level::from_str(command_line.log_level));
  install_signal_handlers();
  // Blocks of 4 MiB and more (stiffness copies, orderings, field arrays) are mapped and unmapped
  // on their own, so that a freed one is not resident beside the factor (heap_memory.hpp; the
  // threshold: docs/benchmarks.md, "Large blocks mapped on their own").
  robin::map_large_blocks_separately(std::size_t{4} << 20);
  try {
    command_line.loop.curve = curve_options(command_line);
  } catch (const std::exception& error) {
    logger->error("{}", error.what());
    return 1;
  }
  if (!command_line.stage_delay.empty()) {
    const StageDelay delay = parse_stage_delay(command_line.stage_delay);  // checked by CLI11
    command_line.server.correction_delay_seconds = delay.seconds;
    command_line.server.correction_delay_iteration = delay.iteration;
  }
  command_line.server.maximum_dofs = command_line.maximum_dofs;
  command_line.server.maximum_mesh_file_bytes = command_line.maximum_mesh_file_bytes;
  command_line.server.mesh_reader = mesh_reader_next_to_this_executable();
  command_line.server.maximum_factor_bytes = command_line.maximum_factor_mebibytes * 1048576.0;
  robin::SubdomainServer server(command_line.server);
  try {
    const std::string reason = robin::run_server_loop(
        server, command_line.loop, stop_requested, handling_request,
        [](const std::string& endpoint) {
          std::cout << "listening on " << endpoint << std::endl;  // the launcher reads this line
          // Nothing else goes to stdout: stray library output joins the logs on stderr, so a
          // launcher that stops reading the pipe can never block the server.
          dup2(STDERR_FILENO, STDOUT_FILENO);
        });
    logger->info("stopped: {}", reason);
    return 0;
  } catch (const robin::BindError& error) {
    logger->error("{}", error.what());
  } catch (const std::exception& error) {
    logger->critical("transport failure: {}", error.what());
  }
  return 1;
}
