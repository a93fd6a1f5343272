#pragma once
// Helpers of the integration tests that run real robin-subdomain / robin-run processes.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../test_files.hpp"
#include "coupling/robin_iteration.hpp"
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

/// Expects every body's contact force and normal trace in `actual` within `tolerance` of
/// `reference` (vectors_close), after printing `label` and the largest differences (body 1's
/// force, body 2's trace); `reference` must be a real contact state (some force > 0).
inline void expect_same_interface_state(const RobinResult& actual, const RobinResult& reference,
                                        double tolerance, const std::string& label) {
  const std::vector<BodyInterfaceState>& a = actual.state.bodies;
  const std::vector<BodyInterfaceState>& b = reference.state.bodies;
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(b.size(), 2u);
  EXPECT_GT(b[0].contact_force.maxCoeff(), 0.0);  // the comparison is about a real contact state
  std::cout << label << ": largest differences: contact force "
            << (a[0].contact_force - b[0].contact_force).lpNorm<Eigen::Infinity>() << " (of "
            << b[0].contact_force.lpNorm<Eigen::Infinity>() << "), normal trace "
            << (a[1].normal_trace - b[1].normal_trace).lpNorm<Eigen::Infinity>() << " (of "
            << b[1].normal_trace.lpNorm<Eigen::Infinity>() << ")\n";
  for (std::size_t body = 0; body < b.size(); ++body) {
    EXPECT_TRUE(vectors_close(a[body].contact_force, b[body].contact_force, tolerance))
        << "body " << body + 1;
    EXPECT_TRUE(vectors_close(a[body].normal_trace, b[body].normal_trace, tolerance))
        << "body " << body + 1;
  }
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

// ---- Tools run in the background, their result directories ----------------------------

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// robin-run `case_file` --output `output` --quiet, its standard error in OUTPUT-logs/; with
/// `coordinator_does_it_all` also --server-executable (this build's robin-subdomain by path):
/// the servers then neither read the mesh files nor write the .vtu files, the coordinator does.
inline ProcessOutcome run_robin_run(const std::filesystem::path& case_file,
                                    const std::filesystem::path& output,
                                    bool coordinator_does_it_all) {
  std::vector<std::string> arguments = {case_file.string(), "--output", output.string(), "--quiet"};
  if (coordinator_does_it_all) {
    arguments.push_back("--server-executable");
    arguments.push_back(tool("robin-subdomain").string());
  }
  const std::filesystem::path logs = output.parent_path() / (output.filename().string() + "-logs");
  std::filesystem::create_directories(logs);
  return run_tool("robin-run", arguments, logs, 300.0);
}

/// NumberOfPoints of a .vtu file's piece (0 when it has none).
inline long vtu_point_count(const std::filesystem::path& vtu) {
  std::smatch match;
  const std::string text = read_text(vtu).substr(0, 4096);  // the XML header
  if (!std::regex_search(text, match, std::regex("NumberOfPoints=\"([0-9]+)\""))) return 0;
  return std::stol(match[1].str());
}

inline bool wait_until(const std::function<bool()>& condition, double seconds) {
  const auto start = std::chrono::steady_clock::now();
  while (!condition()) {
    if (testing::seconds_since(start) > seconds) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

/// examples/`name` copied into `directory` with absolute mesh paths and the mesh size
/// `mesh_size` for both bodies.
inline std::filesystem::path case_copy(const std::filesystem::path& directory, double mesh_size,
                                       const std::string& name = "asymmetric.toml") {
  std::string text = std::regex_replace(read_text(example(name)), std::regex("meshes/"),
                                        example("meshes").string() + "/");
  std::ostringstream size;
  size << "mesh_size = " << mesh_size;
  text = std::regex_replace(text, std::regex("mesh_size = 0\\.1"), size.str());
  const std::filesystem::path path = directory / name;
  std::ofstream(path) << text;
  return path;
}

/// A table of numbers read from a CSV file with a header row; `skipped` columns left out.
inline std::vector<std::vector<double>> csv_values(const std::filesystem::path& path,
                                                   const std::string& skipped = "") {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  std::vector<bool> keep;
  std::istringstream header(line);
  for (std::string name; std::getline(header, name, ',');) keep.push_back(name != skipped);
  std::vector<std::vector<double>> rows;
  while (std::getline(file, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    std::size_t column = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++column) {
      if (column < keep.size() && keep[column]) row.push_back(cell.empty() ? 0.0 : std::stod(cell));
    }
    rows.push_back(row);
  }
  return rows;
}

/// Every value of `actual` within `relative` (of the largest magnitude of its column) of
/// `expected`, with the same shape; prints the largest relative difference.
inline void expect_same_table(const std::vector<std::vector<double>>& actual,
                              const std::vector<std::vector<double>>& expected, double relative,
                              const std::string& what) {
  ASSERT_EQ(actual.size(), expected.size()) << what << ": rows";
  ASSERT_FALSE(expected.empty()) << what;
  std::vector<double> scale(expected[0].size(), 1e-300);
  for (const auto& row : expected) {
    for (std::size_t k = 0; k < row.size() && k < scale.size(); ++k) {
      scale[k] = std::max(scale[k], std::abs(row[k]));
    }
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(actual[i].size(), expected[i].size()) << what << ": row " << i;
    for (std::size_t k = 0; k < expected[i].size(); ++k) {
      worst = std::max(worst, std::abs(actual[i][k] - expected[i][k]) / scale[k]);
    }
  }
  std::cout << what << ": largest relative difference " << worst << "\n";
  EXPECT_LE(worst, relative) << what;
}

inline nlohmann::json read_summary(const std::filesystem::path& directory) {
  std::ifstream file(directory / "summary.json");
  return file.good() ? nlohmann::json::parse(file, nullptr, false) : nlohmann::json::object();
}

/// A tool started in the background, its standard error in `log`.
inline std::unique_ptr<ChildProcess> start_tool(const std::string& tool,
                                                const std::vector<std::string>& arguments,
                                                const std::filesystem::path& log) {
  ChildProcessOptions options;
  options.executable = testing::tool(tool);
  options.arguments = arguments;
  options.log_file = log;
  return std::make_unique<ChildProcess>(options);
}

/// Runs a tool to its end (at most 120 s); returns its exit description.
inline std::string run_to_end(const std::string& tool, const std::vector<std::string>& arguments,
                              const std::filesystem::path& log) {
  const auto process = start_tool(tool, arguments, log);
  while (process->read_line(ChildProcess::Clock::now() + std::chrono::seconds(120))) {
  }
  EXPECT_TRUE(process->wait_for_exit(120.0)) << tool << " did not finish";
  return process->exit_description();
}

}  // namespace robin::testing
