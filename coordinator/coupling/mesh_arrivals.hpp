#pragma once

// Which bodies' meshes are in, for setups that wait each for its own body's mesh while the
// other meshes are still being read or meshed (run_coupled_case).

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <optional>
#include <vector>

namespace robin {

/// Thread-safe: one thread loads the meshes and tells each arrival, others wait.
class MeshArrivals {
 public:
  using Clock = std::chrono::steady_clock;

  explicit MeshArrivals(std::size_t bodies);

  /// Body `body`'s mesh is in its definition (the loading thread).
  void arrive(std::size_t body);
  /// No further mesh will arrive (the loading failed): every waiter gets false.
  void abandon();
  /// Blocks until body `body`'s mesh has arrived (true) or the loading was abandoned (false).
  bool wait(std::size_t body);
  /// When the first mesh arrived; empty before.
  std::optional<Clock::time_point> first_arrival() const;
  /// When the last mesh so far arrived; empty before the first.
  std::optional<Clock::time_point> last_arrival() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<bool> arrived_;
  bool abandoned_ = false;
  std::optional<Clock::time_point> first_arrival_;
  std::optional<Clock::time_point> last_arrival_;
};

}  // namespace robin
