// The real robin-subdomain executable (build/bin), started as a child process with its stdout
// on a pipe: the "listening on" line, error replies that leave it running, Shutdown and
// signals (exit code 0), ipc:// endpoints, bind failures (exit code 1 and a message naming the
// endpoint), the hidden --protocol-major flag, --max-message-size, and one contact solve over
// the wire compared with a BodySolver built in this process.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>
#include <zmq.hpp>

#include "numerics/body_solver.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/material.hpp"
#include "protocol_version.hpp"
#include "robin.pb.h"

extern char** environ;

namespace robin {
namespace {

using namespace std::chrono_literals;

const std::filesystem::path server_binary =
    std::filesystem::path(ROBIN_BINARY_DIR) / "bin/robin-subdomain";
const std::filesystem::path lower_geo =
    std::filesystem::path(ROBIN_EXAMPLES) / "meshes/block_lower.geo";

/// A unique path under the temporary directory for this process.
std::filesystem::path temporary_path(const std::string& label) {
  static int counter = 0;
  return std::filesystem::temp_directory_path() /
         ("robin-subdomain-process-" + std::to_string(getpid()) + "-" + label + "-" +
          std::to_string(counter++));
}

/// robin-subdomain running as a child: stdout on a pipe (for the "listening on" line), stderr
/// in a file. Killed (SIGKILL) and reaped at destruction if still running.
class ServerProcess {
 public:
  explicit ServerProcess(const std::vector<std::string>& arguments)
      : stderr_path_(temporary_path("stderr")) {
    int pipe_ends[2];
    if (pipe(pipe_ends) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipe_ends[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, pipe_ends[0]);
    posix_spawn_file_actions_addclose(&actions, pipe_ends[1]);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_path_.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> words = {server_binary.string()};
    words.insert(words.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& word : words) argv.push_back(word.data());
    argv.push_back(nullptr);
    const int status = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(pipe_ends[1]);
    stdout_ = pipe_ends[0];
    if (status != 0) throw std::runtime_error("cannot start " + server_binary.string());
  }

  ~ServerProcess() {
    if (!exit_status_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    close(stdout_);
    std::filesystem::remove(stderr_path_);
  }

  /// The first line of stdout (without the newline), or "" when stdout closes or `timeout`
  /// passes first.
  std::string read_line(std::chrono::milliseconds timeout = 20s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::string line;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      pollfd descriptor{stdout_, POLLIN, 0};
      if (left.count() <= 0 || poll(&descriptor, 1, static_cast<int>(left.count())) <= 0) return "";
      char character;
      if (read(stdout_, &character, 1) != 1) return "";
      if (character == '\n') return line;
      line += character;
    }
  }

  /// The endpoint of the "listening on ENDPOINT" line ("" if the line is not that).
  std::string endpoint() {
    const std::string line = read_line();
    const std::string prefix = "listening on ";
    return line.rfind(prefix, 0) == 0 ? line.substr(prefix.size()) : "";
  }

  /// The exit code, or nullopt when the process has not exited normally within `timeout`.
  std::optional<int> wait_for_exit(std::chrono::milliseconds timeout = 10s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!exit_status_ && std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exit_status_ = status;
      } else {
        std::this_thread::sleep_for(10ms);
      }
    }
    if (!exit_status_ || !WIFEXITED(*exit_status_)) return std::nullopt;
    return WEXITSTATUS(*exit_status_);
  }

  void signal(int number) { kill(pid_, number); }

  std::string stderr_text() const {
    std::ifstream stream(stderr_path_);
    std::ostringstream text;
    text << stream.rdbuf();
    return text.str();
  }

 private:
  pid_t pid_ = -1;
  int stdout_ = -1;
  std::filesystem::path stderr_path_;
  std::optional<int> exit_status_;
};

/// A REQ socket connected to `endpoint`, giving up on a reply after `receive_timeout`.
zmq::socket_t connect(zmq::context_t& context, const std::string& endpoint,
                      std::chrono::milliseconds receive_timeout = 10s) {
  zmq::socket_t socket(context, zmq::socket_type::req);
  socket.set(zmq::sockopt::linger, 0);
  socket.set(zmq::sockopt::rcvtimeo, static_cast<int>(receive_timeout.count()));
  socket.connect(endpoint);
  return socket;
}

/// Sends `bytes` as one message; the parsed reply, or nullopt when none arrives in time.
std::optional<protocol::Envelope> exchange_bytes(zmq::socket_t& socket, const std::string& bytes) {
  socket.send(zmq::buffer(bytes), zmq::send_flags::none);
  zmq::message_t message;
  if (!socket.recv(message, zmq::recv_flags::none)) return std::nullopt;
  protocol::Envelope reply;
  EXPECT_TRUE(reply.ParseFromArray(message.data(), static_cast<int>(message.size())));
  return reply;
}

protocol::Envelope exchange(zmq::socket_t& socket, const protocol::Envelope& request) {
  const std::optional<protocol::Envelope> reply =
      exchange_bytes(socket, request.SerializeAsString());
  if (!reply) {
    ADD_FAILURE() << "no reply to request " << request.request_id();
    return {};
  }
  EXPECT_EQ(reply->request_id(), request.request_id());
  return *reply;
}

protocol::Envelope request(std::uint64_t id, unsigned major = protocol::protocol_major) {
  protocol::Envelope envelope;
  envelope.mutable_version()->set_major(major);
  envelope.mutable_version()->set_minor(protocol::protocol_minor);
  envelope.set_request_id(id);
  return envelope;
}

protocol::Envelope hello(std::uint64_t id, unsigned major = protocol::protocol_major) {
  protocol::Envelope envelope = request(id, major);
  envelope.mutable_hello()->set_client_name("subdomain_process_test");
  return envelope;
}

protocol::Envelope shutdown(std::uint64_t id) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_shutdown();
  return envelope;
}

/// Body 1 of examples/two_blocks.toml, the mesh given as a path on the server's file system.
protocol::Envelope lower_block_setup(std::uint64_t id) {
  protocol::Envelope setup = request(id);
  protocol::SetupBody& body = *setup.mutable_setup_body();
  body.set_body_name("lower");
  body.set_mesh_path(lower_geo.string());
  body.set_mesh_size(0.1);
  body.set_model(protocol::PLANE_STRAIN);
  body.set_young_modulus(1000.0);
  body.set_poisson_ratio(0.3);
  body.add_dirichlet()->set_boundary("bottom");
  body.mutable_dirichlet(0)->set_x(0.0);
  body.mutable_dirichlet(0)->set_y(0.0);
  body.set_contact_boundary("contact");
  return setup;
}

/// The same body, built in this process.
BodyDefinition lower_block_definition() {
  BodyDefinition definition;
  definition.name = "lower";
  MeshReadOptions options;
  options.size = 0.1;
  definition.mesh = read_gmsh_mesh(lower_geo, options);
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.0, 0.0});
  definition.contact_boundary = "contact";
  return definition;
}

TEST(SubdomainProcess, GarbageGetsAnErrorReplyAndShutdownExitsWithZero) {
  ServerProcess server({"--listen", "tcp://127.0.0.1:*", "--name", "garbage"});
  const std::string endpoint = server.endpoint();
  ASSERT_TRUE(std::regex_match(endpoint, std::regex(R"(tcp://127\.0\.0\.1:[0-9]+)")))
      << "'" << endpoint << "'\n"
      << server.stderr_text();
  zmq::context_t context;
  zmq::socket_t socket = connect(context, endpoint);

  const std::optional<protocol::Envelope> garbage = exchange_bytes(socket, "\xff\xfe garbage");
  ASSERT_TRUE(garbage && garbage->has_error());
  EXPECT_EQ(garbage->error().code(), protocol::MALFORMED_MESSAGE);
  EXPECT_EQ(garbage->version().major(), protocol::protocol_major);

  const protocol::Envelope hello_reply = exchange(socket, hello(2));
  ASSERT_TRUE(hello_reply.has_hello_reply());
  EXPECT_NE(hello_reply.hello_reply().server_name().find("(garbage)"), std::string::npos);

  ASSERT_TRUE(exchange(socket, shutdown(3)).has_acknowledge());
  EXPECT_EQ(server.wait_for_exit(), 0) << server.stderr_text();
  EXPECT_NE(server.stderr_text().find("stopped: Shutdown request"), std::string::npos);
}

TEST(SubdomainProcess, MultiFrameMessageGetsMalformedMessage) {
  ServerProcess server({"--listen", "tcp://127.0.0.1:*"});
  zmq::context_t context;
  zmq::socket_t socket = connect(context, server.endpoint());
  const std::string first = hello(1).SerializeAsString();
  socket.send(zmq::buffer(first), zmq::send_flags::sndmore);
  socket.send(zmq::buffer(first), zmq::send_flags::none);
  zmq::message_t message;
  ASSERT_TRUE(socket.recv(message, zmq::recv_flags::none));
  protocol::Envelope reply;
  ASSERT_TRUE(reply.ParseFromArray(message.data(), static_cast<int>(message.size())));
  ASSERT_TRUE(reply.has_error());
  EXPECT_EQ(reply.error().code(), protocol::MALFORMED_MESSAGE);
  EXPECT_NE(reply.error().message().find("2 frames"), std::string::npos);
  EXPECT_TRUE(exchange(socket, hello(2)).has_hello_reply());
}

TEST(SubdomainProcess, SigtermAndSigintStopTheServerWithExitZero) {
  for (int signal_number : {SIGTERM, SIGINT}) {
    ServerProcess server({"--listen", "tcp://127.0.0.1:*"});
    const std::string endpoint = server.endpoint();
    ASSERT_FALSE(endpoint.empty()) << server.stderr_text();
    zmq::context_t context;
    zmq::socket_t socket = connect(context, endpoint);
    ASSERT_TRUE(exchange(socket, hello(1)).has_hello_reply());  // up and serving
    server.signal(signal_number);
    EXPECT_EQ(server.wait_for_exit(5s), 0) << "signal " << signal_number << "\n"
                                           << server.stderr_text();
    EXPECT_NE(server.stderr_text().find("stopped: stop requested"), std::string::npos);
  }
}

TEST(SubdomainProcess, IpcEndpointServesAContactSolveEqualToADirectSolve) {
  const std::string endpoint = "ipc://" + temporary_path("ipc").string();
  ServerProcess server({"--listen", endpoint, "--log-level", "warn"});
  ASSERT_EQ(server.endpoint(), endpoint) << server.stderr_text();
  zmq::context_t context;
  zmq::socket_t socket = connect(context, endpoint);

  const protocol::Envelope interface_reply = exchange(socket, lower_block_setup(1));
  ASSERT_TRUE(interface_reply.has_interface()) << interface_reply.DebugString();
  BodySolver reference(lower_block_definition());
  const InterfaceDescription interface = reference.contact_boundary();
  ASSERT_EQ(interface_reply.interface().node_ids_size(),
            static_cast<int>(interface.node_ids.size()));
  ContactAssignment assignment{interface.node_ids, {}};
  protocol::Envelope assign = request(2);
  for (int node : interface.node_ids) {
    assign.mutable_assign_contact()->add_node_ids(node);
    assign.mutable_assign_contact()->add_normals(0.0);
    assign.mutable_assign_contact()->add_normals(1.0);
    assignment.normals.emplace_back(0.0, 1.0);
  }
  ASSERT_TRUE(exchange(socket, assign).has_acknowledge());
  reference.assign_contact(assignment);

  // Press the right half of the contact edge down by g = -0.002 x.
  Eigen::VectorXd obstacle(static_cast<Eigen::Index>(interface.node_ids.size()));
  for (Eigen::Index i = 0; i < obstacle.size(); ++i)
    obstacle[i] = -0.002 * interface.coordinates[i].x();
  protocol::Envelope solve = request(3);
  solve.mutable_contact_solve()->mutable_obstacle()->Assign(obstacle.begin(), obstacle.end());
  const protocol::Envelope solved = exchange(socket, solve);
  ASSERT_TRUE(solved.has_contact_result()) << solved.DebugString();
  const ContactSolveResult expected = reference.solve_contact(obstacle);
  ASSERT_EQ(solved.contact_result().contact_force_size(), obstacle.size());
  for (Eigen::Index i = 0; i < obstacle.size(); ++i) {
    const int k = static_cast<int>(i);
    EXPECT_NEAR(solved.contact_result().contact_force(k), expected.contact_force[i],
                1e-12 * (1.0 + std::abs(expected.contact_force[i])));
    EXPECT_NEAR(solved.contact_result().normal_trace(k), expected.normal_trace[i], 1e-12);
  }
  EXPECT_GT(expected.contact_force.maxCoeff(), 0.0);

  ASSERT_TRUE(exchange(socket, shutdown(4)).has_acknowledge());
  EXPECT_EQ(server.wait_for_exit(), 0) << server.stderr_text();
}

TEST(SubdomainProcess, BindingAnEndpointInUseFailsWithExitOneNamingIt) {
  ServerProcess first({"--listen", "tcp://127.0.0.1:*"});
  const std::string endpoint = first.endpoint();
  ASSERT_FALSE(endpoint.empty()) << first.stderr_text();

  ServerProcess second({"--listen", endpoint});
  EXPECT_EQ(second.read_line(), "");  // no "listening on" line
  EXPECT_EQ(second.wait_for_exit(), 1);
  const std::string message = second.stderr_text();
  EXPECT_NE(message.find("cannot listen on '" + endpoint + "'"), std::string::npos) << message;
  EXPECT_NE(message.find("in use"), std::string::npos) << message;

  ServerProcess malformed({"--listen", "nonsense:/endpoint"});
  EXPECT_EQ(malformed.wait_for_exit(), 1);
  EXPECT_NE(malformed.stderr_text().find("'nonsense:/endpoint'"), std::string::npos)
      << malformed.stderr_text();
}

TEST(SubdomainProcess, HiddenProtocolMajorFlagProvokesAVersionMismatch) {
  ServerProcess server({"--listen", "tcp://127.0.0.1:*", "--protocol-major", "2"});
  zmq::context_t context;
  zmq::socket_t socket = connect(context, server.endpoint());
  const protocol::Envelope reply = exchange(socket, hello(1));
  ASSERT_TRUE(reply.has_error());
  EXPECT_EQ(reply.error().code(), protocol::VERSION_MISMATCH);
  EXPECT_EQ(reply.version().major(), 2u);
  // "the request speaks 1.2, this server 2.2": the flag changes the major version only.
  EXPECT_NE(
      reply.error().message().find("this server 2." + std::to_string(protocol::protocol_minor)),
      std::string::npos)
      << reply.error().message();
  EXPECT_TRUE(exchange(socket, hello(2, 2)).has_hello_reply());
}

TEST(SubdomainProcess, OversizedMessageIsDroppedWithoutReplyAndTheServerStaysUp) {
  ServerProcess server({"--listen", "tcp://127.0.0.1:*", "--max-message-size", "1000"});
  const std::string endpoint = server.endpoint();
  zmq::context_t context;
  {
    zmq::socket_t socket = connect(context, endpoint, 1s);
    protocol::Envelope large = hello(1);
    large.mutable_hello()->set_client_name(std::string(2000, 'x'));
    EXPECT_FALSE(exchange_bytes(socket, large.SerializeAsString()));  // no reply
  }
  zmq::socket_t socket = connect(context, endpoint);
  EXPECT_TRUE(exchange(socket, hello(2)).has_hello_reply());
}

}  // namespace
}  // namespace robin
