#pragma once
// Reading one [[body]] table of a case file (internal to case_file.cpp).

#include <filesystem>

#include "coupling/case_file.hpp"
#include "coupling/case_file_table.hpp"

namespace robin {

/// Whether a [[body]] table names its contact boundary: required in a case of two bodies
/// without [[interface]] tables, refused in a case with them (the interfaces name boundaries).
enum class ContactBoundaryKey { required, refused };

/// Reads and checks the [[body]] table `entry` (keys, types, ranges, material, mesh file
/// existence and options). Relative mesh paths are resolved against `directory`.
/// `file` carries the case file label (its body part is ignored). `dimension` is the case's:
/// 2 (plane bodies: a plane model, 2-vectors, 3 x 3 Voigt) or 3 (solid bodies: no model,
/// 3-vectors, 6 x 6 Voigt, u_z). Throws InputError.
BodyCase read_body_case(const TableEntry& entry, const CaseContext& file,
                        const std::filesystem::path& directory, ContactBoundaryKey contact_key,
                        int dimension);

/// Formats a number for messages (up to 12 significant digits).
std::string format_number(double value);

}  // namespace robin
