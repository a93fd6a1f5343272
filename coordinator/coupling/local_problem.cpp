#include "coupling/local_problem.hpp"

#include <chrono>

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
  for (int alpha = 0; alpha < 2; ++alpha) {
    BodySolverOptions options = definition.solver.body;
    if (observer) {
      const BodyDefinition& body = loaded.bodies[alpha].definition;
      const long dof_count = 2L * static_cast<long>(body.mesh.node_count());
      options.observer = [observer, name = body.name, dof_count](SetupStage stage) {
        observer(name, stage, dof_count);
      };
    }
    problem.bodies[alpha] =
        std::make_unique<BodySolver>(std::move(loaded.bodies[alpha].definition), options);
  }
  problem.setup_seconds = seconds_since(setup_start);
  const auto coupling_start = std::chrono::steady_clock::now();
  const BodySolver& body1 = *problem.bodies[0];
  const BodySolver& body2 = *problem.bodies[1];
  problem.pairing = discretize_contact(body1.contact_boundary(), body1.name(),
                                       body2.contact_boundary(), body2.name(), problem.gap.get(),
                                       definition.contact, definition.solver.pairing_tolerance);
  problem.coupling_seconds = seconds_since(coupling_start);
  const auto assignment_start = std::chrono::steady_clock::now();
  for (int alpha = 0; alpha < 2; ++alpha) {
    problem.bodies[alpha]->assign_contact(problem.pairing.assignment(alpha));
  }
  problem.assignment_seconds = seconds_since(assignment_start);
  return problem;
}

}  // namespace robin
