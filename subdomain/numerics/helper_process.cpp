#include "numerics/helper_process.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <stdexcept>

namespace robin {

namespace {

/// The signals whose disposition the child resets before the exec: those a crash raises, and
/// those that stop a run (which the servers and the tools catch).
constexpr int signals_to_reset[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGINT, SIGTERM};

/// In the child, between fork and exec: the parent may have other threads, so only
/// async-signal-safe calls (sigaction, sigprocmask, dup2, execv, _exit) and no allocation. Runs
/// `argv` with its standard output on `descriptor`; never returns.
[[noreturn]] void run_in_child(char* const* argv, int descriptor) {
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  for (const int signal_number : signals_to_reset) {
    sigaction(signal_number, &default_action, nullptr);
  }
  sigset_t no_signals;
  sigemptyset(&no_signals);
  sigprocmask(SIG_SETMASK, &no_signals, nullptr);
  if (dup2(descriptor, STDOUT_FILENO) >= 0) execv(argv[0], argv);
  _exit(cannot_execute_status);
}

}  // namespace

HelperProcess start_helper_process(char* const* argv, const char* pipe_failure,
                                   const char* fork_failure) {
  int pipe_ends[2];
  if (pipe2(pipe_ends, O_CLOEXEC) != 0) throw std::runtime_error(pipe_failure);
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    throw std::runtime_error(fork_failure);
  }
  if (pid == 0) run_in_child(argv, pipe_ends[1]);
  close(pipe_ends[1]);
  return {pid, pipe_ends[0]};
}

}  // namespace robin
