// The 3D face-to-face mortar integrals (coupling/face_mortar.hpp) against numbers known
// without the code: flat parallel surfaces at distance d with non-matching meshes of every
// face type (partition of unity, reproduction of linear fields, the gap d, the analytic overlap
// area of shifted and rotated squares and of a triangle against a square), matching meshes
// (node-to-node rows, D_jj = int phi_j), a tilted normal field (the change of variables from
// the auxiliary plane), a curved mortar surface (the integrated gap against its closed form,
// at the interpolation order), and normals pointing the same way (no rows).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <numbers>
#include <set>
#include <string>
#include <tuple>

#include "coupling/face_mortar.hpp"

namespace robin {
namespace {

using Map = std::function<Eigen::Vector3d(double, double)>;

/// A structured surface over the rectangle [low, high] of the (u, v) plane, nx x ny cells, each
/// a quadrilateral4, or two triangle3 or triangle6 faces (split along the diagonal from
/// (u_i, v_j) to (u_i+1, v_j+1)), placed in space by `position` with nodal normals `normal`.
/// The faces are counter-clockwise in (u, v), reversed when `reversed`.
MortarSurface grid(FacetType type, int nx, int ny, const Eigen::Vector2d& low,
                   const Eigen::Vector2d& high, const Map& position, const Map& normal,
                   bool reversed) {
  MortarSurface surface;
  surface.face_type = type;
  const int step = type == FacetType::triangle6 ? 2 : 1;  // node rows per cell
  const int columns = step * nx + 1, rows = step * ny + 1;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      const double u = low.x() + (high.x() - low.x()) * i / (columns - 1);
      const double v = low.y() + (high.y() - low.y()) * j / (rows - 1);
      surface.coordinates.push_back(position(u, v));
      surface.normals.push_back(normal(u, v).normalized());
    }
  }
  const auto node = [&](int i, int j) { return j * columns + i; };
  const auto add = [&](std::vector<int> face) {
    if (reversed) {
      if (type == FacetType::quadrilateral4) face = {face[0], face[3], face[2], face[1]};
      if (type == FacetType::triangle3) face = {face[0], face[2], face[1]};
      if (type == FacetType::triangle6) {
        face = {face[0], face[2], face[1], face[5], face[4], face[3]};
      }
    }
    surface.faces.insert(surface.faces.end(), face.begin(), face.end());
  };
  for (int cj = 0; cj < ny; ++cj) {
    for (int ci = 0; ci < nx; ++ci) {
      const int i = step * ci, j = step * cj;
      if (type == FacetType::quadrilateral4) {
        add({node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)});
      } else if (type == FacetType::triangle3) {
        add({node(i, j), node(i + 1, j), node(i + 1, j + 1)});
        add({node(i, j), node(i + 1, j + 1), node(i, j + 1)});
      } else {
        add({node(i, j), node(i + 2, j), node(i + 2, j + 2), node(i + 1, j), node(i + 2, j + 1),
             node(i + 1, j + 1)});
        add({node(i, j), node(i + 2, j + 2), node(i, j + 2), node(i + 1, j + 1), node(i + 1, j + 2),
             node(i, j + 1)});
      }
    }
  }
  return surface;
}

/// The plane z = height, the (u, v) plane turned by `angle` about `centre` (in the plane).
Map flat(double height, double angle = 0.0, const Eigen::Vector2d& centre = {0.0, 0.0}) {
  return [=](double u, double v) {
    const double c = std::cos(angle), s = std::sin(angle);
    const Eigen::Vector2d d(u - centre.x(), v - centre.y());
    return Eigen::Vector3d(centre.x() + c * d.x() - s * d.y(), centre.y() + s * d.x() + c * d.y(),
                           height);
  };
}
Map constant(const Eigen::Vector3d& vector) {
  return [=](double, double) { return vector; };
}

const Eigen::Vector3d up(0.0, 0.0, 1.0), down(0.0, 0.0, -1.0);

/// int phi~_j over a flat grid surface whose faces have area `face_area`, by hand: a
/// quadrilateral4 node gets a quarter of each of its faces, a triangle3 node a third, a
/// triangle6 corner 2/15 and a mid-edge node 1/5 (the transformed basis, alpha = 1/5).
std::vector<double> analytic_supports(const MortarSurface& surface, double face_area) {
  std::vector<double> supports(surface.coordinates.size(), 0.0);
  const int count = nodes_per_facet(surface.face_type);
  for (std::size_t k = 0; k < surface.faces.size(); ++k) {
    const int local = static_cast<int>(k) % count;
    double share = 0.0;
    if (surface.face_type == FacetType::quadrilateral4) share = 0.25;
    if (surface.face_type == FacetType::triangle3) share = 1.0 / 3.0;
    if (surface.face_type == FacetType::triangle6) share = local < 3 ? 2.0 / 15.0 : 0.2;
    supports[static_cast<std::size_t>(surface.faces[k])] += share * face_area;
  }
  return supports;
}

double sum(const std::map<int, double>& values) {
  double total = 0.0;
  for (const auto& [position, value] : values) total += value;
  return total;
}

Eigen::Vector3d weighted_positions(const std::map<int, double>& values,
                                   const std::vector<Eigen::Vector3d>& coordinates) {
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const auto& [position, value] : values) {
    total += value * coordinates[static_cast<std::size_t>(position)];
  }
  return total;
}

/// The nodes whose whole support (all faces containing them: convex, so their nodes) lies in
/// the closed region `inside`.
std::set<int> supports_inside(const MortarSurface& surface,
                              const std::function<bool(const Eigen::Vector3d&)>& inside) {
  const int count = nodes_per_facet(surface.face_type);
  std::set<int> outside;
  for (std::size_t face = 0; face < surface.faces.size() / count; ++face) {
    bool all = true;
    for (int a = 0; a < count; ++a) {
      all = all && inside(surface.coordinates[static_cast<std::size_t>(
                       surface.faces[face * static_cast<std::size_t>(count) + a])]);
    }
    if (all) continue;
    for (int a = 0; a < count; ++a) {
      outside.insert(surface.faces[face * static_cast<std::size_t>(count) + a]);
    }
  }
  std::set<int> nodes;
  for (int j = 0; j < static_cast<int>(surface.coordinates.size()); ++j) {
    if (!outside.contains(j)) nodes.insert(j);
  }
  return nodes;
}

struct FlatCase {
  std::string name;
  MortarSurface nonmortar, mortar;
  double nonmortar_face_area = 0.0;
  double overlap_area = 0.0;                           // analytic
  std::function<bool(const Eigen::Vector3d&)> inside;  // the mortar surface's projection
};

constexpr double distance = 0.25;

std::vector<FlatCase> flat_cases() {
  std::vector<FlatCase> cases;
  // 3x3 quadrilaterals on [0,1]^2 against 4x5 cells of triangles on [0.3,1.3]x[0.2,1.2]:
  // the overlap is the rectangle [0.3,1]x[0.2,1].
  cases.push_back(
      {"quadrilaterals against shifted triangles",
       grid(FacetType::quadrilateral4, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false),
       grid(FacetType::triangle3, 4, 5, {0.3, 0.2}, {1.3, 1.2}, flat(distance), constant(down),
            true),
       1.0 / 9.0, 0.7 * 0.8,
       [](const Eigen::Vector3d& x) { return x.x() >= 0.3 - 1e-12 && x.y() >= 0.2 - 1e-12; }});
  // 6x6 cells of triangles on the square [-1/2,1/2]^2 against quadrilaterals on the same square
  // turned by 30 degrees about its centre: the overlap is an octagon, the square less four corner
  // triangles, of area 1 - (c + s - 1)^2 / (2 s c).
  const double angle = std::numbers::pi / 6.0, c = std::cos(angle), s = std::sin(angle);
  cases.push_back(
      {"triangles against quadrilaterals turned by 30 degrees",
       grid(FacetType::triangle3, 6, 6, {-0.5, -0.5}, {0.5, 0.5}, flat(0), constant(up), false),
       grid(FacetType::quadrilateral4, 4, 5, {-0.5, -0.5}, {0.5, 0.5}, flat(distance, angle),
            constant(down), true),
       1.0 / 72.0, 1.0 - (c + s - 1.0) * (c + s - 1.0) / (2.0 * s * c),
       [=](const Eigen::Vector3d& x) {
         const double along = c * x.x() + s * x.y(), across = -s * x.x() + c * x.y();
         return std::abs(along) <= 0.5 + 1e-12 && std::abs(across) <= 0.5 + 1e-12;
       }});
  // Quadratic triangles on [0,1]^2 against quadrilaterals on [-1,2]^2 turned by 20 degrees
  // about (1/2, 1/2), which cover it.
  const auto covers = [](const Eigen::Vector3d&) { return true; };
  cases.push_back({"quadratic triangles against turned quadrilaterals",
                   grid(FacetType::triangle6, 2, 3, {0, 0}, {1, 1}, flat(0), constant(up), false),
                   grid(FacetType::quadrilateral4, 3, 4, {-1, -1}, {2, 2},
                        flat(distance, std::numbers::pi / 9.0, {0.5, 0.5}), constant(down), true),
                   1.0 / 12.0, 1.0, covers});
  // Quadrilaterals against quadratic triangles on [-1/2,3/2]^2 turned by 45 degrees.
  cases.push_back(
      {"quadrilaterals against turned quadratic triangles",
       grid(FacetType::quadrilateral4, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false),
       grid(FacetType::triangle6, 3, 2, {-0.5, -0.5}, {1.5, 1.5},
            flat(distance, std::numbers::pi / 4.0, {0.5, 0.5}), constant(down), true),
       1.0 / 9.0, 1.0, covers});
  // Quadratic triangles against quadratic triangles, non-matching, shifted by (0.1, 0.15):
  // the overlap is [0.1,1]x[0.15,1].
  cases.push_back({"quadratic triangles against shifted quadratic triangles",
                   grid(FacetType::triangle6, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false),
                   grid(FacetType::triangle6, 2, 4, {0.1, 0.15}, {1.1, 1.15}, flat(distance),
                        constant(down), true),
                   1.0 / 18.0, 0.9 * 0.85, [](const Eigen::Vector3d& x) {
                     return x.x() >= 0.1 - 1e-12 && x.y() >= 0.15 - 1e-12;
                   }});
  // One triangle, (-1/2,-1/2), (3/2,-1/2), (-1/2,3/2), against 3x3 quadrilaterals on [0,1]^2:
  // the clipped area is the half of the square below x + y = 1.
  MortarSurface triangle;
  triangle.face_type = FacetType::triangle3;
  triangle.coordinates = {{-0.5, -0.5, distance}, {1.5, -0.5, distance}, {-0.5, 1.5, distance}};
  triangle.normals = {down, down, down};
  triangle.faces = {0, 2, 1};
  cases.push_back(
      {"a triangle against a square",
       grid(FacetType::quadrilateral4, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false),
       triangle, 1.0 / 9.0, 0.5,
       [](const Eigen::Vector3d& x) { return x.x() + x.y() <= 1.0 + 1e-12; }});
  return cases;
}

/// EXPECT_NEAR that also keeps the largest deviation seen, for the record.
struct Deviation {
  double largest = 0.0;
  void check(double actual, double expected, double tolerance, const std::string& what) {
    largest = std::max(largest, std::abs(actual - expected));
    EXPECT_NEAR(actual, expected, tolerance) << what;
  }
};

TEST(FaceMortar, FlatNonMatchingSurfacesGiveTheConsistentRows) {
  for (const FlatCase& test : flat_cases()) {
    SCOPED_TRACE(test.name);
    const FaceCoupling coupling = integrate_face_mortar(test.nonmortar, test.mortar, {});
    const std::vector<double> supports =
        analytic_supports(test.nonmortar, test.nonmortar_face_area);
    const std::set<int> full = supports_inside(test.nonmortar, test.inside);
    ASSERT_FALSE(full.empty());
    Deviation deviation;
    double total = 0.0;
    for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
      const FaceRowIntegrals& row = coupling.rows[j];
      const std::string node = "node " + std::to_string(j);
      total += row.covered;
      if (!full.contains(static_cast<int>(j))) {
        // Partly covered (phi~ of a triangle6 corner changes sign: covered may exceed it).
        EXPECT_GT(std::abs(row.covered - supports[j]), 1e-9 * supports[j]) << node;
        continue;
      }
      const double weight = supports[j];
      const Eigen::Vector3d& x = test.nonmortar.coordinates[j];
      deviation.check(row.covered, weight, 1e-12, node + " covered");
      deviation.check(sum(row.dual_nonmortar), weight, 1e-12, node + " sum_k D_jk");
      deviation.check(sum(row.dual_mortar), weight, 1e-12, node + " sum_l M_jl");
      deviation.check(sum(row.standard_mortar), weight, 1e-12, node + " standard sum_l M_jl");
      deviation.check(row.dual_gap / weight, distance, 1e-12, node + " dual gap / m_j");
      deviation.check(row.standard_gap / weight, distance, 1e-12, node + " standard gap / m_j");
      // sum_l M_jl x_l = sum_k D_jk x_k = m_j x_j (+ d m_j on z): linear fields carry over.
      const Eigen::Vector3d mortar_moment =
          weighted_positions(row.dual_mortar, test.mortar.coordinates);
      const Eigen::Vector3d own_moment =
          weighted_positions(row.dual_nonmortar, test.nonmortar.coordinates);
      for (int axis = 0; axis < 3; ++axis) {
        deviation.check(mortar_moment[axis], weight * (x + distance * up)[axis], 1e-12,
                        node + " sum_l M_jl x_l");
        deviation.check(own_moment[axis], weight * x[axis], 1e-12, node + " sum_k D_jk x_k");
      }
      // Linear faces: D is diagonal, D_jj = int phi_j.
      if (test.nonmortar.face_type != FacetType::triangle6) {
        for (const auto& [position, value] : row.dual_nonmortar) {
          deviation.check(value, position == static_cast<int>(j) ? weight : 0.0, 1e-12,
                          node + " D_jk, k = " + std::to_string(position));
        }
      }
    }
    deviation.check(total, test.overlap_area, 1e-12, "total covered area");
    EXPECT_EQ(coupling.same_direction_candidates, 0);
    std::cout << test.name << ": " << full.size() << " nodes fully covered, largest deviation "
              << deviation.largest << "\n";
  }
}

TEST(FaceMortar, MatchingMeshesGiveTheNodeToNodeRows) {
  for (const FacetType type :
       {FacetType::quadrilateral4, FacetType::triangle3, FacetType::triangle6}) {
    SCOPED_TRACE(to_string(type));
    const MortarSurface nonmortar = grid(type, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false);
    const MortarSurface mortar =
        grid(type, 3, 3, {0, 0}, {1, 1}, flat(distance), constant(down), true);
    const double face_area = type == FacetType::quadrilateral4 ? 1.0 / 9.0 : 1.0 / 18.0;
    const std::vector<double> supports = analytic_supports(nonmortar, face_area);
    const FaceCoupling coupling = integrate_face_mortar(nonmortar, mortar, {});
    for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
      const FaceRowIntegrals& row = coupling.rows[j];
      const int node = static_cast<int>(j);
      EXPECT_NEAR(row.covered, supports[j], 1e-13);
      EXPECT_NEAR(row.dual_gap, distance * supports[j], 1e-13);
      for (const auto& [position, value] : row.dual_mortar) {
        // The grids number their nodes alike: M = D. For linear faces D_jk = delta_jk int phi_j.
        const auto own = row.dual_nonmortar.find(position);
        const double expected = own == row.dual_nonmortar.end() ? 0.0 : own->second;
        EXPECT_NEAR(value, expected, 1e-13) << "node " << j << ", mortar node " << position;
        if (type != FacetType::triangle6) {
          EXPECT_NEAR(expected, position == node ? supports[j] : 0.0, 1e-13);
        }
      }
    }
  }
}

TEST(FaceMortar, QuadraticTrianglesNeedTheTransformedBasis) {
  // An affine triangle6 face of area S = 1/2 tilted in space: int phi_corner = 0, so the
  // untransformed dual basis would vanish at the corners; int phi~ = 2S/15 at the corners and
  // S/5 at the mid-edge nodes, and int psi_j phi~_k = delta_jk int phi~_j.
  const Eigen::Vector3d origin(0.2, -0.1, 0.3), first(1.0, 0.0, 0.0),
      second = Eigen::Vector3d(0.0, 0.6, 0.8);  // unit, orthogonal to first: area 1/2
  std::vector<Eigen::Vector3d> nodes = {origin, origin + first, origin + second};
  nodes.push_back(0.5 * (nodes[0] + nodes[1]));
  nodes.push_back(0.5 * (nodes[1] + nodes[2]));
  nodes.push_back(0.5 * (nodes[2] + nodes[0]));
  const Eigen::MatrixXd mass = face_mass_matrix(FacetType::triangle6, nodes);
  const Eigen::VectorXd integrals = mass.rowwise().sum();
  const double area = 0.5;
  for (int a = 0; a < 6; ++a) EXPECT_NEAR(integrals[a], a < 3 ? 0.0 : area / 3.0, 1e-15);
  const Eigen::MatrixXd transformation = face_basis_transformation(FacetType::triangle6);
  const Eigen::VectorXd transformed = transformation * integrals;
  for (int a = 0; a < 6; ++a) {
    EXPECT_NEAR(transformed[a], a < 3 ? 2.0 * area / 15.0 : area / 5.0, 1e-15);
  }
  const Eigen::MatrixXd biorthogonal =
      face_dual_basis(FacetType::triangle6, nodes) * mass * transformation.transpose();
  for (int a = 0; a < 6; ++a) {
    for (int b = 0; b < 6; ++b) {
      EXPECT_NEAR(biorthogonal(a, b), a == b ? transformed[a] : 0.0, 1e-14);
    }
  }
}

TEST(FaceMortar, ATiltedNormalFieldStillIntegratesOverTheFace) {
  // Normals tilted by atan(0.3) from the flat surfaces' normal: the auxiliary plane is tilted,
  // the covered area is still the face area and the gap is measured along the tilted normal:
  // the mortar point is x + t n with t n_z = d, so g = t = d |(0.3, 0, 1)|.
  const Eigen::Vector3d tilted(0.3, 0.0, 1.0);
  const MortarSurface nonmortar =
      grid(FacetType::quadrilateral4, 3, 3, {0, 0}, {1, 1}, flat(0), constant(tilted), false);
  const MortarSurface mortar =
      grid(FacetType::triangle3, 2, 2, {-1, -1}, {2, 2}, flat(distance), constant(down), true);
  const FaceCoupling coupling = integrate_face_mortar(nonmortar, mortar, {});
  const std::vector<double> supports = analytic_supports(nonmortar, 1.0 / 9.0);
  for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
    EXPECT_NEAR(coupling.rows[j].covered, supports[j], 1e-13);
    EXPECT_NEAR(coupling.rows[j].dual_gap / supports[j], distance * tilted.norm(), 1e-12);
  }
}

/// The mortar surface z = R + d - sqrt(R^2 - x^2) (the bottom of a cylinder of radius R along
/// y, outward normal away from its axis) over the flat non-mortar square [-L,L]^2 (z = 0,
/// normal +z): the gap field is g(x) = R + d - sqrt(R^2 - x^2), whose integral over the square
/// is 2L (2L (R + d) - L sqrt(R^2 - L^2) - R^2 asin(L/R)).
struct Cylinder {
  double radius = 1.0, lift = 0.1, half = 0.5;
  double height(double x) const { return radius + lift - std::sqrt(radius * radius - x * x); }
  double exact() const {
    return 2.0 * half *
           (2.0 * half * (radius + lift) - half * std::sqrt(radius * radius - half * half) -
            radius * radius * std::asin(half / radius));
  }
  /// |sum_j G_j - exact| with the mortar surface meshed by `cells` x `cells` faces of `type`.
  double error(FacetType type, int cells) const {
    const MortarSurface nonmortar = grid(FacetType::quadrilateral4, 3, 3, {-half, -half},
                                         {half, half}, flat(0), constant(up), false);
    const MortarSurface mortar = grid(
        type, cells, cells, {-half, -half}, {half, half},
        [&](double u, double v) { return Eigen::Vector3d(u, v, height(u)); },
        [&](double u, double) { return Eigen::Vector3d(u, 0.0, height(u) - radius - lift); }, true);
    const FaceCoupling coupling = integrate_face_mortar(nonmortar, mortar, {});
    double dual = 0.0, standard = 0.0, covered = 0.0;
    for (const FaceRowIntegrals& row : coupling.rows) {
      dual += row.dual_gap;
      standard += row.standard_gap;
      covered += row.covered;
    }
    EXPECT_NEAR(covered, 4.0 * half * half, 1e-13);
    EXPECT_NEAR(dual, standard, 1e-13);  // both bases are partitions of unity
    return std::abs(dual - exact());
  }
};

TEST(FaceMortar, CurvedMortarSurfaceGapConvergesAtTheInterpolationOrder) {
  const Cylinder cylinder;
  const double width = 2.0 * cylinder.half, r2 = cylinder.radius * cylinder.radius;
  const double x = cylinder.half;
  // g' = x / sqrt(R^2 - x^2) and g''' = 3 R^2 x / (R^2 - x^2)^(5/2), both odd.
  const double slope_jump = 2.0 * x / std::sqrt(r2 - x * x);
  const double third_jump = 2.0 * 3.0 * r2 * x / std::pow(r2 - x * x, 2.5);
  // Linear and bilinear faces interpolate g linearly in x: the error is that of the trapezoidal
  // rule, width h^2 / 12 (g'(L) - g'(-L)) + O(h^4). Quadratic triangles interpolate g by the
  // quadratic through x_i, x_i + h/2, x_i + h (g depends on x only): Simpson's error,
  // width h^4 / 2880 (g'''(L) - g'''(-L)) + O(h^6).
  struct Series {
    FacetType type;
    int first_cells, last_cells;
    double order;
  };
  for (const Series& series :
       {Series{FacetType::quadrilateral4, 4, 32, 2.0}, Series{FacetType::triangle3, 4, 32, 2.0},
        Series{FacetType::triangle6, 4, 16, 4.0}}) {
    SCOPED_TRACE(to_string(series.type));
    std::vector<double> errors;
    for (int cells = series.first_cells; cells <= series.last_cells; cells *= 2) {
      errors.push_back(cylinder.error(series.type, cells));
    }
    for (std::size_t k = 0; k + 1 < errors.size(); ++k) {
      const double measured = std::log2(errors[k] / errors[k + 1]);
      EXPECT_NEAR(measured, series.order, 0.1) << "errors " << errors[k] << " -> " << errors[k + 1];
    }
    const double h = width / series.last_cells;
    const double leading = series.order == 2.0 ? width * h * h / 12.0 * slope_jump
                                               : width * std::pow(h, 4) / 2880.0 * third_jump;
    EXPECT_NEAR(errors.back() / leading, 1.0, 0.01);
    std::cout << to_string(series.type) << " cylinder gap errors:";
    for (const double value : errors) std::cout << " " << value;
    std::cout << " (leading term at the finest: " << leading << ")\n";
  }
}

TEST(FaceMortar, SupportIntegralsAreTheNodalShareOfTheFaces) {
  // Flat grids on [0,1]^2 turned and lifted in space (the supports do not depend on where).
  const Map placed = [](double u, double v) -> Eigen::Vector3d {
    return Eigen::Vector3d(0.6 * u, 0.8 * u, 0.0) + Eigen::Vector3d(0.0, 0.0, 1.0) * v +
           Eigen::Vector3d(1.0, 2.0, 3.0);
  };
  for (const FacetType type :
       {FacetType::quadrilateral4, FacetType::triangle3, FacetType::triangle6}) {
    SCOPED_TRACE(to_string(type));
    const MortarSurface surface =
        grid(type, 3, 2, {0, 0}, {1, 1}, placed, constant({0.8, -0.6, 0.0}), false);
    const double face_area = type == FacetType::quadrilateral4 ? 1.0 / 6.0 : 1.0 / 12.0;
    const std::vector<double> expected = analytic_supports(surface, face_area);
    const std::vector<double> supports = support_integrals(surface);
    for (std::size_t j = 0; j < supports.size(); ++j) {
      EXPECT_NEAR(supports[j], expected[j], 1e-14) << "node " << j;
    }
  }
}

TEST(FaceMortar, DistortedQuadrilateralsAreCoveredUpToTheQuadratureError) {
  // Flat quadrilaterals that are not parallelograms (the map from the plane to the reference
  // square is not affine, the integrands are rational), covered by one large mortar face: the
  // cells tile every face, so the total covered area is the sum of the faces' areas (shoelace
  // formula) to round-off; per node, covered differs from int phi_j (support_integrals, on the
  // reference square) by the cell rule's error, measured 2e-11.
  const Map distorted = [](double u, double v) {
    return Eigen::Vector3d(u + 0.4 * u * v * (1.0 - u),
                           v * (1.0 + 0.5 * u) + 0.3 * u * u * (1.0 - v), 0.0);
  };
  const MortarSurface nonmortar =
      grid(FacetType::quadrilateral4, 3, 3, {0, 0}, {1, 1}, distorted, constant(up), false);
  const MortarSurface mortar =
      grid(FacetType::quadrilateral4, 1, 1, {-1, -1}, {3, 3}, flat(distance), constant(down), true);
  double area = 0.0;
  for (std::size_t face = 0; face < nonmortar.faces.size() / 4; ++face) {
    for (std::size_t a = 0; a < 4; ++a) {
      const Eigen::Vector3d& p =
          nonmortar.coordinates[static_cast<std::size_t>(nonmortar.faces[4 * face + a])];
      const Eigen::Vector3d& q =
          nonmortar.coordinates[static_cast<std::size_t>(nonmortar.faces[4 * face + (a + 1) % 4])];
      area += 0.5 * (p.x() * q.y() - q.x() * p.y());
    }
  }
  const FaceCoupling coupling = integrate_face_mortar(nonmortar, mortar, {});
  const std::vector<double> supports = support_integrals(nonmortar);
  double total = 0.0, largest = 0.0;
  for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
    total += coupling.rows[j].covered;
    largest = std::max(largest, std::abs(coupling.rows[j].covered - supports[j]) / supports[j]);
    EXPECT_NEAR(coupling.rows[j].dual_gap / sum(coupling.rows[j].dual_nonmortar), distance, 1e-12);
  }
  EXPECT_NEAR(total, area, 1e-13);
  EXPECT_LT(largest, 1e-9);
  std::cout << "distorted quadrilaterals: largest relative |covered - int phi_j| " << largest
            << "\n";
}

TEST(FaceMortar, TheInitialGapIsAddedToTheGeometricGap) {
  // g0(x) = x + 2y, linear: the dual basis gives m_j g0(x_j) + m_j d at every node.
  const MortarSurface nonmortar =
      grid(FacetType::triangle3, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false);
  const MortarSurface mortar =
      grid(FacetType::quadrilateral4, 2, 2, {-1, -1}, {2, 2}, flat(distance), constant(down), true);
  const FaceCoupling coupling = integrate_face_mortar(
      nonmortar, mortar, [](const Eigen::Vector3d& x) { return x.x() + 2.0 * x.y(); });
  const std::vector<double> supports = analytic_supports(nonmortar, 1.0 / 18.0);
  for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
    const Eigen::Vector3d& x = nonmortar.coordinates[j];
    EXPECT_NEAR(coupling.rows[j].dual_gap / supports[j], distance + x.x() + 2.0 * x.y(), 1e-12);
  }
}

TEST(FaceMortar, NormalsPointingTheSameWayGiveNoRows) {
  const MortarSurface nonmortar =
      grid(FacetType::quadrilateral4, 3, 3, {0, 0}, {1, 1}, flat(0), constant(up), false);
  const MortarSurface mortar =
      grid(FacetType::triangle3, 4, 4, {0, 0}, {1, 1}, flat(distance), constant(up), false);
  const FaceCoupling coupling = integrate_face_mortar(nonmortar, mortar, {});
  EXPECT_GT(coupling.same_direction_candidates, 0);
  EXPECT_EQ(coupling.facing_candidates, 0);
  for (const FaceRowIntegrals& row : coupling.rows) {
    EXPECT_EQ(row.covered, 0.0);
    EXPECT_TRUE(row.dual_mortar.empty());
    EXPECT_TRUE(row.dual_nonmortar.empty());
  }
}

TEST(FaceMortar, TheSearchFindsOnlyNearbyFaces) {
  // Matching 40x40 grids: each non-mortar face sees its mortar face and the few around it
  // (the search box reaches one face size sideways), not all 1600.
  const MortarSurface nonmortar =
      grid(FacetType::quadrilateral4, 40, 40, {0, 0}, {1, 1}, flat(0), constant(up), false);
  const MortarSurface mortar =
      grid(FacetType::quadrilateral4, 40, 40, {0, 0}, {1, 1}, flat(0.01), constant(down), true);
  const FaceCoupling coupling = integrate_face_mortar(nonmortar, mortar, {});
  EXPECT_LE(coupling.facing_candidates, 1600 * 25);
  EXPECT_GE(coupling.facing_candidates, 1600);
}

TEST(FaceMortar, InconsistentSurfacesAreRejected) {
  MortarSurface surface =
      grid(FacetType::triangle3, 1, 1, {0, 0}, {1, 1}, flat(0), constant(up), false);
  MortarSurface edges = surface;
  edges.face_type = FacetType::line2;
  EXPECT_THROW(integrate_face_mortar(edges, surface, {}), std::invalid_argument);
  MortarSurface missing = surface;
  missing.normals.pop_back();
  EXPECT_THROW(integrate_face_mortar(surface, missing, {}), std::invalid_argument);
  MortarSurface out_of_range = surface;
  out_of_range.faces[0] = 99;
  EXPECT_THROW(integrate_face_mortar(out_of_range, surface, {}), std::invalid_argument);
}

}  // namespace
}  // namespace robin
