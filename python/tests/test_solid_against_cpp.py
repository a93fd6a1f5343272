"""robin-subdomain-py against the C++ robin-subdomain (ROBIN_CONTACT_BIN, set by CTest to
build/bin) on the same solid bodies: both servers are started as processes, get the same
requests over ZeroMQ, and every number of their replies must agree to 1e-10 relative (to the
largest magnitude of the array it belongs to); integers, names and flags exactly.

The bodies (support.box_tetrahedra, box_hexahedra; interior nodes moved off the grid):
  - 4-node tetrahedra with a dense anisotropic 6x6 Voigt material, a body force, a traction
    vector and a pressure, Dirichlet conditions on one, two and three components, and two contact
    sides meeting at an edge (x1 and z1);
  - 8-node hexahedra with an isotropic material given by E and nu, the same loads and sides.
The requests: SetupBody, AssignContact (node-to-node rows with the C++ server's normals),
ContactSolveRequest with an obstacle that closes part of the contact, CorrectionRequest,
NeumannSolveRequest and FieldsRequest, all saying version 2.4: both servers, which speak 2.5,
answer SetupBody, AssignContact and FieldsRequest with a positive peak_resident_bytes (the
server's own minor version decides which fields a reply carries, not the request's); a
FieldsRequest with omit_fields_from_reply and write_directory (under each server's
--output-root) is answered by both without mesh and fields, with the same resultants.
"""

import os
import pathlib
import shutil
import subprocess
import tempfile
import unittest

import numpy as np
import zmq

import support
from robin_subdomain.proto_module import load_protocol

protocol = load_protocol()
TOLERANCE = 1e-10
LENGTHS = (2.0, 1.0, 1.0)


def bin_directory():
    """ROBIN_CONTACT_BIN; without it the tests are skipped (run outside CTest), with it
    robin-subdomain must be there (CTest does not build it: build robin-subdomain first)."""
    directory = os.environ.get("ROBIN_CONTACT_BIN", "")
    if not directory:
        raise unittest.SkipTest("ROBIN_CONTACT_BIN is not set (CTest sets it to build/bin)")
    if not (pathlib.Path(directory) / "robin-subdomain").is_file():
        raise RuntimeError("ROBIN_CONTACT_BIN=%s holds no robin-subdomain: build it first" %
                           directory)
    return pathlib.Path(directory)


class Server:
    """A server process on an ephemeral port and a REQ socket to it."""

    def __init__(self, command, context):
        self.process = subprocess.Popen(command + ["--listen", "tcp://127.0.0.1:*"],
                                        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                        text=True)
        line = self.process.stdout.readline().strip()
        if not line.startswith("listening on "):
            self.process.kill()
            raise RuntimeError("%s did not print its endpoint (got %r)" % (command[0], line))
        self.socket = context.socket(zmq.REQ)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.setsockopt(zmq.RCVTIMEO, 60000)
        self.socket.connect(line[len("listening on "):])
        self.request_id = 0

    def ask(self, **content):
        envelope = protocol.Envelope()
        self.request_id += 1
        envelope.request_id = self.request_id
        envelope.version.major, envelope.version.minor = 2, 4
        for name, message in content.items():
            getattr(envelope, name).CopyFrom(message)
        self.socket.send(envelope.SerializeToString())
        reply = protocol.Envelope()
        reply.ParseFromString(self.socket.recv())
        return reply

    def stop(self):
        self.ask(shutdown=protocol.Shutdown())
        self.socket.close()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def random_voigt():
    """A dense symmetric positive definite 6x6 Voigt stiffness (fixed seed)."""
    generator = np.random.default_rng(20261127)
    factor = generator.normal(size=(6, 6))
    return 100.0 * (factor @ factor.T + 6.0 * np.eye(6))


def loaded_body(mesh, **material):
    body = protocol.SetupBody(body_name="solid", contact_boundaries=["x1", "z1"],
                              body_force=[0.5, -1.0, -3.0], **material)
    body.mesh.CopyFrom(mesh)
    body.dirichlet.add(boundary="x0", x=0.0, y=0.0, z=-0.002)
    body.dirichlet.add(boundary="y0", y=0.0, z=-0.002)
    body.dirichlet.add(boundary="z0", z=-0.002)
    body.traction.add(boundary="x1", vector=[2.0, 1.0, -0.5])
    body.traction.add(boundary="y1", is_pressure=True, pressure=4.0)
    return body


def free_node_to_node_assignment(interface):
    """Node-to-node rows (the C++ server's normals and weights) on the contact nodes whose normal
    displacement is not prescribed (robin-coordinator leaves those out too: their row of B
    would lie on prescribed components only and F would be singular)."""
    normals = np.reshape(interface.normals, (-1, 3))
    fixed = np.reshape(interface.fixed, (-1, 3))
    keep = np.any((np.abs(normals) > 1e-12) & ~fixed, axis=1)
    ids = np.array(interface.node_ids)[keep]
    return protocol.AssignContact(
        row_offsets=range(0, 3 * len(ids) + 1, 3), node_ids=np.repeat(ids, 3),
        components=[0, 1, 2] * len(ids), values=normals[keep].ravel(),
        weights=np.array(interface.weights)[keep])


class AgainstCpp(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        directory = bin_directory()
        cls.context = zmq.Context()
        script = support.PYTHON_DIRECTORY / "robin-subdomain-py"
        cls.output_root = tempfile.mkdtemp(prefix="robin-against-cpp-")
        root = ["--output-root", cls.output_root]
        cls.cpp = Server([str(directory / "robin-subdomain")] + root, cls.context)
        cls.python = Server(["/usr/bin/python3", str(script)] + root, cls.context)

    @classmethod
    def tearDownClass(cls):
        cls.cpp.stop()
        cls.python.stop()
        cls.context.term()
        shutil.rmtree(cls.output_root)

    def both(self, **content):
        replies = [server.ask(**content) for server in (self.cpp, self.python)]
        for reply in replies:
            self.assertNotEqual(reply.WhichOneof("content"), "error", reply.error.message)
        self.assertEqual(replies[0].WhichOneof("content"), replies[1].WhichOneof("content"))
        return replies

    def close(self, cpp, python, what):
        cpp, python = np.asarray(cpp, dtype=float), np.asarray(python, dtype=float)
        self.assertEqual(cpp.shape, python.shape, what)
        scale = np.max(np.abs(cpp), initial=0.0)
        difference = np.max(np.abs(cpp - python), initial=0.0)
        self.assertLessEqual(difference, TOLERANCE * scale, "%s: max difference %g for a scale %g"
                             % (what, difference, scale))
        self.measured[what] = difference / scale if scale > 0 else 0.0

    def compare_interface(self, cpp, python):
        for name in ("body_name", "dimension", "node_ids", "node_tags", "fixed", "dof_count"):
            self.assertEqual(list(np.ravel(getattr(cpp, name))),
                             list(np.ravel(getattr(python, name))), name)
        self.assertEqual(list(cpp.coordinates), list(python.coordinates))
        self.close(cpp.normals, python.normals, "InterfaceDescription.normals")
        self.close(cpp.weights, python.weights, "InterfaceDescription.weights")
        self.assertEqual(len(cpp.surfaces), len(python.surfaces))
        for left, right in zip(cpp.surfaces, python.surfaces):
            self.assertEqual((left.boundary, left.segment_type, list(left.segments)),
                             (right.boundary, right.segment_type, list(right.segments)))

    def compare_fields(self, cpp, python):
        for name in ("dimension", "node_coordinates", "node_tags", "cell_types", "cell_offsets",
                     "connectivity"):
            self.assertEqual(list(np.ravel(getattr(cpp, name))),
                             list(np.ravel(getattr(python, name))), name)
        self.assertEqual([(b.name, b.segments.type, list(b.segments.connectivity))
                          for b in cpp.boundaries],
                         [(b.name, b.segments.type, list(b.segments.connectivity))
                          for b in python.boundaries])
        for kind in ("point_fields", "cell_fields"):
            left = {f.name: f for f in getattr(cpp, kind)}
            right = {f.name: f for f in getattr(python, kind)}
            self.assertEqual(sorted(left), sorted(right), kind)
            for name in left:
                self.assertEqual(left[name].components, right[name].components, name)
                self.close(left[name].values, right[name].values, "%s %s" % (kind, name))
        for name in ("reaction_resultant", "applied_force"):
            self.close(getattr(cpp, name), getattr(python, name), name)

    def expect_peak_resident_sizes(self, *pairs):
        """Both servers speak 2.5 and answer these requests, which say 2.4, with a positive
        peak_resident_bytes: the server's own minor version decides, not the request's."""
        for pair in pairs:
            for server, message in zip(("robin-subdomain", "robin-subdomain-py"), pair):
                self.assertGreater(message.peak_resident_bytes, 0,
                                   "%s, %s" % (server, message.DESCRIPTOR.name))

    def compare_omitted_fields(self, force, body_name):
        """FieldsRequest.omit_fields_from_reply (2.5) with write_directory: both replies without
        mesh and fields, with the same resultants, dimension and file name (each server writes
        its own file under its directory: cpp/, python/)."""
        replies = []
        for server, directory in ((self.cpp, "cpp"), (self.python, "python")):
            reply = server.ask(fields=protocol.FieldsRequest(
                contact_force=force, write_directory=directory, omit_fields_from_reply=True))
            self.assertEqual(reply.WhichOneof("content"), "fields_reply", reply)
            replies.append(reply.fields_reply)
            self.assertEqual(reply.fields_reply.written_file,
                             os.path.join(self.output_root, directory, body_name + ".vtu"))
            self.assertTrue(os.path.isfile(reply.fields_reply.written_file))
        for name in ("node_coordinates", "node_tags", "cell_types", "cell_offsets",
                     "connectivity", "point_fields", "cell_fields", "boundaries"):
            self.assertEqual([len(getattr(reply, name)) for reply in replies], [0, 0], name)
        self.assertEqual([reply.dimension for reply in replies], [3, 3])
        self.assertEqual([[entry.stage for entry in reply.stage_times] for reply in replies],
                         [["fields"], ["fields"]])
        for name in ("reaction_resultant", "applied_force"):
            self.close(getattr(replies[0], name), getattr(replies[1], name), "omitted " + name)

    def run_body(self, body):
        self.measured = {}
        cpp, python = self.both(setup_body=body)
        self.compare_interface(cpp.interface, python.interface)
        assign = free_node_to_node_assignment(cpp.interface)
        count = len(assign.weights)
        acknowledgements = self.both(assign_contact=assign)
        self.expect_peak_resident_sizes([cpp.interface, python.interface],
                                        [reply.acknowledge for reply in acknowledgements])
        # Free trace first (far obstacle), then an obstacle that closes the nodes with x < 1.
        far = self.both(contact_solve=protocol.ContactSolveRequest(obstacle=[1.0] * count))
        free = np.array(far[0].contact_result.normal_trace)
        positions = np.searchsorted(cpp.interface.node_ids, assign.node_ids[::3])
        x = np.reshape(cpp.interface.coordinates, (-1, 3))[positions, 0]
        obstacle = free + 0.002 * (x - 1.0)
        cpp, python = self.both(contact_solve=protocol.ContactSolveRequest(
            obstacle=obstacle.tolist(), iteration=2))
        for reply in (cpp, python):
            self.assertEqual(reply.contact_result.status, protocol.CONVERGED,
                             reply.contact_result.message)
        active = list(cpp.contact_result.active)
        self.assertEqual(active, list(python.contact_result.active))
        self.assertTrue(0 < sum(active) < count, active)
        for name in ("normal_trace", "contact_force"):
            self.close(getattr(cpp.contact_result, name), getattr(python.contact_result, name),
                       "ContactSolveResult." + name)
        force = list(cpp.contact_result.contact_force)
        probe = (1.0 + 0.5 * np.cos(1.3 * np.arange(count))).tolist()
        cpp_correction, python_correction = self.both(correction=protocol.CorrectionRequest(
            interface_force=probe))
        self.close(cpp_correction.correction_result.normal_trace,
                   python_correction.correction_result.normal_trace, "CorrectionResult")
        cpp_neumann, python_neumann = self.both(neumann_solve=protocol.NeumannSolveRequest(
            contact_force=force))
        self.close(cpp_neumann.neumann_result.normal_trace,
                   python_neumann.neumann_result.normal_trace, "NeumannSolveResult")
        cpp_fields, python_fields = self.both(fields=protocol.FieldsRequest(contact_force=force))
        self.compare_fields(cpp_fields.fields_reply, python_fields.fields_reply)
        self.expect_peak_resident_sizes([cpp_fields.fields_reply, python_fields.fields_reply])
        self.compare_omitted_fields(force, body.body_name)
        self.both(end_run=protocol.EndRun())
        worst = max(self.measured, key=self.measured.get)
        print("\n%s: %d comparisons, largest relative difference %.3g (%s)" % (
            body.mesh.cells[0].type == protocol.TETRAHEDRON4 and "tetrahedra" or "hexahedra",
            len(self.measured), self.measured[worst], worst))

    def test_tetrahedra_with_an_anisotropic_material(self):
        nodes, elements, sides = support.box_tetrahedra((4, 2, 2), LENGTHS, 0.2)
        mesh = support.solid_mesh_data(protocol, nodes, "TETRAHEDRON4", elements, sides)
        self.run_body(loaded_body(mesh, voigt=np.ravel(random_voigt()).tolist()))

    def test_hexahedra_with_an_isotropic_material(self):
        nodes, elements, sides = support.box_hexahedra((4, 2, 2), LENGTHS, 0.2)
        mesh = support.solid_mesh_data(protocol, nodes, "HEXAHEDRON8", elements, sides)
        self.run_body(loaded_body(mesh, young_modulus=1000.0, poisson_ratio=0.3))


if __name__ == "__main__":
    unittest.main()
