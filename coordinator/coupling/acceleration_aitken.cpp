#include "coupling/acceleration_aitken.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "coupling/acceleration_relaxation.hpp"
#include "coupling/checkpoint_encoding.hpp"

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

nlohmann::json AitkenAcceleration::save_state() const {
  return {{"method", "aitken"},
          {"omega", encode_number(omega_)},
          {"has_previous", has_previous_},
          {"previous_residual", encode_vector(previous_residual_)}};
}

void AitkenAcceleration::restore_state(const nlohmann::json& state) {
  if (decode_text(state, "method") != "aitken") {
    throw CheckpointFormatError("the checkpoint's acceleration is not 'aitken'");
  }
  Eigen::VectorXd previous = decode_vector(state, "previous_residual");
  const bool has_previous = decode_flag(state, "has_previous");
  if (has_previous && previous.size() != size_) {
    throw CheckpointFormatError("the checkpoint's aitken previous_residual has " +
                                std::to_string(previous.size()) + " values, expected " +
                                std::to_string(size_));
  }
  omega_ = decode_number(state, "omega");
  has_previous_ = has_previous;
  previous_residual_ = std::move(previous);
}

}  // namespace robin
