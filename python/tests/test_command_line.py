"""The command line of robin-subdomain-py (python/robin-subdomain-py), run as a process: the
CurveZMQ options of robin-subdomain are refused with exit status 2 and a message that says the
server speaks plain ZeroMQ only and points to docs/security.md, before anything is bound.
"""

import os
import subprocess
import sys
import unittest

import support

SERVER = support.PYTHON_DIRECTORY / "robin-subdomain-py"


def run_server(*arguments):
    """Runs the server with `arguments`; returns (exit status, stdout, stderr)."""
    environment = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    completed = subprocess.run([sys.executable, str(SERVER)] + list(arguments),
                               capture_output=True, text=True, timeout=60, check=False,
                               stdin=subprocess.DEVNULL, env=environment)
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


if __name__ == "__main__":
    unittest.main()
