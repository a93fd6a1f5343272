#pragma once
// Preconditioned conjugate gradients (Hestenes-Stiefel) for A x = b with A symmetric positive
// definite, applied as a LinearOperator, and a symmetric positive definite preconditioner M^{-1}.
//
// From x_0 (the initial guess): r_0 = b - A x_0, z_0 = M^{-1} r_0, p_0 = z_0, and for k = 0, 1, ..
//   alpha_k = (r_k, z_k) / (p_k, A p_k),  x_{k+1} = x_k + alpha_k p_k,  r_{k+1} = r_k - alpha_k A
//   p_k, z_{k+1} = M^{-1} r_{k+1},  beta_k = (r_{k+1}, z_{k+1}) / (r_k, z_k),  p_{k+1} = z_{k+1} +
//   beta_k p_k.
// x_k minimises the A-norm of the error over x_0 + the Krylov space of M^{-1} A and M^{-1} r_0.
// Stopping test: ||b - A x_k|| <= tolerance ||b|| (Euclidean norms). The recursively updated r_k
// drifts from the true residual in floating point; when it passes the test, the true residual
// b - A x_k is computed, and the iteration stops only if that passes too (otherwise it restarts
// from the true residual with p = M^{-1} r).

#include <Eigen/Core>

#include "numerics/linear_operator.hpp"

namespace robin {

/// z = M^{-1} r for a symmetric positive definite M (the PCG requirement: (x, M^{-1} y) =
/// (y, M^{-1} x) and (x, M^{-1} x) > 0 for x != 0).
class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  virtual int size() const = 0;
  /// correction = M^{-1} residual; `correction` is resized by the callee.
  virtual void apply(const Eigen::VectorXd& residual, Eigen::VectorXd& correction) const = 0;
};

/// M = I: plain conjugate gradients.
class IdentityPreconditioner final : public Preconditioner {
 public:
  explicit IdentityPreconditioner(int size) : size_(size) {}
  int size() const override { return size_; }
  void apply(const Eigen::VectorXd& residual, Eigen::VectorXd& correction) const override {
    correction = residual;
  }

 private:
  int size_;
};

enum class ConjugateGradientStatus {
  converged,        // ||b - A x|| <= tolerance ||b|| (the true residual)
  iteration_limit,  // maximum_iterations done without converging
  breakdown,        // (p, A p) <= 0 or (r, M^{-1} r) <= 0: A or M^{-1} not positive definite
};

struct ConjugateGradientOptions {
  double relative_tolerance = 1e-10;
  int maximum_iterations = 1000;
};

struct ConjugateGradientResult {
  ConjugateGradientStatus status = ConjugateGradientStatus::iteration_limit;
  int iterations = 0;              // products with A inside the loop (one per iteration)
  double relative_residual = 0.0;  // ||b - A x|| / ||b|| at return (the last computed residual)
};

/// Solves A x = b; `solution` holds the initial guess on entry (resized to zeros when its size
/// differs from b's) and the last iterate on return. b = 0 returns x = 0 at once, converged.
/// Throws std::invalid_argument when the sizes of A, M and b differ.
ConjugateGradientResult solve_conjugate_gradient(const LinearOperator& matrix,
                                                 const Preconditioner& preconditioner,
                                                 const Eigen::VectorXd& right_hand_side,
                                                 Eigen::VectorXd& solution,
                                                 const ConjugateGradientOptions& options = {});

}  // namespace robin
