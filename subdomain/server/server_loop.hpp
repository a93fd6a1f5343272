#pragma once
// The subdomain server's transport: a ZeroMQ ROUTER socket that feeds SubdomainServer.
//
// Requests are handled one at a time, in arrival order, by a worker thread; the socket's thread
// stays free meanwhile and answers StatusRequest at once (SubdomainServer::answer_status), so a
// coordinator sees a long setup's progress and tells a slow server from a hung one. Requests of
// other clients arriving while one is handled wait in a queue (at most
// maximum_queued_requests; beyond, they get a MALFORMED_MESSAGE reply saying the server is
// busy). A socket monitor watches the connections: when a client's connection closes, its
// queued requests are dropped and the request being handled for it is abandoned at its next
// stage boundary (SubdomainServer::watch_abandonment). Clients speak REQ framing (an empty
// delimiter frame, then one serialized Envelope; a DEALER may leave the delimiter out); the reply
// goes back with the request's routing frames.
//
// The socket is bound to `endpoint` (tcp://host:port, tcp://*:port, tcp://127.0.0.1:* for an
// ephemeral port, ipc://path). Socket options:
//  - ZMQ_LINGER 0: closing never waits for unsent replies;
//  - ZMQ_MAXMSGSIZE = max_message_size: libzmq refuses a larger message by dropping it and
//    disconnecting its sender, so the sender gets NO reply (its request times out); the server
//    itself stays up and serves other (and reconnecting) clients;
//  - ZMQ_SNDTIMEO = send_timeout (a backstop: a ROUTER drops a reply to a client that vanished
//    instead of blocking).
// Each request must be one frame (one serialized Envelope); a multi-frame message gets a
// MALFORMED_MESSAGE reply.
//
// With `curve` set, the socket is a CurveZMQ server (ZMQ_CURVE_SERVER with the server's secret
// key): traffic is encrypted and only clients whose public key is on the allow-list are
// admitted, by the ZAP handler (zap_handler.hpp) started in the socket's context before the
// socket binds. Without it the transport has no security (ZMTP's NULL mechanism).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "curve_keys.hpp"
#include "server/subdomain_server.hpp"

namespace robin {

/// CurveZMQ on the server's socket (docs/security.md).
struct CurveServerOptions {
  CurveKeyPair key_pair;  // the server's (robin-subdomain --curve-secret-key)
  std::vector<std::string> allowed_client_keys;  // Z85 public keys (--curve-allow)
  std::string allow_list;                        // the allow-list's file, named in the log
};

struct ServerLoopOptions {
  std::string endpoint;
  std::int64_t max_message_size = std::int64_t{1} << 30;  // bytes (1 GiB)
  std::chrono::milliseconds send_timeout{10000};
  /// How often the stop flag is checked while no request arrives.
  std::chrono::milliseconds poll_interval{200};
  /// Requests waiting behind the one being handled; more are refused at once.
  std::size_t maximum_queued_requests = 16;
  /// Unset: no transport security.
  std::optional<CurveServerOptions> curve;
};

/// The endpoint cannot be bound (address in use, malformed endpoint, ...). Names the endpoint.
class BindError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Binds the socket, calls `on_listening` once with the actual endpoint (ZMQ_LAST_ENDPOINT:
/// wildcards and ephemeral ports resolved), then serves requests until `server` has answered a
/// Shutdown or `stop` becomes true (checked every poll_interval; a signal handler may set it).
/// `busy` is true while a request is being handled (a signal handler may then end the process
/// at once instead of waiting for a long setup to finish).
/// Returns "Shutdown request" or "stop requested", the reason it stopped.
/// Throws BindError when binding fails, zmq::error_t on other transport failures.
std::string run_server_loop(SubdomainServer& server, const ServerLoopOptions& options,
                            const std::atomic<bool>& stop, std::atomic<bool>& busy,
                            const std::function<void(const std::string&)>& on_listening);

}  // namespace robin
