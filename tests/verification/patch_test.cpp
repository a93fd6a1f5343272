// Patch tests: an affine displacement u = a + G x (constant strain) must be reproduced
// exactly by every element type on irregular, unstructured Gmsh meshes of a skewed,
// non-convex hexagon, with the recovered stress equal to C * strain. Dirichlet version: u
// prescribed on the whole boundary. Neumann version: u prescribed on two sides and the
// traction sigma n applied on the others. Solved with Eigen's SimplicialLDLT.

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <filesystem>
#include <iostream>
#include <string>

#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

const std::filesystem::path data_directory = ROBIN_TEST_DATA;

/// u(x) = a + G x with a general (non-symmetric) gradient G.
struct AffineField {
  Eigen::Vector2d offset{0.011, -0.023};
  Eigen::Matrix2d gradient{{0.012, -0.007}, {0.005, 0.009}};

  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const {
    Eigen::Vector3d u;
    u << offset + gradient * x.head<2>(), 0.0;
    return u;
  }
  /// Engineering strain (G_xx, G_yy, G_xy + G_yx).
  Eigen::Vector3d strain() const {
    return {gradient(0, 0), gradient(1, 1), gradient(0, 1) + gradient(1, 0)};
  }
  /// Stress tensor [[s_xx, s_xy], [s_xy, s_yy]] of C strain.
  Eigen::Matrix2d stress_tensor(const Material& material) const {
    const Eigen::Vector3d s = material.stiffness * strain();
    return Eigen::Matrix2d{{s(0), s(2)}, {s(2), s(1)}};
  }
};

/// Solves K_ff u_f = f_f - K_fp u_p with u prescribed by `field` on the nodes of `fixed`.
Eigen::VectorXd solve_with_fixed_boundaries(const Mesh& mesh, const SparseMatrix& stiffness,
                                            const Eigen::VectorXd& load,
                                            const std::vector<std::string>& fixed,
                                            const AffineField& field) {
  std::vector<std::optional<double>> prescribed(2 * mesh.node_count());
  for (const std::string& name : fixed) {
    for (const int node : mesh.boundary(name).nodes()) {
      const Eigen::Vector3d value = field(mesh.nodes[node]);
      prescribed[2 * node] = value.x();
      prescribed[2 * node + 1] = value.y();
    }
  }
  const DofMap dofs(prescribed);
  Eigen::SimplicialLDLT<SparseMatrix> factorization(dofs.reduce_matrix(stiffness));
  EXPECT_EQ(factorization.info(), Eigen::Success);
  return dofs.expand(factorization.solve(dofs.reduce_load(stiffness, load)));
}

/// max_i |u_h(x_i) - u(x_i)| / max_i |u(x_i)| over every node.
double relative_nodal_error(const Mesh& mesh, const Eigen::VectorXd& displacement,
                            const AffineField& field) {
  double error = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    const Eigen::Vector3d exact = field(mesh.nodes[i]);
    error = std::max(error, (displacement.segment<2>(2 * i) - exact.head<2>()).norm());
    scale = std::max(scale, exact.norm());
  }
  return error / scale;
}

/// Largest |s - C strain| / |C strain| over element and nodal stresses.
double relative_stress_error(const Mesh& mesh, const Material& material,
                             const Eigen::VectorXd& displacement, const AffineField& field) {
  const Eigen::Vector3d exact = material.stiffness * field.strain();
  const StressField stress = recover_stress(mesh, material, displacement);
  const double element_error =
      (stress.element_stress.colwise() - exact).colwise().norm().maxCoeff();
  const double nodal_error = (stress.nodal_stress.colwise() - exact).colwise().norm().maxCoeff();
  return std::max(element_error, nodal_error) / exact.norm();
}

struct PatchCase {
  std::string name;
  std::string file;
  MeshReadOptions options;
  ElementType expected_type;
};
void PrintTo(const PatchCase& patch_case, std::ostream* stream) {
  *stream << patch_case.name;
}

class PatchTest : public testing::TestWithParam<PatchCase> {
 protected:
  void SetUp() override {
    mesh_ = read_gmsh_mesh(data_directory / GetParam().file, GetParam().options);
    bool has_expected_type = false;
    for (const ElementBlock& block : mesh_.blocks) {
      has_expected_type = has_expected_type || block.type == GetParam().expected_type;
    }
    ASSERT_TRUE(has_expected_type) << to_string(GetParam().expected_type);
  }
  Mesh mesh_;
  AffineField field_;
  Material material_ = make_isotropic_material(210.0, 0.3, PlaneModel::plane_strain, "patch");
};

TEST_P(PatchTest, DirichletOnTheWholeBoundaryReproducesTheAffineField) {
  std::vector<std::string> all_boundaries;
  for (const auto& [name, group] : mesh_.boundaries) all_boundaries.push_back(name);
  const SparseMatrix stiffness = assemble_stiffness(mesh_, material_);
  const Eigen::VectorXd load = Eigen::VectorXd::Zero(2 * mesh_.node_count());
  const Eigen::VectorXd displacement =
      solve_with_fixed_boundaries(mesh_, stiffness, load, all_boundaries, field_);
  const double displacement_error = relative_nodal_error(mesh_, displacement, field_);
  const double stress_error = relative_stress_error(mesh_, material_, displacement, field_);
  std::cout << GetParam().name << ": " << mesh_.node_count() << " nodes, displacement error "
            << displacement_error << ", stress error " << stress_error << "\n";
  EXPECT_LT(displacement_error, 1e-10);
  EXPECT_LT(stress_error, 1e-9);
}

TEST_P(PatchTest, TractionOnPartOfTheBoundaryReproducesTheAffineField) {
  // An anisotropic material makes the test sensitive to every entry of C.
  material_ = make_voigt_material(
      Eigen::Matrix3d{{300.0, 90.0, 25.0}, {90.0, 180.0, -15.0}, {25.0, -15.0, 70.0}},
      PlaneModel::plane_stress, "patch");
  const SparseMatrix stiffness = assemble_stiffness(mesh_, material_);
  const Eigen::Matrix2d stress = field_.stress_tensor(material_);
  const TractionField traction = [&](const Eigen::Vector3d&, const Eigen::Vector3d& normal) {
    Eigen::Vector3d t;
    t << stress * normal.head<2>(), 0.0;  // t = sigma n
    return t;
  };
  Eigen::VectorXd load = Eigen::VectorXd::Zero(2 * mesh_.node_count());
  std::vector<std::string> fixed;
  for (const auto& [name, group] : mesh_.boundaries) {
    if (name == "bottom" || name == "left") {
      fixed.push_back(name);
    } else {
      load += assemble_boundary_traction(mesh_, group, traction);
    }
  }
  ASSERT_EQ(fixed.size(), 2u);
  const Eigen::VectorXd displacement =
      solve_with_fixed_boundaries(mesh_, stiffness, load, fixed, field_);
  const double displacement_error = relative_nodal_error(mesh_, displacement, field_);
  const double stress_error = relative_stress_error(mesh_, material_, displacement, field_);
  std::cout << GetParam().name << " (traction): displacement error " << displacement_error
            << ", stress error " << stress_error << "\n";
  EXPECT_LT(displacement_error, 1e-10);
  EXPECT_LT(stress_error, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(
    IrregularMeshes, PatchTest,
    testing::Values(
        PatchCase{"triangle3", "mesh_irregular.geo", {}, ElementType::triangle3},
        PatchCase{"quadrilateral4",
                  "mesh_irregular.geo",
                  {.recombine = true},
                  ElementType::quadrilateral4},
        PatchCase{"triangle6", "mesh_irregular.geo", {.element_order = 2}, ElementType::triangle6},
        PatchCase{"mixed", "mesh_mixed.geo", {}, ElementType::quadrilateral4}),
    [](const testing::TestParamInfo<PatchCase>& info) { return info.param.name; });

}  // namespace
}  // namespace robin
