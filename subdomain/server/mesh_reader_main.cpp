// robin-mesh-reader FILE: robin-subdomain's reader of SetupBody.mesh_path files
// (mesh_file_reader.hpp), not a tool of its own. Reads FILE with read_gmsh_mesh and writes one
// message on its standard output: mesh_reader_message (the mesh) or mesh_reader_error_message
// (why the file is refused). Exit codes: 0 after writing the message (and after --help and
// --version); 2 for a bad command line or when the message cannot be written; a file Gmsh
// crashes on ends the process by its signal.
// Only the server runs it, on a file it has already checked (under its --data-directory, at
// most --max-mesh-file-size bytes).

#include <unistd.h>

#include <cerrno>
#include <exception>
#include <string>

#include "command_line.hpp"
#include "numerics/gmsh_reader.hpp"
#include "server/mesh_file_reader.hpp"

namespace {

/// The message for the file at `path` (a refusal when read_gmsh_mesh throws).
std::string message_for(const std::string& path) {
  try {
    return robin::mesh_reader_message(robin::read_gmsh_mesh(path));
  } catch (const std::exception& error) {
    return robin::mesh_reader_error_message(error.what());
  } catch (...) {
    return robin::mesh_reader_error_message("the mesh reader failed");
  }
}

/// Writes all of `message` to the standard output; false when it cannot.
bool write_all(const std::string& message) {
  for (std::size_t written = 0; written < message.size();) {
    const ssize_t count = write(STDOUT_FILENO, message.data() + written, message.size() - written);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) return false;
    written += static_cast<std::size_t>(count);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "robin-mesh-reader: reads a mesh file with Gmsh for robin-subdomain (SetupBody.mesh_path) "
      "and writes it on standard output; run by the server, not by hand"};
  std::string file;
  app.add_option("file", file, "the mesh file (.msh or .geo)")->required();
  robin::add_version_option(app, "robin-mesh-reader");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  return write_all(message_for(file)) ? 0 : 2;
}
