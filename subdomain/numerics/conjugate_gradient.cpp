#include "numerics/conjugate_gradient.hpp"

#include <stdexcept>

namespace robin {
namespace {

/// r = b - A x, its norm returned; `product` is workspace for A x.
double true_residual(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                     const Eigen::VectorXd& solution, Eigen::VectorXd& product,
                     Eigen::VectorXd& residual) {
  matrix.apply(solution, product);
  residual = right_hand_side - product;
  return residual.norm();
}

void check_sizes(const LinearOperator& matrix, const Preconditioner& preconditioner,
                 const Eigen::VectorXd& right_hand_side) {
  if (matrix.size() != right_hand_side.size() || preconditioner.size() != matrix.size()) {
    throw std::invalid_argument(
        "solve_conjugate_gradient: the sizes of the matrix, the preconditioner and the "
        "right-hand side differ");
  }
}

}  // namespace

ConjugateGradientResult solve_conjugate_gradient(const LinearOperator& matrix,
                                                 const Preconditioner& preconditioner,
                                                 const Eigen::VectorXd& right_hand_side,
                                                 Eigen::VectorXd& solution,
                                                 const ConjugateGradientOptions& options) {
  check_sizes(matrix, preconditioner, right_hand_side);
  const Eigen::Index size = right_hand_side.size();
  if (solution.size() != size) solution = Eigen::VectorXd::Zero(size);
  ConjugateGradientResult result;
  const double load_norm = right_hand_side.norm();
  if (load_norm == 0.0) {
    solution.setZero();
    result.status = ConjugateGradientStatus::converged;
    return result;
  }
  const double target = options.relative_tolerance * load_norm;
  Eigen::VectorXd residual(size), preconditioned(size), direction(size), product(size);
  double residual_norm = true_residual(matrix, right_hand_side, solution, product, residual);
  bool restart = true;
  double residual_dot = 0.0;  // (r_k, z_k)
  while (true) {
    if (residual_norm <= target) {
      // the recursive residual passed: confirm with the true one
      residual_norm = true_residual(matrix, right_hand_side, solution, product, residual);
      if (residual_norm <= target) {
        result.status = ConjugateGradientStatus::converged;
        break;
      }
      restart = true;
    }
    if (result.iterations >= options.maximum_iterations) break;
    preconditioner.apply(residual, preconditioned);
    const double next_dot = residual.dot(preconditioned);
    if (!(next_dot > 0.0)) {
      result.status = ConjugateGradientStatus::breakdown;
      break;
    }
    if (restart) {
      direction = preconditioned;
      restart = false;
    } else {
      direction = preconditioned + (next_dot / residual_dot) * direction;
    }
    residual_dot = next_dot;
    matrix.apply(direction, product);
    const double curvature = direction.dot(product);
    if (!(curvature > 0.0)) {
      result.status = ConjugateGradientStatus::breakdown;
      break;
    }
    const double step = residual_dot / curvature;
    solution.noalias() += step * direction;
    residual.noalias() -= step * product;
    residual_norm = residual.norm();
    ++result.iterations;
  }
  result.relative_residual = residual_norm / load_norm;
  return result;
}

}  // namespace robin
