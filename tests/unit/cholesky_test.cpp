// CHOLMOD supernodal factor against Eigen's SimplicialLDLT (an independent factorization),
// blocked multiple right-hand sides, the trailing-block congruence B K^{-1} B' against the
// same independent factorization, and the singular / indefinite error path.

#include "numerics/cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <iostream>
#include <random>
#include <vector>

#include "numerics/errors.hpp"

namespace robin {
namespace {

/// Random sparse SPD matrix: B'B + I/10 with B sparse random (about `per_row` entries per
/// row), stored with both triangles; of order 1 with cond ~ 1e2 .. 1e3.
SparseMatrix random_sparse_spd(int size, int per_row, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_int_distribution<int> column(0, size - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int row = 0; row < size; ++row) {
    entries.emplace_back(row, row, 1.0 + value(generator));
    for (int k = 0; k < per_row; ++k)
      entries.emplace_back(row, column(generator), value(generator));
  }
  SparseMatrix factor(size, size);
  factor.setFromTriplets(entries.begin(), entries.end());
  SparseMatrix identity(size, size);
  identity.setIdentity();
  SparseMatrix matrix = SparseMatrix(factor.transpose()) * factor + 0.1 * identity;
  matrix.makeCompressed();
  return matrix;
}

/// Independent reference: Eigen's own simplicial LDL' (no CHOLMOD).
Eigen::MatrixXd reference_solve(const SparseMatrix& matrix, const Eigen::MatrixXd& loads) {
  Eigen::SimplicialLDLT<SparseMatrix> reference(matrix);
  EXPECT_EQ(reference.info(), Eigen::Success);
  return reference.solve(loads);
}

TEST(Cholesky, SolveMatchesSimplicialLdlt) {
  const SparseMatrix matrix = random_sparse_spd(600, 4, 11);
  const CholeskyFactor factor(matrix, "block");
  EXPECT_EQ(factor.size(), 600);
  EXPECT_EQ(factor.solve_count(), 0);
  std::mt19937 generator(12);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const Eigen::VectorXd load = Eigen::VectorXd::NullaryExpr(600, [&] { return value(generator); });
  const Eigen::VectorXd solution = factor.solve(load);
  const Eigen::VectorXd expected = reference_solve(matrix, load);
  const double error = (solution - expected).norm() / expected.norm();
  EXPECT_LE(error, 1e-12);
  EXPECT_LE((matrix * solution - load).norm(), 1e-12 * load.norm());
  EXPECT_EQ(factor.solve_count(), 1);
  // The factor holds at least the lower triangle of the matrix (no cancellation here).
  const long lower_nonzeros = (matrix.nonZeros() + matrix.rows()) / 2;
  EXPECT_GE(factor.factor_nonzeros(), lower_nonzeros);
  EXPECT_LE(factor.factor_nonzeros(), 600L * 601 / 2);
  std::cout << "n = 600: relative error " << error << ", nnz(K lower) " << lower_nonzeros
            << ", nnz(L) " << factor.factor_nonzeros() << "\n";
}

TEST(Cholesky, ManyRightHandSidesAreSolvedInBlocks) {
  const SparseMatrix matrix = random_sparse_spd(400, 3, 21);
  const CholeskyFactor factor(matrix, "block");
  std::mt19937 generator(22);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const Eigen::MatrixXd loads =
      Eigen::MatrixXd::NullaryExpr(400, 130, [&] { return value(generator); });
  const Eigen::MatrixXd solutions = factor.solve(loads);
  const Eigen::MatrixXd expected = reference_solve(matrix, loads);
  ASSERT_EQ(solutions.cols(), 130);
  double worst = 0.0;
  for (Eigen::Index j = 0; j < loads.cols(); ++j) {
    worst = std::max(worst, (solutions.col(j) - expected.col(j)).norm() / expected.col(j).norm());
  }
  EXPECT_LE(worst, 1e-12);
  EXPECT_EQ(factor.solve_count(), 130);
  factor.solve(Eigen::VectorXd(loads.col(0)));
  EXPECT_EQ(factor.solve_count(), 131);
  std::cout << "130 right-hand sides: worst relative error " << worst << "\n";
}

TEST(Cholesky, OnlyTheLowerTriangleIsRead) {
  const SparseMatrix matrix = random_sparse_spd(200, 3, 31);
  const SparseMatrix lower = matrix.triangularView<Eigen::Lower>();
  const CholeskyFactor factor(lower, "lower");
  const Eigen::VectorXd load = Eigen::VectorXd::LinSpaced(200, -1.0, 2.0);
  const Eigen::VectorXd expected = reference_solve(matrix, load);
  EXPECT_LE((factor.solve(load) - expected).norm(), 1e-12 * expected.norm());
}

TEST(Cholesky, IndefiniteMatrixThrowsNamingTheBody) {
  SparseMatrix matrix = random_sparse_spd(100, 3, 41);
  matrix.coeffRef(57, 57) = -50.0;  // a negative diagonal entry: not positive definite
  try {
    const CholeskyFactor factor(matrix, "upper_block");
    FAIL() << "no SingularBodyError";
  } catch (const SingularBodyError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("body 'upper_block'"), std::string::npos) << message;
    EXPECT_NE(message.find("not positive definite"), std::string::npos) << message;
  }
}

/// A floating (pure Neumann) 1D bar: K = tridiag(-1, 2, -1) with K_00 = K_nn = 1, scaled by
/// an irrational stiffness so rounding decides the sign of the last pivot. Singular (constant
/// null vector): must throw whether CHOLMOD meets a negative or a tiny positive pivot.
TEST(Cholesky, SingularMatrixThrowsNamingTheBody) {
  for (const double stiffness : {1.0, 3.14159265358979, 7.1e5 / 3.0}) {
    const int size = 300;
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i + 1 < size; ++i) {
      entries.emplace_back(i, i, stiffness);
      entries.emplace_back(i + 1, i + 1, stiffness);
      entries.emplace_back(i, i + 1, -stiffness);
      entries.emplace_back(i + 1, i, -stiffness);
    }
    SparseMatrix matrix(size, size);
    matrix.setFromTriplets(entries.begin(), entries.end());
    EXPECT_THROW(
        {
          try {
            const CholeskyFactor factor(matrix, "floating_bar");
          } catch (const SingularBodyError& error) {
            EXPECT_NE(std::string(error.what()).find("body 'floating_bar'"), std::string::npos);
            std::cout << error.what() << "\n";
            throw;
          }
        },
        SingularBodyError)
        << "stiffness " << stiffness;
  }
}

/// `count` distinct unknowns of 0 .. size-1, in a random order.
std::vector<int> random_unknowns(int size, int count, unsigned seed) {
  std::vector<int> unknowns(static_cast<std::size_t>(size));
  for (int j = 0; j < size; ++j) unknowns[static_cast<std::size_t>(j)] = j;
  std::mt19937 generator(seed);
  std::shuffle(unknowns.begin(), unknowns.end(), generator);
  unknowns.resize(static_cast<std::size_t>(count));
  return unknowns;
}

/// A sparse rows x size trace with two random entries per row, in the given columns only.
SparseMatrix random_trace(int rows, int size, const std::vector<int>& columns, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_int_distribution<std::size_t> pick(0, columns.size() - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int row = 0; row < rows; ++row) {
    for (int k = 0; k < 2; ++k)
      entries.emplace_back(row, columns[pick(generator)], value(generator));
  }
  SparseMatrix trace(rows, size);
  trace.setFromTriplets(entries.begin(), entries.end());
  return trace;
}

TEST(Cholesky, TrailingCongruenceMatchesAnIndependentSolve) {
  const int size = 600;
  const SparseMatrix matrix = random_sparse_spd(size, 4, 51);
  const std::vector<int> trailing = random_unknowns(size, 60, 52);
  const CholeskyFactor factor(matrix, "block", {.trailing_unknowns = trailing});
  ASSERT_TRUE(factor.has_trailing_block());
  // The reordered factor still solves K x = b.
  const Eigen::VectorXd load = Eigen::VectorXd::LinSpaced(size, -2.0, 1.0);
  const Eigen::VectorXd expected_solution = reference_solve(matrix, load);
  EXPECT_LE((factor.solve(load) - expected_solution).norm(), 1e-12 * expected_solution.norm());

  const SparseMatrix trace = random_trace(35, size, trailing, 53);
  const Eigen::MatrixXd congruence = factor.trailing_congruence(trace);
  const Eigen::MatrixXd expected =
      trace * reference_solve(matrix, Eigen::MatrixXd(trace.transpose()));
  const double error = (congruence - expected).norm() / expected.norm();
  EXPECT_LE(error, 1e-12);
  EXPECT_EQ((congruence - congruence.transpose()).norm(), 0.0);
  std::cout << "B K^-1 B' from the trailing block (m = 60, n_c = 35): relative error " << error
            << "\n";
}

TEST(Cholesky, TrailingCongruenceOfManyRowsMatchesAnIndependentSolve) {
  // more rows than one column block of the staircase solve (64), some without a trailing entry
  const int size = 900;
  const SparseMatrix matrix = random_sparse_spd(size, 4, 81);
  const std::vector<int> trailing = random_unknowns(size, 400, 82);
  const CholeskyFactor factor(matrix, "block", {.trailing_unknowns = trailing});
  ASSERT_TRUE(factor.has_trailing_block());
  SparseMatrix trace = random_trace(230, size, trailing, 83);
  for (const int empty : {0, 117, 229}) trace.row(empty) *= 0.0;
  trace.prune(0.0);
  const Eigen::MatrixXd congruence = factor.trailing_congruence(trace);
  const Eigen::MatrixXd expected =
      trace * reference_solve(matrix, Eigen::MatrixXd(trace.transpose()));
  EXPECT_LE((congruence - expected).norm(), 1e-12 * expected.norm());
  EXPECT_EQ((congruence - congruence.transpose()).norm(), 0.0);
  EXPECT_EQ(congruence.row(117).norm(), 0.0);
}

TEST(Cholesky, LoadOnTheTrailingUnknownsIsSolvedWithTheBackwardSolveAlone) {
  const int size = 600;
  const SparseMatrix matrix = random_sparse_spd(size, 4, 71);
  const std::vector<int> trailing = random_unknowns(size, 60, 72);
  const CholeskyFactor factor(matrix, "block", {.trailing_unknowns = trailing});
  ASSERT_TRUE(factor.has_trailing_block());
  // b = B' lambda for a trace B on the trailing unknowns (the contact forces' load)
  const SparseMatrix trace = random_trace(35, size, trailing, 73);
  const Eigen::VectorXd forces = Eigen::VectorXd::LinSpaced(35, -1.0, 2.0);
  const Eigen::VectorXd load = trace.transpose() * forces;
  const Eigen::VectorXd expected = reference_solve(matrix, load);
  const Eigen::VectorXd solution = factor.solve(load);
  EXPECT_EQ(factor.backward_only_solve_count(), 1);
  EXPECT_LE((solution - expected).norm(), 1e-12 * expected.norm());
  // one entry outside the trailing unknowns: the full solve
  Eigen::VectorXd spread = load;
  const auto outside =
      std::find_if(spread.begin(), spread.end(), [](double value) { return value == 0.0; });
  const auto unknown = static_cast<int>(outside - spread.begin());
  ASSERT_EQ(std::count(trailing.begin(), trailing.end(), unknown), 0);
  spread[unknown] = 0.5;
  const Eigen::VectorXd expected_spread = reference_solve(matrix, spread);
  EXPECT_LE((factor.solve(spread) - expected_spread).norm(), 1e-12 * expected_spread.norm());
  EXPECT_EQ(factor.backward_only_solve_count(), 1);
  EXPECT_EQ(factor.solve_count(), 2);
  // K^{-1} 0 = 0, with or without a trailing block
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(size);
  EXPECT_EQ(factor.solve(zero), zero);
  const CholeskyFactor plain(matrix, "block");
  EXPECT_EQ(plain.solve(zero), zero);
  EXPECT_LE((plain.solve(load) - expected).norm(), 1e-12 * expected.norm());
  EXPECT_EQ(plain.backward_only_solve_count(), 0);
}

TEST(Cholesky, TrailingCongruenceRejectsOtherUnknownsAndMissingBlocks) {
  const int size = 200;
  const SparseMatrix matrix = random_sparse_spd(size, 3, 61);
  const std::vector<int> trailing = random_unknowns(size, 20, 62);
  const CholeskyFactor factor(matrix, "block", {.trailing_unknowns = trailing});
  std::vector<int> others;
  for (int j = 0; j < size; ++j) {
    if (std::find(trailing.begin(), trailing.end(), j) == trailing.end()) others.push_back(j);
  }
  EXPECT_THROW(factor.trailing_congruence(random_trace(5, size, others, 63)),
               std::invalid_argument);
  EXPECT_THROW(factor.trailing_congruence(SparseMatrix(5, size + 1)), std::invalid_argument);

  const CholeskyFactor plain(matrix, "block");
  EXPECT_FALSE(plain.has_trailing_block());
  EXPECT_THROW(plain.trailing_congruence(random_trace(5, size, trailing, 64)), std::logic_error);

  EXPECT_THROW(CholeskyFactor(matrix, "block", {.trailing_unknowns = {3, 7, 3}}),
               std::invalid_argument);
  EXPECT_THROW(CholeskyFactor(matrix, "block", {.trailing_unknowns = {size}}),
               std::invalid_argument);
}

TEST(Cholesky, EmptyOrNonSquareMatrixIsAnInputError) {
  EXPECT_THROW(CholeskyFactor(SparseMatrix(0, 0), "empty"), InputError);
  EXPECT_THROW(CholeskyFactor(SparseMatrix(3, 4), "rectangle"), InputError);
}

}  // namespace
}  // namespace robin
