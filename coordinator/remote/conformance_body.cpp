#include "remote/conformance_body.hpp"

#include "mesh_codec.hpp"
#include "numerics/rectangle_mesher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

namespace robin::conformance {

using protocol::Envelope;

namespace {

constexpr int cells_per_side = 4;  // h = 0.25
constexpr double poisson_ratio = 0.3;

Eigen::VectorXd to_vector(const google::protobuf::RepeatedField<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
}

bool all_finite(const google::protobuf::RepeatedField<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

int nodes_per_cell(unsigned vtk_type) {
  switch (vtk_type) {
    case 5:
      return 3;
    case 22:
      return 6;
    case 9:
      return 4;
    default:
      return 0;
  }
}

/// The element blocks of a FieldsReply; returns the element count (or -1 with `problems`).
long cell_block_problems(const protocol::FieldsReply& fields, long node_count,
                         std::vector<std::string>& problems) {
  const int blocks = fields.cell_types_size();
  if (blocks == 0) problems.push_back("cell_types is empty");
  if (fields.cell_offsets_size() != blocks + 1) {
    problems.push_back("cell_offsets has " + std::to_string(fields.cell_offsets_size()) +
                       " values for " + std::to_string(blocks) + " blocks, expected blocks + 1");
    return -1;
  }
  if (fields.cell_offsets(0) != 0 ||
      fields.cell_offsets(blocks) != static_cast<std::uint64_t>(fields.connectivity_size())) {
    problems.push_back("cell_offsets must start at 0 and end at the connectivity's length");
    return -1;
  }
  long cells = 0;
  for (int b = 0; b < blocks; ++b) {
    const int per_cell = nodes_per_cell(fields.cell_types(b));
    const auto length =
        static_cast<long>(fields.cell_offsets(b + 1)) - static_cast<long>(fields.cell_offsets(b));
    if (per_cell == 0)
      problems.push_back("cell type " + std::to_string(fields.cell_types(b)) +
                         " is not 5, 22 or 9");
    if (per_cell == 0 || length < 0 || length % per_cell != 0) return -1;
    cells += length / per_cell;
  }
  for (const std::int64_t index : fields.connectivity()) {
    if (index < 0 || index >= node_count) {
      problems.push_back("connectivity index " + std::to_string(index) + " is not in [0, " +
                         std::to_string(node_count) + ")");
      return -1;
    }
  }
  return cells;
}

void field_size_problems(const google::protobuf::RepeatedPtrField<protocol::Field>& fields,
                         long count, const std::string& kind, std::vector<std::string>& problems) {
  for (const protocol::Field& field : fields) {
    const long expected = count * static_cast<long>(field.components());
    if (field.components() == 0 || field.values_size() != expected) {
      problems.push_back(kind + " '" + field.name() + "' has " +
                         std::to_string(field.values_size()) + " values and " +
                         std::to_string(field.components()) + " components for " +
                         std::to_string(count) + " " + (kind == "point field" ? "nodes" : "cells"));
    }
  }
}

/// The nodes per segment of a 2D segment type; 0 for any other type.
int nodes_per_segment(protocol::CellType type) {
  if (type == protocol::LINE2) return 2;
  if (type == protocol::LINE3) return 3;
  return 0;
}

Eigen::Vector2d point_of(const protocol::InterfaceDescription& description, std::uint32_t node) {
  return {description.coordinates(static_cast<int>(2 * node)),
          description.coordinates(static_cast<int>(2 * node + 1))};
}

Eigen::Vector2d normal_of(const protocol::InterfaceDescription& description, std::uint32_t node) {
  return {description.normals(static_cast<int>(2 * node)),
          description.normals(static_cast<int>(2 * node + 1))};
}

/// The problems of one segment (its node positions, already checked to be in range) of the top
/// edge; returns its length.
double segment_problems(const protocol::InterfaceDescription& description,
                        const std::vector<std::uint32_t>& nodes, const std::string& segment,
                        double tolerance, std::vector<std::string>& problems) {
  for (const std::uint32_t node : nodes) {
    const Eigen::Vector2d x = point_of(description, node);
    if (std::abs(x.y() - 1.0) > tolerance || x.x() < -tolerance || x.x() > 1.0 + tolerance) {
      problems.push_back(segment + ": its node at position " + std::to_string(node) + " (" +
                         number(x.x()) + ", " + number(x.y()) + ") is not on the top edge");
    }
  }
  const Eigen::Vector2d first = point_of(description, nodes[0]);
  const Eigen::Vector2d direction = point_of(description, nodes[1]) - first;
  const double length = direction.norm();
  if (!(length > tolerance * contact_length)) {
    problems.push_back(segment + " has length " + number(length) + ", expected > 0");
    return 0.0;
  }
  if (nodes.size() == 3 &&
      (point_of(description, nodes[2]) - (first + 0.5 * direction)).norm() > tolerance) {
    problems.push_back(segment +
                       ": its third node (LINE3 midpoint) is not halfway between its "
                       "ends");
  }
  const Eigen::Vector2d outward(direction.y() / length, -direction.x() / length);
  for (const std::uint32_t end : {nodes[0], nodes[1]}) {
    const double agreement = outward.dot(normal_of(description, end));
    if (agreement < 1.0 - tolerance) {
      problems.push_back(
          segment + " has the outward normal (" + number(outward.x()) + ", " + number(outward.y()) +
          ") (its direction turned clockwise: the body on "
          "its left), which disagrees with the normal of its node at position " +
          std::to_string(end) + " (dot product " + number(agreement) + "): reversed segment?");
      break;
    }
  }
  return length;
}
}  // namespace

double partial_obstacle(double x) {
  return lift * (0.5 + x);
}

protocol::SetupBody square_body() {
  protocol::SetupBody body;
  body.set_body_name(body_name);
  Mesh square = make_rectangle_mesh(0.0, 0.0, 1.0, 1.0, cells_per_side, cells_per_side,
                                    ElementType::triangle3);
  square.source = "robin-coordinator --check-server: the unit square";
  *body.mutable_mesh() = encode_mesh(square);
  body.set_model(protocol::PLANE_STRAIN);
  body.set_young_modulus(young_modulus);
  body.set_poisson_ratio(poisson_ratio);
  protocol::Dirichlet& support = *body.add_dirichlet();
  support.set_boundary("bottom");
  support.set_x(0.0);
  support.set_y(lift);
  body.add_contact_boundaries("top");
  body.mutable_solver()->set_qp_tolerance(1e-12);
  return body;
}

protocol::SetupBody with_voigt_material(protocol::SetupBody body) {
  const double modulus = body.young_modulus(), nu = body.poisson_ratio();
  double diagonal = 0.0, coupling = 0.0, shear = 0.0;
  if (body.model() == protocol::PLANE_STRESS) {
    const double factor = modulus / (1.0 - nu * nu);
    diagonal = factor;
    coupling = factor * nu;
    shear = factor * (1.0 - nu) / 2.0;
  } else {
    const double factor = modulus / ((1.0 + nu) * (1.0 - 2.0 * nu));
    diagonal = factor * (1.0 - nu);
    coupling = factor * nu;
    shear = factor * (1.0 - 2.0 * nu) / 2.0;
  }
  body.clear_young_modulus();
  body.clear_poisson_ratio();
  for (const double value : {diagonal, coupling, 0.0, coupling, diagonal, 0.0, 0.0, 0.0, shear}) {
    body.add_voigt(value);
  }
  return body;
}

Envelope setup_request(const protocol::SetupBody& body) {
  Envelope envelope;
  *envelope.mutable_setup_body() = body;
  return envelope;
}

Envelope assign_request(const std::vector<ContactNode>& nodes, double normal_length) {
  Envelope envelope;
  protocol::AssignContact& assign = *envelope.mutable_assign_contact();
  assign.add_row_offsets(0);
  for (const ContactNode& node : nodes) {
    // One row per node: (B u)_i = u(node) . (0, normal_length), the top edge's outward normal.
    assign.add_node_ids(node.id);
    assign.add_components(0);
    assign.add_values(0.0);
    assign.add_node_ids(node.id);
    assign.add_components(1);
    assign.add_values(normal_length);
    assign.add_row_offsets(static_cast<std::uint64_t>(assign.values_size()));
    assign.add_weights(1.0);
  }
  return envelope;
}

Envelope contact_solve_request(const Eigen::VectorXd& obstacle, unsigned iteration) {
  Envelope envelope;
  envelope.mutable_contact_solve()->set_iteration(iteration);
  envelope.mutable_contact_solve()->mutable_obstacle()->Assign(obstacle.begin(), obstacle.end());
  return envelope;
}

Envelope correction_request(const Eigen::VectorXd& force) {
  Envelope envelope;
  envelope.mutable_correction()->set_iteration(1);
  envelope.mutable_correction()->mutable_interface_force()->Assign(force.begin(), force.end());
  return envelope;
}

Envelope neumann_solve_request(const Eigen::VectorXd& force) {
  Envelope envelope;
  envelope.mutable_neumann_solve()->set_iteration(1);
  envelope.mutable_neumann_solve()->mutable_contact_force()->Assign(force.begin(), force.end());
  return envelope;
}

Envelope fields_request(const Eigen::VectorXd& force) {
  Envelope envelope;
  envelope.mutable_fields()->mutable_contact_force()->Assign(force.begin(), force.end());
  return envelope;
}

Envelope end_run_request() {
  Envelope envelope;
  envelope.mutable_end_run();
  return envelope;
}

std::vector<ContactNode> pair_order(const protocol::InterfaceDescription& description) {
  std::vector<ContactNode> nodes;
  for (int i = 0; i < description.node_ids_size(); ++i) {
    nodes.push_back({description.node_ids(i), description.coordinates(2 * i)});
  }
  std::vector<ContactNode> order = nodes;
  std::stable_sort(order.begin(), order.end(),
                   [](const ContactNode& a, const ContactNode& b) { return a.x > b.x; });
  const bool same_as_server =
      std::equal(order.begin(), order.end(), nodes.begin(),
                 [](const ContactNode& a, const ContactNode& b) { return a.id == b.id; });
  if (same_as_server) std::reverse(order.begin(), order.end());
  return order;
}

std::string interface_size_problems(const protocol::InterfaceDescription& description) {
  const int count = description.node_ids_size();
  std::vector<std::string> problems;
  const auto expect_size = [&](const std::string& field, int size, int expected) {
    if (size != expected) {
      problems.push_back(field + " has " + std::to_string(size) + " values for " +
                         std::to_string(count) + " node_ids, expected " + std::to_string(expected));
    }
  };
  expect_size("node_tags", description.node_tags_size(), count);
  expect_size("coordinates", description.coordinates_size(), 2 * count);
  expect_size("normals", description.normals_size(), 2 * count);
  expect_size("weights", description.weights_size(), count);
  expect_size("fixed", description.fixed_size(), 2 * count);
  if (count < 2) {
    problems.push_back(std::to_string(count) +
                       " node_ids for the contact boundary 'top', expected at least its two "
                       "end points");
  }
  if (!all_finite(description.coordinates()) || !all_finite(description.normals()) ||
      !all_finite(description.weights())) {
    problems.push_back("coordinates, normals or weights contain a non-finite value");
  }
  return summarize(problems);
}

std::vector<std::string> interface_node_problems(const protocol::InterfaceDescription& description,
                                                 double tolerance) {
  std::vector<std::string> problems;
  std::set<std::int64_t> seen;
  for (int i = 0; i < description.node_ids_size(); ++i) {
    const std::int64_t id = description.node_ids(i);
    const double x = description.coordinates(2 * i), y = description.coordinates(2 * i + 1);
    const std::string node =
        "node id " + std::to_string(id) + " at (" + number(x) + ", " + number(y) + ")";
    if (!seen.insert(id).second) problems.push_back("node id " + std::to_string(id) + " repeats");
    if (id < 0 || id >= (std::int64_t{1} << 31)) {
      problems.push_back(node + ": ids must lie in [0, 2^31)");
    }
    if (std::abs(y - 1.0) > tolerance || x < -tolerance || x > 1.0 + tolerance) {
      problems.push_back(node + " is not on the top edge y = 1, 0 <= x <= 1");
    }
    const double nx = description.normals(2 * i), ny = description.normals(2 * i + 1);
    if (std::abs(nx) > tolerance || std::abs(ny - 1.0) > tolerance) {
      problems.push_back(node + " has normal (" + number(nx) + ", " + number(ny) +
                         "), expected the unit outward normal (0, 1)");
    }
    if (!(description.weights(i) > 0.0)) {
      problems.push_back(node + " has weight " + number(description.weights(i)) + ", expected > 0");
    }
    if (description.fixed(2 * i) || description.fixed(2 * i + 1)) {
      problems.push_back(node + " is flagged fixed, but no Dirichlet condition reaches the top");
    }
  }
  return problems;
}

std::vector<std::string> interface_weight_problems(
    const protocol::InterfaceDescription& description, double tolerance) {
  std::vector<std::pair<double, double>> by_x;  // (x, weight)
  for (int i = 0; i < description.node_ids_size(); ++i) {
    by_x.emplace_back(description.coordinates(2 * i), description.weights(i));
  }
  std::sort(by_x.begin(), by_x.end());
  std::vector<std::string> problems;
  double sum = 0.0;
  for (std::size_t i = 0; i < by_x.size(); ++i) {
    sum += by_x[i].second;
    const double left = i == 0 ? by_x[i].first : by_x[i - 1].first;
    const double right = i + 1 == by_x.size() ? by_x[i].first : by_x[i + 1].first;
    const double expected = 0.5 * (right - left);
    if (std::abs(by_x[i].second - expected) > tolerance * contact_length) {
      problems.push_back("the weight of the node at x = " + number(by_x[i].first) + " is " +
                         number(by_x[i].second) + ", expected half its adjacent edges " +
                         number(expected));
    }
  }
  if (std::abs(by_x.front().first) > tolerance || std::abs(by_x.back().first - 1.0) > tolerance) {
    problems.push_back("the nodes do not span the top edge from x = 0 to x = 1");
  }
  if (std::abs(sum - contact_length) > tolerance * contact_length) {
    problems.push_back("the weights sum to " + number(sum) +
                       ", expected the contact boundary's length 1");
  }
  return problems;
}

std::vector<std::string> interface_surface_problems(
    const protocol::InterfaceDescription& description, double tolerance) {
  if (description.surfaces_size() != 1) {
    return {"surfaces has " + std::to_string(description.surfaces_size()) +
            " entries, expected one per contact boundary (the checker sends 'top' only)"};
  }
  const protocol::ContactSurface& surface = description.surfaces(0);
  const int per_segment = nodes_per_segment(surface.segment_type());
  const auto node_count = static_cast<std::uint32_t>(description.node_ids_size());
  std::vector<std::string> problems;
  if (surface.boundary() != "top") {
    problems.push_back("surfaces[0].boundary is '" + surface.boundary() + "', expected 'top'");
  }
  if (per_segment == 0 || surface.segments_size() == 0 ||
      surface.segments_size() % per_segment != 0) {
    problems.push_back("surfaces[0] has segment_type " +
                       protocol::CellType_Name(surface.segment_type()) + " and " +
                       std::to_string(surface.segments_size()) +
                       " segment entries: expected LINE2 or LINE3 and a positive multiple of its "
                       "nodes per segment");
    return problems;
  }
  for (const std::uint32_t position : surface.segments()) {
    if (position >= node_count) {
      problems.push_back("surfaces[0].segments holds the position " + std::to_string(position) +
                         ", not less than the node count " + std::to_string(node_count));
      return problems;
    }
  }
  std::vector<bool> used(node_count, false);
  double length = 0.0;
  for (int first = 0; first < surface.segments_size(); first += per_segment) {
    const std::vector<std::uint32_t> nodes(surface.segments().begin() + first,
                                           surface.segments().begin() + first + per_segment);
    for (const std::uint32_t node : nodes) used[node] = true;
    length += segment_problems(description, nodes,
                               "segment " + std::to_string(first / per_segment) + " of 'top'",
                               tolerance, problems);
  }
  if (std::abs(length - contact_length) > tolerance * contact_length) {
    problems.push_back("the segments of 'top' are " + number(length) +
                       " long together, expected the edge's length 1");
  }
  const auto unused = std::find(used.begin(), used.end(), false);
  if (unused != used.end()) {
    problems.push_back("the node at position " + std::to_string(unused - used.begin()) +
                       " is in no segment of 'top'");
  }
  return problems;
}

std::string read_contact_solution(const Exchange& exchange, long count, ContactSolution& solution) {
  if (const std::string problem = expect_content(exchange, Envelope::kContactResult);
      !problem.empty()) {
    return problem;
  }
  const protocol::ContactSolveResult& result = exchange.reply->contact_result();
  if (result.status() != protocol::CONVERGED) {
    return "status " + protocol::SolveStatus_Name(result.status()) +
           ", expected CONVERGED (message: '" + result.message() + "')";
  }
  if (result.normal_trace_size() != count || result.contact_force_size() != count ||
      (result.active_size() != 0 && result.active_size() != count)) {
    return "normal_trace, contact_force and active have " +
           std::to_string(result.normal_trace_size()) + ", " +
           std::to_string(result.contact_force_size()) + " and " +
           std::to_string(result.active_size()) + " values for " + std::to_string(count) +
           " contact nodes (active may be empty)";
  }
  if (!all_finite(result.normal_trace()) || !all_finite(result.contact_force())) {
    return "normal_trace or contact_force contains a non-finite value";
  }
  solution.normal_trace = to_vector(result.normal_trace());
  solution.contact_force = to_vector(result.contact_force());
  return "";
}

std::vector<std::string> signorini_problems(const ContactSolution& solution,
                                            const Eigen::VectorXd& obstacle, double tolerance) {
  const double force_scale = std::max(solution.contact_force.cwiseAbs().maxCoeff(), 1e-300);
  const double length_scale = std::max(obstacle.cwiseAbs().maxCoeff(), lift);
  std::vector<std::string> problems;
  for (Eigen::Index i = 0; i < obstacle.size(); ++i) {
    const double force = solution.contact_force(i), trace = solution.normal_trace(i);
    const double clearance = obstacle(i) - trace;
    std::ostringstream problem;  // (a stream: GCC 12 warns falsely on long string sums here)
    problem.precision(6);
    if (force < -tolerance * force_scale) {
      problem << "contact_force[" << i << "] = " << force << " < 0";
    } else if (-clearance > tolerance * length_scale) {
      problem << "normal_trace[" << i << "] = " << trace << " exceeds the obstacle " << obstacle(i);
    } else if (std::abs(force * clearance) > tolerance * force_scale * length_scale) {
      problem << "complementarity[" << i << "]: lambda (g - u_N) = " << force * clearance
              << " (lambda " << force << ", g - u_N " << clearance << ")";
    }
    if (!problem.str().empty()) problems.push_back(problem.str());
  }
  return problems;
}

/// Checks a reply's normal_trace (one finite value per contact node) and copies it to `trace`;
/// returns the problem in plain words, or "".
std::string read_normal_trace(const google::protobuf::RepeatedField<double>& values, long count,
                              Eigen::VectorXd& trace) {
  if (values.size() != count) {
    return "normal_trace has " + std::to_string(values.size()) + " values for " +
           std::to_string(count) + " contact nodes";
  }
  if (!all_finite(values)) return "normal_trace contains a non-finite value";
  trace = to_vector(values);
  return "";
}

std::string read_correction(const Exchange& exchange, long count, Eigen::VectorXd& trace) {
  if (const std::string problem = expect_content(exchange, Envelope::kCorrectionResult);
      !problem.empty()) {
    return problem;
  }
  const protocol::CorrectionResult& result = exchange.reply->correction_result();
  return read_normal_trace(result.normal_trace(), count, trace);
}

std::string read_neumann_solution(const Exchange& exchange, long count, Eigen::VectorXd& trace) {
  if (const std::string problem = expect_content(exchange, Envelope::kNeumannResult);
      !problem.empty()) {
    return problem;
  }
  const protocol::NeumannSolveResult& result = exchange.reply->neumann_result();
  return read_normal_trace(result.normal_trace(), count, trace);
}

std::vector<std::string> fields_structure_problems(const protocol::FieldsReply& fields) {
  std::vector<std::string> problems;
  const long node_count = fields.node_coordinates_size() / 2;
  if (fields.node_coordinates_size() % 2 != 0 || node_count < 3) {
    problems.push_back("node_coordinates has " + std::to_string(fields.node_coordinates_size()) +
                       " values, expected (x, y) of every mesh node");
    return problems;
  }
  if (fields.node_tags_size() != 0 && fields.node_tags_size() != node_count) {
    problems.push_back("node_tags has " + std::to_string(fields.node_tags_size()) + " values for " +
                       std::to_string(node_count) + " nodes (or give none)");
  }
  const long cells = cell_block_problems(fields, node_count, problems);
  field_size_problems(fields.point_fields(), node_count, "point field", problems);
  if (cells >= 0) field_size_problems(fields.cell_fields(), cells, "cell field", problems);
  if (fields.reaction_resultant_size() % 2 != 0 || fields.reaction_resultant_size() > 2 ||
      fields.applied_force_size() % 2 != 0 || fields.applied_force_size() > 2) {
    problems.push_back("reaction_resultant and applied_force must have 2 values or none");
  }
  return problems;
}

Eigen::Vector2d resultant(const google::protobuf::RepeatedField<double>& values) {
  return values.size() == 2 ? Eigen::Vector2d(values[0], values[1]) : Eigen::Vector2d::Zero();
}

std::string most_pushed_top_node(const protocol::FieldsReply& fields, double tolerance,
                                 double& abscissa) {
  const protocol::Field* displacement = nullptr;
  for (const protocol::Field& field : fields.point_fields()) {
    if (field.name() == "displacement") displacement = &field;
  }
  const int node_count = fields.node_coordinates_size() / 2;
  if (displacement == nullptr || displacement->components() != 2 ||
      displacement->values_size() != 2 * node_count) {
    throw NotChecked("needs the FieldsReply point field 'displacement' (2 components per node)");
  }
  double lowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < node_count; ++k) {
    const double y = fields.node_coordinates(2 * k + 1);
    if (std::abs(y - 1.0) > tolerance || !(displacement->values(2 * k + 1) < lowest)) continue;
    lowest = displacement->values(2 * k + 1);
    abscissa = fields.node_coordinates(2 * k);
  }
  return std::isfinite(lowest) ? "" : "the FieldsReply has no node on the top edge y = 1";
}

}  // namespace robin::conformance
