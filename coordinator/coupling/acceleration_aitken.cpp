#include "coupling/acceleration_aitken.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "coupling/acceleration_relaxation.hpp"

namespace robin {

AitkenAcceleration::AitkenAcceleration(int size, AitkenParameters parameters)
    : size_(size), parameters_(parameters), omega_(parameters.initial) {}

Eigen::VectorXd AitkenAcceleration::next(const Eigen::VectorXd& iterate,
                                         const Eigen::VectorXd& mapped) {
  if (iterate.size() != size_ || mapped.size() != size_) {
    throw std::invalid_argument("Aitken acceleration of size " + std::to_string(size_) +
                                " given vectors of sizes " + std::to_string(iterate.size()) +
                                " and " + std::to_string(mapped.size()));
  }
  // r_k = H(x_k) - x_k
  const Eigen::VectorXd residual = mapped - iterate;
  if (!has_previous_) {
    omega_ = parameters_.initial;
  } else {
    // omega_k = -omega_{k-1} r_{k-1}'(r_k - r_{k-1}) / |r_k - r_{k-1}|^2
    const Eigen::VectorXd residual_change = residual - previous_residual_;
    const double denominator = residual_change.squaredNorm();
    if (denominator > 0.0) {
      const double secant = -omega_ * previous_residual_.dot(residual_change) / denominator;
      const double magnitude =
          std::clamp(std::abs(secant), parameters_.minimum, parameters_.maximum);
      omega_ = std::copysign(magnitude, secant);
    }
  }
  previous_residual_ = residual;
  has_previous_ = true;
  // x_{k+1} = (1 - omega_k) x_k + omega_k H(x_k)
  return (1.0 - omega_) * iterate + omega_ * mapped;
}

std::string AitkenAcceleration::state() const {
  return "aitken omega = " + format_for_state(omega_);
}

void AitkenAcceleration::restart() {
  has_previous_ = false;
  omega_ = parameters_.initial;
}

}  // namespace robin
