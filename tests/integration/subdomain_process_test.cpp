// The real robin-subdomain executable (build/bin), started as a child process with its stdout
// on a pipe: the "listening on" line, error replies that leave it running, Shutdown and
// signals (exit code 0), ipc:// endpoints, bind failures (exit code 1 and a message naming the
// endpoint), the hidden --protocol-major flag, --max-message-size, and one contact solve over
// the wire compared with a BodySolver built in this process (the mesh read by the server from
// its --data-directory).
// The attacks of issue 11 against the real process, which each fail to run or read anything
// and leave the server answering Hello: a 1.x .geo script with a shell command or a file read
// (the nine attacks of hostile_geo_scripts.hpp) in the removed SetupBody.mesh_content
// (hand-encoded wire bytes), mesh_path reads outside --data-directory,
// write_directory writes outside --output-root (also through a symbolic link at the target),
// a 100,000-character body name and an inverted cell; bodies above --max-dofs and
// --max-factor-memory. A body with two contact boundaries, and the refusal of a repeated or
// unknown one.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <thread>
#include <zmq.hpp>

#include "../hostile_geo_scripts.hpp"
#include "../test_files.hpp"
#include "mesh_codec.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/material.hpp"
#include "numerics/rectangle_mesher.hpp"
#include "protocol_version.hpp"
#include "remote/reply_decoding.hpp"
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
  pid_t pid() const { return pid_; }

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

/// Body 1 of examples/two_blocks.toml, the mesh given as a path relative to the server's
/// --data-directory (examples/meshes, where block_lower.geo's own h is 0.1, the case's size).
protocol::Envelope lower_block_setup(std::uint64_t id) {
  protocol::Envelope setup = request(id);
  protocol::SetupBody& body = *setup.mutable_setup_body();
  body.set_body_name("lower");
  body.set_mesh_path(lower_geo.filename().string());
  body.set_model(protocol::PLANE_STRAIN);
  body.set_young_modulus(1000.0);
  body.set_poisson_ratio(0.3);
  body.add_dirichlet()->set_boundary("bottom");
  body.mutable_dirichlet(0)->set_x(0.0);
  body.mutable_dirichlet(0)->set_y(0.0);
  body.add_contact_boundaries("contact");
  return setup;
}

/// block_lower.geo meshed in this process with its own h = 0.1, once.
const Mesh& lower_mesh() {
  static const Mesh mesh = read_gmsh_mesh(lower_geo);
  return mesh;
}

/// lower_block_setup with the mesh sent as MeshData instead.
protocol::Envelope lower_block_data_setup(std::uint64_t id) {
  protocol::Envelope setup = lower_block_setup(id);
  setup.mutable_setup_body()->clear_mesh_path();
  *setup.mutable_setup_body()->mutable_mesh() = encode_mesh(lower_mesh());
  return setup;
}

/// The same body, built in this process.
BodyDefinition lower_block_definition() {
  BodyDefinition definition;
  definition.name = "lower";
  definition.mesh = lower_mesh();
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  definition.contact_boundaries = {"contact"};
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
  ServerProcess server({"--listen", endpoint, "--log-level", "warn", "--data-directory",
                        lower_geo.parent_path().string()});
  ASSERT_EQ(server.endpoint(), endpoint) << server.stderr_text();
  zmq::context_t context;
  zmq::socket_t socket = connect(context, endpoint);

  const protocol::Envelope interface_reply = exchange(socket, lower_block_setup(1));
  ASSERT_TRUE(interface_reply.has_interface()) << interface_reply.DebugString();
  BodySolver reference(lower_block_definition());
  const InterfaceDescription interface = reference.contact_boundary();
  ASSERT_EQ(interface_reply.interface().node_ids_size(),
            static_cast<int>(interface.node_ids.size()));
  // Node-to-node rows with the normal (0, 1): entries (node, x) = 0 and (node, y) = 1.
  const ContactOperator assignment = node_to_node_operator(
      interface.node_ids, std::vector<Eigen::Vector3d>(interface.node_ids.size(), {0.0, 1.0, 0.0}),
      interface.weights);
  protocol::Envelope assign = request(2);
  for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
    protocol::AssignContact& message = *assign.mutable_assign_contact();
    message.add_row_offsets(2 * i);
    for (const int component : {0, 1}) {
      message.add_node_ids(interface.node_ids[i]);
      message.add_components(static_cast<std::uint32_t>(component));
      message.add_values(component == 0 ? 0.0 : 1.0);
    }
    message.add_weights(interface.weights[i]);
  }
  assign.mutable_assign_contact()->add_row_offsets(2 * interface.node_ids.size());
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
  ServerProcess server({"--listen", "tcp://127.0.0.1:*", "--protocol-major", "3"});
  zmq::context_t context;
  zmq::socket_t socket = connect(context, server.endpoint());
  const protocol::Envelope reply = exchange(socket, hello(1));
  ASSERT_TRUE(reply.has_error());
  EXPECT_EQ(reply.error().code(), protocol::VERSION_MISMATCH);
  EXPECT_EQ(reply.version().major(), 3u);
  // "the request speaks 2.0, this server 3.0": the flag changes the major version only.
  EXPECT_NE(
      reply.error().message().find("this server 3." + std::to_string(protocol::protocol_minor)),
      std::string::npos)
      << reply.error().message();
  EXPECT_TRUE(exchange(socket, hello(2, 3)).has_hello_reply());
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

// --- Issue 11: the attacks against the real process --------------------------------------

using testing::file_text;
using testing::write_text;
using ScratchDirectory = testing::TemporaryDirectory;

/// The names under `directory` (recursively, relative; links not followed).
std::set<std::string> listing(const std::filesystem::path& directory) {
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(directory)) {
    names.insert(entry.path().lexically_relative(directory).string());
  }
  return names;
}

/// Hello is answered: the server is up and serving.
void expect_hello(zmq::socket_t& socket, std::uint64_t id) {
  const protocol::Envelope reply = exchange(socket, hello(id));
  EXPECT_TRUE(reply.has_hello_reply()) << reply.DebugString();
}

void expect_error(const protocol::Envelope& reply, protocol::ErrorCode code,
                  const std::string& expected) {
  ASSERT_TRUE(reply.has_error()) << reply.DebugString();
  EXPECT_EQ(protocol::ErrorCode_Name(reply.error().code()), protocol::ErrorCode_Name(code))
      << reply.error().message();
  EXPECT_NE(reply.error().message().find(expected), std::string::npos) << reply.error().message();
}

/// The protobuf wire encoding of a varint.
std::string varint(std::uint64_t value) {
  std::string bytes;
  while (value >= 0x80) {
    bytes.push_back(static_cast<char>((value & 0x7f) | 0x80));
    value >>= 7;
  }
  bytes.push_back(static_cast<char>(value));
  return bytes;
}

/// Field `number` of wire type 2 (length-delimited) holding `payload`.
std::string length_delimited(std::uint32_t number, const std::string& payload) {
  return varint(std::uint64_t{number} << 3 | 2) + varint(payload.size()) + payload;
}

/// The bytes of a 1.x SetupBody request: `setup` (its other fields) with, written by hand,
/// field 2 (mesh_content) = `script` and field 3 (mesh_extension) = ".geo" inside
/// Envelope.setup_body (field 12; protobuf merges the two occurrences of the message).
std::string with_1x_script(const protocol::Envelope& setup, const std::string& script) {
  return setup.SerializeAsString() +
         length_delimited(12, length_delimited(2, script) + length_delimited(3, ".geo"));
}

/// A servers' data directory and output root with the links of the attacks, in a scratch
/// directory:
///   data/square.msh        tests/data/mesh_square_v41.msh
///   data/inverted.msh      tests/data/mesh_square_inverted_v22.msh (triangle 13 reversed)
///   data/passwd.msh     -> /etc/passwd
///   data/outside.msh    -> x.msh (outside the data directory, a valid mesh)
///   data/up             -> the scratch directory
///   x.msh                  a valid mesh
///   root/out/lower.vtu  -> outside/victim.txt ("precious")
///   root/linked         -> outside
///   outside/victim.txt
struct AttackFiles {
  ScratchDirectory scratch{"attack"};
  std::filesystem::path data = scratch.path() / "data";
  std::filesystem::path root = scratch.path() / "root";
  std::filesystem::path outside = scratch.path() / "outside";
  std::filesystem::path victim = outside / "victim.txt";

  AttackFiles() {
    const std::filesystem::path test_data = ROBIN_TEST_DATA;
    std::filesystem::create_directories(data);
    std::filesystem::create_directories(root / "out");
    std::filesystem::create_directories(outside);
    std::filesystem::copy_file(test_data / "mesh_square_v41.msh", data / "square.msh");
    std::filesystem::copy_file(test_data / "mesh_square_inverted_v22.msh", data / "inverted.msh");
    std::filesystem::copy_file(test_data / "mesh_square_v41.msh", scratch.path() / "x.msh");
    std::filesystem::create_symlink("/etc/passwd", data / "passwd.msh");
    std::filesystem::create_symlink(scratch.path() / "x.msh", data / "outside.msh");
    std::filesystem::create_symlink(scratch.path(), data / "up");
    write_text(victim, "precious\n");
    std::filesystem::create_symlink(victim, root / "out/lower.vtu");
    std::filesystem::create_symlink(outside, root / "linked");
  }
};

/// A body on the unit square read from `mesh_path`: clamped "bottom", contact boundary "top".
protocol::Envelope square_path_setup(std::uint64_t id, const std::string& mesh_path) {
  protocol::Envelope setup = request(id);
  protocol::SetupBody& body = *setup.mutable_setup_body();
  body.set_body_name("square");
  body.set_mesh_path(mesh_path);
  body.set_model(protocol::PLANE_STRAIN);
  body.set_young_modulus(1000.0);
  body.set_poisson_ratio(0.3);
  body.add_dirichlet()->set_boundary("bottom");
  body.mutable_dirichlet(0)->set_x(0.0);
  body.mutable_dirichlet(0)->set_y(0.0);
  body.add_contact_boundaries("top");
  return setup;
}

/// A robin-subdomain started on an ephemeral port with `arguments` added, and a socket to it.
struct ConnectedServer {
  explicit ConnectedServer(std::vector<std::string> arguments)
      : process([&] {
          arguments.insert(arguments.begin(),
                           {"--listen", "tcp://127.0.0.1:*", "--log-level", "warn"});
          return arguments;
        }()),
        endpoint(process.endpoint()),
        socket(connect(context, endpoint)) {}
  ServerProcess process;
  std::string endpoint;
  zmq::context_t context;
  zmq::socket_t socket;
};

/// The non-empty lines of /etc/passwd (none when it cannot be read).
std::vector<std::string> passwd_lines() {
  std::ifstream stream("/etc/passwd");
  std::vector<std::string> lines;
  for (std::string line; std::getline(stream, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

/// Expects `reply` to show no line of /etc/passwd and not `directory` (the server's working
/// directory, inherited from this process).
void expect_nothing_read(const protocol::Envelope& reply, const std::string& directory) {
  const std::string bytes = reply.SerializeAsString();
  for (const std::string& line : passwd_lines()) {
    EXPECT_EQ(bytes.find(line), std::string::npos) << "the reply shows '" << line << "'";
  }
  EXPECT_EQ(bytes.find(directory), std::string::npos) << "the reply shows " << directory;
}

// Issue 11 (a): the wire bytes of a 1.x SetupBody with a .geo script in mesh_content (field 2)
// and ".geo" in mesh_extension (field 3), the script holding one of the attacks of
// hostile_geo_scripts.hpp: "touch WITNESS" by SystemCall, by an ExternalProcess mesh size field
// or hidden from a keyword filter (backslash, three single-quote tricks, NUL in a comment), or
// a read of /etc/passwd (ListFromFile) or of the working directory (CurrentDirectory).
// robin-subdomain 2.0 runs no script: without MeshData or mesh_path the body is BAD_INPUT, with
// a valid MeshData the script is ignored; the witness file never appears, no reply shows a
// line of /etc/passwd or the server's working directory, and the server answers Hello after
// each request.
TEST(SubdomainProcess, Version1GeoScriptIsNeverRun) {
  ConnectedServer server({});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  const std::string working_directory = std::filesystem::current_path().string();
  ASSERT_GT(working_directory.size(), 1u);
  std::uint64_t id = 1;
  const std::filesystem::path witness = temporary_path("witness");
  for (const testing::HostileGeoScript& attack : testing::hostile_geo_scripts(witness)) {
    SCOPED_TRACE(attack.label);
    std::filesystem::remove(witness);
    const std::string script = file_text(lower_geo) + attack.text;
    protocol::Envelope without_mesh = lower_block_setup(id++);
    without_mesh.mutable_setup_body()->clear_mesh_path();
    const std::string bytes = with_1x_script(without_mesh, script);
    // The bytes parse, with the script kept as unknown fields of the SetupBody.
    protocol::Envelope parsed;
    ASSERT_TRUE(parsed.ParseFromString(bytes));
    ASSERT_FALSE(
        parsed.setup_body().GetReflection()->GetUnknownFields(parsed.setup_body()).empty());
    const std::optional<protocol::Envelope> reply = exchange_bytes(server.socket, bytes);
    ASSERT_TRUE(reply);
    expect_error(*reply, protocol::BAD_INPUT,
                 "body 'lower': SetupBody.mesh and SetupBody.mesh_path are both absent");
    expect_nothing_read(*reply, working_directory);
    expect_hello(server.socket, id++);

    const std::optional<protocol::Envelope> with_mesh =
        exchange_bytes(server.socket, with_1x_script(lower_block_data_setup(id++), script));
    ASSERT_TRUE(with_mesh);
    EXPECT_TRUE(with_mesh->has_interface()) << with_mesh->DebugString();
    expect_nothing_read(*with_mesh, working_directory);
    expect_hello(server.socket, id++);
    EXPECT_FALSE(std::filesystem::exists(witness)) << "the script ran";
  }
  ASSERT_TRUE(exchange(server.socket, shutdown(id)).has_acknowledge());
  EXPECT_EQ(server.process.wait_for_exit(), 0) << server.process.stderr_text();
}

// Issue 11 (b): mesh_path "/etc/passwd", "../x.msh", links in the data directory to
// /etc/passwd, to a mesh outside and to a directory outside are BAD_INPUT and no reply holds a
// line of /etc/passwd; square.msh inside is read and gives the body built here from the same
// file; a server without --data-directory refuses every mesh_path.
TEST(SubdomainProcess, MeshPathOutsideTheDataDirectoryIsRefusedUnread) {
  const AttackFiles files;
  const std::vector<std::string> secret = passwd_lines();
  ConnectedServer server({"--data-directory", files.data.string()});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  std::uint64_t id = 1;
  for (const auto& [path, expected] : std::vector<std::pair<std::string, std::string>>{
           {"/etc/passwd", "is absolute"},
           {"../x.msh", "contains '..'"},
           {"passwd.msh", "leads out of the data directory"},
           {"outside.msh", "leads out of the data directory"},
           {"up/x.msh", "leads out of the data directory"}}) {
    const protocol::Envelope reply = exchange(server.socket, square_path_setup(id++, path));
    expect_error(reply, protocol::BAD_INPUT, "body 'square': SetupBody.mesh_path");
    expect_error(reply, protocol::BAD_INPUT, expected);
    const std::string bytes = reply.SerializeAsString();
    for (const std::string& line : secret) {
      EXPECT_EQ(bytes.find(line), std::string::npos) << "the reply shows '" << line << "'";
    }
    expect_hello(server.socket, id++);
  }

  const protocol::Envelope reply = exchange(server.socket, square_path_setup(id++, "square.msh"));
  ASSERT_TRUE(reply.has_interface()) << reply.DebugString();
  BodyDefinition definition;
  definition.name = "square";
  definition.mesh = read_gmsh_mesh(std::filesystem::path(ROBIN_TEST_DATA) / "mesh_square_v41.msh");
  definition.material = make_isotropic_material(1000.0, 0.3, PlaneModel::plane_strain, "test");
  definition.dirichlet.push_back({"bottom", 0.0, 0.0, std::nullopt});
  definition.contact_boundaries = {"top"};
  const BodySolver reference(definition);
  const InterfaceDescription expected = reference.contact_boundary();
  ASSERT_EQ(reply.interface().node_ids_size(), static_cast<int>(expected.node_ids.size()));
  for (std::size_t i = 0; i < expected.node_ids.size(); ++i) {
    const int k = static_cast<int>(i);
    EXPECT_EQ(reply.interface().node_ids(k), expected.node_ids[i]);
    EXPECT_EQ(reply.interface().node_tags(k), static_cast<std::int64_t>(expected.node_tags[i]));
    EXPECT_EQ(reply.interface().coordinates(2 * k), expected.coordinates[i].x());
    EXPECT_EQ(reply.interface().coordinates(2 * k + 1), expected.coordinates[i].y());
  }
  EXPECT_EQ(reply.interface().dof_count(), static_cast<std::uint64_t>(reference.free_dof_count()));

  ConnectedServer without_directory({});
  for (const std::string& path :
       {std::string("square.msh"), (files.data / "square.msh").string()}) {
    expect_error(exchange(without_directory.socket, square_path_setup(id++, path)),
                 protocol::BAD_INPUT, "this server was started without --data-directory");
  }
  expect_hello(without_directory.socket, id++);
}

/// A FieldsRequest for 21 contact forces of 0.5, written to `write_directory`.
protocol::Envelope fields_request(std::uint64_t id, const std::string& write_directory) {
  protocol::Envelope envelope = request(id);
  envelope.mutable_fields()->mutable_contact_force()->Resize(21, 0.5);
  envelope.mutable_fields()->set_write_directory(write_directory);
  return envelope;
}

/// Sets the lower block up (MeshData) and assigns its 21 contact nodes, normal (0, 1).
void set_up_lower_block(zmq::socket_t& socket, std::uint64_t& id) {
  const protocol::Envelope interface = exchange(socket, lower_block_data_setup(id++));
  ASSERT_TRUE(interface.has_interface()) << interface.DebugString();
  ASSERT_EQ(interface.interface().node_ids_size(), 21);
  protocol::Envelope assign = request(id++);
  protocol::AssignContact& message = *assign.mutable_assign_contact();
  message.add_row_offsets(0);
  for (int i = 0; i < 21; ++i) {
    message.add_node_ids(interface.interface().node_ids(i));
    message.add_components(1);
    message.add_values(1.0);
    message.add_row_offsets(static_cast<std::uint64_t>(i + 1));
    message.add_weights(interface.interface().weights(i));
  }
  ASSERT_TRUE(exchange(socket, assign).has_acknowledge());
}

// Issue 11 (c): root/out/lower.vtu is a link to a file outside --output-root: FieldsRequest
// with write_directory "out" replaces the link by the VTU and leaves the outside file as it
// was; absolute, ".." and symbolically linked write directories are INVALID_ARGUMENT and create
// nothing outside the root; a server without --output-root refuses every write_directory.
TEST(SubdomainProcess, WriteDirectoryOutsideTheOutputRootIsRefusedUnwritten) {
  const AttackFiles files;
  ConnectedServer server({"--output-root", files.root.string()});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  std::uint64_t id = 1;
  set_up_lower_block(server.socket, id);

  const protocol::Envelope written = exchange(server.socket, fields_request(id++, "out"));
  ASSERT_TRUE(written.has_fields_reply()) << written.DebugString();
  EXPECT_EQ(written.fields_reply().written_file(),
            (std::filesystem::canonical(files.root) / "out/lower.vtu").string());
  EXPECT_EQ(file_text(files.victim), "precious\n");
  EXPECT_FALSE(std::filesystem::is_symlink(files.root / "out/lower.vtu"));
  EXPECT_NE(file_text(files.root / "out/lower.vtu").find("<VTKFile"), std::string::npos);
  expect_hello(server.socket, id++);

  for (const auto& [directory, expected] :
       std::vector<std::pair<std::string, std::string>>{{files.outside.string(), "is absolute"},
                                                        {"../outside", "contains '..'"},
                                                        {"out/../../outside/sub", "contains '..'"},
                                                        {"linked", "is a symbolic link"},
                                                        {"linked/sub", "is a symbolic link"}}) {
    expect_error(exchange(server.socket, fields_request(id++, directory)),
                 protocol::INVALID_ARGUMENT, expected);
    expect_hello(server.socket, id++);
  }
  EXPECT_EQ(listing(files.outside), (std::set<std::string>{"victim.txt"}));
  EXPECT_EQ(file_text(files.victim), "precious\n");
  EXPECT_EQ(listing(files.root), (std::set<std::string>{"linked", "out", "out/lower.vtu"}));

  ConnectedServer without_root({});
  set_up_lower_block(without_root.socket, id);
  expect_error(exchange(without_root.socket, fields_request(id++, "out")),
               protocol::INVALID_ARGUMENT, "this server was started without --output-root");
  expect_hello(without_root.socket, id++);
}

// Issue 11 (d) and (e): a 100,000-character body name is BAD_INPUT (at most 64), not echoed;
// a MeshData triangle with two nodes swapped is BAD_INPUT naming its tag, and so is the .msh
// in the data directory with one triangle reversed against its surface.
TEST(SubdomainProcess, HugeNameAndInvertedCellsAreBadInput) {
  const AttackFiles files;
  ConnectedServer server({"--data-directory", files.data.string()});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  std::uint64_t id = 1;
  protocol::Envelope huge = lower_block_data_setup(id++);
  huge.mutable_setup_body()->set_body_name(std::string(100000, 'a'));
  protocol::Envelope reply = exchange(server.socket, huge);
  expect_error(reply, protocol::BAD_INPUT, "SetupBody.body_name has 100000 characters: at most 64");
  EXPECT_LT(reply.ByteSizeLong(), 1000u);
  expect_hello(server.socket, id++);

  protocol::Envelope inverted = lower_block_data_setup(id++);
  protocol::CellBlock& cells = *inverted.mutable_setup_body()->mutable_mesh()->mutable_cells(0);
  ASSERT_EQ(cells.type(), protocol::TRIANGLE3);
  ASSERT_GT(cells.tags_size(), 5);
  const std::uint32_t second = cells.connectivity(16), third = cells.connectivity(17);
  cells.set_connectivity(16, third);  // triangle 5 (zero-based): its last two nodes swapped
  cells.set_connectivity(17, second);
  reply = exchange(server.socket, inverted);
  expect_error(reply, protocol::BAD_INPUT,
               "body 'lower': SetupBody.mesh: element tag " + std::to_string(cells.tags(5)) + " ");
  expect_error(reply, protocol::BAD_INPUT, "is inverted or folded");
  expect_hello(server.socket, id++);

  reply = exchange(server.socket, square_path_setup(id++, "inverted.msh"));
  expect_error(reply, protocol::BAD_INPUT, "element tag 13 ");
  expect_error(reply, protocol::BAD_INPUT, "inverted");
  expect_hello(server.socket, id++);
  EXPECT_TRUE(exchange(server.socket, lower_block_data_setup(id++)).has_interface());
}

// Issue 11 (bounded resources): a body above --max-dofs is BAD_INPUT naming its size, the
// limit and the option, before assembly; a factor above --max-factor-memory is BAD_INPUT from
// the symbolic analysis (a factor holds at least its diagonal: 8 bytes per unknown, above a
// limit of 1 KiB for this body); the server then answers Hello and sets the body up within
// the limits.
TEST(SubdomainProcess, BodiesAboveTheResourceLimitsAreBadInputNamingTheLimit) {
  const long dof_count = 2L * static_cast<long>(lower_mesh().node_count());
  // The factor's diagonal alone (8 bytes per unknown) exceeds 1 KiB when over half of the
  // unknowns are free, which the fixed bottom edge leaves.
  ASSERT_GT(dof_count, 2 * 1048 / 8);
  std::uint64_t id = 1;
  {
    ConnectedServer server({"--max-dofs", std::to_string(dof_count - 1)});
    ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
    const protocol::Envelope reply = exchange(server.socket, lower_block_data_setup(id++));
    expect_error(reply, protocol::BAD_INPUT,
                 "body 'lower': " + std::to_string(dof_count) +
                     " degrees of freedom, above this server's limit of " +
                     std::to_string(dof_count - 1) + " (robin-subdomain --max-dofs raises it)");
    expect_hello(server.socket, id++);
  }
  {
    ConnectedServer server({"--max-factor-memory", "0.001"});
    ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
    const protocol::Envelope reply = exchange(server.socket, lower_block_data_setup(id++));
    expect_error(reply, protocol::BAD_INPUT, "body 'lower': its Cholesky factor would need ");
    expect_error(reply, protocol::BAD_INPUT,
                 "above this server's limit of 9.77e-07 GiB (robin-subdomain "
                 "--max-factor-memory MIB raises it)");  // 0.001 MiB = 1048.576 bytes
    expect_hello(server.socket, id++);
  }
  ConnectedServer server({"--max-dofs", std::to_string(dof_count)});
  EXPECT_TRUE(exchange(server.socket, lower_block_data_setup(id++)).has_interface());
}

// Issue 11 (b): a mesh file larger than --max-mesh-file-size (default 1 GiB) is refused before
// it is read, naming its size, the limit and the option. A 2 GiB + 1 byte sparse file in the
// data directory is refused at once (the server only stats it); with --max-mesh-file-size 1000
// the 1024-byte square.msh is refused, and the server answers Hello after each.
TEST(SubdomainProcess, MeshFileAboveTheSizeLimitIsRefusedUnread) {
  const AttackFiles files;
  const std::uintmax_t huge_size = (std::uintmax_t{2} << 30) + 1;
  { std::ofstream create(files.data / "huge.msh"); }
  std::filesystem::resize_file(files.data / "huge.msh", huge_size);  // sparse: no disk used
  std::uint64_t id = 1;
  {
    ConnectedServer server({"--data-directory", files.data.string()});
    ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
    const auto start = std::chrono::steady_clock::now();
    const protocol::Envelope reply = exchange(server.socket, square_path_setup(id++, "huge.msh"));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    expect_error(reply, protocol::BAD_INPUT,
                 "body 'square': SetupBody.mesh_path 'huge.msh' is " + std::to_string(huge_size) +
                     " bytes, above this server's limit of 1073741824 bytes for a mesh file "
                     "(its operator raises it with robin-subdomain --max-mesh-file-size BYTES): "
                     "not read");
    EXPECT_LT(seconds, 1.0) << "the file was read";
    expect_hello(server.socket, id++);
    EXPECT_TRUE(exchange(server.socket, square_path_setup(id++, "square.msh")).has_interface());
  }
  ConnectedServer server({"--data-directory", files.data.string(), "--max-mesh-file-size", "1000"});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  const std::uintmax_t square_size = std::filesystem::file_size(files.data / "square.msh");
  ASSERT_GT(square_size, 1000u);
  expect_error(exchange(server.socket, square_path_setup(id++, "square.msh")), protocol::BAD_INPUT,
               "SetupBody.mesh_path 'square.msh' is " + std::to_string(square_size) +
                   " bytes, above this server's limit of 1000 bytes");
  expect_hello(server.socket, id++);
}

// A mesh file that crashes Gmsh 4.8 (tests/data/mesh_gmsh_crash_v22.msh: its $Nodes section says
// 11 nodes and lists 12; `gmsh -0` dies of SIGSEGV on it, found by tests/fuzz/mesh_file_fuzzer)
// in the data directory: robin-subdomain reads .msh files with the native reader (msh_file.hpp),
// which finds a twelfth node where $EndNodes belongs (line 24), so the request is BAD_INPUT
// naming the line, and the server goes on: Hello, and square.msh is read as before.
TEST(SubdomainProcess, MeshFileThatCrashesGmshIsBadInputAndTheServerGoesOn) {
  const AttackFiles files;
  std::filesystem::copy_file(std::filesystem::path(ROBIN_TEST_DATA) / "mesh_gmsh_crash_v22.msh",
                             files.data / "crash.msh");
  ConnectedServer server({"--data-directory", files.data.string()});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  std::uint64_t id = 1;
  expect_error(exchange(server.socket, square_path_setup(id++, "crash.msh")), protocol::BAD_INPUT,
               "body 'square': SetupBody.mesh_path: mesh file 'crash.msh' line 24: expected "
               "$EndNodes, found '12'");
  expect_hello(server.socket, id++);
  EXPECT_TRUE(exchange(server.socket, square_path_setup(id++, "square.msh")).has_interface());
  ASSERT_TRUE(exchange(server.socket, shutdown(id)).has_acknowledge());
  EXPECT_EQ(server.process.wait_for_exit(), 0) << server.process.stderr_text();
}

// A mesh file whose header claims 1.5e9 nodes and holds 12 (tests/data/mesh_square_v41.msh with
// its $Nodes count raised): Gmsh 4.8 reserves memory for the claimed count (`gmsh -0` on it grew
// to 22 GB before the kernel killed it). robin-subdomain's native reader (msh_file.hpp) checks
// the count against the bytes left in the file before allocating anything for it, so the
// request is BAD_INPUT naming the line and the count, at once, and the server goes on.
TEST(SubdomainProcess, MeshFileClaimingBillionsOfNodesIsRefusedWithinAMemoryBound) {
  const AttackFiles files;
  std::ifstream square(std::filesystem::path(ROBIN_TEST_DATA) / "mesh_square_v41.msh");
  std::ofstream claims(files.data / "claims.msh");
  bool replaced = false;
  for (std::string line; std::getline(square, line);) {
    if (line == "9 12 1 12") {  // $Nodes: 9 blocks, 12 nodes, tags 1 to 12
      line = "9 1500000000 1 12";
      replaced = true;
    }
    claims << line << '\n';
  }
  claims.close();
  ASSERT_TRUE(replaced) << "tests/data/mesh_square_v41.msh changed: its $Nodes header line";
  ConnectedServer server({"--data-directory", files.data.string()});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  std::uint64_t id = 1;
  const protocol::Envelope reply = exchange(server.socket, square_path_setup(id++, "claims.msh"));
  ASSERT_TRUE(reply.has_error()) << reply.DebugString();
  EXPECT_EQ(reply.error().code(), protocol::BAD_INPUT);
  EXPECT_NE(reply.error().message().find(
                "body 'square': SetupBody.mesh_path: mesh file 'claims.msh' line 25: $Nodes "
                "declares 1500000000 nodes but the file has "),
            std::string::npos)
      << reply.error().message();
  expect_hello(server.socket, id++);
  EXPECT_TRUE(exchange(server.socket, square_path_setup(id++, "square.msh")).has_interface());
  ASSERT_TRUE(exchange(server.socket, shutdown(id)).has_acknowledge());
  EXPECT_EQ(server.process.wait_for_exit(), 0) << server.process.stderr_text();
}

/// The virtual memory size of process `pid` in bytes (VmSize of /proc/PID/status; 0 if unknown).
std::uint64_t virtual_memory_bytes(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmSize:", 0) == 0) return std::stoull(line.substr(7)) * 1024;  // in kB
  }
  return 0;
}

// Issue 11 (c): an allocation failure inside a request is an Error reply, not an abort. The
// server's address space is capped (prlimit, RLIMIT_AS) 64 MiB above its size after a Hello;
// a legal SetupBody of a 400 x 400 square of linear triangles (160,801 nodes, a message of a
// few MB, far below every limit of the server) then cannot allocate its assembly and
// factorization (hundreds of MB). The reply is an Error saying the server ran out of memory;
// the server answers Hello and exits 0 after Shutdown. (A later factorization under the same
// cap is not asserted: in a CI run, with the tests in parallel, the small lower block's setup
// after the failure hung for 120 s in 1 of 2 runs, OpenBLAS retrying an allocation; passed
// 3 of 3 alone. docs/security.md states it as a known limitation.)
TEST(SubdomainProcess, AllocationFailureIsAnErrorReplyAndTheServerGoesOn) {
  ConnectedServer server({});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  server.socket.set(zmq::sockopt::rcvtimeo, 120000);
  std::uint64_t id = 1;
  expect_hello(server.socket, id++);
  const std::uint64_t size = virtual_memory_bytes(server.process.pid());
  ASSERT_GT(size, 0u);
  const rlimit cap{size + (std::uint64_t{64} << 20), size + (std::uint64_t{64} << 20)};
  ASSERT_EQ(prlimit(server.process.pid(), RLIMIT_AS, &cap, nullptr), 0) << std::strerror(errno);

  protocol::Envelope large = lower_block_data_setup(id++);
  Mesh square = make_rectangle_mesh(0.0, -1.0, 1.0, 0.0, 400, 400, ElementType::triangle3);
  *large.mutable_setup_body()->mutable_mesh() = encode_mesh(square);
  large.mutable_setup_body()->set_contact_boundaries(0, "top");
  const std::size_t message_bytes = large.ByteSizeLong();
  std::cout << "capped at " << cap.rlim_cur / 1048576 << " MiB; the request has " << message_bytes
            << " bytes\n";
  ASSERT_LT(message_bytes, std::size_t{16} << 20);
  const protocol::Envelope reply = exchange(server.socket, large);
  expect_error(reply, protocol::INTERNAL, "body 'lower': the server ran out of memory");
  std::cout << reply.error().message() << "\n";

  expect_hello(server.socket, id++);
  ASSERT_TRUE(exchange(server.socket, shutdown(id)).has_acknowledge());
  EXPECT_EQ(server.process.wait_for_exit(), 0) << server.process.stderr_text();
}

/// lower_block_data_setup with `names` as its contact boundaries.
protocol::Envelope lower_block_contact_setup(std::uint64_t id,
                                             const std::vector<std::string>& names) {
  protocol::Envelope setup = lower_block_data_setup(id);
  setup.mutable_setup_body()->clear_contact_boundaries();
  for (const std::string& name : names) setup.mutable_setup_body()->add_contact_boundaries(name);
  return setup;
}

// A body with two contact boundaries (the lower block's top "contact" and its side "left",
// which share the corner (-1, 0)): one ContactSurface per boundary, the union of their nodes
// with the values a BodySolver of the same body gives in this process (weights adding up to the
// boundaries' lengths 2 + 1), and, decoded as the coordinator decodes it, the description of
// each boundary alone that a body with only that boundary gives. A repeated, unknown, missing
// or excessive list is BAD_INPUT naming the field, and the server keeps serving.
TEST(SubdomainProcess, TwoContactBoundariesAreServedAndARepeatedOrUnknownOneIsRefused) {
  ConnectedServer server({});
  ASSERT_FALSE(server.endpoint.empty()) << server.process.stderr_text();
  std::uint64_t id = 1;
  const protocol::Envelope reply =
      exchange(server.socket, lower_block_contact_setup(id++, {"contact", "left"}));
  ASSERT_TRUE(reply.has_interface()) << reply.DebugString();
  const protocol::InterfaceDescription& message = reply.interface();
  ASSERT_EQ(message.surfaces_size(), 2);
  EXPECT_EQ(message.surfaces(0).boundary(), "contact");
  EXPECT_EQ(message.surfaces(1).boundary(), "left");

  BodyDefinition definition = lower_block_definition();
  definition.contact_boundaries = {"contact", "left"};
  const InterfaceDescription expected = BodySolver(definition).contact_boundary();
  ASSERT_EQ(message.node_ids_size(), static_cast<int>(expected.node_ids.size()));
  double weight_sum = 0.0;
  for (std::size_t i = 0; i < expected.node_ids.size(); ++i) {
    const int k = static_cast<int>(i);
    EXPECT_EQ(message.node_ids(k), expected.node_ids[i]);
    EXPECT_EQ(message.normals(2 * k), expected.normals[i].x());
    EXPECT_EQ(message.normals(2 * k + 1), expected.normals[i].y());
    EXPECT_EQ(message.weights(k), expected.weights[i]);
    weight_sum += message.weights(k);
  }
  EXPECT_NEAR(weight_sum, 3.0, 1e-12);
  for (int k = 0; k < 2; ++k) {
    const std::vector<int>& segments = expected.surfaces[static_cast<std::size_t>(k)].facets;
    EXPECT_EQ(std::vector<int>(message.surfaces(k).segments().begin(),
                               message.surfaces(k).segments().end()),
              segments);
  }

  const InterfaceDescription decoded = decode_interface(message);
  for (const std::string boundary : {"contact", "left"}) {
    SCOPED_TRACE(boundary);
    BodyDefinition alone = lower_block_definition();
    alone.contact_boundaries = {boundary};
    const InterfaceDescription own = BodySolver(alone).contact_boundary();
    const InterfaceDescription restricted = restrict_to_boundary(decoded, boundary);
    EXPECT_EQ(restricted.node_ids, own.node_ids);
    EXPECT_EQ(restricted.coordinates, own.coordinates);
    ASSERT_EQ(restricted.weights.size(), own.weights.size());
    for (std::size_t i = 0; i < own.weights.size(); ++i) {
      EXPECT_NEAR(restricted.weights[i], own.weights[i], 1e-15);
      EXPECT_NEAR((restricted.normals[i] - own.normals[i]).norm(), 0.0, 1e-14);
    }
    ASSERT_EQ(restricted.surfaces.size(), 1u);
    EXPECT_EQ(restricted.surfaces.front().facets, own.surfaces.front().facets);
  }

  expect_error(
      exchange(server.socket, lower_block_contact_setup(id++, {"contact", "left", "contact"})),
      protocol::BAD_INPUT, "SetupBody.contact_boundaries[2] repeats 'contact'");
  expect_hello(server.socket, id++);
  expect_error(exchange(server.socket, lower_block_contact_setup(id++, {"contact", "nowhere"})),
               protocol::BAD_INPUT,
               "SetupBody.contact_boundaries[1] 'nowhere' is not a boundary of the mesh");
  expect_hello(server.socket, id++);
  expect_error(exchange(server.socket, lower_block_contact_setup(id++, {})), protocol::BAD_INPUT,
               "SetupBody.contact_boundaries is empty");
  expect_hello(server.socket, id++);
  expect_error(exchange(server.socket,
                        lower_block_contact_setup(id++, std::vector<std::string>(65, "contact"))),
               protocol::BAD_INPUT, "SetupBody.contact_boundaries has 65 names, more than the 64");
  expect_hello(server.socket, id++);
  // and the server still sets a body up
  EXPECT_TRUE(exchange(server.socket, lower_block_contact_setup(id++, {"left", "contact"}))
                  .has_interface());
}

}  // namespace
}  // namespace robin
