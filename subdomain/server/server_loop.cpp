#include "server/server_loop.hpp"

#include <cholmod.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <sstream>
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

/// One received request: its routing frames (kept for the reply), its payload frames and the
/// file descriptor of the connection it came on (ZMQ_SRCFD; -1 when unknown), which names the
/// connection in the socket monitor's disconnection events.
struct Request {
  std::vector<zmq::message_t> routing;
  std::vector<zmq::message_t> payload;
  int connection = -1;
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
  request.connection = frames.back().get(ZMQ_SRCFD);
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

/// Runs CHOLMOD's supernodal factorization, and through it LAPACK's dpotrf and OpenBLAS, once
/// on a small dense matrix, on the thread that will factorize the bodies. OpenBLAS takes its
/// work buffer (128 MiB of address space) at its first call on a thread and keeps it; when that
/// first call comes with memory short (under an address-space limit, after a body's factor took
/// the rest), OpenBLAS 0.3.21 retries the allocation forever instead of failing, and the server
/// hangs in the request. Taken here, at start, while memory is free, the buffer serves every
/// later factorization, and a factorization short of memory fails in CHOLMOD (an error reply).
void warm_up_dense_kernels() {
  cholmod_common common;
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.print = 0;
  constexpr int size = 8;
  cholmod_sparse* matrix =
      cholmod_allocate_sparse(size, size, size * (size + 1) / 2, 1, 1, -1, CHOLMOD_REAL, &common);
  if (matrix != nullptr) {
    auto* columns = static_cast<int*>(matrix->p);
    auto* rows = static_cast<int*>(matrix->i);
    auto* values = static_cast<double*>(matrix->x);
    int entry = 0;
    for (int column = 0; column < size; ++column) {  // lower triangle of 1 + size I: SPD
      columns[column] = entry;
      for (int row = column; row < size; ++row, ++entry) {
        rows[entry] = row;
        values[entry] = row == column ? 1.0 + size : 1.0;
      }
    }
    columns[size] = entry;
    cholmod_factor* factor = cholmod_analyze(matrix, &common);
    if (factor != nullptr) cholmod_factorize(matrix, factor, &common);
    cholmod_free_factor(&factor, &common);
    cholmod_free_sparse(&matrix, &common);
  }
  cholmod_finish(&common);
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
    abandoned_.store(false);
    current_connection_ = request.connection;
    {
      const std::lock_guard lock(mutex_);
      request_ = std::move(request);
      pending_ = true;
      busy_ = true;
    }
    wake_.notify_one();
  }

  /// The flag SubdomainServer::watch_abandonment() reads.
  const std::atomic<bool>& abandoned() const { return abandoned_; }
  /// Abandons the current request when it came on `connection`; returns whether it did.
  bool abandon_if_from(int connection) {
    if (!busy_ || connection < 0 || current_connection_ != connection) return false;
    abandoned_.store(true);
    return true;
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
    warm_up_dense_kernels();
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
  std::atomic<bool> abandoned_{false};
  int current_connection_ = -1;  // the current request's connection (socket thread only)
  bool pending_ = false;         // a request was handed over and not yet picked up
  bool stopping_ = false;
  std::thread thread_;
};

/// The socket monitor's disconnection events of the ROUTER socket: each names the file
/// descriptor of a connection that closed (the client exited, closed its socket, or its peer
/// heartbeat or TCP connection failed).
class ConnectionMonitor {
 public:
  ConnectionMonitor(zmq::context_t& context, zmq::socket_t& socket)
      : events_(context, zmq::socket_type::pair) {
    std::ostringstream address;
    address << "inproc://robin-server-connections-" << static_cast<const void*>(&socket);
    if (zmq_socket_monitor(socket.handle(), address.str().c_str(), ZMQ_EVENT_DISCONNECTED) != 0) {
      throw zmq::error_t();
    }
    events_.set(zmq::sockopt::linger, 0);
    events_.connect(address.str());
  }

  zmq::socket_t& socket() { return events_; }

  /// The connections reported closed since the last call (never blocks).
  std::vector<int> take_disconnections() {
    std::vector<int> connections;
    while (true) {
      zmq::message_t event;
      zmq::message_t endpoint;
      try {
        if (!events_.recv(event, zmq::recv_flags::dontwait)) return connections;
        if (event.more()) (void)events_.recv(endpoint, zmq::recv_flags::none);
      } catch (const zmq::error_t& error) {
        if (error.num() == EINTR) continue;
        throw;
      }
      // Event frame: 16-bit event number, then the 32-bit value (here the descriptor).
      if (event.size() < 6) continue;
      std::uint16_t number = 0;
      std::int32_t value = 0;
      std::memcpy(&number, event.data(), sizeof number);
      std::memcpy(&value, static_cast<const char*>(event.data()) + 2, sizeof value);
      if (number == ZMQ_EVENT_DISCONNECTED) connections.push_back(value);
    }
  }

 private:
  zmq::socket_t events_;
};

/// Drops the queued requests that came on the closed `connections` and abandons the current
/// one when it did (its reply could not be delivered). Descriptors are reused by later
/// connections, so the events are taken just before each request is received: a request
/// received afterwards came on a connection still open when its predecessor's event was seen.
void forget_requests_of(const std::vector<int>& connections, RequestWorker& worker,
                        std::deque<Request>& queue, spdlog::logger& logger) {
  for (const int connection : connections) {
    const auto before = queue.size();
    queue.erase(std::remove_if(queue.begin(), queue.end(),
                               [connection](const Request& request) {
                                 return request.connection == connection;
                               }),
                queue.end());
    if (queue.size() != before) {
      logger.warn("a client disconnected: dropped its {} queued request(s)", before - queue.size());
    }
    if (worker.abandon_if_from(connection)) {
      logger.warn(
          "the client of the request being handled disconnected: abandoning the "
          "request at its next stage");
    }
  }
}

/// What woke wait_for_work up.
struct Work {
  bool request_waiting = false;
  bool reply_ready = false;
  bool connection_event = false;
};

/// Waits up to `timeout` for a request, a finished reply or a connection event (nothing on
/// timeout or when a signal interrupted the wait).
Work wait_for_work(zmq::socket_t& socket, int ready_descriptor, zmq::socket_t& connection_events,
                   std::chrono::milliseconds timeout) {
  zmq::pollitem_t items[] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                             {nullptr, ready_descriptor, ZMQ_POLLIN, 0},
                             {connection_events.handle(), 0, ZMQ_POLLIN, 0}};
  try {
    zmq::poll(items, 3, timeout);
  } catch (const zmq::error_t& error) {
    if (error.num() == EINTR) return {};
    throw;
  }
  return {(items[0].revents & ZMQ_POLLIN) != 0, (items[1].revents & ZMQ_POLLIN) != 0,
          (items[2].revents & ZMQ_POLLIN) != 0};
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
  server.watch_abandonment(&worker.abandoned());
  ConnectionMonitor monitor(context, socket);
  std::deque<Request> queue;  // requests of other clients behind the current one
  while (!stop.load()) {
    const auto [request_waiting, reply_ready, connection_event] =
        wait_for_work(socket, worker.ready_descriptor(), monitor.socket(), options.poll_interval);
    if (connection_event || request_waiting) {
      forget_requests_of(monitor.take_disconnections(), worker, queue, *logger);
    }
    if (reply_ready) {
      auto [request, reply] = worker.take_reply();
      // Cleared before the reply leaves: a client may signal the server as soon as it has the
      // reply, and that signal must find the server idle (a clean stop, not the mid-request exit).
      busy.store(false);
      send_reply(socket, request, reply);
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
