#include "remote/conformance_check.hpp"

#include <zmq.h>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <zmq.hpp>

#include "protocol_version.hpp"
#include "remote/request_channel.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

using protocol::Envelope;
using Content = protocol::Envelope::ContentCase;

// --- The built-in body -------------------------------------------------------------------

constexpr const char* square_geo = R"(// robin-coordinator --check-server: the unit square [0, 1]^2.
DefineConstant[ h = 0.25 ];
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, h};
Point(3) = {1, 1, 0, h};
Point(4) = {0, 1, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("square") = {1};
)";
constexpr const char* body_name = "conformance_square";
constexpr double mesh_size = 0.25;
constexpr double young_modulus = 1000.0;
constexpr double poisson_ratio = 0.3;
constexpr double lift = 0.01;  // prescribed u_y of the bottom edge: e_i = lift on the top edge
constexpr double contact_length = 1.0;
constexpr double far_obstacle = 1.0;  // g_i >> lift: no contact
/// A reference force: the whole top edge pushed back by `lift` (E * strain * length).
constexpr double force_reference = young_modulus * lift * contact_length;

const std::vector<std::string> core_capabilities = {"contact_solve", "correction_solve", "fields"};
const std::vector<std::string> state_names = {"awaiting_setup", "awaiting_assignment", "ready"};

/// The partial-contact obstacle of a node at abscissa x: below the free trace `lift` for
/// x < 0.5, above it for x > 0.5, so that some nodes touch and others do not.
double partial_obstacle(double x) {
  return lift * (0.5 + x);
}

// --- Small helpers -------------------------------------------------------------------------

std::string number(double value) {
  std::ostringstream text;
  text.precision(6);
  text << value;
  return text.str();
}

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : separator) + part;
  return text;
}

/// The first `limit` problems joined by "; ", with the count of the others.
std::string summarize(const std::vector<std::string>& problems, std::size_t limit = 3) {
  std::vector<std::string> shown(problems.begin(),
                                 problems.begin() + std::min(limit, problems.size()));
  std::string text = join(shown, "; ");
  if (problems.size() > limit) {
    text += "; and " + std::to_string(problems.size() - limit) + " more";
  }
  return text;
}

/// "what: problem", or "" when there is no problem.
std::string in_context(const std::string& what, const std::string& problem) {
  return problem.empty() ? problem : what + ": " + problem;
}

Eigen::VectorXd to_vector(const google::protobuf::RepeatedField<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
}

bool all_finite(const google::protobuf::RepeatedField<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

std::string content_name(Content content) {
  const auto* field = Envelope::GetDescriptor()->FindFieldByNumber(content);
  return field == nullptr ? "(no content)" : field->message_type()->name();
}

/// What a reply is, for messages: "HelloReply", "Error{WRONG_STATE: ...}".
std::string describe(const Envelope& reply) {
  if (reply.has_error()) {
    std::string message = reply.error().message();
    if (message.size() > 160) message = message.substr(0, 157) + "...";
    return "Error{" + protocol::ErrorCode_Name(reply.error().code()) + ": " + message + "}";
  }
  if (reply.content_case() == Envelope::CONTENT_NOT_SET) return "an Envelope without content";
  return content_name(reply.content_case());
}

std::string error_names(const std::vector<protocol::ErrorCode>& codes) {
  std::vector<std::string> names;
  for (const protocol::ErrorCode code : codes) names.push_back(protocol::ErrorCode_Name(code));
  return "Error{" + join(names, " or ") + "}";
}

/// A check that cannot run because an earlier one failed; the text says which.
class NotChecked : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// --- The raw connection --------------------------------------------------------------------

struct ReceivedMessage {
  std::vector<std::string> frames;
  std::string problem;  // empty when a message arrived
};

/// One DEALER connection that sends any frames after the empty delimiter and returns the reply
/// frames as they are, so that the checker sees exactly what the server sends (RequestChannel
/// stamps our version and id on every request and discards replies with another id).
class ProbeConnection {
 public:
  /// `immediate`: queue nothing before the connection exists (a missing server makes the send
  /// time out). Without it, a reply that arrives just before the server closes the connection
  /// is still delivered: with ZMQ_IMMEDIATE libzmq discards the unread messages of a lost
  /// connection, which loses the Acknowledge of a server that exits after Shutdown.
  ProbeConnection(zmq::context_t& context, const std::string& endpoint, bool immediate)
      : socket_(context, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.set(zmq::sockopt::immediate, immediate ? 1 : 0);
    socket_.set(zmq::sockopt::maxmsgsize, std::int64_t{1} << 30);
    socket_.connect(endpoint);  // throws zmq::error_t for a malformed endpoint
  }

  /// Sends the delimiter and `frames`; returns the problem, or "".
  std::string send(const std::vector<std::string>& frames, const Deadline& deadline) {
    if (!wait_for(ZMQ_POLLOUT, deadline)) {
      return "could not send within " + number(deadline.seconds) +
             " s: no connection to the server (is it running at that endpoint?)";
    }
    bool sent = socket_.send(zmq::message_t(), zmq::send_flags::sndmore).has_value();
    for (std::size_t i = 0; sent && i < frames.size(); ++i) {
      const auto flags = i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      sent = socket_.send(zmq::buffer(frames[i]), flags).has_value();
    }
    return sent ? "" : "the request could not be queued for sending";
  }

  ReceivedMessage receive(const Deadline& deadline) {
    if (!wait_for(ZMQ_POLLIN, deadline)) {
      return {{}, "no reply within " + number(deadline.seconds) + " s"};
    }
    ReceivedMessage message;
    zmq::message_t frame;
    do {
      if (!socket_.recv(frame, zmq::recv_flags::dontwait)) {
        return {{}, "a reply was announced but could not be read"};
      }
      message.frames.push_back(frame.to_string());
    } while (frame.more());
    return message;
  }

 private:
  bool wait_for(short events, const Deadline& deadline) {
    for (;;) {
      const auto remaining = deadline.at - Clock::now();
      if (remaining <= Clock::duration::zero()) return false;
      const auto slice = std::min(std::chrono::milliseconds(100),
                                  std::chrono::ceil<std::chrono::milliseconds>(remaining));
      zmq::pollitem_t item{socket_.handle(), 0, events, 0};
      try {
        zmq::poll(&item, 1, slice);
      } catch (const zmq::error_t& error) {
        if (error.num() != EINTR) throw;
        continue;
      }
      if ((item.revents & events) != 0) return true;
    }
  }

  zmq::socket_t socket_;
};

// --- The session: requests, replies, bookkeeping ----------------------------------------------

Envelope hello_request() {
  Envelope envelope;
  envelope.mutable_hello()->set_client_name("robin-coordinator --check-server");
  envelope.mutable_hello()->add_capabilities("fields");
  return envelope;
}

/// One request and what came back.
struct Exchange {
  std::optional<Envelope> reply;  // set when a parsable Envelope came back
  std::string problem;            // why there is no reply (timeout, unparsable, ...)
};

class Session {
 public:
  Session(const std::string& endpoint, const ConformanceOptions& options, ConformanceReport& report)
      : endpoint_(endpoint), options_(options), report_(report) {}

  /// Sends `envelope` with a fresh request id and, when `stamp_version`, our Version.
  Exchange request(Envelope envelope, const std::string& what, bool stamp_version = true) {
    if (stamp_version) {
      envelope.mutable_version()->set_major(protocol::protocol_major);
      envelope.mutable_version()->set_minor(protocol::protocol_minor);
    }
    envelope.set_request_id(next_request_id());
    return send_raw({envelope.SerializeAsString()}, what, envelope.request_id());
  }

  /// Sends `frames` as they are; the reply must carry `expected_id` when one is given.
  Exchange send_raw(const std::vector<std::string>& frames, const std::string& what,
                    std::optional<std::uint64_t> expected_id) {
    Exchange exchange;
    if (!connection_) exchange.problem = connect(connection_, immediate_);
    const Deadline deadline = Deadline::after(options_.reply_timeout_seconds);
    if (exchange.problem.empty()) exchange.problem = connection_->send(frames, deadline);
    if (!exchange.problem.empty()) {
      spoiled_ = true;
      return exchange;
    }
    ReceivedMessage received = connection_->receive(deadline);
    if (!received.problem.empty()) {
      spoiled_ = true;
      exchange.problem = received.problem;
      return exchange;
    }
    Envelope reply;
    if (received.frames.size() != 2 || !received.frames[0].empty()) {
      exchange.problem = "the reply is not an empty delimiter frame and one Envelope (" +
                         std::to_string(received.frames.size()) + " frames)";
    } else if (!reply.ParseFromString(received.frames[1])) {
      exchange.problem = "the reply (" + std::to_string(received.frames[1].size()) +
                         " bytes) is not a serialized robin.protocol.Envelope";
    } else {
      note_reply(reply, what, expected_id);
      exchange.reply = std::move(reply);
    }
    return exchange;
  }

  /// Runs one check and records it; an unresponsive server fails it at once. After a request
  /// without a reply, a new connection replaces the old one (a late reply must not be taken
  /// for the next request's) and must answer a Hello.
  void run(const std::string& name, const std::function<std::string()>& check) {
    if (!unresponsive_.empty()) return record(name, "not checked: " + unresponsive_);
    std::string problem;
    try {
      problem = check();
    } catch (const NotChecked& reason) {
      problem = std::string("not checked: ") + reason.what();
    } catch (const std::exception& error) {
      problem = std::string("the checker's transport failed: ") + error.what();
      spoiled_ = true;
    }
    record(name, problem);
    if (spoiled_) recover(name);
  }

  void record(const std::string& name, const std::string& problem) {
    report_.checks.push_back({name, problem.empty(), problem});
  }

  /// Whether a Hello on a connection of its own gets any reply within `seconds` (not counted
  /// among the replies judged by the reply-wide rules).
  bool answers_hello_within(double seconds) {
    std::unique_ptr<ProbeConnection> probe;
    if (!connect(probe).empty()) return false;
    Envelope hello = hello_request();
    hello.mutable_version()->set_major(protocol::protocol_major);
    hello.set_request_id(next_request_id());
    const Deadline deadline = Deadline::after(seconds);
    return probe->send({hello.SerializeAsString()}, deadline).empty() &&
           probe->receive(deadline).problem.empty();
  }

  std::uint64_t next_request_id() { return next_id_++; }
  const std::string& endpoint() const { return endpoint_; }
  const ConformanceOptions& options() const { return options_; }
  ConformanceReport& report() { return report_; }
  /// Replaces the connection by a new one (at the next request); see ProbeConnection for
  /// `immediate`.
  void reconnect(bool immediate = true) {
    connection_.reset();
    immediate_ = immediate;
  }
  /// Drops the connection without the recovery Hello a request without reply would cause.
  void abandon_connection() {
    reconnect();
    spoiled_ = false;
  }
  void mark_spoiled() { spoiled_ = true; }

  /// The reply-wide rules, over every reply received: request_id echoed, Version present.
  std::string request_id_problems() const { return reply_rule_problems(id_problems_); }
  std::string version_problems() const { return reply_rule_problems(version_problems_); }
  void note_reply(const Envelope& reply, const std::string& what,
                  std::optional<std::uint64_t> expected_id);

 private:
  std::string connect(std::unique_ptr<ProbeConnection>& connection, bool immediate = true) {
    try {
      connection = std::make_unique<ProbeConnection>(context_, endpoint_, immediate);
      return "";
    } catch (const zmq::error_t& error) {
      return "cannot connect to '" + endpoint_ + "': " + error.what() +
             " (endpoints look like tcp://HOST:PORT or ipc:///PATH)";
    }
  }

  void recover(const std::string& after_check);

  std::string reply_rule_problems(const std::vector<std::string>& problems) const {
    if (reply_count_ == 0) return "no reply was received, nothing to judge";
    if (problems.empty()) return "";
    return std::to_string(problems.size()) + " of " + std::to_string(reply_count_) +
           " replies: " + summarize(problems);
  }

  std::string endpoint_;
  const ConformanceOptions& options_;
  ConformanceReport& report_;
  zmq::context_t context_{1};
  std::unique_ptr<ProbeConnection> connection_;
  std::uint64_t next_id_ = 1;
  bool immediate_ = true;
  bool spoiled_ = false;
  std::string unresponsive_;  // why every further check is not run
  int reply_count_ = 0;
  std::vector<std::string> id_problems_;
  std::vector<std::string> version_problems_;
};

void Session::note_reply(const Envelope& reply, const std::string& what,
                         std::optional<std::uint64_t> expected_id) {
  ++reply_count_;
  const std::string type = reply.has_error()
                               ? "Error{" + protocol::ErrorCode_Name(reply.error().code()) + "}"
                               : content_name(reply.content_case());
  const std::string subject = "the " + type + " reply to " + what;
  if (!reply.has_version()) {
    version_problems_.push_back(subject + " carries no Version");
  } else if (reply.version().major() != protocol::protocol_major) {
    version_problems_.push_back(subject + " carries version " +
                                std::to_string(reply.version().major()) + "." +
                                std::to_string(reply.version().minor()) + ", expected major " +
                                std::to_string(protocol::protocol_major));
  }
  if (expected_id && reply.request_id() != *expected_id) {
    id_problems_.push_back(subject + " carries request_id " + std::to_string(reply.request_id()) +
                           ", expected " + std::to_string(*expected_id));
  }
}

void Session::recover(const std::string& after_check) {
  spoiled_ = false;
  reconnect();
  const Exchange hello = request(hello_request(), "Hello (on a new connection)");
  if (hello.reply) {
    spoiled_ = false;
    return;
  }
  unresponsive_ = "the server did not answer a Hello on a new connection after check '" +
                  after_check + "' (" + hello.problem + ")";
  connection_.reset();
}

// --- Expectations -------------------------------------------------------------------------

/// "" when the exchange got a reply with content `expected`; otherwise what came instead.
std::string expect_content(const Exchange& exchange, Content expected) {
  if (!exchange.reply) return exchange.problem;
  if (exchange.reply->content_case() == expected) return "";
  return "expected " + content_name(expected) + ", the reply was " + describe(*exchange.reply);
}

/// "" when the reply is an Error with one of `codes`, a message, and `state` as Error.state.
std::string expect_error(const Exchange& exchange, const std::vector<protocol::ErrorCode>& codes,
                         const std::string& state) {
  if (!exchange.reply) return exchange.problem;
  const std::string expected = "expected " + error_names(codes);
  if (!exchange.reply->has_error())
    return expected + ", the reply was " + describe(*exchange.reply);
  const protocol::Error& error = exchange.reply->error();
  if (std::find(codes.begin(), codes.end(), error.code()) == codes.end()) {
    return expected + ", the reply was " + describe(*exchange.reply);
  }
  if (error.message().empty()) {
    return "the " + protocol::ErrorCode_Name(error.code()) +
           " reply has an empty message (it must say what is wrong)";
  }
  if (!state.empty() && error.state() != state) {
    return "Error.state is '" + error.state() + "', expected '" + state +
           "' (the state after the refused request)";
  }
  return "";
}

/// "" when the reply is Acknowledge{state}.
std::string expect_acknowledge(const Exchange& exchange, const std::string& state) {
  if (const std::string problem = expect_content(exchange, Envelope::kAcknowledge);
      !problem.empty()) {
    return problem;
  }
  const std::string& actual = exchange.reply->acknowledge().state();
  return actual == state ? "" : "Acknowledge.state is '" + actual + "', expected '" + state + "'";
}

// --- Requests --------------------------------------------------------------------------------

protocol::SetupBody square_body() {
  protocol::SetupBody body;
  body.set_body_name(body_name);
  body.set_mesh_content(square_geo);
  body.set_mesh_extension(".geo");
  body.set_mesh_size(mesh_size);
  body.set_element_order(1);
  body.set_model(protocol::PLANE_STRAIN);
  body.set_young_modulus(young_modulus);
  body.set_poisson_ratio(poisson_ratio);
  protocol::Dirichlet& support = *body.add_dirichlet();
  support.set_boundary("bottom");
  support.set_x(0.0);
  support.set_y(lift);
  body.set_contact_boundary("top");
  body.mutable_solver()->set_qp_tolerance(1e-12);
  return body;
}

Envelope setup_request(const protocol::SetupBody& body) {
  Envelope envelope;
  *envelope.mutable_setup_body() = body;
  return envelope;
}

/// A contact node of the built-in body: its server-side id and abscissa.
struct ContactNode {
  std::int64_t id = 0;
  double x = 0.0;
};

Envelope assign_request(const std::vector<ContactNode>& nodes, double normal_length = 1.0) {
  Envelope envelope;
  protocol::AssignContact& assign = *envelope.mutable_assign_contact();
  for (const ContactNode& node : nodes) {
    assign.add_node_ids(node.id);
    assign.add_normals(0.0);  // the outward normal of the top edge, (0, 1)
    assign.add_normals(normal_length);
  }
  return envelope;
}

Envelope contact_solve_request(const Eigen::VectorXd& obstacle, unsigned iteration = 1) {
  Envelope envelope;
  envelope.mutable_contact_solve()->set_iteration(iteration);
  envelope.mutable_contact_solve()->mutable_obstacle()->Assign(obstacle.begin(), obstacle.end());
  return envelope;
}

Envelope correction_request(const Eigen::VectorXd& force) {
  Envelope envelope;
  envelope.mutable_correction()->set_iteration(1);
  envelope.mutable_correction()->mutable_interface_force()->Assign(force.begin(), force.end());
  return envelope;
}

Envelope fields_request(const Eigen::VectorXd& force) {
  Envelope envelope;
  envelope.mutable_fields()->mutable_contact_force()->Assign(force.begin(), force.end());
  return envelope;
}

Envelope end_run_request() {
  Envelope envelope;
  envelope.mutable_end_run();
  return envelope;
}

// --- Judging replies --------------------------------------------------------------------------

/// The contact nodes of an InterfaceDescription in the pair order the checker assigns: by
/// descending x, or ascending when that is the server's own order (so that a server that
/// ignores the pair order is caught).
std::vector<ContactNode> pair_order(const protocol::InterfaceDescription& description) {
  std::vector<ContactNode> nodes;
  for (int i = 0; i < description.node_ids_size(); ++i) {
    nodes.push_back({description.node_ids(i), description.coordinates(2 * i)});
  }
  std::vector<ContactNode> order = nodes;
  std::stable_sort(order.begin(), order.end(),
                   [](const ContactNode& a, const ContactNode& b) { return a.x > b.x; });
  const bool same_as_server =
      std::equal(order.begin(), order.end(), nodes.begin(),
                 [](const ContactNode& a, const ContactNode& b) { return a.id == b.id; });
  if (same_as_server) std::reverse(order.begin(), order.end());
  return order;
}

std::string interface_size_problems(const protocol::InterfaceDescription& description) {
  const int count = description.node_ids_size();
  std::vector<std::string> problems;
  const auto expect_size = [&](const std::string& field, int size, int expected) {
    if (size != expected) {
      problems.push_back(field + " has " + std::to_string(size) + " values for " +
                         std::to_string(count) + " node_ids, expected " + std::to_string(expected));
    }
  };
  expect_size("node_tags", description.node_tags_size(), count);
  expect_size("coordinates", description.coordinates_size(), 2 * count);
  expect_size("normals", description.normals_size(), 2 * count);
  expect_size("weights", description.weights_size(), count);
  expect_size("x_fixed", description.x_fixed_size(), count);
  expect_size("y_fixed", description.y_fixed_size(), count);
  if (count < 2) {
    problems.push_back(std::to_string(count) +
                       " node_ids for the contact boundary 'top', expected at least its two "
                       "end points");
  }
  if (!all_finite(description.coordinates()) || !all_finite(description.normals()) ||
      !all_finite(description.weights())) {
    problems.push_back("coordinates, normals or weights contain a non-finite value");
  }
  return summarize(problems);
}

std::vector<std::string> interface_node_problems(const protocol::InterfaceDescription& description,
                                                 double tolerance) {
  std::vector<std::string> problems;
  std::set<std::int64_t> seen;
  for (int i = 0; i < description.node_ids_size(); ++i) {
    const std::int64_t id = description.node_ids(i);
    const double x = description.coordinates(2 * i), y = description.coordinates(2 * i + 1);
    const std::string node =
        "node id " + std::to_string(id) + " at (" + number(x) + ", " + number(y) + ")";
    if (!seen.insert(id).second) problems.push_back("node id " + std::to_string(id) + " repeats");
    if (id < 0 || id >= (std::int64_t{1} << 31)) {
      problems.push_back(node + ": ids must lie in [0, 2^31)");
    }
    if (std::abs(y - 1.0) > tolerance || x < -tolerance || x > 1.0 + tolerance) {
      problems.push_back(node + " is not on the top edge y = 1, 0 <= x <= 1");
    }
    const double nx = description.normals(2 * i), ny = description.normals(2 * i + 1);
    if (std::abs(nx) > tolerance || std::abs(ny - 1.0) > tolerance) {
      problems.push_back(node + " has normal (" + number(nx) + ", " + number(ny) +
                         "), expected the unit outward normal (0, 1)");
    }
    if (!(description.weights(i) > 0.0)) {
      problems.push_back(node + " has weight " + number(description.weights(i)) + ", expected > 0");
    }
    if (description.x_fixed(i) || description.y_fixed(i)) {
      problems.push_back(node + " is flagged fixed, but no Dirichlet condition reaches the top");
    }
  }
  return problems;
}

/// Linear edges: m_i is half the length of the contact edges next to node i, and the weights
/// sum to the contact boundary's length.
std::vector<std::string> interface_weight_problems(
    const protocol::InterfaceDescription& description, double tolerance) {
  std::vector<std::pair<double, double>> by_x;  // (x, weight)
  for (int i = 0; i < description.node_ids_size(); ++i) {
    by_x.emplace_back(description.coordinates(2 * i), description.weights(i));
  }
  std::sort(by_x.begin(), by_x.end());
  std::vector<std::string> problems;
  double sum = 0.0;
  for (std::size_t i = 0; i < by_x.size(); ++i) {
    sum += by_x[i].second;
    const double left = i == 0 ? by_x[i].first : by_x[i - 1].first;
    const double right = i + 1 == by_x.size() ? by_x[i].first : by_x[i + 1].first;
    const double expected = 0.5 * (right - left);
    if (std::abs(by_x[i].second - expected) > tolerance * contact_length) {
      problems.push_back("the weight of the node at x = " + number(by_x[i].first) + " is " +
                         number(by_x[i].second) + ", expected half its adjacent edges " +
                         number(expected));
    }
  }
  if (std::abs(by_x.front().first) > tolerance || std::abs(by_x.back().first - 1.0) > tolerance) {
    problems.push_back("the nodes do not span the top edge from x = 0 to x = 1");
  }
  if (std::abs(sum - contact_length) > tolerance * contact_length) {
    problems.push_back("the weights sum to " + number(sum) +
                       ", expected the contact boundary's length 1");
  }
  return problems;
}

/// The contact solution of a reply, checked for status, sizes and finite values.
struct ContactSolution {
  Eigen::VectorXd normal_trace;
  Eigen::VectorXd contact_force;
};

std::string read_contact_solution(const Exchange& exchange, long count, ContactSolution& solution) {
  if (const std::string problem = expect_content(exchange, Envelope::kContactResult);
      !problem.empty()) {
    return problem;
  }
  const protocol::ContactSolveResult& result = exchange.reply->contact_result();
  if (result.status() != protocol::CONVERGED) {
    return "status " + protocol::SolveStatus_Name(result.status()) +
           ", expected CONVERGED (message: '" + result.message() + "')";
  }
  if (result.normal_trace_size() != count || result.contact_force_size() != count ||
      (result.active_size() != 0 && result.active_size() != count)) {
    return "normal_trace, contact_force and active have " +
           std::to_string(result.normal_trace_size()) + ", " +
           std::to_string(result.contact_force_size()) + " and " +
           std::to_string(result.active_size()) + " values for " + std::to_string(count) +
           " contact nodes (active may be empty)";
  }
  if (!all_finite(result.normal_trace()) || !all_finite(result.contact_force())) {
    return "normal_trace or contact_force contains a non-finite value";
  }
  solution.normal_trace = to_vector(result.normal_trace());
  solution.contact_force = to_vector(result.contact_force());
  return "";
}

/// The Signorini conditions at every node, relative to the solution's scales.
std::vector<std::string> signorini_problems(const ContactSolution& solution,
                                            const Eigen::VectorXd& obstacle, double tolerance) {
  const double force_scale = std::max(solution.contact_force.cwiseAbs().maxCoeff(), 1e-300);
  const double length_scale = std::max(obstacle.cwiseAbs().maxCoeff(), lift);
  std::vector<std::string> problems;
  for (Eigen::Index i = 0; i < obstacle.size(); ++i) {
    const double force = solution.contact_force(i), trace = solution.normal_trace(i);
    const std::string at = "[" + std::to_string(i) + "]";
    if (force < -tolerance * force_scale) {
      problems.push_back("contact_force" + at + " = " + number(force) + " < 0");
    }
    if (trace - obstacle(i) > tolerance * length_scale) {
      problems.push_back("normal_trace" + at + " = " + number(trace) + " exceeds the obstacle " +
                         number(obstacle(i)));
    }
    const double product = force * (obstacle(i) - trace);
    if (std::abs(product) > tolerance * force_scale * length_scale) {
      problems.push_back("complementarity" + at + ": lambda (g - u_N) = " + number(product) +
                         " (lambda " + number(force) + ", g - u_N " + number(obstacle(i) - trace) +
                         ")");
    }
  }
  return problems;
}

std::string read_correction(const Exchange& exchange, long count, Eigen::VectorXd& trace) {
  if (const std::string problem = expect_content(exchange, Envelope::kCorrectionResult);
      !problem.empty()) {
    return problem;
  }
  const protocol::CorrectionResult& result = exchange.reply->correction_result();
  if (result.normal_trace_size() != count) {
    return "normal_trace has " + std::to_string(result.normal_trace_size()) + " values for " +
           std::to_string(count) + " contact nodes";
  }
  if (!all_finite(result.normal_trace())) return "normal_trace contains a non-finite value";
  trace = to_vector(result.normal_trace());
  return "";
}

int nodes_per_cell(unsigned vtk_type) {
  switch (vtk_type) {
    case 5:
      return 3;
    case 22:
      return 6;
    case 9:
      return 4;
    default:
      return 0;
  }
}

/// The element blocks of a FieldsReply; returns the element count (or -1 with `problems`).
long cell_block_problems(const protocol::FieldsReply& fields, long node_count,
                         std::vector<std::string>& problems) {
  const int blocks = fields.cell_types_size();
  if (blocks == 0) problems.push_back("cell_types is empty");
  if (fields.cell_offsets_size() != blocks + 1) {
    problems.push_back("cell_offsets has " + std::to_string(fields.cell_offsets_size()) +
                       " values for " + std::to_string(blocks) + " blocks, expected blocks + 1");
    return -1;
  }
  if (fields.cell_offsets(0) != 0 ||
      fields.cell_offsets(blocks) != static_cast<std::uint64_t>(fields.connectivity_size())) {
    problems.push_back("cell_offsets must start at 0 and end at the connectivity's length");
    return -1;
  }
  long cells = 0;
  for (int b = 0; b < blocks; ++b) {
    const int per_cell = nodes_per_cell(fields.cell_types(b));
    const auto length =
        static_cast<long>(fields.cell_offsets(b + 1)) - static_cast<long>(fields.cell_offsets(b));
    if (per_cell == 0)
      problems.push_back("cell type " + std::to_string(fields.cell_types(b)) +
                         " is not 5, 22 or 9");
    if (per_cell == 0 || length < 0 || length % per_cell != 0) return -1;
    cells += length / per_cell;
  }
  for (const std::int64_t index : fields.connectivity()) {
    if (index < 0 || index >= node_count) {
      problems.push_back("connectivity index " + std::to_string(index) + " is not in [0, " +
                         std::to_string(node_count) + ")");
      return -1;
    }
  }
  return cells;
}

void field_size_problems(const google::protobuf::RepeatedPtrField<protocol::Field>& fields,
                         long count, const std::string& kind, std::vector<std::string>& problems) {
  for (const protocol::Field& field : fields) {
    const long expected = count * static_cast<long>(field.components());
    if (field.components() == 0 || field.values_size() != expected) {
      problems.push_back(kind + " '" + field.name() + "' has " +
                         std::to_string(field.values_size()) + " values and " +
                         std::to_string(field.components()) + " components for " +
                         std::to_string(count) + " " + (kind == "point field" ? "nodes" : "cells"));
    }
  }
}

std::vector<std::string> fields_structure_problems(const protocol::FieldsReply& fields) {
  std::vector<std::string> problems;
  const long node_count = fields.node_coordinates_size() / 2;
  if (fields.node_coordinates_size() % 2 != 0 || node_count < 3) {
    problems.push_back("node_coordinates has " + std::to_string(fields.node_coordinates_size()) +
                       " values, expected (x, y) of every mesh node");
    return problems;
  }
  if (fields.node_tags_size() != 0 && fields.node_tags_size() != node_count) {
    problems.push_back("node_tags has " + std::to_string(fields.node_tags_size()) + " values for " +
                       std::to_string(node_count) + " nodes (or give none)");
  }
  const long cells = cell_block_problems(fields, node_count, problems);
  field_size_problems(fields.point_fields(), node_count, "point field", problems);
  if (cells >= 0) field_size_problems(fields.cell_fields(), cells, "cell field", problems);
  if (fields.reaction_resultant_size() % 2 != 0 || fields.reaction_resultant_size() > 2 ||
      fields.applied_force_size() % 2 != 0 || fields.applied_force_size() > 2) {
    problems.push_back("reaction_resultant and applied_force must have 2 values or none");
  }
  return problems;
}

Eigen::Vector2d resultant(const google::protobuf::RepeatedField<double>& values) {
  return values.size() == 2 ? Eigen::Vector2d(values[0], values[1]) : Eigen::Vector2d::Zero();
}

// --- The checks -------------------------------------------------------------------------------

class ServerChecks {
 public:
  explicit ServerChecks(Session& session)
      : session_(session), tolerance_(session.options().tolerance) {}

  void run_all() {
    run_envelope_checks();
    run_state_checks();
    run_setup_checks();
    run_assignment_checks();
    run_solve_checks();
    run_run_control_checks();
    session_.run("oversized_message", [this] { return oversized_message(); });
    if (session_.options().include_shutdown) {
      session_.run("shutdown", [this] { return shutdown(); });
    }
    session_.record("request_id_echoed", session_.request_id_problems());
    session_.record("version_on_every_reply", session_.version_problems());
  }

 private:
  void run_envelope_checks();
  void run_state_checks();
  void run_setup_checks();
  void run_assignment_checks();
  void run_solve_checks();
  void run_run_control_checks();

  std::string hello();
  std::string version_mismatch();
  std::string raw_error(const std::vector<std::string>& frames, const std::string& what,
                        std::optional<std::uint64_t> expected_id, protocol::ErrorCode code);
  std::string refused(Envelope request, const std::string& what,
                      const std::vector<protocol::ErrorCode>& codes, const std::string& state,
                      bool stamp_version = true);
  std::string setup_body();
  std::string assign_contact();
  std::string contact_solve_free();
  std::string contact_solve_signorini();
  std::string contact_solve_equilibrium();
  std::string correction_linearity();
  std::string correction_symmetry();
  std::string fields_structure();
  std::string fields_equilibrium();
  std::string fields_pair_order();
  std::string end_run();
  std::string second_run();
  std::string setup_body_in_ready_state();
  std::string oversized_message();
  std::string shutdown();
  std::string still_answers(const std::string& after);

  const std::vector<ContactNode>& require_interface() const;
  void require_assignment() const;
  const ContactSolution& require_partial_solution() const;
  Eigen::VectorXd obstacle_of(const std::vector<ContactNode>& nodes, bool partial) const;
  std::string correction(const Eigen::VectorXd& force, const std::string& what,
                         Eigen::VectorXd& trace);
  std::string solve_partial(const std::string& what, ContactSolution& solution);
  long contact_count() const { return static_cast<long>(nodes_.size()); }

  Session& session_;
  double tolerance_;
  std::vector<ContactNode> nodes_;  // the contact nodes in pair order, after a SetupBody
  bool assigned_ = false;
  std::optional<ContactSolution> partial_;  // the partial-contact solution
  Eigen::VectorXd first_force_;             // r1 of 'correction_linearity'
  Eigen::VectorXd first_response_;          // its reply w(r1)
};

const std::vector<ContactNode>& ServerChecks::require_interface() const {
  if (nodes_.empty()) {
    throw NotChecked("needs the contact boundary of a successful SetupBody (see 'setup_body')");
  }
  return nodes_;
}

void ServerChecks::require_assignment() const {
  require_interface();
  if (!assigned_) throw NotChecked("needs an accepted AssignContact (see 'assign_contact')");
}

const ContactSolution& ServerChecks::require_partial_solution() const {
  require_assignment();
  if (!partial_) {
    throw NotChecked("needs the partial-contact solution (see 'contact_solve_signorini')");
  }
  return *partial_;
}

Eigen::VectorXd ServerChecks::obstacle_of(const std::vector<ContactNode>& nodes,
                                          bool partial) const {
  Eigen::VectorXd obstacle(static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    obstacle(static_cast<Eigen::Index>(i)) = partial ? partial_obstacle(nodes[i].x) : far_obstacle;
  }
  return obstacle;
}

// Envelope-level checks: handshake, versions, malformed and unknown messages.

void ServerChecks::run_envelope_checks() {
  session_.run("hello", [this] { return hello(); });
  session_.run("end_run_before_checks", [this] {
    return in_context("EndRun", expect_acknowledge(session_.request(end_run_request(), "EndRun"),
                                                   "awaiting_setup"));
  });
  session_.run("version_mismatch", [this] { return version_mismatch(); });
  session_.run("version_checked_before_state", [this] {
    Envelope request = contact_solve_request(Eigen::VectorXd::Zero(1));
    request.mutable_version()->set_major(protocol::protocol_major + 1);
    return refused(request, "ContactSolveRequest with another major version before SetupBody",
                   {protocol::VERSION_MISMATCH}, "awaiting_setup", false);
  });
  session_.run("missing_version", [this] {
    return refused(hello_request(), "a Hello without version", {protocol::MALFORMED_MESSAGE},
                   "awaiting_setup", false);
  });
  session_.run("garbage_bytes", [this] {
    return raw_error({std::string("\xff\xff\xff", 3)}, "the bytes ff ff ff", 0,
                     protocol::MALFORMED_MESSAGE);
  });
  session_.run("empty_envelope", [this] {
    return refused(Envelope(), "an Envelope without content", {protocol::MALFORMED_MESSAGE},
                   "awaiting_setup");
  });
  session_.run("several_frames", [this] {
    const std::string hello_bytes = hello_request().SerializeAsString();
    return raw_error({hello_bytes, hello_bytes}, "a message of two frames", std::nullopt,
                     protocol::MALFORMED_MESSAGE);
  });
  session_.run("reply_as_request", [this] {
    Envelope request;
    request.mutable_acknowledge()->set_state("ready");
    return refused(request, "an Acknowledge sent as a request", {protocol::UNSUPPORTED},
                   "awaiting_setup");
  });
  session_.run("unknown_request_type", [this] {
    Envelope envelope;  // version and id, then field 30 (length-delimited, empty): a request
    envelope.mutable_version()->set_major(protocol::protocol_major);  // type of a later minor
    envelope.mutable_version()->set_minor(protocol::protocol_minor);
    envelope.set_request_id(session_.next_request_id());
    return raw_error({envelope.SerializeAsString() + std::string("\xf2\x01\x00", 3)},
                     "a request of an unknown type (Envelope field 30)", envelope.request_id(),
                     protocol::UNSUPPORTED);
  });
}

std::string ServerChecks::hello() {
  const Exchange exchange = session_.request(hello_request(), "Hello");
  if (const std::string problem = expect_content(exchange, Envelope::kHelloReply);
      !problem.empty()) {
    return "Hello: " + problem;
  }
  const protocol::HelloReply& reply = exchange.reply->hello_reply();
  session_.report().server_name = reply.server_name();
  std::vector<std::string> problems;
  if (reply.server_name().empty()) problems.push_back("HelloReply.server_name is empty");
  const std::vector<std::string> offered(reply.capabilities().begin(), reply.capabilities().end());
  for (const std::string& capability : core_capabilities) {
    if (std::find(offered.begin(), offered.end(), capability) == offered.end()) {
      problems.push_back("HelloReply.capabilities lacks the core '" + capability +
                         "' (it offers: " + join(offered, ", ") + ")");
    }
  }
  if (std::find(state_names.begin(), state_names.end(), reply.state()) == state_names.end()) {
    problems.push_back("HelloReply.state '" + reply.state() + "' is not a state name (" +
                       join(state_names, ", ") + ")");
  }
  return summarize(problems);
}

std::string ServerChecks::version_mismatch() {
  Envelope request = hello_request();
  request.mutable_version()->set_major(protocol::protocol_major + 1);
  request.mutable_version()->set_minor(0);
  const std::string problem =
      refused(request, "Hello with version " + std::to_string(protocol::protocol_major + 1) + ".0",
              {protocol::VERSION_MISMATCH}, "awaiting_setup", false);
  if (!problem.empty()) return problem;
  return still_answers("the VERSION_MISMATCH reply");
}

/// The server answers a Hello on the same connection with a HelloReply.
std::string ServerChecks::still_answers(const std::string& after) {
  const Exchange exchange = session_.request(hello_request(), "Hello after " + after);
  return in_context("the Hello after " + after, expect_content(exchange, Envelope::kHelloReply));
}

std::string ServerChecks::raw_error(const std::vector<std::string>& frames, const std::string& what,
                                    std::optional<std::uint64_t> expected_id,
                                    protocol::ErrorCode code) {
  const Exchange exchange = session_.send_raw(frames, what, expected_id);
  const std::string problem = expect_error(exchange, {code}, "awaiting_setup");
  if (!problem.empty()) return what + ": " + problem;
  if (expected_id && exchange.reply->request_id() != *expected_id) {
    return what + ": the reply carries request_id " + std::to_string(exchange.reply->request_id()) +
           ", expected " + std::to_string(*expected_id) +
           (*expected_id == 0 ? " (the id of an unparsable request is unknown)" : "");
  }
  return still_answers(what);
}

std::string ServerChecks::refused(Envelope request, const std::string& what,
                                  const std::vector<protocol::ErrorCode>& codes,
                                  const std::string& state, bool stamp_version) {
  return in_context(
      what, expect_error(session_.request(std::move(request), what, stamp_version), codes, state));
}

// Requests out of order, and refused bodies.

void ServerChecks::run_state_checks() {
  const auto wrong_state = [this](Envelope request, const std::string& what) {
    return refused(std::move(request), what + " before SetupBody", {protocol::WRONG_STATE},
                   "awaiting_setup");
  };
  session_.run("assign_contact_before_setup", [wrong_state] {
    return wrong_state(assign_request({{0, 0.0}}), "AssignContact");
  });
  session_.run("contact_solve_before_setup", [wrong_state] {
    return wrong_state(contact_solve_request(Eigen::VectorXd::Zero(1)), "ContactSolveRequest");
  });
  session_.run("correction_before_setup", [wrong_state] {
    return wrong_state(correction_request(Eigen::VectorXd::Zero(1)), "CorrectionRequest");
  });
  session_.run("fields_before_setup", [wrong_state] {
    return wrong_state(fields_request(Eigen::VectorXd::Zero(1)), "FieldsRequest");
  });
}

void ServerChecks::run_setup_checks() {
  const std::vector<protocol::ErrorCode> bad_input = {protocol::BAD_INPUT,
                                                      protocol::INVALID_ARGUMENT};
  const auto bad_setup = [this](const protocol::SetupBody& body, const std::string& what,
                                const std::vector<protocol::ErrorCode>& codes) {
    return refused(setup_request(body), "SetupBody with " + what, codes, "awaiting_setup");
  };
  session_.run("setup_unknown_boundary", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.set_contact_boundary("no_such_curve");
    return bad_setup(body, "the unknown contact boundary 'no_such_curve'", bad_input);
  });
  session_.run("setup_poisson_ratio_half", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.set_poisson_ratio(0.5);
    return bad_setup(body, "Poisson's ratio 0.5", bad_input);
  });
  session_.run("setup_four_voigt_values", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.clear_young_modulus();
    body.clear_poisson_ratio();
    for (const double value : {1000.0, 300.0, 300.0, 1000.0}) body.add_voigt(value);
    return bad_setup(body, "4 voigt values", bad_input);
  });
  session_.run("setup_floating_body", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.clear_dirichlet();
    return bad_setup(body, "no Dirichlet condition (a floating body)", {protocol::SINGULAR_BODY});
  });
  session_.run("setup_body", [this] { return setup_body(); });
}

std::string ServerChecks::setup_body() {
  const Exchange exchange = session_.request(setup_request(square_body()), "SetupBody");
  if (const std::string problem = expect_content(exchange, Envelope::kInterface);
      !problem.empty()) {
    return "SetupBody of the unit square: " + problem;
  }
  const protocol::InterfaceDescription& description = exchange.reply->interface();
  const std::string what = "InterfaceDescription of the unit square's top edge: ";
  if (const std::string problem = interface_size_problems(description); !problem.empty()) {
    return what + problem;
  }
  std::vector<std::string> problems = interface_node_problems(description, tolerance_);
  const std::vector<std::string> weights = interface_weight_problems(description, tolerance_);
  problems.insert(problems.end(), weights.begin(), weights.end());
  if (description.body_name() != body_name) {
    problems.push_back("body_name is '" + description.body_name() + "', expected the echo '" +
                       body_name + "'");
  }
  if (!problems.empty()) return what + summarize(problems);
  nodes_ = pair_order(description);
  return "";
}

// AssignContact: refusals, then the assignment.

void ServerChecks::run_assignment_checks() {
  session_.run("contact_solve_before_assignment", [this] {
    return refused(contact_solve_request(obstacle_of(require_interface(), false)),
                   "ContactSolveRequest before AssignContact", {protocol::WRONG_STATE},
                   "awaiting_assignment");
  });
  const auto invalid = [this](Envelope request, const std::string& what) {
    return refused(std::move(request), "AssignContact with " + what, {protocol::INVALID_ARGUMENT},
                   "awaiting_assignment");
  };
  session_.run("assign_unknown_node", [this, invalid] {
    std::vector<ContactNode> nodes = require_interface();
    std::int64_t unknown = 0;
    for (const ContactNode& node : nodes) unknown = std::max(unknown, node.id + 1);
    nodes.front().id = unknown;
    return invalid(assign_request(nodes), "the unknown node id " + std::to_string(unknown));
  });
  session_.run("assign_wrong_normal_count", [this, invalid] {
    Envelope request = assign_request(require_interface());
    request.mutable_assign_contact()->mutable_normals()->RemoveLast();
    return invalid(request, "2n - 1 normal values for n nodes");
  });
  session_.run("assign_non_unit_normals", [this, invalid] {
    return invalid(assign_request(require_interface(), 1.5), "normals of length 1.5");
  });
  session_.run("assign_repeated_node", [this, invalid] {
    std::vector<ContactNode> nodes = require_interface();
    nodes[1].id = nodes[0].id;
    return invalid(assign_request(nodes), "a node id given twice");
  });
  session_.run("assign_contact", [this] { return assign_contact(); });
  session_.run("hello_reports_state", [this] {
    require_assignment();
    const Exchange exchange = session_.request(hello_request(), "Hello in state ready");
    std::string problem = expect_content(exchange, Envelope::kHelloReply);
    if (problem.empty() && exchange.reply->hello_reply().state() != "ready") {
      problem = "HelloReply.state is '" + exchange.reply->hello_reply().state() +
                "', expected 'ready' (after an accepted AssignContact)";
    }
    return in_context("Hello in state ready", problem);
  });
}

std::string ServerChecks::assign_contact() {
  const Exchange exchange = session_.request(assign_request(require_interface()), "AssignContact");
  const std::string problem = expect_acknowledge(exchange, "ready");
  assigned_ = problem.empty();
  return in_context("AssignContact of every top-edge node in pair order", problem);
}

// Solves: wrong lengths, the free and the partial contact, the correction operator, fields.

void ServerChecks::run_solve_checks() {
  const auto wrong_length = [this](Envelope request, const std::string& what) {
    return refused(std::move(request), what, {protocol::INVALID_ARGUMENT}, "ready");
  };
  session_.run("contact_solve_wrong_length", [this, wrong_length] {
    require_assignment();
    return wrong_length(contact_solve_request(Eigen::VectorXd::Constant(contact_count() + 1, 1.0)),
                        "ContactSolveRequest with n_c + 1 obstacle values");
  });
  session_.run("correction_wrong_length", [this, wrong_length] {
    require_assignment();
    return wrong_length(correction_request(Eigen::VectorXd::Ones(contact_count() - 1)),
                        "CorrectionRequest with n_c - 1 interface_force values");
  });
  session_.run("fields_wrong_length", [this, wrong_length] {
    require_assignment();
    return wrong_length(fields_request(Eigen::VectorXd::Zero(contact_count() + 1)),
                        "FieldsRequest with n_c + 1 contact_force values");
  });
  session_.run("contact_solve_free", [this] { return contact_solve_free(); });
  session_.run("contact_solve_signorini", [this] { return contact_solve_signorini(); });
  session_.run("contact_solve_equilibrium", [this] { return contact_solve_equilibrium(); });
  session_.run("correction_linearity", [this] { return correction_linearity(); });
  session_.run("correction_symmetry", [this] { return correction_symmetry(); });
  session_.run("fields_structure", [this] { return fields_structure(); });
  session_.run("fields_equilibrium", [this] { return fields_equilibrium(); });
  session_.run("fields_pair_order", [this] { return fields_pair_order(); });
}

std::string ServerChecks::contact_solve_free() {
  require_assignment();
  const std::string what = "ContactSolveRequest with every obstacle far (g = 1)";
  ContactSolution solution;
  const Exchange exchange =
      session_.request(contact_solve_request(obstacle_of(nodes_, false)), what);
  if (const std::string problem = read_contact_solution(exchange, contact_count(), solution);
      !problem.empty()) {
    return what + ": " + problem;
  }
  std::vector<std::string> problems;
  for (long i = 0; i < contact_count(); ++i) {
    if (std::abs(solution.contact_force(i)) > tolerance_ * force_reference) {
      problems.push_back("contact_force[" + std::to_string(i) +
                         "] = " + number(solution.contact_force(i)) + ", expected 0 (no contact)");
    }
    if (std::abs(solution.normal_trace(i) - lift) > tolerance_ * lift) {
      problems.push_back("normal_trace[" + std::to_string(i) +
                         "] = " + number(solution.normal_trace(i)) + ", expected " + number(lift) +
                         " (the body translates rigidly with its lifted bottom edge)");
    }
  }
  return problems.empty() ? "" : what + ": " + summarize(problems);
}

std::string ServerChecks::solve_partial(const std::string& what, ContactSolution& solution) {
  const Exchange exchange =
      session_.request(contact_solve_request(obstacle_of(nodes_, true), 2), what);
  if (const std::string problem = read_contact_solution(exchange, contact_count(), solution);
      !problem.empty()) {
    return problem;
  }
  return summarize(signorini_problems(solution, obstacle_of(nodes_, true), tolerance_));
}

std::string ServerChecks::contact_solve_signorini() {
  require_assignment();
  const std::string what = "ContactSolveRequest with g = lift (0.5 + x)";
  ContactSolution solution;
  const std::string problem = solve_partial(what, solution);
  if (problem.empty()) partial_ = solution;
  return in_context(what, problem);
}

std::string ServerChecks::correction(const Eigen::VectorXd& force, const std::string& what,
                                     Eigen::VectorXd& trace) {
  return in_context(what, read_correction(session_.request(correction_request(force), what),
                                          contact_count(), trace));
}

/// K u = f - B' lambda, seen on the wire: u_N = e - F lambda with e = lift (the free trace)
/// and F lambda the CorrectionResult for r = lambda.
std::string ServerChecks::contact_solve_equilibrium() {
  const ContactSolution& solution = require_partial_solution();
  Eigen::VectorXd response;
  if (const std::string problem =
          correction(solution.contact_force, "CorrectionRequest with r = lambda", response);
      !problem.empty()) {
    return problem;
  }
  const Eigen::VectorXd expected = Eigen::VectorXd::Constant(contact_count(), lift) - response;
  const double difference = (solution.normal_trace - expected).cwiseAbs().maxCoeff();
  if (difference <= tolerance_ * lift) return "";
  return "the partial-contact solution violates u_N = e - F lambda (e = lift, F lambda the "
         "CorrectionResult for r = lambda): max difference " +
         number(difference) + " (length) > " + number(tolerance_ * lift);
}

std::string ServerChecks::correction_linearity() {
  require_assignment();
  Eigen::VectorXd force(contact_count());
  for (long i = 0; i < contact_count(); ++i) force(i) = 1.0 + 0.5 * static_cast<double>(i);
  Eigen::VectorXd single, twice;
  std::string problem = correction(force, "CorrectionRequest with r", single);
  if (problem.empty()) problem = correction(2.0 * force, "CorrectionRequest with 2 r", twice);
  if (!problem.empty()) return problem;
  first_force_ = force;
  first_response_ = single;
  const double difference = (twice - 2.0 * single).cwiseAbs().maxCoeff();
  const double scale = twice.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return "w(r) = 0 for r != 0: the correction ignores its interface_force";
  if (difference > tolerance_ * scale) {
    return "w(2 r) != 2 w(r): max difference " + number(difference) + " for max |w(2 r)| " +
           number(scale) + " (the correction problem is linear)";
  }
  return "";
}

/// F = B K^-1 B' is symmetric positive definite: r1' F r2 = r2' F r1 and r' F r > 0.
std::string ServerChecks::correction_symmetry() {
  if (first_force_.size() == 0) {
    require_assignment();
    throw NotChecked("needs w(r) from 'correction_linearity'");
  }
  Eigen::VectorXd force(contact_count());
  for (long i = 0; i < contact_count(); ++i) force(i) = std::cos(1.3 * i) + 0.2;
  Eigen::VectorXd response;
  if (const std::string problem = correction(force, "CorrectionRequest with r2", response);
      !problem.empty()) {
    return problem;
  }
  const Eigen::VectorXd& force1 = first_force_;
  const Eigen::VectorXd& response1 = first_response_;
  const double forward = force1.dot(response), backward = force.dot(response1);
  const double scale = force1.norm() * response.norm() + force.norm() * response1.norm();
  if (std::abs(forward - backward) > tolerance_ * scale) {
    return "r1' w(r2) = " + number(forward) + " differs from r2' w(r1) = " + number(backward) +
           ": the correction operator F is not symmetric";
  }
  if (!(force1.dot(response1) > 0.0) || !(force.dot(response) > 0.0)) {
    return "r' w(r) = " + number(force1.dot(response1)) + " and " + number(force.dot(response)) +
           ": the correction operator F is not positive definite (sign of B' r?)";
  }
  return "";
}

/// The fields for lambda = 0: the mesh structure, and the rigid translation u = (0, lift).
std::string ServerChecks::fields_structure() {
  require_assignment();
  const std::string what = "FieldsRequest with lambda = 0";
  const Exchange exchange =
      session_.request(fields_request(Eigen::VectorXd::Zero(contact_count())), what);
  if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
      !problem.empty()) {
    return what + ": " + problem;
  }
  const protocol::FieldsReply& fields = exchange.reply->fields_reply();
  std::vector<std::string> problems = fields_structure_problems(fields);
  for (const protocol::Field& field : fields.point_fields()) {
    if (field.name() != "displacement" || field.components() != 2 || !problems.empty()) continue;
    for (int k = 0; k + 1 < field.values_size(); k += 2) {
      if (std::abs(field.values(k)) > tolerance_ * lift ||
          std::abs(field.values(k + 1) - lift) > tolerance_ * lift) {
        problems.push_back("the displacement of node " + std::to_string(k / 2) + " is (" +
                           number(field.values(k)) + ", " + number(field.values(k + 1)) +
                           "), expected the rigid translation (0, " + number(lift) + ")");
        break;
      }
    }
  }
  return problems.empty() ? "" : what + ": " + summarize(problems);
}

/// reaction_resultant + applied_force + sum_i (-lambda_i n_i) = 0 for the partial contact.
std::string ServerChecks::fields_equilibrium() {
  const ContactSolution& solution = require_partial_solution();
  const std::string what = "FieldsRequest with the partial-contact lambda";
  const Exchange exchange = session_.request(fields_request(solution.contact_force), what);
  if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
      !problem.empty()) {
    return what + ": " + problem;
  }
  const protocol::FieldsReply& fields = exchange.reply->fields_reply();
  const double total = solution.contact_force.sum();  // every n_i = (0, 1)
  const Eigen::Vector2d balance = resultant(fields.reaction_resultant()) +
                                  resultant(fields.applied_force()) - Eigen::Vector2d(0.0, total);
  if (balance.norm() <= tolerance_ * std::max(std::abs(total), 1e-300)) return "";
  return what + ": reaction_resultant + applied_force - sum lambda_i n_i = (" +
         number(balance.x()) + ", " + number(balance.y()) +
         "), expected 0 (sum lambda_i = " + number(total) + ")";
}

/// The abscissa of the top-edge node (y = 1) that a FieldsReply's displacement moves down
/// most; a problem when the reply has no usable displacement field.
std::string most_pushed_top_node(const protocol::FieldsReply& fields, double tolerance,
                                 double& abscissa) {
  const protocol::Field* displacement = nullptr;
  for (const protocol::Field& field : fields.point_fields()) {
    if (field.name() == "displacement") displacement = &field;
  }
  const int node_count = fields.node_coordinates_size() / 2;
  if (displacement == nullptr || displacement->components() != 2 ||
      displacement->values_size() != 2 * node_count) {
    throw NotChecked("needs the FieldsReply point field 'displacement' (2 components per node)");
  }
  double lowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < node_count; ++k) {
    const double y = fields.node_coordinates(2 * k + 1);
    if (std::abs(y - 1.0) > tolerance || !(displacement->values(2 * k + 1) < lowest)) continue;
    lowest = displacement->values(2 * k + 1);
    abscissa = fields.node_coordinates(2 * k);
  }
  return std::isfinite(lowest) ? "" : "the FieldsReply has no node on the top edge y = 1";
}

/// The pair order, seen through positions: a unit contact force at pair index k must push the
/// node at (x_k, 1) down most. (On this mesh F = B K^-1 B' is diagonally dominant by columns,
/// by 26 % or more.) Answers indexed by the pair order cannot show a server that uses its own
/// order instead: they are consistently relabelled. The FieldsReply's coordinates can.
std::string ServerChecks::fields_pair_order() {
  require_assignment();
  for (long k = 0; k < contact_count(); ++k) {
    Eigen::VectorXd force = Eigen::VectorXd::Zero(contact_count());
    force(k) = 1.0;
    const std::string what = "FieldsRequest with a unit contact_force at pair index " +
                             std::to_string(k) + " (node id " + std::to_string(nodes_[k].id) +
                             ", x = " + number(nodes_[k].x) + ")";
    const Exchange exchange = session_.request(fields_request(force), what);
    if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
        !problem.empty()) {
      return what + ": " + problem;
    }
    double abscissa = 0.0;
    const std::string problem =
        most_pushed_top_node(exchange.reply->fields_reply(), tolerance_, abscissa);
    if (!problem.empty()) return what + ": " + problem;
    if (std::abs(abscissa - nodes_[k].x) > tolerance_) {
      return what + ": the top-edge node pushed down most is at x = " + number(abscissa) +
             ": the force was not applied in the pair order of AssignContact";
    }
  }
  return "";
}

// Run control: EndRun, a second run, SetupBody in state ready.

void ServerChecks::run_run_control_checks() {
  session_.run("end_run", [this] { return end_run(); });
  session_.run("second_run", [this] { return second_run(); });
  session_.run("setup_body_in_ready_state", [this] { return setup_body_in_ready_state(); });
  session_.run("end_run_after_checks", [this] {
    return in_context("EndRun", expect_acknowledge(session_.request(end_run_request(), "EndRun"),
                                                   "awaiting_setup"));
  });
}

std::string ServerChecks::end_run() {
  require_interface();
  const Exchange exchange = session_.request(end_run_request(), "EndRun in state ready");
  if (const std::string problem = expect_acknowledge(exchange, "awaiting_setup");
      !problem.empty()) {
    return "EndRun in state ready: " + problem;
  }
  return refused(contact_solve_request(obstacle_of(nodes_, true)),
                 "ContactSolveRequest after EndRun", {protocol::WRONG_STATE}, "awaiting_setup");
}

/// SetupBody, AssignContact and the partial-contact solve again: the same answer.
std::string ServerChecks::second_run() {
  const ContactSolution& first = require_partial_solution();
  const Exchange setup = session_.request(setup_request(square_body()), "SetupBody (second run)");
  if (const std::string problem = expect_content(setup, Envelope::kInterface); !problem.empty()) {
    return "SetupBody (second run): " + problem;
  }
  const protocol::InterfaceDescription& description = setup.reply->interface();
  if (!interface_size_problems(description).empty() ||
      description.node_ids_size() != contact_count()) {
    return "SetupBody (second run): the InterfaceDescription differs from the first run's";
  }
  std::vector<ContactNode> nodes = pair_order(description);
  std::stable_sort(nodes.begin(), nodes.end(), [this](const ContactNode& a, const ContactNode& b) {
    return (nodes_.front().x > nodes_.back().x) ? a.x > b.x : a.x < b.x;
  });
  nodes_ = nodes;  // same positions, maybe other ids
  const Exchange assign = session_.request(assign_request(nodes_), "AssignContact (second run)");
  if (const std::string problem = expect_acknowledge(assign, "ready"); !problem.empty()) {
    return "AssignContact (second run): " + problem;
  }
  ContactSolution again;
  if (const std::string problem = solve_partial("ContactSolveRequest (second run)", again);
      !problem.empty()) {
    return "ContactSolveRequest (second run): " + problem;
  }
  const double scale = std::max(first.contact_force.cwiseAbs().maxCoeff(), 1e-300);
  const double difference = (again.contact_force - first.contact_force).cwiseAbs().maxCoeff();
  if (difference > tolerance_ * scale) {
    return "the second run's contact_force differs from the first run's by " + number(difference) +
           " (max lambda " + number(scale) + ")";
  }
  return "";
}

/// SetupBody is valid in every state and discards the body: a solve is then refused.
std::string ServerChecks::setup_body_in_ready_state() {
  require_partial_solution();
  const Exchange setup = session_.request(setup_request(square_body()), "SetupBody in state ready");
  if (const std::string problem = expect_content(setup, Envelope::kInterface); !problem.empty()) {
    return "SetupBody in state ready: " + problem;
  }
  return refused(contact_solve_request(obstacle_of(nodes_, true)),
                 "ContactSolveRequest after a new SetupBody", {protocol::WRONG_STATE},
                 "awaiting_assignment");
}

// The oversized message and Shutdown.

std::string ServerChecks::oversized_message() {
  const long size = session_.options().oversized_message_bytes;
  const std::string what = "a Hello of " + std::to_string(size) + " bytes";
  std::string outcome;
  try {
    RequestChannel channel(session_.endpoint(), ChannelOptions{});
    Envelope request = hello_request();
    request.mutable_hello()->set_client_name(std::string(static_cast<std::size_t>(size), 'x'));
    const Deadline deadline = Deadline::after(session_.options().reply_timeout_seconds);
    const std::uint64_t id = channel.send(request, deadline);
    const Envelope reply = channel.receive(id, deadline);
    session_.note_reply(reply, what, id);
  } catch (const ChannelFailure& failure) {
    outcome = std::string(" (it was dropped: ") + failure.what() + ")";
  }
  session_.reconnect();  // whatever happened, go on with a new connection
  const Exchange exchange = session_.request(hello_request(), "Hello after " + what);
  if (exchange.reply && exchange.reply->has_hello_reply()) return "";
  session_.mark_spoiled();
  return "after " + what + outcome +
         ", a Hello on a new connection: " + expect_content(exchange, Envelope::kHelloReply);
}

std::string ServerChecks::shutdown() {
  Envelope request;
  request.mutable_shutdown();
  session_.reconnect(false);  // the server is there; its last reply must not be discarded
  const Exchange exchange = session_.request(request, "Shutdown");
  session_.abandon_connection();  // the server is expected to be gone: no recovery Hello
  if (const std::string problem = expect_content(exchange, Envelope::kAcknowledge);
      !problem.empty()) {
    return "Shutdown: " + problem;
  }
  const double wait = std::min(2.0, session_.options().reply_timeout_seconds);
  if (session_.answers_hello_within(wait)) {
    return "the server still answered a Hello on a new connection after its Acknowledge to "
           "Shutdown (it must stop serving and exit)";
  }
  return "";
}

}  // namespace

std::size_t ConformanceReport::failure_count() const {
  return static_cast<std::size_t>(std::count_if(
      checks.begin(), checks.end(), [](const ConformanceCheck& check) { return !check.passed; }));
}

ConformanceReport check_server(const std::string& endpoint, const ConformanceOptions& options) {
  const auto start = Clock::now();
  ConformanceReport report;
  report.endpoint = endpoint;
  Session session(endpoint, options, report);
  ServerChecks(session).run_all();
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

std::string format_report(const ConformanceReport& report) {
  std::ostringstream text;
  text << "Protocol " << protocol::protocol_major << "." << protocol::protocol_minor
       << " conformance of the server at " << report.endpoint;
  if (!report.server_name.empty()) text << " (" << report.server_name << ")";
  text << "\n";
  for (const ConformanceCheck& check : report.checks) {
    if (check.passed) {
      text << "PASS " << check.name;
      if (!check.explanation.empty()) text << " (" << check.explanation << ")";
    } else {
      text << "FAIL " << check.name << ": " << check.explanation;
    }
    text << "\n";
  }
  const std::size_t failed = report.failure_count();
  text << report.checks.size() << " checks, " << report.checks.size() - failed << " passed, "
       << failed << " failed in " << number(report.seconds) << " s: the server "
       << (report.conforms() ? "conforms" : "does not conform") << " to the protocol\n";
  return text.str();
}

bool requests_server_check(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word == "--check-server" || word.starts_with("--check-server=")) return true;
  }
  return false;
}

int server_check_main(int argc, const char* const* argv) {
  CLI::App app{
      "robin-coordinator --check-server: drives a subdomain server through every message of "
      "the protocol (docs/protocol.md) and reports each deviation"};
  std::string endpoint;
  ConformanceOptions options;
  app.add_option("--check-server", endpoint, "endpoint of the server to check")->required();
  app.add_option("--timeout", options.reply_timeout_seconds, "deadline of each request, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-message-size-probe", options.oversized_message_bytes,
                 "size of the oversized message (bytes); the server must answer it or drop it, "
                 "and then still answer a new connection")
      ->check(CLI::Range(1L, (1L << 31) - (1L << 16)))  // protobuf's limit is 2 GiB
      ->capture_default_str();
  app.add_option("--tolerance", options.tolerance, "relative tolerance of the numerical checks")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--include-shutdown", options.include_shutdown,
               "finish with a Shutdown request (the server must exit)");
  app.footer("Exit codes: 0 the server conforms, 1 it does not, 2 bad command line.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 2;
  }
  const ConformanceReport report = check_server(endpoint, options);
  std::cout << format_report(report) << std::flush;
  return report.conforms() ? 0 : 1;
}

}  // namespace robin
