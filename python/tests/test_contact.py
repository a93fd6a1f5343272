"""Contact operators and the bound-constrained QP of the Python subdomain server.

- QP: on random SPD matrices with positive entries (like an interface compliance) the solver's
  answer equals the KKT point found by enumerating all 2^n active sets; both the primal-dual
  active set path and the Lawson-Hanson safeguard alone; warm starts change nothing.
- A block pressed by a prescribed top displacement onto a rigid flat obstacle (roller on its
  left side): uniform uniaxial strain, so the nodal contact forces are lambda_i = |s_yy| m_i
  with s_yy = E/(1 - nu^2) (-d/H) (plane strain), to rounding.
- Consistency: e - F lambda equals the normal trace of the displacement computed with lambda.
- The Neumann solve (since protocol 1.1): under the analytic contact forces of the block on the
  flat the bottom does not move (u_N = 0); under other forces it equals e - F lambda and the
  normal trace of the full displacement.
- A general constraint operator B (protocol 2.0: rows combining several nodes and components,
  one with a prescribed component), through the protocol: the free trace, the Neumann trace
  B u with K u = f - B' lambda, the correction B K^-1 B' r and the fields' contact forces
  -B' lambda and pressures |B' lambda| / m equal a direct sparse solve with a stiffness, load
  and Dirichlet reduction assembled in the test itself; node-to-node rows give u_y at the nodes.
"""

import itertools
import unittest

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

import support
from robin_subdomain import contact
from robin_subdomain.assignment import ContactOperator
from robin_subdomain.body import Body, BodyDefinition
from robin_subdomain.material import PLANE_STRAIN, isotropic_material
from robin_subdomain.proto_module import load_protocol
from robin_subdomain.protocol import SubdomainProtocol

protocol = load_protocol()


def enumerated_solution(matrix, right_hand_side):
    """The unique KKT point of min 1/2 x'Ax - b'x, x >= 0, by trying every free set."""
    size = len(right_hand_side)
    for free_count in range(size + 1):
        for free in itertools.combinations(range(size), free_count):
            free = list(free)
            x = np.zeros(size)
            if free:
                x[free] = np.linalg.solve(matrix[np.ix_(free, free)], right_hand_side[free])
            gradient = matrix @ x - right_hand_side
            scale = np.abs(right_hand_side).max()
            if np.all(x >= 0.0) and np.all(gradient[x == 0.0] >= -1e-12 * scale):
                return x
    raise AssertionError("no KKT point found")


def compliance_like(generator, size):
    """SPD with positive entries decaying off the diagonal (a discrete Green's function)."""
    positions = np.sort(generator.uniform(0.0, 1.0, size))
    matrix = np.exp(-np.abs(positions[:, None] - positions[None, :]) / 0.3)
    return matrix + 0.05 * np.eye(size)


class BoundQp(unittest.TestCase):
    def test_equals_enumeration(self):
        generator = np.random.default_rng(20080101)
        for trial in range(40):
            size = int(generator.integers(1, 10))
            matrix = compliance_like(generator, size)
            right_hand_side = generator.normal(size=size)
            expected = enumerated_solution(matrix, right_hand_side)
            result = contact.solve_bound_qp(matrix, right_hand_side, np.zeros(size), 1e-12, 1000,
                                            contact.estimate_norm(matrix))
            self.assertEqual(result.status, contact.CONVERGED, result.message)
            scale = max(np.abs(expected).max(), 1e-300)
            self.assertLess(np.abs(result.solution - expected).max(), 1e-10 * scale,
                            "trial %d" % trial)
            warm = contact.solve_bound_qp(matrix, right_hand_side, expected + 0.1, 1e-12, 1000,
                                          contact.estimate_norm(matrix))
            self.assertLess(np.abs(warm.solution - expected).max(), 1e-10 * scale)

    def test_safeguard_alone_equals_enumeration(self):
        generator = np.random.default_rng(7)
        for _ in range(20):
            size = int(generator.integers(2, 10))
            matrix = compliance_like(generator, size)
            right_hand_side = generator.normal(size=size)
            problem = contact._Problem(matrix, right_hand_side, 1e-12,
                                       contact.estimate_norm(matrix))
            start = np.abs(generator.normal(size=size)) * (generator.uniform(size=size) < 0.5)
            x, _, converged = contact._lawson_hanson(problem, start, 1000)
            self.assertTrue(converged)
            expected = enumerated_solution(matrix, right_hand_side)
            self.assertLess(np.abs(x - expected).max(), 1e-10 * max(np.abs(expected).max(), 1e-300))

    def test_cycling_active_set_hands_over_to_the_safeguard(self):
        # A random SPD matrix (Wishart plus 1e-3 I) on which the primal-dual active set
        # method revisits an active set from lambda = 0.
        matrix = np.array([
            [4.600924183887254, 0.1331167524287453, -0.5172272099346218, -3.7674623189169627,
             -2.482092598643416],
            [0.1331167524287453, 6.0460055622578315, 1.2386919165884653, -0.05035902051059699,
             -4.068208345029607],
            [-0.5172272099346218, 1.2386919165884653, 2.8019509696738534, 4.113450650659886,
             2.1776209347169977],
            [-3.7674623189169627, -0.05035902051059699, 4.113450650659886, 10.187165118328878,
             7.968392933600425],
            [-2.482092598643416, -4.068208345029607, 2.1776209347169977, 7.968392933600425,
             9.732499438539305]])
        right_hand_side = np.array([2.805894318064536, -1.126174269363369, 1.8871533010114294,
                                    0.6928099799776283, 1.714355064134923])
        problem = contact._Problem(matrix, right_hand_side, 1e-12, contact.estimate_norm(matrix))
        _, _, converged = contact._primal_dual_active_set(problem, np.zeros(5), 50)
        self.assertFalse(converged)
        result = contact.solve_bound_qp(matrix, right_hand_side, np.zeros(5), 1e-12, 1000,
                                        problem.norm)
        self.assertEqual(result.status, contact.CONVERGED)
        expected = enumerated_solution(matrix, right_hand_side)
        self.assertLess(np.abs(result.solution - expected).max(), 1e-12 * np.abs(expected).max())

    def test_all_open_gives_zero_forces(self):
        matrix = compliance_like(np.random.default_rng(1), 5)
        result = contact.solve_bound_qp(matrix, -np.ones(5), np.ones(5), 1e-12, 100, 1.0)
        np.testing.assert_array_equal(result.solution, np.zeros(5))
        np.testing.assert_allclose(result.gradient, np.ones(5))


PLATE_GEO = """
DefineConstant[ h = 0.25 ];
Point(1) = {0, 0, 0, h};
Point(2) = {2, 0, 0, h};
Point(3) = {2, 1, 0, h};
Point(4) = {0, 1, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("contact") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
"""


class BlockOnRigidFlat(unittest.TestCase):
    YOUNG, POISSON, PUSH, HEIGHT = 1000.0, 0.3, 0.01, 1.0

    def make_body(self, element_order):
        mesh = support.mesh_from_geo(PLATE_GEO, 0.0, element_order)
        material = isotropic_material(self.YOUNG, self.POISSON, PLANE_STRAIN, "test")
        body = Body(BodyDefinition("block", mesh, material, (0.0, 0.0),
                                   [("left", 0.0, None), ("top", None, -self.PUSH)], [],
                                   ["contact"]))
        interface = body.interface
        body.assign_contact(ContactOperator.node_to_node(interface.node_ids, interface.normals,
                                                         interface.weights))
        return body, interface

    def check(self, element_order):
        body, interface = self.make_body(element_order)
        np.testing.assert_allclose(interface.normals,
                                   np.tile([0.0, -1.0], (len(interface.normals), 1)),
                                   atol=1e-15)
        obstacle = np.zeros(len(interface.node_ids))            # the rigid flat: u_N <= 0
        result = body.contact.solve_contact(obstacle, 1e-12, 1000)
        self.assertEqual(result["status"], contact.CONVERGED)
        stress = self.YOUNG / (1.0 - self.POISSON ** 2) * self.PUSH / self.HEIGHT
        expected = stress * interface.weights
        self.assertLess(np.abs(result["contact_force"] - expected).max(), 1e-10 * expected.max())
        self.assertLess(np.abs(result["normal_trace"]).max(), 1e-12 * self.PUSH)
        # consistency: e - F lambda is the normal trace of u(lambda)
        displacement = body.displacement(result["contact_force"]).reshape(-1, 2)
        trace = np.sum(displacement[interface.node_ids] * interface.normals, axis=1)
        np.testing.assert_allclose(result["normal_trace"], trace, atol=1e-14 * self.PUSH)

    def test_linear_triangles(self):
        self.check(1)

    def test_quadratic_triangles(self):
        self.check(2)

    def test_neumann_solve(self):
        for element_order in (1, 2):
            body, interface = self.make_body(element_order)
            stress = self.YOUNG / (1.0 - self.POISSON ** 2) * self.PUSH / self.HEIGHT
            analytic = stress * interface.weights
            resting = body.contact.solve_neumann(analytic)
            self.assertLess(np.abs(resting).max(), 1e-12 * self.PUSH)
            count = len(analytic)
            force = analytic * (1.0 + 0.5 * np.cos(1.7 * np.arange(count)))
            trace = body.contact.solve_neumann(force)
            dual = body.contact.free_trace - body.contact.compliance @ force  # e - F lambda
            displacement = body.displacement(force).reshape(-1, 2)
            traced = np.sum(displacement[interface.node_ids] * interface.normals, axis=1)
            scale = np.abs(trace).max()
            self.assertGreater(scale, 1e-3 * self.PUSH)  # the forces do move the bottom
            self.assertLess(np.abs(trace - dual).max(), 1e-12 * scale)
            self.assertLess(np.abs(trace - traced).max(), 1e-12 * scale)

    def test_compliance_is_symmetric_positive_definite(self):
        body, _ = self.make_body(1)
        compliance = body.contact.compliance
        np.testing.assert_array_equal(compliance, compliance.T)
        self.assertGreater(np.linalg.eigvalsh(compliance)[0], 0.0)
        norm = contact.estimate_norm(compliance)
        self.assertLessEqual(norm, np.linalg.norm(compliance, 2) * (1 + 1e-12))
        self.assertGreater(norm, 0.9 * np.linalg.norm(compliance, 2))


def matching_nodes(coordinates, nodes):
    """For each point of `coordinates` (k x 2) the index of the point of `nodes` within 1e-9
    (the mesh file's nodes are the nominal points to rounding)."""
    distances = np.linalg.norm(coordinates[:, None, :] - nodes[None, :, :], axis=2)
    indices = np.argmin(distances, axis=1)
    assert np.all(distances[np.arange(len(indices)), indices] < 1e-9)
    return indices


class GeneralConstraintOperator(unittest.TestCase):
    """case_lower.msh ([0, 1] x [-1, 0], linear triangles) sent as MeshData; rollers: left
    u_x = 0, bottom u_y = 0, right u_x = PULL; a body force; contact boundary y = 0 with the
    nodes a = (0, 0), b = (0.5, 0), c = (1, 0) (u_x prescribed at a and c)."""

    YOUNG, POISSON, PULL, BODY_FORCE = 1000.0, 0.3, 0.01, (0.0, -2.0)
    FORCE = np.array([0.3, -0.1, 0.7, 0.2])

    def setUp(self):
        self.server = SubdomainProtocol(protocol)
        self.server.logger.disabled = True
        mesh = support.mesh_data_from_msh(protocol, "case_lower.msh")
        self.nodes = np.array(mesh.coordinates).reshape(-1, 2)
        self.triangles = np.array(mesh.cells[0].connectivity).reshape(-1, 3)
        body = protocol.SetupBody(body_name="lower", mesh=mesh, model=protocol.PLANE_STRAIN,
                                  young_modulus=self.YOUNG, poisson_ratio=self.POISSON,
                                  body_force=self.BODY_FORCE, contact_boundaries=["contact"])
        body.dirichlet.add(boundary="left", x=0.0)
        body.dirichlet.add(boundary="bottom", y=0.0)
        body.dirichlet.add(boundary="right", x=self.PULL)
        self.interface = self.ask(setup_body=body).interface
        coordinates = np.array(self.interface.coordinates).reshape(-1, 2)
        self.mesh_index = matching_nodes(coordinates, self.nodes)   # contact node -> MeshData
        self.node_id = {(float(x), float(y)): int(node) for (x, y), node in
                        zip(coordinates.round(6), self.interface.node_ids)}

    def ask(self, **content):
        envelope = protocol.Envelope(request_id=1)
        envelope.version.major = 2
        for name, message in content.items():
            getattr(envelope, name).CopyFrom(message)
        reply = protocol.Envelope()
        reply.ParseFromString(self.server.handle(envelope.SerializeToString()))
        self.assertNotEqual(reply.WhichOneof("content"), "error", reply.error.message)
        return reply

    def rows(self):
        """[(weight, [((x, y) of the node, component, value), ...])]: a 0.5/0.5 combination of
        two nodes, a node's oblique direction, a prescribed component with a free one."""
        a, b, c = (0.0, 0.0), (0.5, 0.0), (1.0, 0.0)
        return [(0.5, [(a, 1, 0.5), (b, 1, 0.5)]), (0.25, [(b, 0, 0.6), (b, 1, 0.8)]),
                (0.3, [(c, 0, 1.0), (a, 1, 0.3)]), (1.0, [(a, 0, 0.7), (c, 1, -0.2)])]

    def assign(self, rows):
        message = support.sparse_rows(protocol, [
            (weight, [(self.node_id[point], component, value)
                      for point, component, value in entries]) for weight, entries in rows])
        self.assertEqual(self.ask(assign_contact=message).acknowledge.state, "ready")

    def dense_operator(self, rows):
        """B (rows x 2n) over the MeshData's dofs, written out from the rows."""
        operator = np.zeros((len(rows), 2 * len(self.nodes)))
        for row, (_, entries) in enumerate(rows):
            for point, component, value in entries:
                node = matching_nodes(np.array([point]), self.nodes)[0]
                operator[row, 2 * node + component] = value
        return operator

    def direct_solution(self, load, homogeneous=False):
        """u with K u = load on the free dofs and the Dirichlet values (0 if homogeneous) on
        the others, by a direct sparse solve with the test's own K."""
        elasticity = support.plane_strain_elasticity(self.YOUNG, self.POISSON)
        stiffness = support.p1_stiffness(self.nodes, self.triangles, elasticity)
        prescribed = np.full(2 * len(self.nodes), np.nan)
        x, y = self.nodes[:, 0], self.nodes[:, 1]
        prescribed[2 * np.flatnonzero(x == 0.0)] = 0.0
        prescribed[2 * np.flatnonzero(y == -1.0) + 1] = 0.0
        prescribed[2 * np.flatnonzero(x == 1.0)] = 0.0 if homogeneous else self.PULL
        fixed = ~np.isnan(prescribed)
        solution = np.where(fixed, prescribed, 0.0)
        right_hand_side = load[~fixed] - stiffness[~fixed][:, fixed] @ solution[fixed]
        solution[~fixed] = scipy.sparse.linalg.spsolve(
            scipy.sparse.csc_matrix(stiffness[~fixed][:, ~fixed]), right_hand_side)
        return solution

    def body_load(self):
        return support.p1_body_force(self.nodes, self.triangles, self.BODY_FORCE)

    def assert_close(self, actual, expected):
        scale = np.abs(expected).max()
        self.assertGreater(scale, 0.0)
        np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-12 * scale)

    def test_traces_equal_a_direct_solve(self):
        rows = self.rows()
        self.assign(rows)
        operator = self.dense_operator(rows)
        # Neumann: K u = f - B' lambda
        neumann = protocol.NeumannSolveRequest(contact_force=self.FORCE)
        trace = self.ask(neumann_solve=neumann).neumann_result.normal_trace
        displacement = self.direct_solution(self.body_load() - operator.T @ self.FORCE)
        self.assert_close(trace, operator @ displacement)
        # the free trace e = B u(lambda = 0): a contact solve with every obstacle far
        far = protocol.ContactSolveRequest(obstacle=[1.0] * 4)  # far: |B u| < 0.01
        result = self.ask(contact_solve=far).contact_result
        self.assertEqual(list(result.contact_force), [0.0] * 4)
        self.assert_close(result.normal_trace, operator @ self.direct_solution(self.body_load()))
        # the correction B w, K w = B' r with homogeneous Dirichlet conditions
        interface_force = np.array([0.2, 0.5, -0.3, 0.1])
        correction = protocol.CorrectionRequest(interface_force=interface_force)
        trace = self.ask(correction=correction).correction_result.normal_trace
        lifted = self.direct_solution(operator.T @ interface_force, homogeneous=True)
        self.assert_close(trace, operator @ lifted)

    def test_fields_carry_minus_b_transpose_lambda(self):
        rows = self.rows()
        self.assign(rows)
        operator = self.dense_operator(rows)
        reply = self.ask(fields=protocol.FieldsRequest(contact_force=self.FORCE)).fields_reply
        order = matching_nodes(np.array(reply.node_coordinates).reshape(-1, 2), self.nodes)
        fields = {field.name: np.array(field.values).reshape(-1, field.components)
                  for field in reply.point_fields}
        displacement = self.direct_solution(self.body_load() - operator.T @ self.FORCE)
        self.assert_close(fields["displacement"], displacement.reshape(-1, 2)[order])
        nodal = (operator.T @ self.FORCE).reshape(-1, 2)[order]
        self.assert_close(fields["contact_force"], -nodal)
        # the boundary weight of a node of the contact edge y = 0 (linear segments): half the
        # lengths of its segments (about 0.25, 0.5, 0.25 at x = 0, 0.5, 1)
        contact_nodes = np.flatnonzero(self.nodes[:, 1] == 0.0)
        contact_nodes = contact_nodes[np.argsort(self.nodes[contact_nodes, 0])]
        lengths = np.diff(self.nodes[contact_nodes, 0])
        weights = np.zeros(len(self.nodes))
        weights[contact_nodes] = 0.5 * (np.append(lengths, 0.0) + np.append(0.0, lengths))
        weights = weights[order]
        expected = np.zeros(len(weights))
        on_contact = weights > 0.0
        expected[on_contact] = np.hypot(nodal[on_contact, 0],
                                        nodal[on_contact, 1]) / weights[on_contact]
        self.assert_close(fields["contact_pressure"][:, 0], expected)

    def test_node_to_node_rows_are_the_vertical_displacements(self):
        normals = np.array(self.interface.normals).reshape(-1, 2)
        np.testing.assert_allclose(normals, np.tile([0.0, 1.0], (3, 1)), atol=1e-15)
        self.assertEqual(self.ask(assign_contact=support.node_to_node_assignment(
            protocol, self.interface)).acknowledge.state, "ready")
        force = np.array([0.4, 0.1, 0.9])
        trace = self.ask(neumann_solve=protocol.NeumannSolveRequest(contact_force=force))
        # B' lambda: lambda_i (0, 1) at contact node i
        load = self.body_load()
        load[2 * self.mesh_index + 1] -= force
        displacement = self.direct_solution(load)
        self.assert_close(trace.neumann_result.normal_trace,
                          displacement[2 * self.mesh_index + 1])


if __name__ == "__main__":
    unittest.main()
