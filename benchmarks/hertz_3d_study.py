#!/usr/bin/python3
"""Hertz point contact in 3D (examples/hertz_3d.toml, a quarter model of a sphere of R = 1 on a
flat): the contact radius a and the peak pressure p0 of the solution against Hertz's over several
mesh sizes, with the observed order of convergence (docs/verification.md, "Hertz: a sphere on a
flat").

  a and p0 of the solution: least-squares fit of p^2 = p0^2 - (p0^2 / a^2) r^2 to the pressures
  lambda_j / m_j of the loaded rows of contact.csv, then again over those within r < 0.8 a (the
  procedure of the test SolidHertz);
  Hertz: a_H = (3 P R / (4 E*))^(1/3), p0_H = 3 P / (2 pi a_H^2), P four times the quarter's
  contact resultant, R = 1, E* = E / (2 (1 - nu^2)) for the identical bodies.

Usage: benchmarks/hertz_3d_study.py [--build DIR] [--tool robin-monolithic|robin-run] [h ...]
"""

import argparse
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmark_support  # noqa: E402

REPOSITORY = Path(__file__).resolve().parent.parent
YOUNG, POISSON, SPHERE_RADIUS = 1000.0, 0.3, 1.0


def fit(columns, reach):
    """(p0, a, rows) of the fit over the loaded rows within `reach` of the axis."""
    x, y, pressure = (numpy.array(columns[name]) for name in ("x", "y", "pressure"))
    chosen = (pressure > 0.0) & (x * x + y * y < reach * reach)
    matrix = numpy.c_[numpy.ones(chosen.sum()), -(x[chosen] ** 2 + y[chosen] ** 2)]
    coefficients = numpy.linalg.lstsq(matrix, pressure[chosen] ** 2, rcond=None)[0]
    return math.sqrt(coefficients[0]), math.sqrt(coefficients[0] / coefficients[1]), chosen.sum()


def study(contact_file):
    rows = benchmark_support.read_csv_rows(contact_file)
    columns = {name: [float(row[name]) for row in rows] for name in rows[0]}
    load = 4.0 * sum(columns["lambda1"])
    _, radius, _ = fit(columns, math.inf)
    peak, radius, _ = fit(columns, 0.8 * radius)
    modulus = YOUNG / (2.0 * (1.0 - POISSON ** 2))
    hertz_radius = (3.0 * load * SPHERE_RADIUS / (4.0 * modulus)) ** (1.0 / 3.0)
    hertz_peak = 3.0 * load / (2.0 * math.pi * hertz_radius ** 2)
    loaded = sum(1 for value in columns["pressure"] if value > 0.0)
    return {"rows": len(rows), "loaded": loaded, "P": load, "a": radius, "a_H": hertz_radius,
            "p0": peak, "p0_H": hertz_peak, "error_a": abs(radius / hertz_radius - 1.0),
            "error_p0": abs(peak / hertz_peak - 1.0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sizes", nargs="*", type=float, default=[0.08, 0.04, 0.02, 0.01])
    parser.add_argument("--build", default=str(REPOSITORY / "build"))
    parser.add_argument("--tool", default="robin-monolithic", choices=["robin-monolithic", "robin-run"])
    arguments = parser.parse_args()
    tool = Path(arguments.build) / "bin" / arguments.tool
    benchmark_support.print_machine_header()
    header = ["h", "unknowns (flat body)", "rows", "loaded", "P", "a", "a (Hertz)", "error a", "p0",
              "p0 (Hertz)", "error p0", "order a", "order p0"]
    print(benchmark_support.table_row(header))
    print(benchmark_support.table_rule(len(header)))
    previous = None
    with tempfile.TemporaryDirectory() as scratch:
        for size in arguments.sizes:
            output = Path(scratch) / f"h_{size}"
            command = [str(tool), str(REPOSITORY / "examples" / "hertz_3d.toml"), "--output",
                       str(output), "--quiet", f"--set=body[1].mesh_size={size}",
                       f"--set=body[2].mesh_size={size}"]
            subprocess.run(command, check=True)
            result = study(output / "contact.csv")
            summary = (output / "summary.json").read_text()
            dofs = summary.split('"dofs":', 1)[1].split(",", 1)[0].strip() if '"dofs":' in summary else ""
            orders = ["", ""]
            if previous is not None:
                ratio = math.log(previous["h"] / size)
                orders = ["%.2f" % (math.log(previous["error_a"] / result["error_a"]) / ratio),
                          "%.2f" % (math.log(previous["error_p0"] / result["error_p0"]) / ratio)]
            print(benchmark_support.table_row(
                ["%g" % size, dofs, result["rows"], result["loaded"], "%.5f" % result["P"],
                 "%.5f" % result["a"], "%.5f" % result["a_H"], "%.2f %%" % (100 * result["error_a"]),
                 "%.4f" % result["p0"], "%.4f" % result["p0_H"],
                 "%.2f %%" % (100 * result["error_p0"])] + orders))
            previous = dict(result, h=size)


if __name__ == "__main__":
    main()
