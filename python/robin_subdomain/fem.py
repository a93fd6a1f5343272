"""Finite-element assembly of 2D linear elasticity on a Mesh (P1, P2 triangles, Q1 quads).

Degrees of freedom: node i has u_x at 2i and u_y at 2i + 1. Quadrature degrees are those of
the C++ implementation (subdomain/numerics/elasticity.cpp): stiffness exact on affine
elements (1 for P1, 2 for P2, the 2 x 2 Gauss rule for Q1); loads and boundary weights with two
degrees more than the shape functions squared (4, or 6 for quadratic elements and edges).
"""

import numpy as np
import scipy.sparse

from . import element
from .errors import InputError
from .material import von_mises
from .mesh import LINE3, NODES_PER_ELEMENT, QUADRILATERAL4, TRIANGLE3, TRIANGLE6

STIFFNESS_DEGREE = {TRIANGLE3: 1, TRIANGLE6: 2, QUADRILATERAL4: 3}
LOAD_DEGREE = {TRIANGLE3: 4, TRIANGLE6: 6, QUADRILATERAL4: 4}


def edge_load_degree(edge_type):
    return 6 if edge_type == LINE3 else 4


def _describe_element(mesh, element_type, nodes):
    tags = ", ".join(str(mesh.node_tags[node]) for node in nodes)
    return "mesh element %s with node tags (%s)" % (element_type, tags)


def jacobians(coordinates, element_type, reference):
    """Jacobian matrices (elements x 2 x 2) and their determinants (elements) at one reference
    point, for element node coordinates (elements x k x 2): J_ij = sum_k x_k,i dN_k/dxi_j."""
    _, reference_gradients = element.shape_functions(element_type, reference)
    jacobian = np.einsum("eki,kj->eij", coordinates, reference_gradients)
    determinant = jacobian[:, 0, 0] * jacobian[:, 1, 1] - jacobian[:, 0, 1] * jacobian[:, 1, 0]
    return jacobian, determinant


def jacobian_check_points(element_type):
    """The reference points where an element's Jacobian must be positive: its nodes (corners
    and midpoints), its centroid and the points of every quadrature rule used on it."""
    points = [element.reference_nodes(element_type), [element.reference_centroid(element_type)]]
    for degree in (STIFFNESS_DEGREE[element_type], LOAD_DEGREE[element_type]):
        points.append(element.element_quadrature(element_type, degree)[0])
    return np.vstack(points)


def element_points(mesh, block, reference):
    """Shape values N (k), physical gradients (elements x k x 2), Jacobian determinants and
    positions (elements x 2) of every element of `block` at one reference point.
    J_ij = dx_i/dxi_j = sum_k x_k,i dN_k/dxi_j; dN/dx = dN/dxi J^-1."""
    values, reference_gradients = element.shape_functions(block.type, reference)
    coordinates = mesh.nodes[block.connectivity]                      # e x k x 2
    jacobian, determinant = jacobians(coordinates, block.type, reference)
    bad = np.flatnonzero(~(determinant > 0.0))
    if len(bad):
        raise InputError("%s has a non-positive Jacobian %g at reference point (%g, %g): the "
                         "element is degenerate or tangled; fix the mesh" %
                         (_describe_element(mesh, block.type, block.connectivity[bad[0]]),
                          determinant[bad[0]], reference[0], reference[1]))
    inverse = np.empty_like(jacobian)
    inverse[:, 0, 0] = jacobian[:, 1, 1] / determinant
    inverse[:, 1, 1] = jacobian[:, 0, 0] / determinant
    inverse[:, 0, 1] = -jacobian[:, 0, 1] / determinant
    inverse[:, 1, 0] = -jacobian[:, 1, 0] / determinant
    gradients = np.einsum("kj,eji->eki", reference_gradients, inverse)
    positions = np.einsum("eki,k->ei", coordinates, values)
    return values, gradients, determinant, positions


def strain_displacement(gradients):
    """B (elements x 3 x 2k): (e_xx, e_yy, 2 e_xy) = B u_e, u_e = (u_x0, u_y0, u_x1, ...)."""
    count, nodes, _ = gradients.shape
    matrix = np.zeros((count, 3, 2 * nodes))
    matrix[:, 0, 0::2] = gradients[:, :, 0]
    matrix[:, 1, 1::2] = gradients[:, :, 1]
    matrix[:, 2, 0::2] = gradients[:, :, 1]
    matrix[:, 2, 1::2] = gradients[:, :, 0]
    return matrix


def element_dofs(connectivity):
    """Global dofs (elements x 2k) of the elements' nodes, interleaved x, y."""
    dofs = np.empty((len(connectivity), 2 * connectivity.shape[1]), dtype=np.int64)
    dofs[:, 0::2] = 2 * connectivity
    dofs[:, 1::2] = 2 * connectivity + 1
    return dofs


def assemble_stiffness(mesh, material):
    """K (2n x 2n, CSC, symmetric): sum over elements of int B' C B."""
    rows, columns, values = [], [], []
    for block in mesh.blocks:
        size = 2 * NODES_PER_ELEMENT[block.type]
        local = np.zeros((len(block.connectivity), size, size))
        points, weights = element.element_quadrature(block.type, STIFFNESS_DEGREE[block.type])
        for reference, weight in zip(points, weights):
            _, gradients, determinant, _ = element_points(mesh, block, reference)
            b = strain_displacement(gradients)
            # K_e += B' C B |J| w
            local += np.einsum("eai,ab,ebj->eij", b, material.stiffness, b) * (
                determinant * weight)[:, None, None]
        dofs = element_dofs(block.connectivity)
        rows.append(np.repeat(dofs, size, axis=1).ravel())
        columns.append(np.tile(dofs, (1, size)).ravel())
        values.append(local.ravel())
    size = 2 * mesh.node_count()
    return scipy.sparse.coo_matrix(
        (np.concatenate(values), (np.concatenate(rows), np.concatenate(columns))),
        shape=(size, size)).tocsc()


def assemble_body_force(mesh, body_force):
    """Consistent load of a constant body force b (force per unit area): f_i = int N_i b."""
    load = np.zeros(2 * mesh.node_count())
    for block in mesh.blocks:
        points, weights = element.element_quadrature(block.type, LOAD_DEGREE[block.type])
        for reference, weight in zip(points, weights):
            values, _, determinant, _ = element_points(mesh, block, reference)
            amount = np.outer(determinant * weight, values)           # e x k: N_i |J| w
            for component in range(2):
                np.add.at(load, 2 * block.connectivity + component, amount * body_force[component])
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
        owners = _node_elements(mesh, np.unique(self.group.connectivity[:, :2]))
        orientation = np.empty(len(self.group.connectivity))
        for edge, (first, second) in enumerate(self.group.connectivity[:, :2]):
            found = next(((b, e) for b, e in owners.get(first, [])
                          if second in mesh.blocks[b].connectivity[e]), None)
            if found is None:
                raise InputError("boundary '%s': the edge from node tag %d to node tag %d is not a "
                                 "side of any area element, so it has no outward normal" %
                                 (self.name, mesh.node_tags[first], mesh.node_tags[second]))
            block = mesh.blocks[found[0]]
            corners = 4 if block.type == QUADRILATERAL4 else 3
            centroid = mesh.nodes[block.connectivity[found[1], :corners]].sum(axis=0) / corners
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

    def lengths(self):
        points, weights = element.edge_quadrature(6)
        return sum(self.evaluate(t)[2] * w for t, w in zip(points, weights))


def _node_elements(mesh, nodes):
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


def assemble_traction(mesh, edges, traction):
    """Consistent load of a traction t(x, n) (force per unit length) on `edges`:
    f_i = int N_i t ds. `traction(positions, normals)` returns edges x 2."""
    load = np.zeros(2 * mesh.node_count())
    points, weights = element.edge_quadrature(edge_load_degree(edges.group.type))
    for t, weight in zip(points, weights):
        values, positions, lengths, normals = edges.evaluate(t)
        force = traction(positions, normals) * (lengths * weight)[:, None]
        for k, value in enumerate(values):
            for component in range(2):
                np.add.at(load, 2 * edges.group.connectivity[:, k] + component,
                          value * force[:, component])
    return load


def boundary_weights(mesh, edges):
    """m_i = int_group N_i ds per mesh node (zero off the group)."""
    weights_out = np.zeros(mesh.node_count())
    points, weights = element.edge_quadrature(edge_load_degree(edges.group.type))
    for t, weight in zip(points, weights):
        values, _, lengths, _ = edges.evaluate(t)
        for k, value in enumerate(values):
            np.add.at(weights_out, edges.group.connectivity[:, k], value * lengths * weight)
    return weights_out


def boundary_normal_sums(mesh, edges):
    """Per mesh node (n x 2): the sum over the edges of `edges` touching the node of the edge's
    outward normal at the node times the edge's length (zero off the group)."""
    sums = np.zeros((mesh.node_count(), 2))
    lengths = edges.lengths()
    for k, t in enumerate(element.edge_reference_nodes(edges.group.type)):
        _, _, _, normals = edges.evaluate(t)
        np.add.at(sums, edges.group.connectivity[:, k], lengths[:, None] * normals)
    return sums


def unit_normals(mesh, sums, nodes, boundary_names):
    """The normalised rows `nodes` of normal sums (n x 2); a zero sum (the normals of the
    edges at a node cancel out) is an InputError naming the boundaries and the node tag."""
    norms = np.hypot(sums[nodes, 0], sums[nodes, 1])
    zero = np.flatnonzero(norms == 0.0)
    if len(zero):
        raise InputError("boundary '%s': the normals at node %d cancel out (a cusp or a fold)" %
                         ("', '".join(boundary_names), mesh.node_tags[nodes[zero[0]]]))
    return sums[nodes] / norms[:, None]


def boundary_node_normals(mesh, edges):
    """Unit outward normal at each node of the group (ascending node order): the normalised sum
    of its edges' outward normals at the node times the edges' lengths."""
    return unit_normals(mesh, boundary_normal_sums(mesh, edges), edges.group.nodes(),
                        [edges.name])


def recover_stress(mesh, material, displacement):
    """Stress (s_xx, s_yy, s_xy) at element centroids (elements x 3, block order) and at nodes
    (average over the elements touching the node, each evaluated at that node); von Mises of
    both. Returns (element_stress, nodal_stress, element_von_mises, nodal_von_mises)."""
    element_stress = []
    nodal = np.zeros((mesh.node_count(), 3))
    touching = np.zeros(mesh.node_count())
    for block in mesh.blocks:
        local = displacement[element_dofs(block.connectivity)]       # e x 2k

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
