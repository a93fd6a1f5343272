#include "remote/request_channel.hpp"

#include <zmq.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <thread>
#include <zmq.hpp>

#include "protocol_version.hpp"
#include "robin.pb.h"

namespace robin {

namespace {

constexpr auto wait_slice = std::chrono::milliseconds(100);
constexpr int send_backstop_milliseconds = 1000;
constexpr auto lost_connection_grace = std::chrono::milliseconds(500);

std::string format_seconds(double seconds) {
  std::ostringstream text;
  text << seconds;
  return text.str();
}

/// `bytes` in MiB with three significant digits.
std::string format_mebibytes(std::size_t bytes) {
  std::ostringstream text;
  text.precision(3);
  text << static_cast<double>(bytes) / 1048576.0;
  return text.str();
}

/// "not on its allow-list" style explanation of a ZAP status code (RFC 27).
std::string zap_status_meaning(std::uint32_t status_code) {
  switch (status_code) {
    case 300:
      return "a temporary error in the server's authentication";
    case 400:
      return "the server does not admit this client";
    case 500:
      return "an internal error in the server's authentication";
    default:
      return "status " + std::to_string(status_code);
  }
}

std::string next_monitor_address() {
  static std::atomic<unsigned long> counter{0};
  return "inproc://robin-channel-monitor-" + std::to_string(counter++);
}

}  // namespace

Deadline Deadline::after(double seconds) {
  constexpr double longest = 1e9;  // about 30 years: keeps the clock arithmetic finite
  const auto duration = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(std::clamp(seconds, 0.0, longest)));
  return {Clock::now() + duration, seconds};
}

struct RequestChannel::Sockets {
  zmq::context_t context{1};
  zmq::socket_t dealer{context, zmq::socket_type::dealer};
  zmq::socket_t monitor{context, zmq::socket_type::pair};
};

RequestChannel::RequestChannel(const std::string& endpoint, ChannelOptions options)
    : sockets_(std::make_unique<Sockets>()), options_(std::move(options)) {
  zmq::socket_t& dealer = sockets_->dealer;
  dealer.set(zmq::sockopt::linger, 0);
  dealer.set(zmq::sockopt::immediate, options_.immediate ? 1 : 0);
  dealer.set(zmq::sockopt::sndtimeo, send_backstop_milliseconds);
  dealer.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(options_.max_message_bytes));
  dealer.set(zmq::sockopt::heartbeat_ivl, options_.heartbeat_interval_milliseconds);
  dealer.set(zmq::sockopt::heartbeat_timeout, options_.heartbeat_timeout_milliseconds);
  dealer.set(zmq::sockopt::heartbeat_ttl, 2 * options_.heartbeat_timeout_milliseconds);
  if (options_.curve) {
    if (!curve_available()) {
      throw ChannelFailure("this libzmq is built without CURVE (zmq_has(\"curve\") is false)");
    }
    dealer.set(zmq::sockopt::curve_serverkey, options_.curve->server_public_key);
    dealer.set(zmq::sockopt::curve_publickey, options_.curve->client.public_key);
    dealer.set(zmq::sockopt::curve_secretkey, options_.curve->client.secret_key);
  }
  const std::string monitor_address = next_monitor_address();
  constexpr int monitored_events = ZMQ_EVENT_CONNECTED | ZMQ_EVENT_HANDSHAKE_SUCCEEDED |
                                   ZMQ_EVENT_DISCONNECTED | ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL |
                                   ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                                   ZMQ_EVENT_HANDSHAKE_FAILED_AUTH;
  if (zmq_socket_monitor(dealer.handle(), monitor_address.c_str(), monitored_events) != 0) {
    throw ChannelFailure(std::string("cannot monitor the connection: ") + zmq_strerror(errno));
  }
  sockets_->monitor.set(zmq::sockopt::linger, 0);
  sockets_->monitor.connect(monitor_address);
  try {
    dealer.connect(endpoint);
  } catch (const zmq::error_t& error) {
    throw ChannelFailure("cannot connect to '" + endpoint + "': " + error.what() +
                         " (endpoints look like tcp://HOST:PORT or ipc:///PATH)");
  }
}

RequestChannel::~RequestChannel() {
  zmq_socket_monitor(sockets_->dealer.handle(), nullptr, 0);
}

std::uint64_t RequestChannel::send(protocol::Envelope& envelope, const Deadline& deadline) {
  check_connection();
  envelope.mutable_version()->set_major(protocol::protocol_major);
  envelope.mutable_version()->set_minor(protocol::protocol_minor);
  envelope.set_request_id(next_request_id_++);
  const std::string payload = envelope.SerializeAsString();
  wait_for(ZMQ_POLLOUT, deadline,
           "could not send within " + format_seconds(deadline.seconds) +
               " s: no connection to the server (is it running at that endpoint? a peer that "
               "accepts the TCP connection but never completes the ZeroMQ handshake looks the "
               "same)");
  zmq::socket_t& dealer = sockets_->dealer;
  const bool sent = dealer.send(zmq::message_t(), zmq::send_flags::sndmore) &&
                    dealer.send(zmq::buffer(payload), zmq::send_flags::none);
  if (!sent) throw ChannelFailure("the request could not be queued for sending");
  bytes_sent_ += static_cast<long>(payload.size());
  unanswered_request_bytes_ = payload.size();
  return envelope.request_id();
}

protocol::Envelope RequestChannel::receive(std::uint64_t request_id, const Deadline& deadline) {
  std::string timeout_problem = "no reply within " + format_seconds(deadline.seconds) + " s";
  for (int discarded = 0;; ++discarded) {
    if (discarded > 0) {  // a server that does not echo request_id looks silent otherwise
      timeout_problem = "no reply within " + format_seconds(deadline.seconds) + " s (" +
                        std::to_string(discarded) +
                        " replies with another request_id were discarded: late replies to "
                        "abandoned requests, or a server that does not echo request_id)";
    }
    wait_for(ZMQ_POLLIN, deadline, timeout_problem);
    protocol::Envelope reply = read_reply();
    if (reply.request_id() == request_id) {
      unanswered_request_bytes_ = 0;
      return reply;
    }
    // A late reply to an abandoned request: discard it (counted) and keep waiting.
  }
}

std::optional<protocol::Envelope> RequestChannel::try_receive(std::uint64_t request_id) {
  while (poll_dealer(ZMQ_POLLIN, std::chrono::milliseconds(0))) {
    protocol::Envelope reply = read_reply();
    if (reply.request_id() == request_id) {
      unanswered_request_bytes_ = 0;
      return reply;
    }
  }
  check_connection();
  return std::nullopt;
}

protocol::Envelope RequestChannel::read_reply() {
  std::vector<zmq::message_t> frames;
  do {
    frames.emplace_back();
    if (!sockets_->dealer.recv(frames.back(), zmq::recv_flags::dontwait)) {
      throw ChannelFailure("a reply was announced but could not be read");
    }
  } while (frames.back().more());
  for (const zmq::message_t& frame : frames) bytes_received_ += static_cast<long>(frame.size());
  protocol::Envelope reply;
  if (frames.size() != 2 || frames[0].size() != 0 ||
      !reply.ParseFromArray(frames[1].data(), static_cast<int>(frames[1].size()))) {
    throw ChannelFailure(
        "the reply is not a protocol message (expected an empty delimiter "
        "frame and one serialized Envelope); is this a robin-subdomain server?");
  }
  return reply;
}

bool RequestChannel::connection_lost() {
  read_monitor_events();
  return lost_;
}

void RequestChannel::check_connection() {
  const std::string reason = server_failure_reason();
  if (!reason.empty()) throw ChannelFailure(reason);
  const bool lost = connection_lost();
  if (!handshake_failure_.empty()) throw ChannelFailure(handshake_failure_);
  if (!lost) return;
  // The process behind a lost connection is usually exiting: give its fate a moment to show.
  const auto give_up = Clock::now() + lost_connection_grace;
  for (std::string late_reason; Clock::now() < give_up;
       std::this_thread::sleep_for(std::chrono::milliseconds(10))) {
    late_reason = server_failure_reason();
    if (!late_reason.empty()) {
      throw ChannelFailure("the connection to the server was lost: " + late_reason);
    }
    if (!hooks_enabled_ || !options_.server_failure) break;
  }
  const bool server_watched = hooks_enabled_ && options_.server_failure;
  throw ChannelFailure(lost_connection_message(server_watched));
}

std::string RequestChannel::lost_connection_message(bool server_still_running) const {
  const std::string lost = "the connection to the server was lost";
  if (unanswered_request_bytes_ == 0) return lost + " (the server stopped or crashed)";
  const std::string request = "the request of " + std::to_string(unanswered_request_bytes_) +
                              " bytes (" + format_mebibytes(unanswered_request_bytes_) + " MiB)";
  const std::string refusal =
      "a server closes the connection, without a reply, to a request larger than its maximum "
      "message size (robin-subdomain --max-message-size BYTES, default 1073741824 = 1 GiB; "
      "robin-subdomain-py the same)";
  if (server_still_running) {
    return lost + " while " + request + " was unanswered, and the server process is still " +
           "running: it most likely refused the request as too large (" + refusal +
           "); restart it with a larger --max-message-size";
  }
  return lost + " while " + request + " was unanswered: the server stopped or crashed, or " +
         refusal;
}

std::string RequestChannel::server_failure_reason() const {
  return hooks_enabled_ && options_.server_failure ? options_.server_failure() : std::string();
}

void RequestChannel::wait_for(short events, const Deadline& deadline,
                              const std::string& timeout_problem) {
  for (;;) {
    if (hooks_enabled_ && options_.on_wait) options_.on_wait();
    // A reply already delivered wins over a connection lost after it (a server that answers a
    // shutdown and exits at once).
    if (poll_dealer(events, std::chrono::milliseconds(0))) return;
    check_connection();
    const auto remaining = deadline.at - Clock::now();
    if (remaining <= Clock::duration::zero()) throw ChannelFailure(timeout_problem);
    const auto slice =
        std::min(wait_slice, std::chrono::ceil<std::chrono::milliseconds>(remaining));
    if (poll_dealer(events, slice)) return;
  }
}

bool RequestChannel::poll_dealer(short events, std::chrono::milliseconds timeout) {
  std::vector<zmq::pollitem_t> items{{sockets_->dealer.handle(), 0, events, 0},
                                     {sockets_->monitor.handle(), 0, ZMQ_POLLIN, 0}};
  try {
    zmq::poll(items, timeout);
  } catch (const zmq::error_t& error) {
    if (error.num() != EINTR) throw ChannelFailure(std::string("poll failed: ") + error.what());
    return false;  // a signal: the caller's next round runs on_wait, which may abandon the wait
  }
  return (items[0].revents & events) != 0;
}

void RequestChannel::read_monitor_events() {
  // Monitor messages: frame 1 = uint16 event + uint32 value, frame 2 = the endpoint.
  for (;;) {
    zmq::message_t event;
    if (!sockets_->monitor.recv(event, zmq::recv_flags::dontwait)) return;
    std::uint16_t number = 0;
    std::uint32_t value = 0;
    if (event.size() >= sizeof number + sizeof value) {
      std::memcpy(&number, event.data(), sizeof number);
      std::memcpy(&value, static_cast<const char*>(event.data()) + sizeof number, sizeof value);
    }
    while (event.more()) {
      if (!sockets_->monitor.recv(event, zmq::recv_flags::dontwait)) break;
    }
    if (number == ZMQ_EVENT_CONNECTED || number == ZMQ_EVENT_HANDSHAKE_SUCCEEDED) {
      connected_ = true;
    } else if (number == ZMQ_EVENT_DISCONNECTED && connected_) {
      connected_ = false;
      lost_ = true;
    } else if (handshake_failure_.empty() || number == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
      handshake_failure_ = handshake_failure(number, value);
    }
  }
}

std::string RequestChannel::handshake_failure(unsigned event, std::uint32_t value) const {
  const bool curve = options_.curve.has_value();
  const std::string mechanism = curve ? "CurveZMQ" : "unencrypted (no CurveZMQ)";
  if (event == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
    std::string text = "authentication refused by the server (" + zap_status_meaning(value) +
                       ", ZAP status " + std::to_string(value) + ")";
    if (curve && value == 400) {
      text += ": this coordinator's public key " + options_.curve->client.public_key +
              " is not on the server's allow-list (robin-subdomain --curve-allow)";
    }
    return text;
  }
  if (event == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL &&
      value == ZMQ_PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH) {
    return "the security handshake failed: the server and this coordinator use different "
           "security mechanisms (this coordinator: " +
           mechanism + "); " +
           (curve ? "the server runs without --curve-secret-key"
                  : "the server requires CurveZMQ: give --curve-secret-key and "
                    "--curve-server-key");
  }
  if (event == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL) {
    std::ostringstream code;
    code << std::hex << value;
    return "the security handshake failed (" + mechanism + ", ZMTP protocol error 0x" + code.str() +
           ")";
  }
  if (curve) {
    return "the CurveZMQ handshake failed: the server closed the connection during it (is "
           "--curve-server-key this server's public key, and does the server run with "
           "--curve-secret-key?)";
  }
  return "the connection handshake failed: the peer closed the connection during the ZeroMQ "
         "handshake (is it a robin-subdomain server? if it requires CurveZMQ, give "
         "--curve-secret-key and --curve-server-key)";
}

}  // namespace robin
