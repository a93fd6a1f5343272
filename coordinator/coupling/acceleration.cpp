#include "coupling/acceleration.hpp"

#include <cmath>
#include <stdexcept>
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

/// One instance per block, made by `make_block(block index, block size)`, or the instance itself
/// when there is a single block.
template <typename MakeBlock>
std::unique_ptr<Acceleration> per_block(const std::vector<int>& sizes, MakeBlock make_block) {
  if (sizes.size() == 1) return make_block(0, sizes[0]);
  std::vector<std::unique_ptr<Acceleration>> parts;
  for (std::size_t block = 0; block < sizes.size(); ++block) {
    parts.push_back(make_block(static_cast<int>(block), sizes[block]));
  }
  return std::make_unique<BlockwiseAcceleration>(sizes, std::move(parts));
}

/// delta of block `block`: relaxation1 for the first, relaxation2 for the second and every
/// further block (the bodies of a contact graph beyond the second).
RelaxationBlock relaxation_block(const AccelerationOptions& options, int block, int size) {
  return {size, block == 0 ? options.relaxation1 : options.relaxation2};
}

std::unique_ptr<Acceleration> make_quasi_newton(const AccelerationOptions& options,
                                                const std::vector<int>& sizes) {
  const QuasiNewtonParameters parameters{options.history_depth,    options.filter_threshold,
                                         options.safeguard_growth, options.mixing,
                                         options.aitken_minimum,   options.aitken_maximum};
  if (!options.per_body) {
    std::vector<RelaxationBlock> blocks;
    for (std::size_t block = 0; block < sizes.size(); ++block) {
      blocks.push_back(relaxation_block(options, static_cast<int>(block), sizes[block]));
    }
    return std::make_unique<IqnIlsAcceleration>(blocks, parameters);
  }
  return per_block(sizes, [&](int block, int size) -> std::unique_ptr<Acceleration> {
    return std::make_unique<IqnIlsAcceleration>(
        std::vector<RelaxationBlock>{relaxation_block(options, block, size)}, parameters);
  });
}

}  // namespace

void validate(const AccelerationOptions& options) {
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

std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options,
                                                const std::vector<int>& block_sizes) {
  validate(options);
  if (block_sizes.empty()) throw std::invalid_argument("make_acceleration: no blocks");
  if (options.method == AccelerationMethod::none) {
    std::vector<RelaxationBlock> blocks;
    for (std::size_t block = 0; block < block_sizes.size(); ++block) {
      blocks.push_back(relaxation_block(options, static_cast<int>(block), block_sizes[block]));
    }
    return std::make_unique<FixedRelaxation>(blocks);
  }
  if (options.method == AccelerationMethod::aitken) {
    const AitkenParameters parameters{options.aitken_initial, options.aitken_minimum,
                                      options.aitken_maximum};
    return per_block(block_sizes, [&](int /*block*/, int size) -> std::unique_ptr<Acceleration> {
      return std::make_unique<AitkenAcceleration>(size, parameters);
    });
  }
  return make_quasi_newton(options, block_sizes);
}

std::unique_ptr<Acceleration> make_acceleration(const AccelerationOptions& options, int size1,
                                                int size2) {
  return make_acceleration(options, std::vector<int>{size1, size2});
}

}  // namespace robin
