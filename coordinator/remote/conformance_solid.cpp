#include "remote/conformance_solid.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "numerics/body_output.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/box_mesher.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/material.hpp"
#include "remote/conformance_body.hpp"
#include "remote/reply_decoding.hpp"
#include "remote/setup_encoding.hpp"

namespace robin::conformance {
namespace {

using protocol::Envelope;

constexpr const char* solid_body_name = "conformance_cube";
constexpr double solid_lift = 0.01;  // prescribed u_z of the bottom side
constexpr unsigned solid_minor = 4;  // solid bodies: since protocol 2.4

/// The built-in solid body (see the header).
BodyDefinition cube_definition() {
  BodyDefinition definition;
  definition.name = solid_body_name;
  definition.mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(),
                                  Eigen::Vector3i(2, 2, 2), ElementType::tetrahedron4);
  definition.mesh.source = "the conformance checker's unit cube";
  definition.material = make_isotropic_solid_material(young_modulus, 0.3, solid_body_name);
  definition.body_force = Eigen::Vector3d(0.0, 0.0, -2.0);
  definition.dirichlet.push_back({"bottom", 0.0, 0.0, solid_lift});
  TractionCondition traction;
  traction.boundary = "right";
  traction.vector = Eigen::Vector3d(1.0, 0.5, 0.0);
  definition.tractions.push_back(traction);
  definition.contact_boundaries = {"top"};
  return definition;
}

/// max |actual - expected| within tolerance * scale; otherwise a problem naming `what`.
std::string compare(const Eigen::VectorXd& actual, const Eigen::VectorXd& expected,
                    double tolerance, double scale, const std::string& what) {
  if (actual.size() != expected.size()) {
    return what + " has " + std::to_string(actual.size()) + " values, expected " +
           std::to_string(expected.size());
  }
  if (actual.size() == 0) return "";
  const double difference = (actual - expected).cwiseAbs().maxCoeff();
  if (difference <= tolerance * scale) return "";
  Eigen::Index worst = 0;
  (actual - expected).cwiseAbs().maxCoeff(&worst);
  return what + " differs from the reference by up to " + number(difference) + " (at index " +
         std::to_string(worst) + ": " + number(actual(worst)) + ", expected " +
         number(expected(worst)) + "; allowed " + number(tolerance * scale) + ")";
}

Eigen::VectorXd field_values(const OutputField& field) {
  return Eigen::Map<const Eigen::VectorXd>(field.values.data(),
                                           static_cast<Eigen::Index>(field.values.size()));
}

const OutputField* find_field(const std::vector<OutputField>& fields, const std::string& name) {
  for (const OutputField& field : fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

/// The fields of `expected` that `actual` has (displacement required), value by value.
void field_problems(const std::vector<OutputField>& actual,
                    const std::vector<OutputField>& expected, const std::string& kind,
                    double tolerance, std::vector<std::string>& problems) {
  for (const OutputField& reference : expected) {
    const OutputField* found = find_field(actual, reference.name);
    if (found == nullptr) {
      if (reference.name == "displacement" && kind == "point field") {
        problems.push_back("the point field 'displacement' is missing");
      }
      continue;
    }
    const Eigen::VectorXd values = field_values(reference);
    const double scale = std::max(values.cwiseAbs().maxCoeff(), 1e-300);
    if (found->components != reference.components) {
      problems.push_back(kind + " '" + reference.name + "' has " +
                         std::to_string(found->components) + " components, expected " +
                         std::to_string(reference.components));
      continue;
    }
    const std::string problem =
        compare(field_values(*found), values, tolerance, scale, kind + " '" + reference.name + "'");
    if (!problem.empty()) problems.push_back(problem);
  }
}

class SolidChecks {
 public:
  SolidChecks(Session& session, unsigned server_minor, bool neumann_offered)
      : session_(session),
        tolerance_(session.options().tolerance),
        server_minor_(server_minor),
        neumann_offered_(neumann_offered),
        definition_(cube_definition()) {}

  void run_all();

 private:
  std::string setup_body();
  std::string unsupported_note(const Exchange& exchange) const;
  std::string interface_problems(const InterfaceDescription& description);
  std::string match_nodes(const InterfaceDescription& description);
  std::string surface_problems(const InterfaceDescription& description) const;
  std::string assign_contact();
  std::string contact_solve();
  std::string correction();
  std::string neumann_solve();
  std::string fields();
  void require_reference() const;
  void require_assignment() const;
  long contact_count() const { return static_cast<long>(reference_nodes_.node_ids.size()); }

  Session& session_;
  double tolerance_;
  unsigned server_minor_;
  bool neumann_offered_;
  BodyDefinition definition_;
  std::unique_ptr<BodySolver> reference_;  // the same body in process, once set up remotely
  InterfaceDescription reference_nodes_;   // its contact boundary
  std::vector<int> server_ids_;            // per reference contact node, the server's node id
  bool assigned_ = false;
  std::optional<Eigen::VectorXd> contact_force_;  // the reference's lambda for the obstacle
};

void SolidChecks::require_reference() const {
  if (!reference_ || server_ids_.empty()) {
    throw NotChecked("needs the solid body's InterfaceDescription (see 'solid_setup_body')");
  }
}

void SolidChecks::require_assignment() const {
  require_reference();
  if (!assigned_) throw NotChecked("needs an accepted AssignContact (see 'solid_assign_contact')");
}

void SolidChecks::run_all() {
  std::string note;
  session_.run("solid_setup_body", [this, &note] {
    const std::string problem = setup_body();
    if (problem.rfind("3D: not supported", 0) == 0) note = problem;
    return note.empty() ? problem : "";
  });
  if (!note.empty()) {
    session_.report().checks.back().explanation = note;
    return;
  }
  session_.run("solid_assign_contact", [this] { return assign_contact(); });
  session_.run("solid_contact_solve", [this] { return contact_solve(); });
  session_.run("solid_correction", [this] { return correction(); });
  if (neumann_offered_) session_.run("solid_neumann_solve", [this] { return neumann_solve(); });
  session_.run("solid_fields", [this] { return fields(); });
  session_.run("solid_end_run", [this] {
    return in_context(
        "EndRun after the solid body",
        expect_acknowledge(session_.request(end_run_request(), "EndRun"), "awaiting_setup"));
  });
}

/// "3D: not supported (...)" when the server refused the solid body as a server without solid
/// bodies may; "" otherwise.
std::string SolidChecks::unsupported_note(const Exchange& exchange) const {
  if (!exchange.reply || !exchange.reply->has_error()) return "";
  const protocol::ErrorCode code = exchange.reply->error().code();
  const bool older = server_minor_ < solid_minor && code == protocol::BAD_INPUT;
  if (code != protocol::UNSUPPORTED && !older) return "";
  return "3D: not supported (the SetupBody of a solid body was answered " +
         describe(*exchange.reply) + "): the solid-body checks are skipped";
}

std::string SolidChecks::setup_body() {
  const std::string what = "SetupBody of the solid unit cube (tetrahedra, protocol 2.4)";
  const Envelope request =
      setup_request(encode_setup_body(definition_, solid_body_name, SolverOptions{}));
  const Exchange exchange = session_.request(request, what);
  if (const std::string note = unsupported_note(exchange); !note.empty()) return note;
  if (const std::string problem = expect_content(exchange, Envelope::kInterface);
      !problem.empty()) {
    return what + ": " + problem;
  }
  reference_ = std::make_unique<BodySolver>(definition_);
  reference_nodes_ = reference_->contact_boundary();
  InterfaceDescription description;
  try {
    description = decode_interface(exchange.reply->interface());
  } catch (const std::exception& error) {
    return what + ": the InterfaceDescription is malformed: " + error.what();
  }
  return in_context("InterfaceDescription of the cube's top side", interface_problems(description));
}

std::string SolidChecks::interface_problems(const InterfaceDescription& description) {
  if (description.dimension != 3) {
    return "dimension is " + std::to_string(description.dimension) + ", expected 3";
  }
  if (const std::string problem = match_nodes(description); !problem.empty()) return problem;
  return surface_problems(description);
}

/// Matches every reference contact node to the server's node at its position; the server's
/// normals, weights and fixed flags there must be the reference's.
std::string SolidChecks::match_nodes(const InterfaceDescription& description) {
  const std::size_t count = reference_nodes_.node_ids.size();
  if (description.node_ids.size() != count) {
    return std::to_string(description.node_ids.size()) + " nodes, expected the " +
           std::to_string(count) + " nodes of the top side";
  }
  std::vector<int> ids;
  std::vector<std::string> problems;
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3d& x = reference_nodes_.coordinates[j];
    std::size_t k = 0;
    while (k < count && (description.coordinates[k] - x).norm() > tolerance_) ++k;
    const std::string node =
        "the node at (" + number(x.x()) + ", " + number(x.y()) + ", " + number(x.z()) + ")";
    if (k == count) {
      problems.push_back(node + " is missing");
      continue;
    }
    ids.push_back(description.node_ids[k]);
    if ((description.normals[k] - reference_nodes_.normals[j]).norm() > tolerance_) {
      problems.push_back(node + " has the normal (" + number(description.normals[k].x()) + ", " +
                         number(description.normals[k].y()) + ", " +
                         number(description.normals[k].z()) + "), expected (0, 0, 1)");
    }
    if (std::abs(description.weights[k] - reference_nodes_.weights[j]) >
        tolerance_ * reference_nodes_.weights[j]) {
      problems.push_back(node + " has the weight " + number(description.weights[k]) +
                         ", expected " + number(reference_nodes_.weights[j]));
    }
    if (description.fixed[k] != reference_nodes_.fixed[j]) {
      problems.push_back(node + " has fixed flags no Dirichlet condition sets");
    }
  }
  if (problems.empty()) server_ids_ = ids;
  return summarize(problems);
}

/// One surface "top" of TRIANGLE3 faces, oriented outward (+z), covering the area 1.
std::string SolidChecks::surface_problems(const InterfaceDescription& description) const {
  if (description.surfaces.size() != 1 || description.surfaces[0].boundary != "top") {
    return "expected one ContactSurface, boundary 'top'";
  }
  const ContactSurfaceDescription& surface = description.surfaces[0];
  if (surface.facet_type != FacetType::triangle3) {
    return "the surface's segment_type is not TRIANGLE3 (the faces sent were 3-node triangles)";
  }
  double area = 0.0;
  for (std::size_t first = 0; first + 2 < surface.facets.size(); first += 3) {
    const auto corner = [&](std::size_t i) {
      return description.coordinates[static_cast<std::size_t>(surface.facets[first + i])];
    };
    const Eigen::Vector3d normal = (corner(1) - corner(0)).cross(corner(2) - corner(0));
    if (!(normal.z() > 0.0)) {
      return "face " + std::to_string(first / 3) +
             " is not oriented outward: its right-hand "
             "normal (x1 - x0) x (x2 - x0) has z = " +
             number(normal.z()) + ", expected > 0";
    }
    area += 0.5 * normal.norm();
  }
  if (std::abs(area - 1.0) > tolerance_) {
    return "the faces cover an area of " + number(area) + ", expected the side's area 1";
  }
  return "";
}

std::string SolidChecks::assign_contact() {
  require_reference();
  const std::vector<Eigen::Vector3d> normals(server_ids_.size(), Eigen::Vector3d::UnitZ());
  reference_->assign_contact(
      node_to_node_operator(reference_nodes_.node_ids, normals, reference_nodes_.weights));
  Envelope request;
  *request.mutable_assign_contact() = encode_contact_operator(
      node_to_node_operator(server_ids_, normals, reference_nodes_.weights));
  const std::string problem =
      expect_acknowledge(session_.request(request, "AssignContact of the solid body"), "ready");
  assigned_ = problem.empty();
  return in_context("AssignContact of every top-side node with the normal (0, 0, 1)", problem);
}

std::string SolidChecks::contact_solve() {
  require_assignment();
  const std::string what = "ContactSolveRequest of the solid body with g = e + lift (x - 1/2)";
  Eigen::VectorXd obstacle = reference_->free_trace();
  for (long j = 0; j < contact_count(); ++j) {
    obstacle(j) +=
        solid_lift * (reference_nodes_.coordinates[static_cast<std::size_t>(j)].x() - 0.5);
  }
  const ContactSolveResult expected = reference_->solve_contact(obstacle);
  ContactSolution solution;
  if (const std::string problem = read_contact_solution(
          session_.request(contact_solve_request(obstacle), what), contact_count(), solution);
      !problem.empty()) {
    return what + ": " + problem;
  }
  contact_force_ = expected.contact_force;
  const double force_scale = std::max(expected.contact_force.cwiseAbs().maxCoeff(), 1e-300);
  const double length_scale = std::max(obstacle.cwiseAbs().maxCoeff(), solid_lift);
  std::string problem = compare(solution.contact_force, expected.contact_force, tolerance_,
                                force_scale, "contact_force");
  if (problem.empty()) {
    problem = compare(solution.normal_trace, expected.normal_trace, tolerance_, length_scale,
                      "normal_trace");
  }
  return in_context(what, problem);
}

Eigen::VectorXd probe_force(long count) {
  Eigen::VectorXd force(count);
  for (long i = 0; i < count; ++i) {
    force(i) = force_reference / static_cast<double>(count) *
               (1.0 + 0.5 * std::cos(1.3 * static_cast<double>(i)));
  }
  return force;
}

std::string SolidChecks::correction() {
  require_assignment();
  const std::string what = "CorrectionRequest of the solid body";
  const Eigen::VectorXd force = probe_force(contact_count());
  const Eigen::VectorXd expected = reference_->solve_correction(force);
  Eigen::VectorXd trace;
  if (const std::string problem = read_correction(session_.request(correction_request(force), what),
                                                  contact_count(), trace);
      !problem.empty()) {
    return what + ": " + problem;
  }
  return in_context(what, compare(trace, expected, tolerance_, expected.cwiseAbs().maxCoeff(),
                                  "normal_trace (F r)"));
}

std::string SolidChecks::neumann_solve() {
  require_assignment();
  if (!contact_force_) throw NotChecked("needs the contact force of 'solid_contact_solve'");
  const std::string what = "NeumannSolveRequest of the solid body with the contact lambda";
  const Eigen::VectorXd expected = reference_->solve_neumann(*contact_force_);
  Eigen::VectorXd trace;
  if (const std::string problem = read_neumann_solution(
          session_.request(neumann_solve_request(*contact_force_), what), contact_count(), trace);
      !problem.empty()) {
    return what + ": " + problem;
  }
  const double scale = std::max(expected.cwiseAbs().maxCoeff(), solid_lift);
  return in_context(what, compare(trace, expected, tolerance_, scale, "normal_trace"));
}

std::string SolidChecks::fields() {
  require_assignment();
  if (!contact_force_) throw NotChecked("needs the contact force of 'solid_contact_solve'");
  const std::string what = "FieldsRequest of the solid body with the contact lambda";
  const Exchange exchange = session_.request(fields_request(*contact_force_), what);
  if (const std::string problem = expect_content(exchange, Envelope::kFieldsReply);
      !problem.empty()) {
    return what + ": " + problem;
  }
  if (exchange.reply->fields_reply().dimension() != 3) {
    return what + ": FieldsReply.dimension is " +
           std::to_string(exchange.reply->fields_reply().dimension()) + ", expected 3";
  }
  BodyOutput output;
  try {
    output = decode_fields(exchange.reply->fields_reply(), solid_body_name);
  } catch (const std::exception& error) {
    return what + ": the FieldsReply is malformed: " + error.what();
  }
  const BodyOutput expected = make_body_output(*reference_, *contact_force_);
  std::vector<std::string> problems;
  if (output.mesh.nodes != definition_.mesh.nodes) {
    problems.push_back("node_coordinates are not the mesh's nodes in the order of MeshData");
  }
  field_problems(output.point_fields, expected.point_fields, "point field", tolerance_, problems);
  if (output.mesh.element_count() == definition_.mesh.element_count()) {
    field_problems(output.cell_fields, expected.cell_fields, "cell field", tolerance_, problems);
  } else {
    problems.push_back(std::to_string(output.mesh.element_count()) + " cells, expected " +
                       std::to_string(definition_.mesh.element_count()) + " tetrahedra");
  }
  const double scale = std::max(expected.applied_force.norm(), expected.reaction_resultant.norm());
  for (const std::string& problem :
       {compare(output.applied_force, expected.applied_force, tolerance_, scale, "applied_force"),
        compare(output.reaction_resultant, expected.reaction_resultant, tolerance_, scale,
                "reaction_resultant")}) {
    if (!problem.empty()) problems.push_back(problem);
  }
  return problems.empty() ? "" : what + ": " + summarize(problems);
}

}  // namespace

void run_solid_checks(Session& session, unsigned server_minor, bool neumann_offered) {
  SolidChecks(session, server_minor, neumann_offered).run_all();
}

}  // namespace robin::conformance
