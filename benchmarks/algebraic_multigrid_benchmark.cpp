// algebraic_multigrid_benchmark [CELLS_X ...] [--mesh FILE.msh BOUNDARY]
//     [--skip-cholmod-above DOFS] [--degree K] [--theta T] [--distance-theta T]
//     [--no-positions] [--gauss-seidel]
// Conjugate gradients preconditioned by smoothed-aggregation AMG (numerics/algebraic_multigrid.hpp)
// against CHOLMOD (numerics/cholesky.hpp) on the stiffness of a hexahedron8 box [0, 2] x [0, 1] x
// [0, 1] of 2n x n x n cells (one argument n per size; default 26, 34 and 43: 1.1e5, 2.5e5
// and 5.0e5 free dofs) clamped on its left face, under a smooth body force; with --mesh, also
// (first) the Gmsh mesh FILE.msh clamped on its boundary BOUNDARY under the same force. The AMG
// gets the node positions (the distance-Laplacian strength) unless --no-positions. Prints one
// markdown row per size and solver: setup seconds (AMG hierarchy; CHOLMOD ordering and
// factorization), iterations and seconds of PCG to relative residual 1e-10 (CHOLMOD: one solve),
// the relative difference of the two solutions, the AMG's levels and operator complexity or the
// factor's entries, and the peak resident memory (VmHWM) of the process during the solver's setup
// and solve: the peak is reset before each solver (after the problem's assembly, whose matrix and
// load are resident throughout and included). CHOLMOD is skipped above --skip-cholmod-above free
// dofs.

#include <malloc.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "numerics/algebraic_multigrid.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/cholesky.hpp"
#include "numerics/conjugate_gradient.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/material.hpp"
#include "numerics/msh_file.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Starts a new peak: the heap freed so far is given back to the system (malloc_trim) and the
/// peak resident set is reset to the current one (writing 5 to /proc/self/clear_refs).
void reset_peak_resident() {
  malloc_trim(0);
  std::ofstream("/proc/self/clear_refs") << "5";
}

/// The process's peak resident set (VmHWM of /proc/self/status), MiB.
double peak_resident_mib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  }
  return 0.0;
}

struct Problem {
  robin::SparseMatrix lower;
  Eigen::MatrixXd near_null_space;
  std::vector<int> dof_nodes;
  Eigen::VectorXd load;
  std::vector<Eigen::Vector3d> positions;
};

/// `mesh` clamped on `boundary` under a smooth body force.
Problem clamped_body(const robin::Mesh& mesh, const std::string& boundary) {
  std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
  for (int node : mesh.boundary(boundary).nodes()) {
    for (int component = 0; component < 3; ++component) prescribed[3 * node + component] = 0.0;
  }
  const robin::DofMap dofs(prescribed);
  const robin::Material material = robin::make_isotropic_solid_material(210.0, 0.3, "benchmark");
  Problem problem;
  problem.lower = dofs.reduce_matrix_lower(robin::assemble_stiffness(mesh, material));
  problem.near_null_space = robin::free_rigid_body_modes(mesh, dofs);
  problem.dof_nodes = robin::free_dof_nodes(mesh, dofs);
  problem.positions = mesh.nodes;
  problem.load = dofs.restrict(robin::assemble_body_force(mesh, [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(0.1 * x.y(), -1.0, 0.2 * x.z());
  }));
  return problem;
}

Problem clamped_box(int cells) {
  return clamped_body(
      robin::make_box_mesh(Eigen::Vector3d::Zero(), {2.0, 1.0, 1.0}, {2 * cells, cells, cells},
                           robin::ElementType::hexahedron8),
      "left");
}

Eigen::VectorXd run_multigrid(const Problem& problem,
                              const robin::AlgebraicMultigridOptions& options) {
  const robin::AlgebraicMultigrid multigrid(problem.lower, problem.near_null_space,
                                            problem.dof_nodes, problem.positions, options);
  const auto start = Clock::now();
  Eigen::VectorXd solution;
  robin::ConjugateGradientOptions parameters;
  parameters.relative_tolerance = 1e-10;
  parameters.maximum_iterations = 1000;
  const robin::ConjugateGradientResult result = robin::solve_conjugate_gradient(
      multigrid.fine_operator(), multigrid, problem.load, solution, parameters);
  const double solve_seconds = seconds_since(start);
  std::string sizes;
  for (const robin::MultigridLevelSummary& level : multigrid.levels()) {
    if (!sizes.empty()) sizes += '/';
    sizes += std::to_string(level.unknowns);
  }
  std::printf("| %ld | PCG + AMG | %.2f | %d | %.2f | %.1e | levels %s, complexity %.2f | %.0f |\n",
              static_cast<long>(problem.lower.rows()), multigrid.setup_seconds(), result.iterations,
              solve_seconds, result.relative_residual, sizes.c_str(),
              multigrid.operator_complexity(), peak_resident_mib());
  std::fflush(stdout);
  return solution;
}

void run_cholmod(const Problem& problem, const Eigen::VectorXd& iterative) {
  const robin::CholeskyFactor factor(problem.lower, "box");
  const auto start = Clock::now();
  const Eigen::VectorXd direct = factor.solve(problem.load);
  const double solve_seconds = seconds_since(start);
  std::printf(
      "| %ld | CHOLMOD | %.2f + %.2f | - | %.2f | PCG differs by %.1e | factor entries %.3e | "
      "%.0f |\n",
      static_cast<long>(problem.lower.rows()), factor.ordering_seconds(),
      factor.factorization_seconds(), solve_seconds, (iterative - direct).norm() / direct.norm(),
      static_cast<double>(factor.factor_nonzeros()), peak_resident_mib());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> cells;
  long skip_cholmod_above = 400000;
  bool use_positions = true;
  std::string mesh_path, clamped_boundary;
  robin::AlgebraicMultigridOptions options;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--skip-cholmod-above") == 0 && k + 1 < argc) {
      skip_cholmod_above = std::atol(argv[++k]);
    } else if (std::strcmp(argv[k], "--degree") == 0 && k + 1 < argc) {
      options.smoother_degree = std::atoi(argv[++k]);
    } else if (std::strcmp(argv[k], "--gauss-seidel") == 0) {
      options.smoother = robin::MultigridSmoother::symmetric_gauss_seidel;
    } else if (std::strcmp(argv[k], "--theta") == 0 && k + 1 < argc) {
      options.strength_threshold = std::atof(argv[++k]);
    } else if (std::strcmp(argv[k], "--distance-theta") == 0 && k + 1 < argc) {
      options.distance_strength_threshold = std::atof(argv[++k]);
    } else if (std::strcmp(argv[k], "--no-positions") == 0) {
      use_positions = false;
    } else if (std::strcmp(argv[k], "--mesh") == 0 && k + 2 < argc) {
      mesh_path = argv[++k];
      clamped_boundary = argv[++k];
    } else if (std::atoi(argv[k]) > 0) {
      cells.push_back(std::atoi(argv[k]));
    } else {
      std::fprintf(stderr,
                   "usage: algebraic_multigrid_benchmark [CELLS_X ...] [--mesh FILE.msh "
                   "BOUNDARY] [--skip-cholmod-above DOFS] [--degree K] [--theta T] "
                   "[--distance-theta T] [--no-positions] [--gauss-seidel]\n");
      return 1;
    }
  }
  if (cells.empty() && mesh_path.empty()) cells = {26, 34, 43};
  std::printf(
      "| free dofs | solver | setup (s) | iterations | solve (s) | relative residual | "
      "hierarchy / factor | peak RSS (MiB) |\n|---|---|---|---|---|---|---|---|\n");
  std::vector<Problem> problems;
  if (!mesh_path.empty()) {
    problems.push_back(clamped_body(robin::read_msh_file(mesh_path), clamped_boundary));
  }
  for (int n : cells) problems.push_back(clamped_box(n));
  for (Problem& problem : problems) {
    if (!use_positions) problem.positions.clear();
    reset_peak_resident();
    const Eigen::VectorXd solution = run_multigrid(problem, options);
    reset_peak_resident();
    if (problem.lower.rows() <= skip_cholmod_above) run_cholmod(problem, solution);
  }
  return 0;
}
