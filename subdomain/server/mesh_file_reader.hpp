#pragma once
// The server's reader of SetupBody.mesh_path files: Gmsh reads the file in a child process and
// sends the mesh back through a pipe, so that a file Gmsh crashes on costs a BAD_INPUT, not the
// server. Gmsh 4.8 dies of a segmentation fault on malformed MSH 2.2 files (found by
// tests/fuzz/mesh_file_fuzzer.cpp: a $Nodes section one node longer than its count); the
// files come from the operator's data directory, but one bad file must not stop the server
// for every client. The child also keeps Gmsh's memory out of the server, and caps what it may
// allocate (RLIMIT_AS): Gmsh reserves memory for the counts a file's header claims.

#include <filesystem>

#include "numerics/mesh.hpp"

namespace robin {

/// The mesh of `path` as read_gmsh_mesh reads it, in a child process. Throws InputError with
/// the reader's message when it refuses the file, "the mesh reader (Gmsh) crashed on this file
/// (signal N, ...): refused" when the child dies, "the mesh reader ran out of the memory it is
/// allowed for this file (...)" when an allocation fails beyond 256 MiB plus 32 times the file's
/// size, and std::runtime_error when no child can be started.
Mesh read_mesh_file_in_child(const std::filesystem::path& path);

}  // namespace robin
