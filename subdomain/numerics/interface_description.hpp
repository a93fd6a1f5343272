#pragma once
// The candidate contact nodes of a body as the body sees them (InterfaceDescription): the
// nodes of all its contact boundaries, and per boundary its segments and its own nodes.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "numerics/mesh.hpp"

namespace robin {

/// One contact boundary of a body within its InterfaceDescription.
struct ContactSurfaceDescription {
  std::string boundary;  // its name (a BodyDefinition::contact_boundaries entry)
  /// The boundary's facets (edges in 2D, faces in 3D) as positions into
  /// InterfaceDescription::node_ids, nodes_per_facet(facet_type) per facet in Gmsh order, each
  /// oriented outward: an edge with the body on its left (the outward normal is the direction
  /// from the first to the second endpoint turned clockwise), a face with its right-hand normal
  /// (corners 0, 1, 2: (x1 - x0) x (x2 - x0)) pointing out of the body.
  FacetType facet_type = FacetType::line2;
  std::vector<int> facets;
  /// The boundary's own nodes as positions into InterfaceDescription::node_ids, ascending (the
  /// distinct entries of `facets`), with their normals and weights from this boundary's
  /// facets alone: what a body with this one contact boundary reports. A node on this
  /// boundary only has the description's normal and weight; one shared with another contact
  /// boundary differs. Empty when not known (a description built by hand): then
  /// restrict_to_boundary() computes them from the facets.
  std::vector<int> positions;
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> weights;
};

/// The candidate contact nodes of a body: the union of the nodes of all its contact
/// boundaries (a node on several boundaries appears once). With several boundaries, a node's
/// weight is the sum of its weights on each boundary (the integral of its shape function over
/// all of them) and its normal the normalized sum over the adjacent facets of every boundary
/// of the facet's outward normal times its measure (the measure-weighted average); the
/// per-boundary values stay in `surfaces` (restrict_to_boundary()). The Python server makes the
/// same choice (python/robin_subdomain/contact_boundaries.py).
struct InterfaceDescription {
  int dimension = 2;                         // the body's: 2 (plane) or 3 (solid)
  std::vector<int> node_ids;                 // mesh node indices, ascending
  std::vector<std::size_t> node_tags;        // the nodes' tags in the mesh file (for messages)
  std::vector<Eigen::Vector3d> coordinates;  // reference positions (z = 0 in 2D)
  std::vector<Eigen::Vector3d> normals;      // unit outward normals from the geometry
  std::vector<double>
      weights;  // m_i = int_{contact boundaries} phi_i ds (length in 2D, area in 3D)
  /// Per node, which of u_x, u_y, u_z a Dirichlet condition prescribes (u_z: false in 2D).
  std::vector<std::array<bool, 3>> fixed;
  /// One per contact boundary, in the order of BodyDefinition::contact_boundaries.
  std::vector<ContactSurfaceDescription> surfaces;
  int dof_count = 0;  // free degrees of freedom of the body
  /// k: the rigid motions the body's Dirichlet conditions leave free (0..3 in 2D, 0..6 in 3D; 0
  /// unless the body
  /// is a floating body held by contact, body_solver.hpp). The coupling needs it: a floating
  /// body's Neumann response is not defined (coupling_scheme.hpp).
  int rigid_modes = 0;
};

/// The description of the nodes of the contact boundary `boundary` alone, as a body with only
/// that contact boundary describes them: its nodes (node ids ascending), their normals and
/// weights from its own facets, one surface with its facets re-indexed. Bit for bit the
/// description itself when it has that one surface only. Throws InputError when `boundary` is
/// not one of the description's surfaces.
InterfaceDescription restrict_to_boundary(const InterfaceDescription& interface,
                                          const std::string& boundary);

/// Fills `surface`'s positions, normals and weights from its facets: the nodes on no other
/// surface of `interface` take the description's normal and weight (what the body computed for
/// them: its sums over the boundaries have no other term there); the shared nodes theirs from
/// this surface's facets (the measure-weighted average of the facets' outward normals, the
/// integral of the shape function), computed from the coordinates. Throws InputError for a
/// position out of range, a facet of zero measure or normals that cancel out.
void fill_surface_nodes(const InterfaceDescription& interface, ContactSurfaceDescription& surface);

}  // namespace robin
