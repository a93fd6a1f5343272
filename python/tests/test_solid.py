"""Solid bodies (protocol 2.4) on the Python server, without a socket. The meshes are built here
(support.box_tetrahedra, box_hexahedra: a box of cubes, each split into six tetrahedra, interior
nodes moved off the grid) and every expected number comes from closed-form elasticity, not from
the package:
  - patch tests: a uniform strain is reproduced exactly (to round-off, 1e-12 relative) on
    distorted tetrahedra and hexahedra, driven by Dirichlet conditions (uniaxial stress:
    u_x = d x / L, u_y = -nu d y / L, u_z = -nu d z / L) and by a traction vector on a face with
    an orthotropic 36-value Voigt material (strain = S (p, 0, 0, 0, 0, 0), S its compliance);
    the stresses, the reactions on the driven face and the applied force too;
  - the InterfaceDescription of two contact sides meeting at an edge: weights a third of the
    adjacent triangles' areas, normals the normalised area-weighted sums of the adjacent faces'
    normals, faces oriented outward, the fixed flags;
  - the contact solve of a block pressed onto a rigid plane: every node active, contact forces
    p m_i with the uniform pressure p = E d / H, normal trace 0; the Neumann solve and the
    correction agree (u_N(lambda) - u_N(0) = -F lambda);
  - the refusals: TETRAHEDRON10 cells and TRIANGLE6 faces UNSUPPORTED naming the type, and
    BAD_INPUT, INVALID_ARGUMENT or SINGULAR_BODY for malformed solid input, the server going on;
  - the .vtu file of a solid body (tetrahedra, boundary triangles, three-component vectors).
"""

import pathlib
import shutil
import tempfile
import unittest

import numpy as np

import support
from robin_contact import read_vtu
from robin_subdomain.proto_module import load_protocol
from robin_subdomain.protocol import SubdomainProtocol

protocol = load_protocol()
LENGTHS = (2.0, 1.0, 1.0)
CELLS = (4, 2, 2)
YOUNG, POISSON = 1000.0, 0.3


def request(**content):
    envelope = protocol.Envelope(request_id=5)
    envelope.version.major, envelope.version.minor = 2, 4
    for name, message in content.items():
        getattr(envelope, name).CopyFrom(message)
    return envelope.SerializeToString()


def box_mesh(kind="TETRAHEDRON4", perturbation=0.2, cells=CELLS):
    build = support.box_tetrahedra if kind == "TETRAHEDRON4" else support.box_hexahedra
    nodes, elements, sides = build(cells, LENGTHS, perturbation)
    return nodes, sides, support.solid_mesh_data(protocol, nodes, kind, elements, sides)


def solid_body(mesh, dirichlet, contact=("z1",), **fields):
    """SetupBody 'block' of `mesh` with dirichlet [(boundary, component, value)]."""
    message = protocol.SetupBody(body_name="block", contact_boundaries=list(contact), **fields)
    if not message.voigt:
        message.young_modulus, message.poisson_ratio = YOUNG, POISSON
    message.mesh.CopyFrom(mesh)
    for boundary, component, value in dirichlet:
        condition = message.dirichlet.add(boundary=boundary)
        setattr(condition, component, value)
    return message


ROLLERS = [("x0", "x", 0.0), ("y0", "y", 0.0), ("z0", "z", 0.0)]


class SolidServerTestCase(unittest.TestCase):
    def setUp(self):
        self.server = SubdomainProtocol(protocol)
        self.server.logger.disabled = True

    def ask(self, data):
        reply = protocol.Envelope()
        reply.ParseFromString(self.server.handle(data))
        return reply

    def set_up(self, body):
        reply = self.ask(request(setup_body=body))
        self.assertEqual(reply.WhichOneof("content"), "interface", reply)
        interface = reply.interface
        assign = support.solid_node_to_node_assignment(protocol, interface)
        self.assertEqual(self.ask(request(assign_contact=assign)).acknowledge.state, "ready")
        return interface

    def fields(self, count, force=None, write_directory=""):
        force = [0.0] * count if force is None else force
        reply = self.ask(request(fields=protocol.FieldsRequest(
            contact_force=force, write_directory=write_directory)))
        self.assertEqual(reply.WhichOneof("content"), "fields_reply", reply)
        return reply.fields_reply

    def refused(self, data, code, *fragments):
        reply = self.ask(data)
        self.assertEqual(reply.WhichOneof("content"), "error", reply)
        self.assertEqual(protocol.ErrorCode.Name(reply.error.code), code, reply.error.message)
        for fragment in fragments:
            self.assertIn(fragment, reply.error.message)
        self.assertEqual(self.ask(request(hello=protocol.Hello())).WhichOneof("content"),
                         "hello_reply")
        return reply.error.message


def field(reply, name, cells=False):
    found = [f for f in (reply.cell_fields if cells else reply.point_fields) if f.name == name]
    return np.reshape(found[0].values, (-1, found[0].components))


class PatchTests(SolidServerTestCase):
    def expect_uniform(self, reply, nodes, strain, stress):
        """Displacement = strain (as a matrix) x at every node; stress uniform."""
        gradient = np.array([[strain[0], strain[5], strain[4]],
                             [strain[5], strain[1], strain[3]],
                             [strain[4], strain[3], strain[2]]])
        gradient[np.triu_indices(3, 1)] *= 0.5     # engineering shears
        gradient[np.tril_indices(3, -1)] *= 0.5
        exact = nodes @ gradient.T
        displacement = field(reply, "displacement")
        scale = np.max(np.abs(exact))
        error = np.max(np.abs(displacement - exact)) / scale
        self.assertLess(error, 1e-12)
        # Voigt (xx, yy, zz, yz, xz, xy) as ParaView's (XX, YY, ZZ, XY, YZ, XZ).
        tensor = np.asarray(stress)[[0, 1, 2, 5, 3, 4]]
        for values in (field(reply, "stress"), field(reply, "stress", cells=True)):
            self.assertLess(np.max(np.abs(values - tensor)) / np.max(np.abs(stress)), 1e-12)
        return error

    def test_dirichlet_driven_uniaxial_stress_on_distorted_tetrahedra(self):
        nodes, _, mesh = box_mesh()
        stretch = 0.01
        body = solid_body(mesh, [("x0", "x", 0.0), ("x1", "x", stretch), ("y0", "y", 0.0),
                                 ("z0", "z", 0.0)])
        count = len(self.set_up(body).node_ids)
        reply = self.fields(count)
        self.assertEqual(reply.dimension, 3)
        self.assertEqual(list(reply.cell_types), [10])
        strain = stretch / LENGTHS[0]
        self.expect_uniform(reply, nodes, [strain, -POISSON * strain, -POISSON * strain, 0, 0, 0],
                            [YOUNG * strain, 0, 0, 0, 0, 0])
        # The supports at x = L pull with the stress times the side's area.
        reaction = field(reply, "reaction")
        on_right = np.abs(nodes[:, 0] - LENGTHS[0]) < 1e-12
        pull = reaction[on_right, 0].sum()
        self.assertAlmostEqual(pull / (YOUNG * strain * LENGTHS[1] * LENGTHS[2]), 1.0, places=12)
        self.assertLess(np.max(np.abs(reply.reaction_resultant)), 1e-12 * pull)

    def traction_patch(self, kind, voigt, compliance):
        nodes, _, mesh = box_mesh(kind)
        pull = 7.5
        body = solid_body(mesh, ROLLERS, voigt=np.ravel(voigt).tolist())
        body.traction.add(boundary="x1", vector=[pull, 0.0, 0.0])
        count = len(self.set_up(body).node_ids)
        reply = self.fields(count)
        area = LENGTHS[1] * LENGTHS[2]
        np.testing.assert_allclose(reply.applied_force, [pull * area, 0.0, 0.0], rtol=1e-13,
                                   atol=1e-13 * pull * area)
        np.testing.assert_allclose(reply.reaction_resultant, [-pull * area, 0.0, 0.0],
                                   rtol=1e-11, atol=1e-11 * pull * area)
        stress = np.array([pull, 0, 0, 0, 0, 0])
        return self.expect_uniform(reply, nodes, compliance @ stress, stress)

    def test_traction_on_an_orthotropic_voigt_material_on_tetrahedra(self):
        compliance = support.orthotropic_compliance((1000.0, 400.0, 250.0), (0.25, 0.2, 0.3),
                                                    (150.0, 120.0, 300.0))
        self.traction_patch("TETRAHEDRON4", np.linalg.inv(compliance), compliance)

    def test_traction_on_distorted_hexahedra(self):
        voigt = support.isotropic_solid_voigt(YOUNG, POISSON)
        self.traction_patch("HEXAHEDRON8", voigt, np.linalg.inv(voigt))


class ContactBoundaryDescription(SolidServerTestCase):
    def test_two_sides_meeting_at_an_edge(self):
        nodes, sides, mesh = box_mesh(perturbation=0.0, cells=(2, 2, 2))
        interface = self.set_up(solid_body(mesh, ROLLERS, contact=("x1", "z1")))
        self.assertEqual(interface.dimension, 3)
        ids = np.array(interface.node_ids)
        expected_ids = np.unique(np.concatenate([sides["x1"].ravel(), sides["z1"].ravel()]))
        np.testing.assert_array_equal(ids, expected_ids)
        np.testing.assert_array_equal(np.reshape(interface.coordinates, (-1, 3)), nodes[ids])
        # Per node: a third of each adjacent triangle's area; area-weighted normal sums.
        weights = np.zeros(len(nodes))
        sums = np.zeros((len(nodes), 3))
        outward = {"x1": np.array([1.0, 0.0, 0.0]), "z1": np.array([0.0, 0.0, 1.0])}
        for name in ("x1", "z1"):
            for face in sides[name]:
                x = nodes[face]
                area = 0.5 * np.linalg.norm(np.cross(x[1] - x[0], x[2] - x[0]))
                weights[face] += area / 3.0
                sums[face] += area * outward[name]
        np.testing.assert_allclose(interface.weights, weights[ids], rtol=1e-14)
        self.assertAlmostEqual(sum(interface.weights),
                               LENGTHS[1] * LENGTHS[2] + LENGTHS[0] * LENGTHS[1], places=13)
        normals = sums[ids] / np.linalg.norm(sums[ids], axis=1)[:, None]
        np.testing.assert_allclose(np.reshape(interface.normals, (-1, 3)), normals, atol=1e-15)
        edge = [k for k, node in enumerate(ids) if sums[node, 0] > 0 and sums[node, 2] > 0]
        self.assertEqual(len(edge), 3)   # x = 2, z = 1, y = 0, 0.5, 1
        # Each surface's faces, as positions into node_ids, have outward right-hand normals.
        for surface in interface.surfaces:
            self.assertEqual(surface.segment_type, protocol.TRIANGLE3)
            faces = ids[np.reshape(surface.segments, (-1, 3))]
            self.assertEqual(len(faces), len(sides[surface.boundary]))
            x = nodes[faces]
            normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
            self.assertTrue(np.all(normal @ outward[surface.boundary] > 0.0), surface.boundary)
        # Component c is prescribed where the node lies on the roller side c = 0.
        fixed = np.reshape(interface.fixed, (-1, 3))
        np.testing.assert_array_equal(fixed, np.abs(nodes[ids]) < 1e-12)
        self.assertTrue(np.all(np.any(fixed, axis=0)))


class CompressedBlock(SolidServerTestCase):
    """The block on a rigid plane z = 0 (contact side z0, normal -z), pushed down by d at its top,
    rollers on x0 and y0: a uniform uniaxial compression, pressure p = E d / H."""

    def test_contact_solve_neumann_solve_and_correction(self):
        nodes, _, mesh = box_mesh()
        push = 0.01
        body = solid_body(mesh, [("x0", "x", 0.0), ("y0", "y", 0.0), ("z1", "z", -push)],
                          contact=("z0",))
        interface = self.set_up(body)
        count = len(interface.node_ids)
        normals = np.reshape(interface.normals, (-1, 3))
        np.testing.assert_allclose(normals, np.tile([0.0, 0.0, -1.0], (count, 1)), atol=1e-15)
        reply = self.ask(request(contact_solve=protocol.ContactSolveRequest(
            obstacle=[0.0] * count, iteration=1))).contact_result
        self.assertEqual(reply.status, protocol.CONVERGED, reply.message)
        self.assertTrue(all(reply.active))
        pressure = YOUNG * push / LENGTHS[2]
        np.testing.assert_allclose(reply.contact_force, pressure * np.array(interface.weights),
                                   rtol=1e-10)
        self.assertLess(np.max(np.abs(reply.normal_trace)), 1e-12 * push)
        force = np.array(reply.contact_force)
        fields = self.fields(count, force.tolist())
        self.assertLess(np.max(np.abs(field(fields, "contact_pressure")[nodes[:, 2] < 1e-12] -
                                      pressure)), 1e-9 * pressure)
        # u_N(lambda) = e - F lambda, u_N(0) = e: their difference is minus the correction.
        traces = [np.array(self.ask(request(neumann_solve=protocol.NeumannSolveRequest(
            contact_force=values, iteration=1))).neumann_result.normal_trace)
            for values in (force.tolist(), [0.0] * count)]
        correction = np.array(self.ask(request(correction=protocol.CorrectionRequest(
            interface_force=force.tolist(), iteration=1))).correction_result.normal_trace)
        self.assertLess(np.max(np.abs(traces[0])), 1e-11 * push)
        np.testing.assert_allclose(traces[0] - traces[1], -correction, rtol=1e-9,
                                   atol=1e-11 * push)


class SolidRefusals(SolidServerTestCase):
    def setUp(self):
        super().setUp()
        _, _, self.mesh = box_mesh(cells=(2, 1, 1))

    def changed(self, change, **fields):
        mesh = protocol.MeshData()
        mesh.CopyFrom(self.mesh)
        change(mesh)
        return request(setup_body=solid_body(mesh, ROLLERS, **fields))

    def test_unimplemented_cell_types_are_unsupported_naming_the_type(self):
        def quadratic(mesh):
            mesh.cells[0].type = protocol.TETRAHEDRON10
        self.refused(self.changed(quadratic), "UNSUPPORTED", "cells[0].type is TETRAHEDRON10",
                     "robin-subdomain-py")

        def quadratic_face(mesh):
            mesh.boundaries[0].segments.type = protocol.TRIANGLE6
        self.refused(self.changed(quadratic_face), "UNSUPPORTED",
                     "boundaries[0].segments.type is TRIANGLE6")

    def test_malformed_solid_input_is_bad_input(self):
        cases = [
            (lambda mesh: mesh.coordinates.append(1.0), {},
             "coordinates has 37 values, expected 3 per node (x, y, z)"),
            (lambda mesh: setattr(mesh.cells[0], "type", protocol.TRIANGLE3), {},
             "cells[0].type is TRIANGLE3, expected TETRAHEDRON4 or HEXAHEDRON8"),
            (lambda mesh: setattr(mesh.boundaries[0].segments, "type", protocol.LINE2), {},
             "boundaries[0].segments.type is LINE2, expected TRIANGLE3 or QUADRILATERAL4"),
            (lambda mesh: _swap(mesh.cells[0].connectivity, 1, 2), {},
             "cell tag 1 (tetrahedron4) is inverted"),
            (lambda mesh: None, {"voigt": [1.0] * 9}, "voigt has 9 values, expected 36"),
            (lambda mesh: None, {"body_force": [1.0, 2.0]},
             "body_force has 2 values, expected 3 (x, y, z)"),
        ]
        for change, fields, fragment in cases:
            if "voigt" in fields:
                body = solid_body(self.mesh, ROLLERS, voigt=fields["voigt"])
                self.refused(request(setup_body=body), "BAD_INPUT", fragment)
            else:
                self.refused(self.changed(change, **fields), "BAD_INPUT", fragment)

    def test_a_face_that_is_no_side_of_a_cell_and_a_free_rigid_motion(self):
        body = solid_body(self.mesh, ROLLERS)
        faces = body.mesh.boundaries[5].segments.connectivity     # z1
        # Its third face, corners (1, 0, 1), (2, 0, 1), (2, 1, 1), with the first moved to the
        # node (0, 0, 0): a triangle across the box, a side of no tetrahedron.
        faces[6] = 0
        self.refused(request(setup_body=body), "BAD_INPUT", "is not a side of any volume element")
        self.refused(request(setup_body=solid_body(self.mesh, ROLLERS[:2])), "SINGULAR_BODY",
                     "rigid motion")

    def test_a_component_beyond_z_is_invalid_argument(self):
        interface = self.set_up(solid_body(self.mesh, ROLLERS))
        assign = support.solid_node_to_node_assignment(protocol, interface)
        assign.components[2] = 3
        self.refused(request(assign_contact=assign), "INVALID_ARGUMENT",
                     "components[2] is 3, expected 0 (x), 1 (y) or 2 (z)")


def _swap(values, first, second):
    values[first], values[second] = values[second], values[first]


class SolidVtuFile(SolidServerTestCase):
    def setUp(self):
        self.root = pathlib.Path(tempfile.mkdtemp(prefix="robin-py-solid-"))
        self.server = SubdomainProtocol(protocol, output_root=str(self.root))
        self.server.logger.disabled = True

    def tearDown(self):
        shutil.rmtree(self.root)

    def test_tetrahedra_and_boundary_faces_with_three_component_vectors(self):
        nodes, sides, mesh = box_mesh(cells=(2, 1, 1))
        count = len(self.set_up(solid_body(mesh, ROLLERS)).node_ids)
        reply = self.fields(count, [0.1] * count, "out")
        grid = read_vtu(reply.written_file)
        np.testing.assert_array_equal(grid.points, nodes)
        faces = sum(len(faces) for faces in sides.values())
        self.assertEqual(list(np.bincount(grid.types)[[5, 10]]), [faces, 12])
        np.testing.assert_allclose(grid.point_data["displacement"], field(reply, "displacement"),
                                   rtol=0, atol=0)
        self.assertEqual(grid.point_data["contact_force"].shape, (len(nodes), 3))


if __name__ == "__main__":
    unittest.main()
