#pragma once
// Gmsh's own C++ API as the independent reference of the native MSH reader (msh_file.hpp), for
// tests/unit/msh_file_test.cpp only (it links libgmsh).

#include <filesystem>
#include <vector>

#include "numerics/gmsh_reader.hpp"
#include "numerics/mesh.hpp"

namespace robin {

/// The mesh of the .msh file `path` as Gmsh's API reads it, by the extraction robin used before
/// the native reader. Throws InputError naming the file.
Mesh read_msh_with_gmsh_api(const std::filesystem::path& path);

/// One MSH file to write: its path, version (2.2 or 4.1), binary or ASCII, and whether every
/// element is written (Mesh.SaveAll) or only those of physical groups.
struct MshWriting {
  std::filesystem::path path;
  double version = 4.1;
  bool binary = false;
  bool save_all = false;
};

/// Meshes the .geo `geo` with Gmsh's API (h = options.size when > 0) and writes the mesh as each
/// of `writings` asks.
void write_msh_with_gmsh_api(const std::filesystem::path& geo, const MeshReadOptions& options,
                             const std::vector<MshWriting>& writings);

}  // namespace robin
