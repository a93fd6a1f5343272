#pragma once
// robin-coordinator --check-server ENDPOINT: a conformance checker for subdomain servers.
//
// check_server() drives the server at an endpoint through every message of the protocol
// (proto/robin.proto, docs/protocol.md), well-formed and not: malformed bytes, requests out of
// order, refused bodies and assignments, wrong vector lengths, a NaN and an infinity in the
// ContactSolveRequest obstacle and the CorrectionRequest interface force (INVALID_ARGUMENT,
// the server staying ready), an oversized message. It judges only what travels on the wire, so
// that any implementation can be checked, and reports every deviation in plain words naming the
// message.
//
// The body it sets up is built in: the unit square [0, 1]^2 (a structured mesh of 4 x 4 squares
// split into triangles, sent as MeshData), isotropic plane strain, its bottom edge lifted by a
// prescribed displacement u = (0, lift) and no load, its top edge the contact boundary. Its
// solution without contact is the rigid translation u = (0, lift), so e_i = lift at every contact
// node and the expected answers of the free solve and of the fields are known exactly. The
// numerical checks use only that and identities every correct server satisfies: the Signorini
// conditions, u_N = e - F lambda with F r the correction's reply, F linear, symmetric and positive
// definite, the global force balance, and the same answer in a second run. Answers indexed by the
// pair order cannot reveal a server that uses its own node order instead (they are consistently
// relabelled), so the pair order is judged through positions: a unit force at pair index k must
// move the node at x_k most, in the FieldsReply's 'displacement' field (that check needs the
// field).
//
// The optional Neumann solve (protocol 1.1, capability "neumann_solve") is checked only when
// HelloReply.capabilities announces it: WRONG_STATE before SetupBody and AssignContact,
// INVALID_ARGUMENT for a wrong length, a NaN and an infinity, u_N = e = lift for lambda = 0,
// u_N = e - F lambda with e the far-obstacle contact solve's u_N and F lambda the
// CorrectionResult for r = lambda, and the contact solve's u_N for its own lambda. Its absence
// is no deviation (the check 'neumann_solve_capability' passes with a note); the request must
// then be refused as UNSUPPORTED.
//
// Load steps (protocol 2.1, SetLoadFactor) are judged for servers whose HelloReply carries
// version 2.1 or later: a NaN, -infinity and 1e9 must be refused as BAD_INPUT with the state
// 'ready'; the factors 2.5, -0.5 and 1 must each be acknowledged (LoadFactorSet with the factor
// and 'ready'), the far-obstacle contact solve must then give u_N = factor * lift (the body's
// only load is its lifted edge) and the correction must not change (F does not depend on the
// loads); after the final EndRun the request is WRONG_STATE. A 2.0 server must refuse it as
// UNSUPPORTED.
//
// Materials: robin-coordinator sends every material that is not isotropic plane strain as the
// 3x3 SetupBody.voigt matrix. 'voigt_material' sets the body up again with the Voigt matrix
// equivalent to its isotropic material; the partial-contact solve and the correction w(r1) must
// equal those of the isotropic definition to the tolerance.
//
// Solid bodies (protocol 2.4; conformance_solid.hpp): a unit cube of 4-node tetrahedra is set
// up after the plane checks and every reply about it (InterfaceDescription, contact solve,
// correction, Neumann solve when announced, fields) is compared with the same body solved in
// process. A server that refuses it with UNSUPPORTED (or, below protocol 2.4, BAD_INPUT) passes
// 'solid_setup_body' with the note "3D: not supported" and the other solid checks do not run.
//
// Runs (protocol 1.2, Envelope.run_id): 'other_run_refused' sets the body up and assigns it with
// run_id A, then a ContactSolveRequest and an EndRun with run_id B must each be refused as
// WRONG_STATE with Error.state 'ready', after which a ContactSolveRequest with run_id A and one
// without run_id must be served from the same body. A server whose HelloReply carries a version
// below 1.2 is not judged on it: the check passes with the note "not applicable".
//
// Deadlines: every request has reply_timeout_seconds. A request that gets no reply fails its
// check; the checker then opens a new connection and sends a Hello. When that is not answered
// either, the server is considered unresponsive and every remaining check fails at once as
// "not checked", so a silent server costs about two timeouts, never a hang. A server that
// refuses the connection (e.g. its CurveZMQ allow-list does not hold this client's key) fails
// the first check at once with the reason, and every further check as "not checked".
//
// The oversized-message rule: a Hello of oversized_message_bytes bytes (its client_name padded)
// must either be answered (its HelloReply or any Error carrying the request id) or be dropped
// without a reply (libzmq's ZMQ_MAXMSGSIZE drops it and disconnects the sender); in both cases
// the server must then answer a Hello on a new connection within the deadline.
//
// The checker sends EndRun (it forgets any body the server holds) but never Shutdown, unless
// include_shutdown is set; then Shutdown is the last request and the server must stop answering.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "curve_keys.hpp"

namespace robin {

struct ConformanceOptions {
  double reply_timeout_seconds = 10.0;       // deadline of every request
  long oversized_message_bytes = 64L << 20;  // size of the oversized-message probe (64 MiB)
  bool include_shutdown = false;             // finish with Shutdown (the server exits)
  double tolerance = 1e-8;                   // relative tolerance of the numerical checks
  std::optional<CurveClientKeys> curve;      // CurveZMQ client keys; unset: no security
};

struct ConformanceCheck {
  std::string name;  // e.g. "contact_solve_before_setup"
  bool passed = false;
  std::string explanation;  // why it failed, naming the message; or a note on a pass
};

struct ConformanceReport {
  std::string endpoint;
  std::string server_name;               // HelloReply.server_name, when the server answered a Hello
  std::vector<ConformanceCheck> checks;  // in the order they ran
  double seconds = 0.0;                  // wall time of the whole check

  bool conforms() const { return failure_count() == 0 && !checks.empty(); }
  std::size_t failure_count() const;
};

/// Runs every check against the server at `endpoint` (tcp://HOST:PORT or ipc://PATH). Never
/// throws for anything the server does; a bad endpoint fails the checks.
ConformanceReport check_server(const std::string& endpoint, const ConformanceOptions& options);

/// One line per check, "PASS name" (with " (note)" when there is one) or
/// "FAIL name: explanation", then a summary line.
std::string format_report(const ConformanceReport& report);

/// True when the command line asks for a server check (it contains --check-server).
bool requests_server_check(int argc, const char* const* argv);

/// robin-coordinator --check-server ENDPOINT [--timeout S] [--max-message-size-probe BYTES]
/// [--tolerance T] [--include-shutdown] [--curve-secret-key FILE --curve-server-key FILE]:
/// prints the report on standard output. Returns 0 when
/// the server conforms, 1 when it does not, 2 for a bad command line.
int server_check_main(int argc, const char* const* argv);

}  // namespace robin
