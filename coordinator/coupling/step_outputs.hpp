#pragma once
// The result files of a case with quasi-static load steps ([loading], docs/case-format.md),
// written next to the files of the last step (README.md, "Results"):
//
//   solution.pvd              the time series: one DataSet per step and body (part 0 body 1,
//                             part 1 body 2), timestep = the load factor when the factors
//                             increase strictly, otherwise the step number (LoadingOptions::
//                             timestep); it replaces the single-state collection
//   steps/step_NNN/<body>.vtu the fields of both bodies at step NNN (1-based, zero-padded to at
//                             least three digits)
//   steps/step_NNN/contact.csv the interface state of step NNN (the columns of contact.csv)
//   steps.csv                 one row per step: step, load_factor, status, iterations, ...
//   history.csv               (coupled runs) every iteration of every step, with the columns
//                             step and load_factor before those of a single run's history.csv
//
// <body>.vtu, contact.csv and summary.json at the top describe the last step computed, as for a
// case without [loading]; summary.json gains "load_steps" (one object per step).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "coupling/coupled_run.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"

namespace robin {

/// "steps/step_007": the directory of step `step` (1-based) among `count` steps, relative to
/// the result directory.
std::filesystem::path step_directory(int step, std::size_t count);

/// Writes the files above for a coupled run with steps (result.steps not empty) into
/// `directory`. Throws std::runtime_error naming the path when a file cannot be written.
void write_coupled_step_outputs(const std::filesystem::path& directory,
                                const CaseDefinition& definition, const CoupledRunResult& result);

/// The "load_steps" array of summary.json: per step its number, load factor, status, iterations,
/// whether it started from the previous step, its final residual, active pairs, largest
/// pressure, contact force resultant and wall time.
nlohmann::json coupled_steps_json(const CoupledRunResult& result);

/// Writes the files above (without history.csv) for robin-monolithic's steps. Each step's body
/// files are written at that step's load factor; the bodies are left at the last step's.
void write_monolithic_step_outputs(const std::filesystem::path& directory,
                                   const LocalProblem& problem,
                                   const std::vector<MonolithicStep>& steps);

/// The "load_steps" array of robin-monolithic's summary.json.
nlohmann::json monolithic_steps_json(const LocalProblem& problem,
                                     const std::vector<MonolithicStep>& steps);

}  // namespace robin
