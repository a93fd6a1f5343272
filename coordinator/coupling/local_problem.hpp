#pragma once
// A case built entirely in this process: both bodies read, assembled, factorized, their
// contact boundaries paired and assigned. Used by robin-monolithic, by the in-process
// subdomain ports and by tests.

#include <array>
#include <filesystem>
#include <functional>
#include <memory>

#include "coupling/case_file.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/gap_function.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

struct LocalProblem {
  CaseDefinition definition;
  std::unique_ptr<GapFunction> gap;  // null when the case has no [gap]
  std::array<std::unique_ptr<BodySolver>, 2> bodies;
  ContactPairing pairing;
  double mesh_seconds = 0.0;        // reading and meshing both bodies
  double setup_seconds = 0.0;       // both bodies' assembly and factorization, one after the other
  double coupling_seconds = 0.0;    // pairing or mortar rows
  double assignment_seconds = 0.0;  // both bodies' contact assignment (interface operators)
};

/// The case's gap function, or null when it has none.
std::unique_ptr<GapFunction> make_gap_function(const CaseDefinition& definition);

/// Reads, assembles, factorizes and pairs. Throws InputError / SingularBodyError.
/// Told when a body's setup stage begins: (body name, stage, the body's DOFs).
using LocalSetupObserver =
    std::function<void(const std::string& body, SetupStage stage, long dof_count)>;

LocalProblem prepare_local_problem(const CaseDefinition& definition,
                                   const LocalSetupObserver& observer = {});

}  // namespace robin
