#pragma once
// A child process of the launcher (fork + exec, Linux): its standard output on a pipe that the
// parent reads line by line with a deadline, its standard error appended to a log file.
//
// Lifetime guarantees: the child gets prctl(PR_SET_PDEATHSIG, parent_death_signal), so it is
// signalled when the parent's starting thread ends (also when the parent is killed); stop()
// and the destructor always reap it (waitpid), so no zombie or orphan is left behind.
//
// Starting through a command prefix (not used by robin-run yet): `command_prefix` puts words in
// front of the command line, e.g. {"srun", "--ntasks=1"}, {"ssh", "node7"} or
// {"valgrind", "--error-exitcode=1"}; the program run is then command_prefix[0], looked up in
// PATH, with the rest of the prefix, the executable and its arguments as its arguments. The
// prefix program must pass the child's standard output through and forward SIGTERM.

#include <sys/types.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace robin {

struct ChildProcessOptions {
  std::filesystem::path executable;
  std::vector<std::string> arguments;
  /// Standard error is appended to this file (created if needed); empty: inherited.
  std::filesystem::path log_file;
  std::vector<std::string> command_prefix;  // see the file comment; empty: run `executable`
  /// Variables (name, value) set in the child's environment on top of the parent's: a name
  /// the parent has is replaced, every other variable of the parent is passed on.
  std::vector<std::pair<std::string, std::string>> environment;
  int parent_death_signal = SIGTERM;
  /// The child leads its own process group, so that a terminal's Ctrl-C reaches only the
  /// parent, which then stops the child in order (and signals reach the whole group).
  bool new_process_group = true;
};

/// A deadline passed while waiting for the child.
class ChildTimeout : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ChildProcess {
 public:
  using Clock = std::chrono::steady_clock;

  /// Starts the child. Throws std::runtime_error naming the program when the log file cannot
  /// be opened or the program cannot be executed (e.g. it does not exist).
  explicit ChildProcess(const ChildProcessOptions& options);
  /// Kills (SIGKILL) and reaps a child that is still running.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }

  /// The next line of the child's standard output, without the newline; nullopt when the
  /// child closed its output (usually: it exited). Throws ChildTimeout at the deadline.
  /// `on_wait` runs at least every 100 ms and may throw to abandon the wait.
  std::optional<std::string> read_line(Clock::time_point deadline,
                                       const std::function<void()>& on_wait = {});

  /// Empty while the child runs; once it has exited (it is reaped here, without blocking)
  /// "exited with status N" or "was killed by signal N (Name)". Thread-safe.
  std::string exit_description();
  bool running() { return exit_description().empty(); }

  /// Waits up to `seconds` for the child to exit; true when it has. Woken by the exit itself
  /// (a pidfd), not by polling, where the kernel has pidfd_open.
  bool wait_for_exit(double seconds);

  /// SIGTERM, then SIGKILL when the child is still running after `grace_seconds`; always
  /// reaps. Does nothing when the child has already exited.
  void stop(double grace_seconds) noexcept;

 private:
  void send_signal(int signal_number);
  bool reap(int options);

  pid_t pid_ = -1;
  int output_descriptor_ = -1;
  int exit_descriptor_ = -1;  // pidfd of the child, readable once it has exited; -1: none
  bool own_group_ = false;
  std::string pending_output_;
  std::mutex mutex_;  // guards status_ and reaped_
  int status_ = 0;
  bool reaped_ = false;
};

}  // namespace robin
