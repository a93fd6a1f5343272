// robin-run CASE --output DIR [options]
// The one-command launcher: starts two robin-subdomain servers (found next to this executable)
// on tcp://127.0.0.1 with ephemeral ports, logs of the servers in DIR/logs/server-<body>.log,
// runs the coordinator against them and stops them. SIGINT/SIGTERM stop everything cleanly.
// Exit codes: coordinator_application.hpp.

#include <spdlog/spdlog.h>

#include "remote/coordinator_application.hpp"
#include "remote/run_interruption.hpp"
#include "remote/server_launcher.hpp"

namespace {

/// Starts the servers, runs the case against them and stops them; returns the exit code.
int run_with_local_servers(const robin::CaseDefinition& definition,
                           const robin::CoordinatorSettings& settings) {
  robin::ServerLaunchOptions launch;
  launch.log_directory = settings.output_directory / "logs";
  launch.log_level = settings.log_level;
  int code = 1;
  try {
    launch.executable = robin::sibling_executable("robin-subdomain");
    robin::LocalServers servers(
        {definition.bodies[0].definition.name, definition.bodies[1].definition.name}, launch);
    servers.await_listening(robin::throw_if_stop_requested);
    std::array<robin::ChannelOptions, 2> channels;
    for (int index = 0; index < 2; ++index) {
      robin::SubdomainServer& server = servers.server(index);
      spdlog::info("{} listening on {} (log: {})", server.label(), server.endpoint(),
                   server.log_file().string());
      channels[index].on_wait = robin::throw_if_stop_requested;
      channels[index].server_failure = [&server] { return server.failure(); };
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
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  robin::make_coordinator_logger(settings.log_level);
  robin::install_stop_signal_handlers();
  const auto definition = robin::load_case(settings);
  if (!definition) return 1;
  return run_with_local_servers(*definition, settings);
}
