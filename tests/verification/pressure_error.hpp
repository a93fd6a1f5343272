#pragma once
// The patch tests' measure: how far the contact forces of a pairing are from a uniform pressure.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "coupling/contact_pairing.hpp"

namespace robin {

/// Largest |lambda_j / m_j - p| / p over the rows j of `pairing` (m_j: the row's weight, the
/// area or length it carries), for contact forces lambda in row order and an exact pressure p.
inline double largest_pressure_error(const ContactPairing& pairing, const Eigen::VectorXd& force,
                                     double pressure) {
  double error = 0.0;
  for (std::size_t j = 0; j < pairing.size(); ++j) {
    const double value = force[static_cast<Eigen::Index>(j)] / pairing.pairs[j].weight;
    error = std::max(error, std::abs(value - pressure) / pressure);
  }
  return error;
}

}  // namespace robin
