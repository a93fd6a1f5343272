// BodySolver with the iterative inner solver (linear_solver = multigrid: AMG-preconditioned
// conjugate gradients, the contact problem by the primal-dual active set method with projected
// conjugate gradients, numerics/primal_contact.hpp) against the same body with the direct
// solver (a CHOLMOD factor, the contact problem in its dual form by MPRGP; body_solver_test.cpp
// checks that one against an independent solve).
//
// The bodies: a solid box (hexahedra; tetrahedra) clamped at its bottom, pushed up by a body
// force and a traction, its top the contact face with node-to-node rows (normal (0, 0, 1)), and
// the 2D block of tests/test_bodies.hpp on a finer mesh. The obstacle g_j = e_j (0.3 + 1.2 x_j / L)
// (e the free trace) closes the contact for x < 7/12 L and leaves the rest open: a partial contact.
//
// Tolerances. The conjugate gradients stop at ||b - K x|| <= 1e-12 ||b||; the error of x is then
// at most cond(K) times that relative residual, in practice far less. The bounds below (1e-9
// relative) allow cond(K) up to 1e3 in that worst case; the measured errors are printed.
// Also checked: the Signorini conditions of the multigrid result itself (lambda >= 0, no
// penetration beyond 1e-9 of the displacement scale, complementarity), the same active set,
// the displacement field (of the last solve's force, kept, and of another force, solved from the
// kept one, and from the kept one and the last correction), a second solve warm-started after a
// change of obstacle and load factor, the refusal of a floating body, and the fall-back to the
// factor when the contact rows are linearly dependent (as on the mortar side of a finer non-mortar
// side). And solve_primal_contact's inexact active-set steps (the default, none, very loose ones
// limited to two) against the Signorini conditions of the KKT system solved by CHOLMOD.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../test_bodies.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/cholesky.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/errors.hpp"
#include "numerics/material.hpp"
#include "numerics/primal_contact.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

constexpr double agreement = 1e-9;  // relative (the file comment)

BodyDefinition solid_box(ElementType type) {
  BodyDefinition body;
  body.name = "box";
  body.mesh = make_box_mesh({0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, {16, 8, 8}, type);
  body.material = make_isotropic_solid_material(1000.0, 0.3, "box");
  body.body_force = Eigen::Vector3d(0.0, 0.0, 40.0);
  body.dirichlet.push_back({"bottom", 0.0, 0.0, 0.0});
  TractionCondition traction;
  traction.boundary = "right";
  traction.vector = Eigen::Vector3d(-4.0, 1.0, 1.5);
  body.tractions.push_back(traction);
  body.contact_boundaries = {"top"};
  return body;
}

/// The block of tests/test_bodies.hpp on a finer mesh (40 x 20 cells: AMG has coarse levels),
/// pushed up by a body force.
BodyDefinition plane_block() {
  BodyDefinition body = testing::plane_quadratic_block("block");
  body.mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 40, 20, ElementType::triangle6);
  body.body_force = Eigen::Vector3d(0.0, 30.0, 0.0);
  return body;
}

/// Node-to-node rows on every node of "top" with the outward normal (the last axis).
ContactOperator top_operator(const Mesh& mesh) {
  const std::vector<int> nodes = mesh.boundary("top").nodes();
  const Eigen::VectorXd weights = boundary_weights(mesh, mesh.boundary("top"));
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal[mesh.dimension - 1] = 1.0;
  std::vector<double> node_weights;
  for (int node : nodes) node_weights.push_back(weights[node]);
  return node_to_node_operator(nodes, std::vector<Eigen::Vector3d>(nodes.size(), normal),
                               node_weights);
}

std::unique_ptr<BodySolver> make_solver(const BodyDefinition& body, LinearSolverKind kind) {
  BodySolverOptions options;
  options.linear_solver = kind;
  auto solver = std::make_unique<BodySolver>(body, options);
  solver->assign_contact(top_operator(solver->mesh()));
  return solver;
}

/// g_j = e_j (0.3 + 1.2 x_j / L): closed where x_j < 7/12 L (the file comment).
Eigen::VectorXd partial_obstacle(const BodySolver& solver) {
  const ContactOperator& contact = solver.contact_operator();
  const Eigen::VectorXd& free_trace = solver.free_trace();
  double length = 0.0;
  for (const Eigen::Vector3d& node : solver.mesh().nodes) length = std::max(length, node.x());
  Eigen::VectorXd obstacle(contact.row_count());
  for (int row = 0; row < contact.row_count(); ++row) {
    const double x = solver.mesh().nodes[contact.nodes[contact.row_offsets[row]]].x();
    obstacle[row] = free_trace[row] * (0.3 + 1.2 * x / length);
  }
  return obstacle;
}

double relative_difference(const Eigen::VectorXd& value, const Eigen::VectorXd& reference) {
  return (value - reference).lpNorm<Eigen::Infinity>() / reference.lpNorm<Eigen::Infinity>();
}

struct Case {
  std::string label;
  BodyDefinition body;
};

std::vector<Case> cases() {
  return {{"hexahedra", solid_box(ElementType::hexahedron8)},
          {"tetrahedra", solid_box(ElementType::tetrahedron4)},
          {"plane triangle6", plane_block()}};
}

TEST(MultigridBody, TracesAndCorrectionEqualTheDirectSolver) {
  for (const Case& test : cases()) {
    const auto direct = make_solver(test.body, LinearSolverKind::direct);
    const auto multigrid = make_solver(test.body, LinearSolverKind::multigrid);
    EXPECT_EQ(multigrid->factor_nonzeros(), 0) << test.label;
    const double free_error = relative_difference(multigrid->free_trace(), direct->free_trace());
    EXPECT_GT(direct->free_trace().minCoeff(), 0.0) << test.label << ": the top must rise";
    EXPECT_LE(free_error, agreement) << test.label;

    Eigen::VectorXd force(direct->contact_size());
    for (Eigen::Index i = 0; i < force.size(); ++i) force[i] = 1.0 + 0.5 * std::cos(1.3 * i);
    const double correction_error =
        relative_difference(multigrid->solve_correction(force), direct->solve_correction(force));
    const double neumann_error =
        relative_difference(multigrid->solve_neumann(force), direct->solve_neumann(force));
    EXPECT_LE(correction_error, agreement) << test.label;
    EXPECT_LE(neumann_error, agreement) << test.label;
    EXPECT_GT(multigrid->inner_iterations(), 0) << test.label;
    std::cout << test.label << ": free trace " << free_error << ", correction " << correction_error
              << ", Neumann " << neumann_error << " relative; " << multigrid->inner_iterations()
              << " CG iterations in " << multigrid->solve_count() << " solves\n";
  }
}

/// A correction with the accuracy hint 1e-3 (the compliance probe's): fewer conjugate gradient
/// iterations than the full one, and still within 1e-2 of the direct solver's (its relative
/// residual is 1e-3; the error may exceed it by up to cond(K), here little). Hints outside
/// [0, 1) are refused.
TEST(MultigridBody, CorrectionWithAnAccuracyHintStopsEarlier) {
  const BodyDefinition body = solid_box(ElementType::hexahedron8);
  const auto direct = make_solver(body, LinearSolverKind::direct);
  const auto multigrid = make_solver(body, LinearSolverKind::multigrid);
  Eigen::VectorXd force(direct->contact_size());
  for (Eigen::Index i = 0; i < force.size(); ++i) force[i] = (i % 2 == 0 ? 1.0 : -1.0);
  const Eigen::VectorXd expected = direct->solve_correction(force);
  // the hinted one first: a full correction of the same force would be its start (it is kept)
  long before = multigrid->inner_iterations();
  const Eigen::VectorXd hinted = multigrid->solve_correction(force, 1e-3);
  const long hinted_iterations = multigrid->inner_iterations() - before;
  before = multigrid->inner_iterations();
  const Eigen::VectorXd full = multigrid->solve_correction(force);
  const long full_iterations = multigrid->inner_iterations() - before;
  EXPECT_LE(relative_difference(full, expected), agreement);
  const double hinted_error = relative_difference(hinted, expected);
  EXPECT_LE(hinted_error, 1e-2);
  EXPECT_LT(hinted_iterations, full_iterations);
  std::cout << "full: " << full_iterations << " CG iterations; hint 1e-3: " << hinted_iterations
            << " CG iterations, error " << hinted_error << "\n";
  EXPECT_THROW(multigrid->solve_correction(force, 1.0), InputError);
  EXPECT_THROW(multigrid->solve_correction(force, -1e-3), InputError);
}

/// Corrections start from the kept earlier ones (solution_history.hpp): a force that combines
/// two earlier ones costs at most two conjugate gradient iterations, a new one as many as from
/// zero, and all equal the direct solver's.
TEST(MultigridBody, CorrectionsStartFromTheKeptOnes) {
  for (const Case& test : cases()) {
    const auto direct = make_solver(test.body, LinearSolverKind::direct);
    const auto multigrid = make_solver(test.body, LinearSolverKind::multigrid);
    const Eigen::Index size = direct->contact_size();
    Eigen::VectorXd first(size), second(size), fresh(size), combined(size);
    for (Eigen::Index i = 0; i < size; ++i) {
      first[i] = 1.0 + 0.5 * std::cos(1.3 * i);
      second[i] = std::sin(0.4 * i);
      fresh[i] = (i % 3 == 0 ? 1.0 : -0.5) + 0.1 * i / size;
    }
    combined = 0.5 * first - 2.0 * second;
    std::vector<long> iterations;
    for (const Eigen::VectorXd* force : {&first, &second, &combined, &fresh}) {
      const long before = multigrid->inner_iterations();
      const double error = relative_difference(multigrid->solve_correction(*force),
                                               direct->solve_correction(*force));
      iterations.push_back(multigrid->inner_iterations() - before);
      EXPECT_LE(error, agreement) << test.label;
    }
    EXPECT_LE(iterations[2], 2) << test.label;
    EXPECT_GT(iterations[3], 4 * iterations[2]) << test.label;
    std::cout << test.label << ": CG iterations " << iterations[0] << ", " << iterations[1]
              << ", combined " << iterations[2] << ", new " << iterations[3] << "\n";
  }
}

TEST(MultigridBody, ContactSolveEqualsTheDirectSolverAndIsSignorini) {
  for (const Case& test : cases()) {
    const auto direct = make_solver(test.body, LinearSolverKind::direct);
    const auto multigrid = make_solver(test.body, LinearSolverKind::multigrid);
    const Eigen::VectorXd obstacle = partial_obstacle(*direct);
    const ContactSolveResult expected = direct->solve_contact(obstacle);
    const ContactSolveResult result = multigrid->solve_contact(obstacle);
    ASSERT_EQ(expected.status, QpStatus::converged) << test.label << ": " << expected.message;
    ASSERT_EQ(result.status, QpStatus::converged) << test.label << ": " << result.message;
    const long closed = std::count(expected.active.begin(), expected.active.end(), true);
    EXPECT_GE(closed, 3) << test.label;
    EXPECT_GE(direct->contact_size() - closed, 3) << test.label;
    EXPECT_EQ(result.active, expected.active) << test.label;

    const double force_error = relative_difference(result.contact_force, expected.contact_force);
    const double trace_error = relative_difference(result.normal_trace, expected.normal_trace);
    EXPECT_LE(force_error, agreement) << test.label;
    EXPECT_LE(trace_error, agreement) << test.label;
    const double scale = obstacle.lpNorm<Eigen::Infinity>();
    EXPECT_GE(result.contact_force.minCoeff(), 0.0) << test.label;
    EXPECT_LE(result.penetration, 1e-9 * scale) << test.label;
    EXPECT_LE(result.complementarity, 1e-9 * scale * result.contact_force.lpNorm<Eigen::Infinity>())
        << test.label;

    const double displacement_error =
        relative_difference(multigrid->displacement(result.contact_force),
                            direct->displacement(expected.contact_force));
    EXPECT_LE(displacement_error, agreement) << test.label;
    // a force other than the last solve's (the direct solver's): a solve from the kept u
    const double other_force_error =
        relative_difference(multigrid->displacement(expected.contact_force),
                            direct->displacement(expected.contact_force));
    EXPECT_LE(other_force_error, agreement) << test.label;
    std::cout << test.label << ": " << closed << " of " << direct->contact_size()
              << " closed; force " << force_error << ", trace " << trace_error << ", displacement "
              << displacement_error << " relative; " << result.iterations << " active set steps, "
              << result.operator_applications << " CG iterations\n";
  }
}

/// The fields of the other obstacle sequence: after a contact solve (lambda_u) and a correction
/// with r = lambda - lambda_u, displacement(lambda) starts from u - W (K W = B' r), which is
/// already its solution: it equals the direct solver's and takes far fewer conjugate gradient
/// iterations than the same solve from u alone (a second body without the correction).
TEST(MultigridBody, OtherSequenceFieldsStartFromTheLastCorrection) {
  for (const Case& test : cases()) {
    const auto direct = make_solver(test.body, LinearSolverKind::direct);
    const auto corrected = make_solver(test.body, LinearSolverKind::multigrid);
    const auto uncorrected = make_solver(test.body, LinearSolverKind::multigrid);
    const Eigen::VectorXd obstacle = partial_obstacle(*direct);
    const ContactSolveResult solution = corrected->solve_contact(obstacle);
    ASSERT_EQ(solution.status, QpStatus::converged) << test.label << ": " << solution.message;
    ASSERT_EQ(uncorrected->solve_contact(obstacle).status, QpStatus::converged) << test.label;
    Eigen::VectorXd other = 0.8 * solution.contact_force;
    for (Eigen::Index i = 0; i < other.size(); ++i) {
      other[i] += 0.1 * solution.contact_force.maxCoeff() * (1.0 + std::cos(0.7 * i));
    }
    corrected->solve_correction(other - solution.contact_force);
    long before = corrected->inner_iterations();
    const double error =
        relative_difference(corrected->displacement(other), direct->displacement(other));
    const long corrected_iterations = corrected->inner_iterations() - before;
    before = uncorrected->inner_iterations();
    const double uncorrected_error =
        relative_difference(uncorrected->displacement(other), direct->displacement(other));
    const long uncorrected_iterations = uncorrected->inner_iterations() - before;
    EXPECT_LE(error, agreement) << test.label;
    EXPECT_LE(uncorrected_error, agreement) << test.label;
    EXPECT_LE(4 * corrected_iterations, uncorrected_iterations) << test.label;
    std::cout << test.label << ": from u - W " << corrected_iterations << " CG iterations (error "
              << error << "), from u " << uncorrected_iterations << " (error " << uncorrected_error
              << ")\n";
  }
}

TEST(MultigridBody, WarmStartAfterANewObstacleAndLoadFactor) {
  for (const Case& test : cases()) {
    const auto direct = make_solver(test.body, LinearSolverKind::direct);
    const auto multigrid = make_solver(test.body, LinearSolverKind::multigrid);
    const Eigen::VectorXd first = partial_obstacle(*direct);
    ASSERT_EQ(multigrid->solve_contact(first).status, QpStatus::converged) << test.label;
    // more load and an obstacle lowered on one side: rows close and open
    const Eigen::VectorXd second =
        first.cwiseProduct(Eigen::VectorXd::LinSpaced(first.size(), 1.4, 0.8));
    direct->set_load_factor(1.3);
    multigrid->set_load_factor(1.3);
    const ContactSolveResult expected = direct->solve_contact(second);
    const ContactSolveResult result = multigrid->solve_contact(second);
    ASSERT_EQ(result.status, QpStatus::converged) << test.label << ": " << result.message;
    EXPECT_EQ(result.active, expected.active) << test.label;
    EXPECT_LE(relative_difference(result.contact_force, expected.contact_force), agreement)
        << test.label;
    EXPECT_LE(relative_difference(result.normal_trace, expected.normal_trace), agreement)
        << test.label;
    EXPECT_LE(relative_difference(multigrid->displacement(result.contact_force),
                                  direct->displacement(expected.contact_force)),
              agreement)
        << test.label;
  }
}

// Rows u_z(a) for every top node a, then 0.5 u_z(a) + 0.5 u_z(b) for consecutive nodes: the
// second kind are combinations of the first, so B B' is singular and no active set's projection
// exists. The body factorizes K at assign_contact and answers as the direct solver.
TEST(MultigridBody, DependentContactRowsFallBackToTheFactor) {
  const BodyDefinition body = solid_box(ElementType::hexahedron8);
  const std::vector<int> nodes = body.mesh.boundary("top").nodes();
  ContactOperator contact;
  for (int node : nodes) {
    contact.add_entry(node, 2, 1.0);
    contact.finish_row(0.1);
  }
  for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
    contact.add_entry(nodes[i], 2, 0.5);
    contact.add_entry(nodes[i + 1], 2, 0.5);
    contact.finish_row(0.1);
  }
  BodySolverOptions options;
  options.linear_solver = LinearSolverKind::multigrid;
  BodySolver multigrid(body, options);
  BodySolver direct(body);
  EXPECT_EQ(multigrid.linear_solver(), LinearSolverKind::multigrid);
  multigrid.assign_contact(contact);
  direct.assign_contact(contact);
  EXPECT_EQ(multigrid.linear_solver(), LinearSolverKind::direct);
  EXPECT_GT(multigrid.factor_nonzeros(), 0);
  const Eigen::VectorXd obstacle = 0.5 * direct.free_trace();
  const ContactSolveResult expected = direct.solve_contact(obstacle);
  const ContactSolveResult result = multigrid.solve_contact(obstacle);
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;
  // the same dual QP (MPRGP to 1e-12 of ||F|| ||lambda||), F from a factor of another order
  EXPECT_LE(relative_difference(result.normal_trace, expected.normal_trace), 1e-10);
}

TEST(MultigridBody, RefusesAFloatingBody) {
  BodyDefinition body = solid_box(ElementType::hexahedron8);
  body.dirichlet.clear();
  body.body_force = Eigen::Vector3d::Zero();
  body.tractions.clear();
  BodySolverOptions options;
  options.linear_solver = LinearSolverKind::multigrid;
  options.rigid_motions = RigidMotions::held_by_contact;
  try {
    BodySolver solver(body, options);
    FAIL() << "a floating body was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("body 'box'"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("direct"), std::string::npos) << error.what();
  }
}

/// solve_primal_contact itself on the clamped box's contact problem (K and B on the free dofs,
/// the partial obstacle of the file comment from e = B K^{-1} b by CHOLMOD), with the default
/// inexact steps, with every step exact (inexact_steps = 0), and with very loose inexact steps
/// (changing_set_tolerance 0.1) limited to two: each result satisfies the Signorini conditions
/// of the KKT system solved independently by CHOLMOD, u = K^{-1} (b - B' lambda).
TEST(PrimalContact, InexactStepsAndTheirLimitGiveTheSignoriniSolution) {
  const BodyDefinition body = solid_box(ElementType::hexahedron8);
  const Mesh& mesh = body.mesh;
  std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(mesh.dof_count()));
  for (int node : mesh.boundary("bottom").nodes()) {
    for (int component = 0; component < 3; ++component) prescribed[3 * node + component] = 0.0;
  }
  const DofMap dofs(prescribed);
  const SparseMatrix lower = dofs.reduce_matrix_lower(assemble_stiffness(mesh, body.material));
  const Eigen::VectorXd load = dofs.restrict(
      assemble_body_force(mesh, [](const Eigen::Vector3d&) { return Eigen::Vector3d(0, 0, 40); }));
  const ContactOperator contact = top_operator(mesh);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int row = 0; row < contact.row_count(); ++row) {
    for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
      const int dof = 3 * contact.nodes[k] + contact.components[k];
      if (!dofs.is_prescribed(dof))
        triplets.emplace_back(row, dofs.free_index(dof), contact.values[k]);
    }
  }
  SparseMatrix trace(contact.row_count(), dofs.free_count());
  trace.setFromTriplets(triplets.begin(), triplets.end());
  const CholeskyFactor factor(lower, "box");
  const Eigen::VectorXd free_trace = trace * factor.solve(load);
  Eigen::VectorXd bound(contact.row_count());
  for (int row = 0; row < contact.row_count(); ++row) {
    bound[row] = free_trace[row] * (0.3 + 1.2 * mesh.nodes[contact.nodes[row]].x() / 2.0);
  }
  const MultigridStiffnessSolver stiffness(SparseMatrix(lower), free_rigid_body_modes(mesh, dofs),
                                           free_dof_nodes(mesh, dofs), mesh.nodes, 1e-12, "box");
  PrimalContactOptions exact;
  exact.inexact_steps = 0;
  PrimalContactOptions loose;
  loose.changing_set_tolerance = 0.1;
  loose.inexact_steps = 2;
  for (const PrimalContactOptions& options : {PrimalContactOptions{}, exact, loose}) {
    PrimalContactState state;
    const PrimalContactResult result = solve_primal_contact(
        stiffness, trace, load, bound, Eigen::VectorXd::Zero(stiffness.size()), state, options);
    ASSERT_EQ(result.status, QpStatus::converged) << result.message;
    const Eigen::VectorXd& force = result.solution;
    const Eigen::VectorXd contact_load = load - trace.transpose() * force;
    const Eigen::VectorXd gap = bound - trace * factor.solve(contact_load);
    const double scale = bound.lpNorm<Eigen::Infinity>();
    const long closed = (force.array() > 0.0).count();
    EXPECT_GE(closed, 3);
    EXPECT_LE(closed, contact.row_count() - 3);
    EXPECT_GE(force.minCoeff(), 0.0);
    EXPECT_GE(gap.minCoeff(), -1e-9 * scale);  // no penetration
    EXPECT_LE(force.cwiseProduct(gap).cwiseAbs().maxCoeff(),
              1e-9 * scale * force.lpNorm<Eigen::Infinity>());  // complementarity
    std::cout << "changing_set_tolerance " << options.changing_set_tolerance << ", inexact_steps "
              << options.inexact_steps << ": " << closed << " closed, " << result.iterations
              << " active set steps, " << result.operator_applications << " CG iterations\n";
  }
}

}  // namespace
}  // namespace robin
