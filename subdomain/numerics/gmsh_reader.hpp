#pragma once
// Reads meshes through the Gmsh C++ API. Supported inputs:
//  - .msh (format 4.1 and 2.2): read as is;
//  - .geo: meshed on the fly in 2D. When `size` > 0 the Gmsh variable `h` is set
//    to it before the script is parsed (like `gmsh -setnumber h SIZE`); a .geo
//    declares `DefineConstant[ h = 0.1 ];` to use it.
// Area elements of every 2D physical group are read (triangles, quadratic
// triangles, quadrilaterals); every 1D physical group becomes a named boundary.
// Node coordinates must lie in the z = 0 plane.

#include <filesystem>
#include <stdexcept>
#include <string>

#include "numerics/mesh.hpp"

namespace robin {

struct MeshReadOptions {
  double size = 0.0;       // value of the .geo variable `h`; 0 leaves the script's default
  int element_order = 1;   // 1 or 2: order of elements generated from a .geo
  bool recombine = false;  // generate quadrilaterals from a .geo (Mesh.RecombineAll)
};

/// Reads `path`. Throws InputError naming the file on any problem (missing file,
/// parse error, no 2D elements, unsupported element type, no physical groups).
Mesh read_gmsh_mesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

/// The process's temporary directory cannot hold the mesh file of
/// read_gmsh_mesh_from_text: a fault of the environment (TMPDIR, else /tmp, missing,
/// not writable or full), not of the mesh. The message starts with the label and names
/// the directory.
class TemporaryDirectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a mesh given as the text of a file with extension `extension` (".msh" or
/// ".geo"); used when a mesh travels inside a protocol message. The text is written to
/// a file of the temporary directory (TMPDIR, else /tmp) for Gmsh and removed after.
/// `label` names the source in error messages. Throws InputError for a bad extension
/// or mesh, TemporaryDirectoryError when the file cannot be written.
Mesh read_gmsh_mesh_from_text(const std::string& content, const std::string& extension,
                              const std::string& label, const MeshReadOptions& options = {});

}  // namespace robin
