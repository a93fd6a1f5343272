"""The protocol state machine of the Python subdomain server, without a socket: states and their
transitions, the error codes of refused requests, and replies that echo the request id and carry
version 1.2. The Neumann solve of 1.1 through the protocol: its refusals, and its answer equal to
e - F lambda assembled from the server's own contact-solve and correction replies. The run rule of
1.2 (Envelope.run_id): another run's requests are WRONG_STATE and change nothing, the body's run
and requests without run_id are served. A temporary directory that cannot hold the files for gmsh
is the server's fault: INTERNAL, naming the body.
"""

import os
import pathlib
import tempfile
import unittest

import numpy as np

import support
from robin_subdomain.proto_module import load_protocol
from robin_subdomain.protocol import SubdomainProtocol

protocol = load_protocol()
LOWER_GEO = (support.REPOSITORY / "examples" / "meshes" / "block_lower.geo").read_bytes()


def request(request_id=7, major=1, run_id="", **content):
    envelope = protocol.Envelope()
    envelope.request_id = request_id
    envelope.run_id = run_id
    if major is not None:
        envelope.version.major = major
    for name, message in content.items():
        getattr(envelope, name).CopyFrom(message)
    return envelope.SerializeToString()


def setup_body(**changes):
    message = protocol.SetupBody(body_name="lower", mesh_content=LOWER_GEO, mesh_extension=".geo",
                                 mesh_size=0.5, model=protocol.PLANE_STRAIN, young_modulus=1000.0,
                                 poisson_ratio=0.3, contact_boundary="contact")
    condition = message.dirichlet.add()
    condition.boundary, condition.x, condition.y = "bottom", 0.0, 0.0
    for name, value in changes.items():
        setattr(message, name, value)
    return message


class StateMachine(unittest.TestCase):
    def setUp(self):
        self.server = SubdomainProtocol(protocol)
        self.server.logger.disabled = True

    def ask(self, data):
        reply = protocol.Envelope()
        reply.ParseFromString(self.server.handle(data))
        self.assertEqual((reply.version.major, reply.version.minor), (1, 2))
        return reply

    def expect_error(self, data, code, state):
        reply = self.ask(data)
        self.assertEqual(reply.WhichOneof("content"), "error", reply)
        self.assertEqual(protocol.ErrorCode.Name(reply.error.code), code, reply.error.message)
        self.assertEqual(reply.error.state, state)
        return reply.error.message

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
        message = self.expect_error(request(major=2, hello=protocol.Hello()), "VERSION_MISMATCH",
                                    "awaiting_setup")
        self.assertIn("2.0", message)
        self.assertIn("this server 1.2", message)
        self.expect_error(request(acknowledge=protocol.Acknowledge()), "UNSUPPORTED",
                          "awaiting_setup")
        # field 31 of the Envelope: a request type this version does not know
        self.expect_error(request() + b"\xfa\x01\x00", "UNSUPPORTED", "awaiting_setup")

    def test_states_and_transitions(self):
        solve = protocol.ContactSolveRequest(obstacle=[0.0])
        self.expect_error(request(contact_solve=solve), "WRONG_STATE", "awaiting_setup")
        reply = self.ask(request(setup_body=setup_body()))
        interface = reply.interface
        self.assertEqual(interface.body_name, "lower")
        count = len(interface.node_ids)
        self.assertEqual(count, 5)  # the transfinite contact edge, h = 0.5
        np.testing.assert_allclose(np.array(interface.normals).reshape(-1, 2),
                                   np.tile([0.0, 1.0], (count, 1)), atol=1e-15)
        self.assertAlmostEqual(sum(interface.weights), 2.0, delta=1e-14)
        self.expect_error(request(contact_solve=solve), "WRONG_STATE", "awaiting_assignment")
        bad = protocol.AssignContact(node_ids=[interface.node_ids[0]], normals=[0.0, 2.0])
        self.expect_error(request(assign_contact=bad), "INVALID_ARGUMENT", "awaiting_assignment")
        good = protocol.AssignContact(node_ids=interface.node_ids, normals=interface.normals)
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

    def test_neumann_solve(self):
        neumann = protocol.NeumannSolveRequest(iteration=3, contact_force=[0.0])
        self.expect_error(request(neumann_solve=neumann), "WRONG_STATE", "awaiting_setup")
        loaded = setup_body()
        loaded.body_force.extend([0.0, -5.0])
        interface = self.ask(request(setup_body=loaded)).interface
        count = len(interface.node_ids)
        self.expect_error(request(neumann_solve=neumann), "WRONG_STATE", "awaiting_assignment")
        assign = protocol.AssignContact(node_ids=interface.node_ids, normals=interface.normals)
        self.ask(request(assign_contact=assign))
        message = self.expect_error(request(neumann_solve=neumann), "INVALID_ARGUMENT", "ready")
        self.assertIn("NeumannSolveRequest.contact_force has 1 values for the %d" % count,
                      message)
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

    def test_requests_of_another_run_are_wrong_state_and_change_nothing(self):
        run, other = "0123456789abcdef0123456789abcdef", "another-coordinator"
        reply = self.ask(request(run_id=run, setup_body=setup_body()))
        self.assertEqual(reply.run_id, run)                       # echoed
        interface = reply.interface
        count = len(interface.node_ids)
        assign = protocol.AssignContact(node_ids=interface.node_ids, normals=interface.normals)

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
        # the run's own requests, and those without run_id (a 1.1 coordinator), are served
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
        assign = protocol.AssignContact(node_ids=interface.node_ids, normals=interface.normals)
        self.assertEqual(self.ask(request(run_id="b", assign_contact=assign)).acknowledge.state,
                         "ready")
        solve = protocol.ContactSolveRequest(obstacle=[1.0] * len(interface.node_ids))
        self.assertEqual(self.ask(request(run_id="c", contact_solve=solve)).contact_result.status,
                         protocol.CONVERGED)

    def test_bad_bodies(self):
        self.expect_error(request(setup_body=setup_body(poisson_ratio=0.5)), "BAD_INPUT",
                          "awaiting_setup")
        message = self.expect_error(request(setup_body=setup_body(contact_boundary="lid")),
                                    "BAD_INPUT", "awaiting_setup")
        self.assertIn("bottom, contact, left, right", message)
        singular = setup_body()
        singular.ClearField("dirichlet")
        self.expect_error(request(setup_body=singular), "SINGULAR_BODY", "awaiting_setup")
        self.expect_error(request(setup_body=setup_body(mesh_content=b"Point(1) = {0, 0, 0;")),
                          "BAD_INPUT", "awaiting_setup")

    def test_geo_script_that_runs_a_command_is_refused_unrun(self):
        witness = pathlib.Path(tempfile.gettempdir()) / ("robin-py-geo-witness-%d" % os.getpid())
        witness.unlink(missing_ok=True)
        hostile = LOWER_GEO + b'\nSystemCall "touch %s";\n' % str(witness).encode()
        message = self.expect_error(request(setup_body=setup_body(mesh_content=hostile)),
                                    "BAD_INPUT", "awaiting_setup")
        self.assertIn("body 'lower': SetupBody.mesh_content line", message)
        self.assertIn("'SystemCall' is refused", message)
        self.assertFalse(witness.exists())
        harmless = LOWER_GEO + b'\n// SystemCall "touch x";\nDummy = StrCat("Include");\n'
        self.ask(request(setup_body=setup_body(mesh_content=harmless)))
        self.assertEqual(self.server.state, "awaiting_assignment")

    def test_failed_setup_discards_the_previous_body(self):
        self.ask(request(setup_body=setup_body()))
        self.assertEqual(self.server.state, "awaiting_assignment")
        self.expect_error(request(setup_body=setup_body(young_modulus=-1.0)), "BAD_INPUT",
                          "awaiting_setup")

    def test_unusable_temporary_directory_is_internal_and_names_the_body(self):
        saved = tempfile.tempdir
        tempfile.tempdir = "/nonexistent/robin-test-temporary-directory"
        try:
            message = self.expect_error(request(setup_body=setup_body()), "INTERNAL",
                                        "awaiting_setup")
        finally:
            tempfile.tempdir = saved
        self.assertTrue(message.startswith("body 'lower': SetupBody.mesh_content: "), message)
        self.assertIn("'/nonexistent/robin-test-temporary-directory'", message)
        self.assertIn("temporary directory (TMPDIR, else /tmp) is not writable or is full",
                      message)
        self.assertNotIn("internal error", message)
        self.ask(request(setup_body=setup_body()))  # the server goes on
        self.assertEqual(self.server.state, "awaiting_assignment")


if __name__ == "__main__":
    unittest.main()
