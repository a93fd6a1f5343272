// BodySolver's two interface solves against an independent solve of the same body:
//  - correction (paper (11)-(12)): w_N = B K^{-1} B' r for a random interface force r equals
//    the normal trace of w = K^{-1} B' r computed here with Eigen's SimplicialLDLT;
//  - contact (paper (10)): for an obstacle g that closes the middle of the contact edge and
//    leaves its ends open, the returned lambda gives, through the independent solve
//    u = K^{-1} (f - B' lambda), the returned trace u_N = B u, and (u, lambda) satisfies the
//    Signorini conditions lambda >= 0, B u <= g, lambda_i (g_i - (B u)_i) = 0, which for this
//    convex problem are sufficient for the minimum of 1/2 u'Ku - f'u subject to B u <= g.
// K and f come from the project's element assembly (numerics/elasticity.hpp); the Dirichlet
// reduction K_ff, f_f - K_fp u_p, the trace operator B and the factorization are done here.
// Body: [0, 2] x [0, 1], quadratic triangles, clamped bottom with a prescribed lift, upward body
// force and a traction on the right side; contact edge "top" with outward normal (0, 1).
// Every interface operator of BodySolver is checked: dense F from the factor's trailing block,
// dense F by blocked solves, and F applied through the factor.
// The constraint operator B is general (protocol 2.0): besides the node-to-node rows
// (node_to_node_operator, (B u)_i = u(node_i) . n_i), rows that combine two nodes and both
// components (as mortar coupling sends them) are checked against the same independent solve,
// also with a row that touches a prescribed dof (its value enters the trace as B u_p).
// The setup's timings (the profile's stages): finite, non-negative, within the test's own
// measurement of the setup, and the ordering reported apart from the numerical factorization.

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "numerics/body_solver.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

constexpr double bottom_lift = 1e-3;  // prescribed u_y on the bottom edge (length)

/// The test body: 12 x 6 cells of two triangle6, E = 1000, nu = 0.3 (plane strain), body
/// force (0, 40), traction (-4, 1.5) on "right", u = (0, bottom_lift) on "bottom".
BodyDefinition test_body() {
  BodyDefinition body;
  body.name = "block";
  body.mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 12, 6, ElementType::triangle6);
  body.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "block");
  body.body_force = Eigen::Vector3d(0.0, 40.0, 0.0);
  body.dirichlet.push_back({"bottom", 0.0, bottom_lift, std::nullopt});
  TractionCondition traction;
  traction.boundary = "right";
  traction.vector = Eigen::Vector3d(-4.0, 1.5, 0.0);
  body.tractions.push_back(traction);
  body.contact_boundaries = {"top"};
  return body;
}

/// Every node of the contact edge with its geometric normal (0, 1), in ascending node order,
/// as node-to-node rows (weights: the nodes' boundary weights).
ContactOperator top_assignment(const Mesh& mesh) {
  const std::vector<int> nodes = mesh.boundary("top").nodes();
  const Eigen::VectorXd weights = boundary_weights(mesh, mesh.boundary("top"));
  std::vector<double> node_weights;
  for (int node : nodes) node_weights.push_back(weights[node]);
  return node_to_node_operator(nodes, std::vector<Eigen::Vector3d>(nodes.size(), {0.0, 1.0, 0.0}),
                               node_weights);
}

/// A general operator on the nodes of `boundary` (ascending): for each pair of consecutive
/// nodes (a, b) the row 0.5 u_y(a) + 0.5 u_y(b), then every third pair also the row
/// 0.6 u_x(a) - 0.3 u_y(a) + 0.8 u_y(b) (both components of one node, and another node).
ContactOperator two_node_operator(const Mesh& mesh, const std::string& boundary) {
  const std::vector<int> nodes = mesh.boundary(boundary).nodes();
  ContactOperator contact;
  for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
    contact.add_entry(nodes[i], 1, 0.5);
    contact.add_entry(nodes[i + 1], 1, 0.5);
    contact.finish_row(0.1);
    if (i % 3 == 0) {
      contact.add_entry(nodes[i], 0, 0.6);
      contact.add_entry(nodes[i], 1, -0.3);
      contact.add_entry(nodes[i + 1], 1, 0.8);
      contact.finish_row(0.2);
    }
  }
  return contact;
}

/// The body reduced to its free dofs and factorized here, independently of BodySolver.
/// S selects the free dofs (free x total), u_p holds the prescribed values:
///   K_ff = S K S',  f_f = S (f - K u_p),  u = u_p + S' u_f,
///   B' lambda = S (sum_j lambda_j sum_k b_jk e_k),  (B u)_j = sum_k b_jk u_k,
/// with b_jk the entries of the constraint operator over the dofs k = 2 node + component
/// (node-to-node rows: (B u)_i = u(node_i) . n_i).
class ReferenceBody {
 public:
  ReferenceBody(const BodyDefinition& body, const ContactOperator& assignment)
      : assignment_(assignment) {
    const Mesh& mesh = body.mesh;
    const Eigen::Index total = 2 * static_cast<Eigen::Index>(mesh.node_count());
    prescribed_ = Eigen::VectorXd::Zero(total);
    std::vector<bool> fixed(static_cast<std::size_t>(total), false);
    for (int node : mesh.boundary("bottom").nodes()) {
      fixed[2 * node] = fixed[2 * node + 1] = true;
      prescribed_[2 * node + 1] = bottom_lift;
    }
    std::vector<Eigen::Triplet<double>> selection;
    for (Eigen::Index dof = 0; dof < total; ++dof) {
      if (!fixed[static_cast<std::size_t>(dof)]) {
        selection.emplace_back(static_cast<int>(selection.size()), static_cast<int>(dof), 1.0);
      }
    }
    selection_.resize(static_cast<Eigen::Index>(selection.size()), total);
    selection_.setFromTriplets(selection.begin(), selection.end());
    const SparseMatrix stiffness = assemble_stiffness(mesh, body.material);
    Eigen::VectorXd load = assemble_body_force(
        mesh, [&body](const Eigen::Vector3d&) { return Eigen::Vector3d(body.body_force); });
    load += assemble_boundary_traction(mesh, mesh.boundary("right"),
                                       [&body](const Eigen::Vector3d&, const Eigen::Vector3d&) {
                                         return body.tractions[0].vector;
                                       });
    free_load_ = selection_ * (load - stiffness * prescribed_);
    const SparseMatrix free_stiffness =
        selection_ * stiffness * SparseMatrix(selection_.transpose());
    factor_.compute(free_stiffness);
    EXPECT_EQ(factor_.info(), Eigen::Success);
  }

  /// B' lambda on the free dofs.
  Eigen::VectorXd transpose_trace(const Eigen::VectorXd& force) const {
    Eigen::VectorXd load = Eigen::VectorXd::Zero(prescribed_.size());
    for (int row = 0; row < assignment_.row_count(); ++row) {
      for (std::size_t k = assignment_.row_offsets[row]; k < assignment_.row_offsets[row + 1];
           ++k) {
        load[2 * assignment_.nodes[k] + assignment_.components[k]] +=
            force[row] * assignment_.values[k];
      }
    }
    return selection_ * load;
  }

  /// (B u)_j for the full field u = u_p + S' u_f of free values u_f.
  Eigen::VectorXd trace(const Eigen::VectorXd& free_values, bool with_prescribed) const {
    Eigen::VectorXd full = selection_.transpose() * free_values;
    if (with_prescribed) full += prescribed_;
    Eigen::VectorXd result = Eigen::VectorXd::Zero(assignment_.row_count());
    for (int row = 0; row < assignment_.row_count(); ++row) {
      for (std::size_t k = assignment_.row_offsets[row]; k < assignment_.row_offsets[row + 1];
           ++k) {
        result[row] +=
            assignment_.values[k] * full[2 * assignment_.nodes[k] + assignment_.components[k]];
      }
    }
    return result;
  }

  /// w_N = B K^{-1} B' r (homogeneous Dirichlet conditions).
  Eigen::VectorXd correction(const Eigen::VectorXd& force) const {
    return trace(factor_.solve(transpose_trace(force)), false);
  }

  /// u_N = B u with K u = f - B' lambda (prescribed values included).
  Eigen::VectorXd contact_trace(const Eigen::VectorXd& force) const {
    return trace(factor_.solve(Eigen::VectorXd(free_load_ - transpose_trace(force))), true);
  }

 private:
  ContactOperator assignment_;
  SparseMatrix selection_;
  Eigen::VectorXd prescribed_;
  Eigen::VectorXd free_load_;
  Eigen::SimplicialLDLT<SparseMatrix> factor_;
};

struct OperatorChoice {
  InterfaceOperatorKind kind;
  bool contact_unknowns_last;
  std::string label;
};

std::vector<OperatorChoice> operator_choices() {
  return {{InterfaceOperatorKind::dense, true, "dense F from the trailing block"},
          {InterfaceOperatorKind::dense, false, "dense F by blocked solves"},
          {InterfaceOperatorKind::factor, true, "F through the factor"}};
}

std::unique_ptr<BodySolver> make_solver(const OperatorChoice& choice,
                                        const std::string& contact_boundary = "top") {
  BodySolverOptions options;
  options.interface_operator = choice.kind;
  options.contact_unknowns_last = choice.contact_unknowns_last;
  BodyDefinition body = test_body();
  body.contact_boundaries = {contact_boundary};
  auto solver = std::make_unique<BodySolver>(std::move(body), options);
  if (contact_boundary == "top") solver->assign_contact(top_assignment(solver->mesh()));
  return solver;
}

double largest(const Eigen::VectorXd& vector) {
  return vector.cwiseAbs().maxCoeff();
}

TEST(BodySolver, SetupTimingsAreItsStagesWithinTheMeasuredSetup) {
  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  BodyDefinition body = test_body();
  const ContactOperator contact = top_assignment(body.mesh);
  auto start = Clock::now();
  BodySolver solver(std::move(body));
  const double setup_measured = seconds_since(start);
  start = Clock::now();
  solver.assign_contact(contact);
  const double assignment_measured = seconds_since(start);
  const BodyTimings& timings = solver.timings();
  for (const double seconds : {timings.assembly_seconds, timings.ordering_seconds,
                               timings.factorization_seconds, timings.interface_seconds}) {
    EXPECT_TRUE(std::isfinite(seconds) && seconds >= 0.0) << seconds;
  }
  // each stage did work, so a steady clock saw it take time
  EXPECT_GT(timings.assembly_seconds, 0.0);
  EXPECT_GT(timings.ordering_seconds, 0.0);
  EXPECT_GT(timings.factorization_seconds, 0.0);
  EXPECT_DOUBLE_EQ(timings.setup_seconds(), timings.assembly_seconds + timings.ordering_seconds +
                                                timings.factorization_seconds);
  EXPECT_LE(timings.setup_seconds(), setup_measured);
  EXPECT_LE(timings.interface_seconds, assignment_measured);
}

TEST(BodySolver, CorrectionEqualsTheIndependentSolve) {
  const BodyDefinition body = test_body();
  const ReferenceBody reference(body, top_assignment(body.mesh));
  for (const OperatorChoice& choice : operator_choices()) {
    const auto solver = make_solver(choice);
    std::mt19937 generator(7);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    const Eigen::VectorXd force =
        Eigen::VectorXd::NullaryExpr(solver->contact_size(), [&] { return value(generator); });
    const Eigen::VectorXd expected = reference.correction(force);
    const Eigen::VectorXd correction = solver->solve_correction(force);
    ASSERT_EQ(correction.size(), expected.size()) << choice.label;
    EXPECT_GT(largest(expected), 1e-4) << choice.label << ": r must move the boundary";
    const double error = largest(correction - expected) / largest(expected);
    EXPECT_LE(error, 1e-10) << choice.label;
    std::cout << choice.label << ": correction relative error " << error << "\n";
  }
}

/// An obstacle below the free trace e in the middle of the edge and above it at the ends:
/// g_i = e_i (0.4 + 0.8 |x_i - 1|) (e > 0: the body force lifts the edge).
Eigen::VectorXd middle_obstacle(const BodySolver& solver) {
  const Eigen::VectorXd& free_trace = solver.free_trace();
  EXPECT_GT(free_trace.minCoeff(), 0.0) << "the loads must lift the whole contact edge";
  Eigen::VectorXd obstacle(free_trace.size());
  for (int i = 0; i < solver.contact_size(); ++i) {
    const ContactOperator& contact = solver.contact_operator();
    const double x = solver.mesh().nodes[contact.nodes[contact.row_offsets[i]]].x();
    obstacle[i] = free_trace[i] * (0.4 + 0.8 * std::abs(x - 1.0));
  }
  return obstacle;
}

TEST(BodySolver, ContactSolveSatisfiesSignoriniWithTheIndependentSolve) {
  const BodyDefinition body = test_body();
  const ReferenceBody reference(body, top_assignment(body.mesh));
  for (const OperatorChoice& choice : operator_choices()) {
    const auto solver = make_solver(choice);
    const Eigen::VectorXd obstacle = middle_obstacle(*solver);
    const ContactSolveResult result = solver->solve_contact(obstacle);
    ASSERT_EQ(result.status, QpStatus::converged) << choice.label << ": " << result.message;
    const Eigen::VectorXd& force = result.contact_force;
    const int closed = static_cast<int>((force.array() > 0.0).count());
    EXPECT_GE(closed, 3) << choice.label;
    EXPECT_GE(solver->contact_size() - closed, 3) << choice.label;

    // u from the returned lambda, solved here; its trace is the returned u_N.
    const Eigen::VectorXd trace = reference.contact_trace(force);
    const double displacement_scale = std::max(largest(obstacle), largest(trace));
    const double force_scale = largest(force);
    const double trace_error = largest(trace - result.normal_trace) / displacement_scale;
    const Eigen::VectorXd clearance = obstacle - trace;
    const double penetration = std::max(0.0, -clearance.minCoeff());
    const double complementarity =
        largest(force.cwiseProduct(clearance)) / (force_scale * displacement_scale);
    EXPECT_LE(trace_error, 1e-10) << choice.label;
    EXPECT_GE(force.minCoeff(), 0.0) << choice.label;
    EXPECT_LE(penetration, 1e-12) << choice.label;
    EXPECT_LE(complementarity, 1e-10) << choice.label;
    std::cout << choice.label << ": " << closed << " of " << solver->contact_size()
              << " closed, trace error " << trace_error << ", penetration " << penetration
              << " (displacement scale " << displacement_scale << "), complementarity "
              << complementarity << "\n";
  }
}

/// A varying interface force of the size of the operator's rows (deterministic).
Eigen::VectorXd varying_force(Eigen::Index size) {
  Eigen::VectorXd force(size);
  for (Eigen::Index i = 0; i < size; ++i) {
    force[i] = 1.0 + 0.5 * std::cos(1.3 * static_cast<double>(i));
  }
  return force;
}

// Issue 11 (g): a general B, whose rows combine two nodes (0.5 u_y(a) + 0.5 u_y(b)) and both
// components of a node, gives the Neumann solve u_N = B K^{-1}(f - B' lambda) + B u_p and the
// correction w_N = B K^{-1} B' r of the independent solve, to 1e-12 relative, with every
// interface operator. On "right" the first row touches the bottom-right corner, whose u_x and
// u_y are prescribed (u_y = bottom_lift): the prescribed value enters the trace.
TEST(BodySolver, GeneralOperatorEqualsTheIndependentSolve) {
  for (const std::string boundary : {"top", "right"}) {
    BodyDefinition body = test_body();
    body.contact_boundaries = {boundary};
    const ContactOperator contact = two_node_operator(body.mesh, boundary);
    const ReferenceBody reference(body, contact);
    if (boundary == "right") {
      // The corner (2, 0) is the first node of "right" in ascending order and is prescribed.
      const int corner = contact.nodes[0];
      ASSERT_EQ(body.mesh.nodes[corner], Eigen::Vector3d(2.0, 0.0, 0.0));
    }
    for (const OperatorChoice& choice : operator_choices()) {
      const std::string label = choice.label + " on '" + boundary + "'";
      const auto solver = make_solver(choice, boundary);
      solver->assign_contact(contact);
      ASSERT_EQ(solver->contact_size(), contact.row_count()) << label;

      const Eigen::VectorXd force = varying_force(contact.row_count());
      const Eigen::VectorXd expected_correction = reference.correction(force);
      EXPECT_GT(largest(expected_correction), 1e-4) << label << ": r must move the boundary";
      const double correction_error =
          largest(solver->solve_correction(force) - expected_correction) /
          largest(expected_correction);
      EXPECT_LE(correction_error, 1e-12) << label;

      const Eigen::VectorXd expected_neumann = reference.contact_trace(force);
      const double neumann_error =
          largest(solver->solve_neumann(force) - expected_neumann) / largest(expected_neumann);
      EXPECT_LE(neumann_error, 1e-12) << label;

      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(contact.row_count());
      const Eigen::VectorXd expected_free = reference.contact_trace(zero);
      const double free_error =
          largest(solver->free_trace() - expected_free) / largest(expected_free);
      EXPECT_LE(free_error, 1e-12) << label;
      if (boundary == "right") {
        // Row 0 = 0.5 u_y(corner) + 0.5 u_y(next): the prescribed half is bottom_lift / 2.
        EXPECT_GT(std::abs(expected_free[0]), 0.25 * bottom_lift) << label;
      }
      std::cout << label << ": correction " << correction_error << ", Neumann " << neumann_error
                << ", free trace " << free_error << " relative error\n";

      // The contact force field is -B' lambda, entry by entry.
      const Eigen::VectorXd field = solver->contact_force_field(force);
      Eigen::VectorXd expected_field = Eigen::VectorXd::Zero(field.size());
      for (int row = 0; row < contact.row_count(); ++row) {
        for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
          expected_field[2 * contact.nodes[k] + contact.components[k]] -=
              contact.values[k] * force[row];
        }
      }
      EXPECT_LE(largest(field - expected_field), 1e-15 * largest(expected_field)) << label;
    }
  }
}

// Issue 11 (g): node_to_node_operator gives the node-to-node B of protocol 1.x, one row
// (n_x at (node, x), n_y at (node, y)) per node in the given order with the given weights, and
// BodySolver with it gives the trace, correction and Neumann solve of the 1.x definition
// (B u)_i = u(node_i) . n_i computed independently here, to 1e-12, for tilted unit normals, the
// nodes in reversed order and on the boundary "right" whose first node is prescribed.
TEST(BodySolver, NodeToNodeOperatorIsTheNodeNormalTrace) {
  BodyDefinition body = test_body();
  body.contact_boundaries = {"right"};
  std::vector<int> nodes = body.mesh.boundary("right").nodes();
  std::reverse(nodes.begin(), nodes.end());
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> weights;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double angle = 0.1 * static_cast<double>(i) - 0.4;
    normals.emplace_back(std::cos(angle), std::sin(angle), 0.0);
    weights.push_back(0.5 + static_cast<double>(i));
  }
  const ContactOperator contact = node_to_node_operator(nodes, normals, weights);
  ASSERT_EQ(contact.row_count(), static_cast<int>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    ASSERT_EQ(contact.row_offsets[i], 2 * i);
    EXPECT_EQ(contact.nodes[2 * i], nodes[i]);
    EXPECT_EQ(contact.nodes[2 * i + 1], nodes[i]);
    EXPECT_EQ(contact.components[2 * i], 0);
    EXPECT_EQ(contact.components[2 * i + 1], 1);
    EXPECT_EQ(contact.values[2 * i], normals[i].x());
    EXPECT_EQ(contact.values[2 * i + 1], normals[i].y());
    EXPECT_EQ(contact.weights[i], weights[i]);
  }
  EXPECT_EQ(contact.row_offsets.back(), 2 * nodes.size());

  // The 1.x trace, written with the normals: u_N,i = u(node_i) . n_i, on a full field.
  const auto node_normal_trace = [&](const Eigen::VectorXd& full) {
    Eigen::VectorXd trace(static_cast<Eigen::Index>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      trace[static_cast<Eigen::Index>(i)] = full.segment<2>(2 * nodes[i]).dot(normals[i].head<2>());
    }
    return trace;
  };
  for (const OperatorChoice& choice : operator_choices()) {
    const auto solver = make_solver(choice, "right");
    solver->assign_contact(contact);
    const Eigen::VectorXd force = varying_force(solver->contact_size());
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(solver->contact_size());
    const Eigen::VectorXd expected_free = node_normal_trace(solver->displacement(zero));
    const Eigen::VectorXd expected_neumann = node_normal_trace(solver->displacement(force));
    EXPECT_LE(largest(solver->free_trace() - expected_free), 1e-12 * largest(expected_free))
        << choice.label;
    EXPECT_LE(largest(solver->solve_neumann(force) - expected_neumann),
              1e-12 * largest(expected_neumann))
        << choice.label;
    // The contact force field of the 1.x code: -lambda_i n_i at node i.
    Eigen::VectorXd expected_field = Eigen::VectorXd::Zero(2 * body.mesh.node_count());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      expected_field.segment<2>(2 * nodes[i]) -=
          force[static_cast<Eigen::Index>(i)] * normals[i].head<2>();
    }
    EXPECT_LE(largest(solver->contact_force_field(force) - expected_field),
              1e-15 * largest(expected_field))
        << choice.label;
  }
}

}  // namespace
}  // namespace robin
