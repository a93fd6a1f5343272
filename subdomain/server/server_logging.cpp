#include "server/server_logging.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace robin {

std::shared_ptr<spdlog::logger> subdomain_logger() {
  if (auto existing = spdlog::get("subdomain")) return existing;
  auto logger = spdlog::stderr_color_mt("subdomain");
  logger->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  return logger;
}

}  // namespace robin
