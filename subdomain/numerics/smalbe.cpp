#include "numerics/smalbe.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace robin {
namespace {

/// A + rho Q Q' as an operator.
class PenalizedOperator final : public LinearOperator {
 public:
  PenalizedOperator(const LinearOperator& matrix, const Eigen::MatrixXd& basis, double penalty)
      : matrix_(matrix), basis_(basis), penalty_(penalty) {}
  int size() const override { return matrix_.size(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    matrix_.apply(x, y);
    y.noalias() += penalty_ * (basis_ * (basis_.transpose() * x));
  }

 private:
  const LinearOperator& matrix_;
  const Eigen::MatrixXd& basis_;
  const double penalty_;
};

/// The equality with orthonormal rows: C' = Q T, Q'x = d~ = T^{-T} d.
struct OrthonormalEquality {
  Eigen::MatrixXd basis;       // Q (n x m)
  Eigen::MatrixXd triangular;  // T (m x m, upper)
  Eigen::VectorXd target;      // d~
};

OrthonormalEquality orthonormalize(const Eigen::MatrixXd& equality_matrix,
                                   const Eigen::VectorXd& equality_target) {
  const Eigen::Index rows = equality_matrix.rows();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(equality_matrix.transpose());
  OrthonormalEquality equality;
  equality.basis = qr.householderQ() * Eigen::MatrixXd::Identity(equality_matrix.cols(), rows);
  equality.triangular = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
  const double largest = equality.triangular.diagonal().cwiseAbs().maxCoeff();
  if (!(equality.triangular.diagonal().cwiseAbs().minCoeff() > 1e-12 * largest)) {
    throw std::invalid_argument("solve_smalbe: the equality matrix is not of full row rank");
  }
  // T' d~ = d
  equality.target =
      equality.triangular.transpose().triangularView<Eigen::Lower>().solve(equality_target);
  return equality;
}

/// ||g^P|| for the gradient g at x >= lower.
double projected_gradient_norm(const Eigen::VectorXd& x, const Eigen::VectorXd& gradient,
                               const Eigen::VectorXd& lower) {
  double squared = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double g = x[i] > lower[i] ? gradient[i] : std::min(gradient[i], 0.0);
    squared += g * g;
  }
  return std::sqrt(squared);
}

/// The outer iteration's state and fixed data.
class SmalbeIteration {
 public:
  SmalbeIteration(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                  const Eigen::VectorXd& lower, OrthonormalEquality equality,
                  const SmalbeParameters& parameters, SmalbeResult& result)
      : matrix_(matrix),
        right_hand_side_(right_hand_side),
        lower_(lower),
        equality_(std::move(equality)),
        parameters_(parameters),
        result_(result) {}

  void run(const Eigen::VectorXd& initial, Eigen::VectorXd multiplier);

 private:
  double gradient_scale(const Eigen::VectorXd& x) const;
  double equality_scale(const Eigen::VectorXd& x) const;
  MprgpResult inner_solve(const Eigen::VectorXd& start, const Eigen::VectorXd& multiplier,
                          double penalty, double bound, int iteration_budget) const;
  double lagrangian(const MprgpResult& inner, const Eigen::VectorXd& multiplier,
                    double penalty) const;

  const LinearOperator& matrix_;
  const Eigen::VectorXd& right_hand_side_;
  const Eigen::VectorXd& lower_;
  const OrthonormalEquality equality_;
  const SmalbeParameters& parameters_;
  SmalbeResult& result_;
};

double SmalbeIteration::gradient_scale(const Eigen::VectorXd& x) const {
  const double distance = (x - lower_).norm();
  return distance > 0.0 ? result_.operator_norm * distance : right_hand_side_.norm();
}

double SmalbeIteration::equality_scale(const Eigen::VectorXd& x) const {
  return std::max(x.norm(), equality_.target.norm());
}

/// x^k: MPRGP on L(., mu~, rho), gradient (A + rho QQ') x - (b - Q mu~ + rho Q d~), stopping at
/// ||g^P|| <= max(min(M ||Q'x - d~||, eta), epsilon s_g).
MprgpResult SmalbeIteration::inner_solve(const Eigen::VectorXd& start,
                                         const Eigen::VectorXd& multiplier, double penalty,
                                         double bound, int iteration_budget) const {
  const Eigen::MatrixXd& basis = equality_.basis;
  const PenalizedOperator penalized(matrix_, basis, penalty);
  const Eigen::VectorXd inner_right_hand_side =
      right_hand_side_ - basis * multiplier + penalty * (basis * equality_.target);
  const double eta = right_hand_side_.norm();
  MprgpParameters inner;
  inner.operator_norm = result_.operator_norm + penalty;  // ||A + rho QQ'|| <= ||A|| + rho
  inner.max_iterations = iteration_budget;
  inner.absolute_tolerance = std::numeric_limits<double>::min();
  inner.iterate_threshold = [&](const Eigen::VectorXd& x) {
    const double violation = (basis.transpose() * x - equality_.target).norm();
    return std::max(std::min(bound * violation, eta),
                    parameters_.relative_tolerance * gradient_scale(x));
  };
  return solve_mprgp(penalized, inner_right_hand_side, lower_, start, inner);
}

/// L(x, mu~, rho) from the inner result: A x = g + rhs_inner - rho Q Q'x.
double SmalbeIteration::lagrangian(const MprgpResult& inner, const Eigen::VectorXd& multiplier,
                                   double penalty) const {
  const Eigen::MatrixXd& basis = equality_.basis;
  const Eigen::VectorXd& x = inner.solution;
  const Eigen::VectorXd projection = basis.transpose() * x;
  const Eigen::VectorXd inner_right_hand_side =
      right_hand_side_ - basis * multiplier + penalty * (basis * equality_.target);
  const Eigen::VectorXd product =
      inner.gradient + inner_right_hand_side - penalty * basis * projection;
  const Eigen::VectorXd violation = projection - equality_.target;
  return 0.5 * x.dot(product) - right_hand_side_.dot(x) + multiplier.dot(violation) +
         0.5 * penalty * violation.squaredNorm();
}

void SmalbeIteration::run(const Eigen::VectorXd& initial, Eigen::VectorXd multiplier) {
  const double penalty = result_.operator_norm;  // rho = ||A|| for orthonormal rows
  double bound = result_.operator_norm;          // M_0
  double previous_lagrangian = std::numeric_limits<double>::infinity();
  Eigen::VectorXd x = initial.cwiseMax(lower_);
  for (int outer = 1; outer <= parameters_.max_outer_iterations; ++outer) {
    result_.outer_iterations = outer;
    const int budget = parameters_.max_iterations - result_.iterations;
    const MprgpResult inner = inner_solve(x, multiplier, penalty, bound, std::max(budget, 0));
    result_.iterations += inner.iterations;
    result_.operator_applications += inner.operator_applications;
    x = inner.solution;
    const Eigen::VectorXd violation = equality_.basis.transpose() * x - equality_.target;
    result_.equality_residual = violation.norm();  // of the orthonormal rows until the end
    const double current_lagrangian = lagrangian(inner, multiplier, penalty);
    multiplier += penalty * violation;  // mu~^{k+1}: inner.gradient is the Lagrangian's at it
    result_.solution = x;
    result_.gradient = inner.gradient;
    result_.projected_gradient_norm = inner.projected_gradient_norm;
    result_.multiplier = multiplier;
    if (inner.status == QpStatus::breakdown) {
      result_.status = QpStatus::breakdown;
      result_.message = "inner MPRGP: " + inner.message;
      return;
    }
    const bool stationary =
        inner.status == QpStatus::converged &&
        inner.projected_gradient_norm <= parameters_.relative_tolerance * gradient_scale(x);
    if (stationary && violation.norm() <= parameters_.relative_tolerance * equality_scale(x)) {
      result_.status = QpStatus::converged;
      return;
    }
    if (result_.iterations >= parameters_.max_iterations) {
      result_.message = "no convergence in " + std::to_string(parameters_.max_iterations) +
                        " inner iterations (" + std::to_string(outer) + " outer)";
      return;
    }
    if (current_lagrangian < previous_lagrangian + 0.5 * penalty * violation.squaredNorm()) {
      bound /= parameters_.bound_reduction;
    }
    previous_lagrangian = current_lagrangian;
  }
  result_.message = "no convergence in " + std::to_string(parameters_.max_outer_iterations) +
                    " outer iterations: the residual of the orthonormalized equality is " +
                    std::to_string(result_.equality_residual);
}

}  // namespace

SmalbeResult solve_smalbe(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                          const Eigen::VectorXd& lower, const Eigen::MatrixXd& equality_matrix,
                          const Eigen::VectorXd& equality_target, const Eigen::VectorXd& initial,
                          const Eigen::VectorXd& initial_multiplier,
                          const SmalbeParameters& parameters) {
  const Eigen::Index size = matrix.size();
  if (right_hand_side.size() != size || lower.size() != size || initial.size() != size ||
      equality_matrix.cols() != size || equality_target.size() != equality_matrix.rows() ||
      (initial_multiplier.size() != 0 && initial_multiplier.size() != equality_matrix.rows())) {
    throw std::invalid_argument("solve_smalbe: sizes of the operator (" + std::to_string(size) +
                                "), vectors and equality (" +
                                std::to_string(equality_matrix.rows()) + " x " +
                                std::to_string(equality_matrix.cols()) + ") differ");
  }
  OrthonormalEquality equality = orthonormalize(equality_matrix, equality_target);
  SmalbeResult result;
  result.operator_norm = parameters.operator_norm > 0.0
                             ? parameters.operator_norm
                             : estimate_operator_norm(matrix, 10, result.operator_applications);
  // mu~ = T mu
  const Eigen::VectorXd multiplier =
      initial_multiplier.size() == 0
          ? Eigen::VectorXd(Eigen::VectorXd::Zero(equality_matrix.rows()))
          : Eigen::VectorXd(equality.triangular * initial_multiplier);
  const Eigen::MatrixXd triangular = equality.triangular;
  SmalbeIteration iteration(matrix, right_hand_side, lower, std::move(equality), parameters,
                            result);
  iteration.run(initial, multiplier);
  // mu = T^{-1} mu~, so that C'mu = Q mu~
  result.multiplier = triangular.triangularView<Eigen::Upper>().solve(result.multiplier);
  result.equality_residual = (equality_matrix * result.solution - equality_target).norm();
  result.projected_gradient_norm = projected_gradient_norm(result.solution, result.gradient, lower);
  return result;
}

}  // namespace robin
