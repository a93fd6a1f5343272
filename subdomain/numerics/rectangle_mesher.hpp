#pragma once
// A tiny structured mesher for unit tests only (users make meshes with Gmsh).

#include "numerics/mesh.hpp"

namespace robin {

/// Structured mesh of [x0, x1] x [y0, y1] with nx by ny cells, each cell a
/// quadrilateral4 or split into two triangle3 (or two triangle6, whose boundaries are then
/// line3). Boundaries are named "left", "right", "bottom" and "top"; node tags are index + 1.
Mesh make_rectangle_mesh(double x0, double y0, double x1, double y1, int nx, int ny,
                         ElementType type);

}  // namespace robin
