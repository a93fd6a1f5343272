#pragma once
// The conformance checker's conversation with one server (internal to robin_remote; see
// conformance_check.hpp): raw requests and replies as they are on the wire, the bookkeeping of
// the rules every reply must keep (request_id echoed, Version present), the running of checks
// with deadlines, and the expectations that turn a reply into a plain-words problem.
//
// The session speaks through a DEALER connection of its own rather than RequestChannel, which
// stamps our version and a request id on every request and discards replies with another id:
// the checker must send malformed requests and see every reply as it is.
//
// Admission: before its first connection, the session sends a Hello through a RequestChannel
// (the reply is not awaited), whose socket monitor reports a refused security handshake at
// once (the server's ZAP handler refusing this client's CURVE key, mismatched mechanisms, the
// wrong server key; see request_channel.hpp). A failure before the deadline fails the first
// check with RequestChannel's explanation and every further check at once as "not checked": the
// server does not admit this client. A send that times out fails that check like any request
// without a reply (the recovery Hello then decides whether the server is unresponsive).
//
// Deadlines: every request has ConformanceOptions::reply_timeout_seconds. After a request
// without a reply (or one that could not be sent) the connection is replaced, so that a late
// reply is never taken for the next request's, and a Hello must be answered on the new one;
// when it is not, the server is unresponsive and every further check fails at once.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "remote/conformance_check.hpp"
#include "robin.pb.h"

namespace robin::conformance {

// --- Plain words ---------------------------------------------------------------------------

/// A number with 6 significant digits.
std::string number(double value);
std::string join(const std::vector<std::string>& parts, const std::string& separator);
/// The first `limit` problems joined by "; ", and how many more there are.
std::string summarize(const std::vector<std::string>& problems, std::size_t limit = 3);
/// "what: problem", or "" when there is no problem.
std::string in_context(const std::string& what, const std::string& problem);
/// The message type of an Envelope content, e.g. "HelloReply".
std::string content_name(protocol::Envelope::ContentCase content);
/// What a reply is: "HelloReply", or "Error{WRONG_STATE: message}" (message shortened).
std::string describe(const protocol::Envelope& reply);

/// A check that cannot run because an earlier one failed; the text says which.
class NotChecked : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// --- Requests and replies ----------------------------------------------------------------------

/// One request and what came back.
struct Exchange {
  std::optional<protocol::Envelope> reply;  // set when a parsable Envelope came back
  std::string problem;                      // why there is none (timeout, unparsable, ...)
};

/// A Hello request (no version, no id: the session stamps them).
protocol::Envelope hello_request();

class Session {
 public:
  Session(const std::string& endpoint, const ConformanceOptions& options,
          ConformanceReport& report);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// Sends `envelope` with a fresh request id and, when `stamp_version`, our Version.
  Exchange request(protocol::Envelope envelope, const std::string& what, bool stamp_version = true);
  /// Sends `frames` as they are (after the delimiter); the reply must carry `expected_id`
  /// when one is given. `what` names the request in messages.
  Exchange send_raw(const std::vector<std::string>& frames, const std::string& what,
                    std::optional<std::uint64_t> expected_id);

  /// Runs one check and records it: "" from `check` is a pass, anything else the explanation
  /// of a failure; NotChecked fails it as "not checked: ...". An unresponsive server fails it
  /// at once. After a request without a reply, the recovery Hello described above.
  void run(const std::string& name, const std::function<std::string()>& check);
  void record(const std::string& name, const std::string& problem);
  /// Records a passed check with a note (e.g. why a group of optional checks did not run).
  void record_note(const std::string& name, const std::string& note);

  /// Whether a Hello on a connection of its own gets any reply within `seconds` (not counted
  /// among the replies judged by the reply-wide rules).
  bool answers_hello_within(double seconds);

  /// Replaces the connection by a new one at the next request. `immediate` false: the new
  /// connection does not use ZMQ_IMMEDIATE, with which libzmq discards the unread messages of
  /// a lost connection (it would lose the Acknowledge of a server that exits after Shutdown).
  void reconnect(bool immediate = true);
  /// Drops the connection without the recovery Hello a request without reply would cause.
  void abandon_connection();
  /// Makes the current check end with the recovery Hello.
  void mark_spoiled() { spoiled_ = true; }

  /// Counts a reply received outside the session (the oversized message's) for the rules.
  void note_reply(const protocol::Envelope& reply, const std::string& what,
                  std::optional<std::uint64_t> expected_id);
  /// The reply-wide rules over every reply received: "" or the problems.
  std::string request_id_problems() const { return reply_rule_problems(id_problems_); }
  std::string version_problems() const { return reply_rule_problems(version_problems_); }

  std::uint64_t next_request_id() { return next_id_++; }
  const std::string& endpoint() const { return endpoint_; }
  const ConformanceOptions& options() const { return options_; }
  ConformanceReport& report() { return report_; }

 private:
  struct Transport;
  void recover(const std::string& after_check);
  /// The admission Hello described above: "" when it could be sent, otherwise why not
  /// (setting refused_ when that was known before the deadline).
  std::string admission_problem();
  std::string reply_rule_problems(const std::vector<std::string>& problems) const;

  std::string endpoint_;
  const ConformanceOptions& options_;
  ConformanceReport& report_;
  std::unique_ptr<Transport> transport_;
  std::uint64_t next_id_ = 1;
  bool spoiled_ = false;
  bool admission_checked_ = false;
  bool refused_ = false;      // the server (or ZeroMQ) refused the connection: nothing can run
  std::string unresponsive_;  // why every further check is not run
  int reply_count_ = 0;
  std::vector<std::string> id_problems_;
  std::vector<std::string> version_problems_;
};

// --- Expectations: "" when the reply is as expected, otherwise what came instead --------------

std::string expect_content(const Exchange& exchange, protocol::Envelope::ContentCase expected);
/// An Error with one of `codes`, a non-empty message and, unless `state` is empty, that
/// Error.state (the state after the refused request).
std::string expect_error(const Exchange& exchange, const std::vector<protocol::ErrorCode>& codes,
                         const std::string& state);
/// Acknowledge{state}.
std::string expect_acknowledge(const Exchange& exchange, const std::string& state);

}  // namespace robin::conformance
