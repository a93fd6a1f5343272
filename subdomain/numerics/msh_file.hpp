#pragma once
// Gmsh's MSH file format read without Gmsh: versions 2.2 and 4.1, ASCII and binary.
//
// Sections read: $MeshFormat, $PhysicalNames, $Entities (4.1: the physical tags of the points,
// curves, surfaces and volumes), $Nodes and $Elements; every other section ($Periodic,
// $NodeData, $PartitionedEntities, ...) is skipped up to its $End marker. Binary files must
// have been written on a little-endian machine (the endianness word 1 of $MeshFormat) with
// 8-byte sizes and reals (data-size 8).
//
// The mesh is the one Gmsh's API gives for the same file (read_gmsh_mesh's contract,
// gmsh_reader.hpp): a model with a volume entity is a solid body, otherwise a plane body whose
// nodes lie in z = 0; the body's elements are those of the physical groups of its dimension
// (every element of that dimension when there is none), each physical group of one dimension
// less is a named boundary (its tag when it has no name), nodes no element uses are left out,
// node indices follow ascending node tags and elements are oriented positively.
//
// The file is untrusted. Every count is checked against the bytes left in the file before
// anything is allocated for it: an item needs at least a fixed number of bytes (a node 8 in
// ASCII, 4 + 3 x 8 or 8 + 3 x 8 in binary), so a header claiming more items than the rest of the
// file can hold is refused at once, and what is allocated stays within a small multiple of the
// file's size. Every tag and index is checked. Errors are InputError messages
// "mesh file 'NAME' line L: ..." (ASCII) or "mesh file 'NAME' byte B: ..." (binary data), or
// "mesh file 'NAME': ..." for a problem of the mesh as a whole.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

/// The mesh in the MSH file `path`; messages name the file `name` (its path when empty).
/// Throws InputError when the file cannot be read or is refused.
Mesh read_msh_file(const std::filesystem::path& path, const std::string& name = "");

/// What the head of an MSH file, up to its $Nodes header, tells of the body in it: what a
/// coordinator checks of a body whose server reads the file itself.
struct MshSummary {
  /// 4.1: as read_msh_file decides (3 when there is a volume entity); 2.2: 3 when $PhysicalNames
  /// names a volume group.
  int dimension = 2;
  std::uint64_t node_count = 0;  // $Nodes' count (a 2.2 file may list nodes no element uses)
  /// The physical groups of one dimension less, as read_msh_file names its boundaries (by their
  /// names, or their tags when unnamed), except that a group without facets is listed too and a
  /// 2.2 file's unnamed groups are not (they show only in its elements).
  std::vector<std::string> boundary_names;
};

/// The summary of the MSH file `path` (messages name it `name`, its path when empty), read
/// without its nodes and elements; nullopt when its head cannot tell: a 2.2 file without
/// $PhysicalNames (its groups show only in its elements), a 4.1 file without physical groups, a
/// file without $Nodes. Throws InputError like read_msh_file for a malformed head.
std::optional<MshSummary> summarize_msh_file(const std::filesystem::path& path,
                                             const std::string& name = "");

/// The mesh in `bytes`, the contents of an MSH file called `name` in messages.
Mesh parse_msh_file(std::string_view bytes, const std::string& name);

/// Orients the elements of `block` (its connectivity indexes `mesh`'s nodes) positively
/// (counter-clockwise in 2D, a positive Jacobian in 3D), entity by entity: `entities` holds the
/// Gmsh entity (surface or volume tag) of each element. Gmsh meshes each surface or volume
/// consistently, so the sign of the entity's total signed measure gives its orientation, and a
/// negatively oriented entity has every element reversed. An element whose sign differs from
/// its entity's is inverted (a folded or tangled mesh) and refused, naming its tag: throws
/// InputError "NAME: element tag T (TYPE at node tag N) has zero area" (zero volume), or "...
/// is inverted against the other elements of surface E (a folded or tangled mesh)" (volume E).
/// Both the native reader and the tests' reference reader through Gmsh's API
/// (tests/unit/gmsh_api_reader.cpp) orient their elements with it.
void orient_elements_positively(const std::string& name, const Mesh& mesh, ElementBlock& block,
                                const std::vector<int>& entities);

}  // namespace robin
