#include "numerics/rectangle_mesher.hpp"

#include <stdexcept>

namespace robin {

namespace {

/// Grid of (columns x rows) nodes, row-major from the bottom-left corner. Quadratic
/// triangles use a grid twice as fine so that edge midpoints are grid nodes.
struct Grid {
  int columns;
  int rows;
  int node(int column, int row) const { return row * columns + column; }
};

void add_cell(ElementBlock& block, const Grid& grid, int i, int j) {
  if (block.type == ElementType::quadrilateral4) {
    block.connectivity.insert(
        block.connectivity.end(),
        {grid.node(i, j), grid.node(i + 1, j), grid.node(i + 1, j + 1), grid.node(i, j + 1)});
  } else if (block.type == ElementType::triangle3) {
    // Split along the diagonal from (i, j) to (i + 1, j + 1).
    block.connectivity.insert(block.connectivity.end(),
                              {grid.node(i, j), grid.node(i + 1, j), grid.node(i + 1, j + 1),
                               grid.node(i, j), grid.node(i + 1, j + 1), grid.node(i, j + 1)});
  } else {
    const int c = 2 * i;
    const int r = 2 * j;
    block.connectivity.insert(
        block.connectivity.end(),
        {grid.node(c, r), grid.node(c + 2, r), grid.node(c + 2, r + 2), grid.node(c + 1, r),
         grid.node(c + 2, r + 1), grid.node(c + 1, r + 1), grid.node(c, r), grid.node(c + 2, r + 2),
         grid.node(c, r + 2), grid.node(c + 1, r + 1), grid.node(c + 1, r + 2),
         grid.node(c, r + 1)});
  }
}

/// Boundary edges along a line of grid nodes, from `first` to the node `count * step`
/// grid steps further in the direction (column_step, row_step).
BoundaryGroup make_side(const Grid& grid, int step, int column, int row, int column_step,
                        int row_step, int count) {
  BoundaryGroup group;
  group.type = step == 2 ? FacetType::line3 : FacetType::line2;
  for (int k = 0; k < count; ++k) {
    const int c = column + k * step * column_step;
    const int r = row + k * step * row_step;
    const int start = grid.node(c, r);
    const int end = grid.node(c + step * column_step, r + step * row_step);
    group.connectivity.insert(group.connectivity.end(), {start, end});
    if (step == 2) group.connectivity.push_back(grid.node(c + column_step, r + row_step));
  }
  return group;
}

}  // namespace

Mesh make_rectangle_mesh(double x0, double y0, double x1, double y1, int nx, int ny,
                         ElementType type) {
  if (nx < 1 || ny < 1 || !(x1 > x0) || !(y1 > y0)) {
    throw std::invalid_argument("make_rectangle_mesh: need x1 > x0, y1 > y0, nx >= 1, ny >= 1");
  }
  const int step = type == ElementType::triangle6 ? 2 : 1;
  const Grid grid{step * nx + 1, step * ny + 1};
  Mesh mesh;
  for (int row = 0; row < grid.rows; ++row) {
    for (int column = 0; column < grid.columns; ++column) {
      mesh.nodes.emplace_back(x0 + (x1 - x0) * column / (grid.columns - 1),
                              y0 + (y1 - y0) * row / (grid.rows - 1), 0.0);
      mesh.node_tags.push_back(mesh.nodes.size());
    }
  }
  ElementBlock block;
  block.type = type;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) add_cell(block, grid, i, j);
  }
  mesh.blocks.push_back(std::move(block));
  const int right = grid.columns - 1;
  const int top = grid.rows - 1;
  mesh.boundaries["bottom"] = make_side(grid, step, 0, 0, 1, 0, nx);
  mesh.boundaries["right"] = make_side(grid, step, right, 0, 0, 1, ny);
  mesh.boundaries["top"] = make_side(grid, step, right, top, -1, 0, nx);
  mesh.boundaries["left"] = make_side(grid, step, 0, top, 0, -1, ny);
  return mesh;
}

}  // namespace robin
