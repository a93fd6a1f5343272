// BodySolver::solve_neumann (the Neumann solve of the Dirichlet-Neumann iteration, protocol
// 1.1): u_N = B K^{-1} (f - B' lambda) + B u_p, computed as e - F lambda, against the normal
// trace of the full displacement u(lambda) = BodySolver::displacement (one solve with the factor,
// prescribed values included) taken with the assigned normals, u_N,i = u(node_i) . n_i.
// Bodies: both blocks of examples/two_blocks.toml (the lower one clamped, the upper one with a
// prescribed top displacement), with a body force and a traction added so that every kind of
// load enters f; the dense F (from the factor's trailing block, or by blocked solves) and F
// applied through the factor; the contact nodes in reversed order and,
// for the upper block, with flipped normals (as body 2 receives n2 = -n1).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "coupling/case_file.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/contact_operator.hpp"

namespace robin {
namespace {

CaseDefinition two_blocks() {
  return read_case_file(std::filesystem::path(ROBIN_EXAMPLES) / "two_blocks.toml");
}

/// The body of `body_case` with a body force and a traction on its "right" side added.
BodyDefinition loaded_body(const BodyCase& body_case) {
  // load_body reads the mesh (the case file leaves definition.mesh empty until then).
  BodyDefinition definition = load_body(body_case);
  definition.body_force = Eigen::Vector3d(3.0, -20.0, 0.0);
  TractionCondition traction;
  traction.boundary = "right";
  traction.vector = Eigen::Vector3d(-4.0, 1.5, 0.0);
  definition.tractions.push_back(traction);
  return definition;
}

/// Contact nodes with the normal to use at each (pair order), as the 1.x assignment held them.
struct NodeNormals {
  std::vector<int> node_ids;
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> weights;
};

/// Every contact boundary node, in descending id order, with `sign` times its geometric normal.
NodeNormals reversed_assignment(const InterfaceDescription& boundary, double sign) {
  NodeNormals assignment;
  for (std::size_t k = boundary.node_ids.size(); k-- > 0;) {
    assignment.node_ids.push_back(boundary.node_ids[k]);
    assignment.normals.push_back(sign * boundary.normals[k]);
    assignment.weights.push_back(boundary.weights[k]);
  }
  return assignment;
}

/// u(node_i) . n_i of a full displacement vector (2 values per node).
Eigen::VectorXd normal_trace(const Eigen::VectorXd& displacement, const NodeNormals& assignment) {
  Eigen::VectorXd trace(static_cast<Eigen::Index>(assignment.node_ids.size()));
  for (std::size_t i = 0; i < assignment.node_ids.size(); ++i) {
    const int node = assignment.node_ids[i];
    trace[static_cast<Eigen::Index>(i)] =
        displacement.segment<2>(2 * node).dot(assignment.normals[i].head<2>());
  }
  return trace;
}

/// A compressive contact force varying along the pair order, about the size of the
/// two-block contact forces (E = 1000, 1 % strain, 21 nodes on a length-2 edge: about 1 each).
Eigen::VectorXd varying_force(Eigen::Index size) {
  Eigen::VectorXd force(size);
  for (Eigen::Index i = 0; i < size; ++i)
    force[i] = 1.0 + 0.5 * std::cos(1.3 * static_cast<double>(i));
  return force;
}

double largest(const Eigen::VectorXd& vector) {
  return vector.cwiseAbs().maxCoeff();
}

TEST(NeumannSolve, EqualsTheNormalTraceOfTheDisplacement) {
  const CaseDefinition definition = two_blocks();
  for (int alpha = 0; alpha < 2; ++alpha) {
    const BodyDefinition body_definition = loaded_body(definition.bodies[alpha]);
    for (const auto& [kind, contact_last] : {std::pair{InterfaceOperatorKind::dense, true},
                                             std::pair{InterfaceOperatorKind::dense, false},
                                             std::pair{InterfaceOperatorKind::factor, true}}) {
      BodySolverOptions options;
      options.interface_operator = kind;
      options.contact_unknowns_last = contact_last;
      BodySolver body(body_definition, options);
      const NodeNormals assignment =
          reversed_assignment(body.contact_boundary(), alpha == 0 ? 1.0 : -1.0);
      body.assign_contact(
          node_to_node_operator(assignment.node_ids, assignment.normals, assignment.weights));
      const Eigen::VectorXd force = varying_force(body.contact_size());
      const std::string label =
          body.name() + (kind == InterfaceOperatorKind::factor ? " (F through the factor)"
                         : contact_last ? " (dense F from the trailing block)"
                                        : " (dense F by blocked solves)");

      const Eigen::VectorXd trace = body.solve_neumann(force);
      const Eigen::VectorXd expected = normal_trace(body.displacement(force), assignment);
      ASSERT_EQ(trace.size(), expected.size()) << label;
      EXPECT_GT(largest(expected), 1e-4) << label << ": the forces must move the boundary";
      EXPECT_LE(largest(trace - expected), 1e-12 * largest(expected)) << label;

      // lambda = 0: the body's own loads only, u_N = e, the trace of u(0).
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(body.contact_size());
      const Eigen::VectorXd free = normal_trace(body.displacement(zero), assignment);
      EXPECT_GT(largest(free), 1e-4) << label << ": the loads must move the boundary";
      EXPECT_LE(largest(body.solve_neumann(zero) - free), 1e-12 * largest(free)) << label;

      // Compression pushes the boundary inward: u_N(lambda) < u_N(0) where only node i is
      // loaded (F has a positive diagonal).
      Eigen::VectorXd single = zero;
      single[3] = 1.0;
      EXPECT_LT(body.solve_neumann(single)[3], free[3]) << label;
    }
  }
}

}  // namespace
}  // namespace robin
