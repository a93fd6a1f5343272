#include "numerics/primal_contact.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "numerics/cholesky.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

constexpr int maximum_conjugate_gradient_iterations = 5000;

std::string describe(const ConjugateGradientResult& result) {
  std::ostringstream text;
  text << "conjugate gradients stopped after " << result.iterations << " iterations at relative "
       << "residual " << result.relative_residual
       << (result.status == ConjugateGradientStatus::breakdown
               ? " (breakdown: an operator is not positive definite)"
               : " (iteration limit)");
  return text.str();
}

/// The active rows B_A of B, S = B_A B_A' factorized, and the maps of the file comment.
class ActiveConstraints {
 public:
  ActiveConstraints(const RowMajorSparseMatrix& trace, const std::vector<int>& rows,
                    const std::string& body_name)
      : rows_(rows) {
    std::vector<Eigen::Triplet<double>> triplets;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      for (RowMajorSparseMatrix::InnerIterator entry(trace, rows[k]); entry; ++entry) {
        triplets.emplace_back(static_cast<int>(k), entry.col(), entry.value());
      }
    }
    active_trace_.resize(static_cast<Eigen::Index>(rows.size()), trace.cols());
    active_trace_.setFromTriplets(triplets.begin(), triplets.end());
    if (rows.empty()) return;
    active_transpose_ = active_trace_.transpose();
    // positive definite when the rows are independent (BodySolver checks all of them once)
    normal_factor_ = std::make_unique<CholeskyFactor>(
        SparseMatrix(active_trace_ * active_transpose_), body_name);
  }

  bool empty() const { return rows_.empty(); }
  const std::vector<int>& rows() const { return rows_; }

  /// P x = x - B_A' S^{-1} B_A x.
  Eigen::VectorXd project(const Eigen::VectorXd& x) const {
    if (empty()) return x;
    return x - active_transpose_ * solve_normal(active_trace_ * x);
  }
  /// x + B_A' S^{-1} (c_A - B_A x): the nearest point of {B_A y = c_A} to x.
  Eigen::VectorXd move_onto(const Eigen::VectorXd& x, const Eigen::VectorXd& bound) const {
    if (empty()) return x;
    Eigen::VectorXd active_bound(static_cast<Eigen::Index>(rows_.size()));
    for (std::size_t k = 0; k < rows_.size(); ++k) active_bound[k] = bound[rows_[k]];
    return x + active_transpose_ * solve_normal(active_bound - active_trace_ * x);
  }
  /// S^{-1} B_A r: the multipliers lambda_A with B_A' lambda_A nearest to r.
  Eigen::VectorXd multipliers(const Eigen::VectorXd& residual) const {
    if (empty()) return Eigen::VectorXd();
    return solve_normal(active_trace_ * residual);
  }

 private:
  Eigen::VectorXd solve_normal(const Eigen::VectorXd& right_hand_side) const {
    return normal_factor_->solve(right_hand_side);
  }

  std::vector<int> rows_;
  SparseMatrix active_trace_;                      // B_A
  SparseMatrix active_transpose_;                  // B_A'
  std::unique_ptr<CholeskyFactor> normal_factor_;  // S
};

/// P K P on ker B_A.
class ProjectedStiffness final : public LinearOperator {
 public:
  ProjectedStiffness(const LinearOperator& stiffness, const ActiveConstraints& constraints)
      : stiffness_(stiffness), constraints_(constraints) {}
  int size() const override { return stiffness_.size(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    stiffness_.apply(constraints_.project(x), product_);
    y = constraints_.project(product_);
  }

 private:
  const LinearOperator& stiffness_;
  const ActiveConstraints& constraints_;
  mutable Eigen::VectorXd product_;
};

/// P M^{-1} P.
class ProjectedPreconditioner final : public Preconditioner {
 public:
  ProjectedPreconditioner(const Preconditioner& preconditioner,
                          const ActiveConstraints& constraints)
      : preconditioner_(preconditioner), constraints_(constraints) {}
  int size() const override { return preconditioner_.size(); }
  void apply(const Eigen::VectorXd& residual, Eigen::VectorXd& correction) const override {
    preconditioner_.apply(constraints_.project(residual), product_);
    correction = constraints_.project(product_);
  }

 private:
  const Preconditioner& preconditioner_;
  const ActiveConstraints& constraints_;
  mutable Eigen::VectorXd product_;
};

std::vector<int> indices_of(const std::vector<bool>& set) {
  std::vector<int> indices;
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (set[j]) indices.push_back(static_cast<int>(j));
  }
  return indices;
}

/// The rows of B with at least one free dof: only they can be held by a contact force.
std::vector<bool> movable_rows(const RowMajorSparseMatrix& trace) {
  std::vector<bool> movable(static_cast<std::size_t>(trace.rows()), false);
  for (Eigen::Index row = 0; row < trace.rows(); ++row) {
    for (RowMajorSparseMatrix::InnerIterator entry(trace, row); entry; ++entry) {
      if (entry.value() != 0.0) movable[static_cast<std::size_t>(row)] = true;
    }
  }
  return movable;
}

/// The rows that penetrate (B u > c) among the movable ones.
std::vector<bool> penetrating_rows(const Eigen::VectorXd& trace_of_solution,
                                   const Eigen::VectorXd& bound, const std::vector<bool>& movable,
                                   double threshold) {
  std::vector<bool> rows(movable.size(), false);
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const auto row = static_cast<Eigen::Index>(j);
    rows[j] = movable[j] && trace_of_solution[row] - bound[row] > threshold;
  }
  return rows;
}

struct ActiveSetStep {
  Eigen::VectorXd force;  // lambda (zero off the active set)
  ConjugateGradientResult inner;
  double projected_gradient_norm = 0.0;  // ||P (b - K u)||
};

/// One step of the method: `solution` becomes the minimiser of the energy on B_A u = c_A, from
/// the nearest point of that set to it, to `tolerance` (the file comment).
ActiveSetStep solve_on_active_set(const MultigridStiffnessSolver& stiffness,
                                  const ActiveConstraints& constraints, const Eigen::VectorXd& load,
                                  const Eigen::VectorXd& bound, double tolerance,
                                  Eigen::VectorXd& solution) {
  ActiveSetStep outcome;
  outcome.inner.status = ConjugateGradientStatus::converged;
  const Eigen::VectorXd start = constraints.move_onto(solution, bound);  // u_0
  Eigen::VectorXd product;
  stiffness.stiffness().apply(start, product);
  const Eigen::VectorXd load_part = constraints.project(load);
  const Eigen::VectorXd stiffness_part = constraints.project(product);
  const Eigen::VectorXd right_hand_side = load_part - stiffness_part;
  const double scale = load.norm() + product.norm();  // the terms of K u + B' lambda = b
  Eigen::VectorXd step_in_kernel = Eigen::VectorXd::Zero(stiffness.size());
  if (right_hand_side.norm() > tolerance * scale) {
    const ProjectedStiffness projected_stiffness(stiffness.stiffness(), constraints);
    const ProjectedPreconditioner projected_preconditioner(stiffness.preconditioner(), constraints);
    outcome.inner =
        stiffness.solve_with(projected_stiffness, projected_preconditioner, right_hand_side,
                             step_in_kernel, tolerance * scale / right_hand_side.norm());
  }
  solution = start + step_in_kernel;
  stiffness.stiffness().apply(solution, product);
  const Eigen::VectorXd residual = load - product;  // B_A' lambda_A
  outcome.projected_gradient_norm = constraints.project(residual).norm();
  const Eigen::VectorXd active_force = constraints.multipliers(residual);
  outcome.force = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(bound.size()));
  for (std::size_t k = 0; k < constraints.rows().size(); ++k) {
    outcome.force[constraints.rows()[k]] = active_force[static_cast<Eigen::Index>(k)];
  }
  return outcome;
}

/// The next active set: the active rows whose force is not negative beyond the noise, and the
/// inactive ones that penetrate beyond it (the file comment).
std::vector<bool> next_active_set(const std::vector<bool>& active, const Eigen::VectorXd& force,
                                  const Eigen::VectorXd& trace_of_solution,
                                  const Eigen::VectorXd& bound, const std::vector<bool>& movable,
                                  double tolerance) {
  const double force_threshold = tolerance * force.lpNorm<Eigen::Infinity>();
  std::vector<bool> next = penetrating_rows(
      trace_of_solution, bound, movable, tolerance * trace_of_solution.lpNorm<Eigen::Infinity>());
  for (std::size_t j = 0; j < next.size(); ++j) {
    if (active[j]) next[j] = force[static_cast<Eigen::Index>(j)] >= -force_threshold;
  }
  return next;
}

void check_sizes(const MultigridStiffnessSolver& stiffness, const SparseMatrix& trace,
                 const Eigen::VectorXd& load, const Eigen::VectorXd& bound,
                 const Eigen::VectorXd& initial_displacement) {
  if (trace.cols() != stiffness.size() || load.size() != stiffness.size() ||
      bound.size() != trace.rows() || initial_displacement.size() != stiffness.size()) {
    throw std::invalid_argument("solve_primal_contact: the sizes of K, B, b, c and u differ");
  }
}

}  // namespace

MultigridStiffnessSolver::MultigridStiffnessSolver(
    SparseMatrix&& lower, const Eigen::MatrixXd& near_null_space, const std::vector<int>& dof_nodes,
    const std::vector<Eigen::Vector3d>& node_positions, double relative_tolerance,
    std::string body_name)
    : multigrid_(std::make_unique<AlgebraicMultigrid>(std::move(lower), near_null_space, dof_nodes,
                                                      node_positions)),
      relative_tolerance_(relative_tolerance),
      body_name_(std::move(body_name)) {}

MultigridStiffnessSolver::~MultigridStiffnessSolver() = default;

int MultigridStiffnessSolver::size() const {
  return multigrid_->size();
}

const LinearOperator& MultigridStiffnessSolver::stiffness() const {
  return multigrid_->fine_operator();
}

SparseMatrix MultigridStiffnessSolver::stiffness_matrix() const {
  return multigrid_->fine_operator().lower();
}

const Preconditioner& MultigridStiffnessSolver::preconditioner() const {
  return *multigrid_;
}

double MultigridStiffnessSolver::setup_seconds() const {
  return multigrid_->setup_seconds();
}

Eigen::VectorXd MultigridStiffnessSolver::solve(const Eigen::VectorXd& right_hand_side,
                                                const Eigen::VectorXd& initial,
                                                double relative_tolerance) const {
  Eigen::VectorXd solution = initial;
  const ConjugateGradientResult result =
      solve_with(stiffness(), preconditioner(), right_hand_side, solution,
                 relative_tolerance > 0.0 ? relative_tolerance : relative_tolerance_);
  if (result.status != ConjugateGradientStatus::converged) {
    throw std::runtime_error("body '" + body_name_ +
                             "': the stiffness solve failed: " + describe(result));
  }
  return solution;
}

ConjugateGradientResult MultigridStiffnessSolver::solve_with(const LinearOperator& matrix,
                                                             const Preconditioner& preconditioner,
                                                             const Eigen::VectorXd& right_hand_side,
                                                             Eigen::VectorXd& solution,
                                                             double relative_tolerance) const {
  ConjugateGradientOptions options;
  options.relative_tolerance = relative_tolerance;
  options.maximum_iterations = maximum_conjugate_gradient_iterations;
  const ConjugateGradientResult result =
      solve_conjugate_gradient(matrix, preconditioner, right_hand_side, solution, options);
  ++solve_count_;
  iterations_ += result.iterations;
  return result;
}

PrimalContactResult solve_primal_contact(const MultigridStiffnessSolver& stiffness,
                                         const SparseMatrix& trace, const Eigen::VectorXd& load,
                                         const Eigen::VectorXd& bound,
                                         const Eigen::VectorXd& initial_displacement,
                                         PrimalContactState& state,
                                         const PrimalContactOptions& options) {
  check_sizes(stiffness, trace, load, bound, initial_displacement);
  const double tolerance = std::max(options.relative_tolerance, stiffness.relative_tolerance());
  const RowMajorSparseMatrix row_trace(trace);
  const std::vector<bool> movable = movable_rows(row_trace);
  const bool warm =
      state.displacement.size() == stiffness.size() && state.active.size() == movable.size();
  Eigen::VectorXd solution = warm ? state.displacement : initial_displacement;
  std::vector<bool> active =
      warm ? state.active : penetrating_rows(trace * solution, bound, movable, 0.0);

  PrimalContactResult result;
  // the last iterate, also when the solve stops without converging
  const auto record = [&](const Eigen::VectorXd& force, const Eigen::VectorXd& trace_of_solution) {
    result.solution = force.cwiseMax(0.0);
    result.gradient = bound - trace_of_solution;
    result.displacement = solution;
  };
  record(Eigen::VectorXd::Zero(trace.rows()), trace * solution);
  // the steps to a loose tolerance while the active set changes, then the last one to the final
  double step_tolerance = std::max(tolerance, options.changing_set_tolerance);
  std::unique_ptr<const ActiveConstraints> constraints;  // of `active`; kept while it repeats
  for (int step = 1; step <= options.maximum_active_set_steps; ++step) {
    result.iterations = step;
    if (step > options.inexact_steps) step_tolerance = tolerance;
    if (!constraints) {
      constraints = std::make_unique<const ActiveConstraints>(row_trace, indices_of(active),
                                                              stiffness.body_name());
    }
    const ActiveSetStep outcome =
        solve_on_active_set(stiffness, *constraints, load, bound, step_tolerance, solution);
    result.operator_applications += outcome.inner.iterations;
    result.projected_gradient_norm = outcome.projected_gradient_norm;
    if (outcome.inner.status != ConjugateGradientStatus::converged) {
      result.status = outcome.inner.status == ConjugateGradientStatus::breakdown
                          ? QpStatus::breakdown
                          : QpStatus::not_converged;
      result.message = "active set step " + std::to_string(step) + ": " + describe(outcome.inner);
      return result;
    }
    const Eigen::VectorXd trace_of_solution = trace * solution;
    const std::vector<bool> next =
        next_active_set(active, outcome.force, trace_of_solution, bound, movable, step_tolerance);
    record(outcome.force, trace_of_solution);
    if (next == active && step_tolerance > tolerance) {
      step_tolerance = tolerance;  // the same set again, to the final tolerance
    } else if (next == active) {
      result.status = QpStatus::converged;
      state.displacement = solution;
      state.active = active;
      state.contact_force = result.solution;
      return result;
    } else {
      active = next;
      constraints.reset();
    }
  }
  result.message = "the active set still changed after " +
                   std::to_string(options.maximum_active_set_steps) + " steps";
  return result;
}

}  // namespace robin
