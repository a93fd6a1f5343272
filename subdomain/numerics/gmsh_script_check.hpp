#pragma once
// The policy for Gmsh scripts (.geo) that arrive over the protocol. A .geo file is a program:
// Gmsh's script language can run shell commands (SystemCall), read other files (Include,
// Merge, ShapeFromFile) and write files (Printf > "file", Save, Print). A subdomain server that
// meshed any script a client sends would run any command as its user (docs/security.md). A
// script from the wire is therefore meshed only when it uses none of the host-touching
// commands below; geometry, meshing options, variables, loops, macros and physical groups stay
// available, which is everything a mesh needs.
//
// The refused commands (Gmsh 4.11 script keywords that reach the host, the process or the
// user): SystemCall, NonBlockingSystemCall, System, NonBlockingSystem, OnelabRun, OnelabAction,
// Include, Merge, MergeWithBoundingBox, ShapeFromFile, Printf, Print, Save, CreateDir, Exit,
// Abort, Sleep, SendToServer, Plugin, GetEnv, GetString, GetValue, GetNumber, SetString,
// AbsolutePath, FileExists. Keywords are matched as whole identifiers outside comments and
// string literals (case-sensitive, as Gmsh's lexer); a variable of one of these names is
// refused too.

#include <string>

namespace robin {

/// Throws InputError "<label> line L: the Gmsh command 'X' is refused ..." for the first
/// refused command of `script`; returns normally when there is none.
void check_gmsh_script_from_client(const std::string& script, const std::string& label);

}  // namespace robin
