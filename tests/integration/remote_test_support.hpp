#pragma once
// Helpers of the integration tests that run real robin-subdomain / robin-run processes.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../test_files.hpp"
#include "remote/child_process.hpp"
#include "remote/server_launcher.hpp"

namespace robin::testing {

inline std::filesystem::path example(const std::string& name) {
  return std::filesystem::path(ROBIN_EXAMPLES) / name;
}

inline std::filesystem::path tool(const std::string& name) {
  return std::filesystem::path(ROBIN_BINARY_DIR) / "bin" / name;
}

/// Options to start build/bin/robin-subdomain on `listen`, logging into `log_directory`.
inline ServerLaunchOptions server_options(const std::filesystem::path& log_directory,
                                          const std::string& listen = "tcp://127.0.0.1:*") {
  ServerLaunchOptions options;
  options.executable = tool("robin-subdomain");
  options.log_directory = log_directory;
  options.listen = listen;
  options.log_level = "warn";
  return options;
}

/// Options to start the Python server python/robin-subdomain-py (same command line as
/// robin-subdomain) under /usr/bin/python3.
inline ServerLaunchOptions python_server_options(const std::filesystem::path& log_directory) {
  ServerLaunchOptions options = server_options(log_directory);
  options.executable = std::filesystem::path(ROBIN_EXAMPLES) / "../python/robin-subdomain-py";
  options.command_prefix = {"/usr/bin/python3"};
  options.startup_timeout_seconds = 60.0;
  return options;
}

/// max_i |a_i - b_i| <= tolerance * max(max_i |b_i|, tiny), with the sizes equal.
inline ::testing::AssertionResult vectors_close(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                                double tolerance) {
  if (a.size() != b.size()) {
    return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size();
  }
  const double scale = std::max(b.lpNorm<Eigen::Infinity>(), 1e-300);
  const double difference = a.size() == 0 ? 0.0 : (a - b).lpNorm<Eigen::Infinity>();
  if (difference <= tolerance * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "max difference " << difference << " > " << tolerance << " x " << scale;
}

/// What a finished tool process left behind.
struct ProcessOutcome {
  std::string exit;    // ChildProcess::exit_description(), e.g. "exited with status 0"
  std::string errors;  // its standard error
  std::string output;  // its standard output
};

/// Runs build/bin/`executable` `arguments`... to completion (at most `timeout_seconds`), its
/// standard error in `directory`/`executable`.stderr.
inline ProcessOutcome run_tool(const std::string& executable,
                               const std::vector<std::string>& arguments,
                               const std::filesystem::path& directory, double timeout_seconds) {
  ChildProcessOptions options;
  options.executable = tool(executable);
  options.arguments = arguments;
  options.log_file = directory / (executable + ".stderr");
  ChildProcess process(options);
  ProcessOutcome outcome;
  while (const auto line = process.read_line(ChildProcess::Clock::time_point::max())) {
    outcome.output += *line + "\n";
  }
  EXPECT_TRUE(process.wait_for_exit(timeout_seconds)) << executable << " did not finish";
  outcome.exit = process.exit_description();
  std::ifstream file(options.log_file);
  outcome.errors.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  return outcome;
}

/// The columns of a CSV file (history.csv, contact.csv, steps.csv) by header name.
inline std::map<std::string, std::vector<std::string>> read_csv(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::map<std::string, std::vector<std::string>> columns;
  std::vector<std::string> names;
  std::string line;
  for (bool header = true; std::getline(file, line); header = false) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t k = 0; std::getline(row, cell, ','); ++k) {
      if (header) {
        names.push_back(cell);
      } else if (k < names.size()) {
        columns[names[k]].push_back(cell);
      }
    }
  }
  return columns;
}

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace robin::testing
