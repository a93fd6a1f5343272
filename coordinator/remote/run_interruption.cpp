#include "remote/run_interruption.hpp"

#include <csignal>
#include <cstring>
#include <string>

namespace robin {

namespace {

volatile std::sig_atomic_t received_signal = 0;

extern "C" void record_stop_signal(int signal_number) {
  if (received_signal == 0) received_signal = signal_number;
}

}  // namespace

RunInterrupted::RunInterrupted(int signal_number)
    : std::runtime_error(std::string("stopped by signal ") + std::to_string(signal_number) + " (" +
                         strsignal(signal_number) + ")"),
      signal_number_(signal_number) {}

void install_stop_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = record_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll() and waits return EINTR
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int stop_signal() {
  return received_signal;
}

void throw_if_stop_requested() {
  if (const int signal_number = received_signal; signal_number != 0) {
    throw RunInterrupted(signal_number);
  }
}

int interrupted_exit_code(int signal_number) {
  return 128 + signal_number;
}

}  // namespace robin
