#include "numerics/solution_history.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>

namespace robin {

SolutionHistory::SolutionHistory(int capacity) : capacity_(std::max(capacity, 1)) {}

void SolutionHistory::add(const Eigen::VectorXd& force, const Eigen::VectorXd& solution,
                          const Eigen::VectorXd& trace) {
  if (!entries_.empty() &&
      (force.size() != entries_.front().force.size() ||
       solution.size() != entries_.front().solution.size() || trace.size() != force.size())) {
    throw std::invalid_argument("SolutionHistory::add: the sizes differ from the kept ones");
  }
  if (static_cast<int>(entries_.size()) == capacity_) entries_.pop_front();
  entries_.push_back({force, solution, trace});
}

Eigen::VectorXd SolutionHistory::start(const Eigen::VectorXd& force, Eigen::Index unknowns) const {
  Eigen::VectorXd initial = Eigen::VectorXd::Zero(unknowns);
  if (entries_.empty()) return initial;
  if (force.size() != entries_.front().force.size() ||
      unknowns != entries_.front().solution.size()) {
    throw std::invalid_argument("SolutionHistory::start: the sizes differ from the kept ones");
  }
  const auto count = static_cast<Eigen::Index>(entries_.size());
  Eigen::MatrixXd energy(count, count);  // G
  Eigen::VectorXd projection(count);     // h
  for (Eigen::Index i = 0; i < count; ++i) {
    const Entry& row = entries_[static_cast<std::size_t>(i)];
    projection[i] = row.trace.dot(force);
    for (Eigen::Index j = 0; j < count; ++j) {
      energy(i, j) = row.trace.dot(entries_[static_cast<std::size_t>(j)].force);
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (energy + energy.transpose()));
  const double largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0.0)) return initial;
  Eigen::VectorXd coefficients = Eigen::VectorXd::Zero(count);
  for (Eigen::Index k = 0; k < count; ++k) {
    const double value = eigen.eigenvalues()[k];
    if (value <= 1e-10 * largest) continue;
    const Eigen::VectorXd vector = eigen.eigenvectors().col(k);
    coefficients += vector * (vector.dot(projection) / value);
  }
  for (Eigen::Index i = 0; i < count; ++i) {
    initial += coefficients[i] * entries_[static_cast<std::size_t>(i)].solution;
  }
  return initial;
}

}  // namespace robin
