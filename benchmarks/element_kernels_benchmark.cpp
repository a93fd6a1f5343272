// User CPU time (getrusage) of the element kernels on one .msh mesh: check_element_validity,
// assemble_stiffness and recover_stress (E = 1000, nu = 0.3; plane strain for a 2D mesh), each
// the median of 11 calls, and a checksum of their results (equal between builds when the
// kernels agree). Built with the benchmarks (docs/benchmarks.md, "Heap-free element kernels"):
//   build/benchmarks/element_kernels_benchmark mesh.msh
#include <sys/resource.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>
#include "numerics/elasticity.hpp"
#include "numerics/material.hpp"
#include "numerics/mesh_validity.hpp"
#include "numerics/msh_file.hpp"
using namespace robin;
double user_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + 1e-6 * usage.ru_utime.tv_usec;
}
template <class F>
double median_of(int repeats, F f) {
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const double start = user_seconds();
    f();
    times.push_back(user_seconds() - start);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}
int main(int argument_count, char** arguments) {
  if (argument_count != 2) {
    std::fprintf(stderr, "usage: %s mesh.msh\n", arguments[0]);
    return 2;
  }
  const Mesh mesh = read_msh_file(arguments[1], "m");
  const int repeats = 11;
  const bool solid = mesh.dimension == 3;
  const Material material =
      solid ? make_isotropic_solid_material(1000.0, 0.3, "m")
            : make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "m");
  double checksum = 0.0;
  const double validity = median_of(repeats, [&] { check_element_validity(mesh, "m"); });
  SparseMatrix stiffness;
  const double assembly =
      median_of(repeats, [&] { stiffness = assemble_stiffness(mesh, material); });
  checksum += stiffness.sum();
  Eigen::VectorXd displacement(mesh.dof_count());
  for (Eigen::Index i = 0; i < displacement.size(); ++i)
    displacement(i) = 1e-3 * std::sin(0.37 * i);
  StressField field;
  const double stress =
      median_of(repeats, [&] { field = recover_stress(mesh, material, displacement); });
  checksum += field.nodal_stress.sum() + field.element_von_mises.sum();
  std::printf(
      "%zu nodes %zu elements dofs %zu: validity %.4f assembly %.4f recover_stress %.4f (checksum "
      "%.17g)\n",
      mesh.node_count(), mesh.element_count(), static_cast<std::size_t>(mesh.dof_count()), validity,
      assembly, stress, checksum);
}
