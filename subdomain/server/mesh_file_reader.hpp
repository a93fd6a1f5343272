#pragma once
// The server's reader of SetupBody.mesh_path .geo files: robin-mesh-reader (mesh_reader_main.cpp),
// run in a child process, meshes the script with Gmsh and sends the mesh back through a pipe,
// so that a script Gmsh crashes on costs a BAD_INPUT, not the server, Gmsh's memory stays out of
// the server (capped by RLIMIT_AS in the child), and robin-subdomain does not link libgmsh,
// whose dependencies (OpenCASCADE, FLTK, X11: about 120 shared libraries, all bound at load
// time) cost every process that links it about 0.15 s of start-up. A mesh_path .msh file is read
// in the server's own process by the native reader (msh_file.hpp), whose allocations are bounded
// by the file's size; the child still reads one when given it (robin-mesh-reader FILE).

#include <filesystem>
#include <string>

#include "numerics/mesh.hpp"

namespace robin {

/// The mesh of `path` as read_gmsh_mesh reads it, read by the executable `reader`
/// (robin-mesh-reader) in a child process. Throws InputError with the reader's message when it
/// refuses the file, "the mesh reader (Gmsh) crashed on this file (signal N, ...): refused" when
/// the child dies, "the mesh reader ran out of the memory it is allowed for this file (...)"
/// when Gmsh asks for more than 256 MiB plus 32 times the file's size (mesh_reader_main.cpp),
/// and std::runtime_error when no child can be started or `reader` cannot be run.
Mesh read_mesh_file_in_child(const std::filesystem::path& path,
                             const std::filesystem::path& reader);

/// What robin-mesh-reader writes on its standard output for `mesh`: 'M' and the mesh in the
/// layout read_mesh_file_in_child decodes.
std::string mesh_reader_message(const Mesh& mesh);

/// What robin-mesh-reader writes on its standard output when it refuses the file: 'E' and the
/// reader's message.
std::string mesh_reader_error_message(const std::string& error);

}  // namespace robin
