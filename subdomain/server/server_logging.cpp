#include "server/server_logging.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace robin {

std::shared_ptr<spdlog::logger> subdomain_logger() {
  if (auto existing = spdlog::get("subdomain")) return existing;
  auto logger = spdlog::stderr_color_mt("subdomain");
  logger->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  return logger;
}

std::string printable_for_log(std::string_view text, std::size_t maximum) {
  std::string line(text.substr(0, maximum));
  for (char& c : line) {
    const auto code = static_cast<unsigned char>(c);
    if (code < 0x20 || code == 0x7f) c = '?';
  }
  if (text.size() > maximum) {
    line += "... (" + std::to_string(text.size() - maximum) + " more characters)";
  }
  return line;
}

}  // namespace robin
