// Outer iterations of the Robin iteration against the number of bodies: a row of N unit blocks
// along x (N = 2, 4, 8, 16), each clamped at its bottom, the first pushed by a unit pressure on
// its left face, the last held at its right face (u_x = 0), every inner block touching its two
// neighbours, so that the load crosses every interface (N - 1
// interfaces, node-to-node, structured quadrilateral meshes of 1/h x 1/h cells meshed by Gmsh).
// Per N and acceleration: the iteration count, the iteration's wall time, and the largest
// relative difference of the contact forces from the monolithic solution of the same graph.
// Bodies run in process, one after the other (no servers): the counts are what the scheme does,
// the times are not a parallel run. docs/benchmarks.md ("Many bodies").
// Usage: build/benchmarks/many_bodies_benchmark [h]   (default h = 1/16)

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "coupling/graph_coupling.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/robin_iteration.hpp"
#include "numerics/gmsh_reader.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A structured unit block [x0, x0 + 1] x [0, 1] as a .geo file in `directory`.
std::filesystem::path write_block(const std::filesystem::path& directory, int index) {
  const std::filesystem::path path = directory / ("block_" + std::to_string(index) + ".geo");
  std::ofstream file(path);
  file << "DefineConstant[ h = 0.0625 ];\nn = Round(1 / h) + 1;\nx0 = " << index << ";\n"
       << "Point(1) = {x0, 0, 0, h};\nPoint(2) = {x0 + 1, 0, 0, h};\n"
       << "Point(3) = {x0 + 1, 1, 0, h};\nPoint(4) = {x0, 1, 0, h};\n"
       << "Line(1) = {1, 2};\nLine(2) = {2, 3};\nLine(3) = {3, 4};\nLine(4) = {4, 1};\n"
       << "Transfinite Curve{1, 2, 3, 4} = n;\nCurve Loop(1) = {1, 2, 3, 4};\n"
       << "Plane Surface(1) = {1};\nTransfinite Surface{1};\nRecombine Surface{1};\n"
       << "Physical Curve(\"bottom\") = {1};\nPhysical Curve(\"right\") = {2};\n"
       << "Physical Curve(\"top\") = {3};\nPhysical Curve(\"left\") = {4};\n"
       << "Physical Surface(\"block\") = {1};\n";
  return path;
}

robin::BodyDefinition block(const std::filesystem::path& mesh, int index, int count, double h) {
  robin::BodyDefinition body;
  body.name = "block" + std::to_string(index + 1);
  body.mesh = robin::read_gmsh_mesh(mesh, {h, 1, false});
  body.material =
      robin::make_isotropic_material(1000.0, 0.3, robin::PlaneModel::plane_strain, body.name);
  body.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  if (index == 0) body.tractions.push_back({"left", true, Eigen::Vector3d::Zero(), 1.0});
  if (index == count - 1) body.dirichlet.push_back({"right", 0.0, std::nullopt, std::nullopt});
  if (index > 0) body.contact_boundaries.push_back("left");
  if (index < count - 1) body.contact_boundaries.push_back("right");
  return body;
}

void run_row(int count, double h, const std::filesystem::path& directory) {
  std::vector<robin::BodyDefinition> definitions;
  std::vector<robin::InterfaceDescription> interfaces;
  std::vector<std::string> names;
  for (int index = 0; index < count; ++index) {
    definitions.push_back(block(write_block(directory, index), index, count, h));
    interfaces.push_back(robin::BodySolver(definitions.back()).contact_boundary());
    names.push_back(definitions.back().name);
  }
  std::vector<robin::InterfaceDefinition> edges;
  for (int index = 0; index + 1 < count; ++index)
    edges.push_back({index, index + 1, "right", "left"});
  robin::ContactOptions contact;
  contact.method = robin::ContactMethod::node_to_node;
  const robin::GraphCoupling coupling =
      robin::couple_contact_graph(interfaces, names, edges, nullptr, contact, 1e-6);

  std::vector<std::unique_ptr<robin::BodySolver>> solvers;
  std::vector<const robin::BodySolver*> bodies;
  for (int index = 0; index < count; ++index) {
    solvers.push_back(std::make_unique<robin::BodySolver>(definitions[index]));
    solvers.back()->assign_contact(coupling.operators[static_cast<std::size_t>(index)]);
    bodies.push_back(solvers.back().get());
  }
  robin::MprgpParameters qp;
  qp.relative_tolerance = 1e-12;
  const auto monolithic_start = Clock::now();
  const robin::MonolithicResult monolithic =
      robin::solve_monolithic(bodies, coupling.problem.graph, coupling.problem.gaps, qp);
  const double monolithic_seconds = seconds_since(monolithic_start);

  for (const robin::AccelerationMethod acceleration :
       {robin::AccelerationMethod::iqn_ils, robin::AccelerationMethod::aitken,
        robin::AccelerationMethod::none}) {
    std::vector<robin::InProcessPort> ports(static_cast<std::size_t>(count));
    std::vector<robin::SubdomainPort*> pointers;
    robin::SolverOptions solver;
    solver.qp = qp;
    for (int index = 0; index < count; ++index) {
      robin::BodyCase body_case;
      body_case.definition = definitions[static_cast<std::size_t>(index)];
      ports[static_cast<std::size_t>(index)].setup(body_case, solver);
      ports[static_cast<std::size_t>(index)].assign_contact(
          coupling.operators[static_cast<std::size_t>(index)]);
      pointers.push_back(&ports[static_cast<std::size_t>(index)]);
    }
    robin::CouplingOptions options;
    options.acceleration.method = acceleration;
    options.tolerance = 1e-8;
    options.max_iterations = 2000;
    const robin::RobinResult result =
        robin::run_robin_iteration(pointers, coupling.problem, options, nullptr, {});
    double difference = 0.0;
    for (int index = 0; index < count; ++index) {
      const Eigen::VectorXd reference =
          coupling.problem.graph.body_part(index, monolithic.contact_force);
      difference =
          std::max(difference,
                   (result.state.bodies[static_cast<std::size_t>(index)].contact_force - reference)
                           .lpNorm<Eigen::Infinity>() /
                       monolithic.contact_force.lpNorm<Eigen::Infinity>());
    }
    std::printf("| %d | %d | %ld | %s | %s | %zu | %.3f | %.3f | %.1e |\n", count, count - 1,
                static_cast<long>(coupling.problem.graph.total_rows()),
                robin::to_string(acceleration).c_str(), robin::to_string(result.status).c_str(),
                result.history.size(), result.wall_seconds, monolithic_seconds, difference);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const double h = argc > 1 ? std::atof(argv[1]) : 1.0 / 16.0;
  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() / ("robin-many-bodies-" + std::to_string(getpid()));
  std::filesystem::create_directories(directory);
  std::printf("row of N unit blocks, h = %g (tolerance 1e-8, QP tolerance 1e-12)\n\n", h);
  std::printf(
      "| N bodies | interfaces | rows | acceleration | status | iterations | iteration s | "
      "monolithic s | max force difference |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const int count : {2, 4, 8, 16}) run_row(count, h, directory);
  std::filesystem::remove_all(directory);
  return 0;
}
