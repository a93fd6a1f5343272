#pragma once
// Sparse assembly of linear elasticity in two or three dimensions (mesh.dimension = d).
// Degrees of freedom: component c (x, y, z) of node i at d i + c. No dense global matrix is
// ever formed. Points and vectors have three components; z is zero in two dimensions.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <vector>

#include "numerics/finite_element.hpp"
#include "numerics/material.hpp"
#include "numerics/mesh.hpp"

namespace robin {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using VectorField = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

/// Global stiffness K (d n x d n, symmetric) assembled element by element into its pattern (the
/// node pairs that share an element), each entry summing its terms in element order. Throws
/// InputError when the material is not of the mesh's dimension.
SparseMatrix assemble_stiffness(const Mesh& mesh, const Material& material);

/// Consistent load of a body force density b(x) (force per unit area in 2D, per unit volume in
/// 3D): f_i = int N_i b.
Eigen::VectorXd assemble_body_force(const Mesh& mesh, const VectorField& body_force);

/// Consistent load of a traction t(x, n) on boundary `group` (force per unit length in 2D, per
/// unit area in 3D); `outward_normal` is the unit outward normal of the facet at x.
using TractionField = std::function<Eigen::Vector3d(const Eigen::Vector3d& point,
                                                    const Eigen::Vector3d& outward_normal)>;
Eigen::VectorXd assemble_boundary_traction(const Mesh& mesh, const BoundaryGroup& group,
                                           const TractionField& traction);

/// Boundary weights m_i = int_group N_i ds per node of the mesh (zero off the group): lengths in
/// 2D, areas in 3D. 6-node triangular faces are the exception: their corner functions integrate
/// to zero, so their weights come from their four linear sub-triangles (a third of each
/// sub-triangle's area to each of its nodes; positive, with the same total for flat faces). The
/// weights scale contact forces into pressures (pressure_j = lambda_j / m_j).
Eigen::VectorXd boundary_weights(const Mesh& mesh, const BoundaryGroup& group);

/// Unit outward normal at each node of `group` (measure-weighted average of the outward
/// normals of its facets, which are oriented by the adjacent element).
/// Returned in the order of group.nodes().
std::vector<Eigen::Vector3d> boundary_node_normals(const Mesh& mesh, const BoundaryGroup& group);

/// Per mesh node, the sum over the facets of `group` at the node of the facet's outward normal
/// (taken at the node) times the facet's measure (length or area); zero off the group. The
/// facets are oriented by the adjacent element, or, with `facets_oriented_outward`, taken as
/// they are (FacetGeometry's own orientation: an edge's direction turned clockwise, a face's
/// right-hand normal; the mesh needs no elements then).
std::vector<Eigen::Vector3d> boundary_normal_sums(const Mesh& mesh, const BoundaryGroup& group,
                                                  bool facets_oriented_outward = false);

/// sums[node] / |sums[node]| for each of `nodes`, in their order. Throws InputError
/// "<what>: the normals at node <tag> cancel out (a cusp or a fold)" for a zero sum.
std::vector<Eigen::Vector3d> unit_normals(const Mesh& mesh,
                                          const std::vector<Eigen::Vector3d>& sums,
                                          const std::vector<int>& nodes, const std::string& what);

/// Called for one element, whose mesh nodes are nodes[0 .. count - 1], with its Voigt stresses
/// s = C B u_e (material.hpp: 3 components in 2D, 6 in 3D): stresses[0] at the element's
/// reference centroid, stresses[1 + i] at its local node i (i < count).
using ElementStressVisitor =
    std::function<void(const int* nodes, int count, const VoigtVector* stresses)>;

/// Calls `visit` for every element, in the element order of mesh.blocks. Points of an element
/// type with the same reference gradients share one evaluation (the same J and dN/dx).
void for_each_element_stress(const Mesh& mesh, const Material& material,
                             const Eigen::VectorXd& displacement,
                             const ElementStressVisitor& visit);

/// Voigt stress (material.hpp: 3 components in 2D, 6 in 3D) per element (at its centroid) and
/// per node (average over the elements touching the node, each evaluated at that node).
struct StressField {
  Eigen::MatrixXd element_stress;  // voigt_size x element_count, element order of mesh.blocks
  Eigen::MatrixXd nodal_stress;    // voigt_size x node_count
  Eigen::VectorXd element_von_mises;
  Eigen::VectorXd nodal_von_mises;
};
StressField recover_stress(const Mesh& mesh, const Material& material,
                           const Eigen::VectorXd& displacement);

/// L2 norm of (u_h - u_exact) over the mesh, with a rule exact to degree 6.
double l2_displacement_error(const Mesh& mesh, const Eigen::VectorXd& displacement,
                             const VectorField& exact);

}  // namespace robin
