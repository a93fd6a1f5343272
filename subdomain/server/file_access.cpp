#include "server/file_access.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <system_error>

#include "numerics/errors.hpp"

namespace robin {
namespace {

constexpr std::size_t maximum_path_length = 1024;

/// Refuses an empty, absolute or too long path, or one with a ".." component.
std::filesystem::path checked_relative(const std::string& requested, const std::string& field) {
  if (requested.empty()) throw InputError(field + " is empty");
  if (requested.size() > maximum_path_length || requested.find('\0') != std::string::npos) {
    throw InputError(field + " is not a usable path (at most 1024 characters, no NUL)");
  }
  const std::filesystem::path path(requested);
  if (path.is_absolute()) {
    throw InputError(field + " '" + requested + "' is absolute: give a path relative to the " +
                     "server's directory");
  }
  for (const std::filesystem::path& component : path) {
    if (component == "..") {
      throw InputError(field + " '" + requested + "' contains '..': it may not leave the " +
                       "server's directory");
    }
  }
  return path;
}

bool is_inside(const std::filesystem::path& path, const std::filesystem::path& root) {
  auto path_component = path.begin();
  for (auto root_component = root.begin(); root_component != root.end(); ++root_component) {
    if (path_component == path.end() || *path_component != *root_component) return false;
    ++path_component;
  }
  return true;
}

std::filesystem::path real_root(const std::filesystem::path& root, const std::string& field,
                                const std::string& option) {
  if (root.empty()) {
    throw InputError(field + " is refused: this server was started without " + option +
                     " (its operator names the directory a client may use)");
  }
  std::error_code error;
  const std::filesystem::path real = std::filesystem::canonical(root, error);
  if (error) {
    throw InputError(field + " is refused: the server's " + option + " '" + root.string() +
                     "' is not usable (" + error.message() + ")");
  }
  return real;
}

}  // namespace

std::filesystem::path resolve_data_file(const std::filesystem::path& data_directory,
                                        const std::string& requested, const std::string& field) {
  const std::filesystem::path root = real_root(data_directory, field, "--data-directory");
  const std::filesystem::path relative = checked_relative(requested, field);
  std::error_code error;
  const std::filesystem::path real = std::filesystem::canonical(root / relative, error);
  if (error) {
    throw InputError(field + " '" + requested + "' does not exist under the data directory");
  }
  if (!is_inside(real, root)) {
    throw InputError(field + " '" + requested + "' leads out of the data directory (through a " +
                     "symbolic link): refused");
  }
  if (!std::filesystem::is_regular_file(real, error)) {
    throw InputError(field + " '" + requested + "' is not a regular file");
  }
  return real;
}

void check_data_file_size(const std::filesystem::path& path, const std::string& requested,
                          std::uintmax_t maximum_bytes, const std::string& field) {
  if (maximum_bytes == 0) return;
  struct stat status {};
  if (stat(path.c_str(), &status) != 0) {
    throw InputError(field + " '" + requested + "' cannot be examined (" +
                     std::generic_category().message(errno) + ")");
  }
  const auto size = static_cast<std::uintmax_t>(status.st_size);
  if (size <= maximum_bytes) return;
  throw InputError(field + " '" + requested + "' is " + std::to_string(size) +
                   " bytes, above this server's limit of " + std::to_string(maximum_bytes) +
                   " bytes for a mesh file (its operator raises it with robin-subdomain "
                   "--max-mesh-file-size BYTES): not read");
}

std::filesystem::path resolve_output_directory(const std::filesystem::path& output_root,
                                               const std::string& requested,
                                               const std::string& field) {
  std::filesystem::path directory = real_root(output_root, field, "--output-root");
  const std::filesystem::path relative = checked_relative(requested, field);
  for (const std::filesystem::path& component : relative) {
    if (component.empty() || component == ".") continue;
    directory /= component;
    struct stat status {};
    if (lstat(directory.c_str(), &status) == 0) {
      if (S_ISLNK(status.st_mode)) {
        throw InputError(field + " '" + requested + "': '" + component.string() +
                         "' is a symbolic link, which the server does not follow");
      }
      if (!S_ISDIR(status.st_mode)) {
        throw InputError(field + " '" + requested + "': '" + component.string() +
                         "' exists and is not a directory");
      }
      continue;
    }
    if (mkdir(directory.c_str(), 0755) != 0 && errno != EEXIST) {
      throw InputError(field + " '" + requested + "': cannot create '" + component.string() +
                       "' (" + std::generic_category().message(errno) + ")");
    }
  }
  return directory;
}

}  // namespace robin
