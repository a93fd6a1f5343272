#pragma once
// The [loading] table of a case file (docs/case-format.md, "[loading]"): quasi-static load
// steps. Step k multiplies every load of both bodies (body forces, traction vectors,
// pressures) and every prescribed displacement of their Dirichlet conditions by the load
// factor t_k; the bodies are assembled and factorized once, and each step starts from the
// solution of the previous one.
//
//   [loading]
//   factors = [0.25, 0.5, 0.75, 1.0]   # or: steps = 4 (the factors 1/4, 2/4, 3/4, 1)
//   warm_start = true                  # optional

#include <cstddef>
#include <string>
#include <vector>

namespace robin {

class CheckedTable;

struct LoadingOptions {
  /// The load factor of each step, in order; empty when the case has no [loading] table (one
  /// solve at the loads as written, factor 1).
  std::vector<double> factors;
  /// Whether step k > 1 starts from step k - 1 (the obstacles of its fixed point, and the
  /// servers' contact forces as the initial guess of their contact solves) or, when false,
  /// from the case's initial obstacle like a fresh run (for comparisons).
  bool warm_start = true;
  /// "case.toml:31: loading" for messages about the steps; empty without [loading].
  std::string context;

  bool stepped() const { return !factors.empty(); }
  /// The PVD timestep of step k (zero-based): its load factor when the factors increase
  /// strictly, otherwise the step number k + 1 (ParaView orders datasets by timestep).
  double timestep(std::size_t step) const;
};

/// The largest number of steps and the largest factor magnitude [loading] accepts (the
/// servers refuse a factor above 1e6 in magnitude as well).
inline constexpr std::size_t maximum_load_steps = 10000;
inline constexpr double maximum_load_factor_magnitude = 1e6;

/// Reads and checks the optional [loading] table of the case file's root table: exactly one of
/// `factors` (a non-empty array of finite numbers, each of magnitude at most 1e6, at most 10000
/// of them) and `steps` (an integer in [1, 10000]); `warm_start` a boolean. Throws InputError
/// naming the file, the line and the key (loading.factors[3] for one factor).
LoadingOptions read_loading(const CheckedTable& root);

}  // namespace robin
