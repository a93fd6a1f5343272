#pragma once
// Nonnegative least squares (Lawson & Hanson, "Solving Least Squares Problems", 1974, ch. 23):
//
//   minimise ||A x - b||  subject to  x >= 0,
//
// for a small dense A with few rows (m <= a few, any number of columns n). Used to decide
// whether the equality G lambda = h of a floating body (smalbe.hpp) has a solution lambda >= 0,
// i.e. whether h lies in the cone spanned by the columns of G: the residual is zero exactly then.
// Active-set method: the passive columns stay linearly independent, so at most m of them, and
// the method ends after finitely many steps (bounded here by 3 n + 30 as a guard).

#include <Eigen/Core>

namespace robin {

struct NonnegativeLeastSquaresResult {
  Eigen::VectorXd solution;    // x >= 0
  double residual_norm = 0.0;  // ||A x - b||
};

NonnegativeLeastSquaresResult solve_nonnegative_least_squares(const Eigen::MatrixXd& matrix,
                                                              const Eigen::VectorXd& target);

}  // namespace robin
