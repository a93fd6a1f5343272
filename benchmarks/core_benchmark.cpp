// core_benchmark CASE MESH_SIZE
// Measures the numerical core on one case with both bodies meshed at MESH_SIZE (the .geo
// variable h) and prints one line of key=value pairs: DOFs, assembly, factorization, one
// solve, the interface operator, the local contact solve of body 2 (the pushed one) against
// the obstacle g = d (dense and matrix-free compliance), the monolithic solve, and the peak memory.
// Run through benchmarks/core_benchmark.sh, which prints the table for several sizes.

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double peak_memory_megabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

void report_contact_solve(const char* label, robin::BodySolver& body, const Eigen::VectorXd& gaps,
                          const robin::MprgpParameters& parameters) {
  body.reset_warm_start();
  const long solves_before = body.solve_count();
  const auto start = Clock::now();
  const robin::ContactSolveResult result = body.solve_contact(gaps, parameters);
  std::printf(
      " %s_contact_seconds=%.4f %s_contact_iterations=%d %s_contact_products=%d "
      "%s_contact_factor_solves=%ld %s_contact_status=%s",
      label, seconds_since(start), label, result.iterations, label, result.operator_applications,
      label, body.solve_count() - solves_before, label, robin::to_string(result.status).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: core_benchmark CASE MESH_SIZE\n");
    return 1;
  }
  robin::CaseDefinition definition = robin::read_case_file(argv[1]);
  const double size = std::atof(argv[2]);
  for (auto& body : definition.bodies) body.mesh_options.size = size;

  const auto total_start = Clock::now();
  robin::LocalProblem problem = robin::prepare_local_problem(definition);
  robin::BodySolver& body = *problem.bodies[1];  // the pushed body: its local problem has contact
  const int dofs = problem.bodies[0]->free_dof_count() + problem.bodies[1]->free_dof_count();
  std::printf("h=%g dofs=%d contact_pairs=%zu mesh_seconds=%.3f", size, dofs,
              problem.pairing().size(), problem.mesh_seconds);
  double assembly = 0, factorization = 0, interface = 0;
  long factor_nonzeros = 0;
  for (const auto& each : problem.bodies) {
    assembly += each->timings().assembly_seconds;
    factorization += each->timings().ordering_seconds + each->timings().factorization_seconds;
    interface += each->timings().interface_seconds;
    factor_nonzeros += each->factor_nonzeros();
  }
  std::printf(
      " assembly_seconds=%.3f factorization_seconds=%.3f factor_nonzeros=%ld"
      " dense_interface_seconds=%.3f",
      assembly, factorization, factor_nonzeros, interface);

  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(body.contact_size());
  auto start = Clock::now();
  const Eigen::VectorXd field = body.displacement(ones);  // one solve with the factor
  std::printf(" one_solve_seconds=%.4f", seconds_since(start));

  const Eigen::VectorXd gaps = problem.pairing().gaps();
  report_contact_solve("dense", body, gaps, definition.solver.qp);
  robin::BodySolverOptions factor_options;
  factor_options.interface_operator = robin::InterfaceOperatorKind::factor;
  robin::BodySolver matrix_free(body.definition(), factor_options);
  matrix_free.assign_contact(problem.pairing().assignment(1));
  report_contact_solve("factor", matrix_free, gaps, definition.solver.qp);

  start = Clock::now();
  const robin::MonolithicResult monolithic = robin::solve_monolithic(
      *problem.bodies[0], *problem.bodies[1], problem.pairing(), definition.solver.qp);
  std::printf(" monolithic_seconds=%.4f monolithic_iterations=%d monolithic_status=%s",
              seconds_since(start), monolithic.qp.iterations,
              robin::to_string(monolithic.qp.status).c_str());
  std::printf(" total_seconds=%.3f peak_memory_mb=%.0f\n", seconds_since(total_start),
              peak_memory_megabytes());
  return field.size() > 0 ? 0 : 1;
}
