#pragma once
// The server's logger: spdlog logger "subdomain", writing to stderr with timestamps
// (stdout carries only the "listening on" line).

#include <spdlog/spdlog.h>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace robin {

/// The "subdomain" logger, created (stderr, pattern with date and milliseconds) on first use.
std::shared_ptr<spdlog::logger> subdomain_logger();

/// `text` made safe for one log line: control characters (a newline could forge a log line)
/// become '?', and text beyond `maximum` characters is cut, saying how much was left out.
/// Requests are untrusted: body names, run ids and paths reach the log through messages.
std::string printable_for_log(std::string_view text, std::size_t maximum = 1000);

}  // namespace robin
