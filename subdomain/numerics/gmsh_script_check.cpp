#include "numerics/gmsh_script_check.hpp"

#include <array>
#include <cctype>
#include <string_view>

#include "numerics/errors.hpp"

namespace robin {
namespace {

constexpr std::array<std::string_view, 26> refused_commands{"SystemCall",
                                                            "NonBlockingSystemCall",
                                                            "System",
                                                            "NonBlockingSystem",
                                                            "OnelabRun",
                                                            "OnelabAction",
                                                            "Include",
                                                            "Merge",
                                                            "MergeWithBoundingBox",
                                                            "ShapeFromFile",
                                                            "Printf",
                                                            "Print",
                                                            "Save",
                                                            "CreateDir",
                                                            "Exit",
                                                            "Abort",
                                                            "Sleep",
                                                            "SendToServer",
                                                            "Plugin",
                                                            "GetEnv",
                                                            "GetString",
                                                            "GetValue",
                                                            "GetNumber",
                                                            "SetString",
                                                            "AbsolutePath",
                                                            "FileExists"};

bool is_refused(std::string_view identifier) {
  for (const std::string_view command : refused_commands) {
    if (identifier == command) return true;
  }
  return false;
}

bool starts_identifier(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_';
}

bool continues_identifier(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}

/// Index just past the comment or string literal that starts at `position`, or `position`
/// when none starts there. Counts the newlines it skips into `line`.
std::size_t skip_comment_or_string(const std::string& script, std::size_t position, int& line) {
  const auto skip_to = [&](std::size_t end) {
    for (std::size_t k = position; k < end && k < script.size(); ++k) line += script[k] == '\n';
    return std::min(end, script.size());
  };
  if (script.compare(position, 2, "//") == 0) return skip_to(script.find('\n', position));
  if (script.compare(position, 2, "/*") == 0) {
    const std::size_t end = script.find("*/", position + 2);
    return skip_to(end == std::string::npos ? script.size() : end + 2);
  }
  if (script[position] == '"') {
    std::size_t end = position + 1;
    while (end < script.size() && script[end] != '"') end += script[end] == '\\' ? 2 : 1;
    return skip_to(end + 1);
  }
  return position;
}

}  // namespace

void check_gmsh_script_from_client(const std::string& script, const std::string& label) {
  int line = 1;
  std::size_t position = 0;
  while (position < script.size()) {
    if (const std::size_t next = skip_comment_or_string(script, position, line); next != position) {
      position = next;
    } else if (starts_identifier(script[position])) {
      std::size_t end = position;
      while (end < script.size() && continues_identifier(script[end])) ++end;
      const std::string_view identifier(script.data() + position, end - position);
      if (is_refused(identifier)) {
        throw InputError(label + " line " + std::to_string(line) + ": the Gmsh command '" +
                         std::string(identifier) +
                         "' is refused in a script sent to a server (it can run commands, "
                         "read or write files on the server's host; docs/security.md): mesh "
                         "the body with gmsh and send the .msh, or remove the command");
      }
      position = end;
    } else {
      line += script[position] == '\n';
      ++position;
    }
  }
}

}  // namespace robin
