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
  options.method = "none";
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
  options.method = "none";
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

// --- Two bodies with compliance ratio c --------------------------------------------------------

/// The all-active Robin iteration (algorithm.md, "Structure worth knowing"): with interface
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
  options.method = "none";  // delta = 0.5: |1 - 0.5 (1 + 100 s)| > 1 for body 1
  EXPECT_GT(two_body_calls(map, size, options, 500), 500);
  options.method = "aitken";
  const int aitken = two_body_calls(map, size, options, 500);
  std::cout << "c = 100: aitken per body needs " << aitken << " iterations to 1e-10\n";
  EXPECT_LE(aitken, 100);
}

TEST(TwoBodies, QuasiNewtonNeedsTenTimesFewerIterationsThanTheBestRelaxation) {
  std::mt19937 generator(7);
  const int size = 16;
  const LinearMap map = two_bodies(size, 100.0, 2.0, generator);
  AccelerationOptions options;
  options.method = "none";
  const double best = best_single_relaxation(map);
  options.relaxation1 = options.relaxation2 = best;
  const int relaxation = two_body_calls(map, size, options, 20000);
  options.method = "aitken";
  const int aitken = two_body_calls(map, size, options, 20000);
  options.method = "iqn-ils";
  options.relaxation1 = options.relaxation2 = 0.5;
  const int per_body = two_body_calls(map, size, options, 20000);
  options.per_body = false;
  const int joint = two_body_calls(map, size, options, 20000);
  options.mixing = "full";
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

}  // namespace
}  // namespace robin
