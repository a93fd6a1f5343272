"""One elastic body: assembled stiffness, Dirichlet reduction, a sparse LU factor computed once,
its contact boundaries (ContactBoundaries) and the operators of the dual (contact-force)
formulation for its assigned constraint operator B (AssignContact, assignment.ContactOperator).

With B the constraint operator (one row per constraint; node-to-node: (B u)_i = u(node_i) . n_i),
K the stiffness on the free dofs and f the reduced load (f_f - K_fp u_p):
  e = B K^-1 f + B u_p       free normal trace
  F = B K^-1 B'              interface compliance, assembled densely
  u_N = e - F lambda         normal trace under contact forces lambda (K u = f - B' lambda)
"""

import time

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from . import contact, fem
from .contact_boundaries import ContactBoundaries
from .errors import InputError, SingularBodyError


class BodyDefinition:
    """Plain data: name, mesh, material, body_force (d), dirichlet [(boundary, x or None,
    y or None[, z or None])], tractions [(boundary, vector (d) or None, pressure or None)],
    contact_boundaries (names of mesh boundaries, at least one); d = mesh.dimension."""

    def __init__(self, name, mesh, material, body_force=(0.0, 0.0), dirichlet=(), tractions=(),
                 contact_boundaries=()):
        self.name = name
        self.mesh = mesh
        self.material = material
        self.body_force = np.asarray(body_force, dtype=float)
        self.dirichlet = list(dirichlet)
        self.tractions = list(tractions)
        self.contact_boundaries = list(contact_boundaries)


def prescribed_values(definition):
    """Per dof: the prescribed value, NaN when free. Conflicting values are an InputError."""
    mesh = definition.mesh
    dimension = mesh.dimension
    values = np.full(mesh.dof_count(), np.nan)
    source = {}
    for boundary, *components in definition.dirichlet:
        for node in mesh.boundaries[boundary].nodes():
            for component, value in enumerate(components[:dimension]):
                if value is None:
                    continue
                dof = dimension * node + component
                differs = abs(values[dof] - value) > 1e-14 * (1 + abs(value))
                if not np.isnan(values[dof]) and differs:
                    raise InputError(
                        "body '%s': Dirichlet conditions on '%s' and '%s' prescribe different "
                        "values to node tag %d (%s)" % (definition.name, source[dof], boundary,
                                                        mesh.node_tags[node],
                                                        ("u_x", "u_y", "u_z")[component]))
                values[dof] = value
                source[dof] = boundary
    return values


# The rotations of the rigid modes: (axis row, component, sign, coordinate): the rotation about
# the axis moves `component` by sign * (x_coordinate - centre) / scale. One in 2D (about z),
# three in 3D (about x, y, z).
ROTATIONS = {2: [(2, 0, -1.0, 1), (2, 1, 1.0, 0)],
             3: [(3, 1, -1.0, 2), (3, 2, 1.0, 1), (4, 0, 1.0, 2), (4, 2, -1.0, 0),
                 (5, 0, -1.0, 1), (5, 1, 1.0, 0)]}


def removes_rigid_motions(nodes, prescribed):
    """True when the prescribed dofs block the rigid modes: the d translations and the
    rotations (about z in 2D: (-(y - yc), x - xc) / scale; about x, y and z in 3D). The Gram
    matrix of the modes on those dofs has full rank (3 in 2D, 6 in 3D)."""
    count, dimension = nodes.shape
    centre = nodes.mean(axis=0)
    scale = np.max(np.linalg.norm(nodes - centre, axis=1)) or 1.0
    relative = (nodes - centre) / scale
    modes = 3 if dimension == 2 else 6
    rows = np.zeros((count * dimension, modes))
    for component in range(dimension):
        rows[component::dimension, component] = 1.0
    for mode, component, sign, coordinate in ROTATIONS[dimension]:
        rows[component::dimension, mode] = sign * relative[:, coordinate]
    rows = rows[prescribed]
    eigenvalues = np.linalg.eigvalsh(rows.T @ rows)
    return eigenvalues[-1] > 0.0 and eigenvalues[0] > 1e-10 * eigenvalues[-1]


def external_load(definition):
    """f: body force plus tractions (pressure p: traction -p n, compression positive)."""
    mesh = definition.mesh
    load = np.zeros(mesh.dof_count())
    if np.any(definition.body_force != 0.0):
        load += fem.assemble_body_force(mesh, definition.body_force)
    for boundary, vector, pressure in definition.tractions:
        facets = fem.facet_set(mesh, boundary, mesh.boundaries[boundary])
        if pressure is not None:
            load += fem.assemble_traction(mesh, facets, lambda x, n: -pressure * n)
        else:
            constant = np.asarray(vector, dtype=float)
            load += fem.assemble_traction(mesh, facets,
                                          lambda x, n: np.broadcast_to(constant, x.shape))
    return load


class Body:
    """Assembles and factorizes at construction (InputError, SingularBodyError)."""

    def __init__(self, definition):
        self.definition = definition
        self.name = definition.name
        self.mesh = definition.mesh
        start = time.perf_counter()
        if self.mesh.node_count() == 0 or self.mesh.element_count() == 0:
            raise InputError("body '%s': the mesh has no elements" % self.name)
        self.prescribed = prescribed_values(definition)
        self.is_prescribed = ~np.isnan(self.prescribed)
        if not removes_rigid_motions(self.mesh.nodes, self.is_prescribed):
            raise SingularBodyError(
                "body '%s': the Dirichlet conditions leave a rigid motion free (translation or "
                "rotation); fix every displacement component on a boundary, or enough "
                "components on several boundaries" % self.name)
        self.interface = ContactBoundaries(self.mesh, definition.contact_boundaries,
                                           self.is_prescribed)
        self.free_dofs = np.flatnonzero(~self.is_prescribed)
        self.free_index = np.full(len(self.prescribed), -1, dtype=np.int64)
        self.free_index[self.free_dofs] = np.arange(len(self.free_dofs))
        self.prescribed_full = np.where(self.is_prescribed, self.prescribed, 0.0)
        self.full_stiffness = fem.assemble_stiffness(self.mesh, definition.material)
        self.full_load = external_load(definition)
        reduced = self.full_stiffness[self.free_dofs][:, self.free_dofs].tocsc()
        # f_f - K_fp u_p: the free rows of f - K u_p
        self.reduced_load = (self.full_load - self.full_stiffness @ self.prescribed_full)[
            self.free_dofs]
        self.assembly_seconds = time.perf_counter() - start
        start = time.perf_counter()
        self.factor = self._factorize(reduced)
        self.free_solution = self.factor.solve(self.reduced_load)   # K^-1 f
        self.factorization_seconds = time.perf_counter() - start
        self.contact = None
        self.load_factor = 1.0   # since protocol 2.1: loads and prescribed values times this

    def set_load_factor(self, factor):
        """Scales every load and prescribed displacement by `factor` relative to the definition
        (f = t f_1, u_p = t u_p1, e = t e_1); keeps the factor of K, B, F and the warm start."""
        self.load_factor = float(factor)
        if self.contact is not None:
            self.contact.set_load_factor(self.load_factor)

    def _factorize(self, reduced):
        try:
            # K is SPD: symmetric ordering and diagonal pivots (SuperLU's symmetric mode).
            return scipy.sparse.linalg.splu(reduced, permc_spec="MMD_AT_PLUS_A",
                                            diag_pivot_thresh=0.0,
                                            options={"SymmetricMode": True})
        except RuntimeError as error:
            raise SingularBodyError("body '%s': the stiffness matrix is singular (%s)" %
                                    (self.name, error))

    def free_dof_count(self):
        return len(self.free_dofs)

    def assign_contact(self, operator):
        """Sets the constraint operator B (an assignment.ContactOperator whose nodes are contact
        nodes); builds e and F."""
        self.contact = contact.ContactInterface(self, operator)
        self.contact.set_load_factor(self.load_factor)

    def displacement(self, contact_force):
        """Full displacement (d per node): u_f = K^-1 (t f - B' lambda), prescribed values t u_p
        (t the load factor)."""
        free_values = self.load_factor * self.free_solution
        if len(contact_force) and np.max(np.abs(contact_force)) > 0.0:
            free_values -= self.factor.solve(self.contact.trace.T @ contact_force)
        full = self.load_factor * self.prescribed_full
        full[self.free_dofs] = free_values
        return full

    def reactions(self, displacement):
        """K u - f at the prescribed dofs, zero at the free ones."""
        reaction = self.full_stiffness @ displacement - self.load_factor * self.full_load
        reaction[~self.is_prescribed] = 0.0
        return reaction

    def applied_force(self):
        return self.load_factor * self.full_load.reshape(-1, self.mesh.dimension).sum(axis=0)
