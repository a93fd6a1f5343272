#pragma once
// Reading the [[interface]] tables of a case file (internal to case_file.cpp): the contact
// interfaces of a case with N >= 2 bodies (docs/case-format.md, "[[interface]]").

#include <vector>

#include "coupling/case_file.hpp"
#include "coupling/case_file_table.hpp"

namespace robin {

/// Fills definition.interfaces from the [[interface]] tables of `root`, or, when there are none,
/// the one interface of two bodies from their contact_boundary keys; sets every body's
/// contact_boundaries (the boundaries its interfaces name, in interface order, each once) and
/// records each name for the check against the mesh. `bodies` are the [[body]] entries of
/// `root` (for the lines of messages). Reads definition.contact (the [contact] table) for the
/// interfaces' default coupling. Throws InputError naming the file, line and field: an unknown
/// body, a body joined to itself, an interface given twice, a body in no interface.
void read_interfaces(const CheckedTable& root, const std::vector<TableEntry>& bodies,
                     CaseDefinition& definition);

}  // namespace robin
