"""Finite-element assembly of linear elasticity on a Mesh: plane (P1, P2 triangles, Q1 quads)
and, since protocol 2.4, solid (P1 tetrahedra, Q1 hexahedra), one code path for both.

Degrees of freedom: node i has u_x at d i, u_y at d i + 1 (and u_z at d i + 2 in 3D). Voigt
order (xx, yy, xy) in 2D, (xx, yy, zz, yz, xz, xy) in 3D, engineering shear strains.
Quadrature degrees are those of the C++ implementation (subdomain/numerics/elasticity.cpp):
stiffness exact on affine elements (1 for P1, 2 for P2, the 2 x 2 (x 2) Gauss rule for Q1);
loads and boundary weights with two degrees more than the shape functions squared (4, or 6 for
quadratic elements and edges). Boundary facets are edges (EdgeSet) in 2D, faces (FaceSet:
3-node triangles, 4-node quadrilaterals) in 3D, each oriented outward by its adjacent cell.
"""

import numpy as np
import scipy.sparse

from . import element
from .errors import InputError
from .material import von_mises
from .mesh import (CORNER_COUNT, HEXAHEDRON8, LINE3, NODES_PER_ELEMENT, QUADRILATERAL4,
                   TETRAHEDRON4, TRIANGLE3, TRIANGLE6)

STIFFNESS_DEGREE = {TRIANGLE3: 1, TRIANGLE6: 2, QUADRILATERAL4: 3, TETRAHEDRON4: 1,
                    HEXAHEDRON8: 3}
LOAD_DEGREE = {TRIANGLE3: 4, TRIANGLE6: 6, QUADRILATERAL4: 4, TETRAHEDRON4: 4, HEXAHEDRON8: 4}


def edge_load_degree(edge_type):
    return 6 if edge_type == LINE3 else 4


def _describe_element(mesh, element_type, nodes):
    tags = ", ".join(str(mesh.node_tags[node]) for node in nodes)
    return "mesh element %s with node tags (%s)" % (element_type, tags)


def jacobians(coordinates, element_type, reference):
    """Jacobian matrices (elements x d x d) and their determinants (elements) at one reference
    point, for element node coordinates (elements x k x d): J_ij = sum_k x_k,i dN_k/dxi_j."""
    _, reference_gradients = element.shape_functions(element_type, reference)
    jacobian = np.einsum("eki,kj->eij", coordinates, reference_gradients)
    if jacobian.shape[1] == 3:
        return jacobian, np.linalg.det(jacobian)
    determinant = jacobian[:, 0, 0] * jacobian[:, 1, 1] - jacobian[:, 0, 1] * jacobian[:, 1, 0]
    return jacobian, determinant


def _inverse(jacobian, determinant):
    """J^-1 per element (2 x 2 by cofactors, 3 x 3 by LU); the determinants are positive."""
    if jacobian.shape[1] == 3:
        return np.linalg.inv(jacobian)
    inverse = np.empty_like(jacobian)
    inverse[:, 0, 0] = jacobian[:, 1, 1] / determinant
    inverse[:, 1, 1] = jacobian[:, 0, 0] / determinant
    inverse[:, 0, 1] = -jacobian[:, 0, 1] / determinant
    inverse[:, 1, 0] = -jacobian[:, 1, 0] / determinant
    return inverse


def format_reference(reference):
    return "(%s)" % ", ".join("%g" % value for value in reference)


def jacobian_check_points(element_type):
    """The reference points where an element's Jacobian must be positive: its nodes (corners
    and midpoints), its centroid and the points of every quadrature rule used on it."""
    points = [element.reference_nodes(element_type), [element.reference_centroid(element_type)]]
    for degree in (STIFFNESS_DEGREE[element_type], LOAD_DEGREE[element_type]):
        points.append(element.element_quadrature(element_type, degree)[0])
    return np.vstack(points)


def element_points(mesh, block, reference):
    """Shape values N (k), physical gradients (elements x k x d), Jacobian determinants and
    positions (elements x d) of every element of `block` at one reference point.
    J_ij = dx_i/dxi_j = sum_k x_k,i dN_k/dxi_j; dN/dx = dN/dxi J^-1."""
    values, reference_gradients = element.shape_functions(block.type, reference)
    coordinates = mesh.nodes[block.connectivity]                      # e x k x d
    jacobian, determinant = jacobians(coordinates, block.type, reference)
    bad = np.flatnonzero(~(determinant > 0.0))
    if len(bad):
        raise InputError("%s has a non-positive Jacobian %g at reference point %s: the "
                         "element is degenerate or tangled; fix the mesh" %
                         (_describe_element(mesh, block.type, block.connectivity[bad[0]]),
                          determinant[bad[0]], format_reference(reference)))
    inverse = _inverse(jacobian, determinant)
    gradients = np.einsum("kj,eji->eki", reference_gradients, inverse)
    positions = np.einsum("eki,k->ei", coordinates, values)
    return values, gradients, determinant, positions


# Voigt rows of the strains: (row, component differentiated, direction of the derivative); a
# shear row has two entries, 2 e_ij = du_i/dx_j + du_j/dx_i.
VOIGT_ENTRIES = {2: [(0, 0, 0), (1, 1, 1), (2, 0, 1), (2, 1, 0)],
                 3: [(0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 1, 2), (3, 2, 1), (4, 0, 2), (4, 2, 0),
                     (5, 0, 1), (5, 1, 0)]}
VOIGT_SIZE = {2: 3, 3: 6}


def strain_displacement(gradients):
    """B (elements x v x dk): the Voigt strain = B u_e, u_e = (u_x0, u_y0, [u_z0,] u_x1, ...);
    2D (e_xx, e_yy, 2 e_xy), 3D (e_xx, e_yy, e_zz, 2 e_yz, 2 e_xz, 2 e_xy)."""
    count, nodes, dimension = gradients.shape
    matrix = np.zeros((count, VOIGT_SIZE[dimension], dimension * nodes))
    for row, component, direction in VOIGT_ENTRIES[dimension]:
        matrix[:, row, component::dimension] = gradients[:, :, direction]
    return matrix


def element_dofs(connectivity, dimension=2):
    """Global dofs (elements x dk) of the elements' nodes, interleaved x, y[, z]."""
    dofs = np.empty((len(connectivity), dimension * connectivity.shape[1]), dtype=np.int64)
    for component in range(dimension):
        dofs[:, component::dimension] = dimension * connectivity + component
    return dofs


def assemble_stiffness(mesh, material):
    """K (dn x dn, CSC, symmetric): sum over elements of int B' C B."""
    dimension = mesh.dimension
    rows, columns, values = [], [], []
    for block in mesh.blocks:
        size = dimension * NODES_PER_ELEMENT[block.type]
        local = np.zeros((len(block.connectivity), size, size))
        points, weights = element.element_quadrature(block.type, STIFFNESS_DEGREE[block.type])
        for reference, weight in zip(points, weights):
            _, gradients, determinant, _ = element_points(mesh, block, reference)
            b = strain_displacement(gradients)
            # K_e += B' C B |J| w
            local += np.einsum("eai,ab,ebj->eij", b, material.stiffness, b) * (
                determinant * weight)[:, None, None]
        dofs = element_dofs(block.connectivity, dimension)
        rows.append(np.repeat(dofs, size, axis=1).ravel())
        columns.append(np.tile(dofs, (1, size)).ravel())
        values.append(local.ravel())
    size = mesh.dof_count()
    return scipy.sparse.coo_matrix(
        (np.concatenate(values), (np.concatenate(rows), np.concatenate(columns))),
        shape=(size, size)).tocsc()


def assemble_body_force(mesh, body_force):
    """Consistent load of a constant body force b (force per unit area in 2D, volume in 3D):
    f_i = int N_i b."""
    dimension = mesh.dimension
    load = np.zeros(mesh.dof_count())
    for block in mesh.blocks:
        points, weights = element.element_quadrature(block.type, LOAD_DEGREE[block.type])
        for reference, weight in zip(points, weights):
            values, _, determinant, _ = element_points(mesh, block, reference)
            amount = np.outer(determinant * weight, values)           # e x k: N_i |J| w
            for component in range(dimension):
                np.add.at(load, dimension * block.connectivity + component,
                          amount * body_force[component])
    return load


class EdgeSet:
    """The edges of a boundary group with their outward orientation: the chord's clockwise-turned
    tangent points away from the centroid of the first area element holding both endpoints."""

    def __init__(self, mesh, name, group):
        self.mesh = mesh
        self.name = name
        self.group = group
        self.coordinates = mesh.nodes[group.connectivity]              # edges x m x 2
        zero = np.flatnonzero(np.all(self.coordinates[:, 0] == self.coordinates[:, 1], axis=1))
        if len(zero):
            raise InputError("boundary '%s': an edge at node tag %d has zero length; fix the mesh"
                             % (name, mesh.node_tags[group.connectivity[zero[0], 0]]))
        self.orientation = self._orientations()

    def _orientations(self):
        mesh = self.mesh
        owners = node_elements(mesh, np.unique(self.group.connectivity[:, :2]))
        orientation = np.empty(len(self.group.connectivity))
        for edge, (first, second) in enumerate(self.group.connectivity[:, :2]):
            found = element_with(mesh, owners, [first, second])
            if found is None:
                raise InputError("boundary '%s': the edge from node tag %d to node tag %d is not a "
                                 "side of any area element, so it has no outward normal" %
                                 (self.name, mesh.node_tags[first], mesh.node_tags[second]))
            centroid = _element_centroid(mesh, found)
            chord = mesh.nodes[second] - mesh.nodes[first]
            middle = 0.5 * (mesh.nodes[first] + mesh.nodes[second])
            turned = np.array([chord[1], -chord[0]])
            orientation[edge] = 1.0 if turned.dot(middle - centroid) >= 0.0 else -1.0
        return orientation

    def segments_with_body_on_the_left(self):
        """The group's connectivity (edges x m) with each edge's endpoints in the order that has
        the body on its left (outward normal = the direction turned clockwise); midpoints stay
        last."""
        connectivity = self.group.connectivity.copy()
        reversed_edges = self.orientation < 0.0
        connectivity[reversed_edges, 0] = self.group.connectivity[reversed_edges, 1]
        connectivity[reversed_edges, 1] = self.group.connectivity[reversed_edges, 0]
        return connectivity

    def oriented_connectivity(self):
        return self.segments_with_body_on_the_left()

    def evaluate(self, t):
        """Shape values (m), positions (edges x 2), length elements |dx/dt| (edges) and unit
        outward normals orientation (t_y, -t_x) / |t| (edges x 2) at reference t."""
        values, derivatives = element.edge_shape_functions(self.group.type, t)
        positions = np.einsum("eki,k->ei", self.coordinates, values)
        tangents = np.einsum("eki,k->ei", self.coordinates, derivatives)
        lengths = np.hypot(tangents[:, 0], tangents[:, 1])
        normals = self.orientation[:, None] * np.column_stack(
            [tangents[:, 1], -tangents[:, 0]]) / lengths[:, None]
        return values, positions, lengths, normals

    def quadrature(self, degree):
        return element.edge_quadrature(degree)

    def reference_nodes(self):
        return element.edge_reference_nodes(self.group.type)

    def load_degree(self):
        return edge_load_degree(self.group.type)

    def measures(self):
        """The edges' lengths."""
        points, weights = element.edge_quadrature(6)
        return sum(self.evaluate(t)[2] * w for t, w in zip(points, weights))

    def lengths(self):
        return self.measures()


# Reversal of a face's orientation: the corners run the other way round (the C++ server's).
REVERSED_FACE = {TRIANGLE3: [0, 2, 1], QUADRILATERAL4: [0, 3, 2, 1]}


class FaceSet:
    """The faces (3-node triangles, 4-node quadrilaterals) of a boundary group of a solid mesh
    with their outward orientation: the face's right-hand normal dx/dr x dx/ds at its centre
    points away from the centroid of the first volume element holding all its corners (else
    the orientation is reversed). The interface of EdgeSet, in three dimensions."""

    def __init__(self, mesh, name, group):
        self.mesh = mesh
        self.name = name
        self.group = group
        self.coordinates = mesh.nodes[group.connectivity]              # faces x m x 3
        self.orientation = np.ones(len(group.connectivity))
        centre = element.reference_centroid(group.type)
        extent = np.linalg.norm(np.ptp(self.coordinates, axis=1), axis=1)
        zero = np.flatnonzero(~(self.evaluate(centre)[2] > 1e-14 * extent * extent))
        if len(zero):
            raise InputError("boundary '%s': the face with corner node tags (%s) has zero area; "
                             "fix the mesh" % (name, self._corner_tags(zero[0])))
        self.orientation = self._orientations(centre)

    def _corner_tags(self, face):
        return ", ".join(str(self.mesh.node_tags[node]) for node in self.group.connectivity[face])

    def _orientations(self, centre):
        mesh = self.mesh
        owners = node_elements(mesh, np.unique(self.group.connectivity))
        own_normals = self.evaluate(centre)[3]
        orientation = np.empty(len(self.group.connectivity))
        for face, corners in enumerate(self.group.connectivity):
            found = element_with(mesh, owners, corners)
            if found is None:
                raise InputError("boundary '%s': the face with corner node tags (%s) is not a side "
                                 "of any volume element, so it has no outward normal" %
                                 (self.name, self._corner_tags(face)))
            middle = mesh.nodes[corners].mean(axis=0)
            outward = own_normals[face].dot(middle - _element_centroid(mesh, found))
            orientation[face] = 1.0 if outward >= 0.0 else -1.0
        return orientation

    def oriented_connectivity(self):
        """The group's connectivity (faces x m), each face's corners in the order whose
        right-hand normal points out of the body."""
        connectivity = self.group.connectivity.copy()
        reversed_faces = self.orientation < 0.0
        connectivity[reversed_faces] = connectivity[reversed_faces][:, REVERSED_FACE[
            self.group.type]]
        return connectivity

    def evaluate(self, reference):
        """Shape values (m), positions (faces x 3), area elements |x_r x x_s| (faces) and unit
        outward normals orientation (x_r x x_s) / |x_r x x_s| (faces x 3) at `reference`."""
        values, gradients = element.shape_functions(self.group.type, reference)
        positions = np.einsum("eki,k->ei", self.coordinates, values)
        derivatives = np.einsum("eki,kj->eji", self.coordinates, gradients)   # faces x 2 x 3
        direction = np.cross(derivatives[:, 0], derivatives[:, 1])
        areas = np.linalg.norm(direction, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            normals = self.orientation[:, None] * direction / areas[:, None]
        return values, positions, areas, normals

    def quadrature(self, degree):
        return element.element_quadrature(self.group.type, degree)

    def reference_nodes(self):
        return element.reference_nodes(self.group.type)

    def load_degree(self):
        return 4

    def measures(self):
        """The faces' areas."""
        points, weights = self.quadrature(6)
        return sum(self.evaluate(point)[2] * w for point, w in zip(points, weights))


def facet_set(mesh, name, group):
    """The EdgeSet (plane mesh) or FaceSet (solid mesh) of a boundary group."""
    return (FaceSet if mesh.dimension == 3 else EdgeSet)(mesh, name, group)


def node_elements(mesh, nodes):
    """node -> [(block, element)] in (block, element) order, for the given nodes."""
    wanted = set(int(node) for node in nodes)
    owners = {}
    for b, block in enumerate(mesh.blocks):
        hits = np.isin(block.connectivity, list(wanted))
        for e, k in zip(*np.nonzero(hits)):
            owners.setdefault(int(block.connectivity[e, k]), []).append((b, int(e)))
    for node in owners:
        owners[node].sort()
    return owners


def element_with(mesh, owners, corners):
    """The first (block, element) of the first corner's elements holding every corner."""
    for b, e in owners.get(int(corners[0]), []):
        if all(corner in mesh.blocks[b].connectivity[e] for corner in corners[1:]):
            return b, e
    return None


def _element_centroid(mesh, found):
    block = mesh.blocks[found[0]]
    return mesh.nodes[block.connectivity[found[1], :CORNER_COUNT[block.type]]].mean(axis=0)


def assemble_traction(mesh, facets, traction):
    """Consistent load of a traction t(x, n) (force per unit length in 2D, area in 3D) on the
    facets (EdgeSet or FaceSet): f_i = int N_i t ds. `traction(positions, normals)` returns
    facets x d."""
    dimension = mesh.dimension
    load = np.zeros(mesh.dof_count())
    points, weights = facets.quadrature(facets.load_degree())
    for point, weight in zip(points, weights):
        values, positions, measures, normals = facets.evaluate(point)
        force = traction(positions, normals) * (measures * weight)[:, None]
        for k, value in enumerate(values):
            for component in range(dimension):
                np.add.at(load, dimension * facets.group.connectivity[:, k] + component,
                          value * force[:, component])
    return load


def boundary_weights(mesh, facets):
    """m_i = int_group N_i ds per mesh node (zero off the group)."""
    weights_out = np.zeros(mesh.node_count())
    points, weights = facets.quadrature(facets.load_degree())
    for point, weight in zip(points, weights):
        values, _, measures, _ = facets.evaluate(point)
        for k, value in enumerate(values):
            np.add.at(weights_out, facets.group.connectivity[:, k], value * measures * weight)
    return weights_out


def boundary_normal_sums(mesh, facets):
    """Per mesh node (n x d): the sum over the facets touching the node of the facet's outward
    normal at the node times the facet's length (2D) or area (3D) (zero off the group)."""
    sums = np.zeros((mesh.node_count(), mesh.dimension))
    measures = facets.measures()
    for k, point in enumerate(facets.reference_nodes()):
        _, _, _, normals = facets.evaluate(point)
        np.add.at(sums, facets.group.connectivity[:, k], measures[:, None] * normals)
    return sums


def unit_normals(mesh, sums, nodes, boundary_names):
    """The normalised rows `nodes` of normal sums (n x d); a zero sum (the normals of the
    facets at a node cancel out) is an InputError naming the boundaries and the node tag."""
    norms = np.linalg.norm(sums[nodes], axis=1)
    zero = np.flatnonzero(norms == 0.0)
    if len(zero):
        raise InputError("boundary '%s': the normals at node %d cancel out (a cusp or a fold)" %
                         ("', '".join(boundary_names), mesh.node_tags[nodes[zero[0]]]))
    return sums[nodes] / norms[:, None]


def boundary_node_normals(mesh, facets):
    """Unit outward normal at each node of the group (ascending node order): the normalised sum
    of its facets' outward normals at the node times the facets' measures."""
    return unit_normals(mesh, boundary_normal_sums(mesh, facets), facets.group.nodes(),
                        [facets.name])


def recover_stress(mesh, material, displacement):
    """Voigt stress (s_xx, s_yy, s_xy; in 3D s_xx, s_yy, s_zz, s_yz, s_xz, s_xy) at element
    centroids (elements x v, block order) and at nodes (average over the elements touching the
    node, each evaluated at that node); von Mises of both. Returns (element_stress,
    nodal_stress, element_von_mises, nodal_von_mises)."""
    element_stress = []
    nodal = np.zeros((mesh.node_count(), VOIGT_SIZE[mesh.dimension]))
    touching = np.zeros(mesh.node_count())
    for block in mesh.blocks:
        local = displacement[element_dofs(block.connectivity, mesh.dimension)]   # e x dk

        def stress_at(reference):
            _, gradients, _, _ = element_points(mesh, block, reference)
            # s = C B u_e
            return np.einsum("ab,ebj,ej->ea", material.stiffness,
                             strain_displacement(gradients), local)

        element_stress.append(stress_at(element.reference_centroid(block.type)))
        for k, reference in enumerate(element.reference_nodes(block.type)):
            np.add.at(nodal, block.connectivity[:, k], stress_at(reference))
            np.add.at(touching, block.connectivity[:, k], 1.0)
    nodal[touching > 0] /= touching[touching > 0][:, None]
    element_stress = np.vstack(element_stress)
    return (element_stress, nodal, von_mises(material, element_stress),
            von_mises(material, nodal))
