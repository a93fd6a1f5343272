#include "numerics/nonnegative_least_squares.hpp"

#include <Eigen/QR>
#include <limits>
#include <stdexcept>
#include <vector>

namespace robin {
namespace {

/// The least-squares solution of A_P s = b on the passive columns P (zero elsewhere).
Eigen::VectorXd passive_solution(const Eigen::MatrixXd& matrix, const Eigen::VectorXd& target,
                                 const std::vector<bool>& passive) {
  std::vector<Eigen::Index> columns;
  for (Eigen::Index j = 0; j < matrix.cols(); ++j) {
    if (passive[static_cast<std::size_t>(j)]) columns.push_back(j);
  }
  Eigen::MatrixXd block(matrix.rows(), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t k = 0; k < columns.size(); ++k) {
    block.col(static_cast<Eigen::Index>(k)) = matrix.col(columns[k]);
  }
  const Eigen::VectorXd values = block.completeOrthogonalDecomposition().solve(target);
  Eigen::VectorXd solution = Eigen::VectorXd::Zero(matrix.cols());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    solution[columns[k]] = values[static_cast<Eigen::Index>(k)];
  }
  return solution;
}

/// Lawson-Hanson's inner loop: moves from x towards s until s is feasible on P, dropping the
/// passive columns that reach zero on the way.
void make_passive_feasible(const Eigen::MatrixXd& matrix, const Eigen::VectorXd& target,
                           std::vector<bool>& passive, Eigen::VectorXd& x, Eigen::VectorXd& s) {
  for (int guard = 0; guard <= static_cast<int>(matrix.cols()); ++guard) {
    double step = 1.0;
    bool infeasible = false;
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      if (passive[static_cast<std::size_t>(j)] && s[j] <= 0.0) {
        infeasible = true;
        step = std::min(step, x[j] / (x[j] - s[j]));
      }
    }
    if (!infeasible) return;
    // x <- x + step (s - x); columns at zero leave P
    x += step * (s - x);
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      if (passive[static_cast<std::size_t>(j)] && x[j] <= 0.0) {
        passive[static_cast<std::size_t>(j)] = false;
        x[j] = 0.0;
      }
    }
    s = passive_solution(matrix, target, passive);
  }
}

}  // namespace

NonnegativeLeastSquaresResult solve_nonnegative_least_squares(const Eigen::MatrixXd& matrix,
                                                              const Eigen::VectorXd& target) {
  if (matrix.rows() != target.size()) {
    throw std::invalid_argument("nonnegative least squares: a matrix of " +
                                std::to_string(matrix.rows()) + " rows and a target of size " +
                                std::to_string(target.size()));
  }
  const Eigen::Index count = matrix.cols();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(count);
  std::vector<bool> passive(static_cast<std::size_t>(count), false);
  // A dual component w_j = A_j'(b - A x) above this counts as positive.
  const double tolerance = 1e3 * std::numeric_limits<double>::epsilon() *
                           std::max(1.0, matrix.cwiseAbs().maxCoeff() * target.norm() *
                                             static_cast<double>(matrix.rows()));
  for (Eigen::Index step = 0; step < 3 * count + 30; ++step) {
    // w = A'(b - A x): the column with the largest w > 0 outside P enters P
    const Eigen::VectorXd dual = matrix.transpose() * (target - matrix * x);
    Eigen::Index entering = -1;
    double largest = tolerance;
    for (Eigen::Index j = 0; j < count; ++j) {
      if (!passive[static_cast<std::size_t>(j)] && dual[j] > largest) {
        largest = dual[j];
        entering = j;
      }
    }
    if (entering < 0) break;
    passive[static_cast<std::size_t>(entering)] = true;
    const Eigen::VectorXd previous = x;
    Eigen::VectorXd s = passive_solution(matrix, target, passive);
    make_passive_feasible(matrix, target, passive, x, s);
    x = s;
    // Rounding can make the entering column leave at once; nothing else can change then.
    if (!passive[static_cast<std::size_t>(entering)] && x == previous) break;
  }
  return {x, (matrix * x - target).norm()};
}

}  // namespace robin
