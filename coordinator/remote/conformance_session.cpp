#include "remote/conformance_session.hpp"

#include <zmq.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <sstream>
#include <zmq.hpp>

#include "protocol_version.hpp"
#include "remote/request_channel.hpp"

namespace robin::conformance {

using protocol::Envelope;
using Content = protocol::Envelope::ContentCase;

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

std::string summarize(const std::vector<std::string>& problems, std::size_t limit) {
  std::vector<std::string> shown(problems.begin(),
                                 problems.begin() + std::min(limit, problems.size()));
  std::string text = join(shown, "; ");
  if (problems.size() > limit) {
    text += "; and " + std::to_string(problems.size() - limit) + " more";
  }
  return text;
}

std::string in_context(const std::string& what, const std::string& problem) {
  return problem.empty() ? problem : what + ": " + problem;
}

std::string content_name(Content content) {
  const auto* field = Envelope::GetDescriptor()->FindFieldByNumber(content);
  return field == nullptr ? "(no content)" : field->message_type()->name();
}

std::string describe(const Envelope& reply) {
  if (reply.has_error()) {
    std::string message = reply.error().message();
    if (message.size() > 160) message = message.substr(0, 157) + "...";
    return "Error{" + protocol::ErrorCode_Name(reply.error().code()) + ": " + message + "}";
  }
  if (reply.content_case() == Envelope::CONTENT_NOT_SET) return "an Envelope without content";
  return content_name(reply.content_case());
}

namespace {

std::string error_names(const std::vector<protocol::ErrorCode>& codes) {
  std::vector<std::string> names;
  for (const protocol::ErrorCode code : codes) names.push_back(protocol::ErrorCode_Name(code));
  return "Error{" + join(names, " or ") + "}";
}

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
  /// `curve`: a CurveZMQ client with these keys (unset: no transport security).
  ProbeConnection(zmq::context_t& context, const std::string& endpoint, bool immediate,
                  const std::optional<CurveClientKeys>& curve)
      : socket_(context, zmq::socket_type::dealer), curve_(curve.has_value()) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.set(zmq::sockopt::immediate, immediate ? 1 : 0);
    socket_.set(zmq::sockopt::maxmsgsize, std::int64_t{1} << 30);
    if (curve) {
      socket_.set(zmq::sockopt::curve_serverkey, curve->server_public_key);
      socket_.set(zmq::sockopt::curve_publickey, curve->client.public_key);
      socket_.set(zmq::sockopt::curve_secretkey, curve->client.secret_key);
    }
    socket_.connect(endpoint);  // throws zmq::error_t for a malformed endpoint
  }

  /// Sends the delimiter and `frames`; returns the problem, or "".
  std::string send(const std::vector<std::string>& frames, const Deadline& deadline) {
    if (!wait_for(ZMQ_POLLOUT, deadline)) {
      return "could not send within " + number(deadline.seconds) +
             " s: no connection to the server (is it running at that endpoint?" +
             (curve_ ? " with CurveZMQ: is --curve-server-key its public key, and this "
                       "client's public key on its allow-list?"
                     : "") +
             ")";
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
  bool curve_ = false;
};

}  // namespace

Envelope hello_request() {
  Envelope envelope;
  envelope.mutable_hello()->set_client_name("robin-coordinator --check-server");
  envelope.mutable_hello()->add_capabilities("fields");
  return envelope;
}

/// The ZeroMQ side of a session: its context and current connection.
struct Session::Transport {
  zmq::context_t context{1};
  std::unique_ptr<ProbeConnection> connection;
  bool immediate = true;  // for the next connection
  std::optional<CurveClientKeys> curve;

  /// Opens a connection into `connection`; returns the problem, or "".
  std::string connect(const std::string& endpoint, std::unique_ptr<ProbeConnection>& connection,
                      bool immediate) {
    try {
      connection = std::make_unique<ProbeConnection>(context, endpoint, immediate, curve);
      return "";
    } catch (const zmq::error_t& error) {
      return "cannot connect to '" + endpoint + "': " + error.what() +
             " (endpoints look like tcp://HOST:PORT or ipc:///PATH)";
    }
  }
};

Session::Session(const std::string& endpoint, const ConformanceOptions& options,
                 ConformanceReport& report)
    : endpoint_(endpoint),
      options_(options),
      report_(report),
      transport_(std::make_unique<Transport>()) {
  transport_->curve = options.curve;
}

Session::~Session() = default;

Exchange Session::request(Envelope envelope, const std::string& what, bool stamp_version) {
  if (stamp_version) {
    envelope.mutable_version()->set_major(protocol::protocol_major);
    envelope.mutable_version()->set_minor(protocol::protocol_minor);
  }
  envelope.set_request_id(next_request_id());
  return send_raw({envelope.SerializeAsString()}, what, envelope.request_id());
}

Exchange Session::send_raw(const std::vector<std::string>& frames, const std::string& what,
                           std::optional<std::uint64_t> expected_id) {
  Exchange exchange;
  std::unique_ptr<ProbeConnection>& connection = transport_->connection;
  if (!connection && !admission_checked_) exchange.problem = admission_problem();
  if (!connection && exchange.problem.empty())
    exchange.problem = transport_->connect(endpoint_, connection, transport_->immediate);
  const Deadline deadline = Deadline::after(options_.reply_timeout_seconds);
  if (exchange.problem.empty()) exchange.problem = connection->send(frames, deadline);
  ReceivedMessage received;
  if (exchange.problem.empty()) {
    received = connection->receive(deadline);
    exchange.problem = received.problem;
  }
  if (!exchange.problem.empty()) {
    spoiled_ = true;
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

void Session::run(const std::string& name, const std::function<std::string()>& check) {
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
  if (refused_ && unresponsive_.empty()) {
    unresponsive_ = "the connection was refused (see check '" + name + "')";
    spoiled_ = false;
    reconnect();
  }
  if (spoiled_) recover(name);
}

std::string Session::admission_problem() {
  admission_checked_ = true;
  const Deadline deadline = Deadline::after(options_.reply_timeout_seconds);
  try {
    ChannelOptions channel_options;
    channel_options.curve = options_.curve;
    RequestChannel channel(endpoint_, channel_options);
    Envelope hello = hello_request();
    channel.send(hello, deadline);  // returns once the handshake succeeded and Hello is queued
    return "";
  } catch (const ChannelFailure& failure) {
    refused_ = Clock::now() < deadline.at;  // not a timeout: a handshake failure or bad endpoint
    return failure.what();
  }
}

void Session::record(const std::string& name, const std::string& problem) {
  report_.checks.push_back({name, problem.empty(), problem});
}

void Session::record_note(const std::string& name, const std::string& note) {
  report_.checks.push_back({name, true, note});
}

bool Session::answers_hello_within(double seconds) {
  std::unique_ptr<ProbeConnection> probe;
  if (!transport_->connect(endpoint_, probe, true).empty()) return false;
  Envelope hello = hello_request();
  hello.mutable_version()->set_major(protocol::protocol_major);
  hello.set_request_id(next_request_id());
  const Deadline deadline = Deadline::after(seconds);
  return probe->send({hello.SerializeAsString()}, deadline).empty() &&
         probe->receive(deadline).problem.empty();
}

void Session::reconnect(bool immediate) {
  transport_->connection.reset();
  transport_->immediate = immediate;
}

void Session::abandon_connection() {
  reconnect();
  spoiled_ = false;
}

void Session::note_reply(const Envelope& reply, const std::string& what,
                         std::optional<std::uint64_t> expected_id) {
  ++reply_count_;
  const std::string type =
      reply.has_error() ? "Error{" + protocol::ErrorCode_Name(reply.error().code()) + "} reply"
      : reply.content_case() == Envelope::CONTENT_NOT_SET ? "reply without content"
                                                          : content_name(reply.content_case());
  const std::string subject = "the " + type + " to " + what;
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
  spoiled_ = false;
  if (hello.reply) return;
  unresponsive_ = "the server did not answer a Hello on a new connection after check '" +
                  after_check + "' (" + hello.problem + ")";
  reconnect();
}

std::string Session::reply_rule_problems(const std::vector<std::string>& problems) const {
  if (reply_count_ == 0) return "no reply was received, nothing to judge";
  if (problems.empty()) return "";
  return std::to_string(problems.size()) + " of " + std::to_string(reply_count_) +
         " replies: " + summarize(problems);
}

std::string expect_content(const Exchange& exchange, Content expected) {
  if (!exchange.reply) return exchange.problem;
  if (exchange.reply->content_case() == expected) return "";
  return "expected " + content_name(expected) + ", the reply was " + describe(*exchange.reply);
}

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

std::string expect_acknowledge(const Exchange& exchange, const std::string& state) {
  if (const std::string problem = expect_content(exchange, Envelope::kAcknowledge);
      !problem.empty()) {
    return problem;
  }
  const std::string& actual = exchange.reply->acknowledge().state();
  return actual == state ? "" : "Acknowledge.state is '" + actual + "', expected '" + state + "'";
}

}  // namespace robin::conformance
