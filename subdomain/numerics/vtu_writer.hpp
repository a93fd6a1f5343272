#pragma once
// ParaView output: VTK XML unstructured grid (.vtu, ASCII) and collection (.pvd) files.
//
// Format: VTKFile version 1.0, ASCII. Points are Float64 with z = 0; every real number is
// written as the shortest decimal that reads back to the same double (at most max_digits10
// significant digits), so values round-trip exactly. Cells follow the element order of
// mesh.blocks with VTK types
//   triangle3      -> VTK_TRIANGLE (5)
//   triangle6      -> VTK_QUADRATIC_TRIANGLE (22)  (Gmsh order: corners, then the midpoints
//                     of edges 01, 12, 20, which is VTK's order)
//   quadrilateral4 -> VTK_QUAD (9)                  (counter-clockwise, as VTK)
//
// A field of 2 components is written with 3 components, the third zero, so that ParaView
// treats it as a vector (Warp By Vector, Glyph); all other component counts are written as is.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

/// A field with `components` values per node (or per element), stored node-major:
/// values[k * components + c].
struct OutputField {
  std::string name;
  int components = 1;
  std::vector<double> values;
  /// Optional names of the components (ParaView ComponentName attributes), e.g. "xx", "yy",
  /// "xy"; empty for none, otherwise at most `components` entries.
  std::vector<std::string> component_names = {};
};

/// The VTK cell type number of an element type (5, 22 or 9).
int vtk_cell_type(ElementType type);

/// Writes the mesh (z = 0) with point and cell fields. Cell fields follow the element order
/// of mesh.blocks. The parent directory must exist. Throws std::runtime_error naming the
/// path when it cannot be written, and naming the path and the field when a field is
/// malformed (empty name, components < 1, values.size() != components * count).
void write_vtu(const std::filesystem::path& path, const Mesh& mesh,
               const std::vector<OutputField>& point_fields,
               const std::vector<OutputField>& cell_fields);

/// Writes a .pvd collection referencing `datasets` (paths relative to the .pvd), one part each
/// (part = index, timestep 0). Throws std::runtime_error naming the path when it cannot be
/// written.
void write_pvd(const std::filesystem::path& path, const std::vector<std::string>& datasets);

}  // namespace robin
