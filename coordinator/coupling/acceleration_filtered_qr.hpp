#pragma once
// Economy QR factorization V = Q R of a few secant columns, with the filter of preCICE's
// "QR1" kind: a column whose new direction is too small relative to the whole matrix is
// dropped, so that the least-squares problems of IQN-ILS stay well posed.

#include <Eigen/Core>
#include <vector>

namespace robin {

struct FilteredQr {
  Eigen::MatrixXd q;      // n x m, orthonormal columns
  Eigen::MatrixXd r;      // m x m, upper triangular with positive diagonal
  std::vector<int> kept;  // the m columns of V that were kept, in order (0-based)
};

/// Factors the columns of `columns` in their order (for IQN-ILS: newest first) by modified
/// Gram-Schmidt with one re-orthogonalisation pass. Column j is dropped, and the rest factored
/// as if it were absent, when |R_jj| < threshold * ||V||_F (||V||_F = ||R||_F of the unfiltered
/// factorization) or R_jj = 0. Then V(:, kept) = Q R up to rounding.
FilteredQr filtered_qr(const Eigen::MatrixXd& columns, double threshold);

}  // namespace robin
