#pragma once
// A symmetric positive (semi)definite operator y = A x, applied without forming A.

#include <Eigen/Core>

namespace robin {

class LinearOperator {
 public:
  virtual ~LinearOperator() = default;
  virtual int size() const = 0;
  /// y = A x; y is resized by the callee.
  virtual void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const = 0;
};

/// A dense symmetric matrix as an operator (small problems and assembled interface operators).
class DenseOperator final : public LinearOperator {
 public:
  explicit DenseOperator(Eigen::MatrixXd matrix) : matrix_(std::move(matrix)) {}
  int size() const override { return static_cast<int>(matrix_.rows()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    y.noalias() = matrix_ * x;
  }
  const Eigen::MatrixXd& matrix() const { return matrix_; }

 private:
  Eigen::MatrixXd matrix_;
};

}  // namespace robin
