"""The contact boundaries of a body as its InterfaceDescription describes them (protocol 2.0).

For the named boundaries of SetupBody.contact_boundaries:
  node_ids     the union of their nodes, ascending (mesh node indices);
  normals      per node the unit outward normal: the normalised sum over the adjacent segments
               (of every contact boundary) of the segment's outward normal times its length
               (in 3D: over the adjacent faces, times their areas);
  weights      per node m_i = the integral of its shape function over the contact boundaries;
  fixed        per node and component: prescribed by a Dirichlet condition;
  surfaces     per contact boundary its segments as positions into node_ids, each segment with
               the body on its left (outward normal = direction turned clockwise, decided by the
               adjacent domain cell; a segment the mesh has the other way round is reversed);
               in 3D faces whose right-hand normal points out of the body.
"""

import numpy as np

from . import fem


class ContactSurface:
    """One contact boundary: name, segment_type (mesh LINE2 or LINE3; TRIANGLE3 or
    QUADRILATERAL4 faces in 3D), segments (segments x m, positions into
    ContactBoundaries.node_ids, endpoints first, body on the left; faces oriented outward)."""

    def __init__(self, name, segment_type, segments):
        self.name = name
        self.segment_type = segment_type
        self.segments = segments


class ContactBoundaries:
    """node_ids, node_tags, coordinates (n x d), normals (n x d), weights (n), fixed (n x d),
    surfaces (ContactSurface per contact boundary) and node_weights (per mesh node: its weight
    on the contact boundaries, zero elsewhere)."""

    def __init__(self, mesh, names, is_prescribed):
        edge_sets = [fem.facet_set(mesh, name, mesh.boundaries[name]) for name in names]
        self.node_ids = np.unique(np.concatenate([edges.group.nodes() for edges in edge_sets]))
        self.node_tags = mesh.node_tags[self.node_ids]
        self.coordinates = mesh.nodes[self.node_ids]
        normal_sums = sum(fem.boundary_normal_sums(mesh, edges) for edges in edge_sets)
        self.normals = fem.unit_normals(mesh, normal_sums, self.node_ids, names)
        self.node_weights = sum(fem.boundary_weights(mesh, edges) for edges in edge_sets)
        self.weights = self.node_weights[self.node_ids]
        self.fixed = is_prescribed.reshape(-1, mesh.dimension)[self.node_ids]
        self.surfaces = [self._surface(edges) for edges in edge_sets]

    def _surface(self, edges):
        segments = edges.oriented_connectivity()
        positions = np.searchsorted(self.node_ids, segments)
        return ContactSurface(edges.name, edges.group.type, positions)

    def size(self):
        return len(self.node_ids)
