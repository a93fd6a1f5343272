// Heartbeat and setup progress (protocol 2.1, capability "status"; remote/server_heartbeat.hpp):
//  - robin-subdomain answers StatusRequest on a second connection while it sets a large body
//    up: the port reports the stages in their order (mesh, assembly, ordering, factorization)
//    with the body's DOFs (2 per node of the mesh this test built), and a setup that lasts
//    longer than the heartbeat timeout succeeds because the server keeps answering;
//  - a second client's Hello sent during that setup is answered (queued behind it, not lost);
//  - a server that announced "status" and then stops answering (its socket thread hung, its
//    connection alive) fails the setup with "no heartbeat", naming server, body and step, long
//    before the setup deadline;
//  - a protocol 2.0 server (no "status") gets no StatusRequest and is waited for as before;
//  - a client that disconnects while its SetupBody runs and its next request waits in the
//    queue: robin-subdomain drops the queued request and abandons the setup at its next stage
//    (the state stays awaiting_setup, which a completed setup would have left), logs both, and
//    answers the next client.

#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <iterator>
#include <thread>
#include <zmq.hpp>

#include "coupling/case_file.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"
#include "protocol_version.hpp"
#include "remote/remote_port.hpp"
#include "remote/server_launcher.hpp"
#include "remote/setup_encoding.hpp"
#include "remote_test_support.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

using testing::server_options;
using testing::TemporaryDirectory;

/// A 240 x 240 square of triangles, fixed at the bottom, its top the contact boundary.
BodyCase large_square_body() {
  BodyCase body;
  body.definition.name = "square";
  body.definition.mesh = make_rectangle_mesh(0.0, 0.0, 1.0, 1.0, 240, 240, ElementType::triangle3);
  body.definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  body.definition.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  body.definition.contact_boundaries = {"top"};
  body.context = "server_heartbeat_test: body 'square'";
  return body;
}

int stage_rank(const std::string& stage) {
  const std::vector<std::string> order = {"mesh", "assembly", "ordering", "factorization"};
  const auto found = std::find(order.begin(), order.end(), stage);
  return found == order.end() ? -1 : static_cast<int>(found - order.begin());
}

TEST(ServerHeartbeat, ReportsTheSetupStagesOfARealServerAndWaitsForItWhileItAnswers) {
  const TemporaryDirectory logs("heartbeat-real");
  SubdomainServer server("square", server_options(logs.path()));
  server.await_listening();
  RemotePortOptions options;
  options.heartbeat_timeout_seconds = 0.3;  // far below the setup's duration on this mesh
  options.heartbeat_interval_seconds = 0.02;
  std::vector<ServerStatus> statuses;
  std::vector<std::string> steps;
  options.on_status = [&](const std::string& body, const std::string& step,
                          const ServerStatus& status) {
    EXPECT_EQ(body, "square");
    steps.push_back(step);
    statuses.push_back(status);
  };
  RemotePort port(server.endpoint(), "square", options);
  const BodyCase body = large_square_body();
  const long dof_count = 2L * static_cast<long>(body.definition.mesh.node_count());
  ASSERT_EQ(dof_count, 2L * 241 * 241);

  // A second client during the setup: its Hello waits behind the SetupBody and is answered.
  std::atomic<bool> hello_answered{false};
  std::thread second_client([&] {
    zmq::context_t context;
    zmq::socket_t socket(context, zmq::socket_type::req);
    socket.set(zmq::sockopt::linger, 0);
    socket.set(zmq::sockopt::rcvtimeo, 120000);
    socket.connect(server.endpoint());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // while the setup runs
    protocol::Envelope hello;
    hello.mutable_version()->set_major(protocol::protocol_major);
    hello.mutable_version()->set_minor(protocol::protocol_minor);
    hello.set_request_id(77);
    hello.mutable_hello()->set_client_name("second client");
    socket.send(zmq::buffer(hello.SerializeAsString()), zmq::send_flags::none);
    zmq::message_t message;
    if (!socket.recv(message, zmq::recv_flags::none)) return;
    protocol::Envelope reply;
    hello_answered = reply.ParseFromArray(message.data(), static_cast<int>(message.size())) &&
                     reply.request_id() == 77 && reply.has_hello_reply();
  });
  const InterfaceDescription interface = port.setup(body, SolverOptions{});
  second_client.join();
  EXPECT_TRUE(hello_answered);
  EXPECT_TRUE(port.offers("status"));
  EXPECT_EQ(interface.node_ids.size(), 241u);  // the top edge's nodes

  ASSERT_FALSE(statuses.empty()) << "no StatusReply during a setup of " << dof_count << " DOFs";
  int previous_rank = -1;
  bool dofs_reported = false;
  for (std::size_t k = 0; k < statuses.size(); ++k) {
    const ServerStatus& status = statuses[k];
    EXPECT_EQ(steps[k], "setup");
    if (!status.busy) continue;  // answered just before or after the request
    EXPECT_EQ(status.request_type, "SetupBody");
    const int rank = stage_rank(status.stage);
    EXPECT_GE(rank, 0) << "unknown stage '" << status.stage << "'";
    EXPECT_GE(rank, previous_rank) << "stage '" << status.stage << "' after an earlier one";
    previous_rank = std::max(previous_rank, rank);
    if (rank >= 1) {
      EXPECT_EQ(status.dof_count, dof_count) << "stage " << status.stage;
      dofs_reported = true;
    }
    EXPECT_GE(status.request_seconds, status.stage_seconds);
  }
  EXPECT_TRUE(dofs_reported) << statuses.size() << " statuses, none after the mesh stage";
  port.end_run();
}

/// A server played by a thread: a ROUTER that answers Hello (announcing "status" or not, with
/// the given minor version) and never answers anything else.
class SilentServer {
 public:
  SilentServer(bool announce_status, unsigned minor) : socket_(context_, zmq::socket_type::router) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.bind("tcp://127.0.0.1:*");
    endpoint_ = socket_.get(zmq::sockopt::last_endpoint);
    thread_ = std::thread([this, announce_status, minor] { serve(announce_status, minor); });
  }
  ~SilentServer() {
    stop_ = true;
    thread_.join();
  }
  const std::string& endpoint() const { return endpoint_; }
  int status_requests() const { return status_requests_; }

 private:
  void serve(bool announce_status, unsigned minor) {
    while (!stop_) {
      zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(20));
      if ((item.revents & ZMQ_POLLIN) == 0) continue;
      std::vector<zmq::message_t> frames;
      do {
        frames.emplace_back();
        (void)socket_.recv(frames.back(), zmq::recv_flags::none);
      } while (frames.back().more());
      protocol::Envelope request;
      if (frames.size() != 3 ||
          !request.ParseFromArray(frames[2].data(), static_cast<int>(frames[2].size()))) {
        continue;
      }
      if (request.has_status_request()) ++status_requests_;
      if (!request.has_hello()) continue;  // silent from now on
      protocol::Envelope reply;
      reply.mutable_version()->set_major(protocol::protocol_major);
      reply.mutable_version()->set_minor(minor);
      reply.set_request_id(request.request_id());
      protocol::HelloReply& hello = *reply.mutable_hello_reply();
      hello.set_server_name("silent test server");
      hello.set_state("awaiting_setup");
      for (const char* capability : {"contact_solve", "correction_solve", "fields"}) {
        hello.add_capabilities(capability);
      }
      if (announce_status) hello.add_capabilities("status");
      socket_.send(frames[0], zmq::send_flags::sndmore);
      socket_.send(zmq::message_t(), zmq::send_flags::sndmore);
      socket_.send(zmq::buffer(reply.SerializeAsString()), zmq::send_flags::none);
    }
  }

  zmq::context_t context_;
  zmq::socket_t socket_;
  std::string endpoint_;
  std::atomic<bool> stop_{false};
  std::atomic<int> status_requests_{0};
  std::thread thread_;
};

BodyCase small_square_body() {
  BodyCase body = large_square_body();
  body.definition.mesh = make_rectangle_mesh(0.0, 0.0, 1.0, 1.0, 4, 4, ElementType::triangle3);
  return body;
}

/// The PortError message of a setup on `server` (a failure when the setup succeeds).
std::string setup_failure(const SilentServer& server, const RemotePortOptions& options) {
  RemotePort port(server.endpoint(), "square", options);
  try {
    port.setup(small_square_body(), SolverOptions{});
  } catch (const PortError& error) {
    return error.what();
  }
  ADD_FAILURE() << "the setup on a silent server succeeded";
  return "";
}

TEST(ServerHeartbeat, AHungServerFailsTheSetupWithNoHeartbeatLongBeforeItsDeadline) {
  SilentServer server(true, protocol::protocol_minor);
  RemotePortOptions options;
  options.setup_timeout_seconds = 600.0;
  options.heartbeat_timeout_seconds = 1.0;
  options.heartbeat_interval_seconds = 0.1;
  const std::string message = setup_failure(server, options);
  EXPECT_NE(message.find("server " + server.endpoint() + " (body 'square'), step setup: "),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("no heartbeat for 1 s"), std::string::npos) << message;
  EXPECT_NE(message.find("it never answered a StatusRequest"), std::string::npos) << message;
  EXPECT_GE(server.status_requests(), 1);
}

TEST(ServerHeartbeat, AProtocol20ServerGetsNoStatusRequestAndIsWaitedForAsBefore) {
  SilentServer server(false, 0);
  RemotePortOptions options;
  options.setup_timeout_seconds = 1.5;
  options.heartbeat_timeout_seconds = 0.2;
  const std::string message = setup_failure(server, options);
  EXPECT_NE(message.find("step setup: no reply within 1.5 s"), std::string::npos) << message;
  EXPECT_EQ(server.status_requests(), 0);
}

/// A client of a real server speaking the protocol on a DEALER socket (several requests may
/// be in flight); request ids are its own.
class RawClient {
 public:
  explicit RawClient(const std::string& endpoint) : socket_(context_, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.connect(endpoint);
  }
  void send(protocol::Envelope request) {
    request.mutable_version()->set_major(protocol::protocol_major);
    request.mutable_version()->set_minor(protocol::protocol_minor);
    socket_.send(zmq::message_t(), zmq::send_flags::sndmore);
    socket_.send(zmq::buffer(request.SerializeAsString()), zmq::send_flags::none);
  }
  /// The next reply, waiting at most `seconds` (a failure when none comes).
  protocol::Envelope receive(double seconds) {
    protocol::Envelope reply;
    zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
    if ((item.revents & ZMQ_POLLIN) == 0) {
      ADD_FAILURE() << "no reply within " << seconds << " s";
      return reply;
    }
    zmq::message_t delimiter;
    zmq::message_t payload;
    (void)socket_.recv(delimiter, zmq::recv_flags::none);
    (void)socket_.recv(payload, zmq::recv_flags::none);
    EXPECT_TRUE(reply.ParseFromArray(payload.data(), static_cast<int>(payload.size())));
    return reply;
  }
  protocol::StatusReply status() {
    protocol::Envelope request;
    request.set_request_id(++status_requests_);
    request.mutable_status_request();
    send(request);
    return receive(30.0).status_reply();
  }
  void close() { socket_.close(); }

 private:
  zmq::context_t context_;
  zmq::socket_t socket_;
  std::uint64_t status_requests_ = 1000;
};

std::string file_text(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

TEST(ServerHeartbeat, TheRequestsOfAClientThatDisconnectsAreDroppedAndItsSetupAbandoned) {
  const TemporaryDirectory logs("heartbeat-abandon");
  SubdomainServer server("square", server_options(logs.path()));
  server.await_listening();
  BodyCase body = large_square_body();
  body.definition.mesh = make_rectangle_mesh(0.0, 0.0, 1.0, 1.0, 400, 400, ElementType::triangle3);

  RawClient departing(server.endpoint());
  protocol::Envelope setup;
  setup.set_request_id(1);
  *setup.mutable_setup_body() = encode_setup_body(body.definition, body.context, SolverOptions{});
  departing.send(setup);
  protocol::Envelope hello;
  hello.set_request_id(2);
  hello.mutable_hello()->set_client_name("departing client");
  departing.send(hello);  // waits behind the setup

  // Leave while the setup is in an early stage with the Hello queued behind it.
  RawClient observer(server.endpoint());
  const auto start = std::chrono::steady_clock::now();
  protocol::StatusReply status;
  do {
    status = observer.status();
  } while (!(status.busy() && status.queued_requests() == 1 &&
             (status.stage() == "mesh" || status.stage() == "assembly")) &&
           testing::seconds_since(start) < 60.0);
  ASSERT_TRUE(status.busy()) << "the setup never showed its first stages";
  departing.close();

  do {
    status = observer.status();
  } while (status.busy() && testing::seconds_since(start) < 120.0);
  EXPECT_FALSE(status.busy());
  EXPECT_EQ(status.queued_requests(), 0u);
  EXPECT_EQ(status.state(), "awaiting_setup")
      << "the setup ran to its end (stage " << status.stage() << ")";

  protocol::Envelope second_hello;
  second_hello.set_request_id(3);
  second_hello.mutable_hello()->set_client_name("next client");
  observer.send(second_hello);
  const protocol::Envelope reply = observer.receive(30.0);
  EXPECT_EQ(reply.request_id(), 3u);
  EXPECT_TRUE(reply.has_hello_reply());
  EXPECT_EQ(reply.hello_reply().state(), "awaiting_setup");

  const std::string log = file_text(server.log_file());
  EXPECT_NE(log.find("a client disconnected: dropped its 1 queued request(s)"), std::string::npos)
      << log;
  EXPECT_NE(log.find("abandoned before the stage"), std::string::npos) << log;
}

}  // namespace
}  // namespace robin
