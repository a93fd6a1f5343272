#pragma once
// A tiny structured mesher of boxes for tests only (users make meshes with Gmsh): the solid
// counterpart of rectangle_mesher.hpp.

#include "numerics/mesh.hpp"

namespace robin {

/// Structured mesh of [low, high] (a box) with cells.x() by cells.y() by cells.z() cells, each
/// cell a hexahedron8 or split into six tetrahedra (Kuhn's triangulation along the cell diagonal
/// from its lowest to its highest corner, conforming between cells), tetrahedron4 or
/// tetrahedron10 (edge midpoints added). Elements are positively oriented, in Gmsh's node order.
/// Boundaries of faces (quadrilateral4 for hexahedra, triangle3 or triangle6 for tetrahedra):
/// "left" (x = low.x), "right" (x = high.x), "front" (y = low.y), "back" (y = high.y),
/// "bottom" (z = low.z), "top" (z = high.z). Node tags are index + 1.
Mesh make_box_mesh(const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                   const Eigen::Vector3i& cells, ElementType type);

}  // namespace robin
