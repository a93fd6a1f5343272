"""robin_contact (python/robin_contact) through the real executables (ROBIN_CONTACT_BIN, set by
CTest to build/bin): the contact patch test (examples/non_matching_blocks.toml) solved by
robin-run and robin-monolithic, checked against its exact solution, a uniform uniaxial stress:

    p = d / (H1 (1 - nu1^2) / E1 + H2 (1 - nu2^2) / E2)

with the top displacement d, H1 = 0.5, H2 = 0.4, nu1 = 0.3, nu2 = 0.25, E2 = 400 (the case
file's comment). In the lower block [0, 1] x [-0.5, 0] (rollers below and on the left) the
displacement is u_x = nu1 (1 + nu1) p / E1 x, u_y = -(1 - nu1^2) p / E1 (y + 0.5) (plane strain,
sigma_yy = -p, sigma_xx = 0). An override sweep of d and E1 follows p; a bad override is a
RunError naming it."""

import os
import pathlib
import shutil
import sys
import tempfile
import unittest

import numpy as np

import support
import robin_contact

PATCH_CASE = support.REPOSITORY / "examples" / "non_matching_blocks.toml"
TOP_DISPLACEMENT = "body[2].dirichlet[1].y"  # the upper block's top: y = -d
LOWER_MODULUS = "body[1].material.young"


def patch_pressure(displacement=0.01, young1=1000.0):
    return displacement / (0.5 * (1.0 - 0.3 ** 2) / young1 + 0.4 * (1.0 - 0.25 ** 2) / 400.0)


def bin_directory():
    directory = os.environ.get("ROBIN_CONTACT_BIN")
    return robin_contact.find_bin_directory(directory)


class Scratch(unittest.TestCase):
    def setUp(self):
        self.directory = pathlib.Path(tempfile.mkdtemp(prefix="robin-scripting-test-"))
        self.bin = bin_directory()

    def tearDown(self):
        shutil.rmtree(self.directory, ignore_errors=True)

    def run_patch(self, name, tool="robin-run", overrides=None):
        return robin_contact.run_case(PATCH_CASE, overrides=overrides, tool=tool,
                                      output=self.directory / name, bin_directory=self.bin,
                                      timeout=300)


class PatchTest(Scratch):
    def test_coupled_run_arrays(self):
        results = self.run_patch("coupled")
        p = patch_pressure()
        self.assertTrue(results.summary["converged"])
        np.testing.assert_allclose(results.contact["pressure"], p, rtol=1e-6)
        self.assertEqual(results.contact["pair"].dtype, np.int64)
        np.testing.assert_array_equal(results.contact["pair"], np.arange(len(results.contact["pair"])))
        # Contact along y = 0 with the normal of body 1 (the lower block) pointing up.
        np.testing.assert_allclose(results.contact["y"], 0.0, atol=1e-12)
        np.testing.assert_allclose(results.contact["ny"], 1.0, atol=1e-12)
        # One history row per iteration.
        self.assertEqual(len(results.history["iteration"]), results.summary["iterations"])
        # The lower block's displacement field is the exact linear one at every node.
        lower = results.bodies["lower"]
        x, y = lower.points[:, 0], lower.points[:, 1]
        displacement = lower.point_data["displacement"]
        np.testing.assert_allclose(displacement[:, 0], 0.3 * 1.3 * p / 1000.0 * x, atol=1e-9)
        np.testing.assert_allclose(displacement[:, 1], -(1 - 0.09) * p / 1000.0 * (y + 0.5),
                                   atol=1e-9)
        # The upper block's top is where the case file puts it.
        upper = results.bodies["upper"]
        top = np.isclose(upper.points[:, 1], 0.4)
        self.assertGreater(np.count_nonzero(top), 1)
        np.testing.assert_allclose(upper.point_data["displacement"][top, 1], -0.01, atol=1e-15)
        self.assertEqual(results.exit_code, 0)
        self.assertNotIn("[info]", results.log)  # quiet by default

    def test_override_sweep_of_the_load_is_linear(self):
        loads = [0.005, 0.01, 0.02]
        means = []
        for load in loads:
            results = self.run_patch("load-%g" % load, overrides={TOP_DISPLACEMENT: -load})
            self.assertTrue(results.summary["converged"])
            np.testing.assert_allclose(results.contact["pressure"], patch_pressure(load),
                                       rtol=1e-6)
            means.append(np.mean(results.contact["pressure"]))
        # Linear in the load, through the origin.
        np.testing.assert_allclose(np.array(means) / np.array(loads), means[1] / loads[1],
                                   rtol=1e-6)

    def test_monolithic_with_two_overrides(self):
        overrides = {TOP_DISPLACEMENT: -0.02, LOWER_MODULUS: 2000.0}
        results = self.run_patch("monolithic", tool="robin-monolithic", overrides=overrides)
        np.testing.assert_allclose(results.contact["pressure"], patch_pressure(0.02, 2000.0),
                                   rtol=1e-8)
        self.assertIsNone(results.history)
        self.assertEqual(results.summary["overrides"],
                         ["body[2].dirichlet[1].y=-0.02", "body[1].material.young=2000.0"])
        again = robin_contact.read_results(self.directory / "monolithic")
        np.testing.assert_array_equal(again.contact["pressure"], results.contact["pressure"])


class Errors(Scratch):
    def test_bad_value_names_the_override(self):
        with self.assertRaises(robin_contact.RunError) as raised:
            self.run_patch("bad-value", overrides=["coupling.tolerance=abc"])
        self.assertEqual(raised.exception.exit_code, 1)
        self.assertIn("--set coupling.tolerance=abc: coupling.tolerance: expected a number, "
                      "found a string", raised.exception.log)

    def test_unknown_key_is_refused(self):
        with self.assertRaises(robin_contact.RunError) as raised:
            self.run_patch("unknown", tool="robin-monolithic",
                           overrides={"body[1].material.youngs": 5})
        self.assertEqual(raised.exception.exit_code, 1)
        self.assertIn("unknown key 'body[1].material.youngs'", raised.exception.log)

    def test_malformed_override_is_a_command_line_error(self):
        with self.assertRaises(robin_contact.RunError) as raised:
            self.run_patch("malformed", overrides=["coupling.tolerance"])
        self.assertEqual(raised.exception.exit_code, 2)

    def test_unknown_tool(self):
        with self.assertRaises(ValueError):
            robin_contact.run_case(PATCH_CASE, tool="robin-plot")


class TomlValues(unittest.TestCase):
    def test_python_values_become_toml_text(self):
        self.assertEqual(robin_contact.toml_value(1e-10), "1e-10")
        self.assertEqual(robin_contact.toml_value(2e5), "200000.0")
        self.assertEqual(robin_contact.toml_value(np.float64(-0.5)), "-0.5")
        self.assertEqual(robin_contact.toml_value(3), "3")
        self.assertEqual(robin_contact.toml_value(np.int32(7)), "7")
        self.assertEqual(robin_contact.toml_value(True), "true")
        self.assertEqual(robin_contact.toml_value("aitken"), '"aitken"')
        self.assertEqual(robin_contact.toml_value('a "b" \\'), '"a \\"b\\" \\\\"')
        self.assertEqual(robin_contact.toml_value([0.0, -1]), "[0.0, -1]")
        self.assertEqual(robin_contact.toml_value(np.array([[1.0, 2.0], [3.0, 4.0]])),
                         "[[1.0, 2.0], [3.0, 4.0]]")
        self.assertEqual(robin_contact.override_arguments({"a.b": 1, "c": "x"}),
                         ["--set", "a.b=1", "--set", 'c="x"'])
        self.assertEqual(robin_contact.override_arguments(["a=1"]), ["--set", "a=1"])


if __name__ == "__main__":
    sys.exit(unittest.main())
