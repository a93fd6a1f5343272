#pragma once
// One ZeroMQ connection from the coordinator to a subdomain server (internal to robin_remote).
//
// The server binds a REP socket; the channel connects a DEALER socket and speaks the REQ
// envelope by hand: every message is an empty delimiter frame followed by one serialized
// protocol Envelope. Each request carries a fresh request id; replies with another id (stale
// replies to abandoned requests) are discarded. Waits are bounded by a deadline and sliced
// (<= 100 ms) so that cancellation hooks run while waiting.
//
// Socket options, chosen deliberately:
//   ZMQ_LINGER 0           closing never blocks on unsent messages (a dead server must not hang
//                          the coordinator's exit);
//   ZMQ_IMMEDIATE 1        messages are queued only on completed connections, so a request to a
//                          server that is not there waits (and times out) instead of vanishing;
//                          the price: libzmq drops the unread replies of a connection that
//                          closes, so a request after which the server exits (shutdown) uses
//                          ChannelOptions::immediate = false;
//   ZMQ_SNDTIMEO           a backstop: sends happen after the socket polled writable, so they
//                          never block longer than this;
//   ZMQ_MAXMSGSIZE         larger inbound messages drop the connection instead of exhausting
//                          memory;
//   ZMQ_HEARTBEAT_IVL/TIMEOUT/TTL   ZMTP pings detect a peer whose host vanished without
//                          closing its TCP connection.
// A socket monitor reports disconnects: a connection lost after it was established fails the
// pending and every later request at once, instead of at the deadline (a server that crashed or
// was killed lost the body's state, so there is nothing to resume). A server also closes the
// connection, without a reply, to a request above its --max-message-size (libzmq's
// ZMQ_MAXMSGSIZE): the failure then names the size of the request left unanswered and that
// limit, and says that the server is still running when the server_failure hook watched it.
//
// CurveZMQ (ChannelOptions::curve, docs/security.md): the dealer is a CURVE client with the
// coordinator's key pair and the server's public key. The monitor also reports failed security
// handshakes, which fail the pending and every later request at once with a message that says
// why: ZMQ_EVENT_HANDSHAKE_FAILED_AUTH (the server's ZAP handler refused this client's public
// key: status 400; libzmq does not reconnect after it, so without the event a request would
// wait until its deadline), ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL (e.g. one side uses CURVE and
// the other not) and ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL (the server closed the connection
// during the handshake: a CURVE server does that to a client that encrypted its HELLO for
// another server key). A handshake failure takes precedence over the lost connection that
// follows it.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "curve_keys.hpp"

namespace robin::protocol {
class Envelope;
}

namespace robin {

using Clock = std::chrono::steady_clock;

/// A point in time to give up at, and the duration it stands for (for messages).
struct Deadline {
  Clock::time_point at;
  double seconds = 0.0;
  static Deadline after(double seconds);
};

/// A transport failure. The text says what happened ("no reply within 60 s"); the port adds
/// the server, the body and the step.
class ChannelFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ChannelOptions {
  long max_message_bytes = 1L << 30;  // ZMQ_MAXMSGSIZE of inbound messages
  int heartbeat_interval_milliseconds = 1000;
  int heartbeat_timeout_milliseconds = 5000;
  /// ZMQ_IMMEDIATE (see above). False keeps a reply that arrived just before the server closed
  /// its end; the send then queues without waiting for the connection.
  bool immediate = true;
  /// CurveZMQ client keys; unset: no transport security (ZMTP's NULL mechanism).
  std::optional<CurveClientKeys> curve;
  /// Called at least every 100 ms while waiting; may throw (e.g. RunInterrupted) to abandon the
  /// wait. The exception propagates unchanged.
  std::function<void()> on_wait;
  /// Returns why the server cannot answer any more (e.g. "the server process was killed by
  /// signal 9"), or an empty string. Checked while waiting; a reason fails the wait.
  std::function<std::string()> server_failure;
};

class RequestChannel {
 public:
  /// Connects (asynchronously: the connection is made in the background). Throws
  /// ChannelFailure when ZeroMQ rejects the endpoint.
  RequestChannel(const std::string& endpoint, ChannelOptions options);
  ~RequestChannel();
  RequestChannel(const RequestChannel&) = delete;
  RequestChannel& operator=(const RequestChannel&) = delete;

  /// Sends `envelope` after setting its version and a new request id; returns that id.
  /// Throws ChannelFailure when no connection is ready before the deadline or it was lost.
  std::uint64_t send(protocol::Envelope& envelope, const Deadline& deadline);
  /// The reply to `request_id`. Throws ChannelFailure on deadline, lost connection or a reply
  /// that is not a protocol message.
  protocol::Envelope receive(std::uint64_t request_id, const Deadline& deadline);
  /// The reply to `request_id` if it has arrived, without waiting (other replies are
  /// discarded); nullopt otherwise. Throws ChannelFailure like receive().
  std::optional<protocol::Envelope> try_receive(std::uint64_t request_id);

  /// Turns the on_wait and server_failure hooks off or on (off for best-effort requests that
  /// must still be sent after a cancellation, such as EndRun).
  void set_hooks_enabled(bool enabled) { hooks_enabled_ = enabled; }
  /// True once an established connection dropped (the server stopped or crashed).
  bool connection_lost();
  long bytes_sent() const { return bytes_sent_; }
  long bytes_received() const { return bytes_received_; }

 private:
  struct Sockets;
  void wait_for(short events, const Deadline& deadline, const std::string& timeout_problem);
  /// True when the dealer is ready for `events` within `timeout` (false on EINTR).
  bool poll_dealer(short events, std::chrono::milliseconds timeout);
  void check_connection();
  /// Why the connection was lost, naming the size of the request left unanswered (if any):
  /// a server refuses a request above its --max-message-size by closing the connection, which
  /// looks like a crash. `server_still_running`: the server_failure hook watched the server
  /// through the grace period and it did not stop.
  std::string lost_connection_message(bool server_still_running) const;
  /// Reads the waiting message and parses its Envelope (ChannelFailure when it is none).
  protocol::Envelope read_reply();
  std::string server_failure_reason() const;
  void read_monitor_events();
  /// The message for a failed handshake (monitor event `event` with value `value`).
  std::string handshake_failure(unsigned event, std::uint32_t value) const;

  std::unique_ptr<Sockets> sockets_;
  ChannelOptions options_;
  std::uint64_t next_request_id_ = 1;
  bool connected_ = false;
  bool lost_ = false;
  std::string handshake_failure_;  // why the security handshake failed, or ""
  bool hooks_enabled_ = true;
  long bytes_sent_ = 0;
  long bytes_received_ = 0;
  std::size_t unanswered_request_bytes_ = 0;  // the last request sent, until its reply; 0: none
};

}  // namespace robin
