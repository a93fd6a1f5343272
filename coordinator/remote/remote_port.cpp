#include "remote/remote_port.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <sstream>

#include "coupling/case_file_body.hpp"
#include "protocol_version.hpp"
#include "remote/reply_decoding.hpp"
#include "remote/setup_encoding.hpp"
#include "robin.pb.h"

namespace robin {

namespace {

using protocol::Envelope;

const std::vector<std::string> required_capabilities{"contact_solve", "correction_solve", "fields"};
constexpr const char* neumann_solve_capability = "neumann_solve";  // optional, protocol 1.1

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string content_name(int content_case) {
  const auto* field = Envelope::descriptor()->FindFieldByNumber(content_case);
  return field != nullptr ? field->name() : "no content";
}

std::string version_text(unsigned major, unsigned minor) {
  return std::to_string(major) + "." + std::to_string(minor);
}

template <typename Names>
std::string join_names(const Names& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text.empty() ? "nothing" : text;
}

/// Adds the reply's StageTime entries (protocol 2.2) to `stages`; unknown stage names and
/// times that are not finite and non-negative are left out.
template <typename StageTimes>
void record_stage_times(const StageTimes& stage_times, std::map<SetupStage, double>& stages) {
  for (const protocol::StageTime& entry : stage_times) {
    const std::optional<SetupStage> stage = setup_stage_named(entry.stage());
    if (stage && std::isfinite(entry.seconds()) && entry.seconds() >= 0.0) {
      stages[*stage] = entry.seconds();
    }
  }
}

/// A reply's peak_resident_bytes (protocol 2.5) into the profile; 0 (not reported) keeps the
/// value of an earlier reply.
void record_peak_resident(std::uint64_t bytes, BodyProfile& profile) {
  if (bytes > 0) profile.peak_resident_bytes = bytes;
}

template <typename Values>
void append(const Eigen::VectorXd& vector, Values& values) {
  values.Add(vector.data(), vector.data() + vector.size());
}

}  // namespace

struct RemotePort::Pending {
  std::uint64_t request_id = 0;
  std::string step;
  Deadline deadline;
  Clock::time_point sent;
};

RemotePort::RemotePort(std::string endpoint, std::string body_label, RemotePortOptions options)
    : endpoint_(std::move(endpoint)), body_label_(std::move(body_label)), options_(options) {
  ChannelOptions channel = options_.channel;
  channel.on_wait = [this, caller = options_.channel.on_wait] {
    if (caller) caller();
    if (heartbeat_) heartbeat_->poll();
  };
  try {
    channel_ = std::make_unique<RequestChannel>(endpoint_, channel);
  } catch (const ChannelFailure& failure) {
    fail("connect", failure.what());
  }
}

RemotePort::~RemotePort() = default;

std::string RemotePort::describe() const {
  return "server " + endpoint_ + " (body '" + body_label_ + "')";
}

void RemotePort::fail(const std::string& step, const std::string& problem) const {
  throw PortError(describe() + ", step " + step + ": " + problem);
}

void RemotePort::update_byte_counts() {
  timings_.bytes_sent = channel_->bytes_sent();
  timings_.bytes_received = channel_->bytes_received();
}

void RemotePort::send_request(Envelope& request, const std::string& step, double timeout_seconds) {
  if (pending_) fail(step, "the previous request ('" + pending_->step + "') is still in flight");
  const Deadline deadline = Deadline::after(timeout_seconds);
  const auto sent = Clock::now();
  request.set_run_id(run_id_);
  std::uint64_t request_id = 0;
  try {
    request_id = channel_->send(request, deadline);
  } catch (const ChannelFailure& failure) {
    fail(step, failure.what());
  }
  update_byte_counts();
  pending_ = std::make_unique<Pending>(Pending{request_id, step, deadline, sent});
}

/// The reply to the pending request, checked: protocol version, Error replies, content kind.
Envelope RemotePort::finish_request(int expected_content) {
  if (!pending_) fail("reply", "no request in flight");
  const Pending pending = *pending_;
  pending_.reset();
  Envelope reply;
  try {
    reply = channel_->receive(pending.request_id, pending.deadline);
  } catch (const ChannelFailure& failure) {
    fail(pending.step, failure.what());
  }
  update_byte_counts();
  if (!reply.has_version()) {
    fail(pending.step,
         "the reply carries no protocol version (Envelope.version is required in every "
         "message; docs/protocol.md)");
  }
  if (reply.version().major() != protocol::protocol_major) {
    fail(pending.step, "the server speaks protocol " +
                           version_text(reply.version().major(), reply.version().minor()) +
                           ", this coordinator speaks " +
                           version_text(protocol::protocol_major, protocol::protocol_minor) +
                           "; use matching versions of robin-subdomain and the coordinator");
  }
  if (reply.has_error()) {
    fail(pending.step, "server error " + protocol::ErrorCode_Name(reply.error().code()) + ": " +
                           reply.error().message());
  }
  if (reply.content_case() != expected_content) {
    fail(pending.step, "unexpected reply '" + content_name(reply.content_case()) + "' (expected '" +
                           content_name(expected_content) + "')");
  }
  timings_.round_trip_seconds += seconds_since(pending.sent);
  return reply;
}

Envelope RemotePort::exchange(Envelope& request, const std::string& step, double timeout_seconds,
                              int expected_content) {
  send_request(request, step, timeout_seconds);
  return finish_request(expected_content);
}

Envelope RemotePort::watched_exchange(Envelope& request, const std::string& step,
                                      double timeout_seconds, int expected_content) {
  if (!heartbeat_) return exchange(request, step, timeout_seconds, expected_content);
  watched_step_ = step;
  heartbeat_->start();
  try {
    Envelope reply = exchange(request, step, timeout_seconds, expected_content);
    heartbeat_->stop();
    return reply;
  } catch (...) {
    heartbeat_->stop();
    throw;
  }
}

void RemotePort::handshake() {
  Envelope request;
  request.mutable_hello()->set_client_name(
      "robin-coordinator (protocol " +
      version_text(protocol::protocol_major, protocol::protocol_minor) + ")");
  request.mutable_hello()->add_capabilities("fields");
  request.mutable_hello()->add_capabilities(neumann_solve_capability);
  const double timeout =
      std::min(options_.request_timeout_seconds, options_.handshake_timeout_limit);
  const Envelope reply = exchange(request, "handshake", timeout, Envelope::kHelloReply);
  const protocol::HelloReply& hello = reply.hello_reply();
  for (const std::string& capability : required_capabilities) {
    const auto& offered = hello.capabilities();
    if (std::find(offered.begin(), offered.end(), capability) == offered.end()) {
      fail("handshake", "the server does not offer '" + capability + "' (it offers " +
                            join_names(offered) + ")");
    }
  }
  server_name_ = hello.server_name();
  server_major_ = reply.version().major();
  server_minor_ = reply.version().minor();
  capabilities_.assign(hello.capabilities().begin(), hello.capabilities().end());
  if (offers("status") && options_.heartbeat_timeout_seconds > 0.0) {
    try {
      heartbeat_ = std::make_unique<ServerHeartbeat>(
          endpoint_, options_.channel, options_.heartbeat_timeout_seconds,
          options_.heartbeat_interval_seconds, [this](const ServerStatus& status) {
            if (options_.on_status) options_.on_status(body_label_, watched_step_, status);
          });
    } catch (const ChannelFailure& failure) {
      fail("handshake", std::string("cannot open the heartbeat connection: ") + failure.what());
    }
  }
  spdlog::debug("{}: {} (protocol {}, state {}, offers {})", describe(), server_name_,
                version_text(reply.version().major(), reply.version().minor()), hello.state(),
                join_names(hello.capabilities()));
}

InterfaceDescription RemotePort::setup(const BodyCase& body, const SolverOptions& solver) {
  body_label_ = body.definition.name;
  if (body.definition.mesh.node_count() == 0 && body.mesh_delivery == MeshDelivery::data) {
    fail("setup", "body '" + body_label_ + "' has no mesh (load_meshes first)");
  }
  run_id_ = new_run_id();  // a new run: this port's requests carry it from now on
  if (server_name_.empty()) handshake();
  const auto encoding_start = Clock::now();
  Envelope request;
  *request.mutable_setup_body() = encode_setup_body(body, solver);
  const double encoding_seconds = seconds_since(encoding_start);
  const auto sent = Clock::now();
  const Envelope reply =
      watched_exchange(request, "setup", options_.setup_timeout_seconds, Envelope::kInterface);
  const double round_trip_seconds = seconds_since(sent);
  timings_.compute_seconds += reply.interface().setup_seconds();
  record_setup_profile(reply.interface(), encoding_seconds + round_trip_seconds);
  const std::string& linear_solver = request.setup_body().solver().linear_solver();
  profile_.linear_solver = linear_solver.empty() ? "direct" : linear_solver;
  try {
    InterfaceDescription interface = decode_interface(reply.interface());
    const int dimension =
        body.mesh_delivery == MeshDelivery::data ? body.definition.mesh.dimension : body.dimension;
    if (interface.dimension != dimension) {
      fail("setup", "the server set body '" + body_label_ + "' up as a " +
                        std::to_string(interface.dimension) + "D body, not " +
                        std::to_string(dimension) + "D (is its mesh file " +
                        (interface.dimension == 3 ? "a solid" : "a plane") +
                        " mesh? the case has dimension = " + std::to_string(body.dimension) + ")");
    }
    contact_size_ = 0;
    set_up_ = true;
    return interface;
  } catch (const MalformedReply& malformed) {
    fail("setup", std::string("malformed reply: ") + malformed.what());
  }
}

/// The profile of a setup whose request took `seconds` from encoding to the decoded reply.
void RemotePort::record_setup_profile(const protocol::InterfaceDescription& reply, double seconds) {
  profile_ = BodyProfile{};
  record_stage_times(reply.stage_times(), profile_.stages);
  record_peak_resident(reply.peak_resident_bytes(), profile_);
  const double server_seconds = reply.request_seconds();
  if (std::isfinite(server_seconds) && server_seconds > 0.0) {
    profile_.setup_seconds = server_seconds;
    profile_.transfer_seconds = std::max(0.0, seconds - server_seconds);
  }
}

void RemotePort::assign_contact(const ContactOperator& contact) {
  Envelope request;
  *request.mutable_assign_contact() = encode_contact_operator(contact);
  const Envelope reply = watched_exchange(request, "contact assignment",
                                          options_.request_timeout_seconds, Envelope::kAcknowledge);
  record_stage_times(reply.acknowledge().stage_times(), profile_.stages);
  record_peak_resident(reply.acknowledge().peak_resident_bytes(), profile_);
  contact_size_ = contact.row_count();
}

void RemotePort::start_contact_solve(const Eigen::VectorXd& obstacle, int iteration) {
  Envelope request;
  protocol::ContactSolveRequest& solve = *request.mutable_contact_solve();
  solve.set_iteration(static_cast<std::uint32_t>(iteration));
  append(obstacle, *solve.mutable_obstacle());
  send_request(request, "contact solve (iteration " + std::to_string(iteration) + ")",
               options_.request_timeout_seconds);
}

ContactSolveResult RemotePort::finish_contact_solve() {
  const std::string step = pending_ ? pending_->step : "contact solve";
  const Envelope reply = finish_request(Envelope::kContactResult);
  try {
    ContactSolveResult result = decode_contact_result(reply.contact_result(), contact_size_);
    timings_.compute_seconds += result.seconds;
    return result;
  } catch (const MalformedReply& malformed) {
    fail(step, std::string("malformed reply: ") + malformed.what());
  }
}

void RemotePort::start_correction(const Eigen::VectorXd& interface_force, int iteration,
                                  double relative_accuracy) {
  Envelope request;
  protocol::CorrectionRequest& correction = *request.mutable_correction();
  correction.set_iteration(static_cast<std::uint32_t>(iteration));
  correction.set_relative_accuracy(relative_accuracy);
  append(interface_force, *correction.mutable_interface_force());
  send_request(request, "correction (iteration " + std::to_string(iteration) + ")",
               options_.request_timeout_seconds);
}

CorrectionSolveResult RemotePort::finish_correction() {
  const std::string step = pending_ ? pending_->step : "correction";
  const Envelope reply = finish_request(Envelope::kCorrectionResult);
  try {
    CorrectionSolveResult result =
        decode_correction_result(reply.correction_result(), contact_size_);
    timings_.compute_seconds += result.seconds;
    return result;
  } catch (const MalformedReply& malformed) {
    fail(step, std::string("malformed reply: ") + malformed.what());
  }
}

bool RemotePort::offers(const std::string& capability) const {
  return std::find(capabilities_.begin(), capabilities_.end(), capability) != capabilities_.end();
}

void RemotePort::start_neumann_solve(const Eigen::VectorXd& contact_force, int iteration) {
  const std::string step = "Neumann solve (iteration " + std::to_string(iteration) + ")";
  if (server_name_.empty()) fail(step, "no handshake yet: call setup() first");
  if (!offers(neumann_solve_capability)) {
    fail(step, "the server ('" + server_name_ +
                   "') lacks capability neumann_solve (protocol 1.1), which the "
                   "Dirichlet-Neumann algorithm needs; it offers " +
                   join_names(capabilities_) +
                   ". Use a robin-subdomain of protocol 1.1 or later, or a Robin algorithm");
  }
  Envelope request;
  protocol::NeumannSolveRequest& solve = *request.mutable_neumann_solve();
  solve.set_iteration(static_cast<std::uint32_t>(iteration));
  append(contact_force, *solve.mutable_contact_force());
  send_request(request, step, options_.request_timeout_seconds);
}

CorrectionSolveResult RemotePort::finish_neumann_solve() {
  const std::string step = pending_ ? pending_->step : "Neumann solve";
  const Envelope reply = finish_request(Envelope::kNeumannResult);
  try {
    CorrectionSolveResult result = decode_neumann_result(reply.neumann_result(), contact_size_);
    timings_.compute_seconds += result.seconds;
    return result;
  } catch (const MalformedReply& malformed) {
    fail(step, std::string("malformed reply: ") + malformed.what());
  }
}

void RemotePort::set_load_factor(double factor) {
  const std::string step = "load factor " + format_number(factor);
  if (!set_up_) fail(step, "no body set up yet: call setup() first");
  if (server_minor_ < 1) {
    fail(step, "the server ('" + server_name_ + "') speaks protocol " +
                   version_text(server_major_, server_minor_) + ", this coordinator speaks " +
                   version_text(protocol::protocol_major, protocol::protocol_minor) +
                   "; a case with [loading] steps needs SetLoadFactor (protocol 2.1): use a "
                   "server of protocol 2.1 or later, or a case without [loading]");
  }
  Envelope request;
  request.mutable_set_load_factor()->set_factor(factor);
  const Envelope reply =
      exchange(request, step, options_.request_timeout_seconds, Envelope::kLoadFactorSet);
  timings_.compute_seconds += reply.load_factor_set().compute_seconds();
  if (reply.load_factor_set().factor() != factor) {
    fail(step, "malformed reply: LoadFactorSet.factor is " +
                   format_number(reply.load_factor_set().factor()) + ", expected " +
                   format_number(factor));
  }
}

BodyOutput RemotePort::fields(const Eigen::VectorXd& contact_force,
                              const FieldsDestination& destination) {
  Envelope request;
  protocol::FieldsRequest& message = *request.mutable_fields();
  append(contact_force, *message.mutable_contact_force());
  if (!destination.write_directory.empty()) {
    message.set_write_directory(destination.write_directory.generic_string());
    message.set_omit_fields_from_reply(destination.omit_fields);
  }
  const Envelope reply =
      watched_exchange(request, "fields", options_.setup_timeout_seconds, Envelope::kFieldsReply);
  const protocol::FieldsReply& fields = reply.fields_reply();
  record_stage_times(fields.stage_times(), profile_.stages);
  record_peak_resident(fields.peak_resident_bytes(), profile_);
  try {
    BodyOutput output = decode_fields(fields, body_label_);
    if (!destination.write_directory.empty()) output.written_file = written_file_name(fields);
    return output;
  } catch (const MalformedReply& malformed) {
    fail("fields", std::string("malformed reply: ") + malformed.what());
  }
}

/// The name of the file the server wrote for FieldsRequest.write_directory: "<body>.vtu".
/// Without one (a server that did not write it) the coordinator writes the file from the
/// reply's fields, which must then be there.
std::string RemotePort::written_file_name(const protocol::FieldsReply& reply) const {
  const std::string expected = body_label_ + ".vtu";
  if (reply.written_file().empty()) {
    if (reply.node_coordinates().empty()) {
      throw MalformedReply("neither written_file nor the fields: the body's file is nowhere");
    }
    return "";
  }
  if (std::filesystem::path(reply.written_file()).filename() != expected) {
    throw MalformedReply("written_file '" + reply.written_file() + "' is not the body's '" +
                         expected + "'");
  }
  return expected;
}

void RemotePort::end_run() noexcept {
  pending_.reset();  // a reply still in flight is discarded by its request id
  if (!set_up_) return;
  set_up_ = false;
  try {
    if (channel_->connection_lost()) return;
    channel_->set_hooks_enabled(false);  // also after a cancellation, within its short deadline
    Envelope request;
    request.mutable_end_run();
    exchange(request, "end of run", options_.end_run_timeout_seconds, Envelope::kAcknowledge);
  } catch (const std::exception& error) {
    spdlog::debug("{}", error.what());
  } catch (...) {
  }
  channel_->set_hooks_enabled(true);
}

void RemotePort::abandon_request() noexcept {
  pending_.reset();  // a reply still in flight is discarded by its request id
}

bool RemotePort::connection_lost() {
  return channel_->connection_lost();
}

const PortTimings& RemotePort::timings() const {
  return timings_;
}

std::string new_run_id() {
  std::random_device source;
  std::string text;
  constexpr std::array<char, 16> digits{'0', '1', '2', '3', '4', '5', '6', '7',
                                        '8', '9', 'a', 'b', 'c', 'd', 'e', 'f'};
  for (int word = 0; word < 4; ++word) {
    std::uint32_t bits = source();  // random_device yields 32 bits per call
    for (int digit = 0; digit < 8; ++digit, bits >>= 4) text += digits[bits & 0xfu];
  }
  return text;
}

void await_server(const std::string& endpoint, double seconds, const ChannelOptions& channel) {
  const Deadline limit = Deadline::after(seconds);
  std::string last_problem = "no attempt";
  do {
    const double remaining = std::chrono::duration<double>(limit.at - Clock::now()).count();
    try {
      RequestChannel probe(endpoint, channel);
      const Deadline attempt = Deadline::after(std::max(0.1, std::min(1.0, remaining)));
      Envelope request;
      request.mutable_hello()->set_client_name("robin-coordinator (waiting for the server)");
      const std::uint64_t request_id = probe.send(request, attempt);
      if (probe.receive(request_id, attempt).has_hello_reply()) return;
      last_problem = "the reply was not a HelloReply";
    } catch (const ChannelFailure& failure) {
      last_problem = failure.what();
      if (channel.on_wait) channel.on_wait();
    }
  } while (Clock::now() < limit.at);
  std::ostringstream text;
  text << "no server answered at " << endpoint << " within " << seconds << " s (" << last_problem
       << ")";
  throw std::runtime_error(text.str());
}

bool request_server_shutdown(const std::string& endpoint, double timeout_seconds,
                             const std::optional<CurveClientKeys>& curve) noexcept {
  try {
    ChannelOptions options;
    options.immediate = false;  // keep the acknowledgement even though the server exits at once
    options.curve = curve;
    RequestChannel channel(endpoint, options);
    const Deadline deadline = Deadline::after(timeout_seconds);
    Envelope request;
    request.mutable_shutdown();
    const std::uint64_t request_id = channel.send(request, deadline);
    return channel.receive(request_id, deadline).has_acknowledge();
  } catch (...) {
    return false;
  }
}

}  // namespace robin
