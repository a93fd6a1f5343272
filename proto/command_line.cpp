#include "command_line.hpp"

#include "protocol_version.hpp"
#include "robin_version.hpp"

namespace robin {

std::string version_text(const std::string& tool) {
  return tool + " " + product_version + " (protocol " + std::to_string(protocol::protocol_major) +
         "." + std::to_string(protocol::protocol_minor) + ")";
}

void add_version_option(CLI::App& app, const std::string& tool) {
  app.set_version_flag("--version", version_text(tool),
                       "print the product and protocol versions and exit");
}

std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv) {
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 2;
  }
}

}  // namespace robin
