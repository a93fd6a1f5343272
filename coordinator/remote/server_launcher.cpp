#include "remote/server_launcher.hpp"

#include <deque>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <vector>

#include "remote/remote_port.hpp"

namespace robin {

namespace {

const std::string listening_prefix = "listening on ";

std::string format_seconds(double seconds) {
  std::ostringstream text;
  text << seconds;
  return text.str();
}

std::string log_excerpt(const std::filesystem::path& log_file) {
  const std::string tail = last_lines(log_file, 5);
  std::string text = "; its log is " + log_file.string();
  if (!tail.empty()) text += ", ending with:\n" + tail;
  return text;
}

}  // namespace

std::filesystem::path sibling_executable(const std::string& name) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) throw std::runtime_error("cannot find the running executable: " + error.message());
  return self.parent_path() / name;
}

std::string last_lines(const std::filesystem::path& path, int count) {
  std::ifstream file(path);
  std::deque<std::string> lines;
  for (std::string line; std::getline(file, line);) {
    lines.push_back(line);
    if (static_cast<int>(lines.size()) > count) lines.pop_front();
  }
  std::string text;
  for (const std::string& line : lines) text += (text.empty() ? "" : "\n") + line;
  return text;
}

SubdomainServer::SubdomainServer(const std::string& body, const ServerLaunchOptions& options)
    : body_(body), options_(options) {
  std::filesystem::create_directories(options.log_directory);
  log_file_ = options.log_directory / ("server-" + body + ".log");
  ChildProcessOptions child;
  child.executable = options.executable;
  child.arguments = {"--listen", options.listen, "--name", body, "--log-level", options.log_level};
  child.arguments.insert(child.arguments.end(), options.extra_arguments.begin(),
                         options.extra_arguments.end());
  child.log_file = log_file_;
  child.command_prefix = options.command_prefix;
  child.environment = options.environment;
  try {
    process_ = std::make_unique<ChildProcess>(child);
  } catch (const std::exception& error) {
    throw std::runtime_error("cannot start the server for body '" + body + "': " + error.what());
  }
}

SubdomainServer::~SubdomainServer() {
  request_shutdown();
  finish_stop();
}

std::string SubdomainServer::label() const {
  return options_.executable.filename().string() + " for body '" + body_ + "' (pid " +
         std::to_string(process_->pid()) + ")";
}

void SubdomainServer::await_listening(const std::function<void()>& on_wait) {
  const auto deadline = ChildProcess::Clock::now() +
                        std::chrono::duration_cast<ChildProcess::Clock::duration>(
                            std::chrono::duration<double>(options_.startup_timeout_seconds));
  std::optional<std::string> line;
  try {
    line = process_->read_line(deadline, on_wait);
  } catch (const ChildTimeout&) {
    throw std::runtime_error(label() + " did not report 'listening on' within " +
                             format_seconds(options_.startup_timeout_seconds) + " s" +
                             log_excerpt(log_file_));
  }
  if (!line) {
    process_->wait_for_exit(1.0);
    const std::string exit = process_->exit_description();
    throw std::runtime_error(label() + " stopped before listening" +
                             (exit.empty() ? "" : " (it " + exit + ")") + log_excerpt(log_file_));
  }
  if (line->rfind(listening_prefix, 0) != 0) {
    throw std::runtime_error(label() + " printed '" + *line + "' instead of 'listening on " +
                             "ENDPOINT'" + log_excerpt(log_file_));
  }
  endpoint_ = line->substr(listening_prefix.size());
}

std::string SubdomainServer::failure() {
  const std::string exit = process_->exit_description();
  if (exit.empty()) return "";
  return label() + " " + exit + log_excerpt(log_file_);
}

void SubdomainServer::request_shutdown() noexcept {
  if (stopping_) return;
  stopping_ = true;
  if (!endpoint_.empty() && process_->running()) {
    shutdown_acknowledged_ = request_server_shutdown(endpoint_, options_.shutdown_timeout_seconds,
                                                     options_.curve_client);
  }
}

void SubdomainServer::finish_stop() noexcept {
  if (shutdown_acknowledged_ && process_->wait_for_exit(options_.grace_seconds)) return;
  process_->stop(options_.grace_seconds);
}

LocalServers::LocalServers(const std::vector<std::string>& bodies,
                           const ServerLaunchOptions& options)
    : LocalServers(bodies, std::vector<ServerLaunchOptions>(bodies.size(), options)) {}

LocalServers::LocalServers(const std::vector<std::string>& bodies,
                           const std::vector<ServerLaunchOptions>& options)
    : bodies_(bodies), options_(options) {
  if (options.size() != bodies.size()) {
    throw std::invalid_argument("LocalServers: one set of launch options per body");
  }
  for (std::size_t index = 0; index < bodies.size(); ++index) {
    servers_.push_back(std::make_unique<SubdomainServer>(bodies[index], options[index]));
  }
}

LocalServers::~LocalServers() {
  stop();
}

void LocalServers::await_listening(const std::function<void()>& on_wait) {
  for (auto& server : servers_) server->await_listening(on_wait);
}

void LocalServers::restart(int index, const std::function<void()>& on_wait) {
  const auto body = static_cast<std::size_t>(index);
  servers_.at(body).reset();  // reaps the exited server (or stops one that still runs)
  servers_[body] = std::make_unique<SubdomainServer>(bodies_[body], options_[body]);
  servers_[body]->await_listening(on_wait);
}

std::vector<std::string> LocalServers::endpoints() const {
  std::vector<std::string> endpoints;
  for (const auto& server : servers_) endpoints.push_back(server->endpoint());
  return endpoints;
}

void LocalServers::stop() noexcept {
  // Every Shutdown request at once: a server busy with a long setup answers none, and its
  // deadline should not be waited for once per server.
  std::vector<std::thread> requests;
  for (auto& server : servers_) {
    if (!server) continue;
    try {
      requests.emplace_back([&server] { server->request_shutdown(); });
    } catch (const std::system_error&) {  // no thread to spare: ask in this one
      server->request_shutdown();
    }
  }
  for (std::thread& request : requests) request.join();
  for (auto& server : servers_) {
    if (server) server->finish_stop();
  }
}

}  // namespace robin
