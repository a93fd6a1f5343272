#pragma once
// Stopping a run on SIGINT / SIGTERM: the handlers only record the signal; the waits of the
// coordinator (ports, child processes, the iteration observer) check it and throw
// RunInterrupted, so that the run unwinds normally, ends the servers' runs and reaps children.

#include <stdexcept>

namespace robin {

class RunInterrupted : public std::runtime_error {
 public:
  explicit RunInterrupted(int signal_number);
  int signal_number() const { return signal_number_; }

 private:
  int signal_number_;
};

/// Installs the handlers of SIGINT and SIGTERM (without SA_RESTART, so blocking waits return
/// early with EINTR).
void install_stop_signal_handlers();

/// The first stop signal received, or 0.
int stop_signal();

/// Throws RunInterrupted when a stop signal was received.
void throw_if_stop_requested();

/// The conventional exit code of a process stopped by `signal_number`: 128 + signal number
/// (130 for SIGINT, 143 for SIGTERM).
int interrupted_exit_code(int signal_number);

}  // namespace robin
