#include "remote/server_heartbeat.hpp"

#include <fmt/format.h>

#include "robin.pb.h"

namespace robin {
namespace {

double seconds_between(Clock::time_point earlier, Clock::time_point later) {
  return std::chrono::duration<double>(later - earlier).count();
}

ServerStatus decode_status(const protocol::StatusReply& reply) {
  ServerStatus status;
  status.request_type = reply.request_type();
  status.stage = reply.stage();
  status.dof_count = static_cast<long>(reply.dof_count());
  status.request_seconds = reply.request_seconds();
  status.stage_seconds = reply.stage_seconds();
  status.queued_requests = reply.queued_requests();
  status.busy = reply.busy();
  return status;
}

std::string describe_last(const std::optional<ServerStatus>& status) {
  if (!status) return "it never answered a StatusRequest";
  if (!status->busy) return "it last said it was idle";
  return fmt::format("it last said: {}{}, {:.1f} s into the request", status->request_type,
                     status->stage.empty() ? "" : ", stage " + status->stage,
                     status->request_seconds);
}

}  // namespace

ServerHeartbeat::ServerHeartbeat(const std::string& endpoint, ChannelOptions channel,
                                 double timeout_seconds, double interval_seconds,
                                 StatusObserver observer)
    : timeout_seconds_(timeout_seconds),
      interval_seconds_(interval_seconds),
      observer_(std::move(observer)) {
  channel.on_wait = nullptr;  // poll() runs inside the port's waiting hook: no recursion
  channel_ = std::make_unique<RequestChannel>(endpoint, std::move(channel));
  channel_->set_hooks_enabled(false);
}

ServerHeartbeat::~ServerHeartbeat() = default;

void ServerHeartbeat::start() {
  watching_ = true;
  last_answer_ = Clock::now();
  last_request_ = Clock::time_point{};
  outstanding_.reset();
  last_status_.reset();
}

void ServerHeartbeat::stop() {
  watching_ = false;
}

void ServerHeartbeat::poll() {
  if (!watching_) return;
  const Clock::time_point now = Clock::now();
  if (outstanding_) {
    if (std::optional<protocol::Envelope> reply = channel_->try_receive(*outstanding_)) {
      outstanding_.reset();
      last_answer_ = now;
      if (reply->has_status_reply()) {
        last_status_ = decode_status(reply->status_reply());
        if (observer_) observer_(*last_status_);
      }
    }
  }
  if (seconds_between(last_answer_, now) > timeout_seconds_) {
    watching_ = false;
    throw ChannelFailure(fmt::format(
        "no heartbeat for {:.0f} s: the server does not answer StatusRequest ({}); it is hung, "
        "stopped or cut off (robin-coordinator --heartbeat-timeout sets this limit)",
        timeout_seconds_, describe_last(last_status_)));
  }
  if (!outstanding_ && seconds_between(last_request_, now) >= interval_seconds_) {
    protocol::Envelope request;
    request.mutable_status_request();
    // A send that cannot be queued yet (the connection is still being made) is retried at the
    // next poll; the heartbeat timeout covers a connection that never comes.
    try {
      outstanding_ = channel_->send(request, Deadline::after(0.0));
      last_request_ = now;
    } catch (const ChannelFailure&) {
    }
  }
}

}  // namespace robin
