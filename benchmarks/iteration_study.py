#!/usr/bin/python3
"""Iteration study of the coordinator's algorithm family (docs/iteration-study.md).

Runs every method on a grid of cases and mesh sizes h, h/2, h/4, h/8 with the real service
(build/bin/robin-run: two robin-subdomain processes and the coordinator over ZeroMQ), compares
every converged answer with the monolithic reference (build/bin/robin-monolithic), and writes

  OUTPUT/study.json                 every run: case, level, method, status, iterations, error
  OUTPUT/runs/...                   the result directories of every run
  DOCS/iteration-study.md           tables (with --docs DOCS)
  DOCS/images/iteration-study-*.png iterations vs 1/h per method, one plot per case, and the
                                    residual histories on the finest mesh

Usage:  /usr/bin/python3 benchmarks/iteration_study.py [--build build] [--output DIR]
            [--levels 4] [--docs docs] [--cases symmetric,asymmetric,...]
"""

import argparse
import json
import os
import platform
import re
import sys
import time

from benchmark_support import read_csv_rows, run_timed, table_row, table_rule

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")
TOLERANCE = 1e-8
MAX_ITERATIONS = 1000


def case_grid():
    """(name, template, description, young modulus factors for body 1 and body 2, coarsest
    mesh size h or None for the template's)."""
    return [
        ("symmetric", "two_blocks.toml", "two equal blocks, full contact", (1, 1), None),
        ("asymmetric", "asymmetric.toml",
         "cantilever (E = 1000, clamped at one end) on a block (E = 100, clamped below)", (1, 1),
         None),
        ("ratio10-stiff-lower", "two_blocks_partial.toml",
         "partial contact, lower block 10x stiffer", (10, 1), 0.1),
        ("ratio10-stiff-upper", "two_blocks_partial.toml",
         "partial contact, upper block 10x stiffer", (1, 10), 0.1),
        ("ratio100-stiff-lower", "two_blocks_partial.toml",
         "partial contact, lower block 100x stiffer", (100, 1), 0.1),
        ("ratio100-stiff-upper", "two_blocks_partial.toml",
         "partial contact, upper block 100x stiffer", (1, 100), 0.1),
        ("hertz", "hertz.toml", "Hertz: cylinder on a flat, displacement-driven", (1, 1), 0.1),
    ]


def methods():
    """(name, extra robin-run arguments). ALPHA stands for the constant alpha of
    robin-constant, scaled with the mesh (alpha = h / E_max) so that it stays below the
    stability limit of the shortest wavelength on every mesh."""
    return [
        ("robin iqn-ils (default)", []),
        ("robin aitken", ["--acceleration", "aitken"]),
        ("robin plain delta=0.5", ["--acceleration", "none", "--relaxation", "0.5",
                                   "--stopping", "joint"]),
        ("robin-constant", ["--algorithm", "robin-constant", "--alpha", "ALPHA"]),
        ("dirichlet-neumann", ["--algorithm", "dirichlet-neumann"]),
        ("neumann-neumann", ["--algorithm", "neumann-neumann"]),
    ]


def write_case(template, directory, level, young_factors, base_size=None):
    """The template with every mesh_size (or base_size) divided by 2^level, the Young moduli
    multiplied by the factors (body order) and absolute mesh paths. Returns (path, mesh size,
    max E)."""
    with open(os.path.join(EXAMPLES, template)) as file:
        text = file.read()
    sizes = [base_size or float(value)
             for value in re.findall(r"^mesh_size\s*=\s*([0-9.eE+-]+)", text, re.M)]
    text = re.sub(r"^(mesh_size\s*=\s*)([0-9.eE+-]+)",
                  lambda match: match.group(1) + repr(
                      (base_size or float(match.group(2))) / 2 ** level), text, flags=re.M)
    text = re.sub(r'^(mesh\s*=\s*")([^"]+)"',
                  lambda match: match.group(1) + os.path.abspath(
                      os.path.join(EXAMPLES, match.group(2))) + '"', text, flags=re.M)
    youngs = []
    counter = iter(young_factors)

    def scale_young(match):
        value = float(match.group(2)) * next(counter)
        youngs.append(value)
        return match.group(1) + repr(value)

    text = re.sub(r"^(young\s*=\s*)([0-9.eE+-]+)", scale_young, text, flags=re.M)
    os.makedirs(directory, exist_ok=True)
    path = os.path.join(directory, "case.toml")
    with open(path, "w") as file:
        file.write(text)
    return path, min(sizes) / 2 ** level, max(youngs)


def reference_case(case_path):
    """The case with the contact QP solved to 1e-14 instead of the default 1e-12: the
    monolithic reference's own error (QP tolerance times the condition of the active compliance)
    reaches 2e-8 on the finest asymmetric mesh with the default, which would blur the force
    errors of the coupled runs. The templates have no [solver] table."""
    path = os.path.join(os.path.dirname(case_path), "reference.toml")
    with open(case_path) as source, open(path, "w") as target:
        target.write(source.read() + "\n[solver]\nqp_tolerance = 1e-14\n")
    return path


def read_contact_forces(directory):
    rows = read_csv_rows(os.path.join(directory, "contact.csv"))
    return [float(row["lambda1"]) for row in rows], [float(row["lambda2"]) for row in rows]


def relative_force_error(run_directory, reference):
    force1, force2 = read_contact_forces(run_directory)
    scale = max(abs(value) for value in reference) or 1.0
    return max(max(abs(a - r), abs(b - r)) for a, b, r in zip(force1, force2, reference)) / scale


def run(command, log_path):
    """(exit status, wall seconds) of command, its output in log_path; stdin inherited."""
    return run_timed(command, log_path, stdin=None)


def read_history(directory):
    path = os.path.join(directory, "history.csv")
    if not os.path.exists(path):
        return []
    rows = read_csv_rows(path)
    keys = ["obstacle_change", "penetration", "force_balance", "complementarity", "correction"]
    history = []
    for row in rows:
        joint = max(float(row[key]) for key in keys)
        sequences = [float(row[key]) for key in ("sequence1", "sequence2") if row.get(key)]
        history.append(min([joint] + sequences))
    return history


def study_case(build, output, case, levels, reuse):
    """Every method on every level of `case`. With `reuse`, a run whose summary.json exists is
    read, not repeated (to resume an interrupted study)."""
    name, template, description, factors, base_size = case
    results = []
    for level in range(levels):
        directory = os.path.join(output, "runs", name, "level%d" % level)
        case_path, size, young_max = write_case(template, directory, level, factors, base_size)
        monolithic_dir = os.path.join(directory, "monolithic")
        code = 0
        if not (reuse and os.path.exists(os.path.join(monolithic_dir, "summary.json"))):
            code, _ = run([os.path.join(build, "bin", "robin-monolithic"),
                           reference_case(case_path), "--output", monolithic_dir, "--overwrite"],
                          os.path.join(directory, "monolithic.log"))
        if code != 0:
            sys.exit("robin-monolithic failed on %s level %d (see %s)" % (name, level, directory))
        reference, _ = read_contact_forces(monolithic_dir)
        with open(os.path.join(monolithic_dir, "summary.json")) as file:
            dofs = sum(body["dofs"] for body in json.load(file)["bodies"])
        for method, arguments in methods():
            arguments = [repr(size / young_max) if a == "ALPHA" else a for a in arguments]
            slug = re.sub(r"[^a-z0-9]+", "-", method.lower()).strip("-")
            run_dir = os.path.join(directory, slug)
            command = [os.path.join(build, "bin", "robin-run"), case_path, "--output", run_dir, "--overwrite",
                       "--tolerance", repr(TOLERANCE), "--max-iterations", str(MAX_ITERATIONS),
                       "--log-level", "warn"] + arguments
            code, seconds = 0, None
            if not (reuse and os.path.exists(os.path.join(run_dir, "summary.json"))):
                code, seconds = run(command, os.path.join(directory, slug + ".log"))
            record = {"case": name, "description": description, "level": level, "h": size,
                      "dofs": dofs, "method": method, "exit_code": code, "seconds": seconds}
            summary_path = os.path.join(run_dir, "summary.json")
            if os.path.exists(summary_path):
                with open(summary_path) as file:
                    summary = json.load(file)
                record.update(status=summary["status"], iterations=summary["iterations"],
                              algorithm=summary.get("algorithm", ""))
                if summary["converged"]:
                    record["force_error"] = relative_force_error(run_dir, reference)
            else:
                record.update(status="failed (exit %d)" % code, iterations=None)
            record["history"] = read_history(run_dir)
            results.append(record)
            print("%-22s h=%-8.4g %-26s %-24s %s" % (name, size, method, record["status"],
                                                     record.get("iterations")), flush=True)
    return results


def fixed_delta_scan(build, output, case, deltas, reuse, stopping):
    """Iterations of the plain iteration with one delta for both bodies on the coarsest mesh,
    with `stopping` "either-sequence" (the default, as the accelerated runs) or "joint" (the
    paper's test: both obstacle sequences)."""
    name, template, _, factors, base_size = case
    directory = os.path.join(output, "runs", name,
                             "delta-scan" + ("" if stopping == "either-sequence" else "-joint"))
    case_path, _, _ = write_case(template, directory, 0, factors, base_size)
    counts = {}
    for delta in deltas:
        run_dir = os.path.join(directory, "delta-%g" % delta)
        if not (reuse and os.path.exists(os.path.join(run_dir, "summary.json"))):
            run([os.path.join(build, "bin", "robin-run"), case_path, "--output", run_dir, "--overwrite",
                 "--tolerance", repr(TOLERANCE), "--max-iterations", "5000", "--acceleration",
                 "none", "--relaxation", repr(delta), "--stopping", stopping,
                 "--log-level", "warn"],
                os.path.join(directory, "delta-%g.log" % delta))
        with open(os.path.join(run_dir, "summary.json")) as file:
            summary = json.load(file)
        counts[delta] = summary["iterations"] if summary["converged"] else None
        print("%-22s delta=%-6g %-15s %s" % (name, delta, stopping, counts[delta]), flush=True)
    return counts


def plot(results, docs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    images = os.path.join(docs, "images")
    os.makedirs(images, exist_ok=True)
    cases = sorted({record["case"] for record in results}, key=[c[0] for c in case_grid()].index)
    method_names = [m[0] for m in methods()]
    written = []
    for case in cases:
        figure, (left, right) = pyplot.subplots(1, 2, figsize=(12, 4.5))
        finest = max(record["level"] for record in results if record["case"] == case)
        for color, method in enumerate(method_names):
            rows = [r for r in results if r["case"] == case and r["method"] == method]
            points = [(1.0 / r["h"], r["iterations"]) for r in rows
                      if r.get("status") == "converged"]
            if points:
                left.plot(*zip(*points), marker="o", label=method, color="C%d" % color)
            for r in rows:
                if r["level"] == finest and r["history"]:
                    right.semilogy(range(1, len(r["history"]) + 1), r["history"], label=method,
                                   color="C%d" % color)
        left.set_xscale("log", base=2)
        left.set_yscale("log")
        left.set_xlabel("1/h")
        left.set_ylabel("outer iterations to 1e-8")
        left.set_title("%s: iterations vs mesh size" % case)
        left.grid(True, which="both", alpha=0.3)
        left.legend(fontsize=8)
        right.axhline(TOLERANCE, color="gray", linestyle=":")
        right.set_xlabel("iteration")
        right.set_ylabel("largest scaled residual")
        right.set_title("%s: residual history, finest mesh" % case)
        right.grid(True, which="both", alpha=0.3)
        right.legend(fontsize=8)
        figure.tight_layout()
        file_name = "iteration-study-%s.png" % case
        figure.savefig(os.path.join(images, file_name), dpi=100)
        pyplot.close(figure)
        written.append(file_name)
    return written


def write_tables(results, scans, path):
    """Markdown tables: iterations per method and mesh for every case, the largest force error
    against the monolithic reference, and the fixed-delta scans."""
    lines = []
    for case in [c[0] for c in case_grid()]:
        rows = [r for r in results if r["case"] == case]
        if not rows:
            continue
        levels = sorted({r["level"] for r in rows})
        header = ["method"] + ["h = %.4g (%d DOFs)" % (
            next(r["h"] for r in rows if r["level"] == level),
            next(r["dofs"] for r in rows if r["level"] == level)) for level in levels]
        lines += ["### %s: %s" % (case, rows[0]["description"]), "",
                  table_row(header + ["largest force error"]),
                  table_rule(len(header) + 1)]
        for method in [m[0] for m in methods()]:
            cells, errors = [], []
            for level in levels:
                record = next(r for r in rows if r["level"] == level and r["method"] == method)
                if record.get("status") == "converged":
                    cells.append(str(record["iterations"]))
                    errors.append(record.get("force_error", float("nan")))
                else:
                    cells.append("%s (%s)" % (record.get("status"), record.get("iterations")))
            error = "%.1e" % max(errors) if errors else "-"
            lines.append(table_row([method] + cells + [error]))
        lines.append("")
    if scans:
        lines += ["### Single fixed delta (plain iteration, coarsest mesh)", "",
                  "| case | " + " | ".join("delta = %g" % d for d in next(iter(scans.values())))
                  + " |", "|---|" + "---|" * len(next(iter(scans.values())))]
        for case, counts in scans.items():
            lines.append("| %s | " % case + " | ".join(
                str(n) if n is not None else "no convergence" for n in counts.values()) + " |")
        lines.append("")
    with open(path, "w") as file:
        file.write("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--output", default="results/iteration-study")
    parser.add_argument("--levels", type=int, default=4)
    parser.add_argument("--docs", help="write DOCS/iteration-study.md and DOCS/images/*.png")
    parser.add_argument("--cases", help="comma-separated subset of the case names")
    parser.add_argument("--plot-only", action="store_true",
                        help="redraw the plots and tables from OUTPUT/study.json")
    parser.add_argument("--reuse", action="store_true",
                        help="read runs that already have a summary.json instead of repeating them")
    arguments = parser.parse_args()
    if arguments.plot_only:
        with open(os.path.join(arguments.output, "study.json")) as file:
            stored = json.load(file)
        scans = {k: {float(d): n for d, n in v.items()} for k, v in stored["delta_scans"].items()}
        write_tables(stored["results"], scans, os.path.join(arguments.output, "tables.md"))
        if arguments.docs:
            plot(stored["results"], arguments.docs)
        return
    selected = case_grid()
    if arguments.cases:
        wanted = arguments.cases.split(",")
        selected = [case for case in selected if case[0] in wanted]
    results, scans = [], {}
    start = time.monotonic()
    for case in selected:
        results += study_case(arguments.build, arguments.output, case, arguments.levels,
                              arguments.reuse)
        if case[0] in ("asymmetric", "ratio100-stiff-lower", "ratio100-stiff-upper"):
            for stopping in ("either-sequence", "joint"):
                scans[case[0] + ", " + stopping + " stopping"] = fixed_delta_scan(
                    arguments.build, arguments.output, case,
                    [0.5, 0.3, 0.2, 0.15, 0.1, 0.07, 0.05, 0.02, 0.01], arguments.reuse, stopping)
    elapsed = time.monotonic() - start
    os.makedirs(arguments.output, exist_ok=True)
    with open(os.path.join(arguments.output, "study.json"), "w") as file:
        json.dump({"results": results, "delta_scans": {k: {str(d): n for d, n in v.items()}
                                                      for k, v in scans.items()},
                   "machine": platform.platform(), "cpus": os.cpu_count(),
                   "seconds": elapsed}, file, indent=1)
    write_tables(results, scans, os.path.join(arguments.output, "tables.md"))
    if arguments.docs:
        images = plot(results, arguments.docs)
        print("wrote %d plots to %s/images" % (len(images), arguments.docs))
    print("study done in %.0f s; results in %s/study.json" % (elapsed, arguments.output))


if __name__ == "__main__":
    main()
