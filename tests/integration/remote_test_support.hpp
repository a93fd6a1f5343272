#pragma once
// Helpers of the integration tests that run real robin-subdomain / robin-run processes.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>

#include "remote/server_launcher.hpp"

namespace robin::testing {

inline std::filesystem::path example(const std::string& name) {
  return std::filesystem::path(ROBIN_EXAMPLES) / name;
}

inline std::filesystem::path tool(const std::string& name) {
  return std::filesystem::path(ROBIN_BINARY_DIR) / "bin" / name;
}

/// A fresh empty directory under the system's temporary directory, removed at destruction.
class TemporaryDirectory {
 public:
  explicit TemporaryDirectory(const std::string& label) {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("robin-" + label + "-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

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

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace robin::testing
