// The Robin iteration on a contact graph of three bodies (coupling/contact_graph.hpp): a row of
// three unit blocks along x, each clamped at its bottom, the outer two pushed towards the middle
// one by a pressure on their outer faces. The middle block has two contact boundaries, one per
// neighbour, so its constraint operator stacks the rows of both interfaces.
// Checked against numbers from outside the iteration:
//  - the monolithic reference of the same graph (one dual QP over both interfaces): the Robin
//    fixed point equals it to 1e-8 relative, contact forces and traces of every body;
//  - that reference itself satisfies the Signorini conditions computed from the bodies'
//    displacement fields (not from the dual): no penetration, lambda >= 0, complementarity;
//  - mirror symmetry: with equal materials the row is symmetric about x = 1.5 (structured
//    meshes), so both interfaces carry the same contact force at the same height;
//  - with a middle block 100 times stiffer (an asymmetric graph) the iteration still equals the
//    monolithic answer.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "coupling/contact_graph.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/graph_coupling.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/robin_iteration.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

const std::filesystem::path data = ROBIN_TEST_DATA;

BodyDefinition row_block(const std::string& side, double young) {
  BodyDefinition body;
  body.name = side;
  body.mesh = read_gmsh_mesh(data / ("row_block_" + side + ".geo"), {0.0625, 1, false});
  body.material = make_isotropic_material(young, 0.3, PlaneModel::plane_strain, side);
  body.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  const double pressure = 1.0;
  if (side == "left") body.tractions.push_back({"left", true, Eigen::Vector3d::Zero(), pressure});
  if (side == "right") {
    body.tractions.push_back({"right", true, Eigen::Vector3d::Zero(), pressure});
  }
  if (side != "right") body.contact_boundaries.push_back("right");
  if (side != "left") body.contact_boundaries.push_back("left");
  return body;
}

/// The row's bodies, their interfaces and the graph: interface 0 joins the left block (side a,
/// its "right" boundary) and the middle block (side b, "left"); interface 1 the middle block
/// (side a, "right") and the right block (side b, "left").
struct Row {
  std::vector<BodyDefinition> definitions;
  std::vector<ContactPairing> pairings;
  std::vector<ContactOperator> operators;  // per body, body order
  CouplingProblem problem;
};

Row make_row(double middle_young) {
  Row row;
  for (const std::string side : {"left", "middle", "right"}) {
    row.definitions.push_back(row_block(side, side == "middle" ? middle_young : 1000.0));
  }
  std::vector<InterfaceDescription> interfaces;
  std::vector<std::string> names;
  for (const BodyDefinition& definition : row.definitions) {
    interfaces.push_back(BodySolver(definition).contact_boundary());
    names.push_back(definition.name);
  }
  ContactOptions contact;
  contact.method = ContactMethod::node_to_node;
  GraphCoupling coupling =
      couple_contact_graph(interfaces, names, {{0, 1, "right", "left"}, {1, 2, "right", "left"}},
                           nullptr, contact, 1e-6);
  row.pairings = std::move(coupling.pairings);
  row.operators = std::move(coupling.operators);
  row.problem = std::move(coupling.problem);
  return row;
}

double relative_difference(const Eigen::VectorXd& value, const Eigen::VectorXd& reference) {
  return (value - reference).lpNorm<Eigen::Infinity>() /
         std::max(reference.lpNorm<Eigen::Infinity>(), 1e-300);
}

struct MonolithicRow {
  std::vector<std::unique_ptr<BodySolver>> bodies;
  MonolithicResult result;
};

MonolithicRow solve_monolithic_row(const Row& row) {
  MonolithicRow reference;
  std::vector<const BodySolver*> pointers;
  for (std::size_t body = 0; body < row.definitions.size(); ++body) {
    reference.bodies.push_back(std::make_unique<BodySolver>(row.definitions[body]));
    reference.bodies.back()->assign_contact(row.operators[body]);
    pointers.push_back(reference.bodies.back().get());
  }
  MprgpParameters parameters;
  parameters.relative_tolerance = 1e-12;
  reference.result = solve_monolithic(pointers, row.problem.graph, row.problem.gaps, parameters);
  return reference;
}

RobinResult run_row(const Row& row, AccelerationMethod acceleration) {
  std::vector<InProcessPort> ports(row.definitions.size());
  std::vector<SubdomainPort*> pointers;
  SolverOptions solver;
  solver.qp.relative_tolerance = 1e-12;
  for (std::size_t body = 0; body < ports.size(); ++body) {
    BodyCase body_case;
    body_case.definition = row.definitions[body];
    ports[body].setup(body_case, solver);
    ports[body].assign_contact(row.operators[body]);
    pointers.push_back(&ports[body]);
  }
  CouplingOptions options;
  options.acceleration.method = acceleration;
  options.tolerance = 1e-9;  // the QP tolerance (1e-12) limits the stiff row near 3e-10
  options.max_iterations = 500;
  return run_robin_iteration(pointers, row.problem, options, nullptr, {});
}

/// The Robin state of every body equals the monolithic one (forces and traces, body order).
void expect_equals_monolithic(const RobinResult& robin, const Row& row,
                              const MonolithicResult& monolithic) {
  ASSERT_EQ(robin.state.bodies.size(), 3u);
  for (int body = 0; body < 3; ++body) {
    const BodyInterfaceState& state = robin.state.bodies[static_cast<std::size_t>(body)];
    const Eigen::VectorXd force = row.problem.graph.body_part(body, monolithic.contact_force);
    EXPECT_LE(relative_difference(state.contact_force, force), 1e-8) << "body " << body + 1;
    EXPECT_LE(relative_difference(state.normal_trace,
                                  monolithic.normal_traces[static_cast<std::size_t>(body)]),
              1e-8)
        << "body " << body + 1;
  }
}

TEST(ManyBodies, RowOfThreeBlocksEqualsTheMonolithicContactGraphSolution) {
  const Row row = make_row(1000.0);
  const MonolithicRow reference = solve_monolithic_row(row);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged);
  for (const AccelerationMethod acceleration :
       {AccelerationMethod::iqn_ils, AccelerationMethod::none}) {
    const RobinResult robin = run_row(row, acceleration);
    std::printf("row of three blocks, %s: %s after %zu iterations (%s)\n",
                to_string(acceleration).c_str(), to_string(robin.status).c_str(),
                robin.history.size(), robin.message.c_str());
    ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
    expect_equals_monolithic(robin, row, reference.result);
  }
}

TEST(ManyBodies, MonolithicReferenceSatisfiesSignoriniFromTheDisplacementFields) {
  const Row row = make_row(1000.0);
  const MonolithicRow reference = solve_monolithic_row(row);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged);
  const Eigen::VectorXd& force = reference.result.contact_force;
  std::vector<Eigen::VectorXd> displacements;
  for (int body = 0; body < 3; ++body) {
    displacements.push_back(reference.bodies[static_cast<std::size_t>(body)]->displacement(
        row.problem.graph.body_part(body, force)));
  }
  const double largest_force = force.maxCoeff();
  ASSERT_GT(largest_force, 0.0);
  // Per row: the clearance d - (u_a - u_b) . n from the displacement fields at the paired nodes.
  std::vector<double> clearances;
  double displacement_scale = 0.0;
  for (int interface = 0; interface < 2; ++interface) {
    for (const ContactPair& pair : row.pairings[static_cast<std::size_t>(interface)].pairs) {
      const Eigen::Vector2d u_a =
          displacements[static_cast<std::size_t>(interface)].segment<2>(2 * pair.node1);
      const Eigen::Vector2d u_b =
          displacements[static_cast<std::size_t>(interface) + 1].segment<2>(2 * pair.node2);
      clearances.push_back(pair.gap - (u_a - u_b).dot(pair.normal.head<2>()));
      displacement_scale = std::max({displacement_scale, u_a.norm(), u_b.norm()});
    }
  }
  ASSERT_EQ(static_cast<Eigen::Index>(clearances.size()), force.size());
  int closed = 0;
  for (Eigen::Index index = 0; index < force.size(); ++index) {
    const double clearance = clearances[static_cast<std::size_t>(index)];
    EXPECT_GE(force[index], 0.0) << "row " << index;
    EXPECT_GE(clearance, -1e-8 * displacement_scale) << "row " << index;
    EXPECT_LE(std::abs(force[index] * clearance), 1e-8 * largest_force * displacement_scale)
        << "row " << index;
    if (force[index] > 1e-6 * largest_force) ++closed;
  }
  EXPECT_GT(closed, 4);  // a real contact state on both interfaces
}

TEST(ManyBodies, EqualBlocksCarryMirrorSymmetricForcesOnBothInterfaces) {
  const Row row = make_row(1000.0);
  const RobinResult robin = run_row(row, AccelerationMethod::iqn_ils);
  ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
  // The middle block's rows: interface 0's (its left edge), then interface 1's (its right edge).
  const Eigen::VectorXd& middle = robin.state.bodies[1].contact_force;
  const std::vector<ContactPair>& left_pairs = row.pairings[0].pairs;
  const std::vector<ContactPair>& right_pairs = row.pairings[1].pairs;
  ASSERT_EQ(left_pairs.size(), right_pairs.size());
  const double scale = middle.lpNorm<Eigen::Infinity>();
  for (std::size_t i = 0; i < left_pairs.size(); ++i) {
    std::size_t mirror = right_pairs.size();
    for (std::size_t j = 0; j < right_pairs.size(); ++j) {
      if (std::abs(right_pairs[j].position.y() - left_pairs[i].position.y()) < 1e-12) mirror = j;
    }
    ASSERT_LT(mirror, right_pairs.size()) << "no pair at height " << left_pairs[i].position.y();
    EXPECT_NEAR(middle[static_cast<Eigen::Index>(i)],
                middle[static_cast<Eigen::Index>(left_pairs.size() + mirror)], 1e-8 * scale)
        << "height " << left_pairs[i].position.y();
  }
}

TEST(ManyBodies, StiffMiddleBlockStillEqualsTheMonolithicSolution) {
  const Row row = make_row(100000.0);
  const MonolithicRow reference = solve_monolithic_row(row);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged);
  const RobinResult robin = run_row(row, AccelerationMethod::iqn_ils);
  std::printf("row with a middle block 100 times stiffer: %s after %zu iterations (%s)\n",
              to_string(robin.status).c_str(), robin.history.size(), robin.message.c_str());
  ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
  expect_equals_monolithic(robin, row, reference.result);
}

/// Two equal blocks [0, 1] and [1, 2] pressed together by equal pressures on their outer faces:
/// mirror symmetric about x = 1, so the contact interface does not move (u_N is round-off and
/// d = 0). The residuals' displacement scale then comes from the interface compliance times the
/// contact force (robin_iteration.cpp, force_displacement); before that floor every residual
/// was round-off over round-off and a converged state was reported as diverged.
TEST(ManyBodies, SymmetricPairWhoseInterfaceDoesNotMoveConverges) {
  BodyDefinition left = row_block("left", 1000.0);
  BodyDefinition right = row_block("middle", 1000.0);
  right.contact_boundaries = {"left"};
  right.tractions.push_back({"right", true, Eigen::Vector3d::Zero(), 1.0});
  Row row;
  row.definitions = {left, right};
  ContactOptions contact;
  contact.method = ContactMethod::node_to_node;
  GraphCoupling coupling = couple_contact_graph(
      {BodySolver(left).contact_boundary(), BodySolver(right).contact_boundary()},
      {"left", "right"}, {{0, 1, "right", "left"}}, nullptr, contact, 1e-6);
  row.pairings = std::move(coupling.pairings);
  row.operators = std::move(coupling.operators);
  row.problem = std::move(coupling.problem);
  const MonolithicRow reference = solve_monolithic_row(row);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged);
  const double force = reference.result.contact_force.maxCoeff();
  ASSERT_GT(force, 0.0);
  // The interface stays put: its motion is round-off next to the blocks' shortening (1e-3).
  EXPECT_LT(reference.result.normal_traces[0].lpNorm<Eigen::Infinity>(), 1e-12);
  for (const AccelerationMethod acceleration :
       {AccelerationMethod::iqn_ils, AccelerationMethod::aitken, AccelerationMethod::none}) {
    const RobinResult robin = run_row(row, acceleration);
    std::printf("symmetric pair, %s: %s after %zu iterations\n", to_string(acceleration).c_str(),
                to_string(robin.status).c_str(), robin.history.size());
    ASSERT_EQ(robin.status, IterationStatus::converged)
        << to_string(acceleration) << ": " << robin.message;
    for (int body = 0; body < 2; ++body) {
      EXPECT_LE(
          relative_difference(robin.state.bodies[static_cast<std::size_t>(body)].contact_force,
                              reference.result.contact_force),
          1e-8);
    }
  }
}

TEST(ManyBodies, TwoBodyAlgorithmsRefuseAGraphOfThree) {
  const Row row = make_row(1000.0);
  std::vector<InProcessPort> ports(3);
  std::vector<SubdomainPort*> pointers;
  for (InProcessPort& port : ports) pointers.push_back(&port);
  for (const CouplingAlgorithm algorithm :
       {CouplingAlgorithm::dirichlet_neumann, CouplingAlgorithm::neumann_neumann}) {
    CouplingOptions options;
    options.algorithm = algorithm;
    try {
      make_coupling_scheme(options, pointers, row.problem);
      ADD_FAILURE() << to_string(algorithm) << " accepted three bodies";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("exactly two bodies"), std::string::npos)
          << error.what();
    }
  }
}

}  // namespace
}  // namespace robin
