#pragma once
// The result directory of a coupled run: the body files, solution.pvd, contact.csv,
// history.csv and summary.json (README.md, "Results").

#include <filesystem>

#include "coupling/coupled_run.hpp"
#include "coupling/result_directory.hpp"

namespace robin {

/// Writes <body>.vtu x2, solution.pvd, contact.csv and history.csv into the directory's staging
/// area and commits them with summary.json (result_directory.hpp).
void write_coupled_outputs(ResultDirectory& results, const CaseDefinition& definition,
                           const CoupledRunResult& result);

}  // namespace robin
