#include "remote/conformance_check.hpp"

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>

#include "command_line.hpp"
#include "protocol_version.hpp"
#include "remote/conformance_body.hpp"
#include "remote/conformance_session.hpp"
#include "remote/conformance_solid.hpp"
#include "remote/curve_options.hpp"
#include "remote/request_channel.hpp"
#include "robin.pb.h"

namespace robin {
namespace {

using namespace conformance;
using protocol::Envelope;

const std::vector<std::string> core_capabilities = {"contact_solve", "correction_solve", "fields"};
constexpr const char* neumann_solve_capability = "neumann_solve";  // optional, protocol 1.1
constexpr const char* status_capability = "status";                // optional, protocol 2.1
constexpr unsigned run_id_minor = 2;  // Envelope.run_id and its rule: since protocol 1.2
const std::vector<std::string> state_names = {"awaiting_setup", "awaiting_assignment", "ready"};

/// SetLoadFactor (protocol 2.1) with `factor`.
protocol::Envelope load_factor_request(double factor) {
  protocol::Envelope envelope;
  envelope.mutable_set_load_factor()->set_factor(factor);
  return envelope;
}

// --- The checks -------------------------------------------------------------------------------

class ServerChecks {
 public:
  explicit ServerChecks(Session& session)
      : session_(session), tolerance_(session.options().tolerance) {}

  void run_all() {
    run_envelope_checks();
    run_state_checks();
    run_setup_checks();
    run_assignment_checks();
    run_solve_checks();
    run_neumann_solve_checks();
    run_load_factor_checks();
    run_status_checks();
    run_run_control_checks();
    run_if_load_factor("load_factor_before_setup", [this] {
      return refused(load_factor_request(2.0), "SetLoadFactor after EndRun",
                     {protocol::WRONG_STATE}, "awaiting_setup");
    });
    run_solid_checks(session_, server_minor_, neumann_offered_);
    session_.run("oversized_message", [this] { return oversized_message(); });
    if (session_.options().include_shutdown) {
      session_.run("shutdown", [this] { return shutdown(); });
    }
    session_.record("request_id_echoed", session_.request_id_problems());
    session_.record("version_on_every_reply", session_.version_problems());
  }

 private:
  void run_envelope_checks();
  void run_state_checks();
  void run_setup_checks();
  void run_assignment_checks();
  void run_solve_checks();
  void run_neumann_solve_checks();
  void run_run_control_checks();
  /// SetLoadFactor (protocol 2.1), judged for servers that announce minor version 1 or later.
  void run_load_factor_checks();
  void run_if_load_factor(const std::string& name, const std::function<std::string()>& check);
  std::string load_factor_scaling();
  /// StatusRequest (protocol 2.1, optional "status"): answered from the server's progress
  /// record when announced, refused otherwise. Runs in state ready, between requests.
  void run_status_checks();
  std::string idle_status();
  /// Runs a check of the optional Neumann solve, only when the server announced it.
  void run_if_neumann(const std::string& name, const std::function<std::string()>& check);

  std::string hello();
  std::string version_mismatch();
  std::string raw_error(const std::vector<std::string>& frames, const std::string& what,
                        std::optional<std::uint64_t> expected_id, protocol::ErrorCode code);
  std::string refused(Envelope request, const std::string& what,
                      const std::vector<protocol::ErrorCode>& codes, const std::string& state,
                      bool stamp_version = true);
  std::string non_finite_refused(
      const std::function<Envelope(const Eigen::VectorXd&)>& make_request,
      const std::string& request_name, const std::string& field);
  std::string setup_body();
  std::string assign_contact();
  std::string contact_solve_free();
  std::string contact_solve_signorini();
  std::string contact_solve_equilibrium();
  std::string correction_linearity();
  std::string correction_symmetry();
  std::string neumann_solve_free();
  std::string neumann_solve_equation();
  std::string neumann_solve_contact_consistency();
  std::string neumann(const Eigen::VectorXd& force, const std::string& what,
                      Eigen::VectorXd& trace);
  std::string fields_structure();
  std::string fields_equilibrium();
  std::string fields_pair_order();
  std::string end_run();
  std::string second_run();
  std::string voigt_material();
  std::string general_rows();
  std::string set_up_again(const protocol::SetupBody& body, const std::string& what);
  std::string setup_body_in_ready_state();
  std::string other_run_refused();
  std::string oversized_message();
  std::string shutdown();
  std::string still_answers(const std::string& after);

  const std::vector<ContactNode>& require_interface() const;
  void require_assignment() const;
  const ContactSolution& require_partial_solution() const;
  Eigen::VectorXd obstacle_of(const std::vector<ContactNode>& nodes, bool partial) const;
  std::string correction(const Eigen::VectorXd& force, const std::string& what,
                         Eigen::VectorXd& trace);
  std::string solve_partial(const std::string& what, ContactSolution& solution);
  long contact_count() const { return static_cast<long>(nodes_.size()); }

  Session& session_;
  double tolerance_;
  std::vector<ContactNode> nodes_;  // the contact nodes in pair order, after a SetupBody
  bool assigned_ = false;
  std::optional<ContactSolution> partial_;     // the partial-contact solution
  std::optional<Eigen::VectorXd> free_trace_;  // e: u_N of the far-obstacle contact solve
  bool capabilities_known_ = false;            // a HelloReply to 'hello' arrived
  bool neumann_offered_ = false;               // HelloReply.capabilities has "neumann_solve"
  bool status_offered_ = false;                // HelloReply.capabilities has "status"
  unsigned server_major_ = 0;                  // the version of the HelloReply
  unsigned server_minor_ = 0;
  Eigen::VectorXd first_force_;     // r1 of 'correction_linearity'
  Eigen::VectorXd first_response_;  // its reply w(r1)
};

const std::vector<ContactNode>& ServerChecks::require_interface() const {
  if (nodes_.empty()) {
    throw NotChecked("needs the contact boundary of a successful SetupBody (see 'setup_body')");
  }
  return nodes_;
}

void ServerChecks::require_assignment() const {
  require_interface();
  if (!assigned_) throw NotChecked("needs an accepted AssignContact (see 'assign_contact')");
}

const ContactSolution& ServerChecks::require_partial_solution() const {
  require_assignment();
  if (!partial_) {
    throw NotChecked("needs the partial-contact solution (see 'contact_solve_signorini')");
  }
  return *partial_;
}

Eigen::VectorXd ServerChecks::obstacle_of(const std::vector<ContactNode>& nodes,
                                          bool partial) const {
  Eigen::VectorXd obstacle(static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    obstacle(static_cast<Eigen::Index>(i)) = partial ? partial_obstacle(nodes[i].x) : far_obstacle;
  }
  return obstacle;
}

// Envelope-level checks: handshake, versions, malformed and unknown messages.

void ServerChecks::run_envelope_checks() {
  session_.run("hello", [this] { return hello(); });
  session_.run("end_run_before_checks", [this] {
    return in_context("EndRun", expect_acknowledge(session_.request(end_run_request(), "EndRun"),
                                                   "awaiting_setup"));
  });
  session_.run("version_mismatch", [this] { return version_mismatch(); });
  session_.run("version_checked_before_state", [this] {
    Envelope request = contact_solve_request(Eigen::VectorXd::Zero(1));
    request.mutable_version()->set_major(protocol::protocol_major + 1);
    return refused(request, "ContactSolveRequest with another major version before SetupBody",
                   {protocol::VERSION_MISMATCH}, "awaiting_setup", false);
  });
  session_.run("missing_version", [this] {
    return refused(hello_request(), "a Hello without version", {protocol::MALFORMED_MESSAGE},
                   "awaiting_setup", false);
  });
  session_.run("garbage_bytes", [this] {
    return raw_error({std::string("\xff\xff\xff", 3)}, "the bytes ff ff ff", 0,
                     protocol::MALFORMED_MESSAGE);
  });
  session_.run("empty_envelope", [this] {
    return refused(Envelope(), "an Envelope without content", {protocol::MALFORMED_MESSAGE},
                   "awaiting_setup");
  });
  session_.run("several_frames", [this] {
    const std::string hello_bytes = hello_request().SerializeAsString();
    return raw_error({hello_bytes, hello_bytes}, "a message of two frames", std::nullopt,
                     protocol::MALFORMED_MESSAGE);
  });
  session_.run("reply_as_request", [this] {
    Envelope request;
    request.mutable_acknowledge()->set_state("ready");
    return refused(request, "an Acknowledge sent as a request", {protocol::UNSUPPORTED},
                   "awaiting_setup");
  });
  session_.run("unknown_request_type", [this] {
    Envelope envelope;  // version and id, then field 1000 (length-delimited, empty): a request
    envelope.mutable_version()->set_major(protocol::protocol_major);  // type of a later minor
    envelope.mutable_version()->set_minor(protocol::protocol_minor);
    envelope.set_request_id(session_.next_request_id());
    return raw_error({envelope.SerializeAsString() + std::string("\xc2\x3e\x00", 3)},
                     "a request of an unknown type (Envelope field 1000)", envelope.request_id(),
                     protocol::UNSUPPORTED);
  });
}

std::string ServerChecks::hello() {
  const Exchange exchange = session_.request(hello_request(), "Hello");
  if (const std::string problem = expect_content(exchange, Envelope::kHelloReply);
      !problem.empty()) {
    return "Hello: " + problem;
  }
  const protocol::HelloReply& reply = exchange.reply->hello_reply();
  session_.report().server_name = reply.server_name();
  std::vector<std::string> problems;
  if (reply.server_name().empty()) problems.push_back("HelloReply.server_name is empty");
  const std::vector<std::string> offered(reply.capabilities().begin(), reply.capabilities().end());
  for (const std::string& capability : core_capabilities) {
    if (std::find(offered.begin(), offered.end(), capability) == offered.end()) {
      problems.push_back("HelloReply.capabilities lacks the core '" + capability +
                         "' (it offers: " + join(offered, ", ") + ")");
    }
  }
  capabilities_known_ = true;
  server_major_ = exchange.reply->version().major();
  server_minor_ = exchange.reply->version().minor();
  neumann_offered_ =
      std::find(offered.begin(), offered.end(), neumann_solve_capability) != offered.end();
  status_offered_ = std::find(offered.begin(), offered.end(), status_capability) != offered.end();
  if (std::find(state_names.begin(), state_names.end(), reply.state()) == state_names.end()) {
    problems.push_back("HelloReply.state '" + reply.state() + "' is not a state name (" +
                       join(state_names, ", ") + ")");
  }
  return summarize(problems);
}

std::string ServerChecks::version_mismatch() {
  Envelope request = hello_request();
  request.mutable_version()->set_major(protocol::protocol_major + 1);
  request.mutable_version()->set_minor(0);
  const std::string problem =
      refused(request, "Hello with version " + std::to_string(protocol::protocol_major + 1) + ".0",
              {protocol::VERSION_MISMATCH}, "awaiting_setup", false);
  if (!problem.empty()) return problem;
  return still_answers("the VERSION_MISMATCH reply");
}

/// The server answers a Hello on the same connection with a HelloReply.
std::string ServerChecks::still_answers(const std::string& after) {
  const Exchange exchange = session_.request(hello_request(), "Hello after " + after);
  return in_context("the Hello after " + after, expect_content(exchange, Envelope::kHelloReply));
}

std::string ServerChecks::raw_error(const std::vector<std::string>& frames, const std::string& what,
                                    std::optional<std::uint64_t> expected_id,
                                    protocol::ErrorCode code) {
  const Exchange exchange = session_.send_raw(frames, what, expected_id);
  const std::string problem = expect_error(exchange, {code}, "awaiting_setup");
  if (!problem.empty()) return what + ": " + problem;
  if (expected_id && exchange.reply->request_id() != *expected_id) {
    return what + ": the reply carries request_id " + std::to_string(exchange.reply->request_id()) +
           ", expected " + std::to_string(*expected_id) +
           (*expected_id == 0 ? " (the id of an unparsable request is unknown)" : "");
  }
  return still_answers(what);
}

std::string ServerChecks::refused(Envelope request, const std::string& what,
                                  const std::vector<protocol::ErrorCode>& codes,
                                  const std::string& state, bool stamp_version) {
  return in_context(
      what, expect_error(session_.request(std::move(request), what, stamp_version), codes, state));
}

/// `make_request` of an otherwise valid vector of n_c ones with a NaN, then with -inf, at the
/// middle contact node: each must be refused as INVALID_ARGUMENT, the server staying ready.
std::string ServerChecks::non_finite_refused(
    const std::function<Envelope(const Eigen::VectorXd&)>& make_request,
    const std::string& request_name, const std::string& field) {
  require_assignment();
  const long middle = contact_count() / 2;
  const double quiet_nan = std::numeric_limits<double>::quiet_NaN();
  const double infinity = std::numeric_limits<double>::infinity();
  for (const auto& [value, name] : {std::pair{quiet_nan, "NaN"}, std::pair{-infinity, "-inf"}}) {
    Eigen::VectorXd values = Eigen::VectorXd::Ones(contact_count());
    values(middle) = value;
    const std::string what =
        request_name + " with " + name + " in " + field + "[" + std::to_string(middle) + "]";
    if (const std::string problem =
            refused(make_request(values), what, {protocol::INVALID_ARGUMENT}, "ready");
        !problem.empty()) {
      return problem;
    }
  }
  return "";
}

// Requests out of order, and refused bodies.

void ServerChecks::run_state_checks() {
  const auto wrong_state = [this](Envelope request, const std::string& what) {
    return refused(std::move(request), what + " before SetupBody", {protocol::WRONG_STATE},
                   "awaiting_setup");
  };
  session_.run("assign_contact_before_setup", [wrong_state] {
    return wrong_state(assign_request({{0, 0.0}}), "AssignContact");
  });
  session_.run("contact_solve_before_setup", [wrong_state] {
    return wrong_state(contact_solve_request(Eigen::VectorXd::Zero(1)), "ContactSolveRequest");
  });
  session_.run("correction_before_setup", [wrong_state] {
    return wrong_state(correction_request(Eigen::VectorXd::Zero(1)), "CorrectionRequest");
  });
  session_.run("fields_before_setup", [wrong_state] {
    return wrong_state(fields_request(Eigen::VectorXd::Zero(1)), "FieldsRequest");
  });
  run_if_neumann("neumann_solve_before_setup", [wrong_state] {
    return wrong_state(neumann_solve_request(Eigen::VectorXd::Zero(1)), "NeumannSolveRequest");
  });
}

void ServerChecks::run_setup_checks() {
  const std::vector<protocol::ErrorCode> bad_input = {protocol::BAD_INPUT,
                                                      protocol::INVALID_ARGUMENT};
  const auto bad_setup = [this](const protocol::SetupBody& body, const std::string& what,
                                const std::vector<protocol::ErrorCode>& codes) {
    return refused(setup_request(body), "SetupBody with " + what, codes, "awaiting_setup");
  };
  session_.run("setup_unknown_boundary", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.clear_contact_boundaries();
    body.add_contact_boundaries("no_such_curve");
    return bad_setup(body, "the unknown contact boundary 'no_such_curve'", bad_input);
  });
  session_.run("setup_poisson_ratio_half", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.set_poisson_ratio(0.5);
    return bad_setup(body, "Poisson's ratio 0.5", bad_input);
  });
  session_.run("setup_four_voigt_values", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.clear_young_modulus();
    body.clear_poisson_ratio();
    for (const double value : {1000.0, 300.0, 300.0, 1000.0}) body.add_voigt(value);
    return bad_setup(body, "4 voigt values", bad_input);
  });
  session_.run("setup_floating_body", [bad_setup, bad_input] {
    protocol::SetupBody body = square_body();
    body.clear_dirichlet();
    return bad_setup(body, "no Dirichlet condition (a floating body)", {protocol::SINGULAR_BODY});
  });
  session_.run("setup_body", [this] { return setup_body(); });
}

std::string ServerChecks::setup_body() {
  const Exchange exchange = session_.request(setup_request(square_body()), "SetupBody");
  if (const std::string problem = expect_content(exchange, Envelope::kInterface);
      !problem.empty()) {
    return "SetupBody of the unit square: " + problem;
  }
  const protocol::InterfaceDescription& description = exchange.reply->interface();
  const std::string what = "InterfaceDescription of the unit square's top edge: ";
  if (const std::string problem = interface_size_problems(description); !problem.empty()) {
    return what + problem;
  }
  std::vector<std::string> problems = interface_node_problems(description, tolerance_);
  const std::vector<std::string> weights = interface_weight_problems(description, tolerance_);
  problems.insert(problems.end(), weights.begin(), weights.end());
  const std::vector<std::string> surfaces = interface_surface_problems(description, tolerance_);
  problems.insert(problems.end(), surfaces.begin(), surfaces.end());
  if (description.body_name() != body_name) {
    problems.push_back("body_name is '" + description.body_name() + "', expected the echo '" +
                       body_name + "'");
  }
  if (!problems.empty()) return what + summarize(problems);
  nodes_ = pair_order(description);
  return "";
}

// AssignContact: refusals, then the assignment.

void ServerChecks::run_assignment_checks() {
  session_.run("contact_solve_before_assignment", [this] {
    return refused(contact_solve_request(obstacle_of(require_interface(), false)),
                   "ContactSolveRequest before AssignContact", {protocol::WRONG_STATE},
                   "awaiting_assignment");
  });
  run_if_neumann("neumann_solve_before_assignment", [this] {
    require_interface();
    return refused(neumann_solve_request(Eigen::VectorXd::Zero(contact_count())),
                   "NeumannSolveRequest before AssignContact", {protocol::WRONG_STATE},
                   "awaiting_assignment");
  });
  const auto invalid = [this](Envelope request, const std::string& what) {
    return refused(std::move(request), "AssignContact with " + what, {protocol::INVALID_ARGUMENT},
                   "awaiting_assignment");
  };
  session_.run("assign_unknown_node", [this, invalid] {
    std::vector<ContactNode> nodes = require_interface();
    std::int64_t unknown = 0;
    for (const ContactNode& node : nodes) unknown = std::max(unknown, node.id + 1);
    nodes.front().id = unknown;
    return invalid(assign_request(nodes), "the unknown node id " + std::to_string(unknown));
  });
  session_.run("assign_wrong_entry_count", [this, invalid] {
    Envelope request = assign_request(require_interface());
    request.mutable_assign_contact()->mutable_values()->RemoveLast();
    return invalid(request, "one value fewer than node_ids and components");
  });
  session_.run("assign_bad_row_offsets", [this, invalid] {
    Envelope request = assign_request(require_interface());
    request.mutable_assign_contact()->set_row_offsets(1, 0);
    return invalid(request, "an empty first row (row_offsets 0, 0, ...)");
  });
  session_.run("assign_non_positive_weight", [this, invalid] {
    Envelope request = assign_request(require_interface());
    request.mutable_assign_contact()->set_weights(0, 0.0);
    return invalid(request, "the weight 0 for the first constraint");
  });
  session_.run("assign_non_finite_value", [this, invalid] {
    Envelope request = assign_request(require_interface());
    request.mutable_assign_contact()->set_values(1, std::numeric_limits<double>::quiet_NaN());
    return invalid(request, "a NaN coefficient");
  });
  session_.run("assign_repeated_entry", [this, invalid] {
    Envelope request = assign_request(require_interface());
    request.mutable_assign_contact()->set_components(0, 1);  // row 0 names (node, y) twice
    return invalid(request, "a row that names the same node and component twice");
  });
  session_.run("assign_contact", [this] { return assign_contact(); });
  session_.run("hello_reports_state", [this] {
    require_assignment();
    const Exchange exchange = session_.request(hello_request(), "Hello in state ready");
    std::string problem = expect_content(exchange, Envelope::kHelloReply);
    if (problem.empty() && exchange.reply->hello_reply().state() != "ready") {
      problem = "HelloReply.state is '" + exchange.reply->hello_reply().state() +
                "', expected 'ready' (after an accepted AssignContact)";
    }
    return in_context("Hello in state ready", problem);
  });
}

std::string ServerChecks::assign_contact() {
  const Exchange exchange = session_.request(assign_request(require_interface()), "AssignContact");
  const std::string problem = expect_acknowledge(exchange, "ready");
  assigned_ = problem.empty();
  return in_context("AssignContact of every top-edge node in pair order", problem);
}

// Solves: wrong lengths, the free and the partial contact, the correction operator, fields.

void ServerChecks::run_solve_checks() {
  const auto wrong_length = [this](Envelope request, const std::string& what) {
    return refused(std::move(request), what, {protocol::INVALID_ARGUMENT}, "ready");
  };
  session_.run("contact_solve_wrong_length", [this, wrong_length] {
    require_assignment();
    return wrong_length(contact_solve_request(Eigen::VectorXd::Constant(contact_count() + 1, 1.0)),
                        "ContactSolveRequest with n_c + 1 obstacle values");
  });
  session_.run("correction_wrong_length", [this, wrong_length] {
    require_assignment();
    return wrong_length(correction_request(Eigen::VectorXd::Ones(contact_count() - 1)),
                        "CorrectionRequest with n_c - 1 interface_force values");
  });
  session_.run("fields_wrong_length", [this, wrong_length] {
    require_assignment();
    return wrong_length(fields_request(Eigen::VectorXd::Zero(contact_count() + 1)),
                        "FieldsRequest with n_c + 1 contact_force values");
  });
  session_.run("contact_solve_non_finite", [this] {
    return non_finite_refused(
        [](const Eigen::VectorXd& obstacle) { return contact_solve_request(obstacle); },
        "ContactSolveRequest", "obstacle");
  });
  session_.run("correction_non_finite", [this] {
    return non_finite_refused(correction_request, "CorrectionRequest", "interface_force");
  });
  session_.run("contact_solve_free", [this] { return contact_solve_free(); });
  session_.run("contact_solve_signorini", [this] { return contact_solve_signorini(); });
  session_.run("contact_solve_equilibrium", [this] { return contact_solve_equilibrium(); });
  session_.run("correction_linearity", [this] { return correction_linearity(); });
  session_.run("correction_symmetry", [this] { return correction_symmetry(); });
  session_.run("fields_structure", [this] { return fields_structure(); });
  session_.run("fields_equilibrium", [this] { return fields_equilibrium(); });
  session_.run("fields_pair_order", [this] { return fields_pair_order(); });
}

std::string ServerChecks::contact_solve_free() {
  require_assignment();
  const std::string what = "ContactSolveRequest with every obstacle far (g = 1)";
  ContactSolution solution;
  const Exchange exchange =
      session_.request(contact_solve_request(obstacle_of(nodes_, false)), what);
  if (const std::string problem = read_contact_solution(exchange, contact_count(), solution);
      !problem.empty()) {
    return what + ": " + problem;
  }
  std::vector<std::string> problems;
  for (long i = 0; i < contact_count(); ++i) {
    if (std::abs(solution.contact_force(i)) > tolerance_ * force_reference) {
      problems.push_back("contact_force[" + std::to_string(i) +
                         "] = " + number(solution.contact_force(i)) + ", expected 0 (no contact)");
    }
    if (std::abs(solution.normal_trace(i) - lift) > tolerance_ * lift) {
      problems.push_back("normal_trace[" + std::to_string(i) +
                         "] = " + number(solution.normal_trace(i)) + ", expected " + number(lift) +
                         " (the body translates rigidly with its lifted bottom edge)");
    }
  }
  if (!problems.empty()) return what + ": " + summarize(problems);
  free_trace_ = solution.normal_trace;
  return "";
}

std::string ServerChecks::solve_partial(const std::string& what, ContactSolution& solution) {
  const Exchange exchange =
      session_.request(contact_solve_request(obstacle_of(nodes_, true), 2), what);
  if (const std::string problem = read_contact_solution(exchange, contact_count(), solution);
      !problem.empty()) {
    return problem;
  }
  return summarize(signorini_problems(solution, obstacle_of(nodes_, true), tolerance_));
}

std::string ServerChecks::contact_solve_signorini() {
  require_assignment();
  const std::string what = "ContactSolveRequest with g = lift (0.5 + x)";
  ContactSolution solution;
  const std::string problem = solve_partial(what, solution);
  if (problem.empty()) partial_ = solution;
  return in_context(what, problem);
}

std::string ServerChecks::correction(const Eigen::VectorXd& force, const std::string& what,
                                     Eigen::VectorXd& trace) {
  return in_context(what, read_correction(session_.request(correction_request(force), what),
                                          contact_count(), trace));
}

/// K u = f - B' lambda, seen on the wire: u_N = e - F lambda with e = lift (the free trace)
/// and F lambda the CorrectionResult for r = lambda.
std::string ServerChecks::contact_solve_equilibrium() {
  const ContactSolution& solution = require_partial_solution();
  Eigen::VectorXd response;
  if (const std::string problem =
          correction(solution.contact_force, "CorrectionRequest with r = lambda", response);
      !problem.empty()) {
    return problem;
  }
  const Eigen::VectorXd expected = Eigen::VectorXd::Constant(contact_count(), lift) - response;
  const double difference = (solution.normal_trace - expected).cwiseAbs().maxCoeff();
  if (difference <= tolerance_ * lift) return "";
  return "the partial-contact solution violates u_N = e - F lambda (e = lift, F lambda the "
         "CorrectionResult for r = lambda): max difference " +
         number(difference) + " (length) > " + number(tolerance_ * lift);
}

std::string ServerChecks::correction_linearity() {
  require_assignment();
  Eigen::VectorXd force(contact_count());
  for (long i = 0; i < contact_count(); ++i) force(i) = 1.0 + 0.5 * static_cast<double>(i);
  Eigen::VectorXd single, twice;
  std::string problem = correction(force, "CorrectionRequest with r", single);
  if (problem.empty()) problem = correction(2.0 * force, "CorrectionRequest with 2 r", twice);
  if (!problem.empty()) return problem;
  first_force_ = force;
  first_response_ = single;
  const double difference = (twice - 2.0 * single).cwiseAbs().maxCoeff();
  const double scale = twice.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return "w(r) = 0 for r != 0: the correction ignores its interface_force";
  if (difference > tolerance_ * scale) {
    return "w(2 r) != 2 w(r): max difference " + number(difference) + " for max |w(2 r)| " +
           number(scale) + " (the correction problem is linear)";
  }
  return "";
}

/// F = B K^-1 B' is symmetric positive definite: r1' F r2 = r2' F r1 and r' F r > 0.
std::string ServerChecks::correction_symmetry() {
  if (first_force_.size() == 0) {
    require_assignment();
    throw NotChecked("needs w(r) from 'correction_linearity'");
  }
  Eigen::VectorXd force(contact_count());
  for (long i = 0; i < contact_count(); ++i) force(i) = std::cos(1.3 * i) + 0.2;
  Eigen::VectorXd response;
  if (const std::string problem = correction(force, "CorrectionRequest with r2", response);
      !problem.empty()) {
    return problem;
  }
  const Eigen::VectorXd& force1 = first_force_;
  const Eigen::VectorXd& response1 = first_response_;
  const double forward = force1.dot(response), backward = force.dot(response1);
  const double scale = force1.norm() * response.norm() + force.norm() * response1.norm();
  if (std::abs(forward - backward) > tolerance_ * scale) {
    return "r1' w(r2) = " + number(forward) + " differs from r2' w(r1) = " + number(backward) +
           ": the correction operator F is not symmetric";
  }
  if (!(force1.dot(response1) > 0.0) || !(force.dot(response) > 0.0)) {
    return "r' w(r) = " + number(force1.dot(response1)) + " and " + number(force.dot(response)) +
           ": the correction operator F is not positive definite (sign of B' r?)";
  }
  return "";
}

// The Neumann solve (protocol 1.1, optional): K u = f - B' lambda, u_N = B u = e - F lambda.

void ServerChecks::run_if_neumann(const std::string& name,
                                  const std::function<std::string()>& check) {
  if (neumann_offered_) session_.run(name, check);
}

void ServerChecks::run_neumann_solve_checks() {
  if (!capabilities_known_) {
    session_.run("neumann_solve_capability", []() -> std::string {
      throw NotChecked("needs HelloReply.capabilities (see 'hello')");
    });
    return;
  }
  if (!neumann_offered_) {
    session_.record_note("neumann_solve_capability",
                         "not announced: the optional Neumann solve of protocol 1.1 is not "
                         "checked, except that its request must be refused as UNSUPPORTED");
    session_.run("neumann_solve_unsupported", [this] {
      require_assignment();
      return refused(neumann_solve_request(Eigen::VectorXd::Zero(contact_count())),
                     "NeumannSolveRequest to a server that does not announce 'neumann_solve'",
                     {protocol::UNSUPPORTED}, "ready");
    });
    return;
  }
  session_.record_note("neumann_solve_capability", "announced: checked");
  const auto invalid = [this](const Eigen::VectorXd& force, const std::string& what) {
    return refused(neumann_solve_request(force), "NeumannSolveRequest with " + what,
                   {protocol::INVALID_ARGUMENT}, "ready");
  };
  run_if_neumann("neumann_solve_wrong_length", [this, invalid] {
    require_assignment();
    return invalid(Eigen::VectorXd::Ones(contact_count() + 1), "n_c + 1 contact_force values");
  });
  run_if_neumann("neumann_solve_non_finite", [this] {
    return non_finite_refused(neumann_solve_request, "NeumannSolveRequest", "contact_force");
  });
  run_if_neumann("neumann_solve_free", [this] { return neumann_solve_free(); });
  run_if_neumann("neumann_solve_equation", [this] { return neumann_solve_equation(); });
  run_if_neumann("neumann_solve_contact_consistency",
                 [this] { return neumann_solve_contact_consistency(); });
}

std::string ServerChecks::neumann(const Eigen::VectorXd& force, const std::string& what,
                                  Eigen::VectorXd& trace) {
  return in_context(what,
                    read_neumann_solution(session_.request(neumann_solve_request(force), what),
                                          contact_count(), trace));
}

/// lambda = 0: the body's own loads only, u_N = e = lift (the rigid translation).
std::string ServerChecks::neumann_solve_free() {
  require_assignment();
  Eigen::VectorXd trace;
  const std::string what = "NeumannSolveRequest with lambda = 0";
  if (const std::string problem = neumann(Eigen::VectorXd::Zero(contact_count()), what, trace);
      !problem.empty()) {
    return problem;
  }
  const double difference = (trace.array() - lift).abs().maxCoeff();
  if (difference <= tolerance_ * lift) return "";
  return what + ": normal_trace differs from e = " + number(lift) +
         " (the body translates rigidly with its lifted bottom edge) by up to " +
         number(difference);
}

/// u_N(lambda) = e - F lambda, with e the normal trace of the far-obstacle contact solve and
/// F lambda the CorrectionResult for r = lambda: the same operator in the sign convention of
/// the contact solve (force -lambda_i n_i on the body).
std::string ServerChecks::neumann_solve_equation() {
  require_assignment();
  if (!free_trace_) throw NotChecked("needs e from 'contact_solve_free'");
  Eigen::VectorXd force(contact_count());
  for (long i = 0; i < contact_count(); ++i) {
    force(i) = force_reference / static_cast<double>(contact_count()) *
               (1.0 + 0.5 * std::cos(1.3 * static_cast<double>(i)));
  }
  Eigen::VectorXd response, trace;
  std::string problem = correction(force, "CorrectionRequest with r = lambda", response);
  if (problem.empty()) problem = neumann(force, "NeumannSolveRequest with lambda", trace);
  if (!problem.empty()) return problem;
  const Eigen::VectorXd expected = *free_trace_ - response;
  const double scale = std::max(free_trace_->cwiseAbs().maxCoeff(), response.cwiseAbs().maxCoeff());
  const double difference = (trace - expected).cwiseAbs().maxCoeff();
  if (difference <= tolerance_ * scale) return "";
  const double flipped = (trace - (*free_trace_ + response)).cwiseAbs().maxCoeff();
  return "NeumannSolveResult.normal_trace violates u_N = e - F lambda (e from the contact solve "
         "with far obstacles, F lambda the CorrectionResult for r = lambda): max difference " +
         number(difference) + " (length) for a scale " + number(scale) +
         (flipped <= tolerance_ * scale ? "; it equals e + F lambda: the sign of B' lambda is "
                                          "wrong (the force on the body is -lambda_i n_i)"
                                        : "");
}

/// The partial-contact lambda: the Neumann solve reproduces the contact solve's normal trace.
std::string ServerChecks::neumann_solve_contact_consistency() {
  const ContactSolution& solution = require_partial_solution();
  Eigen::VectorXd trace;
  if (const std::string problem = neumann(
          solution.contact_force, "NeumannSolveRequest with the partial-contact lambda", trace);
      !problem.empty()) {
    return problem;
  }
  const double difference = (trace - solution.normal_trace).cwiseAbs().maxCoeff();
  if (difference <= tolerance_ * lift) return "";
  return "NeumannSolveRequest with the partial-contact lambda: normal_trace differs from the "
         "contact solve's u_N for that lambda by up to " +
         number(difference) + " (length) > " + number(tolerance_ * lift);
}

/// The fields for lambda = 0: the mesh structure, and the rigid translation u = (0, lift).
std::string ServerChecks::fields_structure() {
  require_assignment();
  const std::string what = "FieldsRequest with lambda = 0";
  const Exchange exchange =
      session_.request(fields_request(Eigen::VectorXd::Zero(contact_count())), what);
  if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
      !problem.empty()) {
    return what + ": " + problem;
  }
  const protocol::FieldsReply& fields = exchange.reply->fields_reply();
  std::vector<std::string> problems = fields_structure_problems(fields);
  for (const protocol::Field& field : fields.point_fields()) {
    if (field.name() != "displacement" || field.components() != 2 || !problems.empty()) continue;
    for (int k = 0; k + 1 < field.values_size(); k += 2) {
      if (std::abs(field.values(k)) > tolerance_ * lift ||
          std::abs(field.values(k + 1) - lift) > tolerance_ * lift) {
        problems.push_back("the displacement of node " + std::to_string(k / 2) + " is (" +
                           number(field.values(k)) + ", " + number(field.values(k + 1)) +
                           "), expected the rigid translation (0, " + number(lift) + ")");
        break;
      }
    }
  }
  return problems.empty() ? "" : what + ": " + summarize(problems);
}

/// reaction_resultant + applied_force + sum_i (-lambda_i n_i) = 0 for the partial contact.
std::string ServerChecks::fields_equilibrium() {
  const ContactSolution& solution = require_partial_solution();
  const std::string what = "FieldsRequest with the partial-contact lambda";
  const Exchange exchange = session_.request(fields_request(solution.contact_force), what);
  if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
      !problem.empty()) {
    return what + ": " + problem;
  }
  const protocol::FieldsReply& fields = exchange.reply->fields_reply();
  const double total = solution.contact_force.sum();  // every n_i = (0, 1)
  const Eigen::Vector2d balance = resultant(fields.reaction_resultant()) +
                                  resultant(fields.applied_force()) - Eigen::Vector2d(0.0, total);
  if (balance.norm() <= tolerance_ * std::max(std::abs(total), 1e-300)) return "";
  return what + ": reaction_resultant + applied_force - sum lambda_i n_i = (" +
         number(balance.x()) + ", " + number(balance.y()) +
         "), expected 0 (sum lambda_i = " + number(total) + ")";
}
/// The pair order, seen through positions: a unit contact force at pair index k must push the
/// node at (x_k, 1) down most (on this mesh the largest entry of every column of F = B K^-1 B' is
/// on the diagonal: both shipped servers pass). Answers indexed by the pair order cannot show a
/// server that uses its own order instead: they are consistently relabelled. The FieldsReply's
/// coordinates can.
std::string ServerChecks::fields_pair_order() {
  require_assignment();
  for (long k = 0; k < contact_count(); ++k) {
    Eigen::VectorXd force = Eigen::VectorXd::Zero(contact_count());
    force(k) = 1.0;
    const std::string what = "FieldsRequest with a unit contact_force at pair index " +
                             std::to_string(k) + " (node id " + std::to_string(nodes_[k].id) +
                             ", x = " + number(nodes_[k].x) + ")";
    const Exchange exchange = session_.request(fields_request(force), what);
    if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
        !problem.empty()) {
      return what + ": " + problem;
    }
    double abscissa = 0.0;
    const std::string problem =
        most_pushed_top_node(exchange.reply->fields_reply(), tolerance_, abscissa);
    if (!problem.empty()) return what + ": " + problem;
    if (std::abs(abscissa - nodes_[k].x) > tolerance_) {
      return what + ": the top-edge node pushed down most is at x = " + number(abscissa) +
             ": the force was not applied in the pair order of AssignContact";
    }
  }
  return "";
}

// Status (protocol 2.1, optional): what the server is doing, answered between requests too.

Envelope status_request() {
  Envelope envelope;
  envelope.mutable_status_request();
  return envelope;
}

void ServerChecks::run_status_checks() {
  if (!capabilities_known_) {
    session_.run("status", []() -> std::string {
      throw NotChecked("needs HelloReply.capabilities (see 'hello')");
    });
    return;
  }
  if (!status_offered_) {
    session_.record_note("status", "not announced: StatusRequest must be refused");
    session_.run("status_unannounced_refused", [this] {
      require_assignment();
      return refused(status_request(), "StatusRequest to a server without \"status\"",
                     {protocol::UNSUPPORTED, protocol::MALFORMED_MESSAGE}, "ready");
    });
    return;
  }
  session_.record_note("status", "announced: checked");
  session_.run("status_idle", [this] { return idle_status(); });
}

/// Between requests, in state ready after the setup of the conformance body: not busy, no
/// request or stage, no queue, the body's name and its 2 degrees of freedom per node (at least
/// the free ones of InterfaceDescription.dof_count), state "ready".
std::string ServerChecks::idle_status() {
  require_assignment();
  const std::string what = "StatusRequest in state ready, between requests";
  const Exchange exchange = session_.request(status_request(), what);
  if (!exchange.reply) return what + ": " + exchange.problem;
  if (!exchange.reply->has_status_reply()) {
    return what + ": expected StatusReply, got " + describe(*exchange.reply);
  }
  const protocol::StatusReply& status = exchange.reply->status_reply();
  std::vector<std::string> problems;
  if (status.state() != "ready") problems.push_back("state '" + status.state() + "'");
  if (status.busy() || !status.request_type().empty() || !status.stage().empty()) {
    problems.push_back("busy " + std::string(status.busy() ? "true" : "false") +
                       " with request_type '" + status.request_type() + "' and stage '" +
                       status.stage() + "' while no request is being handled");
  }
  if (status.queued_requests() != 0) {
    problems.push_back(std::to_string(status.queued_requests()) + " queued requests");
  }
  if (status.body_name() != body_name) {
    problems.push_back("body_name '" + status.body_name() + "', expected '" + body_name + "'");
  }
  if (status.dof_count() < static_cast<std::uint64_t>(2 * contact_count())) {
    problems.push_back("dof_count " + std::to_string(status.dof_count()) +
                       ", fewer than the 2 per contact node");
  }
  if (!(status.request_seconds() == 0.0 && status.stage_seconds() == 0.0)) {
    problems.push_back("request_seconds " + number(status.request_seconds()) +
                       " and stage_seconds " + number(status.stage_seconds()) +
                       " while idle (0 expected)");
  }
  return problems.empty() ? "" : what + ": " + join(problems, "; ");
}

// Load steps (protocol 2.1): SetLoadFactor scales the loads and the prescribed displacements.

void ServerChecks::run_if_load_factor(const std::string& name,
                                      const std::function<std::string()>& check) {
  if (capabilities_known_ && (server_major_ > 2 || (server_major_ == 2 && server_minor_ >= 1))) {
    session_.run(name, check);
  }
}

void ServerChecks::run_load_factor_checks() {
  if (!capabilities_known_) {
    session_.run("load_factor", []() -> std::string {
      throw NotChecked("needs the server's protocol version from its HelloReply (see 'hello')");
    });
    return;
  }
  if (!(server_major_ > 2 || (server_major_ == 2 && server_minor_ >= 1))) {
    session_.record_note("load_factor", "not applicable: the server speaks protocol " +
                                            std::to_string(server_major_) + "." +
                                            std::to_string(server_minor_) +
                                            ", and SetLoadFactor is since 2.1; a 2.0 server must "
                                            "refuse it as UNSUPPORTED");
    if (server_major_ != 2) return;
    session_.run("load_factor_unsupported", [this] {
      require_assignment();
      return refused(load_factor_request(2.0), "SetLoadFactor to a protocol 2.0 server",
                     {protocol::UNSUPPORTED}, "ready");
    });
    return;
  }
  session_.record_note("load_factor", "protocol 2.1 or later: checked");
  const auto bad = [this](double factor, const std::string& what) {
    require_assignment();
    return refused(load_factor_request(factor), "SetLoadFactor with " + what, {protocol::BAD_INPUT},
                   "ready");
  };
  run_if_load_factor("load_factor_non_finite", [bad] {
    const std::string problem = bad(std::numeric_limits<double>::quiet_NaN(), "a NaN factor");
    return problem.empty() ? bad(-std::numeric_limits<double>::infinity(), "factor -infinity")
                           : problem;
  });
  run_if_load_factor("load_factor_absurd", [bad] { return bad(1e9, "factor 1e9"); });
  run_if_load_factor("load_factor_scaling", [this] { return load_factor_scaling(); });
}

/// The body's only load is the lift of its bottom edge: at load factor t the body translates
/// by t lift, so u_N = t lift with far obstacles; F does not change (the correction for the same
/// r); factor 1 restores the body of the other checks.
std::string ServerChecks::load_factor_scaling() {
  require_assignment();
  const std::array<double, 3> factors{2.5, -0.5, 1.0};
  for (const double factor : factors) {
    const std::string what = "SetLoadFactor " + number(factor) + " in state ready";
    const Exchange exchange = session_.request(load_factor_request(factor), what);
    if (!exchange.reply) return what + ": " + exchange.problem;
    const protocol::Envelope& reply = *exchange.reply;
    if (!reply.has_load_factor_set()) {
      return what + ": expected LoadFactorSet, got " + describe(reply);
    }
    if (reply.load_factor_set().factor() != factor || reply.load_factor_set().state() != "ready") {
      return what + ": LoadFactorSet{factor " + number(reply.load_factor_set().factor()) +
             ", state '" + reply.load_factor_set().state() + "'}, expected {" + number(factor) +
             ", 'ready'}";
    }
    const std::string solve = "ContactSolveRequest with every obstacle far after " + what;
    ContactSolution solution;
    if (const std::string problem = read_contact_solution(
            session_.request(contact_solve_request(obstacle_of(nodes_, false)), solve),
            contact_count(), solution);
        !problem.empty()) {
      return solve + ": " + problem;
    }
    const double difference = (solution.normal_trace.array() - factor * lift).abs().maxCoeff();
    if (difference > tolerance_ * lift) {
      return solve + ": normal_trace differs from the load factor times the lift, " +
             number(factor * lift) + ", by up to " + number(difference) +
             " (every prescribed displacement must scale with the factor)";
    }
    if (first_force_.size() == contact_count()) {
      Eigen::VectorXd response;
      if (const std::string problem =
              correction(first_force_, "CorrectionRequest after " + what, response);
          !problem.empty()) {
        return problem;
      }
      const double change = (response - first_response_).cwiseAbs().maxCoeff();
      if (change > tolerance_ * first_response_.cwiseAbs().maxCoeff()) {
        return "CorrectionRequest after " + what + ": w(r) changed by " + number(change) +
               " (F = B K^-1 B' does not depend on the loads)";
      }
    }
  }
  return "";
}

// Run control: EndRun, a second run, SetupBody in state ready.

void ServerChecks::run_run_control_checks() {
  session_.run("end_run", [this] { return end_run(); });
  session_.run("second_run", [this] { return second_run(); });
  session_.run("voigt_material", [this] { return voigt_material(); });
  session_.run("general_rows", [this] { return general_rows(); });
  session_.run("setup_body_in_ready_state", [this] { return setup_body_in_ready_state(); });
  if (!capabilities_known_) {
    session_.run("other_run_refused", []() -> std::string {
      throw NotChecked("needs the server's protocol version from its HelloReply (see 'hello')");
    });
  } else if (server_major_ < 2 && server_minor_ < run_id_minor) {
    session_.record_note("other_run_refused",
                         "not applicable: the server speaks protocol " +
                             std::to_string(server_major_) + "." + std::to_string(server_minor_) +
                             ", and Envelope.run_id is since 1.2; not checked");
  } else {
    session_.run("other_run_refused", [this] { return other_run_refused(); });
  }
  session_.run("end_run_after_checks", [this] {
    return in_context("EndRun", expect_acknowledge(session_.request(end_run_request(), "EndRun"),
                                                   "awaiting_setup"));
  });
}

std::string ServerChecks::end_run() {
  require_interface();
  const Exchange exchange = session_.request(end_run_request(), "EndRun in state ready");
  if (const std::string problem = expect_acknowledge(exchange, "awaiting_setup");
      !problem.empty()) {
    return "EndRun in state ready: " + problem;
  }
  return refused(contact_solve_request(obstacle_of(nodes_, true)),
                 "ContactSolveRequest after EndRun", {protocol::WRONG_STATE}, "awaiting_setup");
}

/// Sets `body` up and assigns its contact nodes in the pair order of the first run (the same
/// positions, maybe other ids, into nodes_): "" or the problem, naming the requests with
/// `what` (e.g. "second run").
std::string ServerChecks::set_up_again(const protocol::SetupBody& body, const std::string& what) {
  const Exchange setup = session_.request(setup_request(body), "SetupBody (" + what + ")");
  if (const std::string problem = expect_content(setup, Envelope::kInterface); !problem.empty()) {
    return "SetupBody (" + what + "): " + problem;
  }
  const protocol::InterfaceDescription& description = setup.reply->interface();
  if (!interface_size_problems(description).empty() ||
      description.node_ids_size() != contact_count()) {
    return "SetupBody (" + what + "): the InterfaceDescription differs from the first run's";
  }
  std::vector<ContactNode> nodes = pair_order(description);
  std::stable_sort(nodes.begin(), nodes.end(), [this](const ContactNode& a, const ContactNode& b) {
    return (nodes_.front().x > nodes_.back().x) ? a.x > b.x : a.x < b.x;
  });
  nodes_ = nodes;  // same positions, maybe other ids
  const Exchange assign = session_.request(assign_request(nodes_), "AssignContact (" + what + ")");
  if (const std::string problem = expect_acknowledge(assign, "ready"); !problem.empty()) {
    return "AssignContact (" + what + "): " + problem;
  }
  return "";
}

/// SetupBody, AssignContact and the partial-contact solve again: the same answer.
std::string ServerChecks::second_run() {
  const ContactSolution& first = require_partial_solution();
  if (const std::string problem = set_up_again(square_body(), "second run"); !problem.empty()) {
    return problem;
  }
  ContactSolution again;
  if (const std::string problem = solve_partial("ContactSolveRequest (second run)", again);
      !problem.empty()) {
    return "ContactSolveRequest (second run): " + problem;
  }
  const double scale = std::max(first.contact_force.cwiseAbs().maxCoeff(), 1e-300);
  const double difference = (again.contact_force - first.contact_force).cwiseAbs().maxCoeff();
  if (difference > tolerance_ * scale) {
    return "the second run's contact_force differs from the first run's by " + number(difference) +
           " (max lambda " + number(scale) + ")";
  }
  return "";
}

/// The material as robin-coordinator sends every material but isotropic plane strain: the
/// body set up again with the equivalent `voigt` matrix of its isotropic material (see
/// with_voigt_material) must give the isotropic definition's partial-contact solution (lambda
/// relative to max |lambda|, u_N relative to lift) and, when 'correction_linearity' ran, its
/// correction w(r1) (relative to max |w(r1)|), to the checker's tolerance.
std::string ServerChecks::voigt_material() {
  const ContactSolution& isotropic = require_partial_solution();
  const std::string what = "the equivalent Voigt matrix instead of young_modulus/poisson_ratio";
  if (const std::string problem = set_up_again(with_voigt_material(square_body()), what);
      !problem.empty()) {
    return problem;
  }
  const std::string convention =
      ": the server does not read SetupBody.voigt as the same material (row-major 3x3, Voigt "
      "order xx, yy, xy, engineering shear strain)";
  ContactSolution solution;
  const std::string solve_what = "ContactSolveRequest with g = lift (0.5 + x) (" + what + ")";
  if (const std::string problem = solve_partial(solve_what, solution); !problem.empty()) {
    return solve_what + ": " + problem;
  }
  const double force_scale = std::max(isotropic.contact_force.cwiseAbs().maxCoeff(), 1e-300);
  const double force_difference =
      (solution.contact_force - isotropic.contact_force).cwiseAbs().maxCoeff();
  const double trace_difference =
      (solution.normal_trace - isotropic.normal_trace).cwiseAbs().maxCoeff();
  if (force_difference > tolerance_ * force_scale || trace_difference > tolerance_ * lift) {
    return solve_what + ": contact_force differs from the isotropic definition's by up to " +
           number(force_difference) + " (max lambda " + number(force_scale) +
           ") and normal_trace by up to " + number(trace_difference) + convention;
  }
  if (first_force_.size() == 0) return "";  // 'correction_linearity' failed: nothing to compare
  Eigen::VectorXd response;
  const std::string correction_what = "CorrectionRequest with r (" + what + ")";
  if (const std::string problem = correction(first_force_, correction_what, response);
      !problem.empty()) {
    return problem;
  }
  const double scale = std::max(first_response_.cwiseAbs().maxCoeff(), 1e-300);
  const double difference = (response - first_response_).cwiseAbs().maxCoeff();
  if (difference > tolerance_ * scale) {
    return correction_what + ": normal_trace differs from the isotropic definition's w(r) by " +
           "up to " + number(difference) + " (max |w(r)| " + number(scale) + ")" + convention;
  }
  return "";
}

/// Protocol 2.0's general constraint operator: rows of two nodes each,
/// (T u)_j = (u_y(x_j) + u_y(x_{j+1})) / 2 over consecutive contact nodes. Since F_T = T F T' with
/// F the node-to-node compliance, the correction for r must equal T w(T' r), w the node-to-node
/// CorrectionResult. The node-to-node assignment is restored afterwards.
std::string ServerChecks::general_rows() {
  require_assignment();
  if (const std::string problem = set_up_again(square_body(), "node-to-node rows");
      !problem.empty()) {
    return problem;
  }
  const long rows = contact_count() - 1;
  Eigen::MatrixXd averaging = Eigen::MatrixXd::Zero(rows, contact_count());
  Eigen::VectorXd force(rows);
  for (long j = 0; j < rows; ++j) {
    averaging(j, j) = averaging(j, j + 1) = 0.5;
    force(j) = 1.0 - 0.3 * static_cast<double>(j);
  }
  Eigen::VectorXd node_response;
  if (const std::string problem = correction(averaging.transpose() * force,
                                             "CorrectionRequest with r = T' s", node_response);
      !problem.empty()) {
    return problem;
  }
  Envelope assign;
  protocol::AssignContact& rows_message = *assign.mutable_assign_contact();
  rows_message.add_row_offsets(0);
  for (long j = 0; j < rows; ++j) {
    for (const long k : {j, j + 1}) {
      rows_message.add_node_ids(nodes_[static_cast<std::size_t>(k)].id);
      rows_message.add_components(1);
      rows_message.add_values(0.5);
    }
    rows_message.add_row_offsets(static_cast<std::uint64_t>(rows_message.values_size()));
    rows_message.add_weights(1.0);
  }
  const std::string what = "AssignContact with rows (u_y(x_j) + u_y(x_j+1)) / 2";
  if (const std::string problem = expect_acknowledge(session_.request(assign, what), "ready");
      !problem.empty()) {
    return what + ": " + problem;
  }
  Eigen::VectorXd row_response;
  const std::string correction_what = "CorrectionRequest with s (" + what + ")";
  std::string problem = in_context(
      correction_what, read_correction(session_.request(correction_request(force), correction_what),
                                       rows, row_response));
  if (problem.empty()) {
    const Eigen::VectorXd expected = averaging * node_response;
    const double scale = std::max(expected.cwiseAbs().maxCoeff(), 1e-300);
    const double difference = (row_response - expected).cwiseAbs().maxCoeff();
    if (difference > tolerance_ * scale) {
      problem = correction_what + ": normal_trace differs from T w(T' s) (w the node-to-node " +
                "correction) by up to " + number(difference) + " (max " + number(scale) +
                "): the server does not apply the rows of B as sent";
    }
  }
  // Restore the node-to-node assignment for the checks that follow.
  const Exchange restore =
      session_.request(assign_request(nodes_), "AssignContact (node-to-node again)");
  if (const std::string restored = expect_acknowledge(restore, "ready"); problem.empty()) {
    problem = restored.empty() ? "" : "AssignContact (node-to-node again): " + restored;
  }
  return problem;
}

/// SetupBody is valid in every state and discards the body: a solve is then refused.
std::string ServerChecks::setup_body_in_ready_state() {
  require_partial_solution();
  const Exchange setup = session_.request(setup_request(square_body()), "SetupBody in state ready");
  if (const std::string problem = expect_content(setup, Envelope::kInterface); !problem.empty()) {
    return "SetupBody in state ready: " + problem;
  }
  return refused(contact_solve_request(obstacle_of(nodes_, true)),
                 "ContactSolveRequest after a new SetupBody", {protocol::WRONG_STATE},
                 "awaiting_assignment");
}

/// Protocol 1.2: a body set up with run_id A refuses the requests of run B (WRONG_STATE, the
/// state kept, and an EndRun of run B ends nothing), and serves run A's requests and those
/// without run_id from the same body (the free solve: u_N = lift).
std::string ServerChecks::other_run_refused() {
  require_interface();
  const std::string first_run = "conformance-check-run-a", other_run = "conformance-check-run-b";
  const auto of_run = [](Envelope request, const std::string& run_id) {
    request.set_run_id(run_id);
    return request;
  };
  const std::string setup_what = "SetupBody with run_id '" + first_run + "'";
  const Exchange setup =
      session_.request(of_run(setup_request(square_body()), first_run), setup_what);
  if (const std::string problem = expect_content(setup, Envelope::kInterface); !problem.empty()) {
    return setup_what + ": " + problem;
  }
  if (const std::string problem = interface_size_problems(setup.reply->interface());
      !problem.empty()) {
    return setup_what + ": " + problem;
  }
  const std::vector<ContactNode> nodes = pair_order(setup.reply->interface());
  const long count = static_cast<long>(nodes.size());
  const std::string assign_what = "AssignContact with run_id '" + first_run + "'";
  if (const std::string problem = expect_acknowledge(
          session_.request(of_run(assign_request(nodes), first_run), assign_what), "ready");
      !problem.empty()) {
    return assign_what + ": " + problem;
  }
  const Envelope solve = contact_solve_request(obstacle_of(nodes, false));
  const std::string after = " after a SetupBody with run_id '" + first_run + "'";
  if (const std::string problem = refused(
          of_run(solve, other_run), "ContactSolveRequest with run_id '" + other_run + "'" + after,
          {protocol::WRONG_STATE}, "ready");
      !problem.empty()) {
    return problem;
  }
  if (const std::string problem =
          refused(of_run(end_run_request(), other_run),
                  "EndRun with run_id '" + other_run + "'" + after + " (it must end nothing)",
                  {protocol::WRONG_STATE}, "ready");
      !problem.empty()) {
    return problem;
  }
  for (const std::string& run_id : {first_run, std::string()}) {
    const std::string what =
        run_id.empty() ? "ContactSolveRequest without run_id (as a 1.1 coordinator sends it)" +
                             after + " and the refused requests of run '" + other_run + "'"
                       : "ContactSolveRequest with run_id '" + run_id +
                             "' after the refused requests of run '" + other_run + "'";
    ContactSolution solution;
    if (const std::string problem =
            read_contact_solution(session_.request(of_run(solve, run_id), what), count, solution);
        !problem.empty()) {
      return what + ": " + problem;
    }
    const double difference = (solution.normal_trace.array() - lift).abs().maxCoeff();
    if (difference > tolerance_ * lift) {
      return what + ": normal_trace differs from the free trace " + number(lift) + " by up to " +
             number(difference) + " (the body of the run was not kept)";
    }
  }
  return "";
}

// The oversized message and Shutdown.

std::string ServerChecks::oversized_message() {
  const long size = session_.options().oversized_message_bytes;
  const std::string what = "a Hello of " + std::to_string(size) + " bytes";
  std::string outcome;
  try {
    ChannelOptions channel_options;
    channel_options.curve = session_.options().curve;
    RequestChannel channel(session_.endpoint(), channel_options);
    Envelope request = hello_request();
    request.mutable_hello()->set_client_name(std::string(static_cast<std::size_t>(size), 'x'));
    const Deadline deadline = Deadline::after(session_.options().reply_timeout_seconds);
    const std::uint64_t id = channel.send(request, deadline);
    const Envelope reply = channel.receive(id, deadline);
    session_.note_reply(reply, what, id);
  } catch (const ChannelFailure& failure) {
    outcome = std::string(" (it was dropped: ") + failure.what() + ")";
  }
  session_.reconnect();  // whatever happened, go on with a new connection
  const Exchange exchange = session_.request(hello_request(), "Hello after " + what);
  if (exchange.reply && exchange.reply->has_hello_reply()) return "";
  session_.mark_spoiled();
  return "after " + what + outcome +
         ", a Hello on a new connection: " + expect_content(exchange, Envelope::kHelloReply);
}

std::string ServerChecks::shutdown() {
  Envelope request;
  request.mutable_shutdown();
  session_.reconnect(false);  // the server is there; its last reply must not be discarded
  const Exchange exchange = session_.request(request, "Shutdown");
  session_.abandon_connection();  // the server is expected to be gone: no recovery Hello
  if (const std::string problem = expect_content(exchange, Envelope::kAcknowledge);
      !problem.empty()) {
    return "Shutdown: " + problem;
  }
  const double wait = std::min(2.0, session_.options().reply_timeout_seconds);
  if (session_.answers_hello_within(wait)) {
    return "the server still answered a Hello on a new connection after its Acknowledge to "
           "Shutdown (it must stop serving and exit)";
  }
  return "";
}

}  // namespace

std::size_t ConformanceReport::failure_count() const {
  return static_cast<std::size_t>(std::count_if(
      checks.begin(), checks.end(), [](const ConformanceCheck& check) { return !check.passed; }));
}

ConformanceReport check_server(const std::string& endpoint, const ConformanceOptions& options) {
  const auto start = Clock::now();
  ConformanceReport report;
  report.endpoint = endpoint;
  Session session(endpoint, options, report);
  ServerChecks(session).run_all();
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

std::string format_report(const ConformanceReport& report) {
  std::ostringstream text;
  text << "Protocol " << protocol::protocol_major << "." << protocol::protocol_minor
       << " conformance of the server at " << report.endpoint;
  if (!report.server_name.empty()) text << " (" << report.server_name << ")";
  text << "\n";
  for (const ConformanceCheck& check : report.checks) {
    if (check.passed) {
      text << "PASS " << check.name;
      if (!check.explanation.empty()) text << " (" << check.explanation << ")";
    } else {
      text << "FAIL " << check.name << ": " << check.explanation;
    }
    text << "\n";
  }
  const std::size_t failed = report.failure_count();
  text << report.checks.size() << " checks, " << report.checks.size() - failed << " passed, "
       << failed << " failed in " << number(report.seconds) << " s: the server "
       << (report.conforms() ? "conforms" : "does not conform") << " to the protocol\n";
  return text.str();
}

bool requests_server_check(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word == "--check-server" || word.starts_with("--check-server=")) return true;
  }
  return false;
}

int server_check_main(int argc, const char* const* argv) {
  CLI::App app{
      "robin-coordinator --check-server: drives a subdomain server through every message of "
      "the protocol (docs/protocol.md) and reports each deviation"};
  std::string endpoint;
  ConformanceOptions options;
  app.add_option("--check-server", endpoint, "endpoint of the server to check")
      ->type_name("ENDPOINT")
      ->required();
  app.add_option("--timeout", options.reply_timeout_seconds, "deadline of each request, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-message-size-probe", options.oversized_message_bytes,
                 "size of the oversized message (bytes); the server must answer it or drop it, "
                 "and then still answer a new connection")
      ->check(CLI::Range(1L, (1L << 31) - (1L << 16)))  // protobuf's limit is 2 GiB
      ->capture_default_str();
  app.add_option("--tolerance", options.tolerance, "relative tolerance of the numerical checks")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--include-shutdown", options.include_shutdown,
               "finish with a Shutdown request (the server must exit)");
  CurveClientSettings curve;
  add_curve_client_options(app, curve, "(one server)");
  app.footer(
      "Exit codes: 0 the server conforms, 1 it does not (or a key file is unusable), 2 bad "
      "command line.");
  add_version_option(app, "robin-coordinator --check-server");
  if (const auto code = parse_command_line(app, argc, argv)) return *code;
  if (const std::string problem = curve_options_problem(curve, 1); !problem.empty()) {
    std::cerr << "robin-coordinator --check-server: " << problem << "\n";
    return 2;
  }
  try {
    options.curve = load_curve_client_keys(curve, 1).front();
  } catch (const std::exception& error) {
    std::cerr << "robin-coordinator --check-server: " << error.what() << "\n";
    return 1;
  }
  const ConformanceReport report = check_server(endpoint, options);
  std::cout << format_report(report) << std::flush;
  return report.conforms() ? 0 : 1;
}

}  // namespace robin
