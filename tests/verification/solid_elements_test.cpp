// Solid (three-dimensional) bodies, checked against numbers from outside the code:
//  - the reference elements: shape functions are a partition of unity, Kronecker at their nodes,
//    their gradients sum to zero; the quadrature rules integrate the monomials x^a y^b z^c
//    exactly (tetrahedron: a! b! c! / (a + b + c + 3)!, hexahedron: products of 1D integrals);
//  - structured box meshes: the volume, the boundary areas, the outward normals of every side;
//  - patch tests: an affine displacement u = a + G x (constant strain) is reproduced to
//    round-off by 4- and 10-node tetrahedra and 8-node hexahedra, with the stress C * strain,
//    for an isotropic and a general anisotropic (6 x 6 Voigt) material, with u prescribed on
//    the whole boundary (Dirichlet) and with the traction sigma n on three sides (Neumann);
//  - a manufactured solution u_i = sin(k_i . x) with the body force -div(C eps(u)) derived
//    below: the L2 error converges at the interpolation rate (2 for linear elements, 3 for the
//    10-node tetrahedron);
//  - the rigid motions: an unsupported body has six, spanning the kernel of K;
//  - Gmsh: a .geo block meshed with tetrahedra (orders 1 and 2) and recombined into hexahedra
//    passes the patch test with its physical surfaces as boundaries;
//  - contact: a floating block pressed by a pressure p onto a rigid plane (supported only on
//    two symmetry planes, its vertical translation held by contact) carries the uniform contact
//    pressure p and has the uniaxial-stress displacement u_z = -p z / E, u_x = nu p x / E.
// Linear solves with Eigen's SimplicialLDLT, independently of the project's factorization
// (except the contact case, which is the BodySolver's own).

#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <random>
#include <sstream>

#include "numerics/body_solver.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/finite_element.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/mesh_validity.hpp"
#include "numerics/vtu_writer.hpp"

namespace robin {
namespace {

const std::filesystem::path data_directory = ROBIN_TEST_DATA;
const ElementType solid_types[] = {ElementType::tetrahedron4, ElementType::tetrahedron10,
                                   ElementType::hexahedron8};

double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

TEST(SolidElements, ShapeFunctionsInterpolateTheirNodes) {
  for (const ElementType type : solid_types) {
    const std::vector<Eigen::Vector3d> nodes = reference_nodes(type);
    ASSERT_EQ(static_cast<int>(nodes.size()), nodes_per_element(type));
    ShapeValues values;
    ShapeGradients gradients;
    for (std::size_t j = 0; j < nodes.size(); ++j) {
      shape_functions(type, nodes[j], values, gradients);
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        EXPECT_NEAR(values(static_cast<Eigen::Index>(i)), i == j ? 1.0 : 0.0, 1e-14)
            << to_string(type) << " N_" << i << " at node " << j;
      }
    }
    const Eigen::Vector3d inside(0.21, 0.17, 0.33);
    shape_functions(type, inside, values, gradients);
    EXPECT_NEAR(values.sum(), 1.0, 1e-14) << to_string(type);
    EXPECT_LT(gradients.colwise().sum().norm(), 1e-13) << to_string(type);
    // Linear completeness: sum_i N_i x_i = x, sum_i x_i grad N_i = I.
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      position += values(static_cast<Eigen::Index>(i)) * nodes[i];
      jacobian += nodes[i] * gradients.row(static_cast<Eigen::Index>(i));
    }
    EXPECT_LT((position - inside).norm(), 1e-14) << to_string(type);
    EXPECT_LT((jacobian - Eigen::Matrix3d::Identity()).norm(), 1e-13) << to_string(type);
  }
}

TEST(SolidElements, QuadratureIntegratesMonomialsExactly) {
  for (int degree = 0; degree <= 8; ++degree) {
    const auto tetrahedron = element_quadrature(ElementType::tetrahedron4, degree);
    const auto hexahedron = element_quadrature(ElementType::hexahedron8, degree);
    for (int a = 0; a <= degree; ++a) {
      for (int b = 0; a + b <= degree; ++b) {
        const int c = degree - a - b;
        double tetrahedron_sum = 0.0, hexahedron_sum = 0.0;
        for (const QuadraturePoint& point : tetrahedron) {
          for (const double weight : {point.weight}) {
            tetrahedron_sum += weight * std::pow(point.reference.x(), a) *
                               std::pow(point.reference.y(), b) * std::pow(point.reference.z(), c);
          }
        }
        for (const QuadraturePoint& point : hexahedron) {
          hexahedron_sum += point.weight * std::pow(point.reference.x(), a) *
                            std::pow(point.reference.y(), b) * std::pow(point.reference.z(), c);
        }
        const double tetrahedron_exact =
            factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
        // int_{-1}^{1} x^n dx = 2 / (n + 1) for even n, 0 for odd n.
        const auto line = [](int n) { return n % 2 == 1 ? 0.0 : 2.0 / (n + 1); };
        EXPECT_NEAR(tetrahedron_sum, tetrahedron_exact, 1e-15)
            << "degree " << degree << ": x^" << a << " y^" << b << " z^" << c;
        EXPECT_NEAR(hexahedron_sum, line(a) * line(b) * line(c), 1e-14)
            << "degree " << degree << ": x^" << a << " y^" << b << " z^" << c;
      }
    }
  }
}

double mesh_volume(const Mesh& mesh) {
  double volume = 0.0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    for (std::size_t e = 0; e < mesh.blocks[b].element_count(); ++e) {
      const ElementGeometry geometry(mesh, b, e);
      for (const QuadraturePoint& point : element_quadrature(mesh.blocks[b].type, 2)) {
        volume += geometry.evaluate(point.reference).jacobian * point.weight;
      }
    }
  }
  return volume;
}

TEST(SolidElements, BoxMeshesHaveTheBoxVolumeSideAreasAndOutwardNormals) {
  const Eigen::Vector3d low(-0.5, 0.25, 1.0), high(1.5, 1.0, 1.6);
  const Eigen::Vector3d size = high - low;
  const std::map<std::string, Eigen::Vector3d> outward = {
      {"left", -Eigen::Vector3d::UnitX()},   {"right", Eigen::Vector3d::UnitX()},
      {"front", -Eigen::Vector3d::UnitY()},  {"back", Eigen::Vector3d::UnitY()},
      {"bottom", -Eigen::Vector3d::UnitZ()}, {"top", Eigen::Vector3d::UnitZ()}};
  for (const ElementType type : solid_types) {
    const Mesh mesh = make_box_mesh(low, high, {3, 2, 4}, type);
    check_element_validity(mesh, "box");
    EXPECT_NEAR(mesh_volume(mesh), size.prod(), 1e-13) << to_string(type);
    for (const auto& [name, normal] : outward) {
      const BoundaryGroup& group = mesh.boundary(name);
      const int axis = normal.cwiseAbs().maxCoeff() == std::abs(normal.x()) ? 0
                       : std::abs(normal.y()) == 1.0                        ? 1
                                                                            : 2;
      EXPECT_NEAR(boundary_weights(mesh, group).sum(), size.prod() / size[axis], 1e-13)
          << to_string(type) << " " << name;
      for (const Eigen::Vector3d& node_normal : boundary_node_normals(mesh, group)) {
        EXPECT_LT((node_normal - normal).norm(), 1e-14) << to_string(type) << " " << name;
      }
    }
  }
}

/// u(x) = a + G x with a general (non-symmetric) gradient G.
struct AffineField {
  Eigen::Vector3d offset{0.011, -0.023, 0.004};
  Eigen::Matrix3d gradient{{0.012, -0.007, 0.003}, {0.005, 0.009, -0.002}, {-0.004, 0.006, 0.010}};

  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return offset + gradient * x; }
  /// Engineering strain in Voigt order (xx, yy, zz, 2 yz, 2 xz, 2 xy).
  Eigen::VectorXd strain() const {
    Eigen::VectorXd strain(6);
    strain << gradient(0, 0), gradient(1, 1), gradient(2, 2), gradient(1, 2) + gradient(2, 1),
        gradient(0, 2) + gradient(2, 0), gradient(0, 1) + gradient(1, 0);
    return strain;
  }
  /// The stress tensor of C strain.
  Eigen::Matrix3d stress(const Material& material) const {
    const Eigen::VectorXd s = material.stiffness * strain();
    Eigen::Matrix3d tensor;
    tensor << s(0), s(5), s(4), s(5), s(1), s(3), s(4), s(3), s(2);
    return tensor;
  }
};

/// A random symmetric positive definite 6 x 6 stiffness (fully anisotropic), scale ~1.
Eigen::MatrixXd anisotropic_stiffness() {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd factor(6, 6);
  for (Eigen::Index i = 0; i < 36; ++i) factor(i) = uniform(random);
  return factor * factor.transpose() + 2.0 * Eigen::MatrixXd::Identity(6, 6);
}

std::vector<Material> patch_materials() {
  return {make_isotropic_solid_material(2.0, 0.3, "isotropic"),
          make_voigt_material(anisotropic_stiffness(), PlaneModel::plane_strain, "anisotropic")};
}

/// Solves K_ff u_f = f_f - K_fp u_p with u = field on the nodes of the `fixed` boundaries.
Eigen::VectorXd solve_with_prescribed(
    const Mesh& mesh, const Material& material, const std::vector<std::string>& fixed,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& field,
    const Eigen::VectorXd& load) {
  std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
  for (const std::string& name : fixed) {
    for (const int node : mesh.boundary(name).nodes()) {
      const Eigen::Vector3d value = field(mesh.nodes[node]);
      for (int c = 0; c < 3; ++c) prescribed[3 * node + c] = value(c);
    }
  }
  const DofMap dofs(prescribed);
  const SparseMatrix stiffness = assemble_stiffness(mesh, material);
  const Eigen::SimplicialLDLT<SparseMatrix> solver(dofs.reduce_matrix(stiffness));
  EXPECT_EQ(solver.info(), Eigen::Success);
  return dofs.expand(solver.solve(dofs.reduce_load(stiffness, load)));
}

void expect_affine(const Mesh& mesh, const Material& material, const AffineField& field,
                   const Eigen::VectorXd& displacement, const std::string& label) {
  double error = 0.0;
  for (std::size_t node = 0; node < mesh.node_count(); ++node) {
    error = std::max(error, (displacement.segment<3>(3 * node) - field(mesh.nodes[node])).norm());
  }
  EXPECT_LT(error, 1e-12) << label;
  const StressField stress = recover_stress(mesh, material, displacement);
  const Eigen::VectorXd exact = material.stiffness * field.strain();
  const double scale = exact.norm();
  for (Eigen::Index k = 0; k < stress.element_stress.cols(); ++k) {
    ASSERT_LT((stress.element_stress.col(k) - exact).norm(), 1e-10 * scale) << label;
  }
}

TEST(SolidPatchTest, DirichletPatchIsExactForEveryElementAndMaterial) {
  const AffineField field;
  for (const ElementType type : solid_types) {
    // A sheared, non-cubic box: nodes moved by a smooth non-affine map keep the patch test exact
    // only when the elements are isoparametric; a box suffices for the affine tetrahedra.
    Mesh mesh = make_box_mesh({0.0, 0.0, 0.0}, {1.0, 0.7, 0.5}, {3, 3, 2}, type);
    for (Eigen::Vector3d& node : mesh.nodes) {
      node += 0.04 * Eigen::Vector3d(std::sin(3.0 * node.y()), std::sin(2.0 * node.z()),
                                     std::sin(4.0 * node.x()));
    }
    if (type == ElementType::tetrahedron10) {
      // Straight-sided: midside nodes at their edges' midpoints (the affine map of P2).
      mesh = make_box_mesh({0.0, 0.0, 0.0}, {1.0, 0.7, 0.5}, {3, 3, 2}, type);
    }
    for (const Material& material : patch_materials()) {
      const Eigen::VectorXd displacement =
          solve_with_prescribed(mesh, material, {"left", "right", "front", "back", "bottom", "top"},
                                field, Eigen::VectorXd::Zero(mesh.dof_count()));
      expect_affine(mesh, material, field, displacement,
                    to_string(type) + (material.stiffness(0, 1) == material.stiffness(0, 2)
                                           ? " isotropic"
                                           : " anisotropic"));
    }
  }
}

TEST(SolidPatchTest, NeumannPatchIsExactWithTractionsOnThreeSides) {
  const AffineField field;
  for (const ElementType type : solid_types) {
    const Mesh mesh = make_box_mesh({0.0, 0.0, 0.0}, {1.0, 0.7, 0.5}, {3, 2, 2}, type);
    for (const Material& material : patch_materials()) {
      const Eigen::Matrix3d stress = field.stress(material);
      Eigen::VectorXd load = Eigen::VectorXd::Zero(mesh.dof_count());
      for (const char* side : {"right", "back", "top"}) {
        load += assemble_boundary_traction(
            mesh, mesh.boundary(side),
            [&](const Eigen::Vector3d&, const Eigen::Vector3d& normal) -> Eigen::Vector3d {
              return stress * normal;  // t = sigma n
            });
      }
      const Eigen::VectorXd displacement =
          solve_with_prescribed(mesh, material, {"left", "front", "bottom"}, field, load);
      expect_affine(mesh, material, field, displacement, to_string(type) + " Neumann");
    }
  }
}

/// u_i = sin(k_i . x), a smooth field with every strain component non-zero.
const Eigen::Matrix3d wave_vectors{{1.1, 0.7, -0.5}, {0.6, -0.9, 1.2}, {-0.8, 0.5, 1.0}};

Eigen::Vector3d manufactured_displacement(const Eigen::Vector3d& x) {
  return (wave_vectors * x).array().sin().matrix();
}

/// b = -div(C eps(u)): with H_ijl = d_j d_l u_i = -k_ij k_il sin(k_i . x), the derivative of the
/// Voigt strain along x_l is the Voigt form of sym(H_..l) (shears doubled), sigma's derivative
/// C times it, and (div sigma)_i = sum_l d_l sigma_il.
Eigen::Vector3d manufactured_body_force(const Eigen::MatrixXd& stiffness,
                                        const Eigen::Vector3d& x) {
  const Eigen::Vector3d sines = (wave_vectors * x).array().sin().matrix();
  Eigen::Vector3d divergence = Eigen::Vector3d::Zero();
  for (int l = 0; l < 3; ++l) {
    Eigen::Matrix3d gradient_derivative;  // d_l (d_j u_i), i row, j column
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        gradient_derivative(i, j) = -wave_vectors(i, j) * wave_vectors(i, l) * sines(i);
      }
    }
    const Eigen::Matrix3d& g = gradient_derivative;
    Eigen::VectorXd strain_derivative(6);
    strain_derivative << g(0, 0), g(1, 1), g(2, 2), g(1, 2) + g(2, 1), g(0, 2) + g(2, 0),
        g(0, 1) + g(1, 0);
    const Eigen::VectorXd s = stiffness * strain_derivative;
    Eigen::Matrix3d stress_derivative;
    stress_derivative << s(0), s(5), s(4), s(5), s(1), s(3), s(4), s(3), s(2);
    divergence += stress_derivative.col(l);
  }
  return -divergence;
}

TEST(SolidManufacturedSolution, ConvergesAtTheInterpolationRate) {
  const Material material =
      make_voigt_material(anisotropic_stiffness(), PlaneModel::plane_strain, "anisotropic");
  const std::vector<std::string> all = {"left", "right", "front", "back", "bottom", "top"};
  const std::vector<std::pair<ElementType, double>> expected = {{ElementType::tetrahedron4, 2.0},
                                                                {ElementType::hexahedron8, 2.0},
                                                                {ElementType::tetrahedron10, 3.0}};
  for (const auto& [type, rate] : expected) {
    std::vector<double> errors;
    const std::vector<int> divisions = {2, 4, 8};
    for (const int n : divisions) {
      const Mesh mesh = make_box_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, {n, n, n}, type);
      const Eigen::VectorXd load = assemble_body_force(mesh, [&](const Eigen::Vector3d& x) {
        return manufactured_body_force(material.stiffness, x);
      });
      const Eigen::VectorXd displacement =
          solve_with_prescribed(mesh, material, all, manufactured_displacement, load);
      errors.push_back(l2_displacement_error(mesh, displacement, manufactured_displacement));
    }
    for (std::size_t k = 1; k < errors.size(); ++k) {
      const double observed = std::log2(errors[k - 1] / errors[k]);
      std::cout << to_string(type) << ": n = " << divisions[k] << ", L2 error " << errors[k]
                << ", rate " << observed << "\n";
      EXPECT_GT(observed, rate - 0.25) << to_string(type) << " at n = " << divisions[k];
    }
  }
}

TEST(SolidRigidMotions, AnUnsupportedBodyHasSixSpanningTheKernelOfK) {
  for (const ElementType type : solid_types) {
    const Mesh mesh = make_box_mesh({0.0, 0.0, 0.0}, {2.0, 1.0, 0.5}, {2, 2, 1}, type);
    const DofMap free_body(
        std::vector<std::optional<double>>(static_cast<std::size_t>(mesh.dof_count())));
    EXPECT_FALSE(removes_rigid_motions(mesh, free_body));
    const Eigen::MatrixXd modes = rigid_body_modes(mesh, free_body);
    ASSERT_EQ(modes.cols(), 6) << to_string(type);
    const SparseMatrix stiffness =
        assemble_stiffness(mesh, make_isotropic_solid_material(1.0, 0.25, "material"));
    EXPECT_LT((stiffness * modes).norm(), 1e-12) << to_string(type);
    EXPECT_LT((modes.transpose() * modes - Eigen::MatrixXd::Identity(6, 6)).norm(), 1e-12);
    // Fixing the bottom face removes all six.
    std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
    for (const int node : mesh.boundary("bottom").nodes()) {
      for (int c = 0; c < 3; ++c) prescribed[3 * node + c] = 0.0;
    }
    EXPECT_TRUE(removes_rigid_motions(mesh, DofMap(prescribed)));
    // Fixing only u_z on the bottom leaves the two horizontal translations and the rotation
    // about z.
    std::vector<std::optional<double>> sliding(static_cast<std::size_t>(mesh.dof_count()));
    for (const int node : mesh.boundary("bottom").nodes()) sliding[3 * node + 2] = 0.0;
    EXPECT_EQ(rigid_body_modes(mesh, DofMap(sliding)).cols(), 3) << to_string(type);
  }
}

TEST(SolidGmshMeshes, TetrahedraAndHexahedraFromAGeoPassThePatchTest) {
  const AffineField field;
  const Material material = make_isotropic_solid_material(3.0, 0.2, "material");
  for (const auto& [order, recombine, type] : {std::tuple{1, false, ElementType::tetrahedron4},
                                               std::tuple{2, false, ElementType::tetrahedron10},
                                               std::tuple{1, true, ElementType::hexahedron8}}) {
    const Mesh mesh = read_gmsh_mesh(
        data_directory / (recombine ? "solid_block_hexahedra.geo" : "solid_block.geo"),
        {0.35, order, recombine});
    ASSERT_EQ(mesh.dimension, 3);
    ASSERT_EQ(mesh.blocks.size(), 1u);
    EXPECT_EQ(mesh.blocks.front().type, type);
    check_element_validity(mesh, "solid block");
    EXPECT_NEAR(mesh_volume(mesh), 1.0 * 0.6 * 0.4, 1e-12) << to_string(type);
    for (const std::string name : {"left", "right", "front", "back", "bottom", "top"}) {
      EXPECT_NO_THROW(mesh.boundary(name)) << name;
    }
    EXPECT_NEAR(boundary_weights(mesh, mesh.boundary("top")).sum(), 1.0 * 0.6, 1e-12);
    for (const Eigen::Vector3d& normal : boundary_node_normals(mesh, mesh.boundary("top"))) {
      EXPECT_LT((normal - Eigen::Vector3d::UnitZ()).norm(), 1e-12) << to_string(type);
    }
    for (const Eigen::Vector3d& normal : boundary_node_normals(mesh, mesh.boundary("left"))) {
      EXPECT_LT((normal + Eigen::Vector3d::UnitX()).norm(), 1e-12) << to_string(type);
    }
    const Eigen::VectorXd displacement =
        solve_with_prescribed(mesh, material, {"left", "right", "front", "back", "bottom", "top"},
                              field, Eigen::VectorXd::Zero(mesh.dof_count()));
    expect_affine(mesh, material, field, displacement, "Gmsh " + to_string(type));
  }
}

TEST(SolidContact, FloatingBlockOnARigidPlaneCarriesTheUniformPressure) {
  static constexpr double young = 10.0, poisson = 0.3, pressure = 0.2;
  for (const ElementType type : solid_types) {
    BodyDefinition body;
    body.name = "block";
    body.mesh = make_box_mesh({0.0, 0.0, 0.0}, {1.0, 0.8, 0.6}, {3, 2, 2}, type);
    body.material = make_isotropic_solid_material(young, poisson, "block");
    // Symmetry planes x = 0 and y = 0; nothing holds the vertical translation but the contact.
    body.dirichlet = {{"left", 0.0, std::nullopt, std::nullopt},
                      {"front", std::nullopt, 0.0, std::nullopt}};
    TractionCondition load;
    load.boundary = "top";
    load.is_pressure = true;
    load.pressure = pressure;
    body.tractions = {load};
    body.contact_boundaries = {"bottom"};
    BodySolverOptions options;
    options.rigid_motions = RigidMotions::held_by_contact;
    BodySolver solver(body, options);
    const InterfaceDescription interface = solver.contact_boundary();
    ASSERT_EQ(interface.dimension, 3);
    EXPECT_EQ(interface.rigid_modes, 1) << to_string(type);
    // Node-to-node rows against the rigid plane z = 0: u . n <= 0 with n = (0, 0, -1).
    solver.assign_contact(
        node_to_node_operator(interface.node_ids, interface.normals, interface.weights));
    const ContactSolveResult result = solver.solve_contact(
        Eigen::VectorXd::Zero(static_cast<Eigen::Index>(interface.node_ids.size())));
    ASSERT_EQ(result.status, QpStatus::converged) << to_string(type) << ": " << result.message;
    for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
      EXPECT_NEAR(interface.normals[i].z(), -1.0, 1e-14);
      EXPECT_GT(interface.weights[i], 0.0);
    }
    EXPECT_NEAR(std::accumulate(interface.weights.begin(), interface.weights.end(), 0.0), 0.8,
                1e-13);
    // lambda_i = the consistent nodal force of the uniform pressure, p int N_i over the bottom.
    const Eigen::VectorXd consistent = assemble_boundary_traction(
        body.mesh, body.mesh.boundary("bottom"),
        [](const Eigen::Vector3d&, const Eigen::Vector3d&) -> Eigen::Vector3d {
          return Eigen::Vector3d(0.0, 0.0, pressure);
        });
    for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
      EXPECT_NEAR(result.contact_force[static_cast<Eigen::Index>(i)],
                  consistent(3 * interface.node_ids[i] + 2), 1e-9 * pressure)
          << to_string(type) << " node " << interface.node_tags[i];
    }
    const Eigen::VectorXd displacement = solver.displacement(result.contact_force);
    for (std::size_t node = 0; node < body.mesh.node_count(); ++node) {
      const Eigen::Vector3d& x = body.mesh.nodes[node];
      const Eigen::Vector3d exact(poisson * pressure * x.x() / young,
                                  poisson * pressure * x.y() / young, -pressure * x.z() / young);
      EXPECT_LT((displacement.segment<3>(3 * static_cast<Eigen::Index>(node)) - exact).norm(),
                1e-9 * pressure / young)
          << to_string(type) << " node " << node;
    }
  }
}

/// The whitespace-separated numbers of the ascii DataArray called `name` in a .vtu text.
std::vector<double> ascii_array(const std::string& text, const std::string& name) {
  const std::size_t start = text.find("Name=\"" + name + "\"");
  const std::size_t open = text.find('>', start) + 1;
  const std::size_t close = text.find("</DataArray>", open);
  std::istringstream values(text.substr(open, close - open));
  std::vector<double> numbers;
  for (double value = 0.0; values >> value;) numbers.push_back(value);
  return numbers;
}

TEST(SolidOutput, QuadraticTetrahedraAreWrittenInVtkNodeOrder) {
  // VTK_QUADRATIC_TETRA (24): corners 0-3, then the midside nodes of edges 01, 12, 20, 03, 13, 23
  // (VTK's documentation of vtkQuadraticTetra), whatever order Gmsh uses.
  const Mesh mesh =
      make_box_mesh({0.0, 0.0, 0.0}, {1.0, 2.0, 3.0}, {1, 1, 1}, ElementType::tetrahedron10);
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("solid_output_" + std::to_string(::getpid()) + ".vtu");
  write_vtu(path, mesh, {}, {}, {VtuEncoding::ascii, false});
  std::ifstream file(path);
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  const std::vector<double> points = ascii_array(text, "Points");
  const std::vector<double> connectivity = ascii_array(text, "connectivity");
  const std::vector<double> types = ascii_array(text, "types");
  ASSERT_EQ(types.size(), 6u);
  ASSERT_EQ(connectivity.size(), 60u);
  for (const double type : types) EXPECT_EQ(type, 24.0);
  const auto point = [&](double index) {
    const auto k = static_cast<std::size_t>(index);
    return Eigen::Vector3d(points[3 * k], points[3 * k + 1], points[3 * k + 2]);
  };
  constexpr int vtk_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (std::size_t cell = 0; cell < 6; ++cell) {
    const double* nodes = &connectivity[10 * cell];
    for (int edge = 0; edge < 6; ++edge) {
      const Eigen::Vector3d middle =
          0.5 * (point(nodes[vtk_edges[edge][0]]) + point(nodes[vtk_edges[edge][1]]));
      EXPECT_LT((point(nodes[4 + edge]) - middle).norm(), 1e-12)
          << "cell " << cell << " edge " << edge;
    }
  }
}

}  // namespace
}  // namespace robin
