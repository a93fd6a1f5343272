#pragma once
// Everything that defines one elastic body: mesh, material, loads, Dirichlet
// conditions and the names of its contact boundaries. Plain data; no files.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "numerics/material.hpp"
#include "numerics/mesh.hpp"

namespace robin {

/// Displacement components prescribed on every node of a named boundary.
struct DirichletCondition {
  std::string boundary;
  std::optional<double> x;  // prescribed u_x (length), absent = free
  std::optional<double> y;  // prescribed u_y (length), absent = free
  std::optional<double> z;  // prescribed u_z (length), absent = free; solid bodies only
};

/// A traction on a named boundary, force per unit length (2D) or area (3D): either a fixed
/// vector (z = 0 in 2D), or a
/// normal pressure p (compression positive), i.e. traction = -p n with n the outward normal.
struct TractionCondition {
  std::string boundary;
  bool is_pressure = false;
  Eigen::Vector3d vector = Eigen::Vector3d::Zero();
  double pressure = 0.0;
};

struct BodyDefinition {
  std::string name;  // used in every message about this body
  Mesh mesh;
  Material material;
  /// Force per unit area (2D, z = 0) or volume (3D).
  Eigen::Vector3d body_force = Eigen::Vector3d::Zero();
  std::vector<DirichletCondition> dirichlet;
  std::vector<TractionCondition> tractions;
  /// The names of the boundary groups that may touch other bodies: at least one, distinct (a
  /// body of an N-body stack touches its neighbours with several).
  std::vector<std::string> contact_boundaries;
};

}  // namespace robin
