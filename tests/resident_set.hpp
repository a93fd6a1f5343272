#pragma once
// The resident set of the running test process, as the kernel counts it, for the tests of
// heap_memory.hpp.

#include <cstdlib>
#include <fstream>
#include <string>

namespace robin {

/// The resident set of this process, MiB (the "VmRSS:" line of /proc/self/status); -1 when it
/// cannot be read.
inline double resident_mib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  }
  return -1.0;
}

}  // namespace robin
