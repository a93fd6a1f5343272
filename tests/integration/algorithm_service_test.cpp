// Every coupling algorithm and acceleration on the real service: two robin-subdomain processes
// over tcp://127.0.0.1, driven by RemotePort, on two shipped cases (partial contact of two
// blocks; the cantilever on a block: different stiffness and boundary conditions). Each run
// must converge to the monolithic reference (contact forces and normal traces to 1e-7
// relative); the iteration counts go to the test log. A fixed relaxation that is too large
// must be reported as diverged, not as converged. The servers serve every run of a case in
// sequence without restarting.

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

#include "coupling/coupled_run.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::server_options;
using testing::TemporaryDirectory;

double relative_difference(const Eigen::VectorXd& value, const Eigen::VectorXd& reference) {
  return (value - reference).lpNorm<Eigen::Infinity>() / reference.lpNorm<Eigen::Infinity>();
}

struct Variant {
  std::string label;
  std::function<void(CouplingOptions&)> configure;
};

const std::vector<Variant>& variants() {
  static const std::vector<Variant> all{
      {"robin, iqn-ils (default)", [](CouplingOptions&) {}},
      {"robin, aitken",
       [](CouplingOptions& o) { o.acceleration.method = AccelerationMethod::aitken; }},
      {"robin, iqn-ils on (g1, g2), joint stopping",
       [](CouplingOptions& o) {
         o.acceleration.per_body = false;
         o.stopping = StoppingRule::joint;
       }},
      {"robin, per-body delta (0.9, 0.1)",
       [](CouplingOptions& o) {
         o.acceleration.method = AccelerationMethod::none;
         o.relaxation1 = 0.9;
         o.relaxation2 = 0.1;
         o.max_iterations = 2000;
       }},
      {"robin-constant, alpha 1e-4",
       [](CouplingOptions& o) {
         o.algorithm = CouplingAlgorithm::robin_constant;
         o.alpha = 1e-4;
       }},
      {"dirichlet-neumann, auto",
       [](CouplingOptions& o) { o.algorithm = CouplingAlgorithm::dirichlet_neumann; }},
      {"neumann-neumann",
       [](CouplingOptions& o) { o.algorithm = CouplingAlgorithm::neumann_neumann; }},
  };
  return all;
}

void run_every_variant(const std::string& case_name) {
  const CaseDefinition definition = read_case_file(example(case_name));
  const LocalProblem reference = prepare_local_problem(definition);
  const MonolithicResult monolithic = solve_monolithic(*reference.bodies[0], *reference.bodies[1],
                                                       reference.pairing(), definition.solver.qp);
  ASSERT_EQ(monolithic.qp.status, QpStatus::converged);
  const TemporaryDirectory logs("algorithm-service");
  SubdomainServer server1(definition.bodies[0].definition.name, server_options(logs.path()));
  SubdomainServer server2(definition.bodies[1].definition.name, server_options(logs.path()));
  server1.await_listening();
  server2.await_listening();
  for (const Variant& variant : variants()) {
    CouplingOptions options = definition.coupling;
    options.tolerance = 1e-8;
    options.max_iterations = 1000;
    variant.configure(options);
    RemotePort body1(server1.endpoint(), definition.bodies[0].definition.name, {});
    RemotePort body2(server2.endpoint(), definition.bodies[1].definition.name, {});
    const CoupledRunResult run = run_coupled_case(definition, {&body1, &body2}, options);
    body1.end_run();
    body2.end_run();
    const RobinResult& state = run.iteration;
    std::printf("%s: %s: %s after %zu iterations\n", case_name.c_str(), variant.label.c_str(),
                to_string(state.status).c_str(), state.history.size());
    ASSERT_EQ(state.status, IterationStatus::converged) << variant.label << ": " << state.message;
    EXPECT_LE(relative_difference(state.state.bodies[0].contact_force, monolithic.contact_force),
              1e-7)
        << variant.label;
    EXPECT_LE(relative_difference(state.state.bodies[1].contact_force, monolithic.contact_force),
              1e-7)
        << variant.label;
    EXPECT_LE(relative_difference(state.state.bodies[0].normal_trace, monolithic.normal_traces[0]),
              1e-7)
        << variant.label;
    EXPECT_LE(relative_difference(state.state.bodies[1].normal_trace, monolithic.normal_traces[1]),
              1e-7)
        << variant.label;
  }
  EXPECT_EQ(server1.failure(), "");
  EXPECT_EQ(server2.failure(), "");
}

TEST(AlgorithmService, EveryAlgorithmMatchesTheMonolithicAnswerOnPartialContact) {
  run_every_variant("two_blocks_partial.toml");
}

TEST(AlgorithmService, EveryAlgorithmMatchesTheMonolithicAnswerOnTheCantilever) {
  run_every_variant("asymmetric.toml");
}

TEST(AlgorithmService, TooLargeFixedRelaxationIsReportedAsDiverged) {
  const CaseDefinition definition = read_case_file(example("asymmetric.toml"));
  const TemporaryDirectory logs("algorithm-service-divergence");
  SubdomainServer server1(definition.bodies[0].definition.name, server_options(logs.path()));
  SubdomainServer server2(definition.bodies[1].definition.name, server_options(logs.path()));
  server1.await_listening();
  server2.await_listening();
  RemotePort body1(server1.endpoint(), definition.bodies[0].definition.name, {});
  RemotePort body2(server2.endpoint(), definition.bodies[1].definition.name, {});
  CouplingOptions options = definition.coupling;
  options.acceleration.method = AccelerationMethod::none;
  options.relaxation = 1.5;
  options.max_iterations = 500;
  const CoupledRunResult run = run_coupled_case(definition, {&body1, &body2}, options);
  std::printf("delta = 1.5: %s after %zu iterations: %s\n", to_string(run.iteration.status).c_str(),
              run.iteration.history.size(), run.iteration.message.c_str());
  EXPECT_EQ(run.iteration.status, IterationStatus::diverged) << run.iteration.message;
}

}  // namespace
}  // namespace robin
