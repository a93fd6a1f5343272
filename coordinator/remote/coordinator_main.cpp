// robin-coordinator CASE --subdomain ENDPOINT --subdomain ENDPOINT --output DIR [options]
// Runs the Robin domain decomposition of a case on two running robin-subdomain servers; the
// first --subdomain serves body 1, the second body 2. With --curve-secret-key and
// --curve-server-key the connections use CurveZMQ (curve_options.hpp, docs/security.md).
// A server whose connection drops mid-run is waited for at its endpoint (--server-grace-period,
// --max-server-restarts); then its body is set up again and the run carries on from its last
// checkpoint. Exit codes: coordinator_application.hpp.

#include <spdlog/spdlog.h>

#include <iostream>
#include <string>
#include <vector>

#include "remote/conformance_check.hpp"
#include "remote/coordinator_application.hpp"
#include "remote/curve_options.hpp"
#include "remote/remote_port.hpp"
#include "remote/run_interruption.hpp"

int main(int argc, char** argv) {
  // --check-server ENDPOINT: the protocol conformance checker, with its own options.
  if (robin::requests_server_check(argc, argv)) return robin::server_check_main(argc, argv);
  CLI::App app{
      "robin-coordinator: Robin domain decomposition of a contact case on robin-subdomain "
      "servers, one per body"};
  robin::CoordinatorSettings settings;
  std::vector<std::string> subdomains;
  robin::add_coordinator_options(app, settings);
  robin::add_version_option(app, "robin-coordinator");
  app.add_option("--subdomain", subdomains,
                 "endpoint of a robin-subdomain server (e.g. tcp://host:5555); give it once per "
                 "body of the case, in body order (the first serves body 1)")
      ->required()
      ->allow_extra_args(false);  // one endpoint per --subdomain; the count is checked below
  robin::CurveClientSettings curve;
  robin::add_curve_client_options(app, curve, "--subdomain");
  app.add_option("--server-grace-period", settings.server_grace_period_seconds,
                 "when a server is lost mid-run, wait this long (seconds) for it to answer at "
                 "its endpoint again (e.g. restarted by systemd), then set its body up again and "
                 "carry on from the last checkpoint (at most --max-server-restarts times)")
      ->check(CLI::NonNegativeNumber);
  std::string check_server;  // handled above; listed here for --help
  app.add_option("--check-server", check_server,
                 "instead of a run: check that the server at ENDPOINT conforms to the protocol "
                 "(CASE and --subdomain are then not needed; --check-server ENDPOINT --help)")
      ->type_name("ENDPOINT");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  if (subdomains.size() < 2) {
    std::cerr << "robin-coordinator: give one --subdomain ENDPOINT option per body, at least two "
                 "(the first serves body 1, the second body 2, ...); got "
              << subdomains.size() << "\nRun with --help for more information.\n";
    return 2;
  }
  if (const std::string problem = robin::curve_options_problem(curve, subdomains.size());
      !problem.empty()) {
    std::cerr << "robin-coordinator: " << problem << "\nRun with --help for more information.\n";
    return 2;
  }
  settings.display = std::make_shared<robin::ProgressDisplay>(
      robin::progress_output_of_this_process(settings.quiet));
  const auto log = robin::make_coordinator_logger(settings.quiet ? "warn" : settings.log_level,
                                                  settings.display.get());
  robin::install_stop_signal_handlers();
  std::vector<std::optional<robin::CurveClientKeys>> curve_keys;
  try {
    curve_keys = robin::load_curve_client_keys(curve, subdomains.size());
  } catch (const std::exception& error) {
    log->error("{}", error.what());
    return 1;
  }
  const auto definition = robin::load_case(settings);
  if (!definition) return 1;
  if (definition->bodies.size() != subdomains.size()) {
    std::cerr << "robin-coordinator: the case " << definition->file.string() << " has "
              << definition->bodies.size() << " bodies: give one --subdomain ENDPOINT per body, "
              << "in body order; got " << subdomains.size()
              << "\nRun with --help for more information.\n";
    return 2;
  }
  std::vector<robin::ChannelOptions> channels(subdomains.size());
  for (std::size_t index = 0; index < channels.size(); ++index) {
    channels[index].on_wait = robin::throw_if_stop_requested;
    channels[index].curve = curve_keys[index];
  }
  // A lost server (its connection dropped) is waited for at its endpoint.
  robin::ServerRestart restart;
  restart.lost = [](int, bool connection_lost) { return connection_lost; };
  restart.restart = [&](int body) {
    log->info("waiting up to {} s for a server at {} (--server-grace-period)",
              settings.server_grace_period_seconds, subdomains[body]);
    robin::await_server(subdomains[body], settings.server_grace_period_seconds, channels[body]);
    return subdomains[body];
  };
  return robin::run_coordinator(*definition, settings, subdomains, channels, restart);
}
