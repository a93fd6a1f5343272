#include "server/reply_encoding.hpp"

#include "mesh_codec.hpp"

namespace robin {
namespace {

/// The first `dimension` components of `vector` (x, y in 2D; x, y, z in 3D).
void add_vector(const Eigen::Vector3d& vector, int dimension,
                google::protobuf::RepeatedField<double>& values) {
  for (int component = 0; component < dimension; ++component) values.Add(vector[component]);
}

void add_values(const Eigen::VectorXd& vector, google::protobuf::RepeatedField<double>& values) {
  values.Reserve(values.size() + static_cast<int>(vector.size()));
  for (double value : vector) values.Add(value);
}

void encode_field(const OutputField& field, protocol::Field& message) {
  message.set_name(field.name);
  message.set_components(static_cast<std::uint32_t>(field.components));
  message.mutable_values()->Assign(field.values.begin(), field.values.end());
}

void encode_mesh(const Mesh& mesh, protocol::FieldsReply& message) {
  if (mesh.dimension == 3) message.set_dimension(3);  // absent (2) for a plane body, as in 2.3
  message.mutable_node_coordinates()->Reserve(mesh.dof_count());
  for (const Eigen::Vector3d& node : mesh.nodes)
    add_vector(node, mesh.dimension, *message.mutable_node_coordinates());
  for (std::size_t tag : mesh.node_tags) message.add_node_tags(static_cast<std::int64_t>(tag));
  message.add_cell_offsets(0);
  for (const ElementBlock& block : mesh.blocks) {
    message.add_cell_types(static_cast<std::uint32_t>(vtk_cell_type(block.type)));
    const std::size_t first = static_cast<std::size_t>(message.connectivity_size());
    for (int node : block.connectivity) message.add_connectivity(node);
    if (block.type == ElementType::tetrahedron10) {
      // VTK's quadratic tetrahedron numbers the midpoints of edges 3-2 and 3-1 (Gmsh's 8, 9)
      // the other way round.
      auto& connectivity = *message.mutable_connectivity();
      for (std::size_t k = first; k + 10 <= static_cast<std::size_t>(connectivity.size());
           k += 10) {
        connectivity.SwapElements(static_cast<int>(k + 8), static_cast<int>(k + 9));
      }
    }
    message.add_cell_offsets(static_cast<std::uint64_t>(message.connectivity_size()));
  }
  for (const auto& [name, group] : mesh.boundaries) {
    protocol::NamedBoundary& boundary = *message.add_boundaries();
    boundary.set_name(name);
    protocol::CellBlock& segments = *boundary.mutable_segments();
    segments.set_type(to_protocol(group.type));
    segments.mutable_connectivity()->Assign(group.connectivity.begin(), group.connectivity.end());
  }
}

}  // namespace

void encode_interface(const std::string& body_name, const InterfaceDescription& interface,
                      protocol::InterfaceDescription& message) {
  message.set_body_name(body_name);
  const int dimension = interface.dimension;
  message.set_dimension(static_cast<std::uint32_t>(dimension));
  message.set_rigid_modes(static_cast<std::uint32_t>(interface.rigid_modes));
  for (std::size_t i = 0; i < interface.node_ids.size(); ++i) {
    message.add_node_ids(interface.node_ids[i]);
    message.add_node_tags(static_cast<std::int64_t>(interface.node_tags[i]));
    add_vector(interface.coordinates[i], dimension, *message.mutable_coordinates());
    add_vector(interface.normals[i], dimension, *message.mutable_normals());
    message.add_weights(interface.weights[i]);
    for (int component = 0; component < dimension; ++component) {
      message.add_fixed(interface.fixed[i][static_cast<std::size_t>(component)]);
    }
  }
  for (const ContactSurfaceDescription& contact_surface : interface.surfaces) {
    protocol::ContactSurface& surface = *message.add_surfaces();
    surface.set_boundary(contact_surface.boundary);
    surface.set_segment_type(to_protocol(contact_surface.facet_type));
    surface.mutable_segments()->Assign(contact_surface.facets.begin(),
                                       contact_surface.facets.end());
  }
}

protocol::SolveStatus to_protocol(QpStatus status) {
  switch (status) {
    case QpStatus::converged:
      return protocol::CONVERGED;
    case QpStatus::not_converged:
      return protocol::NOT_CONVERGED;
    case QpStatus::breakdown:
      return protocol::BREAKDOWN;
  }
  return protocol::SOLVE_STATUS_UNSPECIFIED;
}

void encode_contact_result(const ContactSolveResult& result,
                           protocol::ContactSolveResult& message) {
  add_values(result.normal_trace, *message.mutable_normal_trace());
  add_values(result.contact_force, *message.mutable_contact_force());
  for (bool active : result.active) message.add_active(active);
  message.set_status(to_protocol(result.status));
  message.set_qp_iterations(static_cast<std::uint32_t>(result.iterations));
  message.set_projected_gradient_norm(result.projected_gradient_norm);
  message.set_penetration(result.penetration);
  message.set_complementarity(result.complementarity);
  message.set_compute_seconds(result.seconds);
  message.set_message(result.message);
}

void encode_fields(const BodyOutput& output, protocol::FieldsReply& message) {
  encode_mesh(output.mesh, message);
  for (const OutputField& field : output.point_fields) {
    encode_field(field, *message.add_point_fields());
  }
  for (const OutputField& field : output.cell_fields)
    encode_field(field, *message.add_cell_fields());
  encode_resultants(output, message);
}

void encode_resultants(const BodyOutput& output, protocol::FieldsReply& message) {
  if (output.mesh.dimension == 3) message.set_dimension(3);  // absent (2) for a plane body
  add_vector(output.reaction_resultant, output.mesh.dimension,
             *message.mutable_reaction_resultant());
  add_vector(output.applied_force, output.mesh.dimension, *message.mutable_applied_force());
}

Eigen::VectorXd to_vector(const google::protobuf::RepeatedField<double>& values) {
  Eigen::VectorXd vector(values.size());
  for (int i = 0; i < values.size(); ++i) vector[i] = values[i];
  return vector;
}

}  // namespace robin
