#pragma once
// Sparse assembly of 2D linear elasticity. Degrees of freedom: node i has
// x at 2i and y at 2i+1. No dense global matrix is ever formed.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <vector>

#include "numerics/material.hpp"
#include "numerics/mesh.hpp"

namespace robin {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using VectorField = std::function<Eigen::Vector2d(const Eigen::Vector2d&)>;

/// Global stiffness K (2n x 2n, symmetric) assembled from element triplets.
SparseMatrix assemble_stiffness(const Mesh& mesh, const Material& material);

/// Consistent load of a body force density b(x) (force per unit area): f_i = int N_i b.
Eigen::VectorXd assemble_body_force(const Mesh& mesh, const VectorField& body_force);

/// Consistent load of a traction t(x, n) on boundary `group` (force per unit length);
/// `outward_normal` is the unit outward normal of the edge at x.
using TractionField = std::function<Eigen::Vector2d(const Eigen::Vector2d& point,
                                                    const Eigen::Vector2d& outward_normal)>;
Eigen::VectorXd assemble_boundary_traction(const Mesh& mesh, const BoundaryGroup& group,
                                           const TractionField& traction);

/// Boundary weights m_i = int_group N_i ds per node of the mesh (zero off the group).
Eigen::VectorXd boundary_weights(const Mesh& mesh, const BoundaryGroup& group);

/// Unit outward normal at each node of `group` (length-weighted average of the outward
/// normals of its edges, which are oriented by the adjacent area element).
/// Returned in the order of group.nodes().
std::vector<Eigen::Vector2d> boundary_node_normals(const Mesh& mesh, const BoundaryGroup& group);

/// Per mesh node, the sum over the edges of `group` at the node of the edge's outward normal
/// (taken at the node) times the edge's length; zero off the group. The edges are oriented by
/// the adjacent area element, or, with `edges_have_body_on_left`, taken as they are (the
/// outward normal is the edge direction turned clockwise; the mesh needs no elements then).
std::vector<Eigen::Vector2d> boundary_normal_sums(const Mesh& mesh, const BoundaryGroup& group,
                                                  bool edges_have_body_on_left = false);

/// sums[node] / |sums[node]| for each of `nodes`, in their order. Throws InputError
/// "<what>: the normals at node <tag> cancel out (a cusp or a fold)" for a zero sum.
std::vector<Eigen::Vector2d> unit_normals(const Mesh& mesh,
                                          const std::vector<Eigen::Vector2d>& sums,
                                          const std::vector<int>& nodes, const std::string& what);

/// Stress (s_xx, s_yy, s_xy) per element (at its centroid) and per node (average over
/// the elements touching the node, each evaluated at that node).
struct StressField {
  Eigen::Matrix3Xd element_stress;  // 3 x element_count, element order of mesh.blocks
  Eigen::Matrix3Xd nodal_stress;    // 3 x node_count
  Eigen::VectorXd element_von_mises;
  Eigen::VectorXd nodal_von_mises;
};
StressField recover_stress(const Mesh& mesh, const Material& material,
                           const Eigen::VectorXd& displacement);

/// L2 norm of (u_h - u_exact) over the mesh, with a rule exact to degree 6.
double l2_displacement_error(const Mesh& mesh, const Eigen::VectorXd& displacement,
                             const VectorField& exact);

}  // namespace robin
