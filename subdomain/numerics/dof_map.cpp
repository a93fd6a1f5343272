#include "numerics/dof_map.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <stdexcept>
#include <utility>

namespace robin {

DofMap::DofMap(std::vector<std::optional<double>> prescribed)
    : prescribed_(std::move(prescribed)),
      free_index_(prescribed_.size(), -1),
      prescribed_values_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(prescribed_.size()))) {
  for (std::size_t dof = 0; dof < prescribed_.size(); ++dof) {
    if (prescribed_[dof]) {
      prescribed_values_(static_cast<Eigen::Index>(dof)) = *prescribed_[dof];
    } else {
      free_index_[dof] = free_count_++;
    }
  }
}

template <typename Keep>
SparseMatrix DofMap::select_entries(const SparseMatrix& full, const std::vector<int>& index,
                                    int size, Keep keep) const {
  if (full.rows() != total_count() || full.cols() != total_count()) {
    throw std::invalid_argument("DofMap: matrix size differs from the dof count");
  }
  // Two passes over full's columns (ascending, rows ascending in each): the counts, then the
  // entries, so the result is built in place, its rows ascending since `index` is.
  SparseMatrix selected(size, size);
  int* column_starts = selected.outerIndexPtr();
  long count = 0;
  for (int column = 0; column < full.outerSize(); ++column) {
    if (index[column] < 0) continue;
    column_starts[index[column]] = static_cast<int>(count);
    for (SparseMatrix::InnerIterator entry(full, column); entry; ++entry) {
      if (index[entry.row()] >= 0 && keep(static_cast<int>(entry.row()), column)) ++count;
    }
  }
  column_starts[size] = static_cast<int>(count);
  selected.resizeNonZeros(count);
  long position = 0;
  for (int column = 0; column < full.outerSize(); ++column) {
    if (index[column] < 0) continue;
    for (SparseMatrix::InnerIterator entry(full, column); entry; ++entry) {
      const int row = static_cast<int>(entry.row());
      if (index[row] < 0 || !keep(row, column)) continue;
      selected.innerIndexPtr()[position] = index[row];
      selected.valuePtr()[position++] = entry.value();
    }
  }
  return selected;
}

SparseMatrix DofMap::reduce_matrix(const SparseMatrix& full) const {
  return select_entries(full, free_index_, free_count_, [](int, int) { return true; });
}

SparseMatrix DofMap::reduce_matrix_lower(const SparseMatrix& full) const {
  return select_entries(full, free_index_, free_count_,
                        [](int row, int column) { return row >= column; });
}

SparseMatrix DofMap::prescribed_part(const SparseMatrix& full) const {
  std::vector<int> identity(prescribed_.size());
  for (std::size_t dof = 0; dof < identity.size(); ++dof) identity[dof] = static_cast<int>(dof);
  return select_entries(full, identity, total_count(), [this](int row, int column) {
    return is_prescribed(row) || is_prescribed(column);
  });
}

Eigen::VectorXd DofMap::reduce_load(const SparseMatrix& full,
                                    const Eigen::VectorXd& full_load) const {
  if (full.rows() != total_count() || full.cols() != total_count() ||
      full_load.size() != total_count()) {
    throw std::invalid_argument("DofMap::reduce_load: sizes differ from the dof count");
  }
  // f_f - K_fp u_p, as the free rows of f - K u_p (u_p is zero on the free dofs).
  const Eigen::VectorXd residual = full_load - full * prescribed_values_;
  return restrict(residual);
}

Eigen::VectorXd DofMap::expand(const Eigen::VectorXd& free_values) const {
  if (free_values.size() != free_count_) {
    throw std::invalid_argument("DofMap::expand: vector size differs from the free dof count");
  }
  Eigen::VectorXd full = prescribed_values_;
  for (int dof = 0; dof < total_count(); ++dof) {
    if (free_index_[dof] >= 0) full(dof) = free_values(free_index_[dof]);
  }
  return full;
}

Eigen::VectorXd DofMap::restrict(const Eigen::VectorXd& full) const {
  if (full.size() != total_count()) {
    throw std::invalid_argument("DofMap::restrict: vector size differs from the dof count");
  }
  Eigen::VectorXd free_values(free_count_);
  for (int dof = 0; dof < total_count(); ++dof) {
    if (free_index_[dof] >= 0) free_values(free_index_[dof]) = full(dof);
  }
  return free_values;
}

int rigid_mode_count(int dimension) {
  return dimension == 3 ? 6 : 3;
}

Eigen::VectorXd rigid_mode_row(const Mesh& mesh, int dof, const Eigen::Vector3d& centre,
                               double scale) {
  const int dimension = mesh.dimension;
  const int component = dof % dimension;
  const Eigen::Vector3d relative = (mesh.nodes[dof / dimension] - centre) / scale;
  Eigen::VectorXd row = Eigen::VectorXd::Zero(rigid_mode_count(dimension));
  row(component) = 1.0;
  if (dimension == 2) {
    row(2) = component == 0 ? -relative.y() : relative.x();
    return row;
  }
  for (int axis = 0; axis < 3; ++axis) {
    row(3 + axis) = Eigen::Vector3d::Unit(axis).cross(relative)(component);
  }
  return row;
}

namespace {

/// The mesh's centre and the largest distance of a node from it (1 for a single point).
std::pair<Eigen::Vector3d, double> centre_and_scale(const Mesh& mesh) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& node : mesh.nodes) centre += node;
  centre /= static_cast<double>(mesh.node_count());
  double scale = 0.0;
  for (const Eigen::Vector3d& node : mesh.nodes) scale = std::max(scale, (node - centre).norm());
  if (scale == 0.0) scale = 1.0;
  return {centre, scale};
}

int mode_count(const Mesh& mesh) {
  return rigid_mode_count(mesh.dimension);
}

/// Eigen decomposition of the Gram matrix Q_p'Q_p of the rigid modes on the prescribed dofs
/// (eigenvalues ascending).
Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> prescribed_gram(const Mesh& mesh,
                                                               const DofMap& dofs) {
  if (dofs.total_count() != mesh.dof_count()) {
    throw std::invalid_argument("rigid motions: dof count is not dimension x nodes");
  }
  const auto [centre, scale] = centre_and_scale(mesh);
  const int count = mode_count(mesh);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(count, count);
  for (int dof = 0; dof < dofs.total_count(); ++dof) {
    if (!dofs.is_prescribed(dof)) continue;
    const Eigen::VectorXd row = rigid_mode_row(mesh, dof, centre, scale);
    gram += row * row.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(gram);
}

/// Whether eigenvalue `index` of the Gram matrix is zero relative to the largest.
bool is_free_motion(const Eigen::VectorXd& eigenvalues, int index) {
  const double largest = eigenvalues(eigenvalues.size() - 1);
  return !(largest > 0.0 && eigenvalues(index) > 1e-10 * largest);
}

}  // namespace

Eigen::MatrixXd free_rigid_body_modes(const Mesh& mesh, const DofMap& dofs) {
  if (dofs.total_count() != mesh.dof_count()) {
    throw std::invalid_argument("free_rigid_body_modes: dof count is not dimension x nodes");
  }
  Eigen::MatrixXd modes(dofs.free_count(), mode_count(mesh));
  if (mesh.node_count() == 0) return modes;
  const auto [centre, scale] = centre_and_scale(mesh);
  for (int dof = 0; dof < dofs.total_count(); ++dof) {
    if (!dofs.is_prescribed(dof)) {
      modes.row(dofs.free_index(dof)) = rigid_mode_row(mesh, dof, centre, scale).transpose();
    }
  }
  return modes;
}

std::vector<int> free_dof_nodes(const Mesh& mesh, const DofMap& dofs) {
  std::vector<int> nodes(static_cast<std::size_t>(dofs.free_count()));
  for (int dof = 0; dof < dofs.total_count(); ++dof) {
    if (!dofs.is_prescribed(dof)) {
      nodes[static_cast<std::size_t>(dofs.free_index(dof))] = dof / mesh.dimension;
    }
  }
  return nodes;
}

bool removes_rigid_motions(const Mesh& mesh, const DofMap& dofs) {
  if (dofs.total_count() != mesh.dof_count()) {
    throw std::invalid_argument("removes_rigid_motions: dof count is not dimension x nodes");
  }
  if (mesh.node_count() == 0) return false;
  // Full rank when the smallest eigenvalue is not negligible relative to the largest.
  return !is_free_motion(prescribed_gram(mesh, dofs).eigenvalues(), 0);
}

Eigen::MatrixXd rigid_body_modes(const Mesh& mesh, const DofMap& dofs) {
  if (mesh.node_count() == 0) return Eigen::MatrixXd(dofs.free_count(), 0);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gram = prescribed_gram(mesh, dofs);
  std::vector<int> free_motions;
  for (int index = 0; index < mode_count(mesh); ++index) {
    if (is_free_motion(gram.eigenvalues(), index)) free_motions.push_back(index);
  }
  const int count = static_cast<int>(free_motions.size());
  Eigen::MatrixXd coefficients(mode_count(mesh), count);  // c: the null space of Q_p
  for (int k = 0; k < count; ++k) coefficients.col(k) = gram.eigenvectors().col(free_motions[k]);
  const Eigen::MatrixXd modes = free_rigid_body_modes(mesh, dofs) * coefficients;  // Q_f c
  // Orthonormal columns: the thin Q of a Householder QR.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(modes);
  return qr.householderQ() * Eigen::MatrixXd::Identity(dofs.free_count(), count);
}

}  // namespace robin
