#include "coupling/acceleration.hpp"

#include <cmath>
#include <utility>
#include <vector>

#include "coupling/acceleration_aitken.hpp"
#include "coupling/acceleration_blockwise.hpp"
#include "coupling/acceleration_quasi_newton.hpp"
#include "coupling/acceleration_relaxation.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

void require(bool condition, const std::string& field, const std::string& rule, double value) {
  if (condition) return;
  throw InputError("acceleration." + field + " must be " + rule + ", got " +
                   format_for_state(value));
}

std::unique_ptr<Acceleration> per_body(int size1, std::unique_ptr<Acceleration> body1, int size2,
                                       std::unique_ptr<Acceleration> body2) {
  std::vector<std::unique_ptr<Acceleration>> parts;
  parts.push_back(std::move(body1));
  parts.push_back(std::move(body2));
  return std::make_unique<BlockwiseAcceleration>(std::vector<int>{size1, size2}, std::move(parts));
}

QuasiNewtonMixing parse_mixing(const std::string& mixing) {
  if (mixing == "full") return QuasiNewtonMixing::full;
  if (mixing == "relaxation") return QuasiNewtonMixing::relaxation;
  return QuasiNewtonMixing::aitken;
}

std::unique_ptr<Acceleration> make_quasi_newton(const AccelerationOptions& options, int size1,
                                                int size2) {
  const QuasiNewtonParameters parameters{options.history_depth,    options.filter_threshold,
                                         options.safeguard_growth, parse_mixing(options.mixing),
                                         options.aitken_minimum,   options.aitken_maximum};
  const RelaxationBlock body1{size1, options.relaxation1};
  const RelaxationBlock body2{size2, options.relaxation2};
  if (!options.per_body) {
    return std::make_unique<IqnIlsAcceleration>(std::vector<RelaxationBlock>{body1, body2},
                                                parameters);
  }
  return per_body(
      size1, std::make_unique<IqnIlsAcceleration>(std::vector<RelaxationBlock>{body1}, parameters),
      size2, std::make_unique<IqnIlsAcceleration>(std::vector<RelaxationBlock>{body2}, parameters));
}

}  // namespace

void validate(const AccelerationOptions& options) {
  if (options.method != "none" && options.method != "aitken" && options.method != "iqn-ils") {
    throw InputError("acceleration.method must be \"none\", \"aitken\" or \"iqn-ils\", got \"" +
                     options.method + "\"");
  }
  if (options.mixing != "full" && options.mixing != "relaxation" && options.mixing != "aitken") {
    throw InputError("acceleration.mixing must be \"full\", \"relaxation\" or \"aitken\", got \"" +
                     options.mixing + "\"");
  }
  // The relaxation range of the plain iteration (case file: coupling.relaxation).
  require(options.relaxation1 > 0.0 && options.relaxation1 < 2.0, "relaxation1", "in (0, 2)",
          options.relaxation1);
  require(options.relaxation2 > 0.0 && options.relaxation2 < 2.0, "relaxation2", "in (0, 2)",
          options.relaxation2);
  require(options.aitken_minimum > 0.0 && std::isfinite(options.aitken_minimum), "aitken_minimum",
          "> 0", options.aitken_minimum);
  require(options.aitken_maximum >= options.aitken_minimum && options.aitken_maximum < 2.0,
          "aitken_maximum", "in [aitken_minimum, 2)", options.aitken_maximum);
  require(options.aitken_initial >= options.aitken_minimum &&
              options.aitken_initial <= options.aitken_maximum,
          "aitken_initial", "in [aitken_minimum, aitken_maximum]", options.aitken_initial);
  require(options.history_depth >= 1, "history_depth", ">= 1", options.history_depth);
  require(options.filter_threshold >= 0.0 && options.filter_threshold < 1.0, "filter_threshold",
          "in [0, 1)", options.filter_threshold);
  require(options.safeguard_growth > 1.0, "safeguard_growth", "> 1", options.safeguard_growth);
}

std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options, int size1,
                                                int size2) {
  validate(options);
  if (options.method == "none") {
    return std::make_unique<FixedRelaxation>(
        std::vector<RelaxationBlock>{{size1, options.relaxation1}, {size2, options.relaxation2}});
  }
  if (options.method == "aitken") {
    const AitkenParameters parameters{options.aitken_initial, options.aitken_minimum,
                                      options.aitken_maximum};
    return per_body(size1, std::make_unique<AitkenAcceleration>(size1, parameters), size2,
                    std::make_unique<AitkenAcceleration>(size2, parameters));
  }
  return make_quasi_newton(options, size1, size2);
}

}  // namespace robin
