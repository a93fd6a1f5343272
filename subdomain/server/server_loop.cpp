#include "server/server_loop.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "server/server_logging.hpp"
#include "server/zap_handler.hpp"

namespace robin {
namespace {

/// The ROUTER socket every client talks to. A request arrives as [routing id, empty
/// delimiter (REQ and the coordinator's DEALER send one), payload...]; the reply goes back with
/// the same routing frames. ROUTER never blocks on a vanished client: its reply is dropped.
zmq::socket_t open_socket(zmq::context_t& context, const ServerLoopOptions& options) {
  zmq::socket_t socket(context, zmq::socket_type::router);
  socket.set(zmq::sockopt::linger, 0);
  socket.set(zmq::sockopt::maxmsgsize, options.max_message_size);
  socket.set(zmq::sockopt::sndtimeo, static_cast<int>(options.send_timeout.count()));
  if (options.curve) {
    socket.set(zmq::sockopt::curve_server, 1);
    socket.set(zmq::sockopt::curve_secretkey, options.curve->key_pair.secret_key);
  }
  try {
    socket.bind(options.endpoint);
  } catch (const zmq::error_t& error) {
    throw BindError("cannot listen on '" + options.endpoint + "': " + error.what());
  }
  return socket;
}

/// One received request: its routing frames (kept for the reply) and its payload frames.
struct Request {
  std::vector<zmq::message_t> routing;
  std::vector<zmq::message_t> payload;
};

/// Receives every frame of the waiting message and splits it after the empty delimiter (or
/// after the routing id when a DEALER sent none).
std::optional<Request> receive_request(zmq::socket_t& socket) {
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
  if (frames.size() < 2) return std::nullopt;  // a routing id alone: nothing to answer
  Request request;
  const std::size_t payload_start = frames[1].size() == 0 ? 2 : 1;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    (k < payload_start ? request.routing : request.payload).push_back(std::move(frames[k]));
  }
  return request;
}

/// Sends `reply` behind copies of the request's routing frames.
void send_reply(zmq::socket_t& socket, const Request& request, const std::string& reply) {
  for (const zmq::message_t& frame : request.routing) {
    zmq::message_t copy(frame.data(), frame.size());
    while (true) {
      try {
        socket.send(copy, zmq::send_flags::sndmore);
        break;
      } catch (const zmq::error_t& error) {
        if (error.num() != EINTR) throw;
      }
    }
  }
  while (true) {
    try {
      socket.send(zmq::buffer(reply), zmq::send_flags::none);
      return;
    } catch (const zmq::error_t& error) {
      if (error.num() != EINTR) throw;
    }
  }
}

std::string reply_to(SubdomainServer& server, const Request& request) {
  if (request.payload.size() == 1) return server.handle(request.payload.front().to_string_view());
  return server.reject("the message has " + std::to_string(request.payload.size()) +
                       " frames, expected one (a serialized Envelope)");
}

/// The thread that runs SubdomainServer::handle, one request at a time, so that the socket's
/// thread stays free to answer StatusRequest. It writes one byte into a pipe when a reply is
/// ready, which the socket's poll watches.
class RequestWorker {
 public:
  explicit RequestWorker(SubdomainServer& server) : server_(server) {
    if (::pipe(pipe_) != 0) throw std::runtime_error("cannot create the worker's pipe");
    thread_ = std::thread([this] { run(); });
  }
  ~RequestWorker() {
    {
      const std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_one();
    thread_.join();
    ::close(pipe_[0]);
    ::close(pipe_[1]);
  }
  RequestWorker(const RequestWorker&) = delete;
  RequestWorker& operator=(const RequestWorker&) = delete;

  /// The pipe end that becomes readable when a reply is ready.
  int ready_descriptor() const { return pipe_[0]; }
  bool busy() const { return busy_; }

  /// Hands `request` to the worker; only when not busy().
  void start(Request request) {
    {
      const std::lock_guard lock(mutex_);
      request_ = std::move(request);
      pending_ = true;
      busy_ = true;
    }
    wake_.notify_one();
  }

  /// The finished request and its reply, once ready_descriptor() was readable.
  std::pair<Request, std::string> take_reply() {
    char byte = 0;
    while (::read(pipe_[0], &byte, 1) < 0 && errno == EINTR) {
    }
    const std::lock_guard lock(mutex_);
    busy_ = false;
    return {std::move(*request_), std::move(reply_)};
  }

 private:
  void run() {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return stopping_ || pending_; });
      if (stopping_) return;
      pending_ = false;
      const Request& request = *request_;  // not touched by the socket's thread until the reply
      lock.unlock();
      std::string reply = reply_to(server_, request);
      lock.lock();
      reply_ = std::move(reply);
      const char byte = 1;
      while (::write(pipe_[1], &byte, 1) < 0 && errno == EINTR) {
      }
    }
  }

  SubdomainServer& server_;
  int pipe_[2] = {-1, -1};
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Request> request_;
  std::string reply_;
  std::atomic<bool> busy_{false};
  bool pending_ = false;  // a request was handed over and not yet picked up
  bool stopping_ = false;
  std::thread thread_;
};

/// Waits up to `timeout` for a request or a finished reply; returns {request waiting, reply
/// ready} (both false on timeout or when a signal interrupted the wait).
std::pair<bool, bool> wait_for_work(zmq::socket_t& socket, int ready_descriptor,
                                    std::chrono::milliseconds timeout) {
  zmq::pollitem_t items[] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                             {nullptr, ready_descriptor, ZMQ_POLLIN, 0}};
  try {
    zmq::poll(items, 2, timeout);
  } catch (const zmq::error_t& error) {
    if (error.num() == EINTR) return {false, false};
    throw;
  }
  return {(items[0].revents & ZMQ_POLLIN) != 0, (items[1].revents & ZMQ_POLLIN) != 0};
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
  zmq::socket_t socket = open_socket(context, options);
  const std::string endpoint = socket.get(zmq::sockopt::last_endpoint);
  logger->info("{} listening on {} (max message size {} bytes, {})", server.server_name(), endpoint,
               options.max_message_size,
               options.curve ? "CurveZMQ with public key " + options.curve->key_pair.public_key +
                                   ", admitting the " +
                                   std::to_string(options.curve->allowed_client_keys.size()) +
                                   " client key(s) of " + options.curve->allow_list
                             : std::string("no transport security"));
  on_listening(endpoint);
  RequestWorker worker(server);
  std::deque<Request> queue;  // requests of other clients behind the current one
  while (!stop.load()) {
    const auto [request_waiting, reply_ready] =
        wait_for_work(socket, worker.ready_descriptor(), options.poll_interval);
    if (reply_ready) {
      auto [request, reply] = worker.take_reply();
      send_reply(socket, request, reply);
      busy.store(false);
      if (server.shutdown_requested()) return "Shutdown request";
    }
    if (request_waiting) {
      if (std::optional<Request> request = receive_request(socket)) {
        const std::optional<std::string> status =
            request->payload.size() == 1
                ? server.answer_status(request->payload.front().to_string_view())
                : std::nullopt;
        if (status) {
          send_reply(socket, *request, *status);
        } else if (queue.size() >= options.maximum_queued_requests) {
          send_reply(socket, *request,
                     server.reject("the server is busy: " + std::to_string(queue.size()) +
                                       " requests of other clients are waiting; try again later",
                                   request->payload.size() == 1
                                       ? SubdomainServer::request_id_of(
                                             request->payload.front().to_string_view())
                                       : 0));
        } else {
          queue.push_back(std::move(*request));
        }
      }
    }
    if (!worker.busy() && !queue.empty()) {
      busy.store(true);
      worker.start(std::move(queue.front()));
      queue.pop_front();
    }
    server.set_queued_requests(static_cast<unsigned>(queue.size()));
  }
  return "stop requested";
}

}  // namespace robin
