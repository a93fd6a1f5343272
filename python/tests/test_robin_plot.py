"""robin-plot and the convergence outputs of a coupled run, through the real tools of a build.

robin-run solves examples/hertz.toml (two robin-subdomain processes, the default
either-sequence stopping); the test then reads history.csv and summary.json itself and checks
that the numbers say how the run converged: the accepted obstacle sequence's residual in its
last row is below the tolerance of summary.json, so is every residual of the accepted state,
stopping_residual is the smallest of the joint state's and the sequences' largest residuals and
first drops below the tolerance in the last row. robin-plot then writes the PNG files, exits 0,
and its figures carry the numbers: the tolerance line, the accepted state, integer iteration
ticks, the title naming the status, and the analytic Hertz curve with the half-width
a = sqrt(4PR/(pi E*)) and peak pressure p0 = 2P/(pi a) computed here from the case's
materials and the run's contact resultant. Its command line: --help, --version (the project
version), exit status 2 for a bad command line and 1 for a directory without results.

Result directories of a contact graph (ContactGraphDirectory) are written by the test itself,
with numbers chosen here: three bodies, two interfaces (one horizontal, one vertical), their
contact_<k>_<a>_<b>.csv files, summary.json with its "interfaces" array and a history.csv with
the per-body columns of three bodies; robin-plot draws one row of panels per interface whose
curves are those numbers, and names the contact file that is missing. These need no build of
the C++ tools (robin-plot of the build when there is one, else the source copy).

The tools are those of the build directory named by ROBIN_CONTACT_BIN (set by CTest), default
build/bin. Needs Debian's matplotlib and numpy (/usr/bin/python3).
"""

import csv
import importlib.machinery
import importlib.util
import json
import math
import os
import pathlib
import re
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

REPOSITORY = pathlib.Path(__file__).resolve().parents[2]
BIN = pathlib.Path(os.environ.get("ROBIN_CONTACT_BIN", REPOSITORY / "build" / "bin"))
HERTZ = REPOSITORY / "examples" / "hertz.toml"
SOURCE_PLOT = REPOSITORY / "coordinator" / "tools" / "robin-plot"

# examples/hertz.toml: both bodies E = 1000, nu = 0.3, plane strain, gap x^2 / (2 R), R = 1.
YOUNG, POISSON, RADIUS = 1000.0, 0.3, 1.0


def run(*arguments, cwd=None):
    completed = subprocess.run([str(argument) for argument in arguments], capture_output=True,
                               text=True, timeout=600, check=False, cwd=cwd,
                               stdin=subprocess.DEVNULL)
    return completed.returncode, completed.stdout, completed.stderr


def read_csv(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def plot_executable():
    """The build's robin-plot, else the source copy (for the tests that need no other tool)."""
    return BIN / "robin-plot" if (BIN / "robin-plot").exists() else SOURCE_PLOT


def load_plot_module(path=None):
    """The build's robin-plot as a module (it has no .py suffix), for its figures."""
    path = BIN / "robin-plot" if path is None else path
    loader = importlib.machinery.SourceFileLoader("robin_plot", str(path))
    spec = importlib.util.spec_from_loader("robin_plot", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    import matplotlib

    matplotlib.use("Agg")
    return module


def project_version():
    """The product version, read from the sources as CMake does (VERSION, else project())."""
    version_file = REPOSITORY / "VERSION"
    if version_file.exists():
        return version_file.read_text().split()[0]
    text = (REPOSITORY / "CMakeLists.txt").read_text()
    return re.search(r"project\(robin_contact VERSION ([0-9.]+)", text).group(1)


@unittest.skipUnless((BIN / "robin-run").exists(), f"no robin-run in {BIN}: build it first")
class HertzRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-plot-test-"))
        cls.directory = cls.scratch / "hertz"
        cls.status, _, cls.log = run(BIN / "robin-run", HERTZ, "--output", cls.directory)
        cls.summary = json.loads((cls.directory / "summary.json").read_text())
        cls.history = read_csv(cls.directory / "history.csv")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.scratch, ignore_errors=True)

    def test_run_converged_by_one_obstacle_sequence(self):
        self.assertEqual(self.status, 0, self.log)
        self.assertEqual(self.summary["status"], "converged")
        self.assertEqual(self.summary["stopping"], "either-sequence")
        self.assertIn(self.summary["completed_by_sequence"], (1, 2))

    def test_accepted_sequence_column_ends_below_the_tolerance(self):
        tolerance = self.summary["tolerance"]
        self.assertEqual(tolerance, 1e-8)  # examples/hertz.toml [coupling] tolerance
        column = f"sequence{self.summary['completed_by_sequence']}"
        last = float(self.history[-1][column])
        self.assertLess(last, tolerance)
        self.assertEqual(len(self.history), self.summary["iterations"])
        for row in self.history:
            self.assertEqual(float(row["tolerance"]), tolerance)

    def test_accepted_state_residuals_are_below_the_tolerance(self):
        tolerance = self.summary["tolerance"]
        residuals = self.summary["final_residuals"]
        for name in ("obstacle_change", "penetration", "complementarity",
                     "force_error_estimate"):
            self.assertLess(residuals[name], tolerance, name)
        self.assertEqual(residuals["force_balance"], 0.0)  # one contact force for both bodies
        self.assertEqual(residuals["correction"], 0.0)

    def test_stopping_residual_is_what_the_stopping_test_compared(self):
        tolerance = self.summary["tolerance"]
        joint = ("obstacle_change", "penetration", "force_balance", "complementarity",
                 "correction")
        for index, row in enumerate(self.history):
            largest_joint = max(float(row[name]) for name in joint)
            expected = min([largest_joint, float(row["sequence1"]), float(row["sequence2"])])
            self.assertEqual(float(row["stopping_residual"]), expected, f"row {index + 1}")
            if index + 1 < len(self.history):
                self.assertGreater(expected, tolerance, f"row {index + 1} would have stopped")
        self.assertLessEqual(float(self.history[-1]["stopping_residual"]), tolerance)

    def test_final_log_line_says_how_the_run_converged(self):
        sequence = self.summary["completed_by_sequence"]
        line = next(line for line in self.log.splitlines() if "converged after" in line)
        self.assertIn(f"converged after {len(self.history)} iterations: obstacle sequence "
                      f"{sequence} reached", line)
        self.assertIn("< tolerance 1e-08", line)
        self.assertIn("force error estimate", line)
        progress = [line for line in self.log.splitlines() if "] iteration " in line]
        self.assertEqual(len(progress), len(self.history))
        self.assertIn(f"stopping test {float(self.history[-1]['stopping_residual']):.2e} "
                      f"(obstacle sequence {sequence}; tolerance 1e-08)", progress[-1])

    def test_robin_plot_writes_both_figures(self):
        directory = self.scratch / "plots"
        shutil.copytree(self.directory, directory)
        status, stdout, stderr = run(BIN / "robin-plot", directory)
        self.assertEqual(status, 0, stderr)
        for name in ("contact.png", "history.png"):
            with open(directory / name, "rb") as handle:
                self.assertEqual(handle.read(8), b"\x89PNG\r\n\x1a\n", name)
        self.assertIn("history.png: converged after", stdout)
        self.assertIn("contact.png: Hertz p0 =", stdout)

    def test_history_figure_shows_the_stopping_test(self):
        plot = load_plot_module()
        columns = plot.read_columns(self.directory / "history.csv")
        figure, _ = plot.history_figure(columns, self.summary)
        axis = figure.axes[0]
        labels = [text.get_text() for text in axis.get_legend().get_texts()]
        self.assertIn("tolerance 1e-08", labels)
        tolerance_line = next(line for line in axis.get_lines()
                              if line.get_label() == "tolerance 1e-08")
        self.assertEqual(list(tolerance_line.get_ydata()), [1e-8, 1e-8])
        sequence = self.summary["completed_by_sequence"]
        accepted_value = max(self.summary["final_residuals"].values())
        accepted = [label for label in labels if label.startswith("accepted:")]
        self.assertEqual(accepted, [f"accepted: obstacle sequence {sequence}, largest residual "
                                    f"{accepted_value:.1e}"])
        for k in (1, 2):
            line = next(line for line in axis.get_lines()
                        if line.get_label().startswith(f"obstacle sequence {k}:"))
            expected = [max(float(row[f"sequence{k}"]), 1e-17) for row in self.history]
            self.assertEqual(list(line.get_ydata()), expected)
        self.assertIn(f"converged after {len(self.history)} iterations", axis.get_title())
        self.assertIn("either-sequence stopping", axis.get_title())
        ticks = [tick for tick in axis.get_xticks()
                 if 1 <= tick <= len(self.history)]
        self.assertTrue(ticks)
        self.assertTrue(all(float(tick).is_integer() for tick in ticks), ticks)

    def test_contact_figure_overlays_hertz(self):
        resultant = self.summary["contact_force_resultant"]
        load = math.hypot(*resultant)
        modulus = YOUNG / (2.0 * (1.0 - POISSON ** 2))  # 1/E* = 2 (1 - nu^2) / E
        half_width = math.sqrt(4.0 * load * RADIUS / (math.pi * modulus))
        peak = 2.0 * load / (math.pi * half_width)
        plot = load_plot_module()
        columns = plot.read_columns(self.directory / "contact.csv")
        reference = plot.read_reference(HERTZ, self.summary)
        figure, lines, comparison = plot.contact_figure(columns, self.summary, reference)
        self.assertAlmostEqual(comparison["half_width"], half_width, delta=1e-12 * half_width)
        self.assertAlmostEqual(comparison["peak_pressure"], peak, delta=1e-12 * peak)
        axis = figure.axes[0]
        hertz = next(line for line in axis.get_lines() if line.get_label().startswith("Hertz"))
        self.assertIn(f"p0 = {peak:.4g}, a = {half_width:.4g}", hertz.get_label())
        x, p = np.asarray(hertz.get_xdata()), np.asarray(hertz.get_ydata())
        self.assertAlmostEqual(p.max(), peak, delta=1e-9 * peak)
        self.assertAlmostEqual(x.min(), -half_width, delta=1e-12)  # center = [0, 0]
        self.assertAlmostEqual(x.max(), half_width, delta=1e-12)
        # The computed p0 and a: the least-squares fit of p^2 = p0^2 (1 - x^2/a^2) to the loaded
        # pairs of contact.csv, the outermost on each side left out, done here with polyfit.
        rows = read_csv(self.directory / "contact.csv")
        loaded = sorted((float(row["x"]), float(row["pressure"])) for row in rows
                        if float(row["pressure"]) > 0.0)[1:-1]
        slope, intercept = np.polyfit([x ** 2 for x, _ in loaded],
                                      [p ** 2 for _, p in loaded], 1)
        fitted_peak, fitted_half_width = math.sqrt(intercept), math.sqrt(-intercept / slope)
        self.assertAlmostEqual(comparison["computed_peak_pressure"], fitted_peak,
                               delta=1e-9 * fitted_peak)
        self.assertAlmostEqual(comparison["computed_half_width"], fitted_half_width,
                               delta=1e-9 * fitted_half_width)
        peak_error, half_width_error = fitted_peak / peak - 1.0, fitted_half_width / half_width - 1
        labels = [text.get_text() for text in axis.get_legend().get_texts()]
        self.assertIn(f"p0 {peak_error:+.2%}, a {half_width_error:+.2%} against Hertz",
                      " ".join(labels))
        # The solution itself: within 2 % of Hertz at the shipped mesh (docs/verification.md).
        self.assertLess(abs(peak_error), 0.02)
        self.assertLess(abs(half_width_error), 0.02)
        self.assertTrue(any("from the computed contact resultant" in line for line in lines))

    def test_explicit_load_of_the_reference_table(self):
        case = self.scratch / "hertz_load.toml"
        text = HERTZ.read_text().replace('kind = "hertz_cylinder"',
                                         'kind = "hertz_cylinder"\nload = 2.5\n'
                                         'contact_modulus = 600.0')
        text = text.replace('"meshes/', f'"{REPOSITORY / "examples" / "meshes"}/')
        case.write_text(text)
        status, stdout, stderr = run(BIN / "robin-plot", "--case", case, self.directory)
        self.assertEqual(status, 0, stderr)
        half_width = math.sqrt(4.0 * 2.5 * 1.0 / (math.pi * 600.0))
        peak = 2.0 * 2.5 / (math.pi * half_width)
        self.assertIn(f"Hertz p0 = {peak:.6g}, a = {half_width:.6g} (P = 2.5 from reference.load)",
                      stdout)


@unittest.skipUnless((BIN / "robin-run").exists(), f"no robin-run in {BIN}: build it first")
class UnconvergedRun(unittest.TestCase):
    def test_iteration_limit_is_plotted_with_the_last_stopping_residual(self):
        with tempfile.TemporaryDirectory() as scratch:
            directory = pathlib.Path(scratch) / "limit"
            status, _, log = run(BIN / "robin-run", REPOSITORY / "examples" / "asymmetric.toml",
                                 "--output", directory, "--max-iterations", "3")
            self.assertEqual(status, 3, log)  # the iteration limit
            history = read_csv(directory / "history.csv")
            self.assertEqual(len(history), 3)
            last = float(history[-1]["stopping_residual"])
            self.assertGreater(last, 1e-8)
            self.assertIn(f"iteration limit reached after 3 iterations (either-sequence "
                          f"stopping, tolerance 1e-08): the stopping test's last value "
                          f"{last:.1e}", log)
            status, stdout, stderr = run(BIN / "robin-plot", directory)
            self.assertEqual(status, 0, stderr)
            self.assertIn(f"history.png: iteration limit reached after 3 iterations: the "
                          f"stopping residual ended at {last:.1e} > tolerance 1e-08", stdout)


@unittest.skipUnless((BIN / "robin-plot").exists(), f"no robin-plot in {BIN}")
class CommandLine(unittest.TestCase):
    def test_help(self):
        status, stdout, _ = run(BIN / "robin-plot", "--help")
        self.assertEqual(status, 0)
        self.assertIn("usage: robin-plot", stdout)
        self.assertIn("Exit status", stdout)

    def test_version_is_the_project_version(self):
        status, stdout, _ = run(BIN / "robin-plot", "--version")
        self.assertEqual(status, 0)
        self.assertEqual(stdout.strip(), f"robin-plot {project_version()}")

    def test_usage_errors_exit_2(self):
        for arguments in ([], ["a", "b"], ["--no-such-option", "a"]):
            status, _, stderr = run(BIN / "robin-plot", *arguments)
            self.assertEqual(status, 2, arguments)
            self.assertIn("usage: robin-plot", stderr)

    def test_directory_without_results_exits_1(self):
        with tempfile.TemporaryDirectory() as directory:
            status, stdout, stderr = run(BIN / "robin-plot", directory)
            self.assertEqual(status, 1)
            self.assertEqual(stdout, "")
            self.assertIn(f"{directory} holds no results of a run: contact.csv is missing",
                          stderr)
            status, _, stderr = run(BIN / "robin-plot", os.path.join(directory, "absent"))
            self.assertEqual(status, 1)
            self.assertIn("no such directory", stderr)


@unittest.skipUnless((BIN / "robin-monolithic").exists(), f"no robin-monolithic in {BIN}")
class MonolithicRun(unittest.TestCase):
    def test_contact_plot_only_and_final_line(self):
        with tempfile.TemporaryDirectory() as scratch:
            directory = pathlib.Path(scratch) / "monolithic"
            status, _, log = run(BIN / "robin-monolithic", HERTZ, "--output", directory)
            self.assertEqual(status, 0, log)
            self.assertRegex(log, r"converged after \d+ MPRGP iterations .*final state: "
                                  r"penetration")
            status, stdout, stderr = run(BIN / "robin-plot", directory)
            self.assertEqual(status, 0, stderr)
            self.assertTrue((directory / "contact.png").exists())
            self.assertFalse((directory / "history.png").exists())
            self.assertIn("contact.png: Hertz p0 =", stdout)

    def test_cylinder_on_a_half_space_matches_the_verification_table(self):
        # docs/verification.md, "Hertz: a real cylinder on non-matching meshes", row h = 0.1
        # (benchmarks/hertz_mortar_study.sh, the same fit): P = 0.83217, a = 0.04332 against
        # 0.04391 (-1.36 %), p0 = 12.2154 against 12.0641 (+1.25 %).
        with tempfile.TemporaryDirectory() as scratch:
            directory = pathlib.Path(scratch) / "cylinder"
            status, _, log = run(BIN / "robin-monolithic",
                                 REPOSITORY / "examples" / "hertz_cylinder.toml",
                                 "--output", directory)
            self.assertEqual(status, 0, log)
            status, stdout, stderr = run(BIN / "robin-plot", directory)
            self.assertEqual(status, 0, stderr)
            numbers = re.search(r"Hertz p0 = (\S+), a = (\S+) \(P = (\S+) from .*computed "
                                r"p0 = (\S+) \((\S+)%\), a = (\S+) \((\S+)%\)", stdout)
            self.assertIsNotNone(numbers, stdout)
            hertz_peak, hertz_half_width, load, peak, peak_error, half_width, half_width_error = (
                float(value) for value in numbers.groups())
            self.assertAlmostEqual(load, 0.83217, delta=1e-5)
            self.assertAlmostEqual(hertz_half_width, 0.04391, delta=1e-5)
            self.assertAlmostEqual(hertz_peak, 12.0641, delta=1e-4)
            self.assertAlmostEqual(half_width, 0.04332, delta=1e-5)
            self.assertAlmostEqual(peak, 12.2154, delta=1e-4)
            self.assertAlmostEqual(half_width_error, -1.36, delta=0.01)
            self.assertAlmostEqual(peak_error, 1.25, delta=0.01)


# --- A contact graph: result files written by the test ----------------------------------------

CONTACT_HEADER = ["pair", "x", "y", "nx", "ny", "gap0", "un1", "un2", "lambda1", "lambda2",
                  "pressure"]
# Interface 1: 'lower' (its boundary 'top') under 'middle' ('bottom') along y = 0, five nodes
# 0.25 apart; interface 2: 'middle' ('right') beside 'side-block' ('left') along x = 1, four
# nodes from y = 0 to y = 0.6 (0.2 apart): vertical, so drawn over y.
INTERFACE1 = {"x": [0.0, 0.25, 0.5, 0.75, 1.0], "y": [0.0] * 5, "nx": [0.0] * 5, "ny": [1.0] * 5,
              "gap0": [0.0, 0.0, 0.0, 0.0, 0.0], "un1": [0.001, 0.002, 0.003, 0.002, 0.0005],
              "un2": [-0.001, -0.002, -0.003, -0.002, 0.0005],
              "pressure": [0.0, 2.0, 3.5, 2.0, 0.0]}
INTERFACE2 = {"x": [1.0] * 4, "y": [0.0, 0.2, 0.4, 0.6], "nx": [1.0] * 4, "ny": [0.0] * 4,
              "gap0": [0.01, 0.01, 0.01, 0.01], "un1": [0.004, 0.006, 0.002, 0.001],
              "un2": [0.006, 0.004, 0.002, 0.001], "pressure": [1.25, 0.75, 0.0, 0.0]}
WEIGHTS = (0.25, 0.2)  # the nodal lengths: lambda = pressure * weight on both sides


def write_contact_file(path, values, weight):
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(CONTACT_HEADER)
        for pair in range(len(values["x"])):
            force = values["pressure"][pair] * weight
            writer.writerow([pair] + [repr(values[name][pair]) for name in CONTACT_HEADER[1:8]]
                            + [repr(force), repr(force), repr(values["pressure"][pair])])


def graph_summary(files=("contact_1_lower_middle.csv", "contact_2_middle_side-block.csv")):
    interfaces = []
    for values, weight, bodies, boundaries, file in (
            (INTERFACE1, WEIGHTS[0], ["lower", "middle"], ["top", "bottom"], files[0]),
            (INTERFACE2, WEIGHTS[1], ["middle", "side-block"], ["right", "left"], files[1])):
        pressures = values["pressure"]
        interfaces.append({
            "bodies": bodies, "boundaries": boundaries,
            "contact_discretization": "node-to-node, %d pairs" % len(pressures),
            "contact_pairs": len(pressures), "active_pairs": sum(p > 0 for p in pressures),
            "largest_pressure": max(pressures), "excluded_pairs": [], "initial_overlap": "",
            "contact_force_resultant": [0.0, sum(pressures) * weight], "file": file})
    return {"status": "converged", "converged": True, "title": "three bodies",
            "algorithm": "robin", "stopping": "either-sequence", "tolerance": 1e-8,
            "iterations": 4, "completed_by_sequence": 2,
            "final_residuals": {"obstacle_change": 4e-9, "penetration": 0.0,
                                "force_balance": 0.0, "complementarity": 2e-9,
                                "correction": 0.0, "force_error_estimate": 6e-9},
            "contact_pairs": 9, "contact_force_resultant": None, "interfaces": interfaces}


# history.csv of three bodies: activeN and qp_iterationsN per body, two obstacle sequences.
HISTORY_HEADER = ("iteration,obstacle_change,penetration,force_balance,complementarity,"
                  "correction,active1,active2,active3,qp_iterations1,qp_iterations2,"
                  "qp_iterations3,seconds,sequence1,sequence2,stopping_residual,tolerance")
HISTORY_ROWS = [
    "1,0.5,0.1,0.3,0.02,0.4,3,5,2,12,15,9,0.01,0.2,0.1,0.1,1e-08",
    "2,0.01,0.002,0.004,0.0003,0.005,3,5,2,8,9,7,0.01,0.003,0.001,0.001,1e-08",
    "3,1e-05,2e-06,3e-06,0,4e-06,3,5,2,4,5,3,0.01,2e-06,5e-07,5e-07,1e-08",
    "4,1e-08,0,2e-08,3e-09,1e-08,3,5,2,2,2,2,0.01,8e-09,6e-09,6e-09,1e-08"]


def write_graph_directory(directory, summary=True, history=True):
    directory.mkdir(parents=True)
    write_contact_file(directory / "contact_1_lower_middle.csv", INTERFACE1, WEIGHTS[0])
    write_contact_file(directory / "contact_2_middle_side-block.csv", INTERFACE2, WEIGHTS[1])
    if summary:
        (directory / "summary.json").write_text(json.dumps(graph_summary(), indent=2))
    if history:
        (directory / "history.csv").write_text("\n".join([HISTORY_HEADER] + HISTORY_ROWS) + "\n")
    return directory


def final_gap(values):
    return [d - u1 - u2 for d, u1, u2 in zip(values["gap0"], values["un1"], values["un2"])]


class ContactGraphDirectory(unittest.TestCase):
    """robin-plot on result directories of three bodies and two interfaces, written here."""

    def setUp(self):
        self.scratch = pathlib.Path(tempfile.mkdtemp(prefix="robin-plot-graph-"))
        self.tool = plot_executable()
        self.plot = load_plot_module(self.tool)

    def tearDown(self):
        shutil.rmtree(self.scratch, ignore_errors=True)

    def test_robin_plot_draws_every_interface(self):
        directory = write_graph_directory(self.scratch / "graph")
        status, stdout, stderr = run(self.tool, directory)
        self.assertEqual(status, 0, stderr)
        for name in ("contact.png", "history.png"):
            with open(directory / name, "rb") as handle:
                self.assertEqual(handle.read(8), b"\x89PNG\r\n\x1a\n", name)
        self.assertIn("robin-plot: contact.png: interface 1: lower / middle (top / bottom): "
                      "5 contact rows, 3 active, largest pressure 3.5 "
                      "(contact_1_lower_middle.csv)", stdout)
        self.assertIn("robin-plot: contact.png: interface 2: middle / side-block (right / left): "
                      "4 contact rows, 2 active, largest pressure 1.25 "
                      "(contact_2_middle_side-block.csv)", stdout)
        self.assertIn("history.png: converged after 4 iterations: obstacle sequence 2 reached "
                      "6.0e-09 < tolerance 1e-08", stdout)
        self.assertNotIn("Hertz", stdout)

    def test_one_row_of_panels_per_interface_with_its_numbers(self):
        directory = write_graph_directory(self.scratch / "graph")
        summary = json.loads((directory / "summary.json").read_text())
        tables = self.plot.contact_tables(directory, summary)
        self.assertEqual([table["file"] for table in tables],
                         ["contact_1_lower_middle.csv", "contact_2_middle_side-block.csv"])
        figure, lines = self.plot.interfaces_figure(tables, summary)
        self.assertEqual(len(figure.axes), 4)  # (pressure, gap) per interface
        pressure1, gap1, pressure2, gap2 = figure.axes
        self.assertEqual(pressure1.get_title(), "interface 1: lower / middle (top / bottom): "
                                                "largest pressure 3.5, 3 of 5 rows active")
        self.assertEqual(pressure2.get_title(), "interface 2: middle / side-block (right / "
                                                "left): largest pressure 1.25, 2 of 4 rows active")
        self.assertIn("interface 2: middle / side-block (right / left): final gap",
                      gap2.get_title())
        curve = pressure1.get_lines()[0]
        self.assertEqual(list(curve.get_xdata()), INTERFACE1["x"])
        self.assertEqual(list(curve.get_ydata()), INTERFACE1["pressure"])
        self.assertEqual(pressure1.get_xlabel(), "x")
        np.testing.assert_allclose(gap1.get_lines()[0].get_ydata(), final_gap(INTERFACE1),
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(gap1.get_lines()[0].get_ydata(), [0.0, 0.0, 0.0, 0.0, -0.001],
                                   atol=1e-15)
        # The vertical interface (x = 1) over y.
        curve = pressure2.get_lines()[0]
        self.assertEqual(list(curve.get_xdata()), INTERFACE2["y"])
        self.assertEqual(list(curve.get_ydata()), INTERFACE2["pressure"])
        self.assertEqual(pressure2.get_xlabel(), "y")
        # A curved interface over the arc length from its first row: (0, 0), (0.3, 0.4),
        # (0.3, 1.4): 0, 0.5, 1.5.
        curved = dict(tables[1], columns=dict(tables[1]["columns"], x=[0.0, 0.3, 0.3, 0.3],
                                              y=[0.0, 0.4, 1.4, 1.4]))
        figure, _ = self.plot.interfaces_figure([tables[0], curved], summary)
        np.testing.assert_allclose(figure.axes[2].get_lines()[0].get_xdata(),
                                   [0.0, 0.5, 1.5, 1.5], atol=1e-15)
        self.assertEqual(figure.axes[2].get_xlabel(), "arc length along the interface")
        np.testing.assert_allclose(gap2.get_lines()[0].get_ydata(), [0.0, 0.0, 0.006, 0.008],
                                   atol=1e-15)
        self.assertEqual(figure._suptitle.get_text(),
                         "contact pressure and final gap on 2 interfaces (three bodies)")
        self.assertEqual(len(lines), 2)

    def test_history_of_three_bodies(self):
        directory = write_graph_directory(self.scratch / "graph")
        summary = json.loads((directory / "summary.json").read_text())
        columns = self.plot.read_columns(directory / "history.csv")
        self.assertEqual(self.plot.sequence_numbers(columns), [1, 2])
        figure, lines = self.plot.history_figure(columns, summary)
        axis = figure.axes[0]
        by_label = {line.get_label(): line for line in axis.get_lines()}
        rows = [row.split(",") for row in HISTORY_ROWS]
        header = HISTORY_HEADER.split(",")
        for k in (1, 2):
            label = (f"obstacle sequence {k}: largest residual of its complete state")
            expected = [float(row[header.index(f"sequence{k}")]) for row in rows]
            self.assertEqual(list(by_label[label].get_ydata()), expected)
        # A zero residual is drawn at 1e-17 on the logarithmic axis.
        self.assertEqual(list(by_label["joint: penetration"].get_ydata()),
                         [0.1, 0.002, 2e-06, 1e-17])
        self.assertEqual(list(by_label["joint: obstacle change"].get_xdata()), [1, 2, 3, 4])
        self.assertEqual(list(by_label["tolerance 1e-08"].get_ydata()), [1e-8, 1e-8])
        self.assertIn("accepted: obstacle sequence 2, largest residual 6.0e-09", by_label)
        self.assertEqual(list(by_label["accepted: obstacle sequence 2, largest residual "
                                       "6.0e-09"].get_ydata()), [6e-9])
        self.assertIn("converged after 4 iterations", axis.get_title())
        self.assertEqual(len(lines), 1)

    def test_without_summary_the_files_on_disk_are_the_interfaces(self):
        directory = write_graph_directory(self.scratch / "bare", summary=False, history=False)
        status, stdout, stderr = run(self.tool, directory)
        self.assertEqual(status, 0, stderr)
        self.assertIn("contact.png: interface 1: contact_1_lower_middle.csv: 5 contact rows, "
                      "3 active, largest pressure 3.5", stdout)
        self.assertIn("contact.png: interface 2: contact_2_middle_side-block.csv: 4 contact "
                      "rows, 2 active, largest pressure 1.25", stdout)
        self.assertTrue((directory / "contact.png").exists())
        self.assertFalse((directory / "history.png").exists())

    def test_a_missing_contact_file_is_named(self):
        directory = write_graph_directory(self.scratch / "missing")
        (directory / "contact_2_middle_side-block.csv").unlink()
        status, stdout, stderr = run(self.tool, directory)
        self.assertEqual(status, 1)
        self.assertEqual(stdout, "")
        self.assertIn(f"{directory}: summary.json lists 2 contact interfaces, but "
                      "contact_2_middle_side-block.csv (interface 2: middle / side-block) is "
                      "missing", stderr)
        self.assertFalse((directory / "contact.png").exists())
        # Without summary.json: the gap in the numbering of the files on disk.
        (directory / "summary.json").unlink()
        write_contact_file(directory / "contact_3_lower_side-block.csv", INTERFACE2, WEIGHTS[1])
        status, _, stderr = run(self.tool, directory)
        self.assertEqual(status, 1)
        self.assertIn("the contact file of interface 2 (contact_2_<a>_<b>.csv) is missing beside "
                      "contact_1_lower_middle.csv, contact_3_lower_side-block.csv", stderr)

    def test_a_failed_run_without_contact_files(self):
        directory = self.scratch / "failed"
        directory.mkdir()
        (directory / "summary.json").write_text(json.dumps(
            {"status": "failed", "message": "server 3 did not answer", "interfaces": []}))
        status, _, stderr = run(self.tool, directory)
        self.assertEqual(status, 1)
        self.assertIn("contact.csv is missing, and so are the contact_<k>_<a>_<b>.csv files",
                      stderr)
        self.assertIn("summary.json is there: the run failed before writing its results", stderr)

    def test_reference_table_is_not_drawn_over_several_interfaces(self):
        directory = write_graph_directory(self.scratch / "graph")
        case = self.scratch / "case.toml"
        case.write_text('[reference]\nkind = "hertz_cylinder"\nradius = 1.0\n')
        status, stdout, stderr = run(self.tool, "--case", case, directory)
        self.assertEqual(status, 0, stderr)
        self.assertIn("contact.png: the case's [reference] table describes one contact; it is "
                      "not drawn for the 2 interfaces", stdout)

    def test_two_body_layout_keeps_its_figure(self):
        # A two-body run: contact.csv and an "interfaces" array of one entry naming it.
        directory = self.scratch / "two"
        directory.mkdir()
        write_contact_file(directory / "contact.csv", INTERFACE1, WEIGHTS[0])
        summary = graph_summary(files=("contact.csv", "unused"))
        summary["interfaces"] = summary["interfaces"][:1]
        summary["contact_force_resultant"] = summary["interfaces"][0]["contact_force_resultant"]
        (directory / "summary.json").write_text(json.dumps(summary))
        status, stdout, stderr = run(self.tool, directory)
        self.assertEqual(status, 0, stderr)
        self.assertIn("robin-plot: contact.png: 5 contact rows, largest pressure 3.5", stdout)
        tables = self.plot.contact_tables(directory, summary)
        self.assertEqual(len(tables), 1)
        figure, _, comparison = self.plot.contact_figure(tables[0]["columns"], summary, None)
        self.assertIsNone(comparison)
        pressure_axis, gap_axis = figure.axes
        self.assertEqual(pressure_axis.get_ylabel(), "contact pressure (force / length)")
        self.assertEqual(list(pressure_axis.get_lines()[0].get_ydata()), INTERFACE1["pressure"])
        self.assertEqual(gap_axis.get_ylabel(), "final normal gap d - u1_N - u2_N")


if __name__ == "__main__":
    unittest.main()
