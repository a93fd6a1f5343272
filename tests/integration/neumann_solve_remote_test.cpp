// The Neumann solve of protocol 1.1 (NeumannSolveRequest, capability "neumann_solve") through
// RemotePort against real robin-subdomain processes over tcp://127.0.0.1, on
// examples/two_blocks.toml with the pair order of the coupled run:
//  - both bodies' u_N equal InProcessPort::finish_neumann_solve (the same C++ numerics in this
//    process) to 1e-12, and the normal trace of the full displacement u(lambda) of a BodySolver
//    built here (BodySolver::displacement, one solve with the factor, taken with the assigned
//    normals) to 1e-12; the port's timings and byte counts grow;
//  - a server that announces protocol 1.0 without the capability (robin-subdomain
//    --protocol-minor 0 --without-capability neumann_solve) still serves the Robin iteration,
//    equal to the in-process run, while start_neumann_solve throws a PortError naming the
//    server, the body and the step, and sends nothing: the port and the server go on.

#include <gtest/gtest.h>

#include <array>
#include <iostream>

#include "coupling/contact_pairing.hpp"
#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/local_problem.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::server_options;
using testing::TemporaryDirectory;
using testing::vectors_close;

/// examples/two_blocks.toml with both meshes loaded (SubdomainPort::setup needs them).
CaseDefinition two_blocks() {
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);
  return definition;
}

RemotePortOptions port_options() {
  RemotePortOptions options;
  options.request_timeout_seconds = 30.0;
  return options;
}

/// Sets both bodies up on `ports`, pairs their contact boundaries and assigns the pair order,
/// as run_coupled_case does.
ContactPairing set_up_pair(const CaseDefinition& definition,
                           const std::array<SubdomainPort*, 2>& ports) {
  std::array<InterfaceDescription, 2> interfaces;
  for (int alpha = 0; alpha < 2; ++alpha) {
    interfaces[alpha] = ports[alpha]->setup(definition.bodies[alpha], definition.solver);
  }
  const std::unique_ptr<GapFunction> gap = make_gap_function(definition);
  ContactPairing pairing = pair_contact_nodes(interfaces[0], definition.bodies[0].definition.name,
                                              interfaces[1], definition.bodies[1].definition.name,
                                              gap.get(), definition.solver.pairing_tolerance);
  for (int alpha = 0; alpha < 2; ++alpha) ports[alpha]->assign_contact(pairing.assignment(alpha));
  return pairing;
}

/// A compressive contact force varying along the pair order, of the size of the two-block
/// contact forces (about 1 per node).
Eigen::VectorXd varying_force(Eigen::Index size) {
  Eigen::VectorXd force(size);
  for (Eigen::Index i = 0; i < size; ++i) {
    force[i] = 1.0 + 0.5 * std::cos(1.3 * static_cast<double>(i));
  }
  return force;
}

/// u(node_i) . n_i of body `alpha` under the contact force lambda, from the full displacement of
/// a BodySolver built here. The pairing's operator is node-to-node: row i holds the components
/// (n_x, n_y) of the assigned normal n_i at node_i, read back here.
Eigen::VectorXd displacement_trace(const CaseDefinition& definition, int alpha,
                                   const ContactOperator& assignment,
                                   const Eigen::VectorXd& force) {
  BodySolver body(load_body(definition.bodies[alpha]), definition.solver.body);
  body.assign_contact(assignment);
  const Eigen::VectorXd displacement = body.displacement(force);
  Eigen::VectorXd trace(force.size());
  for (Eigen::Index i = 0; i < force.size(); ++i) {
    const std::size_t first = assignment.row_offsets[static_cast<std::size_t>(i)];
    EXPECT_EQ(assignment.row_offsets[static_cast<std::size_t>(i) + 1], first + 2);
    EXPECT_EQ(assignment.nodes[first], assignment.nodes[first + 1]);
    EXPECT_EQ(assignment.components[first], 0);
    EXPECT_EQ(assignment.components[first + 1], 1);
    const int node = assignment.nodes[first];
    const Eigen::Vector3d normal(assignment.values[first], assignment.values[first + 1], 0.0);
    EXPECT_NEAR(normal.norm(), 1.0, 1e-12);
    trace[i] = displacement.segment<2>(2 * node).dot(normal.head<2>());
  }
  return trace;
}

TEST(NeumannSolveRemote, CppServerEqualsInProcessPortAndTheDisplacementTrace) {
  const TemporaryDirectory logs("neumann-remote");
  const CaseDefinition definition = two_blocks();
  SubdomainServer server1("lower", server_options(logs.path()));
  SubdomainServer server2("upper", server_options(logs.path()));
  server1.await_listening();
  server2.await_listening();
  RemotePort remote1(server1.endpoint(), "lower", port_options());
  RemotePort remote2(server2.endpoint(), "upper", port_options());
  InProcessPort local1, local2;
  const ContactPairing pairing = set_up_pair(definition, {&remote1, &remote2});
  const ContactPairing local_pairing = set_up_pair(definition, {&local1, &local2});
  ASSERT_EQ(pairing.size(), local_pairing.size());
  ASSERT_EQ(pairing.assignment(0).nodes, local_pairing.assignment(0).nodes);
  ASSERT_EQ(pairing.assignment(1).values, local_pairing.assignment(1).values);
  EXPECT_TRUE(remote1.offers("neumann_solve"));
  const std::array<PortTimings, 2> before = {remote1.timings(), remote2.timings()};

  const Eigen::VectorXd force = varying_force(static_cast<Eigen::Index>(pairing.size()));
  const std::array<RemotePort*, 2> remote = {&remote1, &remote2};
  const std::array<InProcessPort*, 2> local = {&local1, &local2};
  for (RemotePort* port : remote) port->start_neumann_solve(force, 4);  // both in flight
  for (int alpha = 0; alpha < 2; ++alpha) {
    const CorrectionSolveResult over_tcp = remote[alpha]->finish_neumann_solve();
    local[alpha]->start_neumann_solve(force, 4);
    const CorrectionSolveResult in_process = local[alpha]->finish_neumann_solve();
    const Eigen::VectorXd traced =
        displacement_trace(definition, alpha, pairing.assignment(alpha), force);
    std::cout << "body " << alpha + 1 << ": max |u_N| " << traced.lpNorm<Eigen::Infinity>()
              << ", difference to in-process "
              << (over_tcp.normal_trace - in_process.normal_trace).lpNorm<Eigen::Infinity>()
              << ", to the displacement trace "
              << (over_tcp.normal_trace - traced).lpNorm<Eigen::Infinity>() << "\n";
    EXPECT_GT(traced.lpNorm<Eigen::Infinity>(), 1e-4) << "body " << alpha + 1;
    EXPECT_TRUE(vectors_close(over_tcp.normal_trace, in_process.normal_trace, 1e-12))
        << "body " << alpha + 1;
    EXPECT_TRUE(vectors_close(over_tcp.normal_trace, traced, 1e-12)) << "body " << alpha + 1;
    EXPECT_GE(over_tcp.seconds, 0.0);
    const PortTimings& after = remote[alpha]->timings();
    EXPECT_GT(after.bytes_sent, before[alpha].bytes_sent + 8 * static_cast<long>(force.size()));
    EXPECT_GT(after.bytes_received,
              before[alpha].bytes_received + 8 * static_cast<long>(force.size()));
    EXPECT_GE(after.compute_seconds, before[alpha].compute_seconds + over_tcp.seconds);
    EXPECT_GT(after.round_trip_seconds, before[alpha].round_trip_seconds);
  }
  for (SubdomainPort* port :
       {static_cast<SubdomainPort*>(&remote1), static_cast<SubdomainPort*>(&remote2),
        static_cast<SubdomainPort*>(&local1), static_cast<SubdomainPort*>(&local2)}) {
    port->end_run();
  }
}

TEST(NeumannSolveRemote, ServerWithoutTheCapabilityServesRobinButRefusesTheNeumannSolve) {
  const TemporaryDirectory logs("neumann-remote-1.0");
  const CaseDefinition definition = two_blocks();
  ServerLaunchOptions old_options = server_options(logs.path());
  old_options.extra_arguments = {"--protocol-minor", "0", "--without-capability", "neumann_solve"};
  SubdomainServer server1("lower", old_options);
  SubdomainServer server2("upper", server_options(logs.path()));
  server1.await_listening();
  server2.await_listening();
  RemotePort body1(server1.endpoint(), "lower", port_options());
  RemotePort body2(server2.endpoint(), "upper", port_options());

  // The Robin iteration runs on the 1.0 server as on an in-process pair.
  const CoupledRunResult remote =
      run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  InProcessPort local1, local2;
  const CoupledRunResult reference =
      run_coupled_case(definition, {&local1, &local2}, definition.coupling);
  ASSERT_EQ(remote.iteration.status, IterationStatus::converged) << remote.iteration.message;
  EXPECT_EQ(remote.iteration.history.size(), reference.iteration.history.size());
  EXPECT_TRUE(vectors_close(remote.iteration.state.bodies[0].contact_force,
                            reference.iteration.state.bodies[0].contact_force, 1e-12));
  EXPECT_FALSE(body1.offers("neumann_solve"));
  EXPECT_TRUE(body2.offers("neumann_solve"));

  const Eigen::VectorXd& force = remote.iteration.state.bodies[0].contact_force;
  try {
    body1.start_neumann_solve(force, 7);
    FAIL() << "the Neumann solve was started on a server without the capability";
  } catch (const PortError& error) {
    const std::string message = error.what();
    std::cout << message << "\n";
    EXPECT_NE(message.find("server " + server1.endpoint() + " (body 'lower')"), std::string::npos)
        << message;
    EXPECT_NE(message.find("step Neumann solve (iteration 7)"), std::string::npos) << message;
    EXPECT_NE(message.find("lacks capability neumann_solve (protocol 1.1)"), std::string::npos)
        << message;
  }
  // Nothing was sent: the port has no request in flight and the server still serves.
  const BodyOutput output = body1.fields(force, {});
  EXPECT_EQ(output.mesh.nodes.size(), reference.outputs[0].mesh.nodes.size());
  body2.start_neumann_solve(remote.iteration.state.bodies[1].contact_force, 7);
  const CorrectionSolveResult neumann = body2.finish_neumann_solve();
  // At convergence the Neumann body's u_N under lambda is the contact solve's trace.
  EXPECT_TRUE(
      vectors_close(neumann.normal_trace, remote.iteration.state.bodies[1].normal_trace, 1e-9));
  for (SubdomainPort* port :
       {static_cast<SubdomainPort*>(&body1), static_cast<SubdomainPort*>(&body2),
        static_cast<SubdomainPort*>(&local1), static_cast<SubdomainPort*>(&local2)}) {
    port->end_run();
  }
}

}  // namespace
}  // namespace robin
