// Floating bodies (docs/method.md, "Floating bodies"): bodies whose supports leave a rigid
// motion free, held by contact. Checked against numbers from outside the code:
//  - a vertical stack of three blocks with u_x = 0 on every lateral side (uniaxial strain): the
//    bottom block clamped, the top block pushed down by a prescribed displacement delta, the
//    middle block held by contact only (its vertical translation free). The exact answer is the
//    1D series of springs: the pressure p = delta / sum_i (H_i / M_i) on both interfaces and
//    sigma_yy = -p in every block, M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) the plane-strain
//    constrained modulus, and the middle block sits where the bottom one's shortening p H / M
//    puts it. Bilinear elements represent this linear field exactly, so the finite-element
//    answer equals it to round-off: 1e-10, through the monolithic solve and the Robin iteration;
//  - a floating block with a body force (u_x = 0 on its left side only: a genuine 2D state)
//    resting on a clamped block: the Robin iteration equals the monolithic solution to 1e-8 and
//    the total contact force equals the body force (equilibrium of the floating block, exact);
//  - a block with no support at all (three rigid motions) in a cup of three clamped blocks: the
//    same, with the moment of the contact forces zero (the rotation held by contact);
//  - the ill-posed cases are refused with the errors that name the body: a floating block whose
//    loads pull it away from its only contact, and one whose horizontal motion no contact row
//    sees (no lateral support on a flat interface);
//  - the schemes refuse the configurations whose iteration would need a floating body's Neumann
//    response.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "coupling/contact_graph.hpp"
#include "coupling/graph_coupling.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/robin_iteration.hpp"
#include "numerics/body_output.hpp"
#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {
namespace {

const std::filesystem::path data = ROBIN_TEST_DATA;
constexpr double poisson = 0.3;

/// The plane-strain constrained modulus E (1 - nu) / ((1 + nu)(1 - 2 nu)).
double constrained_modulus(double young) {
  return young * (1.0 - poisson) / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
}

BodyDefinition stack_block(const std::string& part, double young) {
  BodyDefinition body;
  body.name = part;
  body.mesh = read_gmsh_mesh(data / ("stack_block_" + part + ".geo"), {0.125, 1, false});
  body.material = make_isotropic_material(young, poisson, PlaneModel::plane_strain, part);
  return body;
}

/// The bodies, the graph's constraint rows and the problem of the coupling.
struct Assembly {
  std::vector<BodyDefinition> definitions;
  std::vector<ContactPairing> pairings;
  std::vector<ContactOperator> operators;
  CouplingProblem problem;
};

BodySolverOptions floating_allowed() {
  BodySolverOptions options;
  options.rigid_motions = RigidMotions::held_by_contact;
  return options;
}

/// The bodies coupled node to node through `edges`.
Assembly couple(std::vector<BodyDefinition> definitions,
                const std::vector<InterfaceDefinition>& edges) {
  Assembly assembly;
  std::vector<InterfaceDescription> interfaces;
  std::vector<std::string> names;
  for (const BodyDefinition& definition : definitions) {
    interfaces.push_back(BodySolver(definition, floating_allowed()).contact_boundary());
    names.push_back(definition.name);
  }
  ContactOptions contact;
  contact.method = ContactMethod::node_to_node;
  GraphCoupling coupling = couple_contact_graph(interfaces, names, edges, nullptr, contact, 1e-6);
  assembly.definitions = std::move(definitions);
  assembly.pairings = std::move(coupling.pairings);
  assembly.operators = std::move(coupling.operators);
  assembly.problem = std::move(coupling.problem);
  return assembly;
}

/// Interface k joins body k (its "top") and body k + 1 (its "bottom").
Assembly couple_stack(std::vector<BodyDefinition> definitions) {
  std::vector<InterfaceDefinition> edges;
  for (std::size_t body = 0; body + 1 < definitions.size(); ++body) {
    edges.push_back({static_cast<int>(body), static_cast<int>(body) + 1, "top", "bottom"});
  }
  return couple(std::move(definitions), edges);
}

/// The stack: u_x = 0 on every lateral side; bottom clamped; top pushed down by `push`.
Assembly uniaxial_stack(const std::vector<double>& youngs, double push) {
  std::vector<BodyDefinition> definitions;
  const char* parts[] = {"bottom", "middle", "top"};
  for (int body = 0; body < 3; ++body) {
    BodyDefinition definition = stack_block(parts[body], youngs[static_cast<std::size_t>(body)]);
    definition.dirichlet.push_back({"left", 0.0, std::nullopt, std::nullopt});
    definition.dirichlet.push_back({"right", 0.0, std::nullopt, std::nullopt});
    if (body == 0) definition.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
    if (body == 2) definition.dirichlet.push_back({"top", std::nullopt, -push, std::nullopt});
    if (body < 2) definition.contact_boundaries.push_back("top");
    if (body > 0) definition.contact_boundaries.push_back("bottom");
    definitions.push_back(std::move(definition));
  }
  return couple_stack(std::move(definitions));
}

struct MonolithicAssembly {
  std::vector<std::unique_ptr<BodySolver>> bodies;
  MonolithicResult result;
};

MonolithicAssembly solve_monolithic_assembly(const Assembly& assembly) {
  MonolithicAssembly reference;
  std::vector<const BodySolver*> pointers;
  for (std::size_t body = 0; body < assembly.definitions.size(); ++body) {
    reference.bodies.push_back(
        std::make_unique<BodySolver>(assembly.definitions[body], floating_allowed()));
    reference.bodies.back()->assign_contact(assembly.operators[body]);
    pointers.push_back(reference.bodies.back().get());
  }
  MprgpParameters parameters;
  parameters.relative_tolerance = 1e-13;  // the pressures are checked to 1e-10
  reference.result =
      solve_monolithic(pointers, assembly.problem.graph, assembly.problem.gaps, parameters);
  return reference;
}

/// In-process ports set up and assigned their rows.
struct Ports {
  std::vector<InProcessPort> ports;
  std::vector<SubdomainPort*> pointers;
  CouplingProblem problem;
};

void set_up_ports(const Assembly& assembly, Ports& ports) {
  ports.ports = std::vector<InProcessPort>(assembly.definitions.size());
  SolverOptions solver;
  solver.qp.relative_tolerance = 1e-13;
  solver.body = floating_allowed();
  ports.problem = assembly.problem;
  ports.problem.rigid_modes.clear();
  for (std::size_t body = 0; body < ports.ports.size(); ++body) {
    BodyCase body_case;
    body_case.definition = assembly.definitions[body];
    // the rigid modes as the port reports them
    ports.problem.rigid_modes.push_back(ports.ports[body].setup(body_case, solver).rigid_modes);
    ports.ports[body].assign_contact(assembly.operators[body]);
    ports.pointers.push_back(&ports.ports[body]);
  }
}

RobinResult run_robin(Ports& ports, AccelerationMethod acceleration, double tolerance) {
  CouplingOptions options;
  options.acceleration.method = acceleration;
  options.tolerance = tolerance;
  options.max_iterations = 300;
  return run_robin_iteration(ports.pointers, ports.problem, options, nullptr, {});
}

double relative_difference(const Eigen::VectorXd& value, const Eigen::VectorXd& reference) {
  return (value - reference).lpNorm<Eigen::Infinity>() /
         std::max(reference.lpNorm<Eigen::Infinity>(), 1e-300);
}

/// The Robin state of every body equals the monolithic one (forces and traces, body order).
void expect_equals_monolithic(const RobinResult& robin, const CouplingProblem& problem,
                              const MonolithicResult& monolithic, double tolerance) {
  ASSERT_EQ(robin.state.bodies.size(), monolithic.normal_traces.size());
  double largest = 0.0;
  for (std::size_t body = 0; body < robin.state.bodies.size(); ++body) {
    const BodyInterfaceState& state = robin.state.bodies[body];
    const Eigen::VectorXd force =
        problem.graph.body_part(static_cast<int>(body), monolithic.contact_force);
    const double force_difference = relative_difference(state.contact_force, force);
    const double trace_difference =
        relative_difference(state.normal_trace, monolithic.normal_traces[body]);
    EXPECT_LE(force_difference, tolerance) << "body " << body + 1;
    EXPECT_LE(trace_difference, tolerance) << "body " << body + 1;
    largest = std::max({largest, force_difference, trace_difference});
  }
  std::printf("  against the monolithic solution: largest relative difference %.2e\n", largest);
}

const std::vector<double> stack_youngs = {1000.0, 400.0, 2500.0};
constexpr double stack_push = 0.01;

/// p = delta / sum_i (H_i / M_i), H_i = 1.
double stack_pressure() {
  double compliance = 0.0;
  for (const double young : stack_youngs) compliance += 1.0 / constrained_modulus(young);
  return stack_push / compliance;
}

/// lambda_j / m_j = p on every row of both interfaces (global order).
void expect_uniform_pressure(const Eigen::VectorXd& force, const CouplingProblem& problem) {
  const double pressure = stack_pressure();
  double largest = 0.0;
  for (Eigen::Index row = 0; row < force.size(); ++row) {
    EXPECT_NEAR(force[row] / problem.weights[row], pressure, 1e-10 * pressure) << "row " << row;
    largest = std::max(largest, std::abs(force[row] / problem.weights[row] - pressure) / pressure);
  }
  std::printf("  pressure %.12g, exact %.12g: largest relative error %.2e\n",
              force[0] / problem.weights[0], pressure, largest);
}

/// The displacement and stress fields of every block of the stack: u_y of the exact 1D answer
/// at every node, sigma_yy = -p and sigma_xx = nu/(1 - nu) sigma_yy at every node.
void expect_exact_fields(const std::vector<BodyOutput>& outputs) {
  const double pressure = stack_pressure();
  double base = 0.0;  // u_y at the bottom of the block
  for (std::size_t body = 0; body < outputs.size(); ++body) {
    const double strain = -pressure / constrained_modulus(stack_youngs[body]);
    const OutputField& displacement = outputs[body].point_fields[0];
    const OutputField& stress = outputs[body].point_fields[1];
    ASSERT_EQ(displacement.name, "displacement");
    ASSERT_EQ(stress.name, "stress");
    const Mesh& mesh = outputs[body].mesh;
    for (std::size_t node = 0; node < mesh.node_count(); ++node) {
      const double height = mesh.nodes[node].y() - static_cast<double>(body);
      EXPECT_NEAR(displacement.values[2 * node], 0.0, 1e-10 * stack_push);
      EXPECT_NEAR(displacement.values[2 * node + 1], base + strain * height, 1e-10 * stack_push)
          << "body " << body + 1 << " node " << node;
      EXPECT_NEAR(stress.values[6 * node + 1], -pressure, 1e-10 * pressure);
      EXPECT_NEAR(stress.values[6 * node], -pressure * poisson / (1.0 - poisson), 1e-10 * pressure);
    }
    base += strain;
  }
}

TEST(FloatingBody, StackOfThreeMonolithicEqualsTheSeriesSprings) {
  const Assembly stack = uniaxial_stack(stack_youngs, stack_push);
  ASSERT_EQ(stack.problem.rigid_modes, (std::vector<int>{0, 1, 0}));
  const MonolithicAssembly reference = solve_monolithic_assembly(stack);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged) << reference.result.qp.message;
  expect_uniform_pressure(reference.result.contact_force, stack.problem);
  // the fields with the monolithic rigid amplitude of the middle block
  ASSERT_EQ(reference.result.rigid_amplitudes[1].size(), 1);
  std::vector<BodyOutput> outputs;
  for (std::size_t body = 0; body < 3; ++body) {
    const Eigen::VectorXd force =
        stack.problem.graph.body_part(static_cast<int>(body), reference.result.contact_force);
    outputs.push_back(
        make_body_output(*reference.bodies[body], force, reference.result.rigid_amplitudes[body]));
  }
  expect_exact_fields(outputs);
}

TEST(FloatingBody, StackOfThreeRobinEqualsTheSeriesSpringsAndTheMonolithicSolution) {
  const Assembly stack = uniaxial_stack(stack_youngs, stack_push);
  const MonolithicAssembly reference = solve_monolithic_assembly(stack);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged);
  for (const AccelerationMethod acceleration :
       {AccelerationMethod::iqn_ils, AccelerationMethod::none}) {
    Ports ports;
    set_up_ports(stack, ports);
    ASSERT_EQ(ports.problem.rigid_modes, (std::vector<int>{0, 1, 0}));
    // the pressure is checked to 1e-10: the iteration's own tolerance must be below that
    const RobinResult robin = run_robin(ports, acceleration, 1e-11);
    std::printf("stack with a floating middle block, %s: %s after %zu iterations (%s)\n",
                to_string(acceleration).c_str(), to_string(robin.status).c_str(),
                robin.history.size(), robin.message.c_str());
    ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
    EXPECT_EQ(robin.completed_by_sequence, 1);  // the floating block's sequence
    expect_equals_monolithic(robin, stack.problem, reference.result, 1e-8);
    expect_uniform_pressure(stack.problem.graph.side(1, robin.state.contact_forces()),
                            stack.problem);
    std::vector<BodyOutput> outputs;
    for (std::size_t body = 0; body < 3; ++body) {
      outputs.push_back(ports.ports[body].fields(robin.state.bodies[body].contact_force, {}));
    }
    expect_exact_fields(outputs);
  }
}

/// A floating block [0, 1] x [1, 2] (u_x = 0 on its left side only, body force (b_x, b_y)) on a
/// block [0, 1] x [0, 1] clamped at its bottom.
Assembly block_on_block(const Eigen::Vector3d& body_force, bool left_support) {
  BodyDefinition base = stack_block("bottom", 1000.0);
  base.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  base.contact_boundaries.push_back("top");
  BodyDefinition floating = stack_block("middle", 300.0);
  if (left_support) floating.dirichlet.push_back({"left", 0.0, std::nullopt, std::nullopt});
  floating.body_force = body_force;
  floating.contact_boundaries.push_back("bottom");
  return couple_stack({base, floating});
}

TEST(FloatingBody, BlockWithBodyForceOnAClampedBlockRobinEqualsMonolithicInEquilibrium) {
  const Eigen::Vector3d body_force(4.0, -10.0, 0.0);  // tilts the block: a genuine 2D contact state
  const Assembly assembly = block_on_block(body_force, true);
  ASSERT_EQ(assembly.problem.rigid_modes, (std::vector<int>{0, 1}));
  const MonolithicAssembly reference = solve_monolithic_assembly(assembly);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged) << reference.result.qp.message;
  // Vertical equilibrium of the floating block: its rows have the normal (0, -1) and the left
  // support only reacts along x, so sum lambda = -b_y * area exactly.
  const double weight = -body_force.y() * 1.0;
  EXPECT_NEAR(reference.result.contact_force.sum(), weight, 1e-12 * weight);
  std::printf("  monolithic: sum of the contact forces - weight = %.2e\n",
              reference.result.contact_force.sum() - weight);
  const double largest = reference.result.contact_force.maxCoeff();
  const double smallest = reference.result.contact_force.minCoeff();
  std::printf("block on block: contact forces from %g to %g (weight %g)\n", smallest, largest,
              weight);
  for (const AccelerationMethod acceleration :
       {AccelerationMethod::iqn_ils, AccelerationMethod::aitken}) {
    Ports ports;
    set_up_ports(assembly, ports);
    const RobinResult robin = run_robin(ports, acceleration, 1e-10);
    std::printf("floating block on a clamped block, %s: %s after %zu iterations\n",
                to_string(acceleration).c_str(), to_string(robin.status).c_str(),
                robin.history.size());
    ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
    expect_equals_monolithic(robin, assembly.problem, reference.result, 1e-8);
    EXPECT_NEAR(robin.state.bodies[1].contact_force.sum(), weight, 1e-9 * weight);
  }
}

/// A block [1, 2] x [0, 1] with no support at all (three rigid motions free) in a cup: a wall on
/// its left ([0, 1] x [0, 1], clamped on its left side), one on its right ([2, 3] x [0, 1],
/// clamped on its right side) and a bottom ([1, 2] x [-1, 0], clamped at its bottom), pushed
/// down and to the right by a body force. Contact holds all three motions (the rotation by the
/// bottom and the walls together).
Assembly block_in_a_cup(const Eigen::Vector3d& body_force) {
  const auto read = [](const std::string& name, const std::string& file, double young) {
    BodyDefinition body;
    body.name = name;
    body.mesh = read_gmsh_mesh(data / file, {0.125, 1, false});
    body.material = make_isotropic_material(young, poisson, PlaneModel::plane_strain, name);
    return body;
  };
  BodyDefinition left = read("left wall", "row_block_left.geo", 1000.0);
  left.dirichlet.push_back({"left", 0.0, 0.0, std::nullopt});
  left.contact_boundaries = {"right"};
  BodyDefinition floating = read("block", "row_block_middle.geo", 300.0);
  floating.body_force = body_force;
  floating.contact_boundaries = {"left", "right", "bottom"};
  BodyDefinition right = read("right wall", "row_block_right.geo", 1000.0);
  right.dirichlet.push_back({"right", 0.0, 0.0, std::nullopt});
  right.contact_boundaries = {"left"};
  BodyDefinition bottom = read("bottom", "cup_bottom.geo", 2000.0);
  bottom.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  bottom.contact_boundaries = {"top"};
  return couple({left, floating, right, bottom},
                {{0, 1, "right", "left"}, {1, 2, "right", "left"}, {3, 1, "top", "bottom"}});
}

TEST(FloatingBody, UnsupportedBlockInACupRobinEqualsMonolithicInEquilibrium) {
  const Eigen::Vector3d body_force(2.0, -5.0, 0.0);
  const Assembly cup = block_in_a_cup(body_force);
  ASSERT_EQ(cup.problem.rigid_modes, (std::vector<int>{0, 3, 0, 0}));
  const MonolithicAssembly reference = solve_monolithic_assembly(cup);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged) << reference.result.qp.message;
  // Equilibrium of the block (area 1): the contact forces on it, -B' lambda, balance the body
  // force, and their moment about its centre (1.5, 0.5) is zero as the body force's.
  const Eigen::VectorXd force = cup.problem.graph.body_part(1, reference.result.contact_force);
  const Eigen::VectorXd field = reference.bodies[1]->contact_force_field(force);
  const Mesh& mesh = reference.bodies[1]->mesh();
  Eigen::Vector3d resultant = Eigen::Vector3d::Zero();
  double moment = 0.0;
  for (std::size_t node = 0; node < mesh.node_count(); ++node) {
    const Eigen::Vector3d nodal(field[2 * static_cast<Eigen::Index>(node)],
                                field[2 * static_cast<Eigen::Index>(node) + 1], 0.0);
    const Eigen::Vector3d arm = mesh.nodes[node] - Eigen::Vector3d(1.5, 0.5, 0.0);
    resultant += nodal;
    moment += arm.x() * nodal.y() - arm.y() * nodal.x();
  }
  const double scale = body_force.norm();
  std::printf("block in a cup: contact resultant + body force = (%.2e, %.2e), moment %.2e\n",
              resultant.x() + body_force.x(), resultant.y() + body_force.y(), moment);
  EXPECT_LE((resultant + body_force).norm(), 1e-11 * scale);
  EXPECT_LE(std::abs(moment), 1e-11 * scale);
  Ports ports;
  set_up_ports(cup, ports);
  const RobinResult robin = run_robin(ports, AccelerationMethod::iqn_ils, 1e-10);
  std::printf("block in a cup, iqn-ils: %s after %zu iterations (%s)\n",
              to_string(robin.status).c_str(), robin.history.size(), robin.algorithm.c_str());
  ASSERT_EQ(robin.status, IterationStatus::converged) << robin.message;
  expect_equals_monolithic(robin, cup.problem, reference.result, 1e-8);
}

/// The message of the SingularBodyError thrown by `action`, or "" when none is thrown.
template <typename Action>
std::string singular_body_message(Action action) {
  try {
    action();
  } catch (const SingularBodyError& error) {
    return error.what();
  }
  return "";
}

TEST(FloatingBody, BlockPulledAwayFromItsOnlyContactIsRefused) {
  const Assembly assembly = block_on_block(Eigen::Vector3d(0.0, 10.0, 0.0), true);  // pulled up
  BodySolver floating(assembly.definitions[1], floating_allowed());
  const std::string message =
      singular_body_message([&] { floating.assign_contact(assembly.operators[1]); });
  EXPECT_NE(message.find("body 'middle'"), std::string::npos) << message;
  EXPECT_NE(message.find("the loads push the body away from every contact"), std::string::npos)
      << message;
}

TEST(FloatingBody, BlockThatCanSlideAlongAFlatInterfaceIsRefused) {
  const Assembly assembly = block_on_block(Eigen::Vector3d(0.0, -10.0, 0.0), false);  // no support
  ASSERT_EQ(assembly.problem.rigid_modes[1], 3);
  BodySolver floating(assembly.definitions[1], floating_allowed());
  const std::string message =
      singular_body_message([&] { floating.assign_contact(assembly.operators[1]); });
  EXPECT_NE(message.find("body 'middle'"), std::string::npos) << message;
  EXPECT_NE(message.find("free sliding direction"), std::string::npos) << message;
  EXPECT_NE(message.find("(u_x, u_y, rotation) ~ (1, 0, 0)"), std::string::npos) << message;
}

TEST(FloatingBody, WithoutTheOptionAFloatingBodyIsStillRefusedAtSetup) {
  const Assembly assembly = block_on_block(Eigen::Vector3d(0.0, -10.0, 0.0), true);
  const std::string message = singular_body_message([&] { BodySolver(assembly.definitions[1]); });
  EXPECT_NE(message.find("leave a rigid motion free"), std::string::npos) << message;
}

/// The InputError message of make_coupling_scheme, or "" when it accepts.
std::string scheme_refusal(const CouplingOptions& options, const CouplingProblem& problem) {
  std::vector<InProcessPort> ports(static_cast<std::size_t>(problem.graph.body_count()));
  std::vector<SubdomainPort*> pointers;
  for (InProcessPort& port : ports) pointers.push_back(&port);
  try {
    make_coupling_scheme(options, pointers, problem);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(FloatingBody, SchemesThatWouldNeedAFloatingBodysNeumannResponseAreRefused) {
  Assembly stack = uniaxial_stack(stack_youngs, stack_push);
  CouplingOptions robin;
  EXPECT_EQ(scheme_refusal(robin, stack.problem), "");
  // floating bodies on both sides of an interface: in both colour classes
  stack.problem.rigid_modes = {0, 1, 1};
  EXPECT_NE(scheme_refusal(robin, stack.problem).find("bodies 2 and 3"), std::string::npos)
      << scheme_refusal(robin, stack.problem);
  stack.problem.rigid_modes = {0, 1, 0};
  CouplingOptions joint;
  joint.stopping = StoppingRule::joint;
  EXPECT_NE(scheme_refusal(joint, stack.problem).find("stopping \"joint\""), std::string::npos);
  // an odd cycle: a triangle of bodies, one floating
  CouplingProblem triangle = stack.problem;
  triangle.graph = ContactGraph(3, {{0, 1, 1}, {1, 2, 1}, {2, 0, 1}});
  triangle.gaps = triangle.weights = Eigen::VectorXd::Ones(3);
  EXPECT_NE(scheme_refusal(robin, triangle).find("odd cycle"), std::string::npos);

  const Assembly pair = block_on_block(Eigen::Vector3d(0.0, -10.0, 0.0), true);
  CouplingOptions dirichlet_neumann;
  dirichlet_neumann.algorithm = CouplingAlgorithm::dirichlet_neumann;
  dirichlet_neumann.contact_body =
      ContactBodyChoice::first;  // the clamped block: the floating one would be Neumann
  EXPECT_NE(scheme_refusal(dirichlet_neumann, pair.problem).find("must be the contact body"),
            std::string::npos);
  CouplingOptions neumann_neumann;
  neumann_neumann.algorithm = CouplingAlgorithm::neumann_neumann;
  EXPECT_NE(scheme_refusal(neumann_neumann, pair.problem).find("floating body 2"),
            std::string::npos)
      << scheme_refusal(neumann_neumann, pair.problem);
}

TEST(FloatingBody, DirichletNeumannWithTheFloatingContactBodyEqualsMonolithic) {
  const Assembly assembly = block_on_block(Eigen::Vector3d(4.0, -10.0, 0.0), true);
  const MonolithicAssembly reference = solve_monolithic_assembly(assembly);
  ASSERT_EQ(reference.result.qp.status, QpStatus::converged);
  Ports ports;
  set_up_ports(assembly, ports);
  CouplingOptions options;
  options.algorithm =
      CouplingAlgorithm::dirichlet_neumann;  // contact body "auto": the floating one
  options.tolerance = 1e-10;
  options.max_iterations = 300;
  const RobinResult result =
      run_robin_iteration(ports.pointers, ports.problem, options, nullptr, {});
  std::printf("dirichlet-neumann, floating contact body: %s after %zu iterations (%s)\n",
              to_string(result.status).c_str(), result.history.size(), result.algorithm.c_str());
  ASSERT_EQ(result.status, IterationStatus::converged) << result.message;
  EXPECT_NE(result.algorithm.find("contact body 2"), std::string::npos);
  expect_equals_monolithic(result, assembly.problem, reference.result, 1e-8);
}

TEST(FloatingBody, RobinConstantRunsWithAFloatingBody) {
  const Assembly assembly = block_on_block(Eigen::Vector3d(4.0, -10.0, 0.0), true);
  const MonolithicAssembly reference = solve_monolithic_assembly(assembly);
  Ports ports;
  set_up_ports(assembly, ports);
  CouplingOptions options;
  options.algorithm = CouplingAlgorithm::robin_constant;
  options.alpha = 1e-4;  // below h / E (docs/method.md, "The algorithm family")
  options.stopping = StoppingRule::joint;
  options.tolerance = 1e-9;
  options.max_iterations = 2000;
  const RobinResult result =
      run_robin_iteration(ports.pointers, ports.problem, options, nullptr, {});
  std::printf("robin-constant, floating body: %s after %zu iterations\n",
              to_string(result.status).c_str(), result.history.size());
  ASSERT_EQ(result.status, IterationStatus::converged) << result.message;
  expect_equals_monolithic(result, assembly.problem, reference.result, 1e-7);
}

}  // namespace
}  // namespace robin
