#pragma once
// ParaView output: VTK XML unstructured grid (.vtu) and collection (.pvd) files.
//
// Format: VTKFile version 1.0, header_type UInt64, byte_order of the machine. By default every
// array is binary in the appended-data section (encoding "raw"), compressed in zlib's format
// (RFC 1950; Float64 arrays by zero_run_deflate.hpp, whose one pass keeps their zero runs at
// memory speed, the integer arrays by libdeflate's level 1) as vtkZLibDataCompressor writes it:
// per array, the UInt64 header [number of blocks, uncompressed block size (32768 bytes),
// uncompressed size of the last block (0 when it is full), compressed size of each block], then
// the zlib streams of the blocks. The arrays are made and compressed one at a time while the
// appended data is written (never the whole block in memory), and their offsets written
// afterwards into room left in the XML: `offset="N"` is followed by spaces up to a fixed width
// before the element's `/>`. VtuEncoding::ascii writes every array inline as text instead, each
// real number as the shortest decimal that reads back to the same double. Either way the values
// read back are the doubles given here, bit for bit.
//
// Points are Float64 (x, y, z; z = 0 for plane bodies). Cells are, in this order:
//  - the elements, block after block of mesh.blocks, with VTK types
//      triangle3      -> VTK_TRIANGLE (5)
//      triangle6      -> VTK_QUADRATIC_TRIANGLE (22)  (Gmsh order: corners, then the midpoints
//                        of edges 01, 12, 20, which is VTK's order)
//      quadrilateral4 -> VTK_QUAD (9)                  (counter-clockwise, as VTK)
//      tetrahedron4   -> VTK_TETRA (10)
//      tetrahedron10  -> VTK_QUADRATIC_TETRA (24)     (Gmsh's midside nodes 8 (edge 3-2) and 9
//                        (edge 3-1) are written swapped: VTK's 8 is on edge 1-3, 9 on 2-3)
//      hexahedron8    -> VTK_HEXAHEDRON (12)           (Gmsh order is VTK's)
//  - with VtuOptions::boundary_cells, the facets of every named boundary of mesh.boundaries
//    (in name order): edges as VTK_LINE (3) or VTK_QUADRATIC_EDGE (21) (Gmsh line3 order: the
//    two endpoints, then the midpoint, which is VTK's order), faces as VTK_TRIANGLE,
//    VTK_QUADRATIC_TRIANGLE or VTK_QUAD. A facet in two boundaries is written twice.
// The cells' connectivity and offsets are Int32 when the connectivity has at most 2^31 - 1
// entries, else Int64; their types UInt8.
// The writer adds the cell field "boundary_id" (Int32): 0 on area elements, k on the edges of
// the k-th boundary (k = 1, 2, ... in name order), and, when there are boundary cells, the
// field-data string array "boundary_names" whose entry k - 1 is the name of boundary k.
// Cell fields are given per element; on a boundary facet each cell field holds the values of the
// element that has that facet as a side (NaN when no element has it).
//
// A field of 2 components is written with 3 components, the third zero, so that ParaView
// treats it as a vector (Warp By Vector, Glyph); all other component counts are written as is
// (6 components with the names XX, YY, ZZ, XY, YZ, XZ are ParaView's symmetric tensor).

#include <Eigen/Core>
#include <filesystem>
#include <functional>
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
  /// Optional names of the components (ParaView ComponentName attributes), e.g. "XX", "YY",
  /// "ZZ", "XY", "YZ", "XZ"; empty for none, otherwise at most `components` entries.
  std::vector<std::string> component_names = {};
};

/// A field whose values are made when the writer comes to it, so that only one field's values
/// are in memory at a time.
struct FieldSource {
  std::string name;
  int components = 1;
  /// As OutputField::component_names.
  std::vector<std::string> component_names = {};
  /// Appends `components` values per node (or per element), node-major, to `values`: empty, with
  /// room reserved for the array as written (so that appending does not reallocate).
  std::function<void(std::vector<double>& values)> append_values;
};

/// How the arrays of a .vtu are stored.
enum class VtuEncoding {
  binary_zlib,  // appended raw binary, zlib-compressed blocks (the default)
  ascii,        // inline decimal text, for reading by eye
};

struct VtuOptions {
  VtuEncoding encoding = VtuEncoding::binary_zlib;
  /// Write the facets of mesh.boundaries as cells (with boundary_id and boundary_names).
  bool boundary_cells = true;
};

/// The VTK cell type number of an element type (5, 22, 9, 10, 24 or 12).
int vtk_cell_type(ElementType type);

/// The VTK cell type number of a facet type (3, 21, 5, 22 or 9).
int vtk_cell_type(FacetType type);

/// Writes the mesh with point and cell fields as described above. Cell fields follow the element
/// order of mesh.blocks (one value set per element). The parent directory must
/// exist. Throws std::runtime_error naming the path when it cannot be written, and naming the
/// path and the field when a field is malformed (empty name, components < 1,
/// values.size() != components * count) or a connectivity entry is out of range.
void write_vtu(const std::filesystem::path& path, const Mesh& mesh,
               const std::vector<OutputField>& point_fields,
               const std::vector<OutputField>& cell_fields, const VtuOptions& options = {});

/// write_vtu with fields made one at a time: each source's append_values is called once, when
/// its array is written (binary: after the XML, in the order of the arrays in the file; point
/// fields before cell fields). The file is the one write_vtu writes of OutputFields holding the
/// same values. A source with a malformed name or component count is reported before the file
/// is opened, one with the wrong number of values when it is written, as write_vtu reports them;
/// an exception from append_values propagates. Either way the file is then left unfinished (the
/// caller removes it).
void write_streamed_vtu(const std::filesystem::path& path, const Mesh& mesh,
                        const std::vector<FieldSource>& point_fields,
                        const std::vector<FieldSource>& cell_fields,
                        const VtuOptions& options = {});

/// Writes a .pvd collection referencing `datasets` (paths relative to the .pvd), one part each
/// (part = index, timestep 0). Throws std::runtime_error naming the path when it cannot be
/// written.
void write_pvd(const std::filesystem::path& path, const std::vector<std::string>& datasets);

}  // namespace robin
