#pragma once
// A case coupled across two independent implementations: body 1 on robin-subdomain, body 2 on
// the Python server robin-subdomain-py, against the monolithic mortar solution of the same
// discretization (for mortar_service_test and solid_service_test).

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "coupling/coupled_run.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/monolithic_solver.hpp"
#include "remote/remote_port.hpp"
#include "remote/server_launcher.hpp"
#include "remote_test_support.hpp"

namespace robin::testing {

/// Runs `definition` (a mortar case; its QP tolerance is set to 1e-13) with body 1 on
/// robin-subdomain and body 2 on robin-subdomain-py, and expects both bodies' contact forces
/// within 1e-8 of the monolithic mortar solution. `label` names the case in the printed line.
inline void expect_python_and_cpp_equal_monolithic(CaseDefinition definition,
                                                   const std::string& label) {
  const TemporaryDirectory logs("python-coupling");
  definition.solver.qp.relative_tolerance = 1e-13;
  SubdomainServer cpp(definition.bodies[0].definition.name, server_options(logs.path()));
  SubdomainServer python(definition.bodies[1].definition.name, python_server_options(logs.path()));
  cpp.await_listening();
  python.await_listening();
  RemotePortOptions port_options;
  port_options.request_timeout_seconds = 120.0;
  RemotePort body1(cpp.endpoint(), definition.bodies[0].definition.name, port_options);
  RemotePort body2(python.endpoint(), definition.bodies[1].definition.name, port_options);
  const CoupledRunResult run = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  EXPECT_EQ(body2.server_name().rfind("robin-subdomain-py ", 0), 0u) << body2.server_name();
  body1.end_run();
  body2.end_run();
  ASSERT_EQ(run.iteration.status, IterationStatus::converged) << run.iteration.message;
  EXPECT_GE(run.pairing().non_mortar_body, 0);

  const LocalProblem problem = prepare_local_problem(definition);
  MprgpParameters reference = definition.solver.qp;
  reference.relative_tolerance = 1e-14;
  const MonolithicResult monolithic =
      solve_monolithic(*problem.bodies[0], *problem.bodies[1], problem.pairing(), reference);
  ASSERT_EQ(monolithic.qp.status, QpStatus::converged);
  std::printf("%s, C++ and Python servers: %zu iterations\n", label.c_str(),
              run.iteration.history.size());
  EXPECT_TRUE(
      vectors_close(run.iteration.state.bodies[0].contact_force, monolithic.contact_force, 1e-8));
  EXPECT_TRUE(
      vectors_close(run.iteration.state.bodies[1].contact_force, monolithic.contact_force, 1e-8));
}

}  // namespace robin::testing
