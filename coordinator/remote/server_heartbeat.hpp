#pragma once
// Heartbeat and progress of a server during a long request (protocol 2.1, capability "status";
// internal to robin_remote).
//
// While a port waits for the reply to a long request (setup, contact assignment, fields), it
// calls poll() from its waiting loop (at least every 100 ms). poll() sends a StatusRequest on a
// connection of its own every `interval`, collects the replies without waiting, reports each
// answered status to the observer, and throws ChannelFailure when no StatusReply arrived for
// `timeout`: the server's socket thread, which answers StatusRequest at once while another
// thread works, is stopped or hung. A slow server that keeps answering is waited for until the
// request's own deadline.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "remote/request_channel.hpp"

namespace robin {

/// What a server said it is doing (StatusReply).
struct ServerStatus {
  std::string request_type;  // "SetupBody"; empty when idle
  std::string stage;         // "factorization"; empty when none
  long dof_count = 0;
  double request_seconds = 0.0;
  double stage_seconds = 0.0;
  unsigned queued_requests = 0;
  bool busy = false;
};

using StatusObserver = std::function<void(const ServerStatus&)>;

class ServerHeartbeat {
 public:
  /// Connects (in the background) to `endpoint` with `channel` (its waiting hooks are not
  /// used). Throws ChannelFailure when ZeroMQ rejects the endpoint.
  ServerHeartbeat(const std::string& endpoint, ChannelOptions channel, double timeout_seconds,
                  double interval_seconds, StatusObserver observer);
  ~ServerHeartbeat();
  ServerHeartbeat(const ServerHeartbeat&) = delete;
  ServerHeartbeat& operator=(const ServerHeartbeat&) = delete;

  /// Starts watching a request that has just been sent (the timeout counts from now).
  void start();
  /// Stops watching; a StatusReply still on its way is discarded later.
  void stop();
  /// See the file comment. Does nothing when not started.
  void poll();

 private:
  std::unique_ptr<RequestChannel> channel_;
  double timeout_seconds_;
  double interval_seconds_;
  StatusObserver observer_;
  bool watching_ = false;
  Clock::time_point last_answer_, last_request_;
  std::optional<std::uint64_t> outstanding_;  // request id of the StatusRequest in flight
  std::optional<ServerStatus> last_status_;
};

}  // namespace robin
