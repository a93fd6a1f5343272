// The cost of build_mortar_coupling alone against the number of contact segments: two straight
// non-matching boundaries of n and 1.4 n segments (ratio of the patch test), n = 1e2 .. 1e5.
// A cost per segment that stays flat as n grows shows the spatial search is linear (a quadratic
// search would grow the per-segment cost with n). docs/benchmarks.md.
// Usage: build/benchmarks/mortar_coupling_benchmark

#include <chrono>
#include <cstdio>

#include "coupling/mortar_coupling.hpp"

namespace {

robin::InterfaceDescription straight(int count, double y, const Eigen::Vector3d& outward,
                                     int first_id, bool body_on_left_forward) {
  robin::InterfaceDescription side;
  for (int i = 0; i <= count; ++i) {
    side.node_ids.push_back(first_id + i);
    side.node_tags.push_back(static_cast<std::size_t>(first_id + i + 1));
    side.coordinates.emplace_back(static_cast<double>(i) / count, y, 0.0);
    side.normals.push_back(outward);
    side.weights.push_back((i == 0 || i == count ? 0.5 : 1.0) / count);
    side.fixed.push_back({false, false, false});
  }
  side.surfaces.emplace_back();
  side.surfaces.back().boundary = "contact";
  for (int i = 0; i < count; ++i) {
    side.surfaces.back().facets.push_back(body_on_left_forward ? i : i + 1);
    side.surfaces.back().facets.push_back(body_on_left_forward ? i + 1 : i);
  }
  return side;
}

}  // namespace

int main() {
  std::printf("| segments (non-mortar) | constraints | seconds | microseconds per segment |\n");
  std::printf("|---|---|---|---|\n");
  for (const int count : {100, 1000, 10000, 100000}) {
    const robin::InterfaceDescription lower = straight(count, 0.0, {0.0, 1.0, 0.0}, 0, false);
    const robin::InterfaceDescription upper =
        straight(static_cast<int>(1.4 * count), 0.0, {0.0, -1.0, 0.0}, 10 * count, true);
    const auto start = std::chrono::steady_clock::now();
    const robin::ContactPairing pairing =
        robin::build_mortar_coupling(lower, "lower", upper, "upper", nullptr, {});
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int segments = static_cast<int>(1.4 * count);
    std::printf("| %d | %zu | %.4f | %.2f |\n", segments, pairing.size(), seconds,
                1e6 * seconds / segments);
  }
  return 0;
}
