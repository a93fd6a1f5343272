#pragma once
// A subdomain port that speaks the protocol of proto/robin.proto to a robin-subdomain server
// over ZeroMQ (see request_channel.hpp for the transport and its socket options).
//
// setup() performs the handshake (Hello; the reply's major version must equal ours; the
// handshake's deadline is min(request timeout, 10 s)) and then SetupBody, whose deadline is the
// setup timeout, as is that of FieldsRequest: both grow with the body (meshing, assembly,
// factorization; the whole fields). Every other request is interface-sized and has the request
// timeout as its deadline. Every failure is a PortError of the form
//   server tcp://127.0.0.1:5555 (body 'upper'), step contact solve (iteration 7): <problem>
// where <problem> is e.g. "no reply within 60 s", "the connection to the server was lost (the
// server stopped or crashed)" or "server error WRONG_STATE: <the server's message>".
//
// Capabilities: the handshake requires the core "contact_solve", "correction_solve" and
// "fields". The optional "neumann_solve" (protocol 1.1) is needed only by
// start_neumann_solve: a server that did not announce it (a protocol 1.0 server) serves the
// Robin iteration as before, and start_neumann_solve throws a PortError naming server, body and
// step, sending nothing. A server of minor version 0 is compatible (same major).
//
// Runs (protocol 1.2): setup() draws a fresh run_id (new_run_id(): 128 random bits) for this
// port, and every request of the port from then on carries it in Envelope.run_id, the
// handshake's Hello and the final EndRun included, until the next setup() draws another. Each
// port (each server) thus has its own run_id. A server that another coordinator set up since
// (the body now belongs to another run) refuses the requests of this run with WRONG_STATE, and
// the step fails with a PortError "... server error WRONG_STATE: ... now belongs to another
// run ..." instead of being answered from the other run's body; a best-effort EndRun refused
// that way ends nothing on the server. A server of protocol 1.0 or 1.1 ignores run_id.
//
// Heartbeat (protocol 2.1): with a server that announced "status", setup, contact assignment
// and fields are watched by a ServerHeartbeat (server_heartbeat.hpp) on a second connection:
// each StatusReply goes to RemotePortOptions::on_status (progress lines), and a server whose
// socket thread stops answering for heartbeat_timeout_seconds fails the step at once, e.g.
//   server tcp://127.0.0.1:5555 (body 'upper'), step setup: no heartbeat for 10 s: ...
// instead of at the setup deadline. A 2.0 server (no "status") is waited for as before.
//
// Profile (protocol 2.2): the stage times of the replies to SetupBody, AssignContact and
// FieldsRequest (StageTime), the server's whole SetupBody time and the setup's transfer: the
// encoding of SetupBody plus its round trip less the server's time. A server of protocol 2.1
// or older reports none: the profile then holds no stages, no setup and no transfer time.
//
// Timings: compute_seconds adds the server-reported times of setup (assembly and
// factorization), contact solves, corrections and Neumann solves; round_trip_seconds adds, for
// the same requests, the time from sending the request to the decoded reply; bytes count every
// message's payload in both directions.
//
// Not thread-safe: one thread at a time (the coupled run may move a port between threads).

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coupling/subdomain_port.hpp"
#include "remote/request_channel.hpp"
#include "remote/server_heartbeat.hpp"

namespace robin::protocol {
class InterfaceDescription;
class FieldsReply;
}  // namespace robin::protocol

namespace robin {

struct RemotePortOptions {
  double request_timeout_seconds = 60.0;  // CouplingOptions.request_timeout_seconds
  double setup_timeout_seconds = 3600.0;  // CouplingOptions.setup_timeout_seconds
  double handshake_timeout_limit = 10.0;  // the handshake waits min(request timeout, this)
  double end_run_timeout_seconds = 2.0;   // EndRun is best effort
  /// Transport settings and the hooks run while waiting (cancellation, child-process checks).
  ChannelOptions channel;
  /// Heartbeat of a server announcing "status" (protocol 2.1) during setup, contact
  /// assignment and fields (server_heartbeat.hpp): a StatusRequest every interval on a second
  /// connection; no StatusReply for the timeout fails the step. 0 turns heartbeats off.
  double heartbeat_timeout_seconds = 10.0;
  double heartbeat_interval_seconds = 1.0;
  /// Told each StatusReply of a long request: (body name, step, status). May be empty.
  std::function<void(const std::string&, const std::string&, const ServerStatus&)> on_status;
};

class RemotePort final : public SubdomainPort {
 public:
  /// Connects to `endpoint` (in the background). `body_label` names the body in messages
  /// until setup() knows its name. Throws PortError for an endpoint ZeroMQ rejects.
  RemotePort(std::string endpoint, std::string body_label, RemotePortOptions options = {});
  ~RemotePort() override;

  std::string describe() const override;
  InterfaceDescription setup(const BodyCase& body, const SolverOptions& solver) override;
  void assign_contact(const ContactOperator& contact) override;
  void start_contact_solve(const Eigen::VectorXd& obstacle, int iteration) override;
  ContactSolveResult finish_contact_solve() override;
  void start_correction(const Eigen::VectorXd& interface_force, int iteration,
                        double relative_accuracy) override;
  CorrectionSolveResult finish_correction() override;
  /// NeumannSolveRequest (protocol 1.1): u_N for the contact force lambda (pair order).
  void start_neumann_solve(const Eigen::VectorXd& contact_force, int iteration) override;
  CorrectionSolveResult finish_neumann_solve() override;
  /// SetLoadFactor (protocol 2.1). A server whose handshake announced minor version 0 is
  /// refused before anything is sent: "..., step load factor 0.5: the server ('NAME') speaks
  /// protocol 2.0, this coordinator speaks 2.1; a case with [loading] steps needs
  /// SetLoadFactor (protocol 2.1): ...".
  void set_load_factor(double factor) override;
  BodyOutput fields(const Eigen::VectorXd& contact_force,
                    const FieldsDestination& destination) override;
  void end_run() noexcept override;
  void abandon_request() noexcept override;
  const PortTimings& timings() const override;
  const BodyProfile& profile() const override { return profile_; }
  /// True once the connection to the server dropped after it was made (the server stopped,
  /// crashed or was killed).
  bool connection_lost();

  const std::string& endpoint() const { return endpoint_; }
  /// What the server said about itself in the handshake ("robin-subdomain 0.1.0").
  const std::string& server_name() const { return server_name_; }
  /// HelloReply.capabilities of the handshake (empty before setup()).
  const std::vector<std::string>& server_capabilities() const { return capabilities_; }
  /// Whether the handshake announced `capability`.
  bool offers(const std::string& capability) const;
  /// The protocol version of the server's handshake reply ({0, 0} before setup()).
  unsigned server_major() const { return server_major_; }
  unsigned server_minor() const { return server_minor_; }
  /// The run_id this port's requests carry (empty before the first setup()).
  const std::string& run_id() const { return run_id_; }

 private:
  struct Pending;
  void handshake();
  void send_request(protocol::Envelope& request, const std::string& step, double timeout_seconds);
  protocol::Envelope finish_request(int expected_content);
  protocol::Envelope exchange(protocol::Envelope& request, const std::string& step,
                              double timeout_seconds, int expected_content);
  /// exchange() with the heartbeat watching the server meanwhile (when it offers "status").
  protocol::Envelope watched_exchange(protocol::Envelope& request, const std::string& step,
                                      double timeout_seconds, int expected_content);
  std::string written_file_name(const protocol::FieldsReply& reply) const;
  [[noreturn]] void fail(const std::string& step, const std::string& problem) const;
  void update_byte_counts();
  void record_setup_profile(const protocol::InterfaceDescription& reply, double seconds);

  std::string endpoint_;
  std::string body_label_;
  RemotePortOptions options_;
  std::unique_ptr<RequestChannel> channel_;
  std::unique_ptr<ServerHeartbeat> heartbeat_;  // made by the handshake when "status" is offered
  std::string watched_step_;
  std::unique_ptr<Pending> pending_;
  std::string server_name_;
  std::vector<std::string> capabilities_;
  unsigned server_major_ = 0, server_minor_ = 0;
  long contact_size_ = 0;
  bool set_up_ = false;
  std::string run_id_;  // Envelope.run_id of every request, drawn by setup()
  PortTimings timings_;
  BodyProfile profile_;
};

/// A fresh run identifier for Envelope.run_id: 128 bits from std::random_device, as 32
/// lowercase hexadecimal digits. Distinct runs get distinct identifiers with overwhelming
/// probability.
std::string new_run_id();

/// Waits until a server answers a handshake (Hello) at `endpoint`, trying every second for at
/// most `seconds`, on fresh connections with `channel`'s transport and hooks. Throws
/// std::runtime_error ("no server answered at ENDPOINT within 30 s") when none did; the hooks'
/// exceptions propagate.
void await_server(const std::string& endpoint, double seconds, const ChannelOptions& channel);

/// Asks the server at `endpoint` to stop (Shutdown request) on a fresh connection (a CurveZMQ
/// one with `curve`); true when it acknowledged within `timeout_seconds`. Never throws.
bool request_server_shutdown(const std::string& endpoint, double timeout_seconds,
                             const std::optional<CurveClientKeys>& curve = std::nullopt) noexcept;

}  // namespace robin
