// robin-subdomain-py (python/robin-subdomain-py run by /usr/bin/python3), the independent Python
// implementation of a subdomain server (its own Gmsh reader, elements, factorization and QP),
// driven by the coordinator's RemotePort:
//  - coupled runs of examples/two_blocks.toml, two_blocks_partial.toml, hertz.toml and
//    asymmetric.toml (two Python servers) with body 1
//    on the C++ robin-subdomain and body 2 on the Python server, and with both bodies on Python
//    servers, equal the all-C++ run (InProcessPort: the C++ numerics in this process, which
//    remote_port_test shows equal to C++ servers to 1e-12) to 1e-6 relative in contact forces,
//    normal traces and displacement fields, with the same iteration count;
//  - the Neumann solve of protocol 1.1 (u_N for a given contact force, computed by the Python
//    server with one solve of its own factor) equals the C++ server's (e - F lambda) to 1e-9
//    relative on both bodies of two_blocks.toml;
//  - the conformance checker (robin-coordinator --check-server) passes on the Python server,
//    its Neumann-solve checks and its solid-body checks (protocol 2.4: a tetrahedron cube
//    compared with the checker's in-process reference) included;
//  - the process: exactly one "listening on" line with the ephemeral port resolved; garbage
//    bytes and a multi-frame message get MALFORMED_MESSAGE replies and the server goes on;
//    Shutdown, SIGTERM and SIGINT end it with exit status 0.

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <iostream>
#include <thread>
#include <zmq.hpp>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "protocol_version.hpp"
#include "remote/conformance_check.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

using testing::example;
using testing::expect_same_interface_state;
using testing::python_server_options;
using testing::server_options;
using testing::TemporaryDirectory;
using testing::vectors_close;

constexpr double tolerance = 1e-6;  // relative, two independent implementations

Eigen::VectorXd point_field(const BodyOutput& output, const std::string& name) {
  for (const OutputField& field : output.point_fields) {
    if (field.name == name) {
      return Eigen::Map<const Eigen::VectorXd>(field.values.data(),
                                               static_cast<Eigen::Index>(field.values.size()));
    }
  }
  throw std::runtime_error("no point field '" + name + "' in body '" + output.body_name + "'");
}

/// The all-C++ run of a case, computed once per case.
const CoupledRunResult& cpp_reference(const std::string& case_file) {
  static std::map<std::string, CoupledRunResult> references;
  const auto found = references.find(case_file);
  if (found != references.end()) return found->second;
  const CaseDefinition definition = read_case_file(example(case_file));
  InProcessPort body1, body2;
  CoupledRunResult result = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  body1.end_run();
  body2.end_run();
  return references.emplace(case_file, std::move(result)).first->second;
}

/// Runs `case_file` with body 1 on a C++ or Python server and body 2 on a Python server.
CoupledRunResult run_with_python(const std::string& case_file, bool python_body1) {
  const TemporaryDirectory logs("python-server-logs");
  const CaseDefinition definition = read_case_file(example(case_file));
  const ServerLaunchOptions python = python_server_options(logs.path());
  SubdomainServer server1(definition.bodies[0].definition.name,
                          python_body1 ? python : server_options(logs.path()));
  SubdomainServer server2(definition.bodies[1].definition.name, python);
  server1.await_listening();
  server2.await_listening();
  RemotePortOptions port_options;
  port_options.request_timeout_seconds = 60.0;
  RemotePort body1(server1.endpoint(), definition.bodies[0].definition.name, port_options);
  RemotePort body2(server2.endpoint(), definition.bodies[1].definition.name, port_options);
  CoupledRunResult result = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  EXPECT_EQ(body2.server_name().rfind("robin-subdomain-py ", 0), 0u) << body2.server_name();
  body1.end_run();
  body2.end_run();
  return result;
}

void expect_equal_to_cpp(const std::string& case_file, const CoupledRunResult& run) {
  const CoupledRunResult& reference = cpp_reference(case_file);
  const RobinResult& a = run.iteration;
  const RobinResult& b = reference.iteration;
  ASSERT_EQ(b.status, IterationStatus::converged) << b.message;
  ASSERT_EQ(a.status, IterationStatus::converged) << a.message;
  EXPECT_EQ(a.history.size(), b.history.size());
  expect_same_interface_state(a, b, tolerance,
                              case_file + ", against the all-C++ run (" +
                                  std::to_string(a.history.size()) + " iterations)");
  for (int alpha = 0; alpha < 2; ++alpha) {
    EXPECT_EQ(run.outputs[alpha].mesh.nodes.size(), reference.outputs[alpha].mesh.nodes.size());
    EXPECT_TRUE(vectors_close(point_field(run.outputs[alpha], "displacement"),
                              point_field(reference.outputs[alpha], "displacement"), tolerance))
        << "body " << alpha + 1;
    EXPECT_TRUE(vectors_close(run.outputs[alpha].reaction_resultant,
                              reference.outputs[alpha].reaction_resultant, tolerance))
        << "body " << alpha + 1;
  }
}

TEST(PythonServer, TwoBlocksCppAndPythonEqualsAllCpp) {
  expect_equal_to_cpp("two_blocks.toml", run_with_python("two_blocks.toml", false));
}

TEST(PythonServer, TwoBlocksTwoPythonServersEqualsAllCpp) {
  expect_equal_to_cpp("two_blocks.toml", run_with_python("two_blocks.toml", true));
}

TEST(PythonServer, PartialContactCppAndPythonEqualsAllCpp) {
  expect_equal_to_cpp("two_blocks_partial.toml", run_with_python("two_blocks_partial.toml", false));
}

TEST(PythonServer, HertzCppAndPythonEqualsAllCpp) {
  expect_equal_to_cpp("hertz.toml", run_with_python("hertz.toml", false));
}

TEST(PythonServer, HertzTwoPythonServersEqualsAllCpp) {
  expect_equal_to_cpp("hertz.toml", run_with_python("hertz.toml", true));
}

TEST(PythonServer, PartialContactTwoPythonServersEqualsAllCpp) {
  expect_equal_to_cpp("two_blocks_partial.toml", run_with_python("two_blocks_partial.toml", true));
}

// The asymmetric pair: a cantilever loaded by a pressure on a block, stiffness ratio 10 and
// different boundary conditions (the case the default acceleration is for).
TEST(PythonServer, AsymmetricPairTwoPythonServersEqualsAllCpp) {
  expect_equal_to_cpp("asymmetric.toml", run_with_python("asymmetric.toml", true));
}

/// Every contact node of `boundary` by descending x, with `sign` times the normal that
/// `normals_from` (the same body on another server) gives at the same position: node-to-node
/// rows, each weighted by the node's boundary weight.
ContactOperator assignment_by_position(const InterfaceDescription& boundary,
                                       const InterfaceDescription& normals_from, double sign) {
  std::vector<std::size_t> order(boundary.node_ids.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return boundary.coordinates[a].x() > boundary.coordinates[b].x();
  });
  std::vector<int> nodes;
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> weights;
  for (const std::size_t k : order) {
    std::size_t nearest = 0;
    for (std::size_t j = 0; j < normals_from.coordinates.size(); ++j) {
      if ((normals_from.coordinates[j] - boundary.coordinates[k]).norm() <
          (normals_from.coordinates[nearest] - boundary.coordinates[k]).norm()) {
        nearest = j;
      }
    }
    EXPECT_LT((normals_from.coordinates[nearest] - boundary.coordinates[k]).norm(), 1e-12);
    nodes.push_back(boundary.node_ids[k]);
    normals.push_back(sign * normals_from.normals[nearest]);
    weights.push_back(normals_from.weights[nearest]);
  }
  return node_to_node_operator(nodes, normals, weights);
}

TEST(PythonServer, NeumannSolveEqualsTheCppServers) {
  const TemporaryDirectory logs("python-server-neumann");
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);  // SubdomainPort::setup sends the loaded mesh
  SubdomainServer cpp_server("cpp", server_options(logs.path()));
  SubdomainServer python_server("python", python_server_options(logs.path()));
  cpp_server.await_listening();
  python_server.await_listening();
  RemotePortOptions options;
  options.request_timeout_seconds = 60.0;
  for (int alpha = 0; alpha < 2; ++alpha) {
    const BodyCase& body = definition.bodies[alpha];
    RemotePort cpp(cpp_server.endpoint(), body.definition.name, options);
    RemotePort python(python_server.endpoint(), body.definition.name, options);
    const InterfaceDescription cpp_boundary = cpp.setup(body, definition.solver);
    const InterfaceDescription python_boundary = python.setup(body, definition.solver);
    ASSERT_EQ(cpp_boundary.node_ids.size(), python_boundary.node_ids.size());
    EXPECT_TRUE(python.offers("neumann_solve")) << python.server_name();
    const double sign = alpha == 0 ? 1.0 : -1.0;  // body 2 receives n2 = -n1
    const ContactOperator cpp_assignment = assignment_by_position(cpp_boundary, cpp_boundary, sign);
    const ContactOperator python_assignment =
        assignment_by_position(python_boundary, cpp_boundary, sign);
    cpp.assign_contact(cpp_assignment);
    python.assign_contact(python_assignment);
    Eigen::VectorXd force(cpp_assignment.row_count());
    for (Eigen::Index i = 0; i < force.size(); ++i) {  // by position: both use descending x
      force[i] = 1.0 + 0.5 * std::cos(1.3 * static_cast<double>(i));
    }
    cpp.start_neumann_solve(force, 1);
    python.start_neumann_solve(force, 1);
    const Eigen::VectorXd cpp_trace = cpp.finish_neumann_solve().normal_trace;
    const Eigen::VectorXd python_trace = python.finish_neumann_solve().normal_trace;
    std::cout << body.definition.name << ": max |u_N| " << cpp_trace.lpNorm<Eigen::Infinity>()
              << ", Python - C++ " << (python_trace - cpp_trace).lpNorm<Eigen::Infinity>() << "\n";
    EXPECT_GT(cpp_trace.lpNorm<Eigen::Infinity>(), 1e-4);
    EXPECT_TRUE(vectors_close(python_trace, cpp_trace, 1e-9)) << body.definition.name;
    cpp.end_run();
    python.end_run();
  }
}

TEST(PythonServer, PassesTheConformanceCheckIncludingTheNeumannSolve) {
  const TemporaryDirectory logs("python-server-conformance");
  SubdomainServer server("conformance", python_server_options(logs.path()));
  server.await_listening();
  ConformanceOptions options;
  options.reply_timeout_seconds = 30.0;
  options.oversized_message_bytes = 1L << 20;
  const ConformanceReport report = check_server(server.endpoint(), options);
  std::string failed;
  for (const ConformanceCheck& check : report.checks) {
    if (!check.passed) failed += "\n  " + check.name + ": " + check.explanation;
  }
  EXPECT_TRUE(report.conforms()) << failed;
  EXPECT_EQ(report.server_name.rfind("robin-subdomain-py ", 0), 0u) << report.server_name;
  for (const char* name :
       {"neumann_solve_before_setup", "neumann_solve_before_assignment",
        "neumann_solve_wrong_length", "neumann_solve_non_finite", "neumann_solve_free",
        "neumann_solve_equation", "neumann_solve_contact_consistency", "solid_setup_body",
        "solid_assign_contact", "solid_contact_solve", "solid_correction", "solid_neumann_solve",
        "solid_fields", "solid_end_run"}) {
    const auto found =
        std::find_if(report.checks.begin(), report.checks.end(),
                     [&](const ConformanceCheck& check) { return check.name == name; });
    ASSERT_NE(found, report.checks.end()) << name;
    EXPECT_TRUE(found->passed) << name << ": " << found->explanation;
  }
  // It solves the solid body (no "3D: not supported" note).
  const auto solid =
      std::find_if(report.checks.begin(), report.checks.end(),
                   [](const ConformanceCheck& check) { return check.name == "solid_setup_body"; });
  ASSERT_NE(solid, report.checks.end());
  EXPECT_EQ(solid->explanation, "");
  // It does not announce the optional "status" and must refuse StatusRequest.
  const auto refused = std::find_if(
      report.checks.begin(), report.checks.end(),
      [](const ConformanceCheck& check) { return check.name == "status_unannounced_refused"; });
  ASSERT_NE(refused, report.checks.end());
  EXPECT_TRUE(refused->passed) << refused->explanation;
}

/// Sends `frames` on a REQ socket and parses the reply.
protocol::Envelope exchange(zmq::socket_t& socket, const std::vector<std::string>& frames) {
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const auto flag = k + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
    socket.send(zmq::buffer(frames[k]), flag);
  }
  zmq::message_t message;
  EXPECT_TRUE(socket.recv(message));
  protocol::Envelope reply;
  EXPECT_TRUE(reply.ParseFromArray(message.data(), static_cast<int>(message.size())));
  EXPECT_EQ(reply.version().major(), protocol::protocol_major);
  return reply;
}

std::string hello_request(std::uint64_t request_id) {
  protocol::Envelope request;
  request.mutable_version()->set_major(protocol::protocol_major);
  request.set_request_id(request_id);
  request.mutable_hello()->set_client_name("python_server_test");
  return request.SerializeAsString();
}

/// Waits up to 10 s for the server's exit; its description ("" while it runs).
std::string await_exit(SubdomainServer& server) {
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const std::string failure = server.failure();
    if (!failure.empty()) return failure;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return "";
}

TEST(PythonServer, GarbageIsMalformedAndTheServerGoesOn) {
  const TemporaryDirectory logs("python-server-garbage");
  SubdomainServer server("lower", python_server_options(logs.path()));
  server.await_listening();
  EXPECT_EQ(server.endpoint().rfind("tcp://127.0.0.1:", 0), 0u) << server.endpoint();
  EXPECT_EQ(server.endpoint().find('*'), std::string::npos) << server.endpoint();
  zmq::context_t context;
  zmq::socket_t socket(context, zmq::socket_type::req);
  socket.set(zmq::sockopt::linger, 0);
  socket.set(zmq::sockopt::rcvtimeo, 20000);
  socket.connect(server.endpoint());
  for (const std::vector<std::string>& garbage :
       {std::vector<std::string>{std::string("\xff\xfe garbage", 10)},
        std::vector<std::string>{"two", "frames"}}) {
    const protocol::Envelope reply = exchange(socket, garbage);
    ASSERT_TRUE(reply.has_error());
    EXPECT_EQ(reply.error().code(), protocol::MALFORMED_MESSAGE) << reply.error().message();
    EXPECT_EQ(reply.error().state(), "awaiting_setup");
  }
  const protocol::Envelope hello = exchange(socket, {hello_request(42)});
  EXPECT_EQ(hello.request_id(), 42u);
  ASSERT_TRUE(hello.has_hello_reply());
  EXPECT_EQ(hello.hello_reply().state(), "awaiting_setup");
  EXPECT_EQ(server.failure(), "");
}

TEST(PythonServer, ShutdownSigtermAndSigintExitWithStatusZero) {
  const TemporaryDirectory logs("python-server-stop");
  for (const int signal_number : {0, SIGTERM, SIGINT}) {
    SubdomainServer server("upper", python_server_options(logs.path()));
    server.await_listening();
    if (signal_number == 0) {
      EXPECT_TRUE(request_server_shutdown(server.endpoint(), 10.0));
    } else {
      ASSERT_EQ(kill(server.pid(), signal_number), 0);
    }
    const std::string exit = await_exit(server);
    EXPECT_NE(exit.find("exited with status 0"), std::string::npos)
        << "signal " << signal_number << ": " << exit;
  }
}

}  // namespace
}  // namespace robin
