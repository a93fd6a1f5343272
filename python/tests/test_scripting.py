"""robin_contact (python/robin_contact) through the real executables (ROBIN_CONTACT_BIN, set by
CTest to build/bin): the contact patch test (examples/non_matching_blocks.toml) solved by
robin-run and robin-monolithic, checked against its exact solution, a uniform uniaxial stress:

    p = d / (H1 (1 - nu1^2) / E1 + H2 (1 - nu2^2) / E2)

with the top displacement d, H1 = 0.5, H2 = 0.4, nu1 = 0.3, nu2 = 0.25, E2 = 400 (the case
file's comment). In the lower block [0, 1] x [-0.5, 0] (rollers below and on the left) the
displacement is u_x = nu1 (1 + nu1) p / E1 x, u_y = -(1 - nu1^2) p / E1 (y + 0.5) (plane strain,
sigma_yy = -p, sigma_xx = 0). An override sweep of d and E1 follows p; a bad override is a
RunError naming it.

ContactGraphResults needs no build: read_results on result directories the test writes itself
(three bodies, two interfaces, their contact_<k>_<a>_<b>.csv files and summary.json's
"interfaces"; a two-body directory; an older one without "interfaces"), with numbers chosen
here."""

import json
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


# --- Result directories of a contact graph, written by the test --------------------------------

CONTACT_HEADER = "pair,x,y,nx,ny,gap0,un1,un2,lambda1,lambda2,pressure"


def contact_text(rows):
    return "\n".join([CONTACT_HEADER] + [",".join(repr(value) for value in row)
                                         for row in rows]) + "\n"


# Interface 1, 'lower' (top) / 'middle' (bottom), three pairs along y = 0; interface 2,
# 'middle' (top) / 'upper' (bottom), two pairs along y = 1. Columns as CONTACT_HEADER.
ROWS1 = [(0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.001, -0.001, 0.5, 0.5, 2.0),
         (1, 0.5, 0.0, 0.0, 1.0, 0.0, 0.002, -0.002, 1.0, 1.0, 4.0),
         (2, 1.0, 0.0, 0.0, 1.0, 0.0, 0.001, -0.001, 0.5, 0.5, 2.0)]
ROWS2 = [(0, 0.0, 1.0, 0.0, 1.0, 0.01, 0.003, 0.002, 0.0, 0.0, 0.0),
         (1, 1.0, 1.0, 0.0, 1.0, 0.0, 0.004, -0.004, 0.75, 0.75, 1.5)]


def vtu_text(offset):
    """A one-triangle UnstructuredGrid in text form, its displacement (offset, 2 offset, 0)."""
    return ("""<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="3" NumberOfCells="1">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">
0 0 0 1 0 0 0 1 0</DataArray></Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="ascii">0 1 2</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">3</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">5</DataArray>
</Cells>
<PointData><DataArray type="Float64" Name="displacement" NumberOfComponents="3" format="ascii">
%r %r 0 %r %r 0 %r %r 0</DataArray></PointData>
</Piece></UnstructuredGrid></VTKFile>
""" % ((offset, 2 * offset) * 3))


def write_result_directory(directory, bodies, contact_files, interfaces):
    """summary.json (with `interfaces` unless None), solution.pvd naming one .vtu per body, and
    the contact files {name: rows}."""
    directory.mkdir()
    summary = {"status": "converged", "converged": True, "iterations": 7,
               "contact_pairs": sum(len(rows) for rows in contact_files.values())}
    if interfaces is not None:
        summary["interfaces"] = interfaces
        summary["contact_force_resultant"] = (interfaces[0]["contact_force_resultant"]
                                              if len(interfaces) == 1 else None)
    (directory / "summary.json").write_text(json.dumps(summary))
    datasets = "".join('<DataSet timestep="0" part="%d" file="%s.vtu"/>' % (part, name)
                       for part, name in enumerate(bodies))
    (directory / "solution.pvd").write_text(
        '<?xml version="1.0"?><VTKFile type="Collection" version="0.1"><Collection>%s'
        '</Collection></VTKFile>\n' % datasets)
    for index, name in enumerate(bodies):
        (directory / ("%s.vtu" % name)).write_text(vtu_text(0.001 * (index + 1)))
    for name, rows in contact_files.items():
        (directory / name).write_text(contact_text(rows))
    return directory


def interface_entry(bodies, boundaries, rows, file):
    return {"bodies": bodies, "boundaries": boundaries,
            "contact_discretization": "node-to-node, %d pairs" % len(rows),
            "contact_pairs": len(rows), "active_pairs": sum(row[10] > 0 for row in rows),
            "largest_pressure": max(row[10] for row in rows), "excluded_pairs": [],
            "initial_overlap": "", "contact_force_resultant": [0.0, sum(row[8] for row in rows)],
            "file": file}


class ContactGraphResults(unittest.TestCase):
    def setUp(self):
        self.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-scripting-graph-"))

    def tearDown(self):
        shutil.rmtree(self.scratch, ignore_errors=True)

    def write_graph(self, name="graph", with_summary_interfaces=True):
        files = {"contact_1_lower_middle.csv": ROWS1, "contact_2_middle_upper.csv": ROWS2}
        interfaces = [interface_entry(["lower", "middle"], ["top", "bottom"], ROWS1,
                                      "contact_1_lower_middle.csv"),
                      interface_entry(["middle", "upper"], ["top", "bottom"], ROWS2,
                                      "contact_2_middle_upper.csv")]
        return write_result_directory(self.scratch / name, ["lower", "middle", "upper"], files,
                                      interfaces if with_summary_interfaces else None)

    def test_every_interface_has_its_bodies_and_table(self):
        results = robin_contact.read_results(self.write_graph())
        self.assertEqual(len(results.interfaces), 2)
        first, second = results.interfaces
        self.assertEqual((first.number, first.bodies, first.boundaries, first.file),
                         (1, ("lower", "middle"), ("top", "bottom"),
                          "contact_1_lower_middle.csv"))
        self.assertEqual((second.number, second.bodies, second.file),
                         (2, ("middle", "upper"), "contact_2_middle_upper.csv"))
        np.testing.assert_array_equal(first.contact["pressure"], [2.0, 4.0, 2.0])
        np.testing.assert_array_equal(first.contact["x"], [0.0, 0.5, 1.0])
        np.testing.assert_array_equal(second.contact["pressure"], [0.0, 1.5])
        np.testing.assert_array_equal(second.contact["lambda1"], [0.0, 0.75])
        self.assertEqual(second.contact["pair"].dtype, np.int64)
        # The final gap d - u_N(a) - u_N(b) of interface 2: 0.01 - 0.005 open, 0 closed.
        gap = second.contact["gap0"] - second.contact["un1"] - second.contact["un2"]
        np.testing.assert_allclose(gap, [0.005, 0.0], atol=1e-15)
        self.assertEqual(first.summary["active_pairs"], 3)
        self.assertEqual(second.summary["largest_pressure"], 1.5)
        self.assertEqual(second.summary["contact_force_resultant"], [0.0, 0.75])
        self.assertIsNone(results.summary["contact_force_resultant"])
        # Lookup by bodies, in either order.
        self.assertIs(results.interface("upper", "middle"), second)
        self.assertIs(results.interface("lower", "middle"), first)
        with self.assertRaises(KeyError) as raised:
            results.interface("lower", "upper")
        self.assertIn("no contact interface between 'lower' and 'upper'", str(raised.exception))
        # The bodies: every part of solution.pvd.
        self.assertEqual(list(results.bodies), ["lower", "middle", "upper"])
        np.testing.assert_allclose(results.bodies["upper"].point_data["displacement"][:, 1],
                                   0.006)

    def test_contact_of_several_interfaces_is_an_error_naming_them(self):
        results = robin_contact.read_results(self.write_graph())
        with self.assertRaises(ValueError) as raised:
            results.contact
        self.assertIn("the run has 2 contact interfaces", str(raised.exception))
        self.assertIn("results.interfaces[k].contact", str(raised.exception))
        self.assertIn("contact_1_lower_middle.csv, contact_2_middle_upper.csv",
                      str(raised.exception))

    def test_without_summary_interfaces_the_files_on_disk(self):
        results = robin_contact.read_results(self.write_graph("bare", False))
        self.assertEqual([(i.number, i.file, i.bodies) for i in results.interfaces],
                         [(1, "contact_1_lower_middle.csv", None),
                          (2, "contact_2_middle_upper.csv", None)])
        np.testing.assert_array_equal(results.interfaces[1].contact["pressure"], [0.0, 1.5])

    def test_a_missing_contact_file_is_named(self):
        directory = self.write_graph()
        (directory / "contact_2_middle_upper.csv").unlink()
        with self.assertRaises(FileNotFoundError) as raised:
            robin_contact.read_results(directory)
        self.assertIn("contact_2_middle_upper.csv", str(raised.exception))

    def test_two_bodies_keep_contact(self):
        interfaces = [interface_entry(["lower", "upper"], ["contact", "contact"], ROWS1,
                                      "contact.csv")]
        directory = write_result_directory(self.scratch / "two", ["lower", "upper"],
                                           {"contact.csv": ROWS1}, interfaces)
        results = robin_contact.read_results(directory)
        np.testing.assert_array_equal(results.contact["pressure"], [2.0, 4.0, 2.0])
        self.assertEqual(len(results.interfaces), 1)
        self.assertIs(results.interfaces[0].contact, results.contact)
        self.assertEqual(results.interfaces[0].bodies, ("lower", "upper"))
        self.assertEqual(results.interfaces[0].boundaries, ("contact", "contact"))
        self.assertEqual(results.summary["contact_force_resultant"], [0.0, 2.0])
        # A result directory of an older version (no "interfaces"): body 1 and body 2.
        older = write_result_directory(self.scratch / "older", ["flat", "punch"],
                                       {"contact.csv": ROWS2}, None)
        results = robin_contact.read_results(older)
        np.testing.assert_array_equal(results.contact["pressure"], [0.0, 1.5])
        self.assertEqual(results.interfaces[0].bodies, ("flat", "punch"))
        self.assertIsNone(results.interfaces[0].boundaries)
        self.assertEqual(results.interface("punch", "flat").file, "contact.csv")


if __name__ == "__main__":
    sys.exit(unittest.main())
