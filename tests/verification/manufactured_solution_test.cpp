// Method of manufactured solutions: u = (sin(a x) cos(b y), cos(c x) sin(d y)) on a skewed,
// non-convex hexagon, body force b = -div(C eps(u)) derived by hand below, u prescribed on
// the whole boundary. The L2 error on Gmsh meshes with h = 0.2 ... 0.025 must converge at
// the interpolation rate: 2 for P1 triangles and Q1 quadrilaterals, 3 for P2 triangles.
// Rates are measured against the effective element size sqrt(area / element count), since
// Gmsh's unstructured meshes do not scale exactly with the requested h (those nominal
// rates are printed too).
// Solved with Eigen's SimplicialLDLT, independently of the project's factorization.

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

const std::filesystem::path data_directory = ROBIN_TEST_DATA;

constexpr double a = 1.3, b = 0.9, c = 0.8, d = 1.1;

Eigen::Vector3d exact_displacement(const Eigen::Vector3d& x) {
  return {std::sin(a * x.x()) * std::cos(b * x.y()), std::cos(c * x.x()) * std::sin(d * x.y()),
          0.0};
}

/// b = -div sigma with sigma = C (u1_x, u2_y, u1_y + u2_x). With s = C e:
///   (div sigma)_x = d_x s_xx + d_y s_xy,   (div sigma)_y = d_x s_xy + d_y s_yy,
/// where d_x e = (u1_xx, u2_xy, u1_xy + u2_xx) and d_y e = (u1_xy, u2_yy, u1_yy + u2_xy).
Eigen::Vector3d body_force(const Eigen::Matrix3d& stiffness, const Eigen::Vector3d& x) {
  const double sin_ax = std::sin(a * x.x()), cos_ax = std::cos(a * x.x());
  const double sin_by = std::sin(b * x.y()), cos_by = std::cos(b * x.y());
  const double sin_cx = std::sin(c * x.x()), cos_cx = std::cos(c * x.x());
  const double sin_dy = std::sin(d * x.y()), cos_dy = std::cos(d * x.y());
  // u1 = sin(a x) cos(b y)
  const double u1_xx = -a * a * sin_ax * cos_by;
  const double u1_xy = -a * b * cos_ax * sin_by;
  const double u1_yy = -b * b * sin_ax * cos_by;
  // u2 = cos(c x) sin(d y)
  const double u2_xx = -c * c * cos_cx * sin_dy;
  const double u2_xy = -c * d * sin_cx * cos_dy;
  const double u2_yy = -d * d * cos_cx * sin_dy;
  const Eigen::Vector3d stress_x = stiffness * Eigen::Vector3d(u1_xx, u2_xy, u1_xy + u2_xx);
  const Eigen::Vector3d stress_y = stiffness * Eigen::Vector3d(u1_xy, u2_yy, u1_yy + u2_xy);
  return -Eigen::Vector3d(stress_x(0) + stress_y(2), stress_x(2) + stress_y(1), 0.0);
}

/// L2 error of the finite-element solution with u prescribed on every boundary node.
double solve_and_measure(const Mesh& mesh, const Material& material) {
  std::vector<std::optional<double>> prescribed(2 * mesh.node_count());
  for (const auto& [name, group] : mesh.boundaries) {
    for (const int node : group.nodes()) {
      const Eigen::Vector3d value = exact_displacement(mesh.nodes[node]);
      prescribed[2 * node] = value.x();
      prescribed[2 * node + 1] = value.y();
    }
  }
  const DofMap dofs(prescribed);
  const SparseMatrix stiffness = assemble_stiffness(mesh, material);
  const Eigen::VectorXd load = assemble_body_force(
      mesh, [&](const Eigen::Vector3d& x) { return body_force(material.stiffness, x); });
  // K_ff u_f = f_f - K_fp u_p
  Eigen::SimplicialLDLT<SparseMatrix> factorization(dofs.reduce_matrix(stiffness));
  EXPECT_EQ(factorization.info(), Eigen::Success);
  const Eigen::VectorXd displacement =
      dofs.expand(factorization.solve(dofs.reduce_load(stiffness, load)));
  return l2_displacement_error(mesh, displacement, exact_displacement);
}

/// Observed rates log(e_k / e_k+1) / log(h_k / h_k+1) and their least-squares slope.
struct Rates {
  std::vector<double> consecutive;
  double fitted = 0.0;
};

Rates convergence_rates(const std::vector<double>& sizes, const std::vector<double>& errors) {
  Rates rates;
  for (std::size_t k = 0; k + 1 < sizes.size(); ++k) {
    rates.consecutive.push_back(std::log(errors[k] / errors[k + 1]) /
                                std::log(sizes[k] / sizes[k + 1]));
  }
  // Slope of log e against log h.
  const auto n = static_cast<double>(sizes.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const double x = std::log(sizes[k]), y = std::log(errors[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  rates.fitted = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return rates;
}

struct ConvergenceCase {
  std::string name;
  MeshReadOptions options;
  double expected_rate;
};
void PrintTo(const ConvergenceCase& convergence_case, std::ostream* stream) {
  *stream << convergence_case.name;
}

class ManufacturedSolution : public testing::TestWithParam<ConvergenceCase> {};

TEST_P(ManufacturedSolution, L2ErrorConvergesAtTheExpectedRate) {
  const Material material =
      make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "manufactured");
  std::vector<double> sizes, errors, nominal = {0.2, 0.1, 0.05, 0.025};
  for (const double size : nominal) {
    MeshReadOptions options = GetParam().options;
    options.size = size;
    const Mesh mesh = read_gmsh_mesh(data_directory / "mesh_irregular.geo", options);
    errors.push_back(solve_and_measure(mesh, material));
    sizes.push_back(std::sqrt(3.135 / mesh.element_count()));
    std::cout << GetParam().name << " h = " << size << ": " << mesh.node_count() << " nodes, "
              << mesh.element_count() << " elements, L2 error " << errors.back() << "\n";
  }
  const Rates rates = convergence_rates(sizes, errors);
  const Rates nominal_rates = convergence_rates(nominal, errors);
  for (const double rate : nominal_rates.consecutive)
    std::cout << "  nominal rate " << rate << "\n";
  for (const double rate : rates.consecutive) std::cout << "  rate " << rate << "\n";
  std::cout << "  fitted rate " << rates.fitted << "\n";
  const double expected = GetParam().expected_rate;
  EXPECT_GE(rates.fitted, expected - 0.2);
  EXPECT_LE(rates.fitted, expected + 0.2);
  for (const double rate : rates.consecutive) {
    EXPECT_GE(rate, expected - 0.2);
    EXPECT_LE(rate, expected + 0.2);
  }
}

INSTANTIATE_TEST_SUITE_P(
    IrregularHexagon, ManufacturedSolution,
    testing::Values(ConvergenceCase{"triangle3", {}, 2.0},
                    ConvergenceCase{"quadrilateral4", {.recombine = true}, 2.0},
                    ConvergenceCase{"triangle6", {.element_order = 2}, 3.0}),
    [](const testing::TestParamInfo<ConvergenceCase>& info) { return info.param.name; });

}  // namespace
}  // namespace robin
