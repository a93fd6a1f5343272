"""Finite elements of the Python subdomain server against analytic solutions.

- Patch test: a linear displacement field prescribed on the whole boundary of a skewed,
  non-convex hexagon is reproduced at every interior node (P1, P2, Q1) and its stress is C eps.
- Uniaxial tension with rollers (left u_x = 0, bottom u_y = 0) and a traction or pressure on the
  right side: the nodal displacements are the analytic ones, plane strain and plane stress,
  isotropic and orthotropic (Voigt) materials; reactions balance the applied force.
- Body force, boundary weights and outward normals of a rectangle: totals and directions.
- The .msh 2.2 and 4.1 files of the same mesh read alike (binary and 4.0 files through gmsh);
  rigid motions left free and conflicting Dirichlet values are refused.
- MeshData (protocol 2.0): a mesh sent as data decodes to the mesh it was made from, the patch
  tests pass through it, and a crossed ("bow-tie") quadrilateral is refused by its tag.
"""

import os
import subprocess
import tempfile
import unittest

import numpy as np
import scipy.sparse.linalg

import support
from robin_subdomain import fem
from robin_subdomain.mesh_data import decode_mesh_data
from robin_subdomain.proto_module import load_protocol
from robin_subdomain.body import Body, BodyDefinition
from robin_subdomain.errors import InputError, SingularBodyError
from robin_subdomain.material import (PLANE_STRAIN, PLANE_STRESS, isotropic_material,
                                      voigt_material)
from robin_subdomain.mesh import QUADRILATERAL4, TRIANGLE3, TRIANGLE6, read_mesh

protocol = load_protocol()
YOUNG, POISSON = 210.0, 0.3
# u(x) = a + G x with a general (non-symmetric) gradient G
OFFSET = np.array([0.01, -0.02])
GRADIENT = np.array([[2e-3, -1e-3], [5e-4, 3e-3]])


def hexagon(element_order=1, recombine=False):
    return read_mesh(support.TEST_DATA / "mesh_irregular.geo", "mesh_irregular.geo", 0.3,
                     element_order, recombine)


def through_mesh_data(mesh, source="test"):
    """The mesh sent as MeshData and decoded by the server."""
    return decode_mesh_data(support.mesh_data(protocol, mesh, source), protocol, "body 'test'")


class PatchTest(unittest.TestCase):
    THROUGH_MESH_DATA = False

    def check_patch(self, mesh, expected_type):
        if self.THROUGH_MESH_DATA:
            mesh = through_mesh_data(mesh)
        self.assertIn(expected_type, [block.type for block in mesh.blocks])
        material = isotropic_material(YOUNG, POISSON, PLANE_STRAIN, "patch")
        stiffness = fem.assemble_stiffness(mesh, material)
        exact = (OFFSET + mesh.nodes @ GRADIENT.T).ravel()
        boundary = np.unique(np.concatenate([g.nodes() for g in mesh.boundaries.values()]))
        prescribed = np.zeros(2 * mesh.node_count(), dtype=bool)
        prescribed[2 * boundary] = prescribed[2 * boundary + 1] = True
        free = ~prescribed
        self.assertGreater(free.sum(), 20)
        # K_ff u_f = -K_fp u_p
        right_hand_side = -stiffness[free][:, prescribed] @ exact[prescribed]
        solution = scipy.sparse.linalg.spsolve(stiffness[free][:, free].tocsc(), right_hand_side)
        error = np.max(np.abs(solution - exact[free])) / np.max(np.abs(exact))
        self.assertLess(error, 1e-12)
        strain = np.array([GRADIENT[0, 0], GRADIENT[1, 1], GRADIENT[0, 1] + GRADIENT[1, 0]])
        element_stress, nodal_stress, _, _ = fem.recover_stress(mesh, material, exact)
        expected = material.stiffness @ strain
        self.assertLess(np.max(np.abs(element_stress - expected)), 1e-12 * np.abs(expected).max())
        self.assertLess(np.max(np.abs(nodal_stress - expected)), 1e-12 * np.abs(expected).max())

    def test_linear_triangles(self):
        self.check_patch(hexagon(), TRIANGLE3)

    def test_quadratic_triangles(self):
        self.check_patch(hexagon(element_order=2), TRIANGLE6)

    def test_bilinear_quadrilaterals(self):
        self.check_patch(hexagon(recombine=True), QUADRILATERAL4)


class PatchTestThroughMeshData(PatchTest):
    THROUGH_MESH_DATA = True


def rectangle(element_order=1, recombine=False):
    return support.mesh_from_geo(support.RECTANGLE_GEO, 0.0, element_order, recombine)


def uniaxial_body(mesh, material, traction):
    """Rollers on the left (u_x = 0) and bottom (u_y = 0); `traction` on the right."""
    return Body(BodyDefinition("block", mesh, material, (0.0, 0.0),
                               [("left", 0.0, None), ("bottom", None, 0.0)], [traction],
                               ["top"]))


class UniaxialTension(unittest.TestCase):
    def check(self, mesh, material, traction, stress_xx):
        body = uniaxial_body(mesh, material, traction)
        # strain = C^-1 (s, 0, 0): u_x = e_xx x, u_y = e_yy y
        strain = np.linalg.solve(material.stiffness, [stress_xx, 0.0, 0.0])
        self.assertAlmostEqual(strain[2], 0.0, delta=1e-15)
        exact = np.column_stack([strain[0] * mesh.nodes[:, 0], strain[1] * mesh.nodes[:, 1]])
        displacement = body.free_solution
        full = body.prescribed_full.copy()
        full[body.free_dofs] = displacement
        scale = np.max(np.abs(exact))
        self.assertLess(np.max(np.abs(full - exact.ravel())), 1e-12 * scale)
        # the reactions balance the traction resultant (right side of height 1)
        resultant = body.reactions(full).reshape(-1, 2).sum(axis=0)
        self.assertAlmostEqual(body.applied_force()[0], stress_xx, delta=1e-12 * abs(stress_xx))
        self.assertAlmostEqual(resultant[0], -stress_xx, delta=1e-12 * abs(stress_xx))

    def test_plane_strain_traction_p1(self):
        material = isotropic_material(YOUNG, POISSON, PLANE_STRAIN, "test")
        self.check(rectangle(), material, ("right", (4.0, 0.0), None), 4.0)

    def test_plane_stress_pressure_p2(self):
        material = isotropic_material(YOUNG, POISSON, PLANE_STRESS, "test")
        self.check(rectangle(element_order=2), material, ("right", None, 3.0), -3.0)

    def test_orthotropic_voigt_q1(self):
        material = voigt_material([300.0, 60.0, 0.0, 60.0, 150.0, 0.0, 0.0, 0.0, 40.0],
                                  PLANE_STRESS, "test")
        self.check(rectangle(recombine=True), material, ("right", (-2.5, 0.0), None), -2.5)

    def test_plane_strain_matches_the_closed_form(self):
        material = isotropic_material(YOUNG, POISSON, PLANE_STRAIN, "test")
        compliance = np.linalg.inv(material.stiffness)
        # plane strain: e_xx = (1 - nu^2)/E s, e_yy = -nu (1 + nu)/E s
        self.assertAlmostEqual(compliance[0, 0], (1 - POISSON ** 2) / YOUNG, delta=1e-15)
        self.assertAlmostEqual(compliance[1, 0], -POISSON * (1 + POISSON) / YOUNG, delta=1e-15)


class LoadsAndBoundaries(unittest.TestCase):
    def test_body_force_total_is_force_times_area(self):
        for mesh in (rectangle(), rectangle(element_order=2), rectangle(recombine=True)):
            load = fem.assemble_body_force(mesh, np.array([0.5, -9.81]))
            total = load.reshape(-1, 2).sum(axis=0)
            np.testing.assert_allclose(total, [1.0, -19.62], rtol=1e-13)

    def test_linear_triangle_body_force_is_a_third_of_the_areas(self):
        mesh = rectangle()
        load = fem.assemble_body_force(mesh, np.array([0.0, 1.0]))
        expected = np.zeros(mesh.node_count())
        for element in mesh.blocks[0].connectivity:
            a, b, c = mesh.nodes[element]
            area = 0.5 * abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
            expected[element] += area / 3.0
        np.testing.assert_allclose(load[1::2], expected, rtol=1e-13, atol=1e-16)

    def test_weights_sum_to_the_length_and_normals_point_outward(self):
        expected_normals = {"bottom": (0, -1), "right": (1, 0), "top": (0, 1), "left": (-1, 0)}
        lengths = {"bottom": 2.0, "right": 1.0, "top": 2.0, "left": 1.0}
        for mesh in (rectangle(), rectangle(element_order=2), rectangle(recombine=True)):
            for name, group in mesh.boundaries.items():
                edges = fem.EdgeSet(mesh, name, group)
                weights = fem.boundary_weights(mesh, edges)
                self.assertAlmostEqual(weights.sum(), lengths[name], delta=1e-13)
                normals = fem.boundary_node_normals(mesh, edges)
                np.testing.assert_allclose(normals, np.tile(expected_normals[name],
                                                            (len(normals), 1)), atol=1e-14)

    def test_line2_weights_are_half_the_adjacent_edges(self):
        mesh = rectangle()
        group = mesh.boundaries["top"]
        weights = fem.boundary_weights(mesh, fem.EdgeSet(mesh, "top", group))
        expected = np.zeros(mesh.node_count())
        for first, second in group.connectivity:
            length = np.linalg.norm(mesh.nodes[second] - mesh.nodes[first])
            expected[[first, second]] += 0.5 * length
        np.testing.assert_allclose(weights, expected, rtol=1e-13, atol=1e-16)


class MeshesAndConditions(unittest.TestCase):
    def test_msh_22_and_41_read_alike(self):
        old = read_mesh(support.TEST_DATA / "mesh_square_v22.msh", "v22")
        new = read_mesh(support.TEST_DATA / "mesh_square_v41.msh", "v41")
        np.testing.assert_array_equal(old.nodes, new.nodes)
        np.testing.assert_array_equal(old.node_tags, new.node_tags)
        self.assertEqual(sorted(old.boundaries), ["14", "bottom", "right", "top"])
        self.assertEqual(sorted(old.boundaries), sorted(new.boundaries))
        for a, b in zip(old.blocks, new.blocks):
            self.assertEqual(a.type, b.type)
            np.testing.assert_array_equal(np.sort(a.connectivity, axis=1),
                                          np.sort(b.connectivity, axis=1))
        self.assertEqual(old.node_count(), 12)  # the unit square's 12 nodes, not the stray point

    def test_binary_and_other_versions_read_like_ascii_41(self):
        with tempfile.TemporaryDirectory() as directory:
            geo = os.path.join(directory, "rectangle.geo")
            with open(geo, "w") as stream:
                stream.write(support.RECTANGLE_GEO)
            meshes = []
            for name, options in (("ascii41.msh", ["-format", "msh41"]),
                                  ("binary41.msh", ["-format", "msh41", "-bin"]),
                                  ("ascii40.msh", ["-format", "msh40"]),
                                  ("ascii22.msh", ["-format", "msh22"])):
                path = os.path.join(directory, name)
                subprocess.run(["gmsh", geo, "-2", "-o", path, "-v", "0"] + options, check=True)
                meshes.append(read_mesh(path, name))
        for other in meshes[1:]:
            np.testing.assert_array_equal(other.nodes, meshes[0].nodes)
            np.testing.assert_array_equal(other.blocks[0].connectivity,
                                          meshes[0].blocks[0].connectivity)
            self.assertEqual(sorted(other.boundaries), ["bottom", "left", "right", "top"])

    def test_free_rotation_is_a_singular_body(self):
        material = isotropic_material(YOUNG, POISSON, PLANE_STRAIN, "test")
        definition = BodyDefinition("loose", rectangle(), material, (0.0, 0.0),
                                    [("left", 0.0, None)], [], ["top"])
        with self.assertRaises(SingularBodyError):
            Body(definition)

    def test_conflicting_dirichlet_values_are_refused(self):
        material = isotropic_material(YOUNG, POISSON, PLANE_STRAIN, "test")
        definition = BodyDefinition("clash", rectangle(), material, (0.0, 0.0),
                                    [("left", 0.0, 0.0), ("bottom", 0.1, 0.0)], [], ["top"])
        with self.assertRaisesRegex(InputError, "prescribe different values"):
            Body(definition)



class MeshDataDecoding(unittest.TestCase):
    def test_decodes_to_the_mesh_it_was_made_from(self):
        mesh = read_mesh(support.TEST_DATA / "mesh_square_v41.msh", "v41")
        decoded = through_mesh_data(mesh)
        np.testing.assert_array_equal(decoded.nodes, mesh.nodes)
        np.testing.assert_array_equal(decoded.node_tags, mesh.node_tags)
        self.assertEqual([block.type for block in decoded.blocks], [TRIANGLE3])
        np.testing.assert_array_equal(decoded.blocks[0].connectivity, mesh.blocks[0].connectivity)
        np.testing.assert_array_equal(decoded.blocks[0].tags, np.arange(1, 15))
        self.assertEqual(sorted(decoded.boundaries), sorted(mesh.boundaries))
        for name, group in mesh.boundaries.items():
            np.testing.assert_array_equal(decoded.boundaries[name].connectivity,
                                          group.connectivity)

    def quadrilateral(self, corners):
        message = protocol.MeshData(dimension=2, source="quadrilateral.msh")
        message.coordinates.extend(np.ravel(corners).tolist())
        message.cells.add(type=protocol.QUADRILATERAL4, connectivity=[0, 1, 2, 3], tags=[5])
        return decode_mesh_data(message, protocol, "body 'test'")

    def test_crossed_quadrilateral_is_refused(self):
        self.assertEqual(self.quadrilateral([[0, 0], [1, 0], [1.2, 1], [0, 0.8]])
                         .element_count(), 1)
        # corners 0, 1, 2 turn left, the last edge crosses the first: a bow tie
        with self.assertRaisesRegex(InputError, r"^body 'test': SetupBody.mesh.cells\[0\]: cell "
                                    r"tag 5 \(quadrilateral4\) is inverted, folded or "
                                    r"degenerate.*\(mesh 'quadrilateral.msh'\)$"):
            self.quadrilateral([[0, 0], [1, 0], [0, 1], [1, 1]])


if __name__ == "__main__":
    unittest.main()
