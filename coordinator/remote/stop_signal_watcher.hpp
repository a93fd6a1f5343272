#pragma once
// Acting on SIGINT / SIGTERM in a process whose work cannot check for them: robin-monolithic's
// meshing, factorizations and QP solve run for seconds without a point where
// throw_if_stop_requested (run_interruption.hpp) could be called. A thread of its own polls
// stop_signal() and calls the handler, which records the interruption and ends the process.

#include <atomic>
#include <functional>
#include <thread>

namespace robin {

class StopSignalWatcher {
 public:
  /// Starts the watching thread: once a stop signal was received (install_stop_signal_handlers
  /// must have been called), `on_stop(signal_number)` is called from that thread, once. The
  /// handler is expected to end the process (see end_interrupted_process).
  explicit StopSignalWatcher(std::function<void(int signal_number)> on_stop);
  /// Stops the thread (without calling the handler when no signal came).
  ~StopSignalWatcher();
  StopSignalWatcher(const StopSignalWatcher&) = delete;
  StopSignalWatcher& operator=(const StopSignalWatcher&) = delete;

 private:
  std::atomic<bool> finished_{false};
  std::thread thread_;
};

/// Ends this process at once with the exit status 128 + `signal_number` (interrupted_exit_code),
/// after killing its own child processes (found in /proc: e.g. Gmsh meshing children, which
/// ignore the stop signal as their parent does). No destructors run: write what must be kept
/// before calling it.
[[noreturn]] void end_interrupted_process(int signal_number);

}  // namespace robin
