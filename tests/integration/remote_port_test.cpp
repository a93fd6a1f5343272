// RemotePort against real robin-subdomain processes (build/bin/robin-subdomain) on
// examples/two_blocks.toml:
//  - the coupled run over tcp://127.0.0.1:* and over ipc:// equals the in-process run
//    (InProcessPort, same iteration code, same numerics in this process) to 1e-12 in contact
//    forces, normal traces and displacement fields, with the same iteration count;
//  - a server killed (SIGKILL) after the first iteration ends the run with a PortError naming
//    the server and the step well before the 5 s request deadline;
//  - a server that never replies fails the handshake after the 2 s deadline, naming the
//    endpoint and "handshake";
//  - when neither server answers, the error names both servers and bodies;
//  - a server that answers the handshake but not SetupBody fails the setup at the setup
//    timeout (3 s), not at the shorter request timeout (1 s);
//  - a SetupBody above the server's --max-message-size fails at once naming the request's
//    size and the option, and the server answers the next connection's Hello;
//  - a server speaking protocol 3.x, and one speaking 1.x, is refused with both versions in
//    the message;
//  - protocol 1.2 runs: when a second coordinator (another RemotePort) sets up the server of a
//    run in progress, the first run's next contact solve fails with a PortError saying that the
//    body belongs to another run (before 1.2 it was answered from the other run's body), and
//    the first run's EndRun does not end the second run.

#include <gtest/gtest.h>
#include <signal.h>

#include <array>
#include <iostream>
#include <regex>
#include <thread>
#include <zmq.hpp>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "protocol_version.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

using testing::example;
using testing::expect_same_interface_state;
using testing::seconds_since;
using testing::server_options;
using testing::TemporaryDirectory;
using testing::vectors_close;

/// examples/two_blocks.toml with both meshes loaded (SubdomainPort::setup needs them).
CaseDefinition two_blocks() {
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);
  return definition;
}

RemotePortOptions port_options(double timeout_seconds) {
  RemotePortOptions options;
  options.request_timeout_seconds = timeout_seconds;
  return options;
}

const OutputField& point_field(const BodyOutput& output, const std::string& name) {
  for (const OutputField& field : output.point_fields) {
    if (field.name == name) return field;
  }
  throw std::runtime_error("no point field '" + name + "' in body '" + output.body_name + "'");
}

Eigen::VectorXd field_values(const OutputField& field) {
  return Eigen::Map<const Eigen::VectorXd>(field.values.data(),
                                           static_cast<Eigen::Index>(field.values.size()));
}

/// The in-process run of two_blocks.toml, computed once.
const CoupledRunResult& in_process_reference() {
  static const CoupledRunResult reference = [] {
    const CaseDefinition definition = two_blocks();
    InProcessPort body1, body2;
    CoupledRunResult result = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
    body1.end_run();
    body2.end_run();
    return result;
  }();
  return reference;
}

/// Runs two_blocks.toml on two servers listening on `listen1` / `listen2`.
CoupledRunResult run_on_servers(const std::string& listen1, const std::string& listen2) {
  const TemporaryDirectory logs("remote-port-logs");
  const CaseDefinition definition = two_blocks();
  SubdomainServer server1(definition.bodies[0].definition.name,
                          server_options(logs.path(), listen1));
  SubdomainServer server2(definition.bodies[1].definition.name,
                          server_options(logs.path(), listen2));
  server1.await_listening();
  server2.await_listening();
  RemotePort body1(server1.endpoint(), "lower", port_options(30.0));
  RemotePort body2(server2.endpoint(), "upper", port_options(30.0));
  CoupledRunResult result = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  body1.end_run();
  body2.end_run();
  return result;
}

void expect_equal_to_in_process(const CoupledRunResult& remote) {
  const CoupledRunResult& reference = in_process_reference();
  ASSERT_EQ(reference.iteration.status, IterationStatus::converged) << reference.iteration.message;
  EXPECT_EQ(remote.iteration.status, IterationStatus::converged) << remote.iteration.message;
  EXPECT_EQ(remote.iteration.history.size(), reference.iteration.history.size());
  expect_same_interface_state(remote.iteration, reference.iteration, 1e-12, "in-process run");
  for (int alpha = 0; alpha < 2; ++alpha) {
    EXPECT_TRUE(vectors_close(field_values(point_field(remote.outputs[alpha], "displacement")),
                              field_values(point_field(reference.outputs[alpha], "displacement")),
                              1e-12))
        << "body " << alpha + 1;
    EXPECT_EQ(remote.outputs[alpha].mesh.nodes.size(), reference.outputs[alpha].mesh.nodes.size());
    EXPECT_GT(remote.port_timings[alpha].bytes_sent, 0);
    EXPECT_GT(remote.port_timings[alpha].bytes_received, 0);
    EXPECT_GE(remote.port_timings[alpha].round_trip_seconds,
              remote.port_timings[alpha].compute_seconds);
  }
}

TEST(RemotePort, TcpRunEqualsInProcessRun) {
  expect_equal_to_in_process(run_on_servers("tcp://127.0.0.1:*", "tcp://127.0.0.1:*"));
}

TEST(RemotePort, IpcRunEqualsInProcessRun) {
  const std::string base = "/tmp/robin-remote-test-" + std::to_string(getpid());
  expect_equal_to_in_process(
      run_on_servers("ipc://" + base + "-1.ipc", "ipc://" + base + "-2.ipc"));
  std::filesystem::remove(base + "-1.ipc");
  std::filesystem::remove(base + "-2.ipc");
}

TEST(RemotePort, KilledServerEndsTheRunWithAPortError) {
  const TemporaryDirectory logs("remote-port-kill");
  const CaseDefinition definition = two_blocks();
  SubdomainServer server1("lower", server_options(logs.path()));
  SubdomainServer server2("upper", server_options(logs.path()));
  server1.await_listening();
  server2.await_listening();
  const double timeout = 5.0;
  RemotePort body1(server1.endpoint(), "lower", port_options(timeout));
  RemotePort body2(server2.endpoint(), "upper", port_options(timeout));
  RunObserver observer;
  auto killed_at = std::chrono::steady_clock::now();
  observer.iteration = [&](const IterationRecord& record) {
    if (record.iteration != 1) return;
    ASSERT_EQ(kill(server2.pid(), SIGKILL), 0);
    killed_at = std::chrono::steady_clock::now();
  };
  CouplingOptions options = definition.coupling;
  options.request_timeout_seconds = timeout;
  options.tolerance = 1e-300;  // the run must go on after the first iteration
  try {
    run_coupled_case(definition, {&body1, &body2}, options, observer);
    FAIL() << "the run went on without the killed server";
  } catch (const PortError& error) {
    const double elapsed = seconds_since(killed_at);
    const std::string message = error.what();
    std::cout << "failed " << elapsed << " s after the kill: " << message << "\n";
    EXPECT_NE(message.find("server " + server2.endpoint() + " (body 'upper')"), std::string::npos)
        << message;
    EXPECT_NE(message.find("step contact solve (iteration 2)"), std::string::npos) << message;
    EXPECT_LT(elapsed, timeout + 1.0) << message;
    EXPECT_LT(elapsed, 1.0) << "the disconnect was not detected before the deadline: " << message;
  }
  body1.end_run();
  body2.end_run();
}

TEST(RemotePort, SilentServerFailsTheHandshakeAtTheDeadline) {
  zmq::context_t context;
  zmq::socket_t silent(context, zmq::socket_type::rep);
  silent.set(zmq::sockopt::linger, 0);
  silent.bind("tcp://127.0.0.1:*");
  const std::string endpoint = silent.get(zmq::sockopt::last_endpoint);
  const CaseDefinition definition = two_blocks();
  RemotePort port(endpoint, "lower", port_options(2.0));
  const auto start = std::chrono::steady_clock::now();
  try {
    port.setup(definition.bodies[0], definition.solver);
    FAIL() << "setup succeeded against a server that never replies";
  } catch (const PortError& error) {
    const double elapsed = seconds_since(start);
    const std::string message = error.what();
    std::cout << "failed after " << elapsed << " s: " << message << "\n";
    EXPECT_NE(message.find("server " + endpoint), std::string::npos) << message;
    EXPECT_NE(message.find("step handshake"), std::string::npos) << message;
    EXPECT_NE(message.find("no reply within 2 s"), std::string::npos) << message;
    EXPECT_GE(elapsed, 2.0 - 0.05);
    EXPECT_LT(elapsed, 2.0 + 1.0);
  }
  zmq::message_t request;
  EXPECT_TRUE(silent.recv(request, zmq::recv_flags::dontwait)) << "the Hello never arrived";
}

TEST(RemotePort, FailureOfBothServersNamesBoth) {
  // Two bound REP sockets that never reply: both handshakes fail at the 1 s deadline.
  zmq::context_t context;
  std::array<zmq::socket_t, 2> silent{zmq::socket_t(context, zmq::socket_type::rep),
                                      zmq::socket_t(context, zmq::socket_type::rep)};
  std::array<std::string, 2> endpoints;
  for (int alpha = 0; alpha < 2; ++alpha) {
    silent[alpha].set(zmq::sockopt::linger, 0);
    silent[alpha].bind("tcp://127.0.0.1:*");
    endpoints[alpha] = silent[alpha].get(zmq::sockopt::last_endpoint);
  }
  const CaseDefinition definition = two_blocks();
  RemotePort body1(endpoints[0], "lower", port_options(1.0));
  RemotePort body2(endpoints[1], "upper", port_options(1.0));
  try {
    run_coupled_case(definition, {&body1, &body2}, definition.coupling);
    FAIL() << "the run succeeded without servers";
  } catch (const PortError& error) {
    const std::string message = error.what();
    std::cout << message << "\n";
    for (int alpha = 0; alpha < 2; ++alpha) {
      EXPECT_NE(message.find("server " + endpoints[alpha]), std::string::npos) << message;
    }
    EXPECT_NE(message.find("body 'lower'"), std::string::npos) << message;
    EXPECT_NE(message.find("body 'upper'"), std::string::npos) << message;
  }
}

/// A REP server that answers the first request (a Hello) with a valid HelloReply and then
/// receives the next request (SetupBody) without ever answering it.
/// How the test server deviates in its HelloReply.
enum class HelloDeviation { none, no_version, wrong_request_id };

class HandshakeOnlyServer {
 public:
  explicit HandshakeOnlyServer(HelloDeviation deviation = HelloDeviation::none)
      : socket_(context_, zmq::socket_type::rep), deviation_(deviation) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.set(zmq::sockopt::rcvtimeo, 3000);
    socket_.bind("tcp://127.0.0.1:*");
    endpoint_ = socket_.get(zmq::sockopt::last_endpoint);
    thread_ = std::thread([this] { serve(); });
  }
  ~HandshakeOnlyServer() {
    if (thread_.joinable()) thread_.join();
  }
  const std::string& endpoint() const { return endpoint_; }
  /// Waits for the server thread (it ends once SetupBody arrived, or 3 s after the last message
  /// without it); true when a SetupBody request arrived.
  bool setup_arrived() {
    thread_.join();
    return setup_arrived_;
  }

 private:
  void serve() {
    zmq::message_t message;
    if (!socket_.recv(message)) return;
    protocol::Envelope hello;
    hello.ParseFromArray(message.data(), static_cast<int>(message.size()));
    protocol::Envelope reply;
    if (deviation_ != HelloDeviation::no_version) {
      reply.mutable_version()->set_major(protocol::protocol_major);
      reply.mutable_version()->set_minor(protocol::protocol_minor);
    }
    reply.set_request_id(hello.request_id() +
                         (deviation_ == HelloDeviation::wrong_request_id ? 1000 : 0));
    for (const char* capability : {"contact_solve", "correction_solve", "fields"})
      reply.mutable_hello_reply()->add_capabilities(capability);
    reply.mutable_hello_reply()->set_server_name("handshake only");
    const std::string bytes = reply.SerializeAsString();
    socket_.send(zmq::buffer(bytes));
    zmq::message_t setup;
    if (socket_.recv(setup)) {
      protocol::Envelope request;
      setup_arrived_ = request.ParseFromArray(setup.data(), static_cast<int>(setup.size())) &&
                       request.has_setup_body();
    }
  }

  zmq::context_t context_;
  zmq::socket_t socket_;
  HelloDeviation deviation_;
  std::string endpoint_;
  std::thread thread_;
  bool setup_arrived_ = false;
};

TEST(RemotePort, SetupHasItsOwnDeadline) {
  const CaseDefinition definition = two_blocks();
  HandshakeOnlyServer server;
  RemotePortOptions options = port_options(1.0);
  options.setup_timeout_seconds = 3.0;
  RemotePort port(server.endpoint(), "lower", options);
  const auto start = std::chrono::steady_clock::now();
  std::string message;
  try {
    port.setup(definition.bodies[0], definition.solver);
    ADD_FAILURE() << "setup succeeded against a server that never answers it";
  } catch (const PortError& error) {
    message = error.what();
  }
  const double elapsed = seconds_since(start);
  std::cout << "failed after " << elapsed << " s: " << message << "\n";
  EXPECT_NE(message.find("server " + server.endpoint()), std::string::npos) << message;
  EXPECT_NE(message.find("step setup"), std::string::npos) << message;
  EXPECT_NE(message.find("no reply within 3 s"), std::string::npos) << message;
  EXPECT_GE(elapsed, 3.0 - 0.05);
  EXPECT_LT(elapsed, 3.0 + 1.0);
  EXPECT_TRUE(server.setup_arrived()) << "the handshake did not lead to a SetupBody request";
}

/// The PortError message of a setup against a server whose HelloReply deviates.
std::string handshake_failure(HelloDeviation deviation) {
  HandshakeOnlyServer server(deviation);
  const CaseDefinition definition = two_blocks();
  RemotePort port(server.endpoint(), "lower", port_options(1.0));
  try {
    port.setup(definition.bodies[0], definition.solver);
  } catch (const PortError& error) {
    std::cout << error.what() << "\n";
    return error.what();
  }
  return "";
}

TEST(RemotePort, ReplyWithoutVersionOrWithAnotherRequestIdIsNamed) {
  const std::string no_version = handshake_failure(HelloDeviation::no_version);
  EXPECT_NE(no_version.find("step handshake"), std::string::npos) << no_version;
  EXPECT_NE(no_version.find("carries no protocol version"), std::string::npos) << no_version;
  const std::string wrong_id = handshake_failure(HelloDeviation::wrong_request_id);
  EXPECT_NE(wrong_id.find("no reply within 1 s (1 replies with another request_id"),
            std::string::npos)
      << wrong_id;
}

TEST(RemotePort, ServerOfAnotherMajorVersionIsRefused) {
  const TemporaryDirectory logs("remote-port-version");
  ServerLaunchOptions options = server_options(logs.path());
  options.extra_arguments = {"--protocol-major", "3"};
  SubdomainServer server("lower", options);
  server.await_listening();
  const CaseDefinition definition = two_blocks();
  RemotePort port(server.endpoint(), "lower", port_options(5.0));
  try {
    port.setup(definition.bodies[0], definition.solver);
    FAIL() << "a protocol 3 server was accepted";
  } catch (const PortError& error) {
    const std::string message = error.what();
    std::cout << message << "\n";
    EXPECT_NE(message.find("server " + server.endpoint()), std::string::npos) << message;
    EXPECT_NE(message.find("speaks protocol 3."), std::string::npos) << message;
    EXPECT_NE(message.find("this coordinator speaks 2."), std::string::npos) << message;
  }
}

// Issue 12: a server of protocol 1.x (robin-subdomain --protocol-major 1 announces 1.x, as a
// server built before protocol 2 does) gets a clear refusal naming both versions.
TEST(RemotePort, ServerOfProtocolOneIsRefusedNamingBothVersions) {
  const TemporaryDirectory logs("remote-port-version-1");
  ServerLaunchOptions options = server_options(logs.path());
  options.extra_arguments = {"--protocol-major", "1"};
  SubdomainServer server("lower", options);
  server.await_listening();
  const CaseDefinition definition = two_blocks();
  RemotePort port(server.endpoint(), "lower", port_options(5.0));
  try {
    port.setup(definition.bodies[0], definition.solver);
    FAIL() << "a protocol 1 server was accepted";
  } catch (const PortError& error) {
    const std::string message = error.what();
    std::cout << message << "\n";
    EXPECT_NE(message.find("server " + server.endpoint()), std::string::npos) << message;
    EXPECT_NE(message.find("step handshake"), std::string::npos) << message;
    EXPECT_NE(message.find("the server speaks protocol 1."), std::string::npos) << message;
    EXPECT_NE(message.find("this coordinator speaks 2."), std::string::npos) << message;
  }
}

// Issue 11: robin-subdomain --max-message-size 1000 closes the connection, without a reply, to
// a SetupBody above 1000 bytes (libzmq's ZMQ_MAXMSGSIZE). The setup fails at once (well
// before the 10 s deadline) with a PortError naming the step, the size of the unanswered
// request and the server's option; the server neither crashed nor hangs: it answers the Hello
// of a new connection.
TEST(RemotePort, RequestAboveTheServersMaximumMessageSizeIsNamed) {
  const TemporaryDirectory logs("remote-port-message-size");
  ServerLaunchOptions options = server_options(logs.path());
  options.extra_arguments = {"--max-message-size", "1000"};
  SubdomainServer server("lower", options);
  server.await_listening();
  const CaseDefinition definition = two_blocks();
  {
    RemotePort port(server.endpoint(), "lower", port_options(10.0));
    const auto start = std::chrono::steady_clock::now();
    try {
      port.setup(definition.bodies[0], definition.solver);
      FAIL() << "a SetupBody above 1000 bytes was answered";
    } catch (const PortError& error) {
      const std::string message = error.what();
      std::cout << message << "\n";
      EXPECT_LT(seconds_since(start), 5.0) << message;
      EXPECT_NE(message.find("step setup"), std::string::npos) << message;
      const std::smatch size = [&message] {
        std::smatch match;
        std::regex_search(message, match, std::regex("the request of ([0-9]+) bytes"));
        return match;
      }();
      ASSERT_FALSE(size.empty()) << message;
      EXPECT_GT(std::stol(size[1].str()), 1000) << message;
      EXPECT_NE(message.find("was unanswered"), std::string::npos) << message;
      EXPECT_NE(message.find("larger than its maximum message size (robin-subdomain "
                             "--max-message-size BYTES"),
                std::string::npos)
          << message;
    }
  }
  zmq::context_t context;
  zmq::socket_t socket(context, zmq::socket_type::req);
  socket.set(zmq::sockopt::linger, 0);
  socket.set(zmq::sockopt::rcvtimeo, 5000);
  socket.connect(server.endpoint());
  protocol::Envelope hello;
  hello.set_request_id(1);
  hello.mutable_version()->set_major(protocol::protocol_major);
  hello.mutable_hello();
  ASSERT_TRUE(socket.send(zmq::buffer(hello.SerializeAsString()), zmq::send_flags::none));
  zmq::message_t answer;
  ASSERT_TRUE(socket.recv(answer)) << "no reply to Hello after the refused request";
  protocol::Envelope reply;
  ASSERT_TRUE(reply.ParseFromArray(answer.data(), static_cast<int>(answer.size())));
  EXPECT_TRUE(reply.has_hello_reply()) << reply.DebugString();
  EXPECT_EQ(kill(server.pid(), 0), 0) << "the server process is gone";
}

TEST(RemotePort, SecondCoordinatorTakingTheServerOverFailsTheFirstRun) {
  const TemporaryDirectory logs("remote-port-takeover");
  const CaseDefinition definition = two_blocks();
  SubdomainServer server("lower", server_options(logs.path()));
  server.await_listening();
  RemotePort first(server.endpoint(), "lower", port_options(10.0));
  const InterfaceDescription interface = first.setup(definition.bodies[0], definition.solver);
  const ContactOperator assignment =
      node_to_node_operator(interface.node_ids, interface.normals, interface.weights);
  first.assign_contact(assignment);
  const Eigen::VectorXd obstacle =
      Eigen::VectorXd::Constant(static_cast<Eigen::Index>(interface.node_ids.size()), 1.0);
  first.start_contact_solve(obstacle, 1);
  EXPECT_EQ(first.finish_contact_solve().status, QpStatus::converged);

  // Another coordinator sets the same body up on the same server: the contact sizes match, so
  // before protocol 1.2 the first run went on, silently answered from the other run's body.
  RemotePort second(server.endpoint(), "lower", port_options(10.0));
  second.setup(definition.bodies[0], definition.solver);
  second.assign_contact(assignment);
  EXPECT_EQ(first.run_id().size(), 32u);
  EXPECT_NE(first.run_id(), second.run_id());
  try {
    first.start_contact_solve(obstacle, 2);
    first.finish_contact_solve();
    ADD_FAILURE() << "the first run was answered from the second run's body";
  } catch (const PortError& error) {
    const std::string message = error.what();
    std::cout << message << "\n";
    EXPECT_NE(message.find("server " + server.endpoint() + " (body 'lower')"), std::string::npos)
        << message;
    EXPECT_NE(message.find("step contact solve (iteration 2)"), std::string::npos) << message;
    EXPECT_NE(message.find("WRONG_STATE"), std::string::npos) << message;
    EXPECT_NE(message.find("another run"), std::string::npos) << message;
  }
  first.end_run();  // refused by the server: it must not end the second run
  second.start_contact_solve(obstacle, 1);
  EXPECT_EQ(second.finish_contact_solve().status, QpStatus::converged);
  second.end_run();
}

}  // namespace
}  // namespace robin
