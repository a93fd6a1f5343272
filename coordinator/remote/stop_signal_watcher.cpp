#include "remote/stop_signal_watcher.hpp"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "remote/run_interruption.hpp"

namespace robin {
namespace {

/// The parent pid of process `pid` from /proc/PID/stat (0 when it cannot be read).
long parent_of(const std::string& pid) {
  std::ifstream file("/proc/" + pid + "/stat");
  std::string text;
  std::getline(file, text);
  // pid (comm) state ppid ...: comm may hold spaces and parentheses, so skip to the last ')'
  const std::size_t end = text.rfind(')');
  if (end == std::string::npos) return 0;
  char state = 0;
  long parent = 0;
  std::istringstream fields(text.substr(end + 1));
  fields >> state >> parent;
  return parent;
}

void kill_child_processes() {
  std::error_code error;
  const long self = static_cast<long>(::getpid());
  for (std::filesystem::directory_iterator entry("/proc", error), end; !error && entry != end;
       entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (parent_of(name) == self) ::kill(static_cast<pid_t>(std::stol(name)), SIGKILL);
  }
}

}  // namespace

StopSignalWatcher::StopSignalWatcher(std::function<void(int)> on_stop)
    : thread_([this, on_stop = std::move(on_stop)] {
        while (!finished_.load()) {
          if (const int signal_number = stop_signal(); signal_number != 0) {
            on_stop(signal_number);
            return;
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
      }) {}

StopSignalWatcher::~StopSignalWatcher() {
  finished_.store(true);
  if (thread_.joinable()) thread_.join();
}

void end_interrupted_process(int signal_number) {
  kill_child_processes();
  std::_Exit(interrupted_exit_code(signal_number));
}

}  // namespace robin
