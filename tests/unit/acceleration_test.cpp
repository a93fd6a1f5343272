// Acceleration of the obstacle fixed-point iteration, on linear maps H(x) = M x + c whose
// spectra are built by the test. The fixed point x* = (I - M)^{-1} c comes from an LU solve,
// rates and iteration counts from the theory quoted in each test.

#include "coupling/acceleration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "coupling/acceleration_aitken.hpp"
#include "coupling/acceleration_filtered_qr.hpp"
#include "coupling/acceleration_quasi_newton.hpp"
#include "coupling/acceleration_relaxation.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

/// H(x) = M x + c with its fixed point from an independent LU solve of (I - M) x* = c.
struct LinearMap {
  Eigen::MatrixXd matrix;
  Eigen::VectorXd constant;
  Eigen::VectorXd fixed_point;

  LinearMap(Eigen::MatrixXd m, Eigen::VectorXd c) : matrix(std::move(m)), constant(std::move(c)) {
    const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(matrix.rows(), matrix.cols());
    fixed_point = (identity - matrix).fullPivLu().solve(constant);
  }
  Eigen::VectorXd operator()(const Eigen::VectorXd& x) const { return matrix * x + constant; }
  double relative_error(const Eigen::VectorXd& x) const {
    return (x - fixed_point).norm() / fixed_point.norm();
  }
};

Eigen::MatrixXd random_matrix(int rows, int columns, std::mt19937& generator) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd matrix(rows, columns);
  for (int column = 0; column < columns; ++column) {
    for (int row = 0; row < rows; ++row) matrix(row, column) = uniform(generator);
  }
  return matrix;
}

Eigen::VectorXd random_vector(int size, std::mt19937& generator) {
  return random_matrix(size, 1, generator).col(0);
}

/// A random orthogonal matrix (the Q of a random matrix).
Eigen::MatrixXd random_orthogonal(int size, std::mt19937& generator) {
  return Eigen::HouseholderQR<Eigen::MatrixXd>(random_matrix(size, size, generator)).householderQ();
}

/// Q diag(eigenvalues) Q' with a random orthogonal Q: symmetric with the given spectrum.
Eigen::MatrixXd symmetric_with_spectrum(const std::vector<double>& eigenvalues,
                                        std::mt19937& generator) {
  const int size = static_cast<int>(eigenvalues.size());
  const Eigen::MatrixXd basis = random_orthogonal(size, generator);
  const Eigen::VectorXd diagonal = Eigen::Map<const Eigen::VectorXd>(eigenvalues.data(), size);
  return basis * diagonal.asDiagonal() * basis.transpose();
}

Eigen::MatrixXd block_diagonal(const Eigen::MatrixXd& first, const Eigen::MatrixXd& second) {
  Eigen::MatrixXd matrix =
      Eigen::MatrixXd::Zero(first.rows() + second.rows(), first.cols() + second.cols());
  matrix.topLeftCorner(first.rows(), first.cols()) = first;
  matrix.bottomRightCorner(second.rows(), second.cols()) = second;
  return matrix;
}

/// Number of calls to next() until the returned iterate is within `tolerance` (relative) of
/// x*, starting from x_0 = 0; max_calls + 1 when it never is.
int calls_to_converge(Acceleration& acceleration, const LinearMap& map, double tolerance,
                      int max_calls) {
  Eigen::VectorXd iterate = Eigen::VectorXd::Zero(map.constant.size());
  for (int call = 1; call <= max_calls; ++call) {
    iterate = acceleration.next(iterate, map(iterate));
    if (!iterate.allFinite()) return max_calls + 1;
    if (map.relative_error(iterate) <= tolerance) return call;
  }
  return max_calls + 1;
}

// --- "none": the paper's update ------------------------------------------------------------

TEST(FixedRelaxation, IsBitForBitThePapersUpdatePerBody) {
  std::mt19937 generator(11);
  const int size1 = 7, size2 = 5;
  const LinearMap map(0.4 * random_matrix(size1 + size2, size1 + size2, generator),
                      random_vector(size1 + size2, generator));
  AccelerationOptions options;
  options.method = AccelerationMethod::none;
  options.relaxation1 = 0.3;
  options.relaxation2 = 0.7;
  const auto acceleration = make_acceleration(options, size1, size2);
  Eigen::VectorXd accelerated = random_vector(size1 + size2, generator);
  Eigen::VectorXd plain = accelerated;
  for (int step = 0; step < 25; ++step) {
    accelerated = acceleration->next(accelerated, map(accelerated));
    // g^a <- (1 - delta_a) g^a + delta_a H^a(g), written out as in the iteration.
    const Eigen::VectorXd mapped = map(plain);
    const Eigen::VectorXd next1 = (1.0 - 0.3) * plain.head(size1) + 0.3 * mapped.head(size1);
    const Eigen::VectorXd next2 = (1.0 - 0.7) * plain.tail(size2) + 0.7 * mapped.tail(size2);
    plain << next1, next2;
    ASSERT_TRUE(accelerated == plain) << "step " << step;
  }
  EXPECT_EQ(acceleration->state(), "relaxation delta = (0.3, 0.7)");
}

/// |e_k| / |e_{k-1}| on one block after `steps` steps of the relaxed iteration.
double observed_rate(const LinearMap& map, int start, int size, int steps,
                     const AccelerationOptions& options, int size1, int size2) {
  const auto acceleration = make_acceleration(options, size1, size2);
  Eigen::VectorXd iterate = Eigen::VectorXd::Zero(size1 + size2);
  double previous_error = 0.0, error = 0.0;
  for (int step = 0; step < steps; ++step) {
    iterate = acceleration->next(iterate, map(iterate));
    previous_error = error;
    error = (iterate - map.fixed_point).segment(start, size).norm();
  }
  return error / previous_error;
}

TEST(FixedRelaxation, ConvergesAtTheRatePredictedByTheSpectrum) {
  std::mt19937 generator(5);
  // The error of block a is multiplied by I - delta_a (I - M_a): the asymptotic rate is
  // max over the eigenvalues mu of M_a of |1 - delta_a (1 - mu)|.
  const std::vector<double> spectrum1 = {-1.5, -0.8, 0.0, 0.3, 0.6, -0.2};  // delta 0.5
  const std::vector<double> spectrum2 = {-3.0, -2.0, -1.0, 0.6, -0.5};      // delta 0.25
  const auto predicted = [](const std::vector<double>& spectrum, double delta) {
    double rate = 0.0;
    for (const double mu : spectrum) rate = std::max(rate, std::abs(1.0 - delta * (1.0 - mu)));
    return rate;
  };
  EXPECT_DOUBLE_EQ(predicted(spectrum1, 0.5), 0.8);
  EXPECT_DOUBLE_EQ(predicted(spectrum2, 0.25), 0.9);
  const LinearMap map(block_diagonal(symmetric_with_spectrum(spectrum1, generator),
                                     symmetric_with_spectrum(spectrum2, generator)),
                      random_vector(11, generator));
  AccelerationOptions options;
  options.method = AccelerationMethod::none;
  options.relaxation1 = 0.5;
  options.relaxation2 = 0.25;
  // The next rates are 0.65 and 0.625: after 60 steps their share is (0.65/0.8)^60 ~ 4e-6.
  EXPECT_NEAR(observed_rate(map, 0, 6, 60, options, 6, 5), 0.8, 1e-3);
  EXPECT_NEAR(observed_rate(map, 6, 5, 60, options, 6, 5), 0.9, 1e-3);
}

// --- Aitken -----------------------------------------------------------------------------------

TEST(Aitken, ScalarBlocksAreExactAfterTheSecantStep) {
  // For M = m I the residual is r = (m - 1)(x - x*), the secant gives omega_1 = 1 / (1 - m)
  // and x_2 = x*. With m = -3 the plain delta = 0.5 does not converge (factor |1 - 2| = 1).
  std::mt19937 generator(3);
  const int size = 8;
  const double m1 = -3.0, m2 = -0.5;
  const Eigen::MatrixXd matrix = block_diagonal(m1 * Eigen::MatrixXd::Identity(size, size),
                                                m2 * Eigen::MatrixXd::Identity(size, size));
  const LinearMap map(matrix, random_vector(2 * size, generator));
  AitkenAcceleration body1(size, AitkenParameters{});
  AitkenAcceleration body2(size, AitkenParameters{});
  Eigen::VectorXd iterate = Eigen::VectorXd::Zero(2 * size);
  for (int call = 1; call <= 2; ++call) {
    const Eigen::VectorXd mapped = map(iterate);
    iterate << body1.next(iterate.head(size), mapped.head(size)),
        body2.next(iterate.tail(size), mapped.tail(size));
    if (call == 1) {
      EXPECT_GT(map.relative_error(iterate), 0.1);
    }
  }
  EXPECT_NEAR(body1.omega(), 1.0 / (1.0 - m1), 1e-14);
  EXPECT_NEAR(body2.omega(), 1.0 / (1.0 - m2), 1e-14);
  EXPECT_LT(map.relative_error(iterate), 1e-13);
  EXPECT_EQ(body1.state(), "aitken omega = 0.25");
}

TEST(Aitken, OmegaIsClampedKeepingItsSign) {
  // M = m I with m = 0.9: the secant asks for omega = 1 / (1 - m) = 10, clamped to 1;
  // with m = 1.5 it asks for -2, clamped to -1.
  for (const double m : {0.9, 1.5}) {
    AitkenAcceleration aitken(3, AitkenParameters{0.5, 1e-4, 1.0});
    const Eigen::Vector3d constant(1.0, -2.0, 0.5);
    Eigen::VectorXd iterate = Eigen::Vector3d::Zero();
    for (int call = 0; call < 2; ++call) iterate = aitken.next(iterate, m * iterate + constant);
    EXPECT_DOUBLE_EQ(aitken.omega(), std::copysign(1.0, 1.0 / (1.0 - m))) << "m = " << m;
  }
}

// --- IQN-ILS ---------------------------------------------------------------------------------

QuasiNewtonParameters with_mixing(QuasiNewtonMixing mixing, int history_depth) {
  QuasiNewtonParameters parameters;
  parameters.mixing = mixing;
  parameters.history_depth = history_depth;
  return parameters;
}

TEST(IqnIls, FullHistoryReachesTheFixedPointInAtMostNPlusTwoSteps) {
  // Anderson mixing on a linear map: x_{k+1} = x^_k + beta r(x^_k) with x^_k the GMRES iterate
  // of (I - M) x = c (Walker & Ni), so x_{n+1} = x* when the grade of r_0 is n (generic).
  std::mt19937 generator(17);
  const int size = 10;
  const Eigen::MatrixXd matrix = random_matrix(size, size, generator);
  const LinearMap map(0.9 * matrix / matrix.operatorNorm(), random_vector(size, generator));
  for (const auto mixing : {QuasiNewtonMixing::full, QuasiNewtonMixing::aitken}) {
    IqnIlsAcceleration acceleration({{size, 0.5}}, with_mixing(mixing, size + 2));
    const int calls = calls_to_converge(acceleration, map, 1e-10, 100);
    std::cout << "full-rank n = " << size << ": " << calls
              << " steps to 1e-10 (theory n + 1 = " << size + 1 << ")\n";
    EXPECT_LE(calls, size + 2);
    EXPECT_GE(calls, size);  // GMRES does not end early on generic data
  }
}

TEST(IqnIls, RankKPerturbationOfAScalarNeedsKPlusTwoSteps) {
  // M = m I + U V' (rank k): I - M = (1 - m) I - U V' gives Krylov spaces of dimension at most
  // k + 1, so GMRES is exact at step k + 1 and x_{k+2} = x*.
  std::mt19937 generator(23);
  const int size = 30;
  for (const int rank : {1, 3, 5}) {
    const Eigen::MatrixXd perturbation = random_matrix(size, rank, generator) *
                                         random_matrix(rank, size, generator) / std::sqrt(size);
    const LinearMap map(-0.5 * Eigen::MatrixXd::Identity(size, size) + perturbation,
                        random_vector(size, generator));
    for (const auto mixing : {QuasiNewtonMixing::full, QuasiNewtonMixing::aitken}) {
      IqnIlsAcceleration acceleration({{size, 0.5}}, with_mixing(mixing, 10));
      const int calls = calls_to_converge(acceleration, map, 1e-10, 100);
      std::cout << "rank " << rank << ": " << calls << " steps to 1e-10\n";
      EXPECT_EQ(calls, rank + 2) << "rank " << rank;
    }
  }
}

TEST(IqnIls, FilterDropsAnExactlyDuplicatedColumn) {
  // Integer data on the line x_j = x_0 + j s make r_2 - r_1 = r_1 - r_0 exactly.
  Eigen::Matrix4d matrix;
  matrix << 1, -2, 0, 1, 0, 3, 1, -1, 2, 0, -1, 0, 1, 1, 0, 2;
  const Eigen::Vector4d constant(4.0, -1.0, 2.0, 3.0);
  const Eigen::Vector4d start(1.0, 2.0, -1.0, 0.0), step(0.0, 1.0, 1.0, -1.0);
  QuasiNewtonParameters parameters = with_mixing(QuasiNewtonMixing::full, 5);
  parameters.safeguard_growth = std::numeric_limits<double>::infinity();
  IqnIlsAcceleration acceleration({{4, 0.5}}, parameters);
  Eigen::VectorXd result;
  for (int j = 0; j <= 2; ++j) {
    const Eigen::Vector4d iterate = start + j * step;
    result = acceleration.next(iterate, matrix * iterate + constant);
  }
  EXPECT_EQ(acceleration.columns(), 1);
  EXPECT_EQ(acceleration.filtered(), 1);
  EXPECT_EQ(acceleration.state(), "iqn-ils 1 column (1 filtered)");
  // One column v = (M - I) s, w = M s: alpha = -v'r_2 / v'v, x_3 = H(x_2) + alpha w.
  const Eigen::Vector4d iterate = start + 2 * step;
  const Eigen::Vector4d residual = matrix * iterate + constant - iterate;
  const Eigen::Vector4d column = (matrix - Eigen::Matrix4d::Identity()) * step;
  const double alpha = -column.dot(residual) / column.dot(column);
  const Eigen::Vector4d expected = matrix * iterate + constant + alpha * (matrix * step);
  EXPECT_LT((result - expected).norm(), 1e-12 * expected.norm());
}

TEST(IqnIls, SafeguardRestartsWithARelaxationStepWhenTheResidualGrows) {
  // Steps: x0 -> relaxation; x1 -> quasi-Newton with the column dv = r1 - r0, dx = x1 - x0;
  // x2 has |r2| = 5 |r1| > 2 |r1|: the history is cleared and x3 = (1 - b) x2 + b H(x2), with
  // b = delta for relaxation mixing, and for aitken mixing the last beta,
  // -dx'dv / |dv|^2 = 0.75 / 1.5 = 0.5.
  const double delta = 0.4;
  const Eigen::Vector3d x0(0.0, 0.0, 0.0), h0(1.0, 2.0, -1.0);  // r0 = (1, 2, -1)
  const Eigen::Vector3d x1(0.5, 0.5, 0.0), h1(1.0, 1.5, -0.5);  // r1 = (0.5, 1, -0.5)
  const Eigen::Vector3d r1 = h1 - x1;
  const Eigen::Vector3d x2(0.2, 0.1, 0.3);
  const Eigen::Vector3d h2 = x2 + 5.0 * Eigen::Vector3d(-r1(1), r1(0), r1(2));
  for (const auto& [mixing, step] : {std::pair{QuasiNewtonMixing::relaxation, delta},
                                     std::pair{QuasiNewtonMixing::aitken, 0.5}}) {
    IqnIlsAcceleration acceleration({{3, delta}}, with_mixing(mixing, 10));
    acceleration.next(x0, h0);
    EXPECT_TRUE(acceleration.relaxation_step());
    acceleration.next(x1, h1);
    EXPECT_EQ(acceleration.columns(), 1);
    const Eigen::VectorXd x3 = acceleration.next(x2, h2);
    EXPECT_TRUE(acceleration.relaxation_step());
    EXPECT_EQ(acceleration.safeguard_restarts(), 1);
    EXPECT_EQ(acceleration.state(), "iqn-ils relaxation step (restart: the residual grew 5x)");
    const Eigen::Vector3d relaxed = (1.0 - step) * x2 + step * h2;
    EXPECT_LT((x3 - relaxed).norm(), 1e-15 * relaxed.norm()) << "step " << step;
    // The next step uses the single column from (x2, h2), not the older ones.
    const Eigen::Vector3d h3 = x3 + Eigen::Vector3d(0.1, -0.2, 0.05);
    acceleration.next(x3, h3);
    EXPECT_EQ(acceleration.columns(), 1);
  }
}

TEST(IqnIls, RestartMakesTheNextStepARelaxationStep) {
  std::mt19937 generator(29);
  const LinearMap map(0.5 * random_matrix(6, 6, generator), random_vector(6, generator));
  IqnIlsAcceleration acceleration({{6, 0.3}}, QuasiNewtonParameters{});
  Eigen::VectorXd iterate = Eigen::VectorXd::Zero(6);
  for (int step = 0; step < 3; ++step) iterate = acceleration.next(iterate, map(iterate));
  EXPECT_FALSE(acceleration.relaxation_step());
  acceleration.restart();
  const Eigen::VectorXd mapped = map(iterate);
  const Eigen::VectorXd next = acceleration.next(iterate, mapped);
  const Eigen::VectorXd relaxed = (1.0 - 0.3) * iterate + 0.3 * mapped;
  EXPECT_TRUE(next == relaxed);
  EXPECT_EQ(acceleration.state(), "iqn-ils relaxation step (first step after a restart)");
}

TEST(FilteredQr, FactorsIndependentColumnsAndDropsADependentOne) {
  std::mt19937 generator(31);
  Eigen::MatrixXd columns = random_matrix(8, 4, generator);
  columns.col(2) = 2.0 * columns.col(0) - columns.col(1);  // dependent on the earlier two
  const FilteredQr factors = filtered_qr(columns, 1e-10);
  ASSERT_EQ(factors.kept, (std::vector<int>{0, 1, 3}));
  Eigen::MatrixXd kept(8, 3);
  kept << columns.col(0), columns.col(1), columns.col(3);
  EXPECT_LT((factors.q * factors.r - kept).norm(), 1e-14 * kept.norm());
  EXPECT_LT((factors.q.transpose() * factors.q - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_TRUE(factors.r.isUpperTriangular());
  // A zero column is dropped even without a threshold (R_jj = 0).
  columns.col(1).setZero();
  EXPECT_EQ(filtered_qr(columns, 0.0).kept, (std::vector<int>{0, 2, 3}));
}

// --- Two bodies with compliance ratio c --------------------------------------------------------

/// The all-active Robin iteration (docs/method.md, "Choosing delta"): with interface
/// compliances F^1 and F^2,
///   H^1(g^1) = -F^2 (F^1)^{-1} g^1 + c^1,   H^2(g^2) = -F^1 (F^2)^{-1} g^2 + c^2,
/// so the error of g^1 is multiplied by I - delta (I + F^2 (F^1)^{-1}) and that of g^2 by
/// I - delta (I + F^1 (F^2)^{-1}). F^1 has the spectrum 1/k, k = 1..size, of a
/// Neumann-to-Dirichlet map; F^2 = c (F^1)^{1/2} S (F^1)^{1/2} with S SPD of spectrum in
/// [1/spread, spread] (S = I: proportional compliances, F^2 = c F^1), so that
/// F^2 (F^1)^{-1} is similar to c S.
LinearMap two_bodies(int size, double compliance_ratio, double spread, std::mt19937& generator) {
  std::vector<double> spectrum1(size), spectrum2(size);
  for (int index = 0; index < size; ++index) {
    spectrum1[index] = std::sqrt(1.0 / (index + 1));  // of (F^1)^{1/2}
    spectrum2[index] = std::pow(spread, -1.0 + 2.0 * index / (size - 1));
  }
  const Eigen::MatrixXd root1 = symmetric_with_spectrum(spectrum1, generator);
  const Eigen::MatrixXd compliance1 = root1 * root1;
  const Eigen::MatrixXd compliance2 =
      compliance_ratio * root1 * symmetric_with_spectrum(spectrum2, generator) * root1;
  const Eigen::MatrixXd map1 = -compliance2 * compliance1.inverse();
  const Eigen::MatrixXd map2 = -compliance1 * compliance2.inverse();
  return LinearMap(block_diagonal(map1, map2), random_vector(2 * size, generator));
}

/// The single delta minimising max |1 - delta lambda| over the (real, positive) eigenvalues
/// lambda of I - M: 2 / (lambda_min + lambda_max).
double best_single_relaxation(const LinearMap& map) {
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(map.matrix.rows(), map.matrix.cols());
  const Eigen::VectorXd eigenvalues =
      Eigen::EigenSolver<Eigen::MatrixXd>(identity - map.matrix, false).eigenvalues().real();
  return 2.0 / (eigenvalues.minCoeff() + eigenvalues.maxCoeff());
}

int two_body_calls(const LinearMap& map, int size, AccelerationOptions options, int max_calls) {
  const auto acceleration = make_acceleration(options, size, size);
  return calls_to_converge(*acceleration, map, 1e-10, max_calls);
}

TEST(TwoBodies, AitkenConvergesWhereASingleRelaxationDiverges) {
  std::mt19937 generator(7);
  const int size = 16;
  const LinearMap map = two_bodies(size, 100.0, 2.0, generator);
  AccelerationOptions options;
  options.method = AccelerationMethod::none;  // delta = 0.5: |1 - 0.5 (1 + 100 s)| > 1 for body 1
  EXPECT_GT(two_body_calls(map, size, options, 500), 500);
  options.method = AccelerationMethod::aitken;
  const int aitken = two_body_calls(map, size, options, 500);
  std::cout << "c = 100: aitken per body needs " << aitken << " iterations to 1e-10\n";
  EXPECT_LE(aitken, 100);
}

TEST(TwoBodies, QuasiNewtonNeedsTenTimesFewerIterationsThanTheBestRelaxation) {
  std::mt19937 generator(7);
  const int size = 16;
  const LinearMap map = two_bodies(size, 100.0, 2.0, generator);
  AccelerationOptions options;
  options.method = AccelerationMethod::none;
  const double best = best_single_relaxation(map);
  options.relaxation1 = options.relaxation2 = best;
  const int relaxation = two_body_calls(map, size, options, 20000);
  options.method = AccelerationMethod::aitken;
  const int aitken = two_body_calls(map, size, options, 20000);
  options.method = AccelerationMethod::iqn_ils;
  options.mixing =
      QuasiNewtonMixing::aitken;  // on this dense random spectrum (full mixing: see the log line)
  options.relaxation1 = options.relaxation2 = 0.5;
  const int per_body = two_body_calls(map, size, options, 20000);
  options.per_body = false;
  const int joint = two_body_calls(map, size, options, 20000);
  options.mixing = QuasiNewtonMixing::full;
  const int joint_full = two_body_calls(map, size, options, 20000);
  options.per_body = true;
  const int per_body_full = two_body_calls(map, size, options, 20000);
  std::cout << "c = 100, 2 x " << size << " pairs, iterations to 1e-10: best single delta " << best
            << ": " << relaxation << ", aitken: " << aitken
            << ", iqn-ils (aitken mixing) per body: " << per_body << ", joint: " << joint
            << ", iqn-ils (full mixing) per body: " << per_body_full << ", joint: " << joint_full
            << "\n";
  EXPECT_GT(relaxation, 100);
  EXPECT_LT(per_body, 20);
  EXPECT_LT(joint, 20);
  EXPECT_GE(relaxation, 10 * per_body);
}

TEST(TwoBodies, AitkenMixingKeepsAShortHistoryConvergent) {
  // With beta = 1 the error of x_{k+1} is M times that of x^, and |M| ~ c for body 1: a short
  // history then loses the stiff modes again. Aitken mixing makes the step a contraction.
  std::mt19937 generator(7);
  const int size = 16;
  const LinearMap map = two_bodies(size, 100.0, 2.0, generator);
  AccelerationOptions options;
  options.method = AccelerationMethod::iqn_ils;
  for (const int depth : {3, 5}) {
    options.history_depth = depth;
    options.mixing = QuasiNewtonMixing::aitken;
    const int aitken = two_body_calls(map, size, options, 500);
    options.mixing = QuasiNewtonMixing::full;
    const int full = two_body_calls(map, size, options, 500);
    std::cout << "c = 100, history depth " << depth << ": aitken mixing " << aitken
              << " iterations, full mixing " << (full > 500 ? "not in 500" : std::to_string(full))
              << "\n";
    EXPECT_LT(aitken, 40);
    EXPECT_GT(full, 3 * aitken);
  }
}

/// Relative error of body 1's block after each of `steps` steps, when body 2's map H^2 carries
/// random noise of standard deviation `noise` (an inexact or non-smooth second sequence).
std::vector<double> body1_errors(const LinearMap& map, int size, const AccelerationOptions& options,
                                 double noise, int steps) {
  const auto acceleration = make_acceleration(options, size, size);
  std::mt19937 generator(3);
  std::normal_distribution<double> normal(0.0, noise);
  std::vector<double> errors;
  Eigen::VectorXd iterate = Eigen::VectorXd::Zero(2 * size);
  for (int step = 0; step < steps; ++step) {
    Eigen::VectorXd mapped = map(iterate);
    for (int index = size; index < 2 * size; ++index) mapped(index) += normal(generator);
    iterate = acceleration->next(iterate, mapped);
    errors.push_back((iterate - map.fixed_point).head(size).norm() /
                     map.fixed_point.head(size).norm());
  }
  return errors;
}

int first_below(const std::vector<double>& errors, double tolerance) {
  for (std::size_t step = 0; step < errors.size(); ++step) {
    if (errors[step] <= tolerance) return static_cast<int>(step) + 1;
  }
  return static_cast<int>(errors.size()) + 1;
}

TEST(TwoBodies, PerBodyQuasiNewtonIsolatesTheGoodSequenceFromANoisyOne) {
  // Either sequence alone fixes the solution (docs/method.md), so the good one must not be held
  // back by the other. Per body, body 1's iterates do not depend on H^2 at all.
  std::mt19937 generator(7);
  const int size = 16;
  const LinearMap map = two_bodies(size, 100.0, 2.0, generator);
  AccelerationOptions options;
  options.method = AccelerationMethod::iqn_ils;
  options.mixing = QuasiNewtonMixing::aitken;
  const std::vector<double> clean = body1_errors(map, size, options, 0.0, 60);
  const std::vector<double> noisy = body1_errors(map, size, options, 1e-3, 60);
  EXPECT_EQ(clean, noisy);
  options.per_body = false;
  const std::vector<double> joint = body1_errors(map, size, options, 1e-3, 60);
  const int per_body_steps = first_below(noisy, 1e-10);
  const int joint_steps = first_below(joint, 1e-10);
  std::cout << "body 1 to 1e-10 with noise 1e-3 on H^2: per body " << per_body_steps
            << " steps, joint " << (joint_steps > 60 ? "not in 60" : std::to_string(joint_steps))
            << "\n";
  EXPECT_LT(per_body_steps, 25);
  EXPECT_GT(joint_steps, 2 * per_body_steps);
}

TEST(TwoBodies, EveryMethodHandlesABodyWithoutPairs) {
  // A body with no contact pairs has an empty block; the other block must still converge.
  std::mt19937 generator(37);
  const LinearMap map(symmetric_with_spectrum({-0.5, -0.2, 0.3}, generator),
                      random_vector(3, generator));
  for (const AccelerationMethod method :
       {AccelerationMethod::none, AccelerationMethod::aitken, AccelerationMethod::iqn_ils}) {
    for (const bool per_body : {true, false}) {
      AccelerationOptions options;
      options.method = method;
      options.per_body = per_body;
      const auto acceleration = make_acceleration(options, 0, 3);
      // "none" with delta = 0.5 contracts at max |1 - 0.5 (1 - mu)| = 0.75: 1e-10 in 81 steps.
      EXPECT_LE(calls_to_converge(*acceleration, map, 1e-10, 100), 81) << to_string(method);
    }
  }
}

// --- Options ----------------------------------------------------------------------------------

/// The message of the InputError thrown by validate(options), or "" when nothing is thrown.
std::string validation_message(const AccelerationOptions& options) {
  try {
    validate(options);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(AccelerationOptions, DefaultsAreValidAndBadValuesNameTheirField) {
  EXPECT_EQ(validation_message(AccelerationOptions{}), "");
  const std::vector<std::pair<std::function<void(AccelerationOptions&)>, std::string>> cases = {
      {[](AccelerationOptions& o) { o.relaxation1 = 0.0; }, "acceleration.relaxation1"},
      {[](AccelerationOptions& o) { o.relaxation2 = 2.5; }, "acceleration.relaxation2"},
      {[](AccelerationOptions& o) { o.relaxation2 = std::nan(""); }, "acceleration.relaxation2"},
      {[](AccelerationOptions& o) { o.aitken_minimum = -1.0; }, "acceleration.aitken_minimum"},
      {[](AccelerationOptions& o) { o.aitken_maximum = 1e-5; }, "acceleration.aitken_maximum"},
      {[](AccelerationOptions& o) { o.aitken_initial = 1.5; }, "acceleration.aitken_initial"},
      {[](AccelerationOptions& o) { o.history_depth = 0; }, "acceleration.history_depth"},
      {[](AccelerationOptions& o) { o.filter_threshold = -1e-3; }, "acceleration.filter_threshold"},
      {[](AccelerationOptions& o) { o.safeguard_growth = 1.0; }, "acceleration.safeguard_growth"},
  };
  for (const auto& [change, field] : cases) {
    AccelerationOptions options;
    change(options);
    const std::string message = validation_message(options);
    EXPECT_EQ(message.rfind(field + " must be", 0), 0u) << field << ": " << message;
    EXPECT_THROW(make_acceleration(options, 2, 3), InputError) << field;
  }
  AccelerationOptions options;
  options.history_depth = 0;
  EXPECT_EQ(validation_message(options), "acceleration.history_depth must be >= 1, got 0");
}

}  // namespace
}  // namespace robin
