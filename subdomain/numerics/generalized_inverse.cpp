#include "numerics/generalized_inverse.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <stdexcept>

namespace robin {
namespace {

/// The k fixing dofs: the first k pivots of a QR with column pivoting of R' (k x free), which
/// makes R restricted to them (k x k) as well conditioned as the greedy choice can.
std::vector<int> choose_fixing_dofs(const Eigen::MatrixXd& kernel) {
  const Eigen::MatrixXd transpose = kernel.transpose();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(transpose);
  std::vector<int> fixing;
  for (Eigen::Index k = 0; k < kernel.cols(); ++k) {
    fixing.push_back(static_cast<int>(qr.colsPermutation().indices()[k]));
  }
  std::sort(fixing.begin(), fixing.end());
  return fixing;
}

/// K restricted to the dofs j with kept_index[j] >= 0, renumbered to kept_index[j].
SparseMatrix kept_block(const SparseMatrix& matrix, const std::vector<int>& kept_index,
                        int kept_count) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(matrix.nonZeros()));
  for (int column = 0; column < matrix.outerSize(); ++column) {
    if (kept_index[column] < 0) continue;
    for (SparseMatrix::InnerIterator entry(matrix, column); entry; ++entry) {
      const int row = kept_index[entry.row()];
      if (row >= 0) entries.emplace_back(row, kept_index[column], entry.value());
    }
  }
  SparseMatrix block(kept_count, kept_count);
  block.setFromTriplets(entries.begin(), entries.end());
  return block;
}

}  // namespace

GeneralizedInverse::GeneralizedInverse(const SparseMatrix& stiffness, Eigen::MatrixXd kernel,
                                       const std::string& body_name, FactorizationOptions options)
    : GeneralizedInverse(SparseMatrix(stiffness), std::move(kernel), body_name,
                         std::move(options)) {}

GeneralizedInverse::GeneralizedInverse(SparseMatrix&& stiffness, Eigen::MatrixXd kernel,
                                       const std::string& body_name, FactorizationOptions options)
    : size_(static_cast<int>(stiffness.rows())), kernel_(std::move(kernel)) {
  if (kernel_.cols() == 0) {
    factor_ = std::make_unique<CholeskyFactor>(std::move(stiffness), body_name, std::move(options));
    return;
  }
  if (kernel_.rows() != size_) {
    throw std::invalid_argument("body '" + body_name + "': a kernel of " +
                                std::to_string(kernel_.rows()) + " rows for a stiffness of size " +
                                std::to_string(size_));
  }
  if (!options.unknown_points.empty() && static_cast<int>(options.unknown_points.size()) != size_) {
    throw std::invalid_argument("body '" + body_name +
                                "': " + std::to_string(options.unknown_points.size()) +
                                " unknown points for a stiffness of size " + std::to_string(size_));
  }
  fixing_dofs_ = choose_fixing_dofs(kernel_);
  kept_index_.assign(static_cast<std::size_t>(size_), 0);
  for (const int dof : fixing_dofs_) kept_index_[static_cast<std::size_t>(dof)] = -1;
  int kept_count = 0;
  for (int& index : kept_index_) index = index < 0 ? -1 : kept_count++;
  options.trailing_unknowns = kept_only(options.trailing_unknowns, body_name);
  std::vector<Eigen::Vector3d> kept_points;
  for (int dof = 0; dof < size_ && !options.unknown_points.empty(); ++dof) {
    if (kept_index_[static_cast<std::size_t>(dof)] >= 0) {
      kept_points.push_back(options.unknown_points[static_cast<std::size_t>(dof)]);
    }
  }
  options.unknown_points = std::move(kept_points);
  SparseMatrix kept = kept_block(stiffness, kept_index_, kept_count);
  SparseMatrix().swap(stiffness);  // only K_rr is factorized
  factor_ = std::make_unique<CholeskyFactor>(std::move(kept), body_name, std::move(options));
}

std::vector<int> GeneralizedInverse::kept_only(const std::vector<int>& unknowns,
                                               const std::string& body_name) const {
  std::vector<int> kept;
  for (const int unknown : unknowns) {
    if (unknown < 0 || unknown >= size_) {
      throw std::invalid_argument("body '" + body_name + "': trailing unknown " +
                                  std::to_string(unknown) + " is out of range");
    }
    if (kept_index_[static_cast<std::size_t>(unknown)] >= 0) {
      kept.push_back(kept_index_[static_cast<std::size_t>(unknown)]);
    }
  }
  return kept;
}

Eigen::VectorXd GeneralizedInverse::restrict_to_kept(const Eigen::VectorXd& values) const {
  Eigen::VectorXd kept(factor_->size());
  for (int dof = 0; dof < size_; ++dof) {
    const int index = kept_index_[static_cast<std::size_t>(dof)];
    if (index >= 0) kept[index] = values[dof];
  }
  return kept;
}

Eigen::VectorXd GeneralizedInverse::expand_from_kept(const Eigen::VectorXd& values) const {
  Eigen::VectorXd full = Eigen::VectorXd::Zero(size_);
  for (int dof = 0; dof < size_; ++dof) {
    const int index = kept_index_[static_cast<std::size_t>(dof)];
    if (index >= 0) full[dof] = values[index];
  }
  return full;
}

Eigen::VectorXd GeneralizedInverse::solve(const Eigen::VectorXd& right_hand_side) const {
  if (kernel_.cols() == 0) return factor_->solve(right_hand_side);
  if (right_hand_side.size() != size_) {
    throw std::invalid_argument("generalized inverse of size " + std::to_string(size_) +
                                " given a right-hand side of size " +
                                std::to_string(right_hand_side.size()));
  }
  // [K_rr^{-1} b_r; 0]
  return expand_from_kept(factor_->solve(restrict_to_kept(right_hand_side)));
}

Eigen::MatrixXd GeneralizedInverse::solve(const Eigen::MatrixXd& right_hand_sides) const {
  if (kernel_.cols() == 0) return factor_->solve(right_hand_sides);
  if (right_hand_sides.rows() != size_) {
    throw std::invalid_argument("generalized inverse of size " + std::to_string(size_) +
                                " given right-hand sides of " +
                                std::to_string(right_hand_sides.rows()) + " rows");
  }
  Eigen::MatrixXd kept(factor_->size(), right_hand_sides.cols());
  for (int dof = 0; dof < size_; ++dof) {
    const int index = kept_index_[static_cast<std::size_t>(dof)];
    if (index >= 0) kept.row(index) = right_hand_sides.row(dof);
  }
  const Eigen::MatrixXd solved = factor_->solve(kept);
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(size_, right_hand_sides.cols());
  for (int dof = 0; dof < size_; ++dof) {
    const int index = kept_index_[static_cast<std::size_t>(dof)];
    if (index >= 0) full.row(dof) = solved.row(index);
  }
  return full;
}

Eigen::VectorXd GeneralizedInverse::solve_minimum_norm(
    const Eigen::VectorXd& right_hand_side) const {
  if (kernel_.cols() == 0) return factor_->solve(right_hand_side);
  // P K^+ P b with P = I - R R'
  const Eigen::VectorXd balanced =
      right_hand_side - kernel_ * (kernel_.transpose() * right_hand_side);
  const Eigen::VectorXd solution = solve(balanced);
  return solution - kernel_ * (kernel_.transpose() * solution);
}

Eigen::MatrixXd GeneralizedInverse::trailing_congruence(const SparseMatrix& trace) const {
  if (kernel_.cols() == 0) return factor_->trailing_congruence(trace);
  if (trace.cols() != size_) {
    throw std::invalid_argument("a trace with " + std::to_string(trace.cols()) +
                                " columns for a generalized inverse of size " +
                                std::to_string(size_));
  }
  // B K^+ B' = B_r K_rr^{-1} B_r': the columns of the fixing dofs drop out.
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column < trace.outerSize(); ++column) {
    const int index = kept_index_[static_cast<std::size_t>(column)];
    if (index < 0) continue;
    for (SparseMatrix::InnerIterator entry(trace, column); entry; ++entry) {
      entries.emplace_back(static_cast<int>(entry.row()), index, entry.value());
    }
  }
  SparseMatrix kept(trace.rows(), factor_->size());
  kept.setFromTriplets(entries.begin(), entries.end());
  return factor_->trailing_congruence(kept);
}

}  // namespace robin
