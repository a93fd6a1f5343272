#include "coupling/acceleration_filtered_qr.hpp"

namespace robin {

FilteredQr filtered_qr(const Eigen::MatrixXd& columns, double threshold) {
  const Eigen::Index rows = columns.rows();
  const Eigen::Index count = columns.cols();
  const double scale = columns.norm();  // ||V||_F
  FilteredQr factors;
  factors.q.resize(rows, count);
  factors.r = Eigen::MatrixXd::Zero(count, count);
  Eigen::Index rank = 0;
  for (Eigen::Index column = 0; column < count; ++column) {
    Eigen::VectorXd direction = columns.col(column);
    Eigen::VectorXd coefficients = Eigen::VectorXd::Zero(rank);
    for (int pass = 0; pass < 2; ++pass) {
      for (Eigen::Index basis = 0; basis < rank; ++basis) {
        // v <- v - (q_i'v) q_i
        const double projection = factors.q.col(basis).dot(direction);
        direction -= projection * factors.q.col(basis);
        coefficients(basis) += projection;
      }
    }
    const double diagonal = direction.norm();  // R_jj
    if (diagonal == 0.0 || diagonal < threshold * scale) continue;
    factors.q.col(rank) = direction / diagonal;
    factors.r.col(rank).head(rank) = coefficients;
    factors.r(rank, rank) = diagonal;
    factors.kept.push_back(static_cast<int>(column));
    ++rank;
  }
  factors.q.conservativeResize(rows, rank);
  factors.r.conservativeResize(rank, rank);
  return factors;
}

}  // namespace robin
