// The start of a solve from earlier solutions (solution_history.hpp) against dense solves of a
// small random problem: K symmetric positive definite, B a random trace operator. The start of a
// force in the span of the kept ones is the solution; for any other force it is the Galerkin
// projection of the solution onto the kept solutions (the dense (X'KX)^{-1} X'B'r), which is
// nearer in the energy norm than zero; the oldest solution is forgotten beyond the capacity.

#include "numerics/solution_history.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <stdexcept>

namespace robin {
namespace {

struct Problem {
  Eigen::MatrixXd stiffness;  // K
  Eigen::MatrixXd trace;      // B (forces x unknowns)
  Eigen::VectorXd solve(const Eigen::VectorXd& force) const {
    return stiffness.llt().solve(trace.transpose() * force);
  }
};

Problem random_problem(int unknowns, int forces) {
  std::mt19937 generator(3);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const auto random = [&](int rows, int columns) {
    return Eigen::MatrixXd::NullaryExpr(rows, columns, [&] { return value(generator); }).eval();
  };
  const Eigen::MatrixXd factor = random(unknowns, unknowns);
  Problem problem;
  problem.stiffness =
      factor * factor.transpose() + unknowns * Eigen::MatrixXd::Identity(unknowns, unknowns);
  problem.trace = random(forces, unknowns);
  return problem;
}

Eigen::VectorXd force_vector(int forces, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  return Eigen::VectorXd::NullaryExpr(forces, [&] { return value(generator); });
}

double energy_norm(const Problem& problem, const Eigen::VectorXd& error) {
  return std::sqrt(error.dot(problem.stiffness * error));
}

void keep(SolutionHistory& history, const Problem& problem, const Eigen::VectorXd& force) {
  const Eigen::VectorXd solution = problem.solve(force);
  history.add(force, solution, problem.trace * solution);
}

TEST(SolutionHistory, ACombinationOfKeptForcesStartsAtItsSolution) {
  const Problem problem = random_problem(40, 12);
  SolutionHistory history(4);
  EXPECT_TRUE(history.start(force_vector(12, 1), 40).isZero());
  const Eigen::VectorXd first = force_vector(12, 1), second = force_vector(12, 2);
  keep(history, problem, first);
  keep(history, problem, second);
  const Eigen::VectorXd combined = 0.3 * first - 1.7 * second;
  const Eigen::VectorXd expected = problem.solve(combined);
  EXPECT_LE((history.start(combined, 40) - expected).norm(), 1e-12 * expected.norm());
}

TEST(SolutionHistory, AnyOtherForceStartsAtTheGalerkinProjection) {
  const Problem problem = random_problem(40, 12);
  SolutionHistory history(4);
  Eigen::MatrixXd kept(40, 3);
  for (int k = 0; k < 3; ++k) {
    const Eigen::VectorXd force = force_vector(12, 10 + k);
    keep(history, problem, force);
    kept.col(k) = problem.solve(force);
  }
  const Eigen::VectorXd force = force_vector(12, 20);
  const Eigen::VectorXd solution = problem.solve(force);
  const Eigen::VectorXd projection =
      kept * (kept.transpose() * problem.stiffness * kept)
                 .llt()
                 .solve(kept.transpose() * problem.trace.transpose() * force);
  const Eigen::VectorXd start = history.start(force, 40);
  EXPECT_LE((start - projection).norm(), 1e-10 * projection.norm());
  EXPECT_LT(energy_norm(problem, solution - start), energy_norm(problem, solution));
}

TEST(SolutionHistory, DependentSolutionsAndTheCapacity) {
  const Problem problem = random_problem(30, 10);
  SolutionHistory history(2);
  const Eigen::VectorXd first = force_vector(10, 1);
  keep(history, problem, first);
  keep(history, problem, 2.0 * first);  // dependent: G is singular, the start still exact
  const Eigen::VectorXd expected = problem.solve(first);
  EXPECT_LE((history.start(first, 30) - expected).norm(), 1e-10 * expected.norm());
  keep(history, problem, force_vector(10, 2));
  keep(history, problem, force_vector(10, 3));  // both of `first`'s solutions forgotten
  EXPECT_EQ(history.size(), 2);
  EXPECT_GT((history.start(first, 30) - expected).norm(), 1e-3 * expected.norm());
  EXPECT_THROW(history.start(force_vector(9, 4), 30), std::invalid_argument);
  EXPECT_THROW(history.add(force_vector(9, 4), expected, force_vector(9, 5)),
               std::invalid_argument);
  history.clear();
  EXPECT_TRUE(history.empty());
}

}  // namespace
}  // namespace robin
