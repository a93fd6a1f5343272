#pragma once
// Where a server may read and write on behalf of a client. The wire is untrusted: a client
// names files only relative to directories the server's operator chose at start, and nothing
// it names may lead out of them, by "..", an absolute path or a symbolic link.
//   - reading: SetupBody.mesh_path, under --data-directory, at most --max-mesh-file-size bytes;
//   - writing: FieldsRequest.write_directory, under --output-root; the file is written to a
//     fresh temporary name and renamed into place, so an existing symbolic link at the target
//     is replaced, never followed.

#include <cstdint>
#include <filesystem>
#include <string>

namespace robin {

/// The real path of `requested` (relative) under `data_directory`, which must be a regular
/// file inside the real path of `data_directory`. Throws InputError "<field> ..." when no data
/// directory was given (empty), or the path is empty, absolute, leaves the directory (also
/// through a symbolic link) or is not a regular file.
std::filesystem::path resolve_data_file(const std::filesystem::path& data_directory,
                                        const std::string& requested, const std::string& field);

/// Refuses the data file `path` (resolved from `requested`) when it is larger than
/// `maximum_bytes` (0: no limit), before anything is read: its size comes from stat, so a huge
/// or sparse file costs nothing. Throws InputError "<field> '<requested>' is N bytes, above ..."
/// naming the limit and the option that raises it (robin-subdomain --max-mesh-file-size).
void check_data_file_size(const std::filesystem::path& path, const std::string& requested,
                          std::uintmax_t maximum_bytes, const std::string& field);

/// The directory `requested` (relative) under `output_root`, created component by component
/// where missing; no component may be a symbolic link, "..", or leave the root. Throws
/// InputError "<field> ..." otherwise, and when no output root was given (empty).
std::filesystem::path resolve_output_directory(const std::filesystem::path& output_root,
                                               const std::string& requested,
                                               const std::string& field);

}  // namespace robin
