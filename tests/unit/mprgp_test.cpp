// MPRGP against independent solutions: an exact enumeration of all 2^n active sets (dense
// LDLT) for small random problems, constructed KKT points for the degenerate cases, and a
// primal-dual active set iteration (sparse LDLT) for a large matrix-free obstacle problem.

#include "numerics/mprgp.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace robin {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// A = Q' D Q with Q orthogonal (QR of a random matrix) and D log-spaced in
/// [scale, scale * condition]: cond(A) = condition exactly (up to rounding).
MatrixXd random_spd(int size, double condition, double scale, std::mt19937_64& generator) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const MatrixXd random = MatrixXd::NullaryExpr(size, size, [&] { return uniform(generator); });
  const MatrixXd orthogonal = Eigen::HouseholderQR<MatrixXd>(random).householderQ();
  VectorXd eigenvalues(size);
  for (int i = 0; i < size; ++i) {
    const double fraction = size == 1 ? 0.0 : static_cast<double>(i) / (size - 1);
    eigenvalues[i] = scale * std::pow(condition, fraction);
  }
  const MatrixXd matrix = orthogonal.transpose() * eigenvalues.asDiagonal() * orthogonal;
  return 0.5 * (matrix + matrix.transpose());
}

VectorXd random_vector(int size, std::mt19937_64& generator) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  return VectorXd::NullaryExpr(size, [&] { return uniform(generator); });
}

struct EnumeratedSolution {
  VectorXd solution;
  double violation = std::numeric_limits<double>::infinity();
};

/// Candidate for the active set `mask`: x_S = l_S, A_FF x_F = b_F - A_FS l_S.
VectorXd solve_with_active_set(const MatrixXd& matrix, const VectorXd& right_hand_side,
                               const VectorXd& lower, unsigned mask) {
  const int size = static_cast<int>(matrix.rows());
  std::vector<int> free, active;
  for (int i = 0; i < size; ++i) ((mask & (1u << i)) ? active : free).push_back(i);
  VectorXd candidate = lower;
  if (free.empty()) return candidate;
  const int free_count = static_cast<int>(free.size());
  MatrixXd free_block(free_count, free_count);
  VectorXd free_right_hand_side(free_count);
  for (int r = 0; r < free_count; ++r) {
    free_right_hand_side[r] = right_hand_side[free[r]];
    for (const int j : active) free_right_hand_side[r] -= matrix(free[r], j) * lower[j];
    for (int c = 0; c < free_count; ++c) free_block(r, c) = matrix(free[r], free[c]);
  }
  const VectorXd free_solution = free_block.ldlt().solve(free_right_hand_side);
  for (int r = 0; r < free_count; ++r) candidate[free[r]] = free_solution[r];
  return candidate;
}

/// The exact minimiser by enumeration of all 2^n active sets: the candidate with the smallest
/// KKT violation max(l_F - x_F, -g_S) (scaled) is the solution; violation ~ 0 certifies it.
EnumeratedSolution solve_by_enumeration(const MatrixXd& matrix, const VectorXd& right_hand_side,
                                        const VectorXd& lower) {
  const int size = static_cast<int>(matrix.rows());
  EnumeratedSolution best;
  for (unsigned mask = 0; mask < (1u << size); ++mask) {
    const VectorXd candidate = solve_with_active_set(matrix, right_hand_side, lower, mask);
    const VectorXd gradient = matrix * candidate - right_hand_side;
    const double primal_scale = std::max(candidate.norm(), 1e-300);
    const double dual_scale = std::max(right_hand_side.norm(), 1e-300);
    double violation = 0.0;
    for (int i = 0; i < size; ++i) {
      violation = (mask & (1u << i))
                      ? std::max(violation, -gradient[i] / dual_scale)
                      : std::max(violation, (lower[i] - candidate[i]) / primal_scale);
    }
    if (violation < best.violation) best = {candidate, violation};
  }
  return best;
}

/// Lower bounds mixing 0, bounds near the unconstrained solution u and inactive ones.
VectorXd random_lower_bound(const MatrixXd& matrix, const VectorXd& right_hand_side,
                            std::mt19937_64& generator) {
  const VectorXd unconstrained = matrix.ldlt().solve(right_hand_side);
  const double magnitude = unconstrained.cwiseAbs().maxCoeff();
  std::uniform_int_distribution<int> kind(0, 2);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  VectorXd lower(matrix.rows());
  for (Eigen::Index i = 0; i < lower.size(); ++i) {
    switch (kind(generator)) {
      case 0:
        lower[i] = 0.0;
        break;
      case 1:
        lower[i] = unconstrained[i] + 0.5 * magnitude * uniform(generator);
        break;
      default:
        lower[i] = unconstrained[i] - magnitude * (1.0 + uniform(generator));
    }
  }
  return lower;
}

/// KKT residuals of the returned point, computed here from A, b, l (not from the result):
/// x >= l, ||g^P|| and |g'(x - l)| relative to ||b|| (and ||b|| ||x - l||).
void expect_kkt(const MatrixXd& matrix, const VectorXd& right_hand_side, const VectorXd& lower,
                const MprgpResult& result, double tolerance) {
  const VectorXd& x = result.solution;
  const VectorXd gradient = matrix * x - right_hand_side;
  EXPECT_GE((x - lower).minCoeff(), 0.0) << "primal infeasibility";
  double projected_squared = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double g = x[i] > lower[i] ? gradient[i] : std::min(gradient[i], 0.0);
    projected_squared += g * g;
  }
  const double scale = right_hand_side.norm();
  EXPECT_LE(std::sqrt(projected_squared), tolerance * scale) << "||g^P||";
  EXPECT_LE(std::abs(gradient.dot(x - lower)),
            tolerance * scale * std::max((x - lower).norm(), 1e-300))
      << "complementarity";
  EXPECT_LE((result.gradient - gradient).norm(), 1e-13 * (scale + matrix.norm() * x.norm()))
      << "returned gradient is not A x - b";
}

/// Counts products independently of the solver's own counter.
class CountingOperator final : public LinearOperator {
 public:
  explicit CountingOperator(MatrixXd matrix) : matrix_(std::move(matrix)) {}
  int size() const override { return static_cast<int>(matrix_.rows()); }
  void apply(const VectorXd& x, VectorXd& y) const override {
    ++applications;
    y.noalias() = matrix_ * x;
  }
  mutable int applications = 0;

 private:
  MatrixXd matrix_;
};

TEST(Mprgp, RandomProblemsMatchActiveSetEnumeration) {
  for (const double condition : {1.0, 1e2, 1e4}) {
    int total_iterations = 0, most_iterations = 0, problems = 0;
    double worst_error = 0.0;
    for (int size = 1; size <= 10; ++size) {
      for (int seed = 0; seed < 6; ++seed) {
        std::mt19937_64 generator(1000 * size + seed);
        const MatrixXd matrix = random_spd(size, condition, 3.7, generator);
        const VectorXd right_hand_side = random_vector(size, generator);
        const VectorXd lower = random_lower_bound(matrix, right_hand_side, generator);
        const EnumeratedSolution exact = solve_by_enumeration(matrix, right_hand_side, lower);
        ASSERT_LE(exact.violation, 1e-12) << "the enumeration found no KKT point";

        const CountingOperator counting(matrix);
        const MprgpResult result =
            solve_mprgp(counting, right_hand_side, lower, VectorXd::Zero(size));
        SCOPED_TRACE("n = " + std::to_string(size) + ", cond = " + std::to_string(condition) +
                     ", seed = " + std::to_string(seed));
        ASSERT_EQ(result.status, QpStatus::converged) << result.message;
        const double scale =
            std::max(exact.solution.norm(), right_hand_side.norm() / matrix.norm());
        const double error = (result.solution - exact.solution).norm() / scale;
        EXPECT_LE(error, 1e-9);
        worst_error = std::max(worst_error, error);
        expect_kkt(matrix, right_hand_side, lower, result, 1e-10);
        EXPECT_EQ(result.operator_applications, counting.applications);
        EXPECT_EQ(result.iterations, result.conjugate_gradient_steps + result.expansion_steps +
                                         result.proportioning_steps);
        total_iterations += result.iterations;
        most_iterations = std::max(most_iterations, result.iterations);
        ++problems;
      }
    }
    std::cout << "cond " << condition << ": " << problems << " problems, mean iterations "
              << static_cast<double>(total_iterations) / problems << ", max " << most_iterations
              << ", worst relative error " << worst_error << "\n";
  }
}

TEST(Mprgp, AllConstraintsActive) {
  std::mt19937_64 generator(7);
  const int size = 8;
  const MatrixXd matrix = random_spd(size, 1e3, 1.0, generator);
  const VectorXd lower = random_vector(size, generator);
  // g(l) = A l - b = multiplier > 0: x = l is the KKT point.
  const VectorXd multiplier = random_vector(size, generator).cwiseAbs().array() + 0.1;
  const VectorXd right_hand_side = matrix * lower - multiplier;
  const VectorXd initial = lower.array() + 1.0;
  const MprgpResult result = solve_mprgp(DenseOperator(matrix), right_hand_side, lower, initial);
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  EXPECT_LE((result.solution - lower).norm(), 1e-9 * lower.norm());
  expect_kkt(matrix, right_hand_side, lower, result, 1e-10);
  std::cout << "all active: " << result.iterations << " iterations\n";
}

TEST(Mprgp, NoConstraintActiveGivesUnconstrainedSolution) {
  std::mt19937_64 generator(8);
  const int size = 9;
  const MatrixXd matrix = random_spd(size, 1e4, 2.0, generator);
  const VectorXd right_hand_side = random_vector(size, generator);
  const VectorXd unconstrained = matrix.ldlt().solve(right_hand_side);
  const VectorXd lower = unconstrained.array() - unconstrained.cwiseAbs().maxCoeff();
  // Start with every constraint active: proportioning has to release them all.
  const MprgpResult result = solve_mprgp(DenseOperator(matrix), right_hand_side, lower, lower);
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  EXPECT_LE((result.solution - unconstrained).norm(), 1e-9 * unconstrained.norm());
  EXPECT_TRUE(((result.solution - lower).array() > 0.0).all());
  expect_kkt(matrix, right_hand_side, lower, result, 1e-10);
  std::cout << "none active: " << result.iterations << " iterations (" << result.proportioning_steps
            << " proportioning)\n";
}

TEST(Mprgp, MinusInfinityBoundsAreInactive) {
  std::mt19937_64 generator(9);
  const int size = 10;
  const MatrixXd matrix = random_spd(size, 1e3, 1.0, generator);
  const VectorXd right_hand_side = random_vector(size, generator);
  VectorXd lower = random_lower_bound(matrix, right_hand_side, generator);
  for (int i = 0; i < size; i += 2) lower[i] = -std::numeric_limits<double>::infinity();
  // Reference: the enumeration with the unbounded components replaced by a bound far below.
  VectorXd far_lower = lower;
  for (int i = 0; i < size; i += 2) far_lower[i] = -1e6;
  const EnumeratedSolution exact = solve_by_enumeration(matrix, right_hand_side, far_lower);
  ASSERT_LE(exact.violation, 1e-12);
  for (int i = 0; i < size; i += 2) ASSERT_GT(exact.solution[i], -1e5);
  const MprgpResult result =
      solve_mprgp(DenseOperator(matrix), right_hand_side, lower, VectorXd::Zero(size));
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  EXPECT_LE((result.solution - exact.solution).norm(), 1e-9 * exact.solution.norm());
}

TEST(Mprgp, UnattainableToleranceIsReportedAsNotConverged) {
  std::mt19937_64 generator(10);
  const MatrixXd matrix = random_spd(10, 1e4, 1.0, generator);
  const VectorXd right_hand_side = random_vector(10, generator);
  const VectorXd lower = random_lower_bound(matrix, right_hand_side, generator);
  MprgpParameters parameters;
  parameters.relative_tolerance = 1e-22;  // far below rounding of A x - b
  parameters.max_iterations = 5000;
  const MprgpResult result =
      solve_mprgp(DenseOperator(matrix), right_hand_side, lower, VectorXd::Zero(10), parameters);
  EXPECT_EQ(result.status, QpStatus::not_converged);
  EXPECT_FALSE(result.message.empty());
  std::cout << "tolerance 1e-22: " << result.iterations << " iterations: " << result.message
            << "\n";
}

/// x* with a chosen partition: strictly active (multiplier > 0), touching (x*_i = l_i with
/// g_i = 0: strict complementarity fails) and free. b = A x* - multiplier.
TEST(Mprgp, ObstacleExactlyTouching) {
  for (int seed = 0; seed < 8; ++seed) {
    std::mt19937_64 generator(100 + seed);
    const int size = 10;
    const MatrixXd matrix = random_spd(size, 1e3, 1.0, generator);
    const VectorXd solution = random_vector(size, generator);
    VectorXd lower = solution.array() - 1.0;
    VectorXd multiplier = VectorXd::Zero(size);
    // Even seeds: touching and free only (b = A x*, the unconstrained solution touches the
    // obstacle). Odd seeds: touching, strictly active and free.
    for (int i = 0; i < size; ++i) {
      const int kind = (i + seed) % 3;
      if (kind == 2) continue;  // free
      lower[i] = solution[i];
      if (seed % 2 == 1 && kind == 1) multiplier[i] = 0.5 + 0.1 * i;
    }
    const VectorXd right_hand_side = matrix * solution - multiplier;
    const EnumeratedSolution exact = solve_by_enumeration(matrix, right_hand_side, lower);
    ASSERT_LE((exact.solution - solution).norm(), 1e-10 * solution.norm());
    const MprgpResult result =
        solve_mprgp(DenseOperator(matrix), right_hand_side, lower, VectorXd::Zero(size));
    ASSERT_EQ(result.status, QpStatus::converged) << result.message;
    EXPECT_LE((result.solution - solution).norm(), 1e-9 * solution.norm()) << "seed " << seed;
    expect_kkt(matrix, right_hand_side, lower, result, 1e-10);
    std::cout << "touching, seed " << seed << ": " << result.iterations << " iterations ("
              << result.conjugate_gradient_steps << " CG, " << result.expansion_steps
              << " expansion, " << result.proportioning_steps << " proportioning)\n";
  }
}

TEST(Mprgp, WarmStartAtTheSolutionConvergesImmediately) {
  for (int seed = 0; seed < 10; ++seed) {
    std::mt19937_64 generator(200 + seed);
    const int size = 10;
    const MatrixXd matrix = random_spd(size, 1e4, 1.0, generator);
    const VectorXd right_hand_side = random_vector(size, generator);
    const VectorXd lower = random_lower_bound(matrix, right_hand_side, generator);
    const EnumeratedSolution exact = solve_by_enumeration(matrix, right_hand_side, lower);
    const MprgpResult result =
        solve_mprgp(DenseOperator(matrix), right_hand_side, lower, exact.solution);
    ASSERT_EQ(result.status, QpStatus::converged) << result.message;
    EXPECT_LE(result.iterations, 1) << "seed " << seed;
    std::cout << result.iterations << (seed == 9 ? " iterations from the exact solutions\n" : " ");
    EXPECT_LE((result.solution - exact.solution).norm(), 1e-9 * exact.solution.norm());
  }
}

TEST(Mprgp, EmptyProblemConvergesImmediately) {
  const MprgpResult result =
      solve_mprgp(DenseOperator(MatrixXd(0, 0)), VectorXd(0), VectorXd(0), VectorXd(0));
  EXPECT_EQ(result.status, QpStatus::converged);
  EXPECT_EQ(result.iterations, 0);
  EXPECT_EQ(result.operator_applications, 0);
  EXPECT_EQ(result.solution.size(), 0);
}

TEST(Mprgp, IterationLimitIsReportedAsNotConverged) {
  std::mt19937_64 generator(300);
  const MatrixXd matrix = random_spd(10, 1e4, 1.0, generator);
  const VectorXd right_hand_side = random_vector(10, generator);
  const VectorXd lower = random_lower_bound(matrix, right_hand_side, generator);
  MprgpParameters parameters;
  parameters.max_iterations = 2;
  const MprgpResult result =
      solve_mprgp(DenseOperator(matrix), right_hand_side, lower, VectorXd::Zero(10), parameters);
  EXPECT_EQ(result.status, QpStatus::not_converged);
  EXPECT_EQ(result.iterations, 2);
  EXPECT_FALSE(result.message.empty());
  EXPECT_LE((result.gradient - (matrix * result.solution - right_hand_side)).norm(), 1e-12);
}

TEST(Mprgp, IndefiniteOperatorBreaksDown) {
  // q = (x1^2 - x2^2)/2 - x2 on x >= 0 is unbounded; from x = 0 the proportioning direction
  // d = beta = (0, -1) has d'Ad = -1.
  const MatrixXd saddle = VectorXd(Eigen::Vector2d(1.0, -1.0)).asDiagonal();
  const MprgpResult proportioning = solve_mprgp(DenseOperator(saddle), Eigen::Vector2d(0.0, 1.0),
                                                VectorXd::Zero(2), VectorXd::Zero(2));
  EXPECT_EQ(proportioning.status, QpStatus::breakdown);
  EXPECT_NE(proportioning.message.find("positive definite"), std::string::npos);

  // No bounds (l = -inf): CG on an indefinite matrix meets p'Ap <= 0 within n steps.
  std::mt19937_64 generator(400);
  MatrixXd matrix = random_spd(6, 10.0, 1.0, generator);
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eigen(matrix);
  matrix -= 3.0 * eigen.eigenvalues()[0] * eigen.eigenvectors().col(0) *
            eigen.eigenvectors().col(0).transpose();
  const VectorXd lower = VectorXd::Constant(6, -std::numeric_limits<double>::infinity());
  const MprgpResult conjugate_gradient =
      solve_mprgp(DenseOperator(matrix), random_vector(6, generator), lower, VectorXd::Zero(6));
  EXPECT_EQ(conjugate_gradient.status, QpStatus::breakdown);
  EXPECT_NE(conjugate_gradient.message.find("p'Ap"), std::string::npos);
}

/// The minimum of q = x'Ax/2 - b'x on x >= 0 for a semidefinite A: every active set S (x_S = 0)
/// whose free block system A_FF x_F = b_F is consistent (a least-squares solution with zero
/// residual) and gives a KKT point (x_F >= 0, g_S >= 0) is a global minimiser of the convex q;
/// the smallest q over them (they all agree) is returned.
double enumerated_minimum(const MatrixXd& matrix, const VectorXd& right_hand_side) {
  const int size = static_cast<int>(matrix.rows());
  double best = std::numeric_limits<double>::infinity();
  const double scale = matrix.norm() * (1.0 + right_hand_side.norm());
  for (unsigned mask = 0; mask < (1u << size); ++mask) {
    std::vector<int> free;
    for (int i = 0; i < size; ++i) {
      if ((mask & (1u << i)) == 0) free.push_back(i);
    }
    VectorXd candidate = VectorXd::Zero(size);
    if (!free.empty()) {
      const int count = static_cast<int>(free.size());
      MatrixXd block(count, count);
      VectorXd right(count);
      for (int r = 0; r < count; ++r) {
        right[r] = right_hand_side[free[r]];
        for (int c = 0; c < count; ++c) block(r, c) = matrix(free[r], free[c]);
      }
      const VectorXd solution = block.completeOrthogonalDecomposition().solve(right);
      if ((block * solution - right).norm() > 1e-10 * scale) continue;  // inconsistent
      for (int r = 0; r < count; ++r) candidate[free[r]] = solution[r];
    }
    const VectorXd gradient = matrix * candidate - right_hand_side;
    bool optimal = true;
    for (int i = 0; i < size; ++i) {
      const bool active = (mask & (1u << i)) != 0;
      if ((!active && candidate[i] < -1e-10) || (active && gradient[i] < -1e-10 * scale)) {
        optimal = false;
      }
    }
    if (optimal) {
      best =
          std::min(best, 0.5 * candidate.dot(matrix * candidate) - right_hand_side.dot(candidate));
    }
  }
  return best;
}

TEST(Mprgp, SemidefiniteOperatorMovesAlongItsNullDirectionToTheBound) {
  // q = (x1 + x2)^2 / 2 + x3^2 / 2 - x1 - 3 x2 - x3 on x >= 0; A is singular, with null vector
  // (1, -1, 0), along which q is linear. For s = x1 + x2 fixed, q is least with x1 = 0
  // (x2 = s), then s^2/2 - 3 s is least at s = 3: the solution is (0, 3, 1). From x = (1, 1, 1)
  // the gradient A x - b = (1, -1, 0) is itself a null vector: p'Ap = 0 on the first step.
  MatrixXd matrix(3, 3);
  matrix << 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0;
  const MprgpResult result = solve_mprgp(DenseOperator(matrix), Eigen::Vector3d(1.0, 3.0, 1.0),
                                         VectorXd::Zero(3), Eigen::Vector3d(1.0, 1.0, 1.0));
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  EXPECT_NEAR(result.solution[0], 0.0, 1e-12);
  EXPECT_NEAR(result.solution[1], 3.0, 1e-12);
  EXPECT_NEAR(result.solution[2], 1.0, 1e-12);

  // Without bounds the same problem is unbounded below along (1, -1, 0): reported, not a
  // silent answer.
  const VectorXd free = VectorXd::Constant(3, -std::numeric_limits<double>::infinity());
  const MprgpResult unbounded = solve_mprgp(DenseOperator(matrix), Eigen::Vector3d(1.0, 3.0, 1.0),
                                            free, Eigen::Vector3d(1.0, 1.0, 1.0));
  EXPECT_EQ(unbounded.status, QpStatus::breakdown);
  EXPECT_NE(unbounded.message.find("unbounded"), std::string::npos) << unbounded.message;
}

TEST(Mprgp, SemidefiniteRandomProblemsMatchActiveSetEnumeration) {
  // A = B B' of rank 3 in 5 unknowns, b = A y + c with c >= 0 off the range of A on purpose:
  // the bounds x >= 0 keep q bounded (c'x >= 0 grows along the null directions that keep x
  // feasible only if they increase x). Solutions from the active-set enumeration.
  std::mt19937_64 generator(17);
  for (int trial = 0; trial < 20; ++trial) {
    const MatrixXd factor = MatrixXd::NullaryExpr(
        5, 3, [&] { return std::uniform_real_distribution<double>(-1.0, 1.0)(generator); });
    const MatrixXd matrix = factor * factor.transpose();
    const VectorXd right =
        matrix * random_vector(5, generator) - random_vector(5, generator).cwiseAbs();
    const VectorXd lower = VectorXd::Zero(5);
    MprgpParameters parameters;
    parameters.relative_tolerance = 1e-12;
    const MprgpResult result =
        solve_mprgp(DenseOperator(matrix), right, lower, VectorXd::Constant(5, 0.5), parameters);
    ASSERT_EQ(result.status, QpStatus::converged) << "trial " << trial << ": " << result.message;
    const double value =
        0.5 * result.solution.dot(matrix * result.solution) - right.dot(result.solution);
    EXPECT_NEAR(value, enumerated_minimum(matrix, right), 1e-9 * (1.0 + std::abs(value)))
        << "trial " << trial;
  }
}

/// y = A x for A = tridiag(-1, 2 + shift, -1): a shifted 1D Laplacian, applied matrix-free.
class TridiagonalOperator final : public LinearOperator {
 public:
  TridiagonalOperator(int size, double shift) : size_(size), diagonal_(2.0 + shift) {}
  int size() const override { return size_; }
  void apply(const VectorXd& x, VectorXd& y) const override {
    y.resize(size_);
    for (int i = 0; i < size_; ++i) {
      y[i] = diagonal_ * x[i] - (i > 0 ? x[i - 1] : 0.0) - (i + 1 < size_ ? x[i + 1] : 0.0);
    }
  }
  Eigen::SparseMatrix<double> assemble() const {
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < size_; ++i) {
      entries.emplace_back(i, i, diagonal_);
      if (i > 0) entries.emplace_back(i, i - 1, -1.0);
      if (i + 1 < size_) entries.emplace_back(i, i + 1, -1.0);
    }
    Eigen::SparseMatrix<double> matrix(size_, size_);
    matrix.setFromTriplets(entries.begin(), entries.end());
    return matrix;
  }

 private:
  int size_;
  double diagonal_;
};

TEST(Mprgp, OperatorNormEstimateBoundsTheLargestEigenvalue) {
  // tridiag(-1, 2 + s, -1) of order n: lambda_max = 2 + s + 2 cos(pi / (n + 1)).
  const int size = 2000;
  const double shift = 1e-3;
  const double largest = 2.0 + shift + 2.0 * std::cos(std::numbers::pi / (size + 1));
  int applications = 0;
  const double estimate =
      estimate_operator_norm(TridiagonalOperator(size, shift), 10, applications);
  EXPECT_EQ(applications, 10);
  EXPECT_GE(estimate, largest);
  EXPECT_LE(estimate, 1.05 * largest);
  // diag(1, ..., 49, 100): the ratio 0.49 of the top eigenvalues makes 40 iterations exact.
  VectorXd diagonal = VectorXd::LinSpaced(50, 1.0, 50.0);
  diagonal[49] = 100.0;
  const double diagonal_estimate = estimate_operator_norm(
      DenseOperator(diagonal.asDiagonal().toDenseMatrix()), 40, applications);
  EXPECT_NEAR(diagonal_estimate, 1.05 * 100.0, 1e-6 * 100.0);
  std::cout << "||A|| estimates: " << estimate << " for lambda_max " << largest << ", "
            << diagonal_estimate << " for 100\n";
}

/// Primal-dual active set iteration (Hintermueller, Ito & Kunisch 2002): with lambda = A x - b,
/// S = {i : lambda_i + (l_i - x_i) > 0}; solve x_S = l_S, A_FF x_F = b_F - A_FS l_S; repeat
/// until S is unchanged. Finite convergence for M-matrices such as this one.
VectorXd solve_by_active_set_iteration(const Eigen::SparseMatrix<double>& matrix,
                                       const VectorXd& right_hand_side, const VectorXd& lower,
                                       int& iterations) {
  const Eigen::Index size = matrix.rows();
  VectorXd x = VectorXd::Zero(size), multiplier = VectorXd::Zero(size);
  std::vector<bool> active(size, false);
  for (iterations = 1; iterations <= 200; ++iterations) {
    std::vector<bool> next(size);
    for (Eigen::Index i = 0; i < size; ++i) next[i] = multiplier[i] + (lower[i] - x[i]) > 0.0;
    if (iterations > 1 && next == active) break;
    active = next;
    std::vector<Eigen::Triplet<double>> entries;
    VectorXd reduced_right_hand_side = right_hand_side;
    for (int column = 0; column < size; ++column) {
      for (Eigen::SparseMatrix<double>::InnerIterator entry(matrix, column); entry; ++entry) {
        const auto row = entry.row();
        if (active[row]) continue;
        if (active[column]) {
          reduced_right_hand_side[row] -= entry.value() * lower[column];
        } else {
          entries.emplace_back(row, column, entry.value());
        }
      }
      if (active[column]) {
        entries.emplace_back(column, column, 1.0);
        reduced_right_hand_side[column] = lower[column];
      }
    }
    Eigen::SparseMatrix<double> reduced(size, size);
    reduced.setFromTriplets(entries.begin(), entries.end());
    x = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(reduced).solve(reduced_right_hand_side);
    multiplier = matrix * x - right_hand_side;
    for (Eigen::Index i = 0; i < size; ++i) {
      if (!active[i]) multiplier[i] = 0.0;
    }
  }
  return x;
}

TEST(Mprgp, LargeObstacleProblemMatchesActiveSetIteration) {
  const int size = 2000;
  const TridiagonalOperator laplacian(size, 1e-3);  // cond ~ 4.001 / 1e-3 = 4e3
  const VectorXd load = VectorXd::Constant(size, -1e-4);
  VectorXd obstacle(size);
  for (int i = 0; i < size; ++i) {
    const double t = (i + 1.0) / (size + 1.0);
    obstacle[i] = -0.05 - 0.5 * (t - 0.5) * (t - 0.5);
  }
  const Eigen::SparseMatrix<double> assembled = laplacian.assemble();
  int reference_iterations = 0;
  const VectorXd reference =
      solve_by_active_set_iteration(assembled, load, obstacle, reference_iterations);
  // The reference is itself a KKT point.
  const VectorXd reference_gradient = assembled * reference - load;
  ASSERT_GE((reference - obstacle).minCoeff(), -1e-15);
  int contacts = 0;
  for (int i = 0; i < size; ++i) {
    const bool touching = reference[i] - obstacle[i] <= 1e-15;
    contacts += touching;
    ASSERT_LE(std::abs(touching ? std::min(reference_gradient[i], 0.0) : reference_gradient[i]),
              1e-14);
  }
  ASSERT_GT(contacts, 100);
  ASSERT_LT(contacts, size - 100);

  const MprgpResult result = solve_mprgp(laplacian, load, obstacle, VectorXd::Zero(size));
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  EXPECT_LE((result.solution - reference).lpNorm<Eigen::Infinity>(),
            1e-8 * reference.lpNorm<Eigen::Infinity>());
  std::cout << "obstacle n = " << size << ", " << contacts << " contacts: " << result.iterations
            << " iterations (" << result.conjugate_gradient_steps << " CG, "
            << result.expansion_steps << " expansion, " << result.proportioning_steps
            << " proportioning), " << result.operator_applications
            << " products; active set iteration: " << reference_iterations << " solves\n";
}

}  // namespace
}  // namespace robin
