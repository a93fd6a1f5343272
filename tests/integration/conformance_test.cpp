// The protocol conformance checker (robin-coordinator --check-server) against the real
// robin-subdomain, against servers written here that deviate in known ways (a REP socket that
// answers everything with HelloReply, one that never answers, a proxy to robin-subdomain that
// corrupts one aspect of its replies or requests), and through the robin-coordinator command
// line. Each deviation must fail the checks that judge it, with an explanation naming the
// message, and the checker must keep to its deadlines. The optional Neumann solve (protocol
// 1.1) is checked when announced; a server without it (robin-subdomain --without-capability
// neumann_solve) conforms. The run rule of protocol 1.2 (Envelope.run_id: another run's requests
// are WRONG_STATE) holds for every 2.x server and is judged on each (also one announcing minor
// version 1), and a proxy that strips run_id fails the check; a 1.x server (major version 1)
// cannot conform to 2.0 and is not judged on run ids. Solid bodies (protocol 2.4): the reference
// server passes the solid-body checks; a server that answers the solid SetupBody with
// UNSUPPORTED (a plane-only server) still conforms, its verdict "3D: not supported", and one
// whose solid fields are wrong fails 'solid_fields'.

#include "remote/conformance_check.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <thread>
#include <zmq.hpp>

#include "protocol_version.hpp"
#include "remote/conformance_body.hpp"
#include "remote_test_support.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

using protocol::Envelope;
using robin::testing::seconds_since;

// --- Servers written for the tests -------------------------------------------------------------

struct FakeReply {
  std::optional<std::string> bytes;  // nullopt: never answer (the socket goes silent)
  bool then_stop = false;            // close the socket after this reply (like an exiting server)
};
using Responder = std::function<FakeReply(const std::vector<std::string>& frames)>;

/// A REP socket on an ephemeral tcp port, served by a thread that asks `responder` for the
/// reply to every message.
class FakeServer {
 public:
  explicit FakeServer(Responder responder) : responder_(std::move(responder)) {
    socket_.set(zmq::sockopt::linger, 1000);  // a reply before closing still goes out
    socket_.bind("tcp://127.0.0.1:*");
    endpoint_ = socket_.get(zmq::sockopt::last_endpoint);
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeServer() {
    stop_ = true;
    thread_.join();
  }
  const std::string& endpoint() const { return endpoint_; }

 private:
  void serve() {
    while (!stop_) {
      zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(20));
      if ((item.revents & ZMQ_POLLIN) == 0) continue;
      std::vector<std::string> frames;
      zmq::message_t frame;
      do {
        (void)socket_.recv(frame);
        frames.push_back(frame.to_string());
      } while (frame.more());
      const FakeReply reply = responder_(frames);
      if (!reply.bytes) break;  // silent from now on: the socket stays, nothing is answered
      (void)socket_.send(zmq::buffer(*reply.bytes), zmq::send_flags::none);
      if (reply.then_stop) {
        socket_.close();  // like an exiting server: a new connection finds nobody
        break;
      }
    }
    while (!stop_) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }

  Responder responder_;
  zmq::context_t context_{1};
  zmq::socket_t socket_{context_, zmq::socket_type::rep};
  std::string endpoint_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::string hello_reply_to(const std::vector<std::string>& frames) {
  Envelope request, reply;
  if (frames.size() == 1 && request.ParseFromString(frames[0])) {
    reply.set_request_id(request.request_id());
  }
  reply.mutable_version()->set_major(protocol::protocol_major);
  reply.mutable_hello_reply()->set_server_name("hello-only test server");
  for (const char* capability : {"contact_solve", "correction_solve", "fields"}) {
    reply.mutable_hello_reply()->add_capabilities(capability);
  }
  reply.mutable_hello_reply()->set_state("awaiting_setup");
  return reply.SerializeAsString();
}

/// Changes a parsed request before it is forwarded, or a parsed reply before it is returned.
using Mutation = std::function<void(Envelope&)>;

/// A responder that forwards every message to `endpoint` (a REQ socket of the serving thread)
/// and passes requests and replies through the mutations. `on_shutdown` answers Shutdown
/// itself when set (robin-subdomain's own Acknowledge to Shutdown can be lost, see the report).
Responder proxy_to(const std::string& endpoint, Mutation on_request, Mutation on_reply,
                   std::function<FakeReply(const Envelope&)> on_shutdown = {}) {
  struct Backend {  // the socket is closed before its context
    zmq::context_t context{1};
    std::unique_ptr<zmq::socket_t> socket;
  };
  auto backend = std::make_shared<Backend>();
  return [=](const std::vector<std::string>& frames) -> FakeReply {
    std::unique_ptr<zmq::socket_t>& socket = backend->socket;
    if (!socket) {
      socket = std::make_unique<zmq::socket_t>(backend->context, zmq::socket_type::req);
      socket->set(zmq::sockopt::linger, 0);
      socket->set(zmq::sockopt::rcvtimeo, 5000);
      socket->connect(endpoint);
    }
    std::vector<std::string> forwarded = frames;
    Envelope request;
    if (frames.size() == 1 && request.ParseFromString(frames[0])) {
      if (request.has_shutdown() && on_shutdown) return on_shutdown(request);
      if (on_request) on_request(request);
      forwarded[0] = request.SerializeAsString();
    }
    for (std::size_t i = 0; i < forwarded.size(); ++i) {
      const auto flags =
          i + 1 < forwarded.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      (void)socket->send(zmq::buffer(forwarded[i]), flags);
    }
    zmq::message_t answer;
    if (!socket->recv(answer)) return {std::nullopt};
    Envelope reply;
    if (!on_reply || !reply.ParseFromArray(answer.data(), static_cast<int>(answer.size()))) {
      return {answer.to_string()};
    }
    on_reply(reply);
    return {reply.SerializeAsString()};
  };
}

// --- Helpers -----------------------------------------------------------------------------------

const ConformanceCheck* find_check(const ConformanceReport& report, const std::string& name) {
  for (const ConformanceCheck& check : report.checks) {
    if (check.name == name) return &check;
  }
  return nullptr;
}

::testing::AssertionResult fails_with(const ConformanceReport& report, const std::string& name,
                                      const std::vector<std::string>& words) {
  const ConformanceCheck* check = find_check(report, name);
  if (check == nullptr) return ::testing::AssertionFailure() << "no check named " << name;
  if (check->passed) return ::testing::AssertionFailure() << name << " passed";
  for (const std::string& word : words) {
    if (check->explanation.find(word) == std::string::npos) {
      return ::testing::AssertionFailure()
             << name << ": '" << check->explanation << "' does not mention '" << word << "'";
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult passes(const ConformanceReport& report, const std::string& name) {
  const ConformanceCheck* check = find_check(report, name);
  if (check == nullptr) return ::testing::AssertionFailure() << "no check named " << name;
  if (!check->passed) return ::testing::AssertionFailure() << name << ": " << check->explanation;
  return ::testing::AssertionSuccess();
}

/// The names of the failed checks, for messages.
std::string failed_checks(const ConformanceReport& report) {
  std::string names;
  for (const ConformanceCheck& check : report.checks) {
    if (!check.passed) names += "\n  " + check.name + ": " + check.explanation;
  }
  return names;
}

/// One robin-subdomain for the whole file (every check run starts with EndRun).
class ConformanceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = std::make_unique<testing::TemporaryDirectory>("conformance");
    ServerLaunchOptions launch = testing::server_options(directory_->path() / "logs");
    launch.shutdown_timeout_seconds = 0.5;  // its Acknowledge to Shutdown can be lost
    server_ = std::make_unique<SubdomainServer>("reference", launch);
    server_->await_listening();
  }
  static void TearDownTestSuite() {
    server_.reset();
    directory_.reset();
  }
  static const std::string& reference_endpoint() { return server_->endpoint(); }

  static ConformanceOptions quick_options() {
    ConformanceOptions options;
    options.reply_timeout_seconds = 5.0;
    options.oversized_message_bytes = 1L << 20;
    return options;
  }

  static std::unique_ptr<testing::TemporaryDirectory> directory_;
  static std::unique_ptr<SubdomainServer> server_;
};

std::unique_ptr<testing::TemporaryDirectory> ConformanceTest::directory_;
std::unique_ptr<SubdomainServer> ConformanceTest::server_;

// --- The reference server ----------------------------------------------------------------------

TEST_F(ConformanceTest, ReferenceServerPassesEveryCheck) {
  ConformanceOptions options;  // the defaults: 10 s deadlines, a 64 MiB oversized message
  const auto start = std::chrono::steady_clock::now();
  const ConformanceReport report = check_server(reference_endpoint(), options);
  const double seconds = seconds_since(start);
  EXPECT_TRUE(report.conforms()) << failed_checks(report);
  EXPECT_GE(report.checks.size(), 40u);
  EXPECT_NE(report.server_name.find("robin-subdomain"), std::string::npos);
  for (const char* name : {"hello",
                           "version_mismatch",
                           "garbage_bytes",
                           "empty_envelope",
                           "contact_solve_before_setup",
                           "setup_floating_body",
                           "setup_body",
                           "assign_unknown_node",
                           "contact_solve_wrong_length",
                           "contact_solve_signorini",
                           "correction_linearity",
                           "correction_symmetry",
                           "fields_structure",
                           "end_run",
                           "second_run",
                           "voigt_material",
                           "oversized_message",
                           "request_id_echoed",
                           "version_on_every_reply",
                           "neumann_solve_capability",
                           "neumann_solve_before_setup",
                           "neumann_solve_before_assignment",
                           "neumann_solve_wrong_length",
                           "neumann_solve_non_finite",
                           "neumann_solve_free",
                           "neumann_solve_equation",
                           "neumann_solve_contact_consistency",
                           "other_run_refused",
                           "status",
                           "status_idle",
                           "solid_setup_body",
                           "solid_assign_contact",
                           "solid_contact_solve",
                           "solid_correction",
                           "solid_neumann_solve",
                           "solid_fields",
                           "solid_end_run"}) {
    EXPECT_TRUE(passes(report, name)) << name;
  }
  EXPECT_EQ(find_check(report, "neumann_solve_capability")->explanation, "announced: checked");
  EXPECT_EQ(find_check(report, "status")->explanation, "announced: checked");
  EXPECT_EQ(find_check(report, "other_run_refused")->explanation, "");  // judged, no note
  EXPECT_EQ(find_check(report, "solid_setup_body")->explanation, "");   // solved, no note
  EXPECT_EQ(find_check(report, "neumann_solve_unsupported"), nullptr);
  EXPECT_EQ(find_check(report, "shutdown"), nullptr);  // only with include_shutdown
  std::cout << "reference server: " << report.checks.size() << " checks in " << seconds << " s\n";
}

TEST_F(ConformanceTest, ServerThatDropsOversizedMessagesConformsAndShutsDown) {
  // libzmq drops a message above --max-message-size and disconnects its sender: no reply, and
  // the server answers the next connection. The rule accepts that as well as an answer.
  testing::TemporaryDirectory directory("conformance-drop");
  ServerLaunchOptions launch = testing::server_options(directory.path());
  launch.extra_arguments = {"--max-message-size", "1048576"};
  SubdomainServer server("small", launch);
  server.await_listening();
  ConformanceOptions options = quick_options();
  options.oversized_message_bytes = 4L << 20;
  options.include_shutdown = true;
  const auto start = std::chrono::steady_clock::now();
  const ConformanceReport report = check_server(server.endpoint(), options);
  EXPECT_TRUE(report.conforms()) << failed_checks(report);
  EXPECT_TRUE(passes(report, "oversized_message"));
  EXPECT_TRUE(passes(report, "shutdown"));
  EXPECT_LT(seconds_since(start), 10.0);  // the dropped connection is noticed at once
  std::string fate;
  for (int wait = 0; wait < 100 && fate.empty(); ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    fate = server.failure();
  }
  EXPECT_NE(fate.find("exited with status 0"), std::string::npos) << fate;
}

TEST_F(ConformanceTest, ServerWithoutTheOptionalNeumannSolveConforms) {
  // A 2.0 server without the optional "neumann_solve": its request UNSUPPORTED.
  testing::TemporaryDirectory directory("conformance-2.0-no-neumann");
  ServerLaunchOptions launch = testing::server_options(directory.path());
  launch.extra_arguments = {"--protocol-minor", "0", "--without-capability", "neumann_solve"};
  SubdomainServer server("old", launch);
  server.await_listening();
  const ConformanceReport report = check_server(server.endpoint(), quick_options());
  EXPECT_TRUE(report.conforms()) << failed_checks(report);
  EXPECT_TRUE(passes(report, "neumann_solve_unsupported"));
  const ConformanceCheck* note = find_check(report, "neumann_solve_capability");
  ASSERT_NE(note, nullptr);
  EXPECT_TRUE(note->passed);
  EXPECT_NE(note->explanation.find("not announced"), std::string::npos) << note->explanation;
  for (const char* name : {"neumann_solve_before_setup", "neumann_solve_equation"}) {
    EXPECT_EQ(find_check(report, name), nullptr) << name;
  }
  EXPECT_NE(format_report(report).find("PASS neumann_solve_capability (not announced"),
            std::string::npos);
  // run_id is honoured by every 2.x server: the check is made, and passed.
  EXPECT_TRUE(passes(report, "other_run_refused"));
  const ConformanceCheck* run_check = find_check(report, "other_run_refused");
  ASSERT_NE(run_check, nullptr);
  EXPECT_EQ(run_check->explanation.find("not applicable"), std::string::npos)
      << run_check->explanation;
}

/// A proxy to robin-subdomain that plays a plane-only 2.4 server: a SetupBody of a solid body
/// is forwarded as an EndRun (the server stays without a body) and answered UNSUPPORTED.
Responder plane_only_proxy(const std::string& endpoint) {
  auto solid_setup = std::make_shared<bool>(false);
  return proxy_to(
      endpoint,
      [solid_setup](Envelope& request) {
        *solid_setup = request.has_setup_body() && request.setup_body().mesh().dimension() == 3;
        if (*solid_setup) request.mutable_end_run();
      },
      [solid_setup](Envelope& reply) {
        if (!*solid_setup) return;
        reply.mutable_error()->set_code(protocol::UNSUPPORTED);
        reply.mutable_error()->set_message("solid bodies are not implemented by this server");
        reply.mutable_error()->set_state("awaiting_setup");
      });
}

TEST_F(ConformanceTest, PlaneOnlyServerConformsWithoutSolidBodies) {
  FakeServer proxy(plane_only_proxy(reference_endpoint()));
  const ConformanceReport report = check_server(proxy.endpoint(), quick_options());
  EXPECT_TRUE(report.conforms()) << failed_checks(report);
  ASSERT_TRUE(passes(report, "solid_setup_body"));
  const std::string note = find_check(report, "solid_setup_body")->explanation;
  EXPECT_EQ(note.rfind("3D: not supported", 0), 0u) << note;
  EXPECT_NE(note.find("UNSUPPORTED"), std::string::npos) << note;
  for (const char* name : {"solid_assign_contact", "solid_contact_solve", "solid_fields"}) {
    EXPECT_EQ(find_check(report, name), nullptr) << name;
  }
  EXPECT_NE(format_report(report).find("PASS solid_setup_body (3D: not supported"),
            std::string::npos);
}

TEST_F(ConformanceTest, WrongSolidDisplacementFailsTheSolidFieldsCheck) {
  // The solid FieldsReply (dimension 3) with every displacement value doubled.
  FakeServer proxy(proxy_to(reference_endpoint(), {}, [](Envelope& reply) {
    if (!reply.has_fields_reply() || reply.fields_reply().dimension() != 3) return;
    for (protocol::Field& field : *reply.mutable_fields_reply()->mutable_point_fields()) {
      if (field.name() != "displacement") continue;
      for (double& value : *field.mutable_values()) value *= 2.0;
    }
  }));
  const ConformanceReport report = check_server(proxy.endpoint(), quick_options());
  EXPECT_TRUE(fails_with(report, "solid_fields", {"point field 'displacement'", "reference"}));
  EXPECT_TRUE(passes(report, "solid_contact_solve"));
  EXPECT_TRUE(passes(report, "fields_structure"));  // the plane fields are untouched
}

TEST_F(ConformanceTest, ServerOfMinorVersion1IsJudgedOnRunIds) {
  // robin-subdomain --protocol-minor 1 announces 2.1: within 2.x the run rule always holds (a
  // minor version only adds), so 'other_run_refused' judges it, and it honours run_id.
  testing::TemporaryDirectory directory("conformance-2.1");
  ServerLaunchOptions launch = testing::server_options(directory.path());
  launch.extra_arguments = {"--protocol-minor", "1"};
  SubdomainServer server("minor1", launch);
  server.await_listening();
  const ConformanceReport report = check_server(server.endpoint(), quick_options());
  EXPECT_TRUE(report.conforms()) << failed_checks(report);
  const ConformanceCheck* check = find_check(report, "other_run_refused");
  ASSERT_NE(check, nullptr);
  EXPECT_TRUE(check->passed) << check->explanation;
  EXPECT_EQ(check->explanation.find("not applicable"), std::string::npos) << check->explanation;
  EXPECT_TRUE(passes(report, "neumann_solve_equation"));
}

TEST_F(ConformanceTest, ServerOfProtocol11IsNotJudgedOnRunIds) {
  // robin-subdomain --protocol-major 1 --protocol-minor 1 plays a 1.1 server (which ignores
  // Envelope.run_id): a 2.0 checker cannot talk to it, every check fails on VERSION_MISMATCH,
  // and the run rule is not judged (the checker has no HelloReply to learn the version from).
  testing::TemporaryDirectory directory("conformance-1.1");
  ServerLaunchOptions launch = testing::server_options(directory.path());
  launch.extra_arguments = {"--protocol-major", "1", "--protocol-minor", "1"};
  SubdomainServer server("old", launch);
  server.await_listening();
  const ConformanceReport report = check_server(server.endpoint(), quick_options());
  EXPECT_FALSE(report.conforms());
  EXPECT_TRUE(fails_with(report, "hello", {"VERSION_MISMATCH", "this server 1.1"}));
  EXPECT_TRUE(fails_with(report, "other_run_refused", {"not checked"}));
}

// --- Servers that do not conform ----------------------------------------------------------------

TEST_F(ConformanceTest, HelloOnlyServerFailsEveryOtherMessage) {
  FakeServer fake(
      [](const std::vector<std::string>& frames) { return FakeReply{hello_reply_to(frames)}; });
  const auto start = std::chrono::steady_clock::now();
  const ConformanceReport report = check_server(fake.endpoint(), quick_options());
  EXPECT_FALSE(report.conforms());
  EXPECT_TRUE(passes(report, "hello"));
  EXPECT_TRUE(fails_with(report, "end_run_before_checks",
                         {"EndRun", "expected Acknowledge", "HelloReply"}));
  EXPECT_TRUE(
      fails_with(report, "version_mismatch",
                 {"Hello with version " + std::to_string(protocol::protocol_major + 1) + ".0",
                  "Error{VERSION_MISMATCH}", "HelloReply"}));
  EXPECT_TRUE(fails_with(report, "garbage_bytes", {"ff ff ff", "MALFORMED_MESSAGE"}));
  EXPECT_TRUE(fails_with(report, "contact_solve_before_setup",
                         {"ContactSolveRequest before SetupBody", "WRONG_STATE", "HelloReply"}));
  EXPECT_TRUE(fails_with(report, "setup_floating_body", {"SINGULAR_BODY", "HelloReply"}));
  EXPECT_TRUE(fails_with(report, "setup_body", {"SetupBody", "InterfaceDescription"}));
  EXPECT_TRUE(fails_with(report, "contact_solve_signorini", {"not checked", "setup_body"}));
  EXPECT_TRUE(passes(report, "request_id_echoed"));  // it does echo the ids
  EXPECT_LT(seconds_since(start), 5.0);
}

TEST_F(ConformanceTest, SilentServerFailsWithinTheDeadlines) {
  FakeServer fake([](const std::vector<std::string>&) { return FakeReply{std::nullopt}; });
  ConformanceOptions options = quick_options();
  options.reply_timeout_seconds = 0.5;
  const auto start = std::chrono::steady_clock::now();
  const ConformanceReport report = check_server(fake.endpoint(), options);
  const double seconds = seconds_since(start);
  EXPECT_EQ(report.failure_count(), report.checks.size());
  EXPECT_TRUE(fails_with(report, "hello", {"Hello", "no reply within 0.5 s"}));
  EXPECT_TRUE(fails_with(report, "setup_body", {"not checked", "did not answer a Hello"}));
  EXPECT_TRUE(fails_with(report, "request_id_echoed", {"no reply"}));
  // The first Hello and the Hello on a new connection: two deadlines, then nothing waits.
  EXPECT_GE(seconds, 1.0);
  EXPECT_LT(seconds, 2.5);
}

TEST_F(ConformanceTest, NoServerAtTheEndpointFailsWithinTheDeadlines) {
  testing::TemporaryDirectory directory("conformance-nobody");
  ConformanceOptions options = quick_options();
  options.reply_timeout_seconds = 0.3;
  const auto start = std::chrono::steady_clock::now();
  const ConformanceReport report =
      check_server("ipc://" + (directory.path() / "nobody.sock").string(), options);
  EXPECT_EQ(report.failure_count(), report.checks.size());
  EXPECT_TRUE(fails_with(report, "hello", {"could not send within 0.3 s"}));
  EXPECT_LT(seconds_since(start), 1.5);
}

struct Deviation {
  std::string name;
  Mutation on_request;
  Mutation on_reply;
  std::vector<std::pair<std::string, std::vector<std::string>>> failures;  // check, words
};

std::ostream& operator<<(std::ostream& stream, const Deviation& deviation) {
  return stream << deviation.name;
}

class DeviationTest : public ConformanceTest, public ::testing::WithParamInterface<Deviation> {};

TEST_P(DeviationTest, FailsTheChecksThatJudgeIt) {
  const Deviation& deviation = GetParam();
  FakeServer proxy(proxy_to(reference_endpoint(), deviation.on_request, deviation.on_reply));
  ConformanceOptions options = quick_options();
  options.reply_timeout_seconds = 2.0;  // a reply with a wrong id costs one deadline
  const ConformanceReport report = check_server(proxy.endpoint(), options);
  EXPECT_FALSE(report.conforms());
  EXPECT_TRUE(passes(report, "hello"));
  EXPECT_TRUE(passes(report, "setup_body"));
  for (const auto& [name, words] : deviation.failures) {
    EXPECT_TRUE(fails_with(report, name, words));
  }
}

Deviation negated_contact_force() {
  return {"NegatedContactForce",
          {},
          [](Envelope& reply) {
            if (!reply.has_contact_result()) return;
            for (double& force : *reply.mutable_contact_result()->mutable_contact_force()) {
              force = -force;
            }
          },
          {{"contact_solve_signorini", {"ContactSolveRequest", "contact_force", "< 0"}}}};
}

Deviation ignored_pair_order() {
  // The server sees the nodes in ascending id order: it applies the obstacles to other nodes.
  return {"IgnoredPairOrder",
          [](Envelope& request) {
            if (!request.has_assign_contact()) return;
            auto& ids = *request.mutable_assign_contact()->mutable_node_ids();
            std::sort(ids.begin(), ids.end());
          },
          {},
          {{"fields_pair_order", {"FieldsRequest", "pair index", "pair order of AssignContact"}}}};
}

Deviation shifted_correction() {
  // w = F r + 1e-3: not linear, and u_N = e - F lambda no longer holds.
  return {"ShiftedCorrection",
          {},
          [](Envelope& reply) {
            if (!reply.has_correction_result()) return;
            for (double& trace : *reply.mutable_correction_result()->mutable_normal_trace()) {
              trace += 1e-3;
            }
          },
          {{"correction_linearity", {"w(2 r) != 2 w(r)"}},
           {"contact_solve_equilibrium", {"u_N = e - F lambda"}}}};
}

Deviation negated_neumann_force() {
  // The server loads the body with +lambda n instead of -lambda n: u_N = e + F lambda.
  return {"NegatedNeumannForce",
          [](Envelope& request) {
            if (!request.has_neumann_solve()) return;
            for (double& force : *request.mutable_neumann_solve()->mutable_contact_force()) {
              force = -force;
            }
          },
          {},
          {{"neumann_solve_equation", {"u_N = e - F lambda", "it equals e + F lambda"}},
           {"neumann_solve_contact_consistency", {"contact solve's u_N"}}}};
}

Deviation neumann_without_loads() {
  // The server answers the correction's -F lambda, forgetting its own loads (e).
  return {"NeumannWithoutLoads",
          {},
          [](Envelope& reply) {
            if (!reply.has_neumann_result()) return;
            for (double& trace : *reply.mutable_neumann_result()->mutable_normal_trace()) {
              trace -= conformance::lift;
            }
          },
          {{"neumann_solve_free", {"NeumannSolveRequest with lambda = 0", "e = 0.01"}},
           {"neumann_solve_equation", {"u_N = e - F lambda"}}}};
}

Deviation wrong_request_ids() {
  return {"WrongRequestIds",
          {},
          [](Envelope& reply) { reply.set_request_id(reply.request_id() + 1000); },
          {{"request_id_echoed", {"the HelloReply to Hello carries request_id 1001, expected 1"}},
           {"unknown_request_type", {"request_id"}}}};
}

Deviation errors_without_version() {
  return {"ErrorsWithoutVersion",
          {},
          [](Envelope& reply) {
            if (reply.has_error()) reply.clear_version();
          },
          {{"version_on_every_reply",
            {"the Error{VERSION_MISMATCH} reply to Hello with version " +
             std::to_string(protocol::protocol_major + 1) + ".0 carries no Version"}}}};
}

Deviation dropped_run_ids() {
  // The server never sees run_id (as a 1.1 server ignores it) but announces 2.0.
  return {"DroppedRunIds",
          [](Envelope& request) { request.clear_run_id(); },
          {},
          {{"other_run_refused",
            {"ContactSolveRequest with run_id 'conformance-check-run-b'",
             "expected Error{WRONG_STATE}", "ContactSolveResult"}}}};
}

Deviation tensor_shear_voigt() {
  // The server reads SetupBody.voigt with tensor shear strain (C_33 = 2 G): another material.
  return {"TensorShearVoigt",
          [](Envelope& request) {
            if (!request.has_setup_body() || request.setup_body().voigt_size() != 9) return;
            request.mutable_setup_body()->set_voigt(8, 2.0 * request.setup_body().voigt(8));
          },
          {},
          {{"voigt_material",
            {"equivalent Voigt matrix", "isotropic definition's",
             "does not read SetupBody.voigt as the same material"}}}};
}

Deviation isotropic_only_material() {
  // The server understands only young_modulus/poisson_ratio: a Voigt material is no material.
  return {"IsotropicOnlyMaterial",
          [](Envelope& request) {
            if (request.has_setup_body()) request.mutable_setup_body()->clear_voigt();
          },
          {},
          {{"voigt_material",
            {"SetupBody (the equivalent Voigt matrix", "expected InterfaceDescription"}}}};
}

Deviation no_fields_reactions() {
  return {"NoReactionResultant",
          {},
          [](Envelope& reply) {
            if (reply.has_fields_reply()) reply.mutable_fields_reply()->clear_reaction_resultant();
          },
          {{"fields_equilibrium", {"FieldsRequest", "reaction_resultant"}}}};
}

Deviation busy_while_idle() {
  // StatusReply claims a factorization under way between requests.
  return {"BusyWhileIdle",
          {},
          [](Envelope& reply) {
            if (!reply.has_status_reply()) return;
            reply.mutable_status_reply()->set_busy(true);
            reply.mutable_status_reply()->set_stage("factorization");
          },
          {{"status_idle",
            {"StatusRequest in state ready, between requests", "busy true", "factorization"}}}};
}

INSTANTIATE_TEST_SUITE_P(Conformance, DeviationTest,
                         ::testing::Values(negated_contact_force(), ignored_pair_order(),
                                           shifted_correction(), negated_neumann_force(),
                                           neumann_without_loads(), wrong_request_ids(),
                                           errors_without_version(), no_fields_reactions(),
                                           dropped_run_ids(), tensor_shear_voigt(),
                                           isotropic_only_material(), busy_while_idle()),
                         [](const auto& info) { return info.param.name; });

// --- Contact surfaces (InterfaceDescription.surfaces) --------------------------------------------

/// A proxy whose InterfaceDescription has its surfaces changed by `change`: setup_body must fail
/// naming `words`.
void expect_surface_deviation_fails(const std::string& endpoint,
                                    const std::function<void(protocol::ContactSurface&)>& change,
                                    const std::vector<std::string>& words) {
  FakeServer proxy(proxy_to(endpoint, {}, [&change](Envelope& reply) {
    if (!reply.has_interface()) return;
    for (protocol::ContactSurface& surface : *reply.mutable_interface()->mutable_surfaces()) {
      change(surface);
    }
  }));
  ConformanceOptions options;
  options.reply_timeout_seconds = 2.0;
  options.oversized_message_bytes = 1L << 20;
  const ConformanceReport report = check_server(proxy.endpoint(), options);
  EXPECT_TRUE(passes(report, "hello"));
  EXPECT_TRUE(fails_with(report, "setup_body", words));
}

// Issue 12: the checker judges the segments of the top edge. robin-subdomain passes
// (ReferenceServerPassesEveryCheck); a server whose segments run the other way (the body on their
// right: outward normal (0, -1) against the node normals (0, 1)), name a position beyond the
// nodes, or leave a node out fails setup_body, naming the defect.
TEST_F(ConformanceTest, SurfacesWithReversedOrMissingSegmentsFailTheSetupCheck) {
  const ConformanceReport reference = check_server(reference_endpoint(), quick_options());
  ASSERT_TRUE(passes(reference, "setup_body"));
  expect_surface_deviation_fails(
      reference_endpoint(),
      [](protocol::ContactSurface& surface) {
        auto& segments = *surface.mutable_segments();
        for (int first = 0; first + 1 < segments.size(); first += 2) {
          std::swap(segments[first], segments[first + 1]);
        }
      },
      {"InterfaceDescription of the unit square's top edge", "segment 0 of 'top'",
       "outward normal (0, -1)", "reversed segment?"});
  expect_surface_deviation_fails(
      reference_endpoint(),
      [](protocol::ContactSurface& surface) { surface.set_segments(0, 1000); },
      {"surfaces[0].segments holds the position 1000", "not less than the node count 5"});
  expect_surface_deviation_fails(
      reference_endpoint(),
      [](protocol::ContactSurface& surface) {
        surface.mutable_segments()->Truncate(surface.segments_size() - 2);
      },
      {"the segments of 'top' are 0.75 long together", "is in no segment of 'top'"});
  expect_surface_deviation_fails(
      reference_endpoint(), [](protocol::ContactSurface& surface) { surface.set_boundary("x"); },
      {"surfaces[0].boundary is 'x', expected 'top'"});
}

// --- Shutdown (only with include_shutdown) ------------------------------------------------------

/// Acknowledges Shutdown itself; `stops` says whether it then closes its socket.
std::function<FakeReply(const Envelope&)> shutdown_answer(bool stops) {
  return [stops](const Envelope& request) {
    Envelope reply;
    reply.set_request_id(request.request_id());
    reply.mutable_version()->set_major(protocol::protocol_major);
    reply.mutable_acknowledge()->set_state("awaiting_setup");
    return FakeReply{reply.SerializeAsString(), stops};
  };
}

TEST_F(ConformanceTest, ShutdownMustStopTheServer) {
  ConformanceOptions options = quick_options();
  options.include_shutdown = true;
  {
    FakeServer stopping(proxy_to(reference_endpoint(), {}, {}, shutdown_answer(true)));
    const ConformanceReport report = check_server(stopping.endpoint(), options);
    EXPECT_TRUE(report.conforms()) << failed_checks(report);
    EXPECT_TRUE(passes(report, "shutdown"));
  }
  FakeServer immortal(proxy_to(reference_endpoint(), {}, {}, shutdown_answer(false)));
  const ConformanceReport report = check_server(immortal.endpoint(), options);
  EXPECT_TRUE(fails_with(report, "shutdown", {"still answered a Hello", "after its Acknowledge"}));
}

// --- The command line ---------------------------------------------------------------------------

struct CommandResult {
  int exit_code = -1;
  std::string output;
};

CommandResult run_command(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) {
    result.output += buffer.data();
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

TEST_F(ConformanceTest, CommandLinePrintsOneLinePerCheckAndTheExitCode) {
  const std::string coordinator = testing::tool("robin-coordinator").string();
  const CommandResult conforming = run_command(
      coordinator + " --check-server " + reference_endpoint() + " --max-message-size-probe 1024");
  EXPECT_EQ(conforming.exit_code, 0) << conforming.output;
  EXPECT_NE(conforming.output.find("\nPASS hello\n"), std::string::npos);
  EXPECT_NE(conforming.output.find("0 failed"), std::string::npos);
  EXPECT_NE(conforming.output.find("the server conforms"), std::string::npos);

  testing::TemporaryDirectory directory("conformance-cli");
  const CommandResult nobody =
      run_command(coordinator + " --check-server ipc://" +
                  (directory.path() / "nobody.sock").string() + " --timeout 0.2");
  EXPECT_EQ(nobody.exit_code, 1) << nobody.output;
  EXPECT_NE(nobody.output.find("FAIL hello: Hello: could not send within 0.2 s"), std::string::npos)
      << nobody.output;
  EXPECT_NE(nobody.output.find("does not conform"), std::string::npos);

  EXPECT_EQ(run_command(coordinator + " --check-server").exit_code, 2);
  EXPECT_EQ(run_command(coordinator + " --check-server tcp://127.0.0.1:1 --timeout -1").exit_code,
            2);
}

}  // namespace
}  // namespace robin
