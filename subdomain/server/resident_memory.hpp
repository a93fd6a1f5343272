#pragma once
// The process's peak resident set size, for the replies of the long requests (protocol 2.5,
// peak_resident_bytes of InterfaceDescription, Acknowledge and FieldsReply).

#include <cstdint>
#include <filesystem>

namespace robin {

/// The peak resident set size of the process whose status file is `status_file` (Linux:
/// the "VmHWM:" line of /proc/<pid>/status, in kB of 1024 bytes), in bytes; 0 when the file or
/// the line cannot be read (another system).
std::uint64_t peak_resident_bytes(const std::filesystem::path& status_file = "/proc/self/status");

}  // namespace robin
