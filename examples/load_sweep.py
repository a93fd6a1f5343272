#!/usr/bin/python3
"""A load sweep of the contact patch test (non_matching_blocks.toml) from Python.

Runs the coupled Robin solve (robin-run) once per top displacement d, each with
--set body[2].dirichlet[1].y=-d in a fresh result directory, and compares the contact pressure
with its exact value p = d / (H1 (1 - nu1^2) / E1 + H2 (1 - nu2^2) / E2) (the case file's
comment): the pressure is uniform along the contact and linear in d. Prints one line per load
and exits 1 if a pressure is off by more than 1e-6 relative.

    /usr/bin/python3 examples/load_sweep.py [--bin build/bin] [--keep DIR]

docs/scripting.md describes the package python/robin_contact it uses.
"""

import argparse
import pathlib
import shutil
import sys
import tempfile

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))

import robin_contact  # noqa: E402

LOADS = [0.0025, 0.005, 0.01, 0.02]  # top displacements d (length)


def exact_pressure(displacement):
    """The patch test's uniform pressure: H1 = 0.5, nu1 = 0.3, E1 = 1000 (lower block),
    H2 = 0.4, nu2 = 0.25, E2 = 400 (upper block)."""
    return displacement / (0.5 * (1 - 0.3 ** 2) / 1000.0 + 0.4 * (1 - 0.25 ** 2) / 400.0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", help="directory of robin-run (default: build/bin)")
    parser.add_argument("--keep", metavar="DIR",
                        help="keep the result directories in DIR (one per load)")
    options = parser.parse_args()
    root = pathlib.Path(options.keep) if options.keep else pathlib.Path(
        tempfile.mkdtemp(prefix="robin-load-sweep-"))
    root.mkdir(parents=True, exist_ok=True)
    worst = 0.0
    print("%10s %14s %14s %10s %11s %12s" % ("d", "mean p", "exact p", "rel. err", "iterations",
                                             "max |u_y|"))
    try:
        for load in LOADS:
            results = robin_contact.run_case(
                HERE / "non_matching_blocks.toml",
                overrides={"body[2].dirichlet[1].y": -load},
                output=root / ("d=%g" % load), bin_directory=options.bin)
            pressure = results.contact["pressure"]
            exact = exact_pressure(load)
            error = np.max(np.abs(pressure - exact)) / exact
            worst = max(worst, error)
            lower = results.bodies["lower"].point_data["displacement"]
            print("%10g %14.8f %14.8f %10.1e %11d %12.4e" % (
                load, np.mean(pressure), exact, error, results.summary["iterations"],
                np.max(np.abs(lower[:, 1]))))
    finally:
        if not options.keep:
            shutil.rmtree(root, ignore_errors=True)
    print("largest relative error of the pressure: %.1e" % worst)
    return 0 if worst <= 1e-6 else 1


if __name__ == "__main__":
    sys.exit(main())
