#pragma once
// Small bodies shared by the tests.

#include <optional>
#include <string>

#include "numerics/body_definition.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin::testing {

/// The block [0, 2] x [0, 1] (4 x 2 cells of two quadratic triangles each), plane strain
/// (E = 100, nu = 0.25), clamped at its bottom, its top the contact boundary.
inline BodyDefinition plane_quadratic_block(const std::string& name) {
  BodyDefinition definition;
  definition.name = name;
  definition.mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 4, 2, ElementType::triangle6);
  definition.material = make_isotropic_material(100.0, 0.25, PlaneModel::plane_strain, "test");
  definition.dirichlet = {{"bottom", 0.0, 0.0, std::nullopt}};
  definition.contact_boundaries = {"top"};
  return definition;
}

}  // namespace robin::testing
