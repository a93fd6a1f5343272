#!/usr/bin/python3
"""The stage-by-stage profile for N bodies (issue 16 item 7, the N-bodies half; docs/benchmarks.md).

    /usr/bin/python3 benchmarks/many_bodies_profile_benchmark.py [--build build]
        [--counts 2 4 8 16] [--total-dofs 1e5] [--arch-refine 1 4 10] [--repeats 1]
        [--robin-timeout SECONDS] [--keep DIR]

Runs robin-run (one robin-subdomain server per body on this machine) and robin-monolithic on

  * the row of N unit blocks of benchmarks/many_bodies_service_benchmark.py (each clamped at its
    bottom, the first pushed by a unit pressure on its left face, the last on its right face;
    neighbours alternate the mesh sizes h and 0.8 h, so the N - 1 interfaces are non-matching
    and coupled by mortar; structured quadrilateral .geo bodies meshed by the coordinator), for
    every N of --counts at a FIXED TOTAL number of DOFs (--total-dofs, about; h is chosen for
    each N so that the N bodies together have that many, the actual sum is printed);
  * the keystone arch, examples/arch.toml (four bodies, one floating, three mortar interfaces),
    with every body's mesh_size divided by each factor of --arch-refine (1: the case as
    shipped; 4 and 10: about 16 and 100 times the elements), set with robin-run's --set.

and prints the summary.json `profile` (docs/outputs.md) as one markdown table, one row per
stage, one column per case and tool, in seconds, like benchmarks/profile_benchmark.sh; "server:"
rows are the largest over the N bodies (robin-run sets them up in parallel; in robin-monolithic
they are its own setup of each body, one after the other); – is a stage the tool does not have.
Below the stages: the outer iterations (robin-run; robin-monolithic's MPRGP iterations are not
comparable and not shown), "wall" measured around the process, "rest" = wall minus the sum of the
coordinator's stages, the peak RSS (VmHWM polled from /proc every 0.1 s) of the largest
robin-subdomain server, of the N servers summed, of the coordinator (robin-run) and of
robin-monolithic's one process (exact, wait4's ru_maxrss).

--robin-timeout passes robin-run's --timeout (the deadline of an interface-sized request such as
AssignContact; default 60 s): on 2 shared cores the arch refined tenfold needs more (its floating
keystone's interface operator took 74 s in robin-monolithic on 2026-11-26).

With --repeats R > 1 each column is the run with the median wall time of R interleaved runs.
A run that fails or does not converge is reported in its column's "status" row.
"""

import argparse
import json
import re
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchmark_support import (COORDINATOR_KEYS, print_machine_header,  # noqa: E402
                               profile_column, profile_rows, run_measured, scratch_directory,
                               table_row, table_rule, tool_directory)
from many_bodies_service_benchmark import mesh_size, write_row_case  # noqa: E402

REPOSITORY = Path(__file__).resolve().parent.parent

ROWS = profile_rows("all bodies")

def row_dofs(count, h):
    """Free DOFs of the row at h: (m + 1)^2 nodes per block (m = Round(1 / h_k)), two DOFs per
    node, less the clamped bottom's nodes (the .geo's transfinite structure)."""
    total = 0
    for index in range(count):
        m = round(1 / mesh_size(h, index))
        total += 2 * (m + 1) ** 2 - 2 * (m + 1)
    return total


def h_for(count, target):
    """The h whose row of count blocks has about target DOFs (bisection on log h)."""
    low, high = 1e-4, 0.5
    for _ in range(60):
        middle = (low * high) ** 0.5
        if row_dofs(count, middle) > target:
            low = middle
        else:
            high = middle
    return high


def arch_overrides(factor):
    """--set arguments dividing every arch body's mesh_size by factor."""
    if factor == 1:
        return []
    text = (REPOSITORY / "examples" / "arch.toml").read_text()
    sizes = [float(value) for value in re.findall(r"^mesh_size = ([0-9.eE+-]+)", text, re.M)]
    arguments = []
    for index, size in enumerate(sizes):
        arguments += ["--set", f"body[{index + 1}].mesh_size={size / factor!r}"]
    return arguments


def column_of(summary, status, wall, peaks, maxrss, tool):
    profile = summary.get("profile", {})
    column = profile_column(profile, ROWS)
    stages = sum(profile.get(key) or 0.0 for key in COORDINATOR_KEYS) if profile else None
    servers = [kib for name, kib in peaks.values() if name.startswith("robin-subdom")]
    coordinator = [kib for name, kib in peaks.values() if name.startswith("robin-run")]
    extra = {
        "sum of the stages (not indented)": stages,
        "wall (measured)": wall,
        "rest (wall - sum)": wall - stages if stages is not None else None,
        "outer iterations": summary.get("iterations") if tool == "robin-run" else "–",
        "status": "converged" if status == 0 else
            f"exit {status}: {summary.get('message') or summary.get('status') or 'no summary'}",
        "peak RSS, largest server (MiB)": max(servers) / 1024 if servers else None,
        "peak RSS, servers summed (MiB)": sum(servers) / 1024 if servers else None,
        "peak RSS, coordinator / robin-monolithic (MiB)":
            (max(coordinator) / 1024 if coordinator else None) if tool == "robin-run"
            else maxrss / 1024,
    }
    return column, extra


def cell(value, digits=3):
    if value is None:
        return "–"
    if isinstance(value, str):
        return value
    if isinstance(value, int):
        return str(value)
    return f"%.{digits}f" % value


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=str(REPOSITORY / "build"),
                        help="build directory holding bin/robin-run, bin/robin-monolithic")
    parser.add_argument("--counts", type=int, nargs="*", default=[2, 4, 8, 16],
                        help="numbers of blocks in the row (none: skip the row)")
    parser.add_argument("--total-dofs", type=float, default=1e5,
                        help="about this many DOFs summed over the row's bodies, for every N")
    parser.add_argument("--arch-refine", type=float, nargs="*", default=[1, 4, 10],
                        help="divide the arch's mesh sizes by these factors (none: skip)")
    parser.add_argument("--repeats", type=int, default=1,
                        help="interleaved runs per column; the median-wall one is shown")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds per run")
    parser.add_argument("--robin-timeout", type=float,
                        help="robin-run's --timeout (request deadline, s); default: robin-run's")
    parser.add_argument("--keep", help="keep the scratch directory here")
    arguments = parser.parse_args()

    binaries = tool_directory(arguments.build,
                              ("robin-run", "robin-subdomain", "robin-monolithic"))
    print_machine_header()
    scratch = scratch_directory(arguments.keep, "robin-many-bodies-profile-")

    cases = []  # (label, case file, extra arguments)
    for count in arguments.counts:
        h = h_for(count, arguments.total_dofs)
        case = write_row_case(scratch / f"row_{count}", count, h)
        cases.append((f"row N = {count} (h = {h:.4g})", case, []))
    for factor in arguments.arch_refine:
        cases.append((f"arch, mesh sizes / {factor:g}", REPOSITORY / "examples" / "arch.toml",
                      arch_overrides(factor)))

    headers, columns, extras = [], [], []
    failures = 0
    try:
        for index, (label, case, overrides) in enumerate(cases):
            for tool in ("robin-run", "robin-monolithic"):
                runs = []
                for repeat in range(arguments.repeats):
                    output = scratch / f"case{index}_{tool}_{repeat}"
                    timeout = ([] if arguments.robin_timeout is None or tool != "robin-run"
                               else ["--timeout", repr(arguments.robin_timeout)])
                    status, wall, maxrss, peaks = run_measured(
                        [str(binaries / tool), str(case), "--output", str(output), "--quiet",
                         *overrides, *timeout], scratch / f"case{index}_{tool}_{repeat}.log",
                        arguments.timeout)
                    try:
                        summary = json.loads((output / "summary.json").read_text())
                    except (OSError, ValueError):
                        summary = {}
                    runs.append((wall, status, summary, peaks, maxrss))
                    print(f"{label}, {tool}, run {repeat + 1}: exit {status}, {wall:.2f} s, "
                          f"{sum(body.get('dofs', 0) for body in summary.get('bodies', []))} "
                          "DOFs", flush=True)
                runs.sort(key=lambda run: run[0])
                wall, status, summary, peaks, maxrss = runs[len(runs) // 2]
                failures += status != 0
                dofs = sum(body.get("dofs", 0) for body in summary.get("bodies", []))
                bodies = len(summary.get("bodies", [])) or "?"
                headers.append(f"{label}: {bodies} bodies, {dofs or '?'} DOFs, "
                               f"{'DD' if tool == 'robin-run' else 'mono'}")
                column, extra = column_of(summary, status, wall, peaks, maxrss, tool)
                columns.append(column)
                extras.append(extra)
    finally:
        if not arguments.keep:
            shutil.rmtree(scratch, ignore_errors=True)

    print("\n" + table_row(["stage (s)"] + headers))
    print(table_rule(len(headers) + 1))
    for index, (label, _, _) in enumerate(ROWS):
        print(table_row([label.replace("  ", "&nbsp;&nbsp;")]
                        + [cell(column[index]) for column in columns]))
    for key in extras[0]:
        digits = 0 if "MiB" in key else 3
        print(table_row([key] + [cell(extra[key], digits) for extra in extras]))
    if failures:
        print(f"\n{failures} run(s) failed or did not converge (see the status row)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
