// robin-run CASE --output DIR [options]
// The one-command launcher: starts two robin-subdomain servers (found next to this executable)
// on tcp://127.0.0.1 with ephemeral ports, logs of the servers in DIR/logs/server-<body>.log,
// runs the coordinator against them and stops them. SIGINT/SIGTERM stop everything cleanly.
// --curve encrypts the local connections with CurveZMQ, with keys made for this run only
// (curve_options.hpp); without it the loopback connections are not encrypted.
// Exit codes: coordinator_application.hpp.

#include <spdlog/spdlog.h>

#include <optional>

#include "remote/coordinator_application.hpp"
#include "remote/curve_options.hpp"
#include "remote/run_interruption.hpp"
#include "remote/server_launcher.hpp"

namespace {

/// Starts the servers, runs the case against them and stops them; returns the exit code.
int run_with_local_servers(const robin::CaseDefinition& definition,
                           const robin::CoordinatorSettings& settings, bool curve) {
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
    robin::LocalServers servers(
        {definition.bodies[0].definition.name, definition.bodies[1].definition.name}, launch);
    servers.await_listening(robin::throw_if_stop_requested);
    if (keys) keys->remove_files();  // read by the servers; the coordinator's are in memory
    std::array<robin::ChannelOptions, 2> channels;
    for (int index = 0; index < 2; ++index) {
      robin::SubdomainServer& server = servers.server(index);
      spdlog::info("{} listening on {} (log: {})", server.label(), server.endpoint(),
                   server.log_file().string());
      channels[index].on_wait = robin::throw_if_stop_requested;
      channels[index].server_failure = [&server] { return server.failure(); };
      channels[index].curve = launch.curve_client;
    }
    code = robin::run_coordinator(definition, settings, servers.endpoints(), channels);
    servers.stop();
    spdlog::info("servers stopped");
  } catch (const std::exception& error) {
    code = robin::failure_exit_code(error);
  }
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "robin-run: solve a two-body contact case by Robin domain decomposition, with two local "
      "robin-subdomain servers"};
  robin::CoordinatorSettings settings;
  robin::add_coordinator_options(app, settings);
  bool curve = false;
  app.add_flag("--curve", curve,
               "encrypt the connections to the local servers with CurveZMQ, with keys made for "
               "this run (off by default: the connections stay on this machine's loopback)");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  robin::make_coordinator_logger(settings.log_level);
  robin::install_stop_signal_handlers();
  const auto definition = robin::load_case(settings);
  if (!definition) return 1;
  return run_with_local_servers(*definition, settings, curve);
}
