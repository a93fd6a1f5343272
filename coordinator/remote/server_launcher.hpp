#pragma once
// Local robin-subdomain servers for robin-run (and the integration tests): one child process
// per body, started with `--listen ENDPOINT --name BODY --log-level L`, its standard error in
// <log directory>/server-<body>.log. A server announces itself with exactly one line
// "listening on <endpoint>" on its standard output, with wildcard ports resolved.
//
// Stopping (request_shutdown + finish_stop, also in the destructor): a Shutdown request, then
// SIGTERM when the server did not acknowledge it or has not exited within the grace period,
// then SIGKILL after another grace period; the process is always reaped.

#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "curve_keys.hpp"
#include "remote/child_process.hpp"

namespace robin {

struct ServerLaunchOptions {
  std::filesystem::path executable;     // robin-subdomain
  std::filesystem::path log_directory;  // created if needed
  std::string listen = "tcp://127.0.0.1:*";
  std::string log_level = "info";
  double startup_timeout_seconds = 20.0;     // until the "listening on" line
  double shutdown_timeout_seconds = 2.0;     // deadline of the Shutdown request
  double grace_seconds = 3.0;                // before SIGTERM, and again before SIGKILL
  std::vector<std::string> extra_arguments;  // appended to the server's command line
  std::vector<std::string> command_prefix;   // see child_process.hpp; empty: run directly
  /// Set in the server's environment on top of the launcher's (ChildProcessOptions).
  std::vector<std::pair<std::string, std::string>> environment;
  /// The coordinator's keys for the Shutdown request when the servers use CurveZMQ (their
  /// --curve-secret-key and --curve-allow in extra_arguments).
  std::optional<CurveClientKeys> curve_client;
};

/// `name` next to the running executable (/proc/self/exe), e.g. build/bin/robin-subdomain.
std::filesystem::path sibling_executable(const std::string& name);

class SubdomainServer {
 public:
  /// Starts the server for `body` (does not wait for it). Throws std::runtime_error naming the
  /// body and the executable when it cannot be started.
  SubdomainServer(const std::string& body, const ServerLaunchOptions& options);
  ~SubdomainServer();

  /// Reads the "listening on" line. Throws std::runtime_error naming the server, why it is
  /// not listening (exited, no line before the deadline, unexpected output) and the end of
  /// its log. `on_wait` runs while waiting and may throw to abandon the wait.
  void await_listening(const std::function<void()>& on_wait = {});

  /// The server's actual endpoint (after await_listening).
  const std::string& endpoint() const { return endpoint_; }
  const std::string& body() const { return body_; }
  pid_t pid() const { return process_->pid(); }
  const std::filesystem::path& log_file() const { return log_file_; }
  /// "robin-subdomain for body 'upper' (pid 123)", for messages.
  std::string label() const;
  /// Empty while the server runs; otherwise what happened to it, naming it and its log.
  /// Thread-safe.
  std::string failure();
  /// Whether the server has exited, waiting up to `seconds` for it (a lost connection is
  /// usually seen just before the process's exit is).
  bool exited_within(double seconds) { return process_->wait_for_exit(seconds); }

  /// Sends Shutdown (when listening) without waiting for the process.
  void request_shutdown() noexcept;
  /// Waits for the exit after request_shutdown; SIGTERM, then SIGKILL. Always reaps.
  void finish_stop() noexcept;

 private:
  std::string body_;
  ServerLaunchOptions options_;
  std::filesystem::path log_file_;
  std::unique_ptr<ChildProcess> process_;
  std::string endpoint_;
  bool stopping_ = false;
  bool shutdown_acknowledged_ = false;
};

/// Starts one server per body and stops them all (in parallel) at destruction.
class LocalServers {
 public:
  LocalServers(const std::vector<std::string>& bodies, const ServerLaunchOptions& options);
  /// One set of options per body (e.g. another command prefix and listen address per host).
  LocalServers(const std::vector<std::string>& bodies,
               const std::vector<ServerLaunchOptions>& options);
  ~LocalServers();
  /// Waits until every server listens (see SubdomainServer::await_listening).
  void await_listening(const std::function<void()>& on_wait = {});
  std::vector<std::string> endpoints() const;
  std::size_t size() const { return servers_.size(); }
  SubdomainServer& server(int index) { return *servers_.at(static_cast<std::size_t>(index)); }
  /// Replaces server `index` (which has exited) by a new one started with the same options and
  /// waits until it listens (its log goes on in the same file). Throws as the constructor and
  /// await_listening do.
  void restart(int index, const std::function<void()>& on_wait = {});
  /// Stops every server; idempotent.
  void stop() noexcept;

 private:
  std::vector<std::string> bodies_;
  std::vector<ServerLaunchOptions> options_;
  std::vector<std::unique_ptr<SubdomainServer>> servers_;
};

/// The last `count` lines of a text file ("" when it cannot be read), for error messages.
std::string last_lines(const std::filesystem::path& path, int count);

}  // namespace robin
