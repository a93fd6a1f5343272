// BodySolver with a floating body (body_solver.hpp, "Floating bodies") against an independent
// solve of the same body: a block with u_x = 0 on its left and right sides (its vertical
// translation free) under gravity, resting on a rigid flat obstacle at its bottom (node-to-node
// rows, normal (0, -1), obstacle 0). Every row is in contact, so the answer is that of the same
// block with u_y = 0 prescribed on its bottom, an ordinary body factorized by CHOLMOD alone:
// the contact forces are its bottom reactions, the displacement field is its displacement, and
// the trace is zero. The floating solve goes through K^+, SMALBE-M and the rigid amplitude.

#include <gtest/gtest.h>

#include "numerics/body_solver.hpp"
#include "numerics/errors.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"

namespace robin {
namespace {

BodyDefinition block(bool supported_bottom) {
  BodyDefinition body;
  body.name = "block";
  body.mesh = make_rectangle_mesh(0.0, 0.0, 2.0, 1.0, 8, 4, ElementType::quadrilateral4);
  body.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "block");
  body.dirichlet.push_back({"left", 0.0, std::nullopt, std::nullopt});
  body.dirichlet.push_back({"right", 0.0, std::nullopt, std::nullopt});
  if (supported_bottom) body.dirichlet.push_back({"bottom", std::nullopt, 0.0, std::nullopt});
  body.body_force = Eigen::Vector3d(0.0, -3.0, 0.0);
  body.contact_boundaries.push_back(supported_bottom ? "top" : "bottom");
  return body;
}

TEST(FloatingBodySolver, RestingOnARigidObstacleEqualsTheSupportedBody) {
  BodySolverOptions options;
  options.rigid_motions = RigidMotions::held_by_contact;
  BodySolver floating(block(false), options);
  ASSERT_EQ(floating.rigid_mode_count(), 1);
  const std::vector<int> nodes = floating.mesh().boundary("bottom").nodes();
  const std::vector<Eigen::Vector3d> normals(nodes.size(), Eigen::Vector3d(0.0, -1.0, 0.0));
  const std::vector<double> weights(nodes.size(), 1.0);
  floating.assign_contact(node_to_node_operator(nodes, normals, weights));
  MprgpParameters parameters;
  parameters.relative_tolerance = 1e-13;
  const ContactSolveResult result = floating.solve_contact(
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nodes.size())), parameters);
  ASSERT_EQ(result.status, QpStatus::converged) << result.message;

  const BodySolver supported(block(true));  // an ordinary body (k = 0)
  ASSERT_EQ(supported.rigid_mode_count(), 0);
  const Eigen::VectorXd displacement = supported.displacement(Eigen::VectorXd());
  const Eigen::VectorXd reactions = supported.reactions(displacement);
  const double weight = 3.0 * 2.0;
  double force_scale = 0.0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    force_scale = std::max(force_scale, reactions[2 * nodes[i] + 1]);
  }
  ASSERT_GT(force_scale, 0.0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    // the obstacle pushes up: lambda_i = the upward reaction at node i
    EXPECT_NEAR(result.contact_force[static_cast<Eigen::Index>(i)], reactions[2 * nodes[i] + 1],
                1e-10 * force_scale)
        << "node " << nodes[i];
    EXPECT_NEAR(result.normal_trace[static_cast<Eigen::Index>(i)], 0.0,
                1e-10 * displacement.lpNorm<Eigen::Infinity>());
  }
  EXPECT_NEAR(result.contact_force.sum(), weight, 1e-11 * weight);
  const Eigen::VectorXd floating_displacement = floating.displacement(result.contact_force);
  EXPECT_LE((floating_displacement - displacement).lpNorm<Eigen::Infinity>(),
            1e-10 * displacement.lpNorm<Eigen::Infinity>());
  // K u = f - B' lambda has no solution for an unbalanced lambda: the Neumann solve is refused.
  EXPECT_THROW(floating.solve_neumann(result.contact_force), SingularBodyError);
}

}  // namespace
}  // namespace robin
