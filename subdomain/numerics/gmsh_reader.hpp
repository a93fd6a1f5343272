#pragma once
// Reads Gmsh meshes. Supported inputs:
//  - .msh (format 4.1 and 2.2, ASCII or binary): read as is by read_msh_file (msh_file.hpp),
//    without Gmsh;
//  - .geo: meshed on the fly in its dimension by Gmsh under robin-mesh-reader, in a child
//    process (the tools do not link libgmsh), which writes a binary MSH 4.1 file read_msh_file
//    reads.
//    When `size` > 0 the Gmsh variable `h` is set to it before the script is parsed (like
//    `gmsh -setnumber h SIZE`); a .geo declares `DefineConstant[ h = 0.1 ];` to use it.
// A model with a volume is a solid body (Mesh::dimension 3): the elements of every 3D physical
// group are read (4- and 10-node tetrahedra, 8-node hexahedra) and every 2D physical group
// becomes a named boundary of faces (3- and 6-node triangles, 4-node quadrilaterals). A model
// without volumes is a plane body (dimension 2): the elements of every 2D physical group
// (triangles, quadratic triangles, quadrilaterals), every 1D physical group a named boundary of
// lines, and every node in the z = 0 plane. Elements are oriented positively (counter-clockwise
// in 2D, a positive Jacobian in 3D).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

struct MeshReadOptions {
  double size = 0.0;       // value of the .geo variable `h`; 0 leaves the script's default
  int element_order = 1;   // 1 or 2: order of elements generated from a .geo
  bool recombine = false;  // generate quadrilaterals from a .geo (Mesh.RecombineAll)
};

/// Reads `path`. Throws InputError naming the file on any problem (missing file,
/// parse error, no elements of the body's dimension, unsupported element type, no physical
/// groups).
Mesh read_gmsh_mesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

/// One mesh file to read, with its .geo options.
struct MeshFileRequest {
  std::filesystem::path path;
  MeshReadOptions options;
};

/// Told as read_gmsh_meshes goes, with the index of the request: when its meshing (a .geo) or
/// reading (a .msh) begins, and when its mesh has been read, with the seconds since it began.
/// Called on the calling thread; empty members are not called.
struct MeshReadObserver {
  std::function<void(std::size_t request)> started;
  std::function<void(std::size_t request, const Mesh& mesh, double seconds)> finished;
  /// Called about once a second while meshing children are still running.
  std::function<void()> waiting;
};

/// Receives the mesh of request `request` as soon as it is read (read_gmsh_meshes).
using MeshReceiver = std::function<void(std::size_t request, Mesh&& mesh)>;

/// Reads several mesh files at once, each as read_gmsh_mesh reads it, and hands each mesh to
/// `receive` as soon as it is read, on the calling thread, after observer.finished. The .geo
/// files are meshed by one robin-mesh-reader process (mesh_reader_executable, --mesh-geo-batch),
/// which loads libgmsh once and meshes each file in a child process of its own, all
/// concurrently; a child writes its mesh as binary MSH 4.1 into a private temporary directory,
/// which this process reads as soon as that child has ended (in the order they end). The .msh
/// files are read after the .geo files are meshed, on concurrent threads (at most one per
/// processor), and handed over in request order. Only the user's own files belong here: a .geo
/// is a program. Throws InputError naming the file for the first request that fails (in the
/// order the failures are seen), after every child has ended; an InputError thrown by `receive`
/// counts as that request's failure. No mesh is handed over after a failure.
void read_gmsh_meshes(const std::vector<MeshFileRequest>& requests, const MeshReceiver& receive,
                      const MeshReadObserver& observer = {});

/// read_gmsh_meshes, the meshes returned in request order.
std::vector<Mesh> read_gmsh_meshes(const std::vector<MeshFileRequest>& requests,
                                   const MeshReadObserver& observer = {});

/// The robin-mesh-reader that meshes .geo files: the one next to the running executable (the
/// tools are installed together), else the one of the build tree (tests and benchmarks).
std::filesystem::path mesh_reader_executable();

/// How a .geo script refers to a variable, read from its text (comments and strings skipped).
enum class GeoVariableUse {
  used,           // the identifier occurs in the script
  unused,         // it does not, and the script includes no other file
  indeterminate,  // it does not, but the script includes other files (Include "...")
};

/// Whether the .geo script `path` mentions the variable `name` (e.g. "h", which MeshReadOptions
/// sets: a script that never mentions it ignores the size). Throws InputError naming the file
/// when it cannot be read.
GeoVariableUse geo_variable_use(const std::filesystem::path& path, const std::string& name);

}  // namespace robin
