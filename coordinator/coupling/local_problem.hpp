#pragma once
// A case built entirely in this process: every body read, assembled, factorized, the contact
// interfaces discretized (node-to-node pairing or mortar rows) and each body assigned its rows
// in body order (contact_graph.hpp). Used by robin-monolithic, by the in-process subdomain
// ports and by tests.

#include <filesystem>
#include <functional>
#include <memory>

#include "coupling/case_file.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/gap_function.hpp"
#include "coupling/graph_coupling.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

struct LocalProblem {
  CaseDefinition definition;
  std::unique_ptr<GapFunction> gap;                 // null when the case has no [gap]
  std::vector<std::unique_ptr<BodySolver>> bodies;  // body order
  /// Per interface its rows (pairings), per body its operator, and the graph's problem.
  GraphCoupling coupling;
  double mesh_seconds = 0.0;        // reading and meshing every body
  double setup_seconds = 0.0;       // every body's assembly and factorization, one after another
  double coupling_seconds = 0.0;    // pairing or mortar rows
  double assignment_seconds = 0.0;  // every body's contact assignment (interface operators)

  /// The rows of the only interface of a two-body case. Throws std::logic_error when the case
  /// has several interfaces.
  const ContactPairing& pairing() const;
  /// The bodies as the graph's solvers take them (body order).
  std::vector<const BodySolver*> body_solvers() const;
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
