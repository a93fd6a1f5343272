#!/usr/bin/python3
"""example_iterations.py [--build DIR] [--output DIR]: outer iterations of every shipped example.

For each case of examples/ runs robin-run with the default method (IQN-ILS per body,
either-sequence stopping) and with the variants below, and robin-monolithic; prints a Markdown
table of the iteration counts (with the obstacle sequence that was accepted, or "joint") and the
largest relative difference to the monolithic reference in the contact force lambda and the
normal traces u_N (contact.csv, max norm relative to the monolithic maximum). The figures that
docs quote are made with this script (docs/iteration-study.md, "The shipped examples").
Not a test: it asserts nothing.
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

from benchmark_support import read_csv_rows, table_rule, tool_directory

REPOSITORY = pathlib.Path(__file__).resolve().parents[1]
CASES = ["two_blocks", "two_blocks_partial", "asymmetric", "hertz", "hertz_cylinder",
         "non_matching_blocks"]
METHODS = [
    ("iqn-ils (default)", []),
    ("aitken", ["--acceleration", "aitken"]),
    ("none, δ = ½, either-sequence", ["--acceleration", "none", "--relaxation", "0.5"]),
    ("none, δ = ½, joint (the paper)",
     ["--acceleration", "none", "--relaxation", "0.5", "--stopping", "joint"]),
    ("none, δ = 0.02, joint",
     ["--acceleration", "none", "--relaxation", "0.02", "--stopping", "joint",
      "--max-iterations", "5000"]),
]


def read_contact(path):
    rows = read_csv_rows(path)
    return {key: [float(row[key]) for row in rows] for key in ("un1", "un2", "lambda1", "lambda2")}


def relative_difference(run, reference, keys):
    scale = max(max(abs(value) for value in reference[key]) for key in keys) or 1.0
    return max(max(abs(a - b) for a, b in zip(run[key], reference[key])) for key in keys) / scale


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=str(REPOSITORY / "build"), help="build directory")
    parser.add_argument("--output", help="where the result directories go (default: temporary)")
    parser.add_argument("--tolerance", help="--tolerance of every run (default: the case's)")
    options = parser.parse_args()
    tools = tool_directory(options.build)
    scratch = pathlib.Path(options.output or tempfile.mkdtemp(prefix="example-iterations-"))
    extra = ["--tolerance", options.tolerance] if options.tolerance else []
    print("| case | pairs | " + " | ".join(name for name, _ in METHODS) +
          " | default vs monolithic: λ, u_N |")
    print(table_rule(len(METHODS) + 3))
    for case in CASES:
        case_file = REPOSITORY / "examples" / f"{case}.toml"
        monolithic = scratch / f"{case}-monolithic"
        subprocess.run([tools / "robin-monolithic", case_file, "--output", monolithic, "--overwrite"],
                       check=True, capture_output=True)
        reference = read_contact(monolithic / "contact.csv")
        cells, difference, pairs = [], "", ""
        for index, (name, arguments) in enumerate(METHODS):
            directory = scratch / f"{case}-{index}"
            subprocess.run([tools / "robin-run", case_file, "--output", directory, "--overwrite"] + arguments +
                           extra, check=False, capture_output=True)
            summary = json.loads((directory / "summary.json").read_text())
            pairs = summary.get("contact_pairs", pairs)
            if summary.get("status") == "converged":
                sequence = summary.get("completed_by_sequence", 0)
                accepted = f"sequence {sequence}" if sequence else "joint"
                cells.append(f"{summary['iterations']} ({accepted})")
            else:
                cells.append(f"{summary.get('status', 'failed')} ({summary.get('iterations', '-')})")
            if index == 0:
                run = read_contact(directory / "contact.csv")
                difference = (f"{relative_difference(run, reference, ['lambda1', 'lambda2']):.1e}"
                              f", {relative_difference(run, reference, ['un1', 'un2']):.1e}")
        print(f"| {case} | {pairs} | " + " | ".join(cells) + f" | {difference} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
