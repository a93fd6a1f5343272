#pragma once
// The command-line conventions every robin-contact tool follows: --help and --version print to
// standard output and exit 0; a bad command line prints CLI11's message and exits 2.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace robin {

/// "TOOL VERSION (protocol MAJOR.MINOR)": the product version (the file VERSION) and the
/// protocol version this build speaks (protocol_version.hpp).
std::string version_text(const std::string& tool);

/// Adds --version to `app`: prints version_text(tool) and exits 0 (through parse_command_line).
void add_version_option(CLI::App& app, const std::string& tool);

/// Parses the command line; nullopt to go on, otherwise the exit code: 0 after --help or
/// --version, 2 for a bad command line (the message printed).
std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv);

}  // namespace robin
