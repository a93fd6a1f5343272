"""The protocol state machine of the Python subdomain server (protocol 2.0), without a socket:
states and their transitions, the error codes of refused requests, and replies that echo the
request id and carry version 2.5 (a 1.x request is VERSION_MISMATCH naming both versions).
SetupBody: MeshData checked (sizes, indices, names, inverted or folded cells named by tag and
source), mesh_path confined to the data directory, InterfaceDescription with its fixed components
and its segments oriented with the body on their left. AssignContact: every inconsistency of the
compressed-row operator is INVALID_ARGUMENT naming the field. The Neumann solve (since 1.1), the
run rule of 1.2, FieldsRequest.write_directory confined to the output root, SOLVER_FAILURE instead
of a non-finite reply. After every error the server answers a following Hello.
"""

import gc
import os
import pathlib
import shutil
import tempfile
import unittest
import weakref
from unittest import mock

import numpy as np

import support
from robin_subdomain import setup_decoding
from robin_subdomain.proto_module import load_protocol
from robin_subdomain.protocol import SubdomainProtocol

protocol = load_protocol()
LOWER_GEO_PATH = support.REPOSITORY / "examples" / "meshes" / "block_lower.geo"
# block_lower.geo with h = 0.5: [-1, 1] x [-1, 0], contact edge y = 0 meshed from x = -1 to 1.
LOWER_MESH = support.mesh_data(protocol, support.mesh_from_geo(LOWER_GEO_PATH.read_text(), 0.5),
                               "block_lower.geo")


def request(request_id=7, major=2, minor=0, run_id="", **content):
    envelope = protocol.Envelope()
    envelope.request_id = request_id
    envelope.run_id = run_id
    if major is not None:
        envelope.version.major = major
        envelope.version.minor = minor
    for name, message in content.items():
        getattr(envelope, name).CopyFrom(message)
    return envelope.SerializeToString()


def setup_body(mesh=LOWER_MESH, **changes):
    """The lower block: bottom clamped, contact boundary 'contact'."""
    message = protocol.SetupBody(body_name="lower", model=protocol.PLANE_STRAIN,
                                 young_modulus=1000.0, poisson_ratio=0.3,
                                 contact_boundaries=["contact"])
    if mesh is not None:
        message.mesh.CopyFrom(mesh)
    condition = message.dirichlet.add()
    condition.boundary, condition.x, condition.y = "bottom", 0.0, 0.0
    for name, value in changes.items():
        if isinstance(value, list):
            message.ClearField(name)
            getattr(message, name).extend(value)
        else:
            setattr(message, name, value)
    return message


def changed_mesh(change):
    """A copy of LOWER_MESH after change(copy)."""
    mesh = protocol.MeshData()
    mesh.CopyFrom(LOWER_MESH)
    change(mesh)
    return mesh


class ServerTestCase(unittest.TestCase):
    SERVER_MINOR = 5   # the minor version the server speaks (protocol 2.5), on every reply

    def make_server(self, **options):
        server = SubdomainProtocol(protocol, **options)
        server.logger.disabled = True
        self.expected_version = (2, options.get("protocol_minor", self.SERVER_MINOR))
        return server

    def setUp(self):
        self.server = self.make_server()

    def ask(self, data):
        reply = protocol.Envelope()
        reply.ParseFromString(self.server.handle(data))
        self.assertEqual((reply.version.major, reply.version.minor), self.expected_version)
        return reply

    def expect_error(self, data, code, state):
        """The message of the expected Error; the server then answers a Hello."""
        reply = self.ask(data)
        self.assertEqual(reply.WhichOneof("content"), "error", reply)
        self.assertEqual(protocol.ErrorCode.Name(reply.error.code), code, reply.error.message)
        self.assertEqual(reply.error.state, state)
        hello = self.ask(request(request_id=1000, hello=protocol.Hello()))
        self.assertEqual(hello.hello_reply.state, state)
        return reply.error.message

    def set_up_and_assign(self, body=None):
        interface = self.ask(request(setup_body=body or setup_body())).interface
        assign = support.node_to_node_assignment(protocol, interface)
        self.assertEqual(self.ask(request(assign_contact=assign)).acknowledge.state, "ready")
        return interface


class StateMachine(ServerTestCase):
    def test_garbage_is_malformed_and_the_server_goes_on(self):
        self.expect_error(b"\xff\xfe not protobuf", "MALFORMED_MESSAGE", "awaiting_setup")
        reply = self.ask(request(request_id=11, hello=protocol.Hello()))
        self.assertEqual(reply.request_id, 11)
        self.assertEqual(reply.hello_reply.state, "awaiting_setup")
        self.assertEqual(list(reply.hello_reply.capabilities),
                         ["contact_solve", "correction_solve", "fields", "neumann_solve"])

    def test_envelope_checks(self):
        self.expect_error(request(), "MALFORMED_MESSAGE", "awaiting_setup")
        self.expect_error(request(major=None, hello=protocol.Hello()), "MALFORMED_MESSAGE",
                          "awaiting_setup")
        for major, minor in ((1, 2), (1, 0), (3, 1)):
            message = self.expect_error(request(major=major, minor=minor, hello=protocol.Hello()),
                                        "VERSION_MISMATCH", "awaiting_setup")
            self.assertIn("the request speaks %d.%d, this server 2.5" % (major, minor), message)
        self.expect_error(request(major=1, minor=2, setup_body=setup_body()), "VERSION_MISMATCH",
                          "awaiting_setup")
        self.expect_error(request(acknowledge=protocol.Acknowledge()), "UNSUPPORTED",
                          "awaiting_setup")
        # field 31 of the Envelope: a request type this version does not know
        self.expect_error(request() + b"\xfa\x01\x00", "UNSUPPORTED", "awaiting_setup")

    def test_states_and_transitions(self):
        solve = protocol.ContactSolveRequest(obstacle=[0.0])
        self.expect_error(request(contact_solve=solve), "WRONG_STATE", "awaiting_setup")
        body = setup_body()
        body.dirichlet.add(boundary="left", x=0.0)
        interface = self.ask(request(setup_body=body)).interface
        self.assertEqual(interface.body_name, "lower")
        self.assertEqual(interface.dimension, 2)
        count = len(interface.node_ids)
        self.assertEqual(count, 5)  # the transfinite contact edge, h = 0.5
        self.assertEqual(list(interface.node_ids), sorted(interface.node_ids))
        coordinates = np.array(interface.coordinates).reshape(-1, 2)
        np.testing.assert_allclose(np.sort(coordinates[:, 0]), [-1, -0.5, 0, 0.5, 1], atol=1e-11)
        np.testing.assert_array_equal(coordinates[:, 1], 0.0)
        np.testing.assert_allclose(np.array(interface.normals).reshape(-1, 2),
                                   np.tile([0.0, 1.0], (count, 1)), atol=1e-15)
        self.assertAlmostEqual(sum(interface.weights), 2.0, delta=1e-14)
        # only the corner (-1, 0) lies on 'left', whose u_x is prescribed
        fixed = np.array(interface.fixed).reshape(-1, 2)
        np.testing.assert_array_equal(fixed[:, 0], coordinates[:, 0] == -1.0)
        np.testing.assert_array_equal(fixed[:, 1], False)
        self.expect_error(request(contact_solve=solve), "WRONG_STATE", "awaiting_assignment")
        good = support.node_to_node_assignment(protocol, interface)
        self.assertEqual(self.ask(request(assign_contact=good)).acknowledge.state, "ready")
        self.expect_error(request(contact_solve=solve), "INVALID_ARGUMENT", "ready")
        solve = protocol.ContactSolveRequest(obstacle=[1.0] * count)
        result = self.ask(request(contact_solve=solve)).contact_result
        self.assertEqual(result.status, protocol.CONVERGED)
        self.assertEqual(list(result.contact_force), [0.0] * count)  # unloaded body, far obstacle
        self.assertEqual(self.ask(request(end_run=protocol.EndRun())).acknowledge.state,
                         "awaiting_setup")
        self.assertEqual(self.ask(request(shutdown=protocol.Shutdown())).acknowledge.state,
                         "awaiting_setup")
        self.assertTrue(self.server.shutdown_requested)

    def test_surface_segments_have_the_body_on_their_left(self):
        interface = self.ask(request(setup_body=setup_body())).interface
        self.assertEqual(len(interface.surfaces), 1)
        surface = interface.surfaces[0]
        self.assertEqual(surface.boundary, "contact")
        self.assertEqual(surface.segment_type, protocol.LINE2)
        coordinates = np.array(interface.coordinates).reshape(-1, 2)
        segments = np.array(surface.segments).reshape(-1, 2)
        self.assertEqual(len(segments), 4)
        # the body lies below y = 0: with it on the left, every segment runs towards -x (the mesh
        # has them towards +x), and the clockwise-turned direction (t_y, -t_x) is +y
        directions = coordinates[segments[:, 1]] - coordinates[segments[:, 0]]
        np.testing.assert_allclose(directions, np.tile([-0.5, 0.0], (4, 1)), atol=1e-11)
        self.assertEqual(sorted(set(segments.ravel())), list(range(5)))

    def test_two_contact_boundaries(self):
        reply = self.ask(request(setup_body=setup_body(contact_boundaries=["contact", "right"])))
        interface = reply.interface
        coordinates = np.array(interface.coordinates).reshape(-1, 2)
        on_contact = coordinates[:, 1] == 0.0
        on_right = coordinates[:, 0] == 1.0
        self.assertTrue(np.all(on_contact | on_right))
        self.assertEqual((on_contact.sum(), on_right.sum(), len(coordinates)), (5, 3, 7))
        self.assertEqual([surface.boundary for surface in interface.surfaces],
                         ["contact", "right"])
        self.assertAlmostEqual(sum(interface.weights), 3.0, delta=1e-14)  # lengths 2 + 1
        normals = np.array(interface.normals).reshape(-1, 2)
        corner = np.flatnonzero(on_contact & on_right)[0]
        np.testing.assert_allclose(normals[corner], [np.sqrt(0.5), np.sqrt(0.5)], atol=1e-12)
        right = np.array(interface.surfaces[1].segments).reshape(-1, 2)
        directions = coordinates[right[:, 1]] - coordinates[right[:, 0]]
        np.testing.assert_allclose(directions, np.tile([0.0, 0.5], (2, 1)), atol=1e-11)

    def test_neumann_solve(self):
        neumann = protocol.NeumannSolveRequest(iteration=3, contact_force=[0.0])
        self.expect_error(request(neumann_solve=neumann), "WRONG_STATE", "awaiting_setup")
        loaded = setup_body()
        loaded.body_force.extend([0.0, -5.0])
        interface = self.ask(request(setup_body=loaded)).interface
        count = len(interface.node_ids)
        self.expect_error(request(neumann_solve=neumann), "WRONG_STATE", "awaiting_assignment")
        self.ask(request(assign_contact=support.node_to_node_assignment(protocol, interface)))
        message = self.expect_error(request(neumann_solve=neumann), "INVALID_ARGUMENT", "ready")
        self.assertIn("NeumannSolveRequest.contact_force has 1 values for the %d constraints" %
                      count, message)
        for bad in (float("nan"), float("inf")):
            neumann = protocol.NeumannSolveRequest(contact_force=[1.0] * (count - 1) + [bad])
            message = self.expect_error(request(neumann_solve=neumann), "INVALID_ARGUMENT",
                                        "ready")
            self.assertIn("contact_force[%d] of body 'lower' is not a finite number" % (count - 1),
                          message)
        # e: the normal trace with every obstacle far; F lambda: the correction for r = lambda
        far = protocol.ContactSolveRequest(obstacle=[1e3] * count)
        free = self.ask(request(contact_solve=far)).contact_result
        self.assertEqual(list(free.contact_force), [0.0] * count)
        force = 1.0 + np.cos(np.arange(count))
        correction = protocol.CorrectionRequest(interface_force=force)
        response = np.array(self.ask(request(correction=correction)).correction_result.normal_trace)
        neumann = protocol.NeumannSolveRequest(iteration=4, contact_force=force)
        reply = self.ask(request(request_id=99, neumann_solve=neumann))
        self.assertEqual(reply.request_id, 99)
        trace = np.array(reply.neumann_result.normal_trace)
        expected = np.array(free.normal_trace) - response
        self.assertGreater(np.abs(response).max(), 1e-3 * np.abs(expected).max())
        scale = max(np.abs(free.normal_trace).max(), np.abs(response).max())
        np.testing.assert_allclose(trace, expected, rtol=0, atol=1e-10 * scale)
        self.assertEqual(self.server.state, "ready")

    def test_replies_carry_the_stage_times(self):
        """Since 2.2: SetupBody's reply names mesh, assembly and factorization (SuperLU has no
        separate ordering) and the whole request, which is at least their sum; AssignContact's
        the interface operator, FieldsRequest's the fields; each once, finite, non-negative."""
        def stages(stage_times):
            names = [entry.stage for entry in stage_times]
            self.assertEqual(len(names), len(set(names)), names)
            for entry in stage_times:
                self.assertTrue(np.isfinite(entry.seconds) and entry.seconds >= 0.0, entry)
            return {entry.stage: entry.seconds for entry in stage_times}

        interface = self.ask(request(setup_body=setup_body())).interface
        setup = stages(interface.stage_times)
        self.assertEqual(set(setup), {"mesh", "assembly", "factorization"})
        self.assertGreater(setup["assembly"], 0.0)
        self.assertGreater(setup["factorization"], 0.0)
        self.assertGreaterEqual(interface.request_seconds, sum(setup.values()))
        self.assertGreaterEqual(interface.request_seconds, interface.setup_seconds)
        assign = support.node_to_node_assignment(protocol, interface)
        acknowledge = self.ask(request(assign_contact=assign)).acknowledge
        self.assertEqual(set(stages(acknowledge.stage_times)), {"interface operator"})
        count = len(interface.node_ids)
        fields = self.ask(request(fields=protocol.FieldsRequest(
            contact_force=[0.0] * count))).fields_reply
        self.assertEqual(set(stages(fields.stage_times)), {"fields"})
        hello = self.ask(request(hello=protocol.Hello()))
        self.assertEqual(len(self.ask(request(end_run=protocol.EndRun())).acknowledge.stage_times),
                         0, hello)

    def test_set_load_factor_scales_loads_and_prescribed_displacements(self):
        """Since 2.1: e(t) = t e(1) for body force and a prescribed lift together (both scale),
        F is unchanged, bad factors are BAD_INPUT with the factor in force kept."""
        scale = protocol.SetLoadFactor(factor=2.0)
        self.expect_error(request(set_load_factor=scale), "WRONG_STATE", "awaiting_setup")
        loaded = setup_body()
        loaded.body_force.extend([0.0, -5.0])
        loaded.dirichlet[0].y = 0.01             # the bottom lifted: a prescribed displacement
        interface = self.ask(request(setup_body=loaded)).interface
        count = len(interface.node_ids)
        reply = self.ask(request(set_load_factor=protocol.SetLoadFactor(factor=1.0)))
        self.assertEqual((reply.load_factor_set.factor, reply.load_factor_set.state),
                         (1.0, "awaiting_assignment"))
        self.ask(request(assign_contact=support.node_to_node_assignment(protocol, interface)))
        far = protocol.ContactSolveRequest(obstacle=[1.0] * count)   # above every trace
        unit = np.array(self.ask(request(contact_solve=far)).contact_result.normal_trace)
        force = 1.0 + np.cos(np.arange(count))
        correction = protocol.CorrectionRequest(interface_force=force)
        response = np.array(self.ask(request(correction=correction)).correction_result.normal_trace)
        unit_fields = self.ask(request(fields=protocol.FieldsRequest(
            contact_force=[0.0] * count))).fields_reply
        reply = self.ask(request(set_load_factor=protocol.SetLoadFactor(factor=2.5)))
        self.assertEqual((reply.load_factor_set.factor, reply.load_factor_set.state), (2.5, "ready"))
        for bad in (float("nan"), float("inf"), -float("inf"), 1.0e7, -2.0e6):
            message = self.expect_error(request(set_load_factor=protocol.SetLoadFactor(factor=bad)),
                                        "BAD_INPUT", "ready")
            self.assertIn("SetLoadFactor.factor", message)
            self.assertIn("body 'lower'", message)
        scaled = np.array(self.ask(request(contact_solve=far)).contact_result.normal_trace)
        np.testing.assert_allclose(scaled, 2.5 * unit, rtol=0, atol=1e-14)
        self.assertGreater(np.abs(unit).max(), 1e-3)
        again = np.array(self.ask(request(correction=correction)).correction_result.normal_trace)
        np.testing.assert_allclose(again, response, rtol=0, atol=1e-14 * np.abs(response).max())
        fields = self.ask(request(fields=protocol.FieldsRequest(
            contact_force=[0.0] * count))).fields_reply
        np.testing.assert_allclose(fields.applied_force, 2.5 * np.array(unit_fields.applied_force),
                                   rtol=1e-14)
        np.testing.assert_allclose(fields.reaction_resultant,      # the supports carry the load
                                   -np.array(fields.applied_force), rtol=0,
                                   atol=1e-10 * np.abs(fields.applied_force).max())
        displacement = dict((f.name, np.array(f.values)) for f in fields.point_fields)
        unit_displacement = dict((f.name, np.array(f.values)) for f in unit_fields.point_fields)
        np.testing.assert_allclose(displacement["displacement"],
                                   2.5 * unit_displacement["displacement"], rtol=0,
                                   atol=1e-12 * np.abs(unit_displacement["displacement"]).max())
        # the lift itself: u_y = 2.5 * 0.01 on the bottom edge y = -1
        bottom = np.abs(np.array(fields.node_coordinates).reshape(-1, 2)[:, 1] + 1.0) < 1e-12
        self.assertGreater(bottom.sum(), 1)
        np.testing.assert_allclose(displacement["displacement"].reshape(-1, 2)[bottom, 1], 0.025,
                                   rtol=1e-15)
        # a new SetupBody is at factor 1 again
        interface = self.ask(request(setup_body=loaded)).interface
        self.ask(request(assign_contact=support.node_to_node_assignment(protocol, interface)))
        fresh = np.array(self.ask(request(contact_solve=far)).contact_result.normal_trace)
        np.testing.assert_allclose(fresh, unit, rtol=0, atol=1e-14)

    def test_requests_of_another_run_are_wrong_state_and_change_nothing(self):
        run, other = "0123456789abcdef0123456789abcdef", "another-coordinator"
        reply = self.ask(request(run_id=run, setup_body=setup_body()))
        self.assertEqual(reply.run_id, run)                       # echoed
        interface = reply.interface
        count = len(interface.node_ids)
        assign = support.node_to_node_assignment(protocol, interface)

        def refused(state, **content):
            message = self.expect_error(request(run_id=other, **content), "WRONG_STATE", state)
            self.assertIn("this server's body 'lower' now belongs to another run (run_id '%s')" %
                          run, message)
            return message

        refused("awaiting_assignment", assign_contact=assign)
        refused("awaiting_assignment", end_run=protocol.EndRun())
        self.assertEqual(self.ask(request(run_id=run, assign_contact=assign)).acknowledge.state,
                         "ready")
        solve = protocol.ContactSolveRequest(obstacle=[1.0] * count)
        message = refused("ready", contact_solve=solve)
        self.assertEqual(message, "ContactSolveRequest of run '%s': this server's body 'lower' "
                         "now belongs to another run (run_id '%s'): another coordinator set it "
                         "up; this run's state is lost" % (other, run))
        refused("ready", correction=protocol.CorrectionRequest(interface_force=[1.0] * count))
        refused("ready", neumann_solve=protocol.NeumannSolveRequest(contact_force=[1.0] * count))
        refused("ready", fields=protocol.FieldsRequest(contact_force=[0.0] * count))
        refused("ready", end_run=protocol.EndRun())
        refused("ready", assign_contact=assign)
        self.assertEqual(self.server.state, "ready")
        # the run's own requests, and those without run_id, are served
        for run_id in (run, ""):
            reply = self.ask(request(run_id=run_id, contact_solve=solve))
            self.assertEqual(reply.run_id, run_id)
            self.assertEqual(reply.contact_result.status, protocol.CONVERGED)
            self.assertEqual(list(reply.contact_result.contact_force), [0.0] * count)
        # another run may always take the server over; the first run is then refused
        self.ask(request(run_id=other, setup_body=setup_body()))
        message = self.expect_error(request(run_id=run, contact_solve=solve), "WRONG_STATE",
                                    "awaiting_assignment")
        self.assertIn("now belongs to another run (run_id '%s')" % other, message)
        self.expect_error(request(run_id=run, end_run=protocol.EndRun()), "WRONG_STATE",
                          "awaiting_assignment")
        self.assertEqual(self.ask(request(run_id=other, end_run=protocol.EndRun()))
                         .acknowledge.state, "awaiting_setup")
        # without a body no run owns the server
        message = self.expect_error(request(run_id=run, contact_solve=solve), "WRONG_STATE",
                                    "awaiting_setup")
        self.assertEqual(message, "ContactSolveRequest before SetupBody: send SetupBody first")

    def test_body_set_up_without_run_id_serves_every_run(self):
        interface = self.ask(request(setup_body=setup_body())).interface
        assign = support.node_to_node_assignment(protocol, interface)
        self.assertEqual(self.ask(request(run_id="b", assign_contact=assign)).acknowledge.state,
                         "ready")
        solve = protocol.ContactSolveRequest(obstacle=[1.0] * len(interface.node_ids))
        self.assertEqual(self.ask(request(run_id="c", contact_solve=solve)).contact_result.status,
                         protocol.CONVERGED)

    def test_failed_setup_discards_the_previous_body(self):
        self.ask(request(setup_body=setup_body()))
        self.assertEqual(self.server.state, "awaiting_assignment")
        self.expect_error(request(setup_body=setup_body(young_modulus=-1.0)), "BAD_INPUT",
                          "awaiting_setup")

    def test_a_body_above_max_dofs_is_bad_input_before_assembly(self):
        dof_count = len(LOWER_MESH.coordinates)   # 2 coordinates, 2 DOFs per node
        self.server = self.make_server(maximum_dofs=dof_count - 1)
        message = self.expect_error(request(setup_body=setup_body()), "BAD_INPUT",
                                    "awaiting_setup")
        self.assertIn("body 'lower': %d degrees of freedom, above this server's limit of %d "
                      "(robin-subdomain-py --max-dofs raises it)" % (dof_count, dof_count - 1),
                      message)
        self.server = self.make_server(maximum_dofs=dof_count)
        self.assertEqual(self.ask(request(setup_body=setup_body())).WhichOneof("content"),
                         "interface")

    def test_a_discarded_body_is_freed_without_the_garbage_collector(self):
        # A body in a reference cycle (and its factor) waits for a full collection: a server
        # serving many runs then grows (benchmarks/soak_benchmark.py).
        gc.collect()
        gc.disable()
        try:
            for finish in (request(end_run=protocol.EndRun()), request(setup_body=setup_body())):
                interface = self.set_up_and_assign()
                count = len(interface.node_ids)
                self.ask(request(contact_solve=protocol.ContactSolveRequest(
                    obstacle=[0.0] * count)))
                self.ask(request(correction=protocol.CorrectionRequest(
                    interface_force=[1.0] * count)))
                self.ask(request(neumann_solve=protocol.NeumannSolveRequest(
                    contact_force=[1.0] * count)))
                self.ask(request(fields=protocol.FieldsRequest(contact_force=[1.0] * count)))
                body = weakref.ref(self.server.body)
                self.ask(finish)
                self.assertIsNone(body(), "the body outlived its run")
        finally:
            gc.enable()


class BadBodies(ServerTestCase):
    def refused(self, body, *fragments, code="BAD_INPUT"):
        message = self.expect_error(request(setup_body=body), code, "awaiting_setup")
        for fragment in fragments:
            self.assertIn(fragment, message)
        return message

    def test_definition(self):
        self.refused(setup_body(poisson_ratio=0.5), "Poisson ratio")
        self.refused(setup_body(contact_boundaries=["lid"]), "SetupBody.contact_boundaries[0]",
                     "'lid' is not a boundary of the mesh (its boundaries: bottom, contact, "
                     "left, right)")
        self.refused(setup_body(contact_boundaries=[]), "SetupBody.contact_boundaries is empty")
        self.refused(setup_body(contact_boundaries=["contact", "contact"]),
                     "contact_boundaries[1] repeats 'contact'")
        self.refused(setup_body(contact_boundaries=["contact"] * 65),
                     "SetupBody.contact_boundaries has 65 names, more than the 64")
        self.refused(setup_body(body_name="b" * 65), "SetupBody.body_name", "1 to 64 characters")
        self.refused(setup_body(body_name="../lower"), "SetupBody.body_name")
        singular = setup_body()
        singular.ClearField("dirichlet")
        self.refused(singular, code="SINGULAR_BODY")
        floating = setup_body()
        floating.ClearField("dirichlet")
        floating.floating = True  # protocol 2.3: this reference server has no floating bodies
        self.refused(floating, "body 'lower' is floating (held by contact alone)",
                     code="UNSUPPORTED")
        self.refused(setup_body(mesh=None), "SetupBody.mesh and SetupBody.mesh_path are both "
                     "empty")
        three = setup_body()
        three.dirichlet.add(boundary="left", z=0.0)
        self.refused(three, "dirichlet[1].z")

    def test_solver_hints(self):
        """SolverSettings.interface_operator and linear_solver are hints (this server always
        assembles F densely and solves directly), but only their documented strings."""
        for value in ("", "direct", "multigrid"):
            body = setup_body()
            body.solver.linear_solver = value
            reply = self.ask(request(setup_body=body))
            self.assertEqual(reply.WhichOneof("content"), "interface", (value, reply))
        body = setup_body()
        body.solver.linear_solver = "amg"
        self.refused(body, "body 'lower': SetupBody.solver.linear_solver is 'amg', expected "
                     "\"direct\" or \"multigrid\"")
        body = setup_body()
        body.solver.interface_operator = "sparse"
        self.refused(body, "body 'lower': SetupBody.solver.interface_operator is 'sparse', "
                     "expected \"auto\", \"dense\" or \"factor\"")

    def test_mesh_data_sizes_and_indices(self):
        node_count = len(LOWER_MESH.coordinates) // 2

        def refused(change, *fragments):
            message = self.refused(setup_body(mesh=changed_mesh(change)), *fragments)
            self.assertTrue(message.startswith("body 'lower': SetupBody.mesh."), message)
            self.assertIn("(mesh 'block_lower.geo')", message)

        refused(lambda mesh: setattr(mesh, "dimension", 4),
                "mesh.dimension is 4, expected 2 (plane problems) or 3 (solid bodies)")
        refused(lambda mesh: mesh.coordinates.append(0.5),
                "mesh.coordinates has %d values, expected 2 per node" % (2 * node_count + 1))
        refused(lambda mesh: mesh.coordinates.__setitem__(5, float("inf")),
                "coordinates of node 3 (1-based position) are not finite")
        refused(lambda mesh: mesh.node_tags.append(99),
                "node_tags has %d values for %d nodes" % (node_count + 1, node_count))
        refused(lambda mesh: mesh.cells[0].connectivity.__setitem__(4, node_count),
                "mesh.cells[0].connectivity[4] is %d, not an index of the %d nodes" %
                (node_count, node_count))
        refused(lambda mesh: mesh.cells[0].connectivity.__setitem__(4, 2 ** 32 - 1),
                "mesh.cells[0].connectivity[4] is 4294967295")
        refused(lambda mesh: mesh.cells[0].connectivity.append(0),
                "mesh.cells[0].connectivity has 67 entries, not a multiple of the 3 nodes")
        refused(lambda mesh: mesh.cells[0].tags.append(1), "cells[0].tags has 23 values for 22")
        refused(lambda mesh: setattr(mesh.cells[0], "type", protocol.LINE2),
                "mesh.cells[0].type is LINE2, expected TRIANGLE3 or TRIANGLE6 or QUADRILATERAL4")
        refused(lambda mesh: mesh.boundaries[1].segments.connectivity.__setitem__(0, 10 ** 6),
                "mesh.boundaries[1].segments.connectivity[0] is 1000000")
        refused(lambda mesh: setattr(mesh.boundaries[0].segments, "type", protocol.TRIANGLE3),
                "boundaries[0].segments.type is TRIANGLE3, expected LINE2 or LINE3")
        refused(lambda mesh: setattr(mesh.boundaries[2], "name", "le ft"),
                "boundaries[2].name 'le ft' is not a boundary name")
        refused(lambda mesh: setattr(mesh.boundaries[2], "name", "x" * 65),
                "is not a boundary name ([A-Za-z0-9_.-], 1 to 64 characters)")
        refused(lambda mesh: setattr(mesh.boundaries[2], "name", "contact"),
                "boundaries[2].name 'contact' names two boundaries")
        refused(lambda mesh: mesh.ClearField("cells"), "mesh.cells holds no domain cell")
        # a node no cell uses (the last triangle dropped leaves its nodes... add a stray node)
        refused(lambda mesh: mesh.coordinates.extend([5.0, 5.0]) or mesh.node_tags.append(999),
                "define node %d (1-based position), which is not a node of any domain cell" %
                (node_count + 1))

    def inverted(self, change, *fragments):
        message = self.refused(setup_body(mesh=changed_mesh(change)), *fragments)
        self.assertIn("is inverted, folded or degenerate", message)
        self.assertIn("(mesh 'block_lower.geo')", message)
        return message

    def test_inverted_triangle_is_refused_naming_its_tag(self):
        def invert_cell_eight(mesh):
            mesh.cells[0].tags[:] = range(101, 123)
            first, second = mesh.cells[0].connectivity[22:24]
            mesh.cells[0].connectivity[22:24] = [second, first]

        self.inverted(invert_cell_eight, "body 'lower': SetupBody.mesh.cells[0]: cell tag 108 ")

        def invert_without_tags(mesh):
            mesh.cells[0].ClearField("tags")
            first, second = mesh.cells[0].connectivity[0:2]
            mesh.cells[0].connectivity[0:2] = [second, first]

        self.inverted(invert_without_tags, "cell at position 1 (triangle3)")

        def collapse(mesh):
            """Cell k gets two equal corners; its replaced node is kept by another cell."""
            cells = np.array(mesh.cells[0].connectivity).reshape(-1, 3)
            uses = np.bincount(cells.ravel())
            self.collapsed = next(k for k in range(len(cells)) if uses[cells[k, 1]] > 1)
            mesh.cells[0].connectivity[3 * self.collapsed + 1] = int(cells[self.collapsed, 0])

        self.inverted(collapse, "Jacobian is 0 ")
        self.inverted(collapse, "cell tag %d (triangle3)" % (self.collapsed + 1))

    def test_folded_quadratic_triangle_is_refused(self):
        # one 6-node triangle, corners counter-clockwise, the midpoint of edge 0-1 pulled across
        # the opposite corner: the corners alone look fine, the element is folded
        mesh = protocol.MeshData(dimension=2, source="folded.msh")
        mesh.coordinates.extend([0, 0, 1, 0, 0, 1, 0.5, 1.2, 0.5, 0.5, 0, 0.5])
        mesh.cells.add(type=protocol.TRIANGLE6, connectivity=range(6), tags=[41])
        mesh.boundaries.add(name="edge").segments.CopyFrom(
            protocol.CellBlock(type=protocol.LINE3, connectivity=[0, 1, 3]))
        corners = np.array(mesh.coordinates).reshape(-1, 2)[:3]
        twice_area = np.cross(corners[1] - corners[0], corners[2] - corners[0])
        self.assertGreater(twice_area, 0.0)                       # counter-clockwise corners
        body = setup_body(mesh=mesh, contact_boundaries=["edge"])
        body.dirichlet[0].boundary = "edge"
        self.refused(body, "SetupBody.mesh.cells[0]: cell tag 41 (triangle6) is inverted, "
                     "folded or degenerate", "(mesh 'folded.msh')")

    def test_mesh_data_is_not_reordered(self):
        """A clockwise mesh is refused as sent, not turned around."""
        def clockwise(mesh):
            cells = np.array(mesh.cells[0].connectivity).reshape(-1, 3)
            mesh.cells[0].connectivity[:] = cells[:, [0, 2, 1]].ravel().tolist()

        self.inverted(clockwise, "cell tag 1 (triangle3)")


class Version1GeoScripts(ServerTestCase):
    """A 1.x SetupBody with a .geo script in the removed mesh_content (field 2, mesh_extension
    ".geo" in field 3, hand-encoded as a 1.x coordinator sent them) holding each attack of
    support.hostile_geo_scripts: SystemCall, an ExternalProcess mesh size field, the five
    keyword-filter bypasses, ListFromFile("/etc/passwd") and CurrentDirectory. The server runs
    no script and reads no mesh: without MeshData the body is BAD_INPUT, with MeshData the script
    is ignored; the witness never appears, no reply shows a line of /etc/passwd or the working
    directory, and the server answers Hello after each."""

    def setUp(self):
        super().setUp()
        self.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-py-geo-"))
        self.addCleanup(shutil.rmtree, self.scratch)

    def expect_nothing_read(self, reply_bytes):
        for line in support.passwd_lines():
            self.assertNotIn(line.encode(), reply_bytes)
        self.assertNotIn(os.getcwd().encode(), reply_bytes)

    def test_scripts_are_never_run(self):
        witness = self.scratch / "witness"
        script_start = LOWER_GEO_PATH.read_text()
        with mock.patch.object(setup_decoding.mesh_reader, "read_mesh") as reader:
            for label, text in support.hostile_geo_scripts(witness):
                with self.subTest(label):
                    script = script_start + text
                    data = support.with_1x_script(request(setup_body=setup_body(mesh=None)),
                                                  script)
                    self.assertIn(text.encode(), data)
                    reply_bytes = self.server.handle(data)
                    self.expect_nothing_read(reply_bytes)
                    reply = protocol.Envelope.FromString(reply_bytes)
                    self.assertEqual(protocol.ErrorCode.Name(reply.error.code), "BAD_INPUT")
                    self.assertIn("body 'lower': SetupBody.mesh and SetupBody.mesh_path are "
                                  "both empty", reply.error.message)
                    self.assertEqual(self.ask(request(hello=protocol.Hello())).hello_reply.state,
                                     "awaiting_setup")

                    data = support.with_1x_script(request(setup_body=setup_body()), script)
                    reply_bytes = self.server.handle(data)
                    self.expect_nothing_read(reply_bytes)
                    reply = protocol.Envelope.FromString(reply_bytes)
                    self.assertEqual(reply.WhichOneof("content"), "interface", reply)
                    self.assertEqual(self.ask(request(hello=protocol.Hello())).hello_reply.state,
                                     "awaiting_assignment")
                    self.assertFalse(witness.exists(), "the script ran")
                    self.ask(request(end_run=protocol.EndRun()))
            reader.assert_not_called()


class MeshPath(ServerTestCase):
    """SetupBody.mesh_path: only files under the data directory, and nothing else is read."""

    def setUp(self):
        self.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-py-data-"))
        self.data = self.scratch / "data"
        (self.data / "sub").mkdir(parents=True)
        shutil.copy(support.TEST_DATA / "case_lower.msh", self.data / "sub" / "lower.msh")
        shutil.copy(LOWER_GEO_PATH, self.data / "block_lower.geo")
        shutil.copy(support.TEST_DATA / "case_lower.msh", self.scratch / "outside.msh")
        (self.data / "passwd.msh").symlink_to("/etc/passwd")
        (self.data / "outside-link.msh").symlink_to(self.scratch / "outside.msh")
        (self.data / "etc").symlink_to("/etc")
        (self.data / "inside-link.msh").symlink_to("sub/lower.msh")
        self.server = self.make_server(data_directory=str(self.data))

    def tearDown(self):
        shutil.rmtree(self.scratch)

    def body(self, path):
        return setup_body(mesh=None, mesh_path=path)

    def test_paths_under_the_data_directory_are_read(self):
        for path in ("sub/lower.msh", "./sub/../sub/lower.msh", "inside-link.msh"):
            interface = self.ask(request(setup_body=self.body(path))).interface
            coordinates = np.array(interface.coordinates).reshape(-1, 2)
            # case_lower.msh: [0, 1] x [-1, 0], its contact edge y = 0 in two segments
            np.testing.assert_allclose(coordinates[:, 0], [1.0, 0.0, 0.5], atol=1e-11)
            np.testing.assert_allclose(interface.weights, [0.25, 0.25, 0.5], rtol=1e-11)

    def test_geo_file_of_the_data_directory_is_meshed(self):
        interface = self.ask(request(setup_body=self.body("block_lower.geo"))).interface
        self.assertAlmostEqual(sum(interface.weights), 2.0, delta=1e-13)  # the edge y = 0

    def test_paths_that_leave_the_data_directory_are_refused_unread(self):
        outside = str(self.scratch / "outside.msh")
        inside_absolute = str(self.data / "sub" / "lower.msh")
        with mock.patch.object(setup_decoding.mesh_reader, "read_mesh",
                               wraps=setup_decoding.mesh_reader.read_mesh) as reader:
            for path, reason in (("../outside.msh", "leaves the server's data directory"),
                                 ("sub/../../outside.msh", "leaves the server's data directory"),
                                 (outside, "is an absolute path"),
                                 (inside_absolute, "is an absolute path"),
                                 ("passwd.msh", "leaves the server's data directory"),
                                 ("outside-link.msh", "leaves the server's data directory"),
                                 ("etc/passwd", "leaves the server's data directory")):
                message = self.expect_error(request(setup_body=self.body(path)), "BAD_INPUT",
                                            "awaiting_setup")
                self.assertIn("body 'lower': SetupBody.mesh_path %r %s" % (path, reason),
                              message)
            reader.assert_not_called()
            self.ask(request(setup_body=self.body("sub/lower.msh")))
            reader.assert_called_once()

    def test_without_data_directory_every_mesh_path_is_refused(self):
        self.server = self.make_server()
        with mock.patch.object(setup_decoding.mesh_reader, "read_mesh") as reader:
            for path in ("sub/lower.msh", str(self.data / "sub" / "lower.msh")):
                message = self.expect_error(request(setup_body=self.body(path)), "BAD_INPUT",
                                            "awaiting_setup")
                self.assertIn("SetupBody.mesh_path %r is refused: the server was started "
                              "without --data-directory" % path, message)
            reader.assert_not_called()

    def test_unusable_temporary_directory_is_internal_and_names_the_body(self):
        saved = tempfile.tempdir
        tempfile.tempdir = "/nonexistent/robin-test-temporary-directory"
        try:
            message = self.expect_error(request(setup_body=self.body("block_lower.geo")),
                                        "INTERNAL", "awaiting_setup")
        finally:
            tempfile.tempdir = saved
        self.assertTrue(message.startswith("body 'lower': SetupBody.mesh_path: "), message)
        self.assertIn("'/nonexistent/robin-test-temporary-directory'", message)
        self.assertIn("temporary directory (TMPDIR, else /tmp) is not writable or is full",
                      message)
        self.assertNotIn("internal error", message)
        self.ask(request(setup_body=self.body("block_lower.geo")))  # the server goes on
        self.assertEqual(self.server.state, "awaiting_assignment")


class AssignContactChecks(ServerTestCase):
    def setUp(self):
        super().setUp()
        self.interface = self.ask(request(setup_body=setup_body())).interface
        self.nodes = list(self.interface.node_ids)

    def refused(self, message, field, fragment, state="awaiting_assignment"):
        text = self.expect_error(request(assign_contact=message), "INVALID_ARGUMENT", state)
        self.assertIn("AssignContact for body 'lower': AssignContact." + field, text)
        self.assertIn(fragment, text)

    def test_every_inconsistency_is_invalid_argument_naming_the_field(self):
        a, b = self.nodes[:2]
        not_contact = min(set(range(100)) - set(self.nodes))

        def rows(*entries, offsets=None, weights=None):
            message = support.sparse_rows(protocol, [(1.0, list(row)) for row in entries])
            if offsets is not None:
                message.row_offsets[:] = offsets
            if weights is not None:
                message.weights[:] = weights
            return message

        one = [(a, 1, 1.0)]
        self.refused(rows(one, offsets=[]), "row_offsets", "must start with 0")
        self.refused(rows(one, offsets=[1, 1]), "row_offsets", "must start with 0")
        self.refused(rows(one, offsets=[0, 2]), "row_offsets", "ends with 2, expected the "
                     "number of entries (1 values)")
        message = rows(one)
        message.node_ids.append(b)
        self.refused(message, "node_ids", "has 2 values for 1 entries")
        message = rows(one)
        message.components.append(0)
        self.refused(message, "components", "has 2 values for 1 entries")
        self.refused(rows(one, weights=[1.0, 1.0]), "weights", "has 2 values for 1 constraints")
        self.refused(rows(one, [(b, 1, 1.0)], offsets=[0, 0, 2], weights=[1.0, 1.0]),
                     "row_offsets", "row 0 is empty")
        self.refused(rows(one, [(b, 1, 1.0)], [(a, 0, 1.0)], offsets=[0, 2, 1, 3],
                          weights=[1.0] * 3), "row_offsets", "row 1 ends before it starts")
        self.refused(rows(one, [(not_contact, 1, 1.0)]), "node_ids[1]",
                     "is %d, not a node of the contact boundaries" % not_contact)
        self.refused(rows([(-1, 1, 1.0)]), "node_ids[0]", "is -1, not a node")
        self.refused(rows([(a, 2, 1.0)]), "components[0]", "is 2, expected 0 (x) or 1 (y)")
        self.refused(rows([(a, 1, float("nan"))]), "values[0]", "is not a finite number")
        self.refused(rows([(a, 1, 1.0)], weights=[0.0]), "weights[0]", "is 0, expected > 0")
        self.refused(rows([(a, 1, 1.0)], weights=[-2.0]), "weights[0]", "expected > 0")
        self.refused(rows([(a, 1, 1.0)], weights=[float("inf")]), "weights[0]", "not a finite")
        self.refused(rows([(a, 1, 1.0), (b, 1, 1.0), (a, 1, 0.5)]), "node_ids[2]",
                     "repeats node id %d" % a)
        # the same pair in two rows, and both components of a node in one row, are fine
        good = rows([(a, 0, 0.6), (a, 1, 0.8)], [(a, 1, 1.0)])
        self.assertEqual(self.ask(request(assign_contact=good)).acknowledge.state, "ready")
        # a refused assignment keeps the previous one
        self.refused(rows([(a, 2, 1.0)]), "components[0]", "expected 0 (x) or 1 (y)", "ready")
        solve = protocol.ContactSolveRequest(obstacle=[1.0, 1.0])
        self.assertEqual(self.ask(request(contact_solve=solve)).contact_result.status,
                         protocol.CONVERGED)


class FieldsOutput(ServerTestCase):
    """FieldsRequest.write_directory: only under the output root, no symbolic link followed."""

    def setUp(self):
        self.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-py-output-"))
        self.root = self.scratch / "root"
        self.elsewhere = self.scratch / "elsewhere"
        self.root.mkdir()
        self.elsewhere.mkdir()
        (self.root / "link").symlink_to(self.elsewhere)
        self.server = self.make_server(output_root=str(self.root))
        self.count = len(self.set_up_and_assign().node_ids)

    def tearDown(self):
        shutil.rmtree(self.scratch)

    def fields(self, directory):
        return request(fields=protocol.FieldsRequest(contact_force=[0.0] * self.count,
                                                     write_directory=directory))

    def test_written_under_the_output_root(self):
        reply = self.ask(self.fields("results/run-1")).fields_reply
        expected = self.root / "results" / "run-1" / "lower.vtu"
        self.assertEqual(reply.written_file, str(expected))
        self.assertTrue(expected.read_bytes().startswith(b'<?xml version="1.0"?>'))

    def test_the_file_holds_the_reply_fields_as_vtk_reads_them(self):
        """The written .vtu read by VTK's reader (ParaView's, python3-paraview): binary and
        zlib-compressed; the reply's points and fields; the stress as (XX, YY, ZZ, XY, YZ, XZ)
        with ZZ = nu (XX + YY) (plane strain, nu = 0.3) and YZ = XZ = 0; the reply's named
        boundaries as line cells (VTK_LINE) with boundary_id k naming boundary_names[k - 1]."""
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
        message = request(fields=protocol.FieldsRequest(contact_force=[1.0] * self.count,
                                                        write_directory="run"))
        reply = self.ask(message).fields_reply
        path = self.root / "run" / "lower.vtu"
        self.assertIn(b'compressor="vtkZLibDataCompressor"', path.read_bytes()[:400])
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(path))
        reader.Update()
        grid = reader.GetOutput()
        points = vtk_to_numpy(grid.GetPoints().GetData())
        np.testing.assert_array_equal(points[:, :2],
                                      np.reshape(reply.node_coordinates, (-1, 2)))
        fields = {field.name: np.reshape(field.values, (-1, field.components))
                  for field in reply.point_fields}
        displacement = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
        np.testing.assert_array_equal(displacement[:, :2], fields["displacement"])
        self.assertGreater(np.abs(displacement).max(), 0.0)
        stress = vtk_to_numpy(grid.GetPointData().GetArray("stress"))
        np.testing.assert_array_equal(stress, fields["stress"])
        np.testing.assert_allclose(stress[:, 2], 0.3 * (stress[:, 0] + stress[:, 1]),
                                   rtol=1e-15, atol=1e-15 * np.abs(stress).max())
        np.testing.assert_array_equal(stress[:, 4:], 0.0)
        names = grid.GetFieldData().GetAbstractArray("boundary_names")
        self.assertEqual([names.GetValue(k) for k in range(names.GetNumberOfValues())],
                         sorted(boundary.name for boundary in reply.boundaries))
        self.assertEqual(sorted(boundary.name for boundary in reply.boundaries),
                         ["bottom", "contact", "left", "right"])
        boundary_id = vtk_to_numpy(grid.GetCellData().GetArray("boundary_id"))
        types = np.array([grid.GetCellType(k) for k in range(grid.GetNumberOfCells())])
        element_count = len(reply.connectivity) // 3
        np.testing.assert_array_equal(boundary_id[:element_count], 0)
        np.testing.assert_array_equal(types[element_count:], 3)
        segments = sum(len(boundary.segments.connectivity) // 2 for boundary in reply.boundaries)
        self.assertEqual(len(types), element_count + segments)

    def test_a_symbolic_link_at_the_target_is_replaced_not_followed(self):
        victim = self.elsewhere / "victim.txt"
        victim.write_text("untouched")
        (self.root / "out").mkdir()
        (self.root / "out" / "lower.vtu").symlink_to(victim)
        self.ask(self.fields("out"))
        self.assertEqual(victim.read_text(), "untouched")
        target = self.root / "out" / "lower.vtu"
        self.assertFalse(target.is_symlink())
        self.assertIn(b"<VTKFile", target.read_bytes())

    def test_directories_outside_the_root_are_refused(self):
        for directory, reason in (("../escape", "contains '..'"),
                                  ("results/../../escape", "contains '..'"),
                                  (str(self.elsewhere), "is an absolute path"),
                                  ("link", "goes through the symbolic link 'link'"),
                                  ("link/sub", "goes through the symbolic link 'link'")):
            message = self.expect_error(self.fields(directory), "INVALID_ARGUMENT", "ready")
            self.assertIn("FieldsRequest.write_directory %r of body 'lower' %s" %
                          (directory, reason), message)
        self.assertEqual(list(self.elsewhere.iterdir()), [])
        self.assertFalse((self.scratch / "escape").exists())
        self.assertEqual([path.name for path in self.root.iterdir()], ["link"])

    def test_without_output_root_write_directory_is_refused(self):
        self.server = self.make_server()
        self.set_up_and_assign()
        message = self.expect_error(self.fields("results"), "INVALID_ARGUMENT", "ready")
        self.assertIn("FieldsRequest.write_directory 'results' of body 'lower' is refused: the "
                      "server was started without --output-root", message)
        self.assertFalse(os.path.exists("results"))
        self.assertEqual(len(self.ask(self.fields("")).fields_reply.point_fields), 6)


class NonFiniteReplies(ServerTestCase):
    """A reply that would carry a NaN or an infinity is Error(SOLVER_FAILURE) instead."""

    def test_overflowing_forces_are_solver_failure(self):
        scratch = tempfile.mkdtemp(prefix="robin-py-output-")
        self.addCleanup(shutil.rmtree, scratch)
        self.server = self.make_server(output_root=scratch)
        interface = self.ask(request(setup_body=setup_body())).interface
        node = interface.node_ids[2]
        # two constraints on the same u_y: B' lambda = 1.5e308 + 1.5e308 overflows
        assign = support.sparse_rows(protocol, [(1.0, [(node, 1, 1.0)]), (1.0, [(node, 1, 1.0)])])
        self.ask(request(assign_contact=assign))
        huge = [1.5e308, 1.5e308]
        message = self.expect_error(
            request(neumann_solve=protocol.NeumannSolveRequest(iteration=5, contact_force=huge)),
            "SOLVER_FAILURE", "ready")
        self.assertIn("body 'lower': NeumannSolveRequest iteration 5: the reply would carry the "
                      "non-finite number NeumannSolveResult.normal_trace[0]", message)
        fields = protocol.FieldsRequest(contact_force=huge, write_directory="out")
        message = self.expect_error(request(fields=fields), "SOLVER_FAILURE", "ready")
        self.assertIn("body 'lower': FieldsRequest: the reply would carry the non-finite number "
                      "FieldsReply.point_fields[0].values", message)
        self.assertEqual(os.listdir(scratch), [])          # nothing written
        finite = protocol.NeumannSolveRequest(contact_force=[1.0, 1.0])
        self.assertEqual(len(self.ask(request(neumann_solve=finite)).neumann_result.normal_trace),
                         2)


if __name__ == "__main__":
    unittest.main()
