#pragma once
// ParaView output: VTK XML unstructured grid (.vtu, ASCII) and collection (.pvd) files.

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
};

/// Writes the mesh (z = 0) with point and cell fields. Cell fields follow the element order
/// of mesh.blocks. Throws std::runtime_error naming the path when it cannot be written.
void write_vtu(const std::filesystem::path& path, const Mesh& mesh,
               const std::vector<OutputField>& point_fields,
               const std::vector<OutputField>& cell_fields);

/// Writes a .pvd collection referencing `datasets` (paths relative to the .pvd), one part each.
void write_pvd(const std::filesystem::path& path, const std::vector<std::string>& datasets);

}  // namespace robin
