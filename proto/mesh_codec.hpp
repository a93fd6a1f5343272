#pragma once
// MeshData (proto/robin.proto) to and from the numerics' Mesh: how a mesh travels as data.
// The decoder is the server's gate for meshes from the wire: it checks every size against the
// message before it allocates, every index and value, and every element's validity.

#include <string>

#include "numerics/mesh.hpp"
#include "robin.pb.h"

namespace robin {

/// The protocol's cell type of a boundary facet (LINE2 ... QUADRILATERAL4).
protocol::CellType to_protocol(FacetType type);

/// The mesh as MeshData: its dimension (2 or 3), `dimension` coordinates per node, node and
/// element tags, element blocks and named boundaries, `mesh.source` as the source.
protocol::MeshData encode_mesh(const Mesh& mesh);

/// The Mesh of `data`. Throws InputError "<context>: SetupBody.mesh.<field> ..." naming the
/// field, the block or boundary and the mesh's source for: a dimension other than 2 or 3; a
/// coordinate count that is not a multiple of the dimension, no node, or a non-finite
/// coordinate; tags of the wrong count; an unknown cell type or one of the other dimension (2D:
/// triangles and quadrilaterals bounded by lines; 3D: tetrahedra and hexahedra bounded by
/// triangles and quadrilaterals); a connectivity length that is not a
/// multiple of the nodes per cell; a node index out of range; a node that no cell uses; a
/// boundary name that is empty, longer than 64 characters, not [A-Za-z0-9_.-]+ or repeated;
/// and (check_element_validity) an inverted, folded or degenerate element, named by its tag.
Mesh decode_mesh(const protocol::MeshData& data, const std::string& context);

}  // namespace robin
