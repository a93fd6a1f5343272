#pragma once
// The subdomain server's protocol state machine (proto/robin.proto), free of transport:
// a serialized request Envelope in, a serialized reply Envelope out. One body at a time.
//
// States and the requests they accept (Hello, SetupBody, EndRun and Shutdown in every state):
//   awaiting_setup       no body
//   awaiting_assignment  body assembled and factorized (SetupBody done); + AssignContact
//   ready                contact nodes assigned; + AssignContact, ContactSolveRequest,
//                        CorrectionRequest, NeumannSolveRequest, FieldsRequest
// SetLoadFactor (since 2.1) is accepted in awaiting_assignment and ready and keeps the state:
// it scales the body's loads and prescribed displacements (BAD_INPUT for a factor that is not
// finite or above 1e6 in magnitude), keeps the factor of K, B and F, and makes the next
// solves answer for the new loads.
// Transitions: SetupBody -> awaiting_assignment (the previous body is discarded first, so a
// failed SetupBody leaves awaiting_setup); AssignContact -> ready (a refused assignment keeps
// the state and the previous assignment); EndRun -> awaiting_setup; Shutdown -> unchanged, and
// shutdown_requested() becomes true. The body is factorized once per SetupBody, except that a
// SetupBody whose body has the stiffness of the previous one (same mesh, material, prescribed
// degrees of freedom, contact boundary; loads and prescribed values may differ), also after
// EndRun, keeps that factor (and, when AssignContact brings the same B, F): a sweep over loads
// or a repeated run skips the factorization. Contact solves warm-start from the previous
// converged solution of the same assignment.
//
// Runs (protocol 1.2 and later, Envelope.run_id): a successful SetupBody records its request's
// run_id with the body (any previous body is discarded whichever run it belonged to: a new run may
// always take over a server whose coordinator died). While the body is held, AssignContact,
// ContactSolveRequest, CorrectionRequest, NeumannSolveRequest, FieldsRequest and EndRun whose
// run_id is non-empty and differs from a non-empty recorded one are refused with WRONG_STATE
// ("... now belongs to another run ..."), the state unchanged: another coordinator set the body
// up, and this run must not be answered from it. An empty run_id (a 1.0 or 1.1 coordinator) is
// served as before. A server announcing a version below 1.2 (ServerSettings, testing) ignores
// run_id, as a 1.1 server would. Replies echo the request's run_id.
//
// Every reply echoes the request_id and carries this server's Version. Failures are Error
// replies, never exceptions:
//   MALFORMED_MESSAGE  not a parsable Envelope, no version, or no content
//   VERSION_MISMATCH   the request's major version differs from ours (both are named)
//   WRONG_STATE        the request is not accepted in the current state, or it names another
//                      run than the body's (run_id, see above)
//   INVALID_ARGUMENT   wrong sizes, a malformed constraint operator B (AssignContact),
//                      non-finite values, a write_directory outside the output root or where
//                      the fields cannot be written
//   BAD_INPUT          the body definition is unusable (robin::InputError while setting up)
//   SINGULAR_BODY      the Dirichlet conditions leave a rigid motion free (SingularBodyError)
//   UNSUPPORTED        a reply type sent as a request, a request unknown to this version, or
//                      a NeumannSolveRequest when "neumann_solve" is withheld (testing only)
//   SOLVER_FAILURE     a result with a non-finite value (never sent)
//   INTERNAL           any other exception ("internal error: ...")
// The state after the request is in Acknowledge.state, HelloReply.state and Error.state.
//
// Capabilities (HelloReply.capabilities): the core "contact_solve", "correction_solve",
// "fields", since protocol 1.1 the optional "neumann_solve" (NeumannSolveRequest:
// u_N = B K^{-1} (f - B' lambda) = e - F lambda for a given contact force lambda), and since 2.1
// "status": StatusRequest is answered from a progress record (request, stage, DOFs, times) that
// handle() keeps up to date, also through answer_status() from another thread while handle()
// works (server_loop.hpp runs handle() on a worker thread).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "numerics/body_solver.hpp"
#include "numerics/mprgp.hpp"
#include "numerics/setup_progress.hpp"
#include "protocol_version.hpp"

namespace spdlog {
class logger;
}

namespace robin {

namespace protocol {
class Envelope;
}

enum class ServerState { awaiting_setup, awaiting_assignment, ready };
/// "awaiting_setup", "awaiting_assignment", "ready".
std::string to_string(ServerState state);

struct ServerSettings {
  std::string name;  // optional label, appended to HelloReply.server_name and the logs
  /// The major version announced and accepted (tests set another one to provoke a mismatch).
  unsigned protocol_major = protocol::protocol_major;
  /// The minor version announced (tests set 0 to play a protocol 1.0 server). Below 2 the
  /// server also ignores Envelope.run_id, as a protocol 1.1 server would.
  unsigned protocol_minor = protocol::protocol_minor;
  /// Optional capabilities neither announced nor served (testing only: with "neumann_solve"
  /// the server answers NeumannSolveRequest with UNSUPPORTED, like a protocol 1.0 server).
  std::vector<std::string> withheld_capabilities;
  /// The directory under which SetupBody.mesh_path may name files (--data-directory); empty:
  /// every mesh_path is refused.
  std::filesystem::path data_directory;
  /// The largest mesh file a mesh_path may name, in bytes (--max-mesh-file-size; 0 = none),
  /// checked with stat before the file is read.
  std::uintmax_t maximum_mesh_file_bytes = 0;
  /// The executable that reads those files (robin-mesh-reader; robin-subdomain's is the one next
  /// to it): the server itself never runs Gmsh (mesh_file_reader.hpp).
  std::filesystem::path mesh_reader;
  /// The directory under which FieldsRequest.write_directory may write (--output-root); empty:
  /// every write_directory is refused.
  std::filesystem::path output_root;
  /// Resource limits of a body, checked before the work starts (0 = none): degrees of freedom
  /// (--max-dofs) and the memory of its Cholesky factor and dense interface operator
  /// (--max-factor-memory).
  long maximum_dofs = 0;
  double maximum_factor_bytes = 0.0;
  /// Testing only (robin-subdomain --testing-stage-delay correction[@ITERATION]=SECONDS): the
  /// server sleeps this long at the start of each CorrectionRequest (of iteration
  /// `correction_delay_iteration` only, when that is not 0), logging "correction request
  /// (iteration K): ..." first, so that a test can kill it inside a correction step. Set by
  /// the operator's command line only, never by a request.
  double correction_delay_seconds = 0.0;
  unsigned correction_delay_iteration = 0;
  /// Where requests are logged; null means subdomain_logger().
  std::shared_ptr<spdlog::logger> logger;
};

class SubdomainServer {
 public:
  explicit SubdomainServer(ServerSettings settings = {});
  ~SubdomainServer();
  SubdomainServer(const SubdomainServer&) = delete;
  SubdomainServer& operator=(const SubdomainServer&) = delete;

  /// Handles one request and returns the serialized reply Envelope. Never throws; logs the
  /// request (type, body, iteration, duration, outcome).
  std::string handle(std::string_view request_bytes) noexcept;
  /// The StatusReply to `request_bytes` when it is a StatusRequest of this server's major
  /// version (capability "status"), otherwise nullopt (the request goes to handle()).
  /// Thread-safe: answers from the progress record while handle() runs on another thread.
  std::optional<std::string> answer_status(std::string_view request_bytes) noexcept;
  /// The number of requests waiting behind the current one (reported in StatusReply).
  void set_queued_requests(unsigned count) noexcept;
  /// The MALFORMED_MESSAGE reply (request_id 0) to a message the transport could not pass to
  /// handle(), e.g. one of several frames; `reason` says why. Never throws; logs. Thread-safe
  /// like answer_status().
  /// `request_id`: echoed when the message's id is known (0 otherwise).
  std::string reject(std::string_view reason, std::uint64_t request_id = 0) noexcept;
  /// The request_id of a serialized Envelope, 0 when it does not parse. Thread-safe.
  static std::uint64_t request_id_of(std::string_view request_bytes) noexcept;
  /// `abandoned` (may be null; must outlive the server's use of it) is read at each stage
  /// boundary of a long request (the setup stages and the fields): once true, handle() stops
  /// the request there and answers INTERNAL "abandoned ...", the state as after a failure of
  /// that request (a SetupBody leaves awaiting_setup). The transport sets it when the
  /// request's client has disconnected, so that nobody waits for a reply that cannot arrive.
  void watch_abandonment(const std::atomic<bool>* abandoned) noexcept { abandoned_ = abandoned; }

  ServerState state() const { return state_; }
  /// True once a Shutdown request has been answered.
  bool shutdown_requested() const { return shutdown_requested_; }
  /// "robin-subdomain VERSION" plus " (name)" when a name is set.
  std::string server_name() const;

 private:
  struct RequestRecord;

  void dispatch(protocol::Envelope& request, protocol::Envelope& reply, RequestRecord& record);
  void check_version(const protocol::Envelope& request) const;
  void require_state(ServerState minimum, const std::string& request_type) const;
  /// Throws WRONG_STATE when `request` names another run than the body's (see above).
  void require_same_run(const protocol::Envelope& request, const std::string& request_type) const;
  void on_hello(protocol::Envelope& reply);
  void on_setup_body(protocol::Envelope& request, protocol::Envelope& reply, RequestRecord& record);
  void on_assign_contact(const protocol::Envelope& request, protocol::Envelope& reply);
  void on_contact_solve(const protocol::Envelope& request, protocol::Envelope& reply,
                        RequestRecord& record);
  void on_correction(const protocol::Envelope& request, protocol::Envelope& reply,
                     RequestRecord& record);
  void on_neumann_solve(const protocol::Envelope& request, protocol::Envelope& reply,
                        RequestRecord& record);
  /// Sleeps at the start of a CorrectionRequest of `iteration` as ServerSettings'
  /// correction_delay_* say (testing only; nothing when they are 0).
  void delay_for_testing(unsigned iteration) const;
  void on_fields(const protocol::Envelope& request, protocol::Envelope& reply);
  std::filesystem::path fields_directory(const std::string& requested) const;
  void on_set_load_factor(const protocol::Envelope& request, protocol::Envelope& reply,
                          RequestRecord& record);
  /// Whether the optional capability `name` is announced and served.
  bool offers(const std::string& name) const;
  void acknowledge(protocol::Envelope& reply) const;
  /// Sets our version on `reply`, logs `record` and serializes the reply.
  std::string finish(protocol::Envelope& reply, RequestRecord& record) noexcept;
  void log(const RequestRecord& record) const;

  /// What the server is doing, for StatusReply: written by the thread in handle(), read by
  /// answer_status() on the socket's thread.
  struct Progress {
    ServerState state = ServerState::awaiting_setup;
    std::string request_type, stage, body_name;
    std::chrono::steady_clock::time_point request_start, stage_start;
    bool busy = false;
    long dof_count = 0;
    unsigned queued_requests = 0;
  };
  void begin_request(const std::string& request_type);
  void begin_stage(SetupStage stage, long dof_count);
  void end_request() noexcept;
  void fill_status(protocol::Envelope& reply) const;

  ServerSettings settings_;
  mutable std::mutex progress_mutex_;
  Progress progress_;
  ServerState state_ = ServerState::awaiting_setup;
  bool shutdown_requested_ = false;
  std::unique_ptr<BodySolver> body_;
  /// The body of the last run after EndRun (state awaiting_setup): a SetupBody of a body with
  /// the same stiffness (BodySolver::has_same_stiffness) takes its factor instead of computing
  /// one; any other SetupBody frees it first.
  std::unique_ptr<BodySolver> retained_body_;
  std::string run_id_;  // run_id of the SetupBody that set up body_; "" without body or run_id
  std::vector<int> interface_nodes_;  // the contact boundary's node ids, ascending
  MprgpParameters qp_parameters_;
  const std::atomic<bool>* abandoned_ = nullptr;  // see watch_abandonment()
};

}  // namespace robin
