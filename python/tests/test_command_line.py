"""The command line of robin-subdomain-py (python/robin-subdomain-py), run as a process: the
CurveZMQ options of robin-subdomain are refused with exit status 2 and a message that says the
server speaks plain ZeroMQ only and points to docs/security.md, before anything is bound;
--data-directory and --output-root must name existing directories (else exit status 2); a server
started with them reads SetupBody.mesh_path only under the data directory and writes
FieldsRequest.write_directory only under the output root, answers after refusals and exits 0
after Shutdown. The Gmsh script attacks of issue 11, in a 1.x SetupBody, run and read nothing.
"""

import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest

import support
from robin_subdomain.proto_module import load_protocol

SERVER = support.PYTHON_DIRECTORY / "robin-subdomain-py"
protocol = load_protocol()


def server_environment():
    return dict(os.environ, PYTHONDONTWRITEBYTECODE="1")


def run_server(*arguments):
    """Runs the server with `arguments`; returns (exit status, stdout, stderr)."""
    completed = subprocess.run([sys.executable, str(SERVER)] + list(arguments),
                               capture_output=True, text=True, timeout=60, check=False,
                               stdin=subprocess.DEVNULL, env=server_environment())
    return completed.returncode, completed.stdout, completed.stderr


class CurveOptions(unittest.TestCase):
    def expect_refused(self, option, *arguments):
        status, stdout, stderr = run_server(*arguments)
        self.assertEqual(status, 2, stderr)
        self.assertEqual(stdout, "")  # no "listening on" line: nothing was bound
        self.assertIn(option + " is not supported", stderr)
        self.assertIn("plain ZeroMQ only", stderr)
        self.assertIn("docs/security.md", stderr)
        self.assertIn("tcp://127.0.0.1:PORT", stderr)
        self.assertNotIn("unrecognized arguments", stderr)

    def test_curve_secret_key_is_refused(self):
        self.expect_refused("--curve-secret-key", "--listen", "tcp://127.0.0.1:*",
                            "--curve-secret-key", "server.secret")

    def test_curve_allow_is_refused_also_with_equals_and_before_listen(self):
        self.expect_refused("--curve-allow", "--curve-allow=allowed", "--listen",
                            "tcp://127.0.0.1:*")

    def test_both_options_as_robin_run_curve_passes_them(self):
        self.expect_refused("--curve-secret-key", "--listen", "tcp://127.0.0.1:*", "--name",
                            "lower", "--log-level", "info", "--curve-secret-key", "keys/server",
                            "--curve-allow", "keys/coordinator.public")

    def test_other_bad_options_keep_argparse_message(self):
        status, _, stderr = run_server("--listen", "tcp://127.0.0.1:*", "--no-such-option")
        self.assertEqual(status, 2)
        self.assertIn("unrecognized arguments: --no-such-option", stderr)

    def test_negative_max_dofs_is_refused(self):
        status, _, stderr = run_server("--listen", "tcp://127.0.0.1:*", "--max-dofs", "-1")
        self.assertEqual(status, 2)
        self.assertIn("--max-dofs must be 0 (no limit) or a positive number", stderr)

    def test_negative_protocol_minor_is_refused(self):
        status, _, stderr = run_server("--listen", "tcp://127.0.0.1:*", "--protocol-minor", "-1")
        self.assertEqual(status, 2)
        self.assertIn("--protocol-minor must be 0 or a positive number", stderr)


class Directories(unittest.TestCase):
    def setUp(self):
        self.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-py-command-line-"))
        self.data = self.scratch / "data"
        self.output = self.scratch / "output"
        self.data.mkdir()
        self.output.mkdir()
        shutil.copy(support.TEST_DATA / "case_lower.msh", self.data / "lower.msh")
        shutil.copy(support.TEST_DATA / "case_lower.msh", self.scratch / "outside.msh")

    def tearDown(self):
        shutil.rmtree(self.scratch)

    def test_missing_directories_are_refused(self):
        missing = str(self.scratch / "missing")
        for option in ("--data-directory", "--output-root"):
            status, stdout, stderr = run_server("--listen", "tcp://127.0.0.1:*", option, missing)
            self.assertEqual(status, 2, stderr)
            self.assertEqual(stdout, "")
            self.assertIn("%s '%s' is not an existing directory" % (option, missing), stderr)

    def start_server(self, *options):
        """Starts the server with both directories and `options`; returns (process, ask) where
        ask(**content) sends one request Envelope (version 2.0) and returns the reply
        Envelope."""
        import zmq
        process = subprocess.Popen(
            [sys.executable, str(SERVER), "--listen", "tcp://127.0.0.1:*", "--log-level", "warn",
             "--data-directory", str(self.data), "--output-root", str(self.output)] + list(options),
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
            text=True, env=server_environment())
        self.addCleanup(self.stop, process)
        line = process.stdout.readline()
        self.assertTrue(line.startswith("listening on "), line)
        context = zmq.Context()
        self.addCleanup(context.term)
        socket = context.socket(zmq.REQ)
        self.addCleanup(socket.close, 0)
        socket.setsockopt(zmq.RCVTIMEO, 30000)
        socket.connect(line.split()[-1])

        def ask(raw=None, **content):
            """The reply to `raw` (bytes, when given) or to an Envelope with `content`."""
            envelope = protocol.Envelope(request_id=3)
            envelope.version.major = 2
            for name, message in content.items():
                getattr(envelope, name).CopyFrom(message)
            socket.send(raw if raw is not None else envelope.SerializeToString())
            reply = protocol.Envelope()
            reply.ParseFromString(socket.recv())
            return reply

        return process, ask

    @staticmethod
    def setup_body(path):
        body = protocol.SetupBody(body_name="lower", mesh_path=path, model=protocol.PLANE_STRAIN,
                                  young_modulus=1000.0, poisson_ratio=0.3,
                                  contact_boundaries=["contact"])
        body.dirichlet.add(boundary="bottom", x=0.0, y=0.0)
        return body

    def test_protocol_minor_4_plays_a_2_4_server(self):
        """The testing option --protocol-minor (robin-subdomain's): 2.5 by default, with the peak
        resident size in InterfaceDescription; with 4, version 2.4 on every reply and none."""
        for options, version, reports_peak in (((), (2, 5), True),
                                               (("--protocol-minor", "4"), (2, 4), False)):
            with self.subTest(options=options):
                process, ask = self.start_server(*options)
                reply = ask(setup_body=self.setup_body("lower.msh"))
                self.assertEqual((reply.version.major, reply.version.minor), version)
                self.assertEqual(reply.interface.peak_resident_bytes > 0, reports_peak, reply)
                self.assertEqual(ask(shutdown=protocol.Shutdown()).version.minor, version[1])
                self.assertEqual(process.wait(timeout=30), 0)

    def test_served_files_stay_under_the_directories(self):
        process, ask = self.start_server()
        refused = ask(setup_body=self.setup_body("../outside.msh"))
        self.assertEqual(refused.error.code, protocol.BAD_INPUT)
        self.assertIn("leaves the server's data directory", refused.error.message)
        self.assertEqual(ask(hello=protocol.Hello()).hello_reply.state, "awaiting_setup")
        interface = ask(setup_body=self.setup_body("lower.msh")).interface
        self.assertEqual(len(interface.node_ids), 3)     # y = 0 of [0, 1] x [-1, 0], h = 0.5
        assign = support.node_to_node_assignment(protocol, interface)
        self.assertEqual(ask(assign_contact=assign).acknowledge.state, "ready")
        fields = protocol.FieldsRequest(contact_force=[0.0] * 3, write_directory="../escape")
        self.assertEqual(ask(fields=fields).error.code, protocol.INVALID_ARGUMENT)
        fields.write_directory = "run"
        written = ask(fields=fields).fields_reply.written_file
        self.assertEqual(written, str(self.output.resolve() / "run" / "lower.vtu"))
        self.assertTrue(os.path.isfile(written))
        self.assertEqual(sorted(os.listdir(self.scratch)), ["data", "output", "outside.msh"])
        self.assertEqual(ask(shutdown=protocol.Shutdown()).acknowledge.state, "ready")
        self.assertEqual(process.wait(timeout=30), 0)

    def test_version_1_geo_scripts_are_never_run(self):
        """Each attack of support.hostile_geo_scripts in the removed 1.x SetupBody.mesh_content,
        without and then with a MeshData: BAD_INPUT, then a body set up from the MeshData; the
        witness never appears, no reply shows a line of /etc/passwd or the server's working
        directory (this process's), and the server answers Hello after each request."""
        process, ask = self.start_server()
        witness = self.scratch / "witness"
        script_start = (support.REPOSITORY / "examples" / "meshes" / "block_lower.geo").read_text()
        mesh = support.mesh_data_from_msh(protocol, "case_lower.msh")
        for label, text in support.hostile_geo_scripts(witness):
            with self.subTest(label):
                for body, content in ((self.setup_body(""), "error"),
                                      (self.setup_body(""), "interface")):
                    if content == "interface":
                        body.mesh.CopyFrom(mesh)
                    envelope = protocol.Envelope(request_id=4, setup_body=body)
                    envelope.version.major = 2
                    reply = ask(raw=support.with_1x_script(envelope.SerializeToString(),
                                                           script_start + text))
                    self.assertEqual(reply.WhichOneof("content"), content, reply)
                    if content == "error":
                        self.assertEqual(reply.error.code, protocol.BAD_INPUT)
                        self.assertIn("SetupBody.mesh and SetupBody.mesh_path are both empty",
                                      reply.error.message)
                    reply_bytes = reply.SerializeToString()
                    for line in support.passwd_lines():
                        self.assertNotIn(line.encode(), reply_bytes)
                    self.assertNotIn(os.getcwd().encode(), reply_bytes)
                    self.assertIn(ask(hello=protocol.Hello()).hello_reply.state,
                                  ("awaiting_setup", "awaiting_assignment"))
                self.assertFalse(witness.exists(), "the script ran")
        self.assertEqual(ask(shutdown=protocol.Shutdown()).acknowledge.state,
                         "awaiting_assignment")
        self.assertEqual(process.wait(timeout=30), 0)

    @staticmethod
    def stop(process):
        """Ends the server this test started (if still running) and closes its pipe."""
        if process.poll() is None:
            process.kill()
            process.wait(timeout=30)
        process.stdout.close()


if __name__ == "__main__":
    unittest.main()
