#pragma once
// The server's ZAP handler (ZeroMQ RFC 27, ZAP 1.0) for CurveZMQ (docs/security.md).
//
// With ZMQ_CURVE_SERVER, libzmq asks the handler bound to inproc://zeromq.zap.01 in the socket's
// context about every client that completed the CURVE handshake (and so proved it holds the
// secret key of the public key it presents). Without a handler libzmq admits every client, so
// the server creates one before it binds. The handler admits exactly the public keys of the
// allow-list (status 200) and refuses every other client (status 400, logged with the client's
// key and address); libzmq then closes that connection and the server goes on serving others.
//
// ZAP 1.0 request frames: version "1.0", request id, domain, address, identity, mechanism,
// credentials (CURVE: the client's 32-byte public key). Reply frames: version "1.0", the
// request id, status code, status text, user id, metadata (empty).

#include <atomic>
#include <set>
#include <string>
#include <thread>
#include <vector>
#include <zmq.hpp>

namespace robin {

/// The handler's verdict on one ZAP request.
struct ZapDecision {
  std::string status_code;  // "200" admitted, "400" refused, "500" malformed request
  std::string status_text;
  std::string client_key;  // the CURVE public key in Z85, when the request carries one
  std::string address;     // the peer's address (e.g. "10.0.0.7"), when the request has one
};

/// The verdict on `request` (its frames as received): 200 for a CURVE client whose public key
/// (Z85) is in `allowed`, 400 for any other client, 500 for a request that is not ZAP 1.0.
ZapDecision decide_zap_request(const std::vector<std::string>& request,
                               const std::set<std::string>& allowed);

/// The reply frames to `request` with `decision` (the user id is the client's key).
std::vector<std::string> zap_reply(const std::vector<std::string>& request,
                                   const ZapDecision& decision);

class ZapHandler {
 public:
  /// Binds inproc://zeromq.zap.01 in `context` and answers on a thread of its own until
  /// destruction. `allow_list` names the allow-list in the log lines. Throws zmq::error_t when
  /// another handler is bound in the context.
  ZapHandler(zmq::context_t& context, const std::vector<std::string>& allowed_keys,
             std::string allow_list);
  ~ZapHandler();
  ZapHandler(const ZapHandler&) = delete;
  ZapHandler& operator=(const ZapHandler&) = delete;

 private:
  void serve();
  void answer(const std::vector<std::string>& request);

  zmq::socket_t socket_;
  std::set<std::string> allowed_;
  std::string allow_list_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace robin
