#pragma once
// Validity of a mesh's elements: each must map its reference element one to one.

#include <string>

#include "numerics/mesh.hpp"

namespace robin {

/// Checks that every element of `mesh` is valid: the Jacobian determinant det(dx/dxi) is
/// positive at every node of the element and at every quadrature point of the stiffness rule,
/// and above 1e-12 times the square of the element's longest corner distance (not degenerate).
/// A clockwise (inverted), folded or collapsed element throws InputError
/// "<context>: <element label> (TYPE at node tags a, b, c) is inverted ..." naming the element's
/// tag and the mesh's source file when known.
void check_element_validity(const Mesh& mesh, const std::string& context);

}  // namespace robin
