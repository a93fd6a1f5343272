#include "numerics/interface_description.hpp"

#include <algorithm>

#include "numerics/elasticity.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

/// The surface of `interface` called `boundary`; InputError listing the known ones otherwise.
const ContactSurfaceDescription& surface_named(const InterfaceDescription& interface,
                                               const std::string& boundary) {
  for (const ContactSurfaceDescription& surface : interface.surfaces) {
    if (surface.boundary == boundary) return surface;
  }
  std::string known;
  for (const ContactSurfaceDescription& surface : interface.surfaces) {
    known += (known.empty() ? "'" : ", '") + surface.boundary + "'";
  }
  throw InputError("'" + boundary + "' is not a contact boundary of the interface description " +
                   "(its contact boundaries: " + (known.empty() ? "none" : known) + ")");
}

}  // namespace

void fill_surface_nodes(const InterfaceDescription& interface, ContactSurfaceDescription& surface) {
  const std::size_t count = interface.node_ids.size();
  for (const int position : surface.facets) {
    if (position < 0 || static_cast<std::size_t>(position) >= count) {
      throw InputError("contact boundary '" + surface.boundary + "': a facet names position " +
                       std::to_string(position) + ", beyond the " + std::to_string(count) +
                       " nodes");
    }
  }
  surface.positions = surface.facets;
  std::sort(surface.positions.begin(), surface.positions.end());
  surface.positions.erase(std::unique(surface.positions.begin(), surface.positions.end()),
                          surface.positions.end());
  std::vector<bool> on_other_surface(count, false);
  for (const ContactSurfaceDescription& other : interface.surfaces) {
    if (other.boundary == surface.boundary) continue;
    for (const int position : other.facets) {
      if (position >= 0 && static_cast<std::size_t>(position) < count) {
        on_other_surface[static_cast<std::size_t>(position)] = true;
      }
    }
  }
  std::vector<int> shared;
  for (const int position : surface.positions) {
    if (on_other_surface[static_cast<std::size_t>(position)]) shared.push_back(position);
  }
  surface.normals.clear();
  surface.weights.clear();
  for (const int position : surface.positions) {
    surface.normals.push_back(interface.normals[static_cast<std::size_t>(position)]);
    surface.weights.push_back(interface.weights[static_cast<std::size_t>(position)]);
  }
  if (shared.empty()) return;
  // The shared nodes from this surface's facets alone: a mesh of the description's nodes
  // (positions as node indices) with the surface as its one boundary, facets oriented outward.
  Mesh mesh;
  mesh.dimension = interface.dimension;
  mesh.nodes = interface.coordinates;
  mesh.node_tags = interface.node_tags;
  BoundaryGroup& group = mesh.boundaries[surface.boundary];
  group.type = surface.facet_type;
  group.connectivity = surface.facets;
  const Eigen::VectorXd weights = boundary_weights(mesh, group);
  const std::vector<Eigen::Vector3d> normals =
      unit_normals(mesh, boundary_normal_sums(mesh, group, true), shared,
                   "boundary " + mesh.boundary_label(group));
  for (std::size_t k = 0; k < shared.size(); ++k) {
    const auto at = std::lower_bound(surface.positions.begin(), surface.positions.end(), shared[k]);
    const auto index = static_cast<std::size_t>(at - surface.positions.begin());
    surface.normals[index] = normals[k];
    surface.weights[index] = weights[shared[k]];
  }
}

InterfaceDescription restrict_to_boundary(const InterfaceDescription& interface,
                                          const std::string& boundary) {
  const ContactSurfaceDescription& found = surface_named(interface, boundary);
  if (interface.surfaces.size() == 1) return interface;
  ContactSurfaceDescription surface = found;
  if (surface.positions.empty() || surface.normals.size() != surface.positions.size() ||
      surface.weights.size() != surface.positions.size()) {
    fill_surface_nodes(interface, surface);
  }
  InterfaceDescription restricted;
  restricted.dimension = interface.dimension;
  restricted.dof_count = interface.dof_count;
  for (const int position : surface.positions) {
    const auto p = static_cast<std::size_t>(position);
    restricted.node_ids.push_back(interface.node_ids[p]);
    restricted.node_tags.push_back(interface.node_tags[p]);
    restricted.coordinates.push_back(interface.coordinates[p]);
    restricted.fixed.push_back(interface.fixed[p]);
  }
  restricted.normals = surface.normals;
  restricted.weights = surface.weights;
  ContactSurfaceDescription own;
  own.boundary = surface.boundary;
  own.facet_type = surface.facet_type;
  own.facets.reserve(surface.facets.size());
  for (const int position : surface.facets) {
    own.facets.push_back(static_cast<int>(
        std::lower_bound(surface.positions.begin(), surface.positions.end(), position) -
        surface.positions.begin()));
  }
  own.positions.resize(surface.positions.size());
  for (std::size_t k = 0; k < own.positions.size(); ++k) own.positions[k] = static_cast<int>(k);
  own.normals = surface.normals;
  own.weights = surface.weights;
  restricted.surfaces.push_back(std::move(own));
  return restricted;
}

}  // namespace robin
