// A body's factor kept for a later run of the same body (BodySolver::has_same_stiffness and
// replace_loads; robin-subdomain keeps the previous run's body for this):
//  - with other loads and prescribed values (body force, traction, bottom lift), the kept
//    factor gives the free trace e, the contact solve (lambda and u_N), the correction
//    w_N = F r and the displacement field of a BodySolver set up from scratch for the new
//    loads, to 1e-12 relative, for each interface operator;
//  - replace_loads costs one solve with the kept factor (K^{-1} f), and assign_contact with the
//    same B none: e = B K^{-1} f + B u_p reuses it and F is kept (building F by blocked solves
//    takes one solve per block of constraints);
//  - a change of material, of one node's position, of the prescribed degrees of freedom, of
//    the contact boundary or of the factor options is a different stiffness; a change of name,
//    loads or prescribed values is not.

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "numerics/body_solver.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

/// [0, 2] x [0, 1] in 12 x 6 cells of two triangle6, E = 1000, nu = 0.3 (plane strain),
/// clamped bottom lifted by `lift`, body force `body_force`, traction `traction` on "right",
/// contact boundary "top".
BodyDefinition loaded_block(double lift, const Eigen::Vector2d& body_force,
                            const Eigen::Vector2d& traction) {
  BodyDefinition body;
  body.name = "block";
  body.mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 12, 6, ElementType::triangle6);
  body.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "block");
  body.body_force << body_force, 0.0;
  body.dirichlet.push_back({"bottom", 0.0, lift, std::nullopt});
  TractionCondition condition;
  condition.boundary = "right";
  condition.vector << traction, 0.0;
  body.tractions.push_back(condition);
  body.contact_boundaries = {"top"};
  return body;
}

BodyDefinition first_loads() {
  return loaded_block(1e-3, {0.0, 40.0}, {-4.0, 1.5});
}

BodyDefinition second_loads() {
  return loaded_block(2.5e-3, {3.0, 25.0}, {6.0, -2.0});
}

/// Node-to-node rows on every node of "top" with normal (0, 1), weights 1.
ContactOperator top_rows(const Mesh& mesh) {
  const std::vector<int> nodes = mesh.boundary("top").nodes();
  return node_to_node_operator(nodes, std::vector<Eigen::Vector3d>(nodes.size(), {0.0, 1.0, 0.0}),
                               std::vector<double>(nodes.size(), 1.0));
}

/// An obstacle that closes the middle of the top edge and leaves its ends open.
Eigen::VectorXd middle_obstacle(const Eigen::VectorXd& free_trace) {
  Eigen::VectorXd obstacle = free_trace;
  const Eigen::Index size = obstacle.size();
  for (Eigen::Index i = 0; i < size; ++i) {
    const bool middle = i > size / 4 && i < 3 * size / 4;
    obstacle[i] += middle ? -2e-3 : 5e-3;
  }
  return obstacle;
}

::testing::AssertionResult close(const Eigen::VectorXd& value, const Eigen::VectorXd& reference) {
  if (value.size() != reference.size()) {
    return ::testing::AssertionFailure() << "sizes " << value.size() << ", " << reference.size();
  }
  const double scale = std::max(reference.lpNorm<Eigen::Infinity>(), 1e-300);
  const double difference = (value - reference).lpNorm<Eigen::Infinity>();
  if (difference <= 1e-12 * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "difference " << difference << " at scale " << scale;
}

BodySolverOptions options_for(InterfaceOperatorKind kind, bool contact_unknowns_last) {
  BodySolverOptions options;
  options.interface_operator = kind;
  options.contact_unknowns_last = contact_unknowns_last;
  return options;
}

TEST(BodyReuse, TheKeptFactorAnswersAsAFreshSetupForOtherLoads) {
  for (const auto& [kind, last] : {std::pair{InterfaceOperatorKind::dense, true},
                                   std::pair{InterfaceOperatorKind::dense, false},
                                   std::pair{InterfaceOperatorKind::factor, true}}) {
    SCOPED_TRACE(testing::Message() << "operator " << static_cast<int>(kind) << ", last " << last);
    const BodySolverOptions options = options_for(kind, last);
    BodySolver kept(first_loads(), options);
    const ContactOperator rows = top_rows(kept.mesh());
    kept.assign_contact(rows);
    (void)kept.solve_contact(middle_obstacle(kept.free_trace()));  // a first run's solve

    ASSERT_TRUE(kept.has_same_stiffness(second_loads(), options));
    kept.replace_loads(second_loads(), options);
    kept.assign_contact(rows);
    BodySolver fresh(second_loads(), options);
    fresh.assign_contact(rows);

    EXPECT_TRUE(close(kept.free_trace(), fresh.free_trace()));
    const Eigen::VectorXd obstacle = middle_obstacle(fresh.free_trace());
    const ContactSolveResult reused = kept.solve_contact(obstacle);
    const ContactSolveResult reference = fresh.solve_contact(obstacle);
    EXPECT_GT(reference.contact_force.maxCoeff(), 0.0);
    EXPECT_TRUE(close(reused.contact_force, reference.contact_force));
    EXPECT_TRUE(close(reused.normal_trace, reference.normal_trace));
    const Eigen::VectorXd force = Eigen::VectorXd::LinSpaced(rows.row_count(), 1.0, -0.5);
    EXPECT_TRUE(close(kept.solve_correction(force), fresh.solve_correction(force)));
    EXPECT_TRUE(close(kept.displacement(reference.contact_force),
                      fresh.displacement(reference.contact_force)));
    EXPECT_TRUE(close(kept.reactions(kept.displacement(reference.contact_force)),
                      fresh.reactions(fresh.displacement(reference.contact_force))));
  }
}

TEST(BodyReuse, ReplacingLoadsAndAssigningTheSameRowsCostOneSolve) {
  const BodySolverOptions options = options_for(InterfaceOperatorKind::dense, false);
  BodySolver body(first_loads(), options);
  const ContactOperator rows = top_rows(body.mesh());
  const long before_first_assignment = body.solve_count();
  body.assign_contact(rows);
  // Building F by blocked solves takes solves of every constraint (and e one more).
  ASSERT_GE(body.solve_count() - before_first_assignment, 2);
  const long before = body.solve_count();
  body.replace_loads(second_loads(), options);
  body.assign_contact(rows);
  EXPECT_EQ(body.solve_count() - before, 1);  // K^{-1} f; e = B K^{-1} f + B u_p reuses it
}

TEST(BodyReuse, OnlyLoadsNameAndPrescribedValuesMayChange) {
  const BodySolverOptions options = options_for(InterfaceOperatorKind::automatic, true);
  const BodySolver body(first_loads(), options);

  BodyDefinition renamed = second_loads();
  renamed.name = "other";
  EXPECT_TRUE(body.has_same_stiffness(renamed, options));

  BodyDefinition softer = first_loads();
  softer.material = make_isotropic_material(999.0, 0.3, PlaneModel::plane_strain, "block");
  EXPECT_FALSE(body.has_same_stiffness(softer, options));

  BodyDefinition moved = first_loads();
  moved.mesh.nodes[7].x() += 1e-9;
  EXPECT_FALSE(body.has_same_stiffness(moved, options));

  BodyDefinition sliding = first_loads();
  sliding.dirichlet[0].x.reset();  // u_x no longer prescribed on the bottom
  sliding.dirichlet.push_back({"left", 0.0, std::nullopt, std::nullopt});
  EXPECT_FALSE(body.has_same_stiffness(sliding, options));

  BodyDefinition other_contact = first_loads();
  other_contact.contact_boundaries = {"right"};
  EXPECT_FALSE(body.has_same_stiffness(other_contact, options));

  EXPECT_FALSE(
      body.has_same_stiffness(first_loads(), options_for(InterfaceOperatorKind::factor, true)));
}

}  // namespace
}  // namespace robin
