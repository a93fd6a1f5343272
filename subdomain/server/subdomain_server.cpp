#include "server/subdomain_server.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <new>
#include <thread>

#include "numerics/body_output.hpp"
#include "numerics/errors.hpp"
#include "numerics/heap_memory.hpp"
#include "robin.pb.h"
#include "server/file_access.hpp"
#include "server/reply_encoding.hpp"
#include "server/request_error.hpp"
#include "server/resident_memory.hpp"
#include "server/server_logging.hpp"
#include "server/setup_decoding.hpp"

#ifndef ROBIN_VERSION
#define ROBIN_VERSION "unknown"
#endif

namespace robin {

/// What the log line of a request says.
struct SubdomainServer::RequestRecord {
  std::string type = "(unparsed message)";
  std::string body;       // the body's name when known
  std::string iteration;  // " iteration N" for solves
  std::string outcome = "ok";
  bool failed = false;
  double seconds = 0.0;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* neumann_solve_capability = "neumann_solve";  // protocol 1.1
constexpr const char* status_capability = "status";                // protocol 2.1
/// A StatusRequest Envelope is a few dozen bytes; larger messages are not parsed twice.
constexpr std::size_t largest_status_request = 256;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Appends StageTime {stage, seconds} to a reply's stage_times (protocol 2.2).
template <typename StageTimes>
void add_stage_time(StageTimes& stage_times, SetupStage stage, double seconds) {
  protocol::StageTime& entry = *stage_times.Add();
  entry.set_stage(to_string(stage));
  entry.set_seconds(seconds);
}

std::string version_text(unsigned major, unsigned minor) {
  return std::to_string(major) + "." + std::to_string(minor);
}

/// The request's message type name, e.g. "ContactSolveRequest".
std::string content_type_name(const protocol::Envelope& request) {
  const auto* field = request.GetDescriptor()->FindFieldByNumber(request.content_case());
  return field == nullptr ? "(no content)" : field->message_type()->name();
}

bool is_request(protocol::Envelope::ContentCase content) {
  using Envelope = protocol::Envelope;
  switch (content) {
    case Envelope::kHello:
    case Envelope::kSetupBody:
    case Envelope::kAssignContact:
    case Envelope::kContactSolve:
    case Envelope::kCorrection:
    case Envelope::kNeumannSolve:
    case Envelope::kFields:
    case Envelope::kEndRun:
    case Envelope::kShutdown:
    case Envelope::kSetLoadFactor:
    case Envelope::kStatusRequest:
      return true;
    default:
      return false;
  }
}

/// max_i |v_i|, 0 for an empty vector.
double largest_magnitude(const Eigen::VectorXd& vector) {
  return vector.size() == 0 ? 0.0 : vector.cwiseAbs().maxCoeff();
}

/// Checks a per-contact-node vector of the request: its length and finiteness.
Eigen::VectorXd checked_vector(const google::protobuf::RepeatedField<double>& values,
                               int contact_size, const std::string& field,
                               const std::string& body_name) {
  if (values.size() != contact_size) {
    throw RequestError(protocol::INVALID_ARGUMENT,
                       field + " has " + std::to_string(values.size()) + " values for the " +
                           std::to_string(contact_size) + " contact constraints of body '" +
                           body_name + "' (the rows of AssignContact)");
  }
  for (int i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw RequestError(
          protocol::INVALID_ARGUMENT,
          field + "[" + std::to_string(i) + "] of body '" + body_name + "' is not a finite number");
    }
  }
  return to_vector(values);
}

/// The constraint operator B of an AssignContact request, its sizes checked against the message
/// before anything is allocated; its entries are checked by BodySolver::assign_contact.
ContactOperator decoded_operator(const protocol::AssignContact& message,
                                 const std::string& body_name) {
  const auto invalid = [&](const std::string& problem) {
    return RequestError(protocol::INVALID_ARGUMENT,
                        "AssignContact for body '" + body_name + "': " + problem);
  };
  const int entries = message.values_size();
  if (message.node_ids_size() != entries || message.components_size() != entries) {
    throw invalid(std::to_string(message.node_ids_size()) + " node_ids, " +
                  std::to_string(message.components_size()) + " components and " +
                  std::to_string(entries) + " values: expected one of each per entry");
  }
  if (message.row_offsets_size() < 2 || message.weights_size() != message.row_offsets_size() - 1) {
    throw invalid(std::to_string(message.row_offsets_size()) + " row_offsets and " +
                  std::to_string(message.weights_size()) +
                  " weights: expected constraints + 1 offsets and one weight per constraint");
  }
  ContactOperator contact;
  contact.row_offsets.assign(message.row_offsets().begin(), message.row_offsets().end());
  contact.weights.assign(message.weights().begin(), message.weights().end());
  contact.values.assign(message.values().begin(), message.values().end());
  contact.components.reserve(static_cast<std::size_t>(entries));
  contact.nodes.reserve(static_cast<std::size_t>(entries));
  for (int k = 0; k < entries; ++k) {
    const std::int64_t node = message.node_ids(k);
    // Out-of-range ids become -1, which check_contact_operator refuses as unknown nodes.
    contact.nodes.push_back(
        node >= 0 && node <= std::numeric_limits<int>::max() ? static_cast<int>(node) : -1);
    contact.components.push_back(
        static_cast<int>(std::min<std::uint32_t>(message.components(k), 1000)));
  }
  return contact;
}

/// Refuses a result with a NaN or an infinity: SOLVER_FAILURE naming the body and the request.
void require_finite(const Eigen::Ref<const Eigen::VectorXd>& values, const std::string& what,
                    const std::string& body_name) {
  if (values.allFinite()) return;
  throw RequestError(protocol::SOLVER_FAILURE,
                     what + " of body '" + body_name +
                         "' has a value that is not a finite number (the data overflow the "
                         "solver: check the magnitudes of loads, obstacles and forces)");
}

/// Writes <directory>/<body>.vtu (creating the directory); returns the path written. An
/// unusable directory is an INVALID_ARGUMENT.
std::string write_fields_file(const std::filesystem::path& directory, const BodyOutput& output) {
  try {
    return (directory / write_body_output(directory, output)).string();
  } catch (const std::exception& error) {
    throw RequestError(protocol::INVALID_ARGUMENT,
                       "FieldsRequest.write_directory: cannot write the fields of body '" +
                           output.body_name + "' to '" + directory.string() + "': " + error.what());
  }
}

/// Refuses fields with a NaN or an infinity (SOLVER_FAILURE naming the field and the body).
void require_finite_fields(const BodyOutput& output, const std::string& body_name) {
  for (const auto* fields : {&output.point_fields, &output.cell_fields}) {
    const FieldLocation location =
        fields == &output.point_fields ? FieldLocation::point : FieldLocation::cell;
    for (const OutputField& field : *fields) {
      require_finite(Eigen::Map<const Eigen::VectorXd>(
                         field.values.data(), static_cast<Eigen::Index>(field.values.size())),
                     "FieldsReply " + std::string(field_location_name(location)) + " field '" +
                         field.name + "'",
                     body_name);
    }
  }
}

/// Writes <directory>/<body>.vtu one field at a time (write_body_fields), a field with a NaN or
/// an infinity refused as require_finite_fields refuses it; returns the output without mesh and
/// fields, written_file the path written. An unusable directory is an INVALID_ARGUMENT.
BodyOutput write_streamed_fields_file(const std::filesystem::path& directory,
                                      const BodySolver& body,
                                      const Eigen::VectorXd& contact_force) {
  const FieldCheck check = [&body](FieldLocation location, const std::string& name,
                                   const std::vector<double>& values) {
    require_finite(
        Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size())),
        "FieldsReply " + std::string(field_location_name(location)) + " field '" + name + "'",
        body.name());
  };
  try {
    BodyOutput output = write_body_fields(directory, body, contact_force, check);
    output.written_file = (directory / output.written_file).string();
    return output;
  } catch (const RequestError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& error) {
    throw RequestError(protocol::INVALID_ARGUMENT,
                       "FieldsRequest.write_directory: cannot write the fields of body '" +
                           body.name() + "' to '" + directory.string() + "': " + error.what());
  }
}

/// The INTERNAL message of a request that could not allocate its memory (std::bad_alloc; the
/// request's memory is freed by then).
std::string out_of_memory_message(const std::string& request_type, const std::string& body) {
  const std::string prefix =
      body.empty() || body.size() > maximum_body_name_length ? "" : "body '" + body + "': ";
  return prefix + "the server ran out of memory (std::bad_alloc) while handling " + request_type +
         ": the request was abandoned and its memory freed; the server goes on. Its operator "
         "can refuse such bodies before the work starts with lower --max-dofs or "
         "--max-factor-memory limits, or give the server more memory";
}

void set_error(protocol::Envelope& reply, protocol::ErrorCode code, const std::string& message,
               ServerState state) {
  protocol::Error& error = *reply.mutable_error();
  error.set_code(code);
  error.set_message(message);
  error.set_state(to_string(state));
}

}  // namespace

std::string to_string(ServerState state) {
  switch (state) {
    case ServerState::awaiting_setup:
      return "awaiting_setup";
    case ServerState::awaiting_assignment:
      return "awaiting_assignment";
    case ServerState::ready:
      return "ready";
  }
  return "unknown";
}

SubdomainServer::SubdomainServer(ServerSettings settings) : settings_(std::move(settings)) {
  if (!settings_.logger) settings_.logger = subdomain_logger();
}

SubdomainServer::~SubdomainServer() = default;

std::string SubdomainServer::server_name() const {
  std::string name = std::string("robin-subdomain ") + ROBIN_VERSION;
  if (!settings_.name.empty()) name += " (" + settings_.name + ")";
  return name;
}

std::string SubdomainServer::handle(std::string_view request_bytes) noexcept {
  RequestRecord record;
  const auto start = record.start;
  protocol::Envelope reply;
  try {
    protocol::Envelope request;
    if (request_bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
        !request.ParseFromArray(request_bytes.data(), static_cast<int>(request_bytes.size()))) {
      throw RequestError(protocol::MALFORMED_MESSAGE,
                         "the message (" + std::to_string(request_bytes.size()) +
                             " bytes) is not a serialized robin.protocol.Envelope");
    }
    reply.set_request_id(request.request_id());
    reply.set_run_id(request.run_id());
    record.type = content_type_name(request);
    if (body_) record.body = body_->name();
    check_version(request);
    begin_request(record.type);
    dispatch(request, reply, record);
  } catch (const RequestError& error) {
    set_error(reply, error.code(), error.what(), state_);
  } catch (const SingularBodyError& error) {
    set_error(reply, protocol::SINGULAR_BODY, error.what(), state_);
  } catch (const InputError& error) {
    set_error(reply, protocol::BAD_INPUT, error.what(), state_);
  } catch (const std::bad_alloc&) {
    set_error(reply, protocol::INTERNAL, out_of_memory_message(record.type, record.body), state_);
  } catch (const std::exception& error) {
    set_error(reply, protocol::INTERNAL, std::string("internal error: ") + error.what(), state_);
  } catch (...) {
    set_error(reply, protocol::INTERNAL, "internal error: unknown exception", state_);
  }
  end_request();
  record.seconds = seconds_since(start);
  return finish(reply, record);
}

std::optional<std::string> SubdomainServer::answer_status(std::string_view request_bytes) noexcept {
  if (!offers(status_capability) || request_bytes.size() > largest_status_request) {
    return std::nullopt;
  }
  try {
    protocol::Envelope request;
    if (!request.ParseFromArray(request_bytes.data(), static_cast<int>(request_bytes.size())) ||
        request.content_case() != protocol::Envelope::kStatusRequest ||
        request.version().major() != settings_.protocol_major) {
      return std::nullopt;
    }
    protocol::Envelope reply;
    reply.set_request_id(request.request_id());
    fill_status(reply);
    reply.mutable_version()->set_major(settings_.protocol_major);
    reply.mutable_version()->set_minor(settings_.protocol_minor);
    return reply.SerializeAsString();
  } catch (...) {
    return std::nullopt;
  }
}

void SubdomainServer::set_queued_requests(unsigned count) noexcept {
  const std::lock_guard lock(progress_mutex_);
  progress_.queued_requests = count;
}

void SubdomainServer::begin_request(const std::string& request_type) {
  const std::lock_guard lock(progress_mutex_);
  progress_.busy = true;
  progress_.request_type = request_type;
  progress_.stage.clear();
  progress_.request_start = progress_.stage_start = Clock::now();
}

void SubdomainServer::begin_stage(SetupStage stage, long dof_count) {
  if (abandoned_ != nullptr && abandoned_->load()) {
    throw RequestError(protocol::INTERNAL, "abandoned before the stage '" + to_string(stage) +
                                               "': the client that sent the request disconnected");
  }
  const std::lock_guard lock(progress_mutex_);
  progress_.stage = to_string(stage);
  progress_.stage_start = Clock::now();
  if (dof_count > 0) progress_.dof_count = dof_count;
}

void SubdomainServer::end_request() noexcept {
  const std::lock_guard lock(progress_mutex_);
  progress_.busy = false;
  progress_.request_type.clear();
  progress_.stage.clear();
  progress_.state = state_;
  progress_.body_name = body_ ? body_->name() : std::string();
  progress_.dof_count = body_ ? static_cast<long>(body_->mesh().dof_count()) : 0;
}

void SubdomainServer::fill_status(protocol::Envelope& reply) const {
  protocol::StatusReply& status = *reply.mutable_status_reply();
  const std::lock_guard lock(progress_mutex_);
  const auto now = Clock::now();
  status.set_state(to_string(progress_.state));
  status.set_busy(progress_.busy);
  status.set_request_type(progress_.request_type);
  status.set_stage(progress_.stage);
  status.set_request_seconds(
      progress_.busy ? std::chrono::duration<double>(now - progress_.request_start).count() : 0.0);
  status.set_stage_seconds(
      progress_.busy ? std::chrono::duration<double>(now - progress_.stage_start).count() : 0.0);
  status.set_dof_count(static_cast<std::uint64_t>(progress_.dof_count));
  status.set_body_name(progress_.body_name);
  status.set_queued_requests(progress_.queued_requests);
}

std::uint64_t SubdomainServer::request_id_of(std::string_view request_bytes) noexcept {
  try {
    protocol::Envelope request;
    if (request_bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
        !request.ParseFromArray(request_bytes.data(), static_cast<int>(request_bytes.size()))) {
      return 0;
    }
    return request.request_id();
  } catch (...) {
    return 0;
  }
}

std::string SubdomainServer::reject(std::string_view reason, std::uint64_t request_id) noexcept {
  RequestRecord record;
  protocol::Envelope reply;
  try {
    reply.set_request_id(request_id);
    ServerState state = ServerState::awaiting_setup;
    {
      // the state as of the last finished request: reject() may run while handle() works
      const std::lock_guard lock(progress_mutex_);
      state = progress_.state;
    }
    set_error(reply, protocol::MALFORMED_MESSAGE, std::string(reason), state);
  } catch (...) {
    return {};
  }
  return finish(reply, record);
}

std::string SubdomainServer::finish(protocol::Envelope& reply, RequestRecord& record) noexcept {
  try {
    if (reply.has_error()) {
      record.failed = true;
      record.outcome =
          protocol::ErrorCode_Name(reply.error().code()) + ": " + reply.error().message();
    }
    reply.mutable_version()->set_major(settings_.protocol_major);
    reply.mutable_version()->set_minor(settings_.protocol_minor);
    log(record);
    return reply.SerializeAsString();
  } catch (...) {
    return {};  // out of memory while replying: the client receives an empty message
  }
}

void SubdomainServer::check_version(const protocol::Envelope& request) const {
  if (!request.has_version()) {
    throw RequestError(protocol::MALFORMED_MESSAGE,
                       "the Envelope carries no version: every message must carry the sender's "
                       "protocol Version");
  }
  const unsigned major = request.version().major();
  if (major != settings_.protocol_major) {
    throw RequestError(protocol::VERSION_MISMATCH,
                       "protocol version mismatch: the request speaks " +
                           version_text(major, request.version().minor()) + ", this server " +
                           version_text(settings_.protocol_major, settings_.protocol_minor) +
                           " (the major versions must be equal); use a matching coordinator "
                           "or server");
  }
}

void SubdomainServer::dispatch(protocol::Envelope& request, protocol::Envelope& reply,
                               RequestRecord& record) {
  using Envelope = protocol::Envelope;
  switch (request.content_case()) {
    case Envelope::kHello:
      return on_hello(reply);
    case Envelope::kSetupBody:
      return on_setup_body(request, reply, record);
    case Envelope::kAssignContact:
      return on_assign_contact(request, reply);
    case Envelope::kContactSolve:
      return on_contact_solve(request, reply, record);
    case Envelope::kCorrection:
      return on_correction(request, reply, record);
    case Envelope::kNeumannSolve:
      return on_neumann_solve(request, reply, record);
    case Envelope::kFields:
      return on_fields(request, reply);
    case Envelope::kSetLoadFactor:
      return on_set_load_factor(request, reply, record);
    case Envelope::kStatusRequest:
      if (!offers(status_capability)) break;
      return fill_status(reply);
    case Envelope::kEndRun:
      require_same_run(request, "EndRun");
      retained_body_ = std::move(body_);  // its factor may serve a later run of the same body
      run_id_.clear();
      interface_nodes_.clear();
      state_ = ServerState::awaiting_setup;
      return acknowledge(reply);
    case Envelope::kShutdown:
      shutdown_requested_ = true;
      return acknowledge(reply);
    case Envelope::CONTENT_NOT_SET:
      break;
    default:
      if (!is_request(request.content_case())) {
        throw RequestError(protocol::UNSUPPORTED,
                           content_type_name(request) + " is a reply, not a request");
      }
  }
  if (!request.GetReflection()->GetUnknownFields(request).empty()) {
    throw RequestError(protocol::UNSUPPORTED,
                       "the request type is unknown to this server (protocol " +
                           version_text(settings_.protocol_major, settings_.protocol_minor) +
                           "); check HelloReply.capabilities");
  }
  throw RequestError(protocol::MALFORMED_MESSAGE, "the Envelope carries no request (no content)");
}

void SubdomainServer::require_state(ServerState minimum, const std::string& request_type) const {
  if (state_ == ServerState::awaiting_setup && minimum != ServerState::awaiting_setup) {
    throw RequestError(protocol::WRONG_STATE,
                       request_type + " before SetupBody: send SetupBody first");
  }
  if (state_ == ServerState::awaiting_assignment && minimum == ServerState::ready) {
    throw RequestError(protocol::WRONG_STATE, request_type +
                                                  " before AssignContact: send "
                                                  "AssignContact for body '" +
                                                  body_->name() + "' first");
  }
}

void SubdomainServer::require_same_run(const protocol::Envelope& request,
                                       const std::string& request_type) const {
  const bool before_run_ids = settings_.protocol_major < 2 && settings_.protocol_minor < 2;
  if (before_run_ids || !body_ || run_id_.empty() || request.run_id().empty() ||
      request.run_id() == run_id_) {
    return;
  }
  throw RequestError(protocol::WRONG_STATE,
                     request_type + " of run '" + request.run_id() + "': this server's body '" +
                         body_->name() + "' now belongs to another run (run_id '" + run_id_ +
                         "'): another coordinator set it up; this run's state is lost");
}

void SubdomainServer::on_hello(protocol::Envelope& reply) {
  protocol::HelloReply& hello = *reply.mutable_hello_reply();
  hello.set_server_name(server_name());
  for (const char* capability : {"contact_solve", "correction_solve", "fields"}) {
    hello.add_capabilities(capability);
  }
  if (offers(neumann_solve_capability)) hello.add_capabilities(neumann_solve_capability);
  if (offers(status_capability)) hello.add_capabilities(status_capability);
  hello.set_state(to_string(state_));
}

void SubdomainServer::on_setup_body(protocol::Envelope& request, protocol::Envelope& reply,
                                    RequestRecord& record) {
  // A SetupBody starts a new run, whatever its outcome (and whose the body was); the previous
  // body's factor serves it when the stiffness is the same, and is freed before a new one is
  // computed otherwise.
  std::unique_ptr<BodySolver> previous = body_ ? std::move(body_) : std::move(retained_body_);
  body_.reset();
  retained_body_.reset();
  run_id_.clear();
  interface_nodes_.clear();
  state_ = ServerState::awaiting_setup;
  record.body = request.setup_body().body_name();
  {
    const std::lock_guard lock(progress_mutex_);
    progress_.body_name = printable_for_log(record.body);
    progress_.dof_count = 0;
  }
  begin_stage(SetupStage::mesh, 0);
  const auto mesh_start = Clock::now();
  DecodedSetup setup = decode_setup_body(
      request.setup_body(),
      {settings_.data_directory, settings_.maximum_mesh_file_bytes, settings_.mesh_reader});
  const double mesh_seconds = seconds_since(mesh_start);
  // The body holds its own copy of the mesh: the request's is freed before the assembly.
  request.mutable_setup_body()->clear_mesh();
  setup.body.maximum_dofs = settings_.maximum_dofs;
  setup.body.maximum_factor_bytes = settings_.maximum_factor_bytes;
  const long dof_count = static_cast<long>(setup.definition.mesh.dof_count());
  setup.body.observer = [this, dof_count](SetupStage stage) { begin_stage(stage, dof_count); };
  const bool reuse = previous && previous->has_same_stiffness(setup.definition, setup.body);
  std::unique_ptr<BodySolver> body;
  if (reuse) {
    previous->replace_loads(std::move(setup.definition), setup.body);
    body = std::move(previous);
  } else {
    previous.reset();
    body = std::make_unique<BodySolver>(std::move(setup.definition), setup.body);
  }
  const InterfaceDescription interface = body->contact_boundary();
  protocol::InterfaceDescription& description = *reply.mutable_interface();
  encode_interface(body->name(), interface, description);
  description.set_dof_count(static_cast<std::uint64_t>(body->free_dof_count()));
  const BodyTimings& timings = body->timings();
  description.set_setup_seconds(timings.setup_seconds());
  if (settings_.protocol_minor >= 2) {
    auto& stage_times = *description.mutable_stage_times();
    add_stage_time(stage_times, SetupStage::mesh, mesh_seconds);
    add_stage_time(stage_times, SetupStage::assembly, timings.assembly_seconds);
    add_stage_time(stage_times, SetupStage::ordering, timings.ordering_seconds);
    add_stage_time(stage_times, SetupStage::factorization, timings.factorization_seconds);
    description.set_request_seconds(seconds_since(record.start));
  }
  if (settings_.protocol_minor >= 5) description.set_peak_resident_bytes(peak_resident_bytes());
  interface_nodes_ = interface.node_ids;
  qp_parameters_ = setup.qp;
  body_ = std::move(body);
  run_id_ = request.run_id();
  state_ = ServerState::awaiting_assignment;
  record.outcome = "ok, " + std::to_string(body_->mesh().node_count()) + " nodes, " +
                   std::to_string(body_->free_dof_count()) + " free dofs, " +
                   std::to_string(interface_nodes_.size()) + " contact boundary nodes";
  if (body_->linear_solver() == LinearSolverKind::multigrid) {
    record.outcome += ", multigrid solver";
  }
  if (reuse) record.outcome += ", factorization of the previous run reused";
  if (const std::uint64_t peak = peak_resident_bytes(); peak > 0) {
    record.outcome +=
        fmt::format(", peak resident {:.0f} MiB", static_cast<double>(peak) / 1048576.0);
  }
  if (!run_id_.empty()) record.outcome += ", run " + run_id_;
}

void SubdomainServer::on_assign_contact(const protocol::Envelope& request,
                                        protocol::Envelope& reply) {
  require_same_run(request, "AssignContact");
  require_state(ServerState::awaiting_assignment, "AssignContact");
  const ContactOperator contact = decoded_operator(request.assign_contact(), body_->name());
  try {
    // Checked before anything changes: a refused assignment keeps the state and the previous B.
    check_contact_operator(contact, interface_nodes_, body_->mesh().dimension,
                           "body '" + body_->name() + "'");
  } catch (const InputError& error) {
    throw RequestError(protocol::INVALID_ARGUMENT, error.what());
  }
  state_ = ServerState::awaiting_assignment;  // until the body accepted the assignment
  const LinearSolverKind solver = body_->linear_solver();
  body_->assign_contact(contact);
  state_ = ServerState::ready;
  if (solver != body_->linear_solver()) {
    settings_.logger->warn(
        "body '{}': its {} contact rows are linearly dependent (the mortar side of a finer "
        "non-mortar side), which the multigrid solver's primal contact solve cannot project on: "
        "K factorized, the body continues with the direct solver",
        printable_for_log(body_->name(), 80), body_->contact_size());
  }
  acknowledge(reply);
  if (settings_.protocol_minor >= 2) {
    add_stage_time(*reply.mutable_acknowledge()->mutable_stage_times(),
                   SetupStage::interface_operator, body_->timings().interface_seconds);
  }
  if (settings_.protocol_minor >= 5) {
    reply.mutable_acknowledge()->set_peak_resident_bytes(peak_resident_bytes());
  }
}

void SubdomainServer::on_contact_solve(const protocol::Envelope& request, protocol::Envelope& reply,
                                       RequestRecord& record) {
  const protocol::ContactSolveRequest& message = request.contact_solve();
  record.iteration = " iteration " + std::to_string(message.iteration());
  require_same_run(request, "ContactSolveRequest");
  require_state(ServerState::ready, "ContactSolveRequest");
  const Eigen::VectorXd obstacle = checked_vector(message.obstacle(), body_->contact_size(),
                                                  "ContactSolveRequest.obstacle", body_->name());
  const ContactSolveResult result = body_->solve_contact(obstacle, qp_parameters_);
  require_finite(result.normal_trace, "ContactSolveResult.normal_trace", body_->name());
  require_finite(result.contact_force, "ContactSolveResult.contact_force", body_->name());
  encode_contact_result(result, *reply.mutable_contact_result());
  record.outcome =
      protocol::SolveStatus_Name(to_protocol(result.status)) + ", " +
      std::to_string(result.iterations) +
      (body_->linear_solver() == LinearSolverKind::multigrid
           ? " active set steps, " + std::to_string(result.operator_applications) + " CG iterations"
           : " QP iterations");
  if (!result.message.empty()) record.outcome += " (" + result.message + ")";
}

void SubdomainServer::on_correction(const protocol::Envelope& request, protocol::Envelope& reply,
                                    RequestRecord& record) {
  const auto start = Clock::now();
  const protocol::CorrectionRequest& message = request.correction();
  record.iteration = " iteration " + std::to_string(message.iteration());
  require_same_run(request, "CorrectionRequest");
  require_state(ServerState::ready, "CorrectionRequest");
  delay_for_testing(message.iteration());
  const Eigen::VectorXd interface_force =
      checked_vector(message.interface_force(), body_->contact_size(),
                     "CorrectionRequest.interface_force", body_->name());
  const double relative_accuracy = message.relative_accuracy();
  if (!(relative_accuracy >= 0.0 && relative_accuracy < 1.0)) {
    throw RequestError(protocol::INVALID_ARGUMENT,
                       "CorrectionRequest.relative_accuracy of body '" + body_->name() + "' is " +
                           std::to_string(relative_accuracy) + ", outside [0, 1)");
  }
  // w_N = B K^-1 B' r
  const long iterations_before = body_->inner_iterations();
  const Eigen::VectorXd trace = body_->solve_correction(interface_force, relative_accuracy);
  if (body_->linear_solver() == LinearSolverKind::multigrid) {
    record.outcome +=
        ", " + std::to_string(body_->inner_iterations() - iterations_before) + " CG iterations";
  }
  require_finite(trace, "CorrectionResult.normal_trace", body_->name());
  protocol::CorrectionResult& result = *reply.mutable_correction_result();
  result.mutable_normal_trace()->Assign(trace.begin(), trace.end());
  result.set_compute_seconds(seconds_since(start));
}

void SubdomainServer::delay_for_testing(unsigned iteration) const {
  const double seconds = settings_.correction_delay_seconds;
  if (seconds <= 0.0) return;
  if (settings_.correction_delay_iteration != 0 &&
      settings_.correction_delay_iteration != iteration) {
    return;
  }
  settings_.logger->info(
      "correction request (iteration {}): waiting {} s before the solve (--testing-stage-delay, "
      "testing only)",
      iteration, seconds);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

/// Since protocol 1.1: K u = f - B' lambda with the given lambda, u_N = B u = e - F lambda.
void SubdomainServer::on_neumann_solve(const protocol::Envelope& request, protocol::Envelope& reply,
                                       RequestRecord& record) {
  const auto start = Clock::now();
  const protocol::NeumannSolveRequest& message = request.neumann_solve();
  record.iteration = " iteration " + std::to_string(message.iteration());
  if (!offers(neumann_solve_capability)) {
    throw RequestError(protocol::UNSUPPORTED,
                       "NeumannSolveRequest is not served: this server withholds the capability "
                       "'neumann_solve' (started with --without-capability neumann_solve)");
  }
  require_same_run(request, "NeumannSolveRequest");
  require_state(ServerState::ready, "NeumannSolveRequest");
  const Eigen::VectorXd contact_force =
      checked_vector(message.contact_force(), body_->contact_size(),
                     "NeumannSolveRequest.contact_force", body_->name());
  const Eigen::VectorXd trace = body_->solve_neumann(contact_force);  // u_N = e - F lambda
  require_finite(trace, "NeumannSolveResult.normal_trace", body_->name());
  protocol::NeumannSolveResult& result = *reply.mutable_neumann_result();
  result.mutable_normal_trace()->Assign(trace.begin(), trace.end());
  result.set_compute_seconds(seconds_since(start));
  record.outcome = fmt::format("ok, max |lambda| {:.3e}, max |u_N| {:.3e}",
                               largest_magnitude(contact_force), largest_magnitude(trace));
}

void SubdomainServer::on_fields(const protocol::Envelope& request, protocol::Envelope& reply) {
  const protocol::FieldsRequest& message = request.fields();
  require_same_run(request, "FieldsRequest");
  require_state(ServerState::ready, "FieldsRequest");
  // Since 2.5: a reply without mesh and fields, for a file the server writes itself.
  const bool omit_fields = settings_.protocol_minor >= 5 && message.omit_fields_from_reply();
  if (omit_fields && message.write_directory().empty()) {
    throw RequestError(protocol::INVALID_ARGUMENT,
                       "body '" + body_->name() +
                           "': FieldsRequest.omit_fields_from_reply is set without "
                           "write_directory: the fields would go nowhere");
  }
  begin_stage(SetupStage::fields, 0);
  const auto start = Clock::now();
  const Eigen::VectorXd contact_force = checked_vector(
      message.contact_force(), body_->contact_size(), "FieldsRequest.contact_force", body_->name());
  const std::filesystem::path directory = fields_directory(message.write_directory());
  protocol::FieldsReply& fields = *reply.mutable_fields_reply();
  release_free_heap_memory();
  if (omit_fields) {  // the file made field by field, from the body's own mesh
    const BodyOutput output = write_streamed_fields_file(directory, *body_, contact_force);
    fields.set_written_file(output.written_file);
    encode_resultants(output, fields);
  } else {
    const BodyOutput output = make_body_output(*body_, contact_force);
    require_finite_fields(output, body_->name());
    // the file first: its buffers are freed before the reply's copy of the fields is made
    if (!directory.empty()) fields.set_written_file(write_fields_file(directory, output));
    encode_fields(output, fields);
  }  // the fields are freed before the reply is serialized
  if (settings_.protocol_minor >= 2) {
    add_stage_time(*fields.mutable_stage_times(), SetupStage::fields, seconds_since(start));
  }
  if (settings_.protocol_minor >= 5) fields.set_peak_resident_bytes(peak_resident_bytes());
}

/// The directory of FieldsRequest.write_directory under the output root (created); empty when
/// none was asked for. A refused directory is an INVALID_ARGUMENT naming the body.
std::filesystem::path SubdomainServer::fields_directory(const std::string& requested) const {
  if (requested.empty()) return {};
  try {
    return resolve_output_directory(settings_.output_root, requested,
                                    "FieldsRequest.write_directory");
  } catch (const InputError& error) {
    throw RequestError(protocol::INVALID_ARGUMENT, "body '" + body_->name() + "': " + error.what());
  }
}

/// Since protocol 2.1: scales the body's loads and prescribed displacements (BodySolver::
/// set_load_factor); the factor of K, B and F are kept, the state does not change.
void SubdomainServer::on_set_load_factor(const protocol::Envelope& request,
                                         protocol::Envelope& reply, RequestRecord& record) {
  const auto start = Clock::now();
  if (settings_.protocol_minor < 1) {  // playing a protocol 2.0 server (testing)
    throw RequestError(protocol::UNSUPPORTED,
                       "SetLoadFactor is a request of protocol 2.1; this server speaks " +
                           version_text(settings_.protocol_major, settings_.protocol_minor));
  }
  require_same_run(request, "SetLoadFactor");
  require_state(ServerState::awaiting_assignment, "SetLoadFactor");
  const double factor = request.set_load_factor().factor();
  record.iteration = fmt::format(" factor {}", factor);
  if (!std::isfinite(factor) || std::abs(factor) > BodySolver::maximum_load_factor) {
    throw RequestError(protocol::BAD_INPUT,
                       fmt::format("SetLoadFactor.factor = {} for body '{}' is not a finite "
                                   "number of magnitude at most {:g}",
                                   factor, body_->name(), BodySolver::maximum_load_factor));
  }
  body_->set_load_factor(factor);
  protocol::LoadFactorSet& result = *reply.mutable_load_factor_set();
  result.set_factor(body_->load_factor());
  result.set_state(to_string(state_));
  result.set_compute_seconds(seconds_since(start));
}

bool SubdomainServer::offers(const std::string& name) const {
  // a server playing protocol 2.0 (testing) has no StatusRequest, as a 2.0 server would not
  if (name == status_capability && settings_.protocol_minor < 1) return false;
  const auto& withheld = settings_.withheld_capabilities;
  return std::find(withheld.begin(), withheld.end(), name) == withheld.end();
}

void SubdomainServer::acknowledge(protocol::Envelope& reply) const {
  reply.mutable_acknowledge()->set_state(to_string(state_));
}

void SubdomainServer::log(const RequestRecord& record) const {
  const std::string body =
      record.body.empty() ? "" : " body '" + printable_for_log(record.body, 80) + "'";
  settings_.logger->log(record.failed ? spdlog::level::warn : spdlog::level::info,
                        "{}{}{}: {} ({:.3f} ms)", record.type, body, record.iteration,
                        printable_for_log(record.outcome), 1e3 * record.seconds);
}

}  // namespace robin
