#include "remote/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>
#include <utility>

namespace robin {

namespace {

constexpr int wait_slice_milliseconds = 100;

std::string system_error_text(int error_number) {
  return std::strerror(error_number);
}

/// The child's command line: the prefix (if any), the executable, its arguments.
std::vector<std::string> command_line(const ChildProcessOptions& options) {
  std::vector<std::string> words = options.command_prefix;
  words.push_back(options.executable.string());
  words.insert(words.end(), options.arguments.begin(), options.arguments.end());
  return words;
}

/// The child's environment, "NAME=value" words: the parent's, with options.environment's
/// variables replacing or added to it. Built before fork (the child must not allocate).
std::vector<std::string> child_environment(const ChildProcessOptions& options) {
  std::vector<std::string> words;
  const auto overridden = [&options](const std::string& word) {
    return std::any_of(options.environment.begin(), options.environment.end(),
                       [&word](const auto& variable) {
                         return word.size() > variable.first.size() &&
                                word.compare(0, variable.first.size(), variable.first) == 0 &&
                                word[variable.first.size()] == '=';
                       });
  };
  for (char** variable = environ; variable != nullptr && *variable != nullptr; ++variable) {
    if (!overridden(*variable)) words.emplace_back(*variable);
  }
  for (const auto& [name, value] : options.environment) words.push_back(name + "=" + value);
  return words;
}

/// Pointers to `words` followed by the null pointer that ends an argv or envp array.
std::vector<char*> null_terminated(std::vector<std::string>& words) {
  std::vector<char*> pointers;
  for (std::string& word : words) pointers.push_back(word.data());
  pointers.push_back(nullptr);
  return pointers;
}

/// Everything between fork and exec: only async-signal-safe calls. Never returns; on failure
/// the errno of the failed call is written to `error_descriptor`.
[[noreturn]] void become_child(const ChildProcessOptions& options, char* const* argv,
                               char* const* environment, pid_t parent, int output_descriptor,
                               int log_descriptor, int error_descriptor) {
  if (options.new_process_group) setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, options.parent_death_signal);
  if (getppid() != parent) _exit(127);  // the parent died before prctl took effect
  sigset_t all_signals;
  sigemptyset(&all_signals);
  sigprocmask(SIG_SETMASK, &all_signals, nullptr);
  if (dup2(output_descriptor, STDOUT_FILENO) < 0 ||
      (log_descriptor >= 0 && dup2(log_descriptor, STDERR_FILENO) < 0)) {
    const int error_number = errno;
    [[maybe_unused]] auto written = write(error_descriptor, &error_number, sizeof error_number);
    _exit(127);
  }
  if (options.command_prefix.empty()) {
    execve(argv[0], argv, environment);
  } else {
    execvpe(argv[0], argv, environment);
  }
  const int error_number = errno;
  [[maybe_unused]] auto written = write(error_descriptor, &error_number, sizeof error_number);
  _exit(127);
}

int open_log_file(const std::filesystem::path& path) {
  if (path.empty()) return -1;
  const int descriptor = open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (descriptor < 0) {
    throw std::runtime_error("cannot open log file '" + path.string() +
                             "': " + system_error_text(errno));
  }
  return descriptor;
}

/// The errno the child reported through the close-on-exec pipe, or 0 when exec succeeded
/// (the pipe closed without data).
int read_exec_error(int descriptor) {
  int error_number = 0;
  ssize_t count = 0;
  do {
    count = read(descriptor, &error_number, sizeof error_number);
  } while (count < 0 && errno == EINTR);
  return count == static_cast<ssize_t>(sizeof error_number) ? error_number : 0;
}

/// A descriptor that becomes readable when process `pid` (a child not yet reaped) exits
/// (pidfd_open, Linux 5.3); -1 when the kernel or the C library has none.
int open_exit_descriptor(pid_t pid) {
#ifdef SYS_pidfd_open
  return static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
#else
  (void)pid;
  return -1;
#endif
}

/// Waits up to `milliseconds` for `exit_descriptor` (open_exit_descriptor) to become readable;
/// false when the wait failed at once (the caller then sleeps instead of spinning). A signal or
/// the timeout ends the wait early without being an error.
bool await_exit_event(int exit_descriptor, long milliseconds) {
  pollfd item{exit_descriptor, POLLIN, 0};
  const int ready = poll(&item, 1, static_cast<int>(std::min<long>(milliseconds, 60'000)));
  return ready >= 0 || errno == EINTR;
}

}  // namespace

ChildProcess::ChildProcess(const ChildProcessOptions& options)
    : own_group_(options.new_process_group) {
  std::vector<std::string> words = command_line(options);
  const std::vector<char*> argv = null_terminated(words);
  std::vector<std::string> environment_words = child_environment(options);
  const std::vector<char*> environment = null_terminated(environment_words);
  const int log_descriptor = open_log_file(options.log_file);
  int output[2], error[2];
  if (pipe2(output, O_CLOEXEC) != 0 || pipe2(error, O_CLOEXEC) != 0) {
    throw std::runtime_error("cannot create a pipe for '" + words.front() +
                             "': " + system_error_text(errno));
  }
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ == 0) {
    become_child(options, argv.data(), environment.data(), parent, output[1], log_descriptor,
                 error[1]);
  }
  const int fork_error = errno;
  close(output[1]);
  close(error[1]);
  if (log_descriptor >= 0) close(log_descriptor);
  output_descriptor_ = output[0];
  const int exec_error = pid_ > 0 ? read_exec_error(error[0]) : fork_error;
  close(error[0]);
  if (pid_ > 0 && exec_error != 0) reap(0);
  if (pid_ > 0 && exec_error == 0) exit_descriptor_ = open_exit_descriptor(pid_);
  if (pid_ < 0 || exec_error != 0) {
    close(output_descriptor_);
    output_descriptor_ = -1;
    throw std::runtime_error("cannot start '" + words.front() +
                             "': " + system_error_text(exec_error));
  }
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && running()) {
    send_signal(SIGKILL);
    reap(0);
  }
  if (output_descriptor_ >= 0) close(output_descriptor_);
  if (exit_descriptor_ >= 0) close(exit_descriptor_);
}

std::optional<std::string> ChildProcess::read_line(Clock::time_point deadline,
                                                   const std::function<void()>& on_wait) {
  for (;;) {
    if (const auto end = pending_output_.find('\n'); end != std::string::npos) {
      std::string line = pending_output_.substr(0, end);
      pending_output_.erase(0, end + 1);
      return line;
    }
    if (output_descriptor_ < 0) {
      if (pending_output_.empty()) return std::nullopt;
      return std::exchange(pending_output_, std::string());
    }
    if (on_wait) on_wait();
    const auto remaining =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (remaining <= 0) throw ChildTimeout("no output line before the deadline");
    pollfd item{output_descriptor_, POLLIN, 0};
    const int ready =
        poll(&item, 1, static_cast<int>(std::min<long>(remaining, wait_slice_milliseconds)));
    if (ready <= 0) continue;  // timeout slice or EINTR
    char buffer[4096];
    const ssize_t count = read(output_descriptor_, buffer, sizeof buffer);
    if (count > 0) {
      pending_output_.append(buffer, static_cast<std::size_t>(count));
    } else if (count == 0 || errno != EINTR) {
      close(output_descriptor_);
      output_descriptor_ = -1;
    }
  }
}

bool ChildProcess::reap(int options) {
  std::lock_guard lock(mutex_);
  if (reaped_) return true;
  int status = 0;
  pid_t result = 0;
  do {
    result = waitpid(pid_, &status, options);
  } while (result < 0 && errno == EINTR);
  if (result == pid_ || (result < 0 && errno == ECHILD)) {
    status_ = result == pid_ ? status : 0;
    reaped_ = true;
  }
  return reaped_;
}

std::string ChildProcess::exit_description() {
  if (!reap(WNOHANG)) return "";
  std::lock_guard lock(mutex_);
  if (WIFSIGNALED(status_)) {
    const int signal_number = WTERMSIG(status_);
    return "was killed by signal " + std::to_string(signal_number) + " (" +
           strsignal(signal_number) + ")";
  }
  return "exited with status " + std::to_string(WIFEXITED(status_) ? WEXITSTATUS(status_) : -1);
}

bool ChildProcess::wait_for_exit(double seconds) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(seconds));
  while (!reap(WNOHANG)) {
    const auto remaining =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (remaining <= 0) return false;
    if (exit_descriptor_ < 0 || !await_exit_event(exit_descriptor_, remaining)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(std::min<long>(remaining, 10)));
    }
  }
  return true;
}

void ChildProcess::send_signal(int signal_number) {
  std::lock_guard lock(mutex_);
  if (reaped_) return;  // the pid may belong to another process by now
  // Until the child has called setpgid its group does not exist yet: then signal it alone.
  if (!own_group_ || kill(-pid_, signal_number) != 0) kill(pid_, signal_number);
}

void ChildProcess::stop(double grace_seconds) noexcept {
  if (pid_ <= 0 || reap(WNOHANG)) return;
  send_signal(SIGTERM);
  if (wait_for_exit(grace_seconds)) return;
  send_signal(SIGKILL);
  reap(0);
}

}  // namespace robin
