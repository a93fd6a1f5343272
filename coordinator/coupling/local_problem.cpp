#include "coupling/local_problem.hpp"

#include <chrono>
#include <stdexcept>

namespace robin {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::unique_ptr<GapFunction> make_gap_function(const CaseDefinition& definition) {
  if (!definition.gap_expression) return nullptr;
  return std::make_unique<GapFunction>(*definition.gap_expression, definition.gap_constants,
                                       definition.file.string() + ": gap.expression");
}

LocalProblem prepare_local_problem(const CaseDefinition& definition,
                                   const LocalSetupObserver& observer) {
  LocalProblem problem;
  problem.definition = definition;
  problem.gap = make_gap_function(definition);
  const auto start = std::chrono::steady_clock::now();
  CaseDefinition loaded = definition;
  load_meshes(loaded);
  problem.mesh_seconds = seconds_since(start);
  const auto setup_start = std::chrono::steady_clock::now();
  for (BodyCase& body_case : loaded.bodies) {
    BodySolverOptions options = body_solver_options(definition.solver, body_case);
    if (observer) {
      const BodyDefinition& body = body_case.definition;
      const long dof_count = static_cast<long>(body.mesh.dof_count());
      options.observer = [observer, name = body.name, dof_count](SetupStage stage) {
        observer(name, stage, dof_count);
      };
    }
    problem.bodies.push_back(
        std::make_unique<BodySolver>(std::move(body_case.definition), options));
  }
  problem.setup_seconds = seconds_since(setup_start);
  const auto coupling_start = std::chrono::steady_clock::now();
  std::vector<InterfaceDescription> descriptions;
  for (const auto& body : problem.bodies) descriptions.push_back(body->contact_boundary());
  problem.coupling = couple_contact_graph(descriptions, body_names(definition),
                                          interface_definitions(definition), problem.gap.get(),
                                          definition.contact, definition.solver.pairing_tolerance);
  problem.coupling_seconds = seconds_since(coupling_start);
  const auto assignment_start = std::chrono::steady_clock::now();
  for (std::size_t alpha = 0; alpha < problem.bodies.size(); ++alpha) {
    problem.bodies[alpha]->assign_contact(problem.coupling.operators[alpha]);
  }
  problem.assignment_seconds = seconds_since(assignment_start);
  return problem;
}

const ContactPairing& LocalProblem::pairing() const {
  if (coupling.pairings.size() != 1) {
    throw std::logic_error("LocalProblem::pairing: the case has " +
                           std::to_string(coupling.pairings.size()) + " contact interfaces");
  }
  return coupling.pairings.front();
}

std::vector<const BodySolver*> LocalProblem::body_solvers() const {
  std::vector<const BodySolver*> solvers;
  for (const auto& body : bodies) solvers.push_back(body.get());
  return solvers;
}

}  // namespace robin
