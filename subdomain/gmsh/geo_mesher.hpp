#pragma once
// Meshing a Gmsh .geo script with the Gmsh C++ API (libgmsh): the only code of the project that
// calls Gmsh. robin-mesh-reader runs it in a process of its own (mesh_reader_main.cpp), so that
// the tools do not link libgmsh (about 120 shared libraries bound at start-up) and a .geo
// script, which is a program, runs outside them.

#include <filesystem>

#include "numerics/gmsh_reader.hpp"

namespace robin {

/// Meshes the .geo script `geo` in its dimension (3 when it defines a volume, 2 otherwise) with
/// `options` (the variable h set before the script is parsed when options.size > 0, the element
/// order, recombination into quadrilaterals) and writes every element to `output` as binary
/// MSH 4.1, which read_msh_file reads into the body's mesh. Throws InputError naming the file
/// "mesh file 'GEO'" with Gmsh's errors when the script cannot be parsed, meshed or written.
void mesh_geo_file(const std::filesystem::path& geo, const MeshReadOptions& options,
                   const std::filesystem::path& output);

}  // namespace robin
