#pragma once
// The server's logger: spdlog logger "subdomain", writing to stderr with timestamps
// (stdout carries only the "listening on" line).

#include <spdlog/spdlog.h>
#include <memory>

namespace robin {

/// The "subdomain" logger, created (stderr, pattern with date and milliseconds) on first use.
std::shared_ptr<spdlog::logger> subdomain_logger();

}  // namespace robin
