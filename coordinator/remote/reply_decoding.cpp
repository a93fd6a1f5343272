#include "remote/reply_decoding.hpp"

#include <google/protobuf/repeated_field.h>

#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include "numerics/errors.hpp"
#include "numerics/interface_description.hpp"

namespace robin {

namespace {

template <typename Repeated>
void expect_size(const Repeated& values, long expected, const std::string& what) {
  if (static_cast<long>(values.size()) != expected) {
    throw MalformedReply(what + " has " + std::to_string(values.size()) + " values, expected " +
                         std::to_string(expected));
  }
}

/// Throws MalformedReply naming `what` and the first entry that is NaN or infinite.
void expect_finite(const google::protobuf::RepeatedField<double>& values, const std::string& what) {
  for (int i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw MalformedReply(what + "[" + std::to_string(i) + "] is " + std::to_string(values[i]) +
                           ", not a finite number");
    }
  }
}

Eigen::VectorXd to_vector(const google::protobuf::RepeatedField<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
}

/// Contact forces are compressive, lambda >= 0; a negative entry beyond round-off (1e-12 of the
/// largest) is a sign-convention error of the server (docs/protocol.md, "Signs").
void expect_compressive(const Eigen::VectorXd& force) {
  const double round_off = 1e-12 * (force.size() == 0 ? 0.0 : force.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < force.size(); ++i) {
    if (force[i] < -round_off) {
      throw MalformedReply("contact_force[" + std::to_string(i) +
                           "] = " + std::to_string(force[i]) +
                           " is negative (contact forces are compressive: lambda >= 0)");
    }
  }
}

/// `dimension` values per point (z = 0 in 2D).
std::vector<Eigen::Vector3d> to_points(const google::protobuf::RepeatedField<double>& values,
                                       int dimension) {
  std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(values.size() / dimension),
                                      Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int component = 0; component < dimension; ++component) {
      points[i][component] = values[static_cast<int>(i) * dimension + component];
    }
  }
  return points;
}

/// FieldsReply.dimension: 2 or 3, and 2 when absent (0: a server older than 2.4).
int checked_dimension(std::uint32_t dimension, const std::string& what) {
  if (dimension == 0) return 2;
  if (dimension != 2 && dimension != 3) {
    throw MalformedReply(what + " is " + std::to_string(dimension) + ", expected 2 or 3");
  }
  return static_cast<int>(dimension);
}

/// The facet (boundary cell) type of a mesh of `dimension`: LINE2, LINE3 in 2D; TRIANGLE3,
/// TRIANGLE6, QUADRILATERAL4 in 3D; nullopt otherwise.
std::optional<FacetType> facet_type_of(protocol::CellType type, int dimension) {
  if (dimension == 2) {
    if (type == protocol::LINE2) return FacetType::line2;
    if (type == protocol::LINE3) return FacetType::line3;
    return std::nullopt;
  }
  if (type == protocol::TRIANGLE3) return FacetType::triangle3;
  if (type == protocol::TRIANGLE6) return FacetType::triangle6;
  if (type == protocol::QUADRILATERAL4) return FacetType::quadrilateral4;
  return std::nullopt;
}

std::string facet_type_names(int dimension) {
  return dimension == 2 ? "LINE2 or LINE3" : "TRIANGLE3, TRIANGLE6 or QUADRILATERAL4";
}

QpStatus to_qp_status(protocol::SolveStatus status) {
  switch (status) {
    case protocol::CONVERGED:
      return QpStatus::converged;
    case protocol::NOT_CONVERGED:
      return QpStatus::not_converged;
    case protocol::BREAKDOWN:
      return QpStatus::breakdown;
    default:
      throw MalformedReply("the contact result has no solve status");
  }
}

OutputField decode_field(const protocol::Field& message, long count, const std::string& where) {
  OutputField field;
  field.name = message.name();
  field.components = static_cast<int>(message.components());
  if (field.name.empty() || field.components < 1) {
    throw MalformedReply(where + " field '" + field.name + "' has no name or no components");
  }
  expect_size(message.values(), field.components * count, where + " field '" + field.name + "'");
  field.values.assign(message.values().begin(), message.values().end());
  if (field.name == "stress" && field.components == 3) field.component_names = {"xx", "yy", "xy"};
  if (field.name == "stress" && field.components == 6) {
    field.component_names = stress_tensor_components();
  }
  return field;
}

/// The named boundaries of the output mesh: names unique and non-empty, LINE2 or LINE3 segments
/// (2D) or TRIANGLE3, TRIANGLE6 or QUADRILATERAL4 faces (3D), node indices checked against the
/// nodes.
std::map<std::string, BoundaryGroup> decode_boundaries(const protocol::FieldsReply& message,
                                                       long node_count, int dimension) {
  std::map<std::string, BoundaryGroup> boundaries;
  for (int g = 0; g < message.boundaries_size(); ++g) {
    const protocol::NamedBoundary& boundary = message.boundaries(g);
    const std::string what = "boundaries[" + std::to_string(g) + "]";
    if (boundary.name().empty() || boundaries.count(boundary.name()) != 0) {
      throw MalformedReply(what + " has an empty or repeated name '" + boundary.name() + "'");
    }
    const std::optional<FacetType> type = facet_type_of(boundary.segments().type(), dimension);
    if (!type) {
      throw MalformedReply(what + " ('" + boundary.name() + "') has segments that are not " +
                           facet_type_names(dimension));
    }
    BoundaryGroup group;
    group.type = *type;
    const auto& connectivity = boundary.segments().connectivity();
    if (connectivity.size() % nodes_per_facet(group.type) != 0) {
      throw MalformedReply(
          what + " ('" + boundary.name() + "') has " + std::to_string(connectivity.size()) +
          " segment nodes, not a multiple of " + std::to_string(nodes_per_facet(group.type)));
    }
    for (const std::uint32_t node : connectivity) {
      if (static_cast<long>(node) >= node_count) {
        throw MalformedReply(what + " ('" + boundary.name() + "') refers to node " +
                             std::to_string(node) + " of " + std::to_string(node_count));
      }
      group.connectivity.push_back(static_cast<int>(node));
    }
    boundaries.emplace(boundary.name(), std::move(group));
  }
  return boundaries;
}

/// Element blocks from cell types, offsets and connectivity; indices checked against the nodes.
std::vector<ElementBlock> decode_blocks(const protocol::FieldsReply& message, long node_count,
                                        int dimension) {
  const long block_count = message.cell_types_size();
  // no mesh at all: the reply of a server that wrote the file itself (protocol 2.5)
  if (block_count == 0 && message.cell_offsets().empty()) return {};
  expect_size(message.cell_offsets(), block_count + 1, "cell_offsets");
  std::vector<ElementBlock> blocks;
  for (long b = 0; b < block_count; ++b) {
    ElementBlock block;
    block.type = element_type_of_vtk_cell(message.cell_types(b));
    if (element_dimension(block.type) != dimension) {
      throw MalformedReply("element block " + std::to_string(b) + " has VTK cell type " +
                           std::to_string(message.cell_types(b)) + ", not a cell of dimension " +
                           std::to_string(dimension));
    }
    const auto begin = message.cell_offsets(b), end = message.cell_offsets(b + 1);
    const auto per_element = static_cast<std::uint64_t>(nodes_per_element(block.type));
    if (begin > end || end > static_cast<std::uint64_t>(message.connectivity_size()) ||
        (end - begin) % per_element != 0) {
      throw MalformedReply("element block " + std::to_string(b) + " has inconsistent offsets");
    }
    for (auto k = begin; k < end; ++k) {
      const auto node = message.connectivity(static_cast<int>(k));
      if (node < 0 || node >= node_count) {
        throw MalformedReply("element block " + std::to_string(b) + " refers to node " +
                             std::to_string(node) + " of " + std::to_string(node_count));
      }
      block.connectivity.push_back(static_cast<int>(node));
    }
    if (block.type == ElementType::tetrahedron10) {
      // VTK's node order to Gmsh's (the mesh's): the midpoints of edges 1-3 and 2-3 swap.
      for (std::size_t k = 0; k + 10 <= block.connectivity.size(); k += 10) {
        std::swap(block.connectivity[k + 8], block.connectivity[k + 9]);
      }
    }
    blocks.push_back(std::move(block));
  }
  return blocks;
}

Eigen::Vector3d decode_resultant(const google::protobuf::RepeatedField<double>& values,
                                 int dimension, const std::string& what) {
  if (values.empty()) return Eigen::Vector3d::Zero();
  expect_size(values, dimension, what);
  return to_points(values, dimension).front();
}

}  // namespace

ElementType element_type_of_vtk_cell(unsigned cell_type) {
  switch (cell_type) {
    case 5:
      return ElementType::triangle3;
    case 22:
      return ElementType::triangle6;
    case 9:
      return ElementType::quadrilateral4;
    case 10:
      return ElementType::tetrahedron4;
    case 24:
      return ElementType::tetrahedron10;
    case 12:
      return ElementType::hexahedron8;
    default:
      throw MalformedReply("unknown VTK cell type " + std::to_string(cell_type) +
                           " (expected 5, 22 or 9; 10, 24 or 12 in 3D)");
  }
}

/// One contact surface: its segments (positions into node_ids, checked in range), and its own
/// nodes with their normals and weights (fill_surface_nodes).
ContactSurfaceDescription decode_surface(const protocol::InterfaceDescription& message, int k,
                                         int dimension) {
  const protocol::ContactSurface& surface = message.surfaces(k);
  const std::string field = "surfaces[" + std::to_string(k) + "]";
  const std::optional<FacetType> type = facet_type_of(surface.segment_type(), dimension);
  if (!type) {
    throw MalformedReply(field + ".segment_type is not " + facet_type_names(dimension));
  }
  const int nodes_per_segment = nodes_per_facet(*type);
  if (surface.segments_size() % nodes_per_segment != 0) {
    throw MalformedReply(field + ".segments has " + std::to_string(surface.segments_size()) +
                         " entries, not a multiple of " + std::to_string(nodes_per_segment));
  }
  for (const std::uint32_t position : surface.segments()) {
    if (position >= static_cast<std::uint32_t>(message.node_ids_size())) {
      throw MalformedReply(field + ".segments names position " + std::to_string(position) +
                           ", beyond the " + std::to_string(message.node_ids_size()) + " nodes");
    }
  }
  ContactSurfaceDescription decoded;
  decoded.boundary = surface.boundary();
  decoded.facet_type = *type;
  decoded.facets.assign(surface.segments().begin(), surface.segments().end());
  return decoded;
}

/// The contact surfaces: at least one, names distinct; then each one's own nodes.
void decode_surfaces(const protocol::InterfaceDescription& message,
                     InterfaceDescription& interface) {
  if (message.surfaces_size() == 0) {
    throw MalformedReply("surfaces is empty, expected one per contact boundary");
  }
  for (int k = 0; k < message.surfaces_size(); ++k) {
    interface.surfaces.push_back(decode_surface(message, k, interface.dimension));
    for (int j = 0; j < k; ++j) {
      if (interface.surfaces[static_cast<std::size_t>(j)].boundary ==
          interface.surfaces.back().boundary) {
        throw MalformedReply("surfaces[" + std::to_string(k) + "] repeats the boundary '" +
                             interface.surfaces.back().boundary + "'");
      }
    }
  }
  for (ContactSurfaceDescription& surface : interface.surfaces) {
    try {
      fill_surface_nodes(interface, surface);
    } catch (const InputError& error) {
      throw MalformedReply(std::string("surfaces: ") + error.what());
    }
  }
}

InterfaceDescription decode_interface(const protocol::InterfaceDescription& message) {
  const long count = message.node_ids_size();
  if (message.dimension() != 2 && message.dimension() != 3) {
    throw MalformedReply("dimension is " + std::to_string(message.dimension()) +
                         ", expected 2 (or 3: a solid body)");
  }
  const int dimension = static_cast<int>(message.dimension());
  expect_size(message.node_tags(), count, "node_tags");
  expect_size(message.coordinates(), dimension * count, "coordinates");
  expect_size(message.normals(), dimension * count, "normals");
  expect_size(message.weights(), count, "weights");
  expect_size(message.fixed(), dimension * count, "fixed");
  expect_finite(message.coordinates(), "coordinates");
  expect_finite(message.normals(), "normals");
  expect_finite(message.weights(), "weights");
  InterfaceDescription interface;
  interface.dimension = dimension;
  interface.node_ids.assign(message.node_ids().begin(), message.node_ids().end());
  interface.node_tags.assign(message.node_tags().begin(), message.node_tags().end());
  interface.coordinates = to_points(message.coordinates(), dimension);
  interface.normals = to_points(message.normals(), dimension);
  interface.weights.assign(message.weights().begin(), message.weights().end());
  interface.fixed.assign(static_cast<std::size_t>(count), {false, false, false});
  for (long i = 0; i < count; ++i) {
    for (int component = 0; component < dimension; ++component) {
      interface.fixed[static_cast<std::size_t>(i)][static_cast<std::size_t>(component)] =
          message.fixed(static_cast<int>(dimension * i + component));
    }
  }
  decode_surfaces(message, interface);
  interface.dof_count = static_cast<int>(message.dof_count());
  const unsigned most_rigid_modes = dimension == 2 ? 3 : 6;
  if (message.rigid_modes() > most_rigid_modes) {
    throw MalformedReply(
        "rigid_modes is " + std::to_string(message.rigid_modes()) +
        (dimension == 2 ? ", at most 3 in two dimensions" : ", at most 6 in three dimensions"));
  }
  interface.rigid_modes = static_cast<int>(message.rigid_modes());
  return interface;
}

ContactSolveResult decode_contact_result(const protocol::ContactSolveResult& message,
                                         long contact_size) {
  ContactSolveResult result;
  result.status = to_qp_status(message.status());
  result.message = message.message();
  if (result.status == QpStatus::breakdown) return result;  // values are not usable
  expect_size(message.normal_trace(), contact_size, "normal_trace");
  expect_size(message.contact_force(), contact_size, "contact_force");
  expect_finite(message.normal_trace(), "normal_trace");
  expect_finite(message.contact_force(), "contact_force");
  result.normal_trace = to_vector(message.normal_trace());
  result.contact_force = to_vector(message.contact_force());
  expect_compressive(result.contact_force);
  if (message.active_size() == 0) {
    for (long i = 0; i < contact_size; ++i) result.active.push_back(result.contact_force[i] > 0);
  } else {
    expect_size(message.active(), contact_size, "active");
    result.active.assign(message.active().begin(), message.active().end());
  }
  result.iterations = static_cast<int>(message.qp_iterations());
  result.projected_gradient_norm = message.projected_gradient_norm();
  result.penetration = message.penetration();
  result.complementarity = message.complementarity();
  result.seconds = message.compute_seconds();
  return result;
}

CorrectionSolveResult decode_correction_result(const protocol::CorrectionResult& message,
                                               long contact_size) {
  expect_size(message.normal_trace(), contact_size, "normal_trace");
  expect_finite(message.normal_trace(), "normal_trace");
  return {to_vector(message.normal_trace()), message.compute_seconds()};
}

CorrectionSolveResult decode_neumann_result(const protocol::NeumannSolveResult& message,
                                            long contact_size) {
  expect_size(message.normal_trace(), contact_size, "normal_trace");
  expect_finite(message.normal_trace(), "normal_trace");
  return {to_vector(message.normal_trace()), message.compute_seconds()};
}

BodyOutput decode_fields(const protocol::FieldsReply& message, const std::string& body_name) {
  BodyOutput output;
  output.body_name = body_name;
  const int dimension = checked_dimension(message.dimension(), "dimension");
  output.mesh.dimension = dimension;
  const long node_count = message.node_coordinates_size() / dimension;
  expect_size(message.node_coordinates(), dimension * node_count, "node_coordinates");
  output.mesh.nodes = to_points(message.node_coordinates(), dimension);
  if (message.node_tags_size() != 0) expect_size(message.node_tags(), node_count, "node_tags");
  output.mesh.node_tags.assign(message.node_tags().begin(), message.node_tags().end());
  output.mesh.blocks = decode_blocks(message, node_count, dimension);
  output.mesh.boundaries = decode_boundaries(message, node_count, dimension);
  const long element_count = static_cast<long>(output.mesh.element_count());
  for (const protocol::Field& field : message.point_fields()) {
    output.point_fields.push_back(decode_field(field, node_count, "point"));
  }
  for (const protocol::Field& field : message.cell_fields()) {
    output.cell_fields.push_back(decode_field(field, element_count, "cell"));
  }
  output.reaction_resultant =
      decode_resultant(message.reaction_resultant(), dimension, "reaction_resultant");
  output.applied_force = decode_resultant(message.applied_force(), dimension, "applied_force");
  return output;
}

}  // namespace robin
