#pragma once
// Splits the d n degrees of freedom of a body (d = mesh.dimension) into free and prescribed ones
// (Dirichlet conditions) and reduces K u = f to the free block:
//   K_ff u_f = f_f - K_fp u_p.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "numerics/elasticity.hpp"

namespace robin {

class DofMap {
 public:
  /// `prescribed[d]` holds the value of degree of freedom d when it is fixed.
  explicit DofMap(std::vector<std::optional<double>> prescribed);

  int total_count() const { return static_cast<int>(prescribed_.size()); }
  int free_count() const { return free_count_; }
  /// Index of dof d among the free ones, or -1 when d is prescribed.
  int free_index(int dof) const { return free_index_[dof]; }
  bool is_prescribed(int dof) const { return prescribed_[dof].has_value(); }
  /// Full vector of prescribed values (zero at free dofs).
  const Eigen::VectorXd& prescribed_values() const { return prescribed_values_; }

  /// Free-free block of K and the reduced load f_f - K_fp u_p.
  SparseMatrix reduce_matrix(const SparseMatrix& full) const;
  /// The lower triangle of the free-free block (all that a Cholesky factor reads).
  SparseMatrix reduce_matrix_lower(const SparseMatrix& full) const;
  /// The entries of K in a prescribed row or column (zero elsewhere): with it instead of K,
  /// reduce_load gives the same f_f - K_fp u_p and (K u)_p = K_p: u is the same at prescribed
  /// rows, each sum taken in the same order (the free-free entries only add u_p's zeros).
  SparseMatrix prescribed_part(const SparseMatrix& full) const;
  Eigen::VectorXd reduce_load(const SparseMatrix& full, const Eigen::VectorXd& full_load) const;
  /// Full field from free values plus the prescribed values.
  Eigen::VectorXd expand(const Eigen::VectorXd& free_values) const;
  /// Restriction of a full vector to the free dofs.
  Eigen::VectorXd restrict(const Eigen::VectorXd& full) const;

 private:
  /// The entries (row, column) of `full` that `keep` accepts, renumbered by `index` (-1: a
  /// dropped row or column; ascending among the kept ones), in a size x size matrix.
  template <typename Keep>
  SparseMatrix select_entries(const SparseMatrix& full, const std::vector<int>& index, int size,
                              Keep keep) const;

  std::vector<std::optional<double>> prescribed_;
  std::vector<int> free_index_;
  Eigen::VectorXd prescribed_values_;
  int free_count_ = 0;
};

/// m, the number of rigid motions of a body: 3 in 2D, 6 in 3D.
int rigid_mode_count(int dimension);

/// Row `dof` (d node + c) of the m rigid modes of `mesh` about `centre`: the translations e_c,
/// then the rotations w x (x - centre) / scale with w = e_z in 2D (the row (-(y - yc), x - xc)
/// / scale) and w = e_x, e_y, e_z in 3D.
Eigen::VectorXd rigid_mode_row(const Mesh& mesh, int dof, const Eigen::Vector3d& centre,
                               double scale = 1.0);

/// The m rigid modes Q of `mesh` (rigid_mode_row about the mean of the nodes, scaled by the largest
/// distance of a node from it) on the free dofs of `dofs`: Q_f, free x m. For elasticity they
/// span the near-null space of the reduced stiffness (algebraic_multigrid.hpp).
Eigen::MatrixXd free_rigid_body_modes(const Mesh& mesh, const DofMap& dofs);

/// The mesh node of each free dof of `dofs` (the dof d node + c of free index i gives node).
std::vector<int> free_dof_nodes(const Mesh& mesh, const DofMap& dofs);

/// True when the prescribed dofs remove every rigid motion of the mesh (in 2D two translations
/// and one rotation, in 3D three of each): the m rigid modes (m = 3 or 6) restricted to the
/// prescribed dofs have rank m.
bool removes_rigid_motions(const Mesh& mesh, const DofMap& dofs);

/// The rigid motions the prescribed dofs leave free, on the free dofs: R (free x k, k <= m) with
/// orthonormal columns spanning { r = Q c : (Q c)_p = 0 on every prescribed dof p }, Q the m
/// rigid modes of the mesh: the translations e_c and the rotations w x (x - xc) / s for w = e_z
/// (2D) or w = e_x, e_y, e_z (3D), centred and scaled so the test does not depend on position
/// and size. c runs over the null space of Q_p'Q_p (m x m; its eigenvalues below 1e-10 times the
/// largest, the test of removes_rigid_motions, count as zero), so k = m - rank(Q_p) and k = 0
/// exactly when removes_rigid_motions() holds. Since K Q = 0 on
/// the whole mesh and R vanishes on the prescribed dofs, K_ff R = 0: R spans the kernel of the
/// reduced stiffness (a connected mesh has no other).
Eigen::MatrixXd rigid_body_modes(const Mesh& mesh, const DofMap& dofs);

}  // namespace robin
