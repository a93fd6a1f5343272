#pragma once
// A helper executable (robin-mesh-reader) run in a child process with its standard output on a
// pipe: the fork and everything between fork and exec, for read_gmsh_meshes (gmsh_reader.cpp,
// robin-mesh-reader --mesh-geo-batch) and read_mesh_file_in_child (server/mesh_file_reader.cpp).

#include <sys/types.h>

namespace robin {

/// The exit status of a child that could not run the helper (the shell's "cannot execute").
inline constexpr int cannot_execute_status = 126;

/// A started helper: its process id and the read end of its standard output (close-on-exec).
/// The caller reads the output, closes it and reaps the process.
struct HelperProcess {
  pid_t pid = -1;
  int output = -1;
};

/// Starts `argv` (argv[0] the executable's path, null-terminated, built before the call) in a
/// child process whose standard output is a pipe, with the default disposition of SIGSEGV,
/// SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGINT and SIGTERM and no signal blocked from the start, so
/// that no handler or mask of this process (a server's stop handler, a sanitizer's) acts in the
/// child, even before the exec; a crash or a stop signal ends the child by that signal. The
/// child exits with cannot_execute_status when the exec fails. Throws std::runtime_error with
/// `pipe_failure` when no pipe can be created and with `fork_failure` when fork fails.
HelperProcess start_helper_process(char* const* argv, const char* pipe_failure,
                                   const char* fork_failure);

}  // namespace robin
