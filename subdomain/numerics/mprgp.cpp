#include "numerics/mprgp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

namespace robin {
namespace {

/// Power iterations for ||A|| and the factor that makes the (lower) estimate an upper bias.
constexpr int norm_estimate_iterations = 10;
constexpr double norm_safety_factor = 1.05;
/// How many times the recurrence gradient may pass the test and fail it once recomputed
/// (rounding drift) before the tolerance is declared unattainable.
constexpr int max_gradient_replacements = 10;

std::string format_number(double value) {
  std::ostringstream stream;
  stream.precision(3);
  stream << value;
  return stream.str();
}

/// Norms of the parts of the gradient at x: the chopped gradient beta, phi~'phi and g^P.
struct GradientSplit {
  double chopped_squared = 0.0;        // ||beta||^2
  double reduced_free_dot_free = 0.0;  // phi~'phi
  double projected_squared = 0.0;      // ||g^P||^2 = ||phi||^2 + ||beta||^2
};

void check_arguments(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                     const Eigen::VectorXd& lower, const Eigen::VectorXd& initial,
                     const MprgpParameters& parameters) {
  const Eigen::Index size = matrix.size();
  if (right_hand_side.size() != size || lower.size() != size || initial.size() != size) {
    throw std::invalid_argument("solve_mprgp: operator of size " + std::to_string(size) +
                                " but right-hand side, lower bound and start of sizes " +
                                std::to_string(right_hand_side.size()) + ", " +
                                std::to_string(lower.size()) + ", " +
                                std::to_string(initial.size()));
  }
  if (!(parameters.step_factor > 0.0 && parameters.step_factor <= 2.0) ||
      !(parameters.proportioning > 0.0) || !(parameters.relative_tolerance >= 0.0) ||
      !(parameters.absolute_tolerance >= 0.0) || parameters.max_iterations < 0) {
    throw std::invalid_argument(
        "solve_mprgp: parameters need step_factor in (0, 2], proportioning > 0, "
        "non-negative tolerances and max_iterations");
  }
  if (lower.hasNaN() || (lower.array() == std::numeric_limits<double>::infinity()).any()) {
    throw std::invalid_argument("solve_mprgp: the lower bound has NaN or +infinity entries");
  }
}

/// The MPRGP iteration on one problem. The solution and gradient live in the result.
class MprgpIteration {
 public:
  MprgpIteration(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                 const Eigen::VectorXd& lower, const MprgpParameters& parameters,
                 MprgpResult& result)
      : matrix_(matrix),
        right_hand_side_(right_hand_side),
        lower_(lower),
        parameters_(parameters),
        result_(result),
        x_(result.solution),
        gradient_(result.gradient) {}

  void run(const Eigen::VectorXd& initial, double expansion_step);
  void update_threshold();

 private:
  bool is_free(Eigen::Index i) const { return x_[i] > lower_[i]; }
  GradientSplit split_gradient() const;
  void compute_free_gradient(Eigen::VectorXd& free_gradient) const;
  void recompute_gradient();
  double feasible_step_length(Eigen::Index& blocking_index) const;
  bool conjugate_gradient_or_expansion();
  bool null_direction_step();
  double null_curvature(const Eigen::VectorXd& direction) const;
  void expansion(double feasible_step, Eigen::Index blocking_index);
  bool proportioning();
  bool confirm_convergence();
  bool stop(QpStatus status, const std::string& message);

  const LinearOperator& matrix_;
  const Eigen::VectorXd& right_hand_side_;
  const Eigen::VectorXd& lower_;
  const MprgpParameters& parameters_;
  MprgpResult& result_;
  Eigen::VectorXd& x_;
  Eigen::VectorXd& gradient_;
  Eigen::VectorXd direction_;       // p (or the proportioning direction d = beta)
  Eigen::VectorXd product_;         // A p
  Eigen::VectorXd free_gradient_;   // phi, scratch
  double expansion_step_ = 0.0;     // alpha_bar
  double threshold_ = 0.0;          // stopping tolerance on ||g^P||
  int gradient_replacements_ = 0;   // recurrence gradients replaced by A x - b
  bool gradient_is_fresh_ = false;  // g was computed as A x - b, not by the recurrence
};

GradientSplit MprgpIteration::split_gradient() const {
  GradientSplit split;
  for (Eigen::Index i = 0; i < x_.size(); ++i) {
    const double g = gradient_[i];
    if (is_free(i)) {
      // phi~_i = min((x_i - l_i) / alpha_bar, phi_i)
      split.reduced_free_dot_free += std::min((x_[i] - lower_[i]) / expansion_step_, g) * g;
      split.projected_squared += g * g;
    } else if (g < 0.0) {
      split.chopped_squared += g * g;
      split.projected_squared += g * g;
    }
  }
  return split;
}

void MprgpIteration::compute_free_gradient(Eigen::VectorXd& free_gradient) const {
  free_gradient.resize(x_.size());
  for (Eigen::Index i = 0; i < x_.size(); ++i) free_gradient[i] = is_free(i) ? gradient_[i] : 0.0;
}

void MprgpIteration::recompute_gradient() {
  // g = A x - b
  matrix_.apply(x_, gradient_);
  ++result_.operator_applications;
  gradient_ -= right_hand_side_;
  gradient_is_fresh_ = true;
}

/// Largest alpha with x - alpha p >= l; the index that blocks it (or -1 when unbounded).
double MprgpIteration::feasible_step_length(Eigen::Index& blocking_index) const {
  double step = std::numeric_limits<double>::infinity();
  blocking_index = -1;
  for (Eigen::Index i = 0; i < x_.size(); ++i) {
    if (direction_[i] > 0.0) {
      const double candidate = (x_[i] - lower_[i]) / direction_[i];
      if (candidate < step) {
        step = candidate;
        blocking_index = i;
      }
    }
  }
  return step;
}

/// Records the outcome; the returned gradient is always A x - b, not the recurrence.
bool MprgpIteration::stop(QpStatus status, const std::string& message) {
  result_.status = status;
  result_.message = message;
  if (!gradient_is_fresh_) {
    recompute_gradient();
    result_.projected_gradient_norm = std::sqrt(split_gradient().projected_squared);
  }
  return false;
}

void MprgpIteration::run(const Eigen::VectorXd& initial, double expansion_step) {
  expansion_step_ = expansion_step;
  x_ = initial.cwiseMax(lower_);
  recompute_gradient();
  compute_free_gradient(direction_);
  while (true) {
    const GradientSplit split = split_gradient();
    result_.projected_gradient_norm = std::sqrt(split.projected_squared);
    update_threshold();
    if (!std::isfinite(result_.projected_gradient_norm) || !std::isfinite(x_.sum())) {
      stop(QpStatus::breakdown, "non-finite iterate or gradient after " +
                                    std::to_string(result_.iterations) + " iterations");
      return;
    }
    if (result_.projected_gradient_norm <= threshold_) {
      if (!confirm_convergence()) return;
      continue;
    }
    if (result_.iterations >= parameters_.max_iterations) {
      stop(QpStatus::not_converged,
           "no convergence in " + std::to_string(parameters_.max_iterations) +
               " iterations: ||g^P|| = " + format_number(result_.projected_gradient_norm) + " > " +
               format_number(threshold_));
      return;
    }
    ++result_.iterations;
    const double gamma = parameters_.proportioning;
    // Proportional iterate: ||beta||^2 <= Gamma^2 phi~'phi.
    const bool proceed = split.chopped_squared <= gamma * gamma * split.reduced_free_dot_free
                             ? conjugate_gradient_or_expansion()
                             : proportioning();
    if (!proceed) return;
  }
}

/// threshold = max(relative_tolerance * scale, absolute_tolerance) with scale = ||b||, or, for
/// a solution-scaled tolerance, ||A|| ||x - l|| over the finite bounds (||b|| while that is 0).
void MprgpIteration::update_threshold() {
  if (parameters_.iterate_threshold) {
    threshold_ = std::max(parameters_.iterate_threshold(x_), parameters_.absolute_tolerance);
    return;
  }
  double scale = right_hand_side_.norm();
  if (parameters_.solution_scaled_tolerance) {
    double distance_squared = 0.0;
    for (Eigen::Index i = 0; i < x_.size(); ++i) {
      if (std::isfinite(lower_[i])) distance_squared += (x_[i] - lower_[i]) * (x_[i] - lower_[i]);
    }
    const double solution_scale =
        std::sqrt(distance_squared) / expansion_step_ * parameters_.step_factor;
    if (solution_scale > 0.0) scale = solution_scale;
  }
  threshold_ = std::max(parameters_.relative_tolerance * scale, parameters_.absolute_tolerance);
}

/// Called at ||g^P|| <= threshold: converged when g is A x - b; otherwise g came from the
/// recurrence and may have drifted, so it is replaced by A x - b and the CG sequence restarts.
/// Returns false when the iteration stops.
bool MprgpIteration::confirm_convergence() {
  if (gradient_is_fresh_) return stop(QpStatus::converged, "");
  if (++gradient_replacements_ > max_gradient_replacements) {
    return stop(QpStatus::not_converged,
                "||g^P|| = " + format_number(result_.projected_gradient_norm) +
                    " of the recurrence is not confirmed by A x - b: the tolerance " +
                    format_number(threshold_) + " is below the attainable accuracy");
  }
  recompute_gradient();
  compute_free_gradient(direction_);
  return true;
}

bool MprgpIteration::conjugate_gradient_or_expansion() {
  // Ap = A p
  matrix_.apply(direction_, product_);
  ++result_.operator_applications;
  const double curvature = direction_.dot(product_);
  if (!(curvature > 0.0) || !std::isfinite(curvature)) {
    // 0 >= p'Ap >= -null_curvature is zero to round-off (a positive p'Ap, however small, keeps
    // the conjugate gradient step); below that, or not finite, A is not positive semidefinite.
    if (curvature <= 0.0 && curvature >= -null_curvature(direction_)) return null_direction_step();
    return stop(QpStatus::breakdown, "p'Ap = " + format_number(curvature) +
                                         " <= 0 in a conjugate gradient step: the operator is "
                                         "not positive definite on the free set");
  }
  // alpha_cg = g'p / p'Ap, alpha_f = max{alpha : x - alpha p >= l}
  const double conjugate_gradient_step = gradient_.dot(direction_) / curvature;
  if (!std::isfinite(conjugate_gradient_step)) {
    return stop(QpStatus::breakdown, "non-finite conjugate gradient step length");
  }
  Eigen::Index blocking_index = -1;
  const double feasible_step = feasible_step_length(blocking_index);
  if (conjugate_gradient_step > feasible_step) {
    expansion(feasible_step, blocking_index);
    return true;
  }
  // x -= alpha_cg p, g -= alpha_cg Ap (clamped against rounding below the bound)
  x_ -= conjugate_gradient_step * direction_;
  x_ = x_.cwiseMax(lower_);
  gradient_ -= conjugate_gradient_step * product_;
  gradient_is_fresh_ = false;
  // p = phi - (phi'Ap / p'Ap) p
  compute_free_gradient(free_gradient_);
  const double conjugation = free_gradient_.dot(product_) / curvature;
  direction_ *= -conjugation;
  direction_ += free_gradient_;
  ++result_.conjugate_gradient_steps;
  return true;
}

/// The size of p'Ap that round-off alone gives for p in the null space of A: 1e-13 ||A|| p'p
/// (||A|| = step_factor / expansion step). A semidefinite A whose smallest positive eigenvalue
/// is below 1e-13 ||A|| is not told from a singular one.
double MprgpIteration::null_curvature(const Eigen::VectorXd& direction) const {
  return 1e-13 * parameters_.step_factor / expansion_step_ * direction.squaredNorm();
}

/// p'Ap <= 0 is zero to round-off: p lies in the null space of A on the free set (A semidefinite,
/// e.g. the dual contact operator of a body whose trace has fewer degrees of freedom than the
/// constraint has rows), where q(x - t p) = q(x) - t g'p is linear in t. With g'p != 0 the
/// iterate moves along the descent direction to the nearest bound (an expansion step; none:
/// the problem is unbounded). With g'p = 0 too, p is of no use: the conjugate directions
/// restart from the free gradient.
bool MprgpIteration::null_direction_step() {
  const double slope = gradient_.dot(direction_);
  if (std::abs(slope) <=
      64.0 * std::numeric_limits<double>::epsilon() * gradient_.norm() * direction_.norm()) {
    compute_free_gradient(direction_);
    return true;
  }
  if (slope < 0.0) {  // -p is then the descent direction: g'p > 0
    direction_ = -direction_;
    product_ = -product_;
  }
  Eigen::Index blocking_index = -1;
  const double feasible_step = feasible_step_length(blocking_index);
  if (blocking_index < 0) {
    return stop(QpStatus::breakdown,
                "the objective decreases without bound along a null direction of the operator "
                "(p'Ap = 0, g'p != 0, no bound in the way): the problem is unbounded");
  }
  // product_ = A p is zero to round-off; expansion moves g along it as in a CG step.
  expansion(feasible_step, blocking_index);
  return true;
}

void MprgpIteration::expansion(double feasible_step, Eigen::Index blocking_index) {
  // x_half = x - alpha_f p, g_half = g - alpha_f Ap
  x_ -= feasible_step * direction_;
  x_ = x_.cwiseMax(lower_);
  x_[blocking_index] = lower_[blocking_index];
  gradient_ -= feasible_step * product_;
  // x = P(x_half - alpha_bar phi(x_half)), g = A x - b, p = phi(x)
  compute_free_gradient(free_gradient_);
  x_ -= expansion_step_ * free_gradient_;
  x_ = x_.cwiseMax(lower_);
  recompute_gradient();
  compute_free_gradient(direction_);
  ++result_.expansion_steps;
}

bool MprgpIteration::proportioning() {
  // d = beta (non-positive, on the active set)
  for (Eigen::Index i = 0; i < x_.size(); ++i) {
    direction_[i] = is_free(i) ? 0.0 : std::min(gradient_[i], 0.0);
  }
  // Ad = A d
  matrix_.apply(direction_, product_);
  ++result_.operator_applications;
  const double curvature = direction_.dot(product_);
  if (!(curvature > 0.0) || !std::isfinite(curvature)) {
    return stop(QpStatus::breakdown, "d'Ad = " + format_number(curvature) +
                                         " <= 0 in a proportioning step: the operator is not "
                                         "positive definite");
  }
  // x -= alpha d, g -= alpha Ad with alpha = d'g / d'Ad (x only increases: stays feasible)
  const double step = direction_.dot(gradient_) / curvature;
  x_ -= step * direction_;
  gradient_ -= step * product_;
  gradient_is_fresh_ = false;
  compute_free_gradient(direction_);
  ++result_.proportioning_steps;
  return true;
}

}  // namespace

std::string to_string(QpStatus status) {
  switch (status) {
    case QpStatus::converged:
      return "converged";
    case QpStatus::not_converged:
      return "not converged";
    case QpStatus::breakdown:
      return "breakdown";
  }
  return "unknown";
}

double estimate_operator_norm(const LinearOperator& matrix, int iterations, int& applications) {
  const Eigen::Index size = matrix.size();
  if (size == 0) return 0.0;
  // Deterministic start with all frequencies present: portable minstd values in [-1, 1].
  std::minstd_rand generator(20050101u);
  Eigen::VectorXd vector(size);
  for (Eigen::Index i = 0; i < size; ++i) {
    const auto raw = static_cast<double>(generator() - std::minstd_rand::min());
    vector[i] = 2.0 * raw / static_cast<double>(std::minstd_rand::max() - 1) - 1.0;
  }
  vector.normalize();
  Eigen::VectorXd product;
  double norm = 0.0;
  for (int iteration = 0; iteration < std::max(iterations, 1); ++iteration) {
    // w = A v, ||A|| >= ||w|| for ||v|| = 1
    matrix.apply(vector, product);
    ++applications;
    norm = product.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return norm;
    vector = product / norm;
  }
  return norm_safety_factor * norm;
}

MprgpResult solve_mprgp(const LinearOperator& matrix, const Eigen::VectorXd& right_hand_side,
                        const Eigen::VectorXd& lower, const Eigen::VectorXd& initial,
                        const MprgpParameters& parameters) {
  check_arguments(matrix, right_hand_side, lower, initial, parameters);
  MprgpResult result;
  if (matrix.size() == 0) {
    result.status = QpStatus::converged;
    return result;
  }
  result.operator_norm =
      parameters.operator_norm > 0.0
          ? parameters.operator_norm
          : estimate_operator_norm(matrix, norm_estimate_iterations, result.operator_applications);
  if (!(result.operator_norm > 0.0) || !std::isfinite(result.operator_norm)) {
    result.status = QpStatus::breakdown;
    result.message = "the estimate of ||A|| is " + format_number(result.operator_norm) +
                     ": the operator is zero or not finite";
    result.solution = initial.cwiseMax(lower);
    // g = A x - b
    matrix.apply(result.solution, result.gradient);
    ++result.operator_applications;
    result.gradient -= right_hand_side;
    return result;
  }
  MprgpIteration iteration(matrix, right_hand_side, lower, parameters, result);
  iteration.run(initial, parameters.step_factor / result.operator_norm);
  return result;
}

}  // namespace robin
