#include "server/server_loop.hpp"

#include <spdlog/spdlog.h>
#include <cerrno>
#include <optional>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "server/server_logging.hpp"
#include "server/zap_handler.hpp"

namespace robin {
namespace {

/// The REP socket, re-created on the same (resolved) endpoint after a failed send.
class ReplySocket {
 public:
  ReplySocket(zmq::context_t& context, const ServerLoopOptions& options)
      : context_(context), options_(options) {
    try {
      socket_ = open(options.endpoint);
    } catch (const zmq::error_t& error) {
      throw BindError("cannot listen on '" + options.endpoint + "': " + error.what());
    }
    endpoint_ = socket_.get(zmq::sockopt::last_endpoint);
  }

  const std::string& endpoint() const { return endpoint_; }
  zmq::socket_t& socket() { return socket_; }

  /// Closes the socket (dropping a pending reply) and binds a new one to endpoint(); retries
  /// for about a second while the old listener is being released.
  void reopen() {
    socket_.close();
    for (int attempt = 0;; ++attempt) {
      try {
        socket_ = open(endpoint_);
        return;
      } catch (const zmq::error_t& error) {
        if (error.num() != EADDRINUSE || attempt == 20) {
          throw BindError("cannot listen again on '" + endpoint_ + "': " + error.what());
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
  }

 private:
  zmq::socket_t open(const std::string& endpoint) {
    zmq::socket_t socket(context_, zmq::socket_type::rep);
    socket.set(zmq::sockopt::linger, 0);
    socket.set(zmq::sockopt::maxmsgsize, options_.max_message_size);
    socket.set(zmq::sockopt::sndtimeo, static_cast<int>(options_.send_timeout.count()));
    if (options_.curve) {
      socket.set(zmq::sockopt::curve_server, 1);
      socket.set(zmq::sockopt::curve_secretkey, options_.curve->key_pair.secret_key);
    }
    socket.bind(endpoint);
    return socket;
  }

  zmq::context_t& context_;
  const ServerLoopOptions& options_;
  zmq::socket_t socket_;
  std::string endpoint_;
};

/// Waits up to `timeout` for a request; false when none arrived (or a signal interrupted).
bool wait_for_request(zmq::socket_t& socket, std::chrono::milliseconds timeout) {
  zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
  try {
    zmq::poll(&item, 1, timeout);
  } catch (const zmq::error_t& error) {
    if (error.num() == EINTR) return false;
    throw;
  }
  return (item.revents & ZMQ_POLLIN) != 0;
}

/// Receives every frame of the waiting message.
std::vector<zmq::message_t> receive_frames(zmq::socket_t& socket) {
  std::vector<zmq::message_t> frames;
  do {
    zmq::message_t frame;
    try {
      if (!socket.recv(frame, zmq::recv_flags::none)) break;
    } catch (const zmq::error_t& error) {
      if (error.num() != EINTR) throw;
      continue;  // interrupted before the frame arrived: receive it again
    }
    frames.push_back(std::move(frame));
  } while (frames.back().more());
  return frames;
}

/// Sends `reply`; false when it could not be queued within the send timeout.
bool send_reply(zmq::socket_t& socket, const std::string& reply) {
  for (;;) {
    try {
      return socket.send(zmq::buffer(reply), zmq::send_flags::none).has_value();
    } catch (const zmq::error_t& error) {
      if (error.num() != EINTR) throw;
    }
  }
}

std::string reply_to(SubdomainServer& server, const std::vector<zmq::message_t>& frames) {
  if (frames.size() == 1) return server.handle(frames.front().to_string_view());
  return server.reject("the message has " + std::to_string(frames.size()) +
                       " frames, expected one (a serialized Envelope)");
}

}  // namespace

std::string run_server_loop(SubdomainServer& server, const ServerLoopOptions& options,
                            const std::atomic<bool>& stop, std::atomic<bool>& busy,
                            const std::function<void(const std::string&)>& on_listening) {
  const auto logger = subdomain_logger();
  zmq::context_t context(1);
  // Bound before the socket: without a ZAP handler, libzmq admits every CURVE client.
  std::optional<ZapHandler> authentication;
  if (options.curve) {
    authentication.emplace(context, options.curve->allowed_client_keys, options.curve->allow_list);
  }
  ReplySocket socket(context, options);
  logger->info("{} listening on {} (max message size {} bytes, {})", server.server_name(),
               socket.endpoint(), options.max_message_size,
               options.curve ? "CurveZMQ with public key " + options.curve->key_pair.public_key +
                                   ", admitting the " +
                                   std::to_string(options.curve->allowed_client_keys.size()) +
                                   " client key(s) of " + options.curve->allow_list
                             : std::string("no transport security"));
  on_listening(socket.endpoint());
  while (!stop.load()) {
    if (!wait_for_request(socket.socket(), options.poll_interval)) continue;
    const std::vector<zmq::message_t> frames = receive_frames(socket.socket());
    if (frames.empty()) continue;
    busy.store(true);
    const std::string reply = reply_to(server, frames);
    busy.store(false);
    if (!send_reply(socket.socket(), reply)) {
      logger->warn(
          "the reply could not be sent within {} ms (client gone?); re-creating the "
          "socket on {}",
          options.send_timeout.count(), socket.endpoint());
      socket.reopen();
    }
    if (server.shutdown_requested()) return "Shutdown request";
  }
  return "stop requested";
}

}  // namespace robin
