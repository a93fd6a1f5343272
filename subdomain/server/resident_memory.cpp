#include "server/resident_memory.hpp"

#include <fstream>
#include <sstream>
#include <string>

namespace robin {

std::uint64_t peak_resident_bytes(const std::filesystem::path& status_file) {
  std::ifstream status(status_file);
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) != 0) continue;
    std::istringstream fields(line.substr(6));
    std::uint64_t kibibytes = 0;
    std::string unit;
    if (!(fields >> kibibytes >> unit) || unit != "kB") return 0;
    return kibibytes * 1024;
  }
  return 0;
}

}  // namespace robin
