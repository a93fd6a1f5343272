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

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "numerics/body_solver.hpp"
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
  body.body_force = Eigen::Vector2d(0.0, 40.0);
  body.dirichlet.push_back({"bottom", 0.0, bottom_lift});
  TractionCondition traction;
  traction.boundary = "right";
  traction.vector = Eigen::Vector2d(-4.0, 1.5);
  body.tractions.push_back(traction);
  body.contact_boundary = "top";
  return body;
}

/// Every node of the contact edge with its geometric normal (0, 1), in ascending node order.
ContactAssignment top_assignment(const Mesh& mesh) {
  ContactAssignment assignment;
  assignment.node_ids = mesh.boundary("top").nodes();
  assignment.normals.assign(assignment.node_ids.size(), Eigen::Vector2d(0.0, 1.0));
  return assignment;
}

/// The body reduced to its free dofs and factorized here, independently of BodySolver.
/// S selects the free dofs (free x total), u_p holds the prescribed values:
///   K_ff = S K S',  f_f = S (f - K u_p),  u = u_p + S' u_f,
///   B' lambda = S (sum_i lambda_i n_i at node_i),  (B u)_i = u(node_i) . n_i.
class ReferenceBody {
 public:
  ReferenceBody(const BodyDefinition& body, const ContactAssignment& assignment)
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
        mesh, [&body](const Eigen::Vector2d&) { return Eigen::Vector2d(body.body_force); });
    load += assemble_boundary_traction(mesh, mesh.boundary("right"),
                                       [&body](const Eigen::Vector2d&, const Eigen::Vector2d&) {
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
    for (std::size_t i = 0; i < assignment_.node_ids.size(); ++i) {
      load.segment<2>(2 * assignment_.node_ids[i]) +=
          force[static_cast<Eigen::Index>(i)] * assignment_.normals[i];
    }
    return selection_ * load;
  }

  /// (B u)_i for the full field u = u_p + S' u_f of free values u_f.
  Eigen::VectorXd trace(const Eigen::VectorXd& free_values, bool with_prescribed) const {
    Eigen::VectorXd full = selection_.transpose() * free_values;
    if (with_prescribed) full += prescribed_;
    Eigen::VectorXd result(static_cast<Eigen::Index>(assignment_.node_ids.size()));
    for (std::size_t i = 0; i < assignment_.node_ids.size(); ++i) {
      result[static_cast<Eigen::Index>(i)] =
          full.segment<2>(2 * assignment_.node_ids[i]).dot(assignment_.normals[i]);
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
  ContactAssignment assignment_;
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

std::unique_ptr<BodySolver> make_solver(const OperatorChoice& choice) {
  BodySolverOptions options;
  options.interface_operator = choice.kind;
  options.contact_unknowns_last = choice.contact_unknowns_last;
  auto solver = std::make_unique<BodySolver>(test_body(), options);
  solver->assign_contact(top_assignment(solver->mesh()));
  return solver;
}

double largest(const Eigen::VectorXd& vector) {
  return vector.cwiseAbs().maxCoeff();
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
    const double x = solver.mesh().nodes[solver.contact_nodes()[i]].x();
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

}  // namespace
}  // namespace robin
