#include "coupling/case_file_loading.hpp"

#include <cmath>

#include "coupling/case_file_body.hpp"
#include "coupling/case_file_table.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

const std::vector<std::string> loading_keys{"factors", "steps", "warm_start"};

/// The factors of `loading.factors`, each checked; messages name the element and its line.
std::vector<double> read_factors(const CheckedTable& table, const toml::node& node,
                                 const CaseContext& context) {
  const toml::array* array = node.as_array();
  if (array == nullptr) {
    table.fail("factors", "expected an array of load factors, e.g. [0.5, 1.0]");
  }
  if (array->empty()) table.fail("factors", "expected at least one load factor, found []");
  if (array->size() > maximum_load_steps) {
    table.fail("factors", "at most " + std::to_string(maximum_load_steps) +
                              " load steps are accepted, found " + std::to_string(array->size()));
  }
  std::vector<double> factors;
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& element = *array->get(i);
    const std::string where =
        context.prefix(line_of(element) > 0 ? line_of(element) : table.line("factors")) +
        ": loading.factors[" + std::to_string(i + 1) + "]: ";
    double value = 0.0;
    if (const auto* integer = element.as_integer()) {
      value = static_cast<double>(integer->get());
    } else if (const auto* floating = element.as_floating_point()) {
      value = floating->get();
    } else {
      throw InputError(where + "expected a number (a load factor)");
    }
    if (!std::isfinite(value) || std::abs(value) > maximum_load_factor_magnitude) {
      throw InputError(where + "must be a finite number of magnitude at most 1e6, got " +
                       format_number(value));
    }
    factors.push_back(value);
  }
  return factors;
}

}  // namespace

double LoadingOptions::timestep(std::size_t step) const {
  for (std::size_t k = 1; k < factors.size(); ++k) {
    if (!(factors[k] > factors[k - 1])) return static_cast<double>(step + 1);
  }
  return step < factors.size() ? factors[step] : static_cast<double>(step + 1);
}

LoadingOptions read_loading(const CheckedTable& root) {
  LoadingOptions loading;
  const auto table = root.optional_table("loading", loading_keys);
  if (!table) return loading;
  const CaseContext& context = root.context();
  loading.context = table->location("") + ": loading";
  const toml::table& raw = table->raw();
  const bool has_factors = raw.contains("factors");
  const bool has_steps = raw.contains("steps");
  if (has_factors && has_steps) {
    table->fail("steps", "give either factors or steps, not both");
  }
  if (has_factors) {
    loading.factors = read_factors(*table, *raw.get("factors"), context);
  } else if (has_steps) {
    const int steps = *table->optional_integer("steps");
    if (steps < 1 || static_cast<std::size_t>(steps) > maximum_load_steps) {
      table->fail("steps", "must be an integer in [1, " + std::to_string(maximum_load_steps) +
                               "], got " + std::to_string(steps));
    }
    for (int k = 1; k <= steps; ++k) loading.factors.push_back(static_cast<double>(k) / steps);
  } else {
    table->fail("",
                "expected one of factors (the load factor of each step) and steps (the "
                "number of equal steps up to factor 1)");
  }
  loading.warm_start = table->optional_boolean("warm_start").value_or(loading.warm_start);
  return loading;
}

}  // namespace robin
