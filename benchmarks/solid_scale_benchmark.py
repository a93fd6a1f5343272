#!/usr/bin/python3
"""The 3D scale benchmark: a sphere on a flat at 1e4 to 1e6 DOFs (issue 13 item 6, issue 16 item 7).

    /usr/bin/python3 benchmarks/solid_scale_benchmark.py [--build build]
        [--sizes 1e4 1e5 1e6] [--include-3e6] [--operators dense factor]
        [--linear-solvers direct multigrid]
        [--tools robin-run robin-monolithic] [--timeout 900] [--memory-limit 18]
        [--robin-timeout 1800] [--keep DIR]
    /usr/bin/python3 benchmarks/solid_scale_benchmark.py --tabulate DIR/results.json ...

The case is examples/hertz_3d.toml (quarter model of a sphere of radius R = 1 pressed onto a
flat through the gap (x^2 + y^2) / (2 R), both bodies E = 1000, nu = 0.3, the upper body's far
face moved by -0.012, symmetry conditions on x = 0 and y = 0), meshed with
benchmarks/meshes/solid_scale_lower.geo and solid_scale_upper.geo instead of the graded meshes
of the example: n cells per direction (n^3 8-node hexahedra per body, mildly graded towards the
origin and the contact face, the largest cell 8 times the smallest), so that the number of DOFs
can be chosen. For every size of --sizes (total DOFs of both bodies, about) the script takes
the n whose two bodies have the nearest number of free DOFs, 2 (3 (n+1)^3 - 3 (n+1)^2 - 2 n (n+1)),
writes a case file into its scratch directory (mesh_size = 1 / n: the .geo's h), and runs
robin-run (one robin-subdomain server per body on this machine) and robin-monolithic on it,
once per interface operator of --operators (`[solver] interface_operator`, set with --set:
"dense" assembles F = B K^-1 B^T once, "factor" applies it by triangular solves, "auto" is
dense up to dense_limit = 8000 contact nodes; the contact face has (n+1)^2 nodes, node-to-node
pairs), and once per linear solver of --linear-solvers (`[solver] linear_solver`, also set with
--set: "direct" factorizes K once; "multigrid" solves by AMG-preconditioned conjugate
gradients; "auto", the case file's default, chooses by the body's size, docs/case-format.md).
Sizes above
2e6 DOFs run only with --include-3e6 (which also adds 3e6 to the sizes).

Prints, per run as it finishes, one line; then two Markdown tables:

  1. the stages of summary.json's `profile` (docs/outputs.md), one row per stage, one column per
     size, operator (and linear solver, when not "direct") and tool, in seconds ("server:" rows
     are the larger of the two bodies'; robin-run sets them up in parallel, robin-monolithic one
     after the other), the iterations, wall time, peak RSS of each robin-subdomain server, of
     the coordinator and of robin-monolithic, and robin-monolithic's factor fill (nonzeros of L
     per body);
  2. one row per size, operator and linear solver: DOFs, contact nodes, robin-run's outer
     iterations, their time and messaging share (summary.json
     timings.messaging_share_of_iteration), the wall times of robin-run and robin-monolithic and
     their ratio, the peak RSS per server, and the agreement: the largest difference of the
     contact forces of contact.csv (the mean of the lambda1 and lambda2 columns, row by row)
     between robin-run and robin-monolithic, relative to the largest contact force.

Runs are measured with benchmark_support (VmHWM of every process of the run polled from /proc
every 0.1 s). A run is stopped (SIGTERM, then SIGKILL of the processes seen) when it takes longer
than --timeout seconds or when the resident memory of its processes summed exceeds
--memory-limit GiB; its column then says so. robin-run's own request deadline (--timeout of
robin-run: AssignContact builds the dense F, which takes minutes at 1e6 DOFs) is raised to
--robin-timeout. --keep DIR keeps the case files, logs, outputs and results.json; --tabulate
prints the tables again from such results.json files (several invocations in one table).

On 2 cores and 24 GiB the default 1e6 size does not fit: its two servers were stopped by the
memory guard (18 GiB) after 677 s, still factorizing (docs/benchmarks.md, "Solid bodies (3D) at
scale"); 4.9e5 DOFs (--sizes 5e5) took 410 s with robin-run and 461 s with robin-monolithic.
No time is asserted anywhere: the tables are measurements on a machine that may be shared.
"""

import argparse
import itertools
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchmark_support import (COORDINATOR_KEYS, children_of, exit_on_sigterm,  # noqa: E402
                               print_machine_header, read_csv_rows, read_hwm,
                               resident_megabytes, scratch_directory, table_row, table_rule,
                               tool_directory, profile_rows, profile_column)

REPOSITORY = Path(__file__).resolve().parent.parent
MESHES = REPOSITORY / "benchmarks" / "meshes"

ROWS = profile_rows("both bodies")

CASE = """\
# Written by benchmarks/solid_scale_benchmark.py: examples/hertz_3d.toml on n = {n} cells per
# direction (benchmarks/meshes/solid_scale_block.geo, h = 1 / n).
title = "3D scale benchmark: sphere on a flat, n = {n}"
dimension = 3

[gap]
expression = "(x^2 + y^2) / (2 * R)"
constants = {{ R = 1.0 }}

[coupling]
tolerance = 1e-8

[[body]]
name = "flat"
mesh = "{lower}"
mesh_size = {h!r}
contact_boundary = "contact"
[body.material]
young = 1000.0
poisson = 0.3
[[body.dirichlet]]
boundary = "far"
fix = "all"
[[body.dirichlet]]
boundary = "symmetry_x"
fix = "x"
[[body.dirichlet]]
boundary = "symmetry_y"
fix = "y"

[[body]]
name = "sphere"
mesh = "{upper}"
mesh_size = {h!r}
contact_boundary = "contact"
[body.material]
young = 1000.0
poisson = 0.3
[[body.dirichlet]]
boundary = "far"
x = 0.0
y = 0.0
z = -0.012
[[body.dirichlet]]
boundary = "symmetry_x"
fix = "x"
[[body.dirichlet]]
boundary = "symmetry_y"
fix = "y"
"""


def body_dofs(n):
    """Free DOFs of one body with n cells per direction: 3 per node of the (n+1)^3, less the far
    face's (all fixed), less one per node of each symmetry face not on the far face."""
    return 3 * (n + 1) ** 3 - 3 * (n + 1) ** 2 - 2 * n * (n + 1)


def cells_for(target):
    """The n whose two bodies together have the number of free DOFs nearest to target."""
    return min(range(2, 400), key=lambda n: abs(2 * body_dofs(n) - target))


def write_case(directory, n):
    directory.mkdir(parents=True, exist_ok=True)
    case = directory / f"solid_scale_n{n}.toml"
    case.write_text(CASE.format(n=n, h=1.0 / n, lower=MESHES / "solid_scale_lower.geo",
                                upper=MESHES / "solid_scale_upper.geo"))
    return case


def process_label(pid):
    """The process's name, with the body for a robin-subdomain server (from its command line)."""
    try:
        words = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return None
    words = [word.decode(errors="replace") for word in words if word]
    if not words:
        return None
    name = os.path.basename(words[0])
    if name == "robin-subdomain":
        for index, word in enumerate(words[:-1]):
            if word in ("--name", "--body", "--label"):
                return f"{name} {words[index + 1]}"
    return name


def run_guarded(command, log_path, timeout, memory_limit_mib):
    """Runs command, polling its processes every 0.1 s: their VmHWM (peaks by pid, with a label)
    and the sum of their VmRSS. Over `timeout` seconds or `memory_limit_mib` summed: SIGTERM to
    the command, after 10 s SIGKILL to every process seen. Returns (exit status, wall seconds,
    ru_maxrss KiB, {pid: (label, VmHWM KiB)}, largest summed VmRSS MiB, why stopped or None,
    [(seconds, {label: VmRSS MiB})] every 10 s)."""
    peaks, labels, timeline = {}, {}, []
    state = {"largest_sum": 0.0, "stopped": None, "term_time": None, "sampled": -1e9}
    done = threading.Event()
    with open(log_path, "w") as log:
        start = time.monotonic()
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL)

        def poll():
            while not done.is_set():
                pending, seen, total, sample = [process.pid], set(), 0.0, {}
                while pending:
                    pid = pending.pop()
                    if pid in seen:
                        continue
                    seen.add(pid)
                    value = read_hwm(pid)
                    if value is not None:
                        if pid not in labels:
                            labels[pid] = process_label(pid) or value[0]
                        if value[1] >= peaks.get(pid, ("", 0))[1]:
                            peaks[pid] = (labels[pid], value[1])
                        try:
                            resident = resident_megabytes(pid)
                            total += resident
                            sample[labels[pid]] = round(resident)
                        except OSError:
                            pass
                    pending.extend(children_of(pid))
                state["largest_sum"] = max(state["largest_sum"], total)
                elapsed = time.monotonic() - start
                if elapsed - state["sampled"] >= 10:
                    timeline.append((round(elapsed, 1), sample))
                    state["sampled"] = elapsed
                if state["stopped"] is None:
                    if elapsed > timeout:
                        state["stopped"] = f"stopped after {timeout:.0f} s"
                    elif total > memory_limit_mib:
                        state["stopped"] = (f"stopped at {total / 1024:.1f} GiB resident "
                                            f"after {elapsed:.0f} s")
                    if state["stopped"] is not None:
                        state["term_time"] = elapsed
                        process.send_signal(signal.SIGTERM)
                elif elapsed - state["term_time"] > 10:
                    for pid in list(peaks):  # still the process seen (not a reused pid)
                        if process_label(pid) != labels.get(pid):
                            continue
                        try:
                            os.kill(pid, signal.SIGKILL)
                        except OSError:
                            pass
                done.wait(0.1)

        poller = threading.Thread(target=poll, daemon=True)
        poller.start()
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.monotonic() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        done.set()
        poller.join()
    return (process.returncode, wall, usage.ru_maxrss, peaks, state["largest_sum"],
            state["stopped"], timeline)


def contact_forces(output):
    """The contact force of every row of contact.csv (mean of lambda1 and lambda2), or None."""
    try:
        rows = read_csv_rows(output / "contact.csv")
    except OSError:
        return None
    return [(float(row["lambda1"]) + float(row["lambda2"])) / 2 for row in rows]


def agreement(first, second):
    """max_i |a_i - b_i| / max_i |b_i|, or None."""
    if not first or not second or len(first) != len(second):
        return None
    scale = max(abs(value) for value in second) or 1.0
    return max(abs(a - b) for a, b in zip(first, second)) / scale


def cell(value, digits=3):
    if value is None:
        return "–"
    if isinstance(value, str):
        return value
    if isinstance(value, int):
        return str(value)
    return f"%.{digits}f" % value


def run_one(binaries, tool, case, operator, linear_solver, output, arguments):
    command = [str(binaries / tool), str(case), "--output", str(output), "--quiet",
               "--set", f"solver.interface_operator={operator}"]
    command += ["--set", f"solver.linear_solver={linear_solver}"]
    if tool == "robin-run":
        command += ["--timeout", repr(arguments.robin_timeout)]
    status, wall, maxrss, peaks, largest_sum, stopped, timeline = run_guarded(
        command, output.parent / f"{output.name}.log", arguments.timeout,
        arguments.memory_limit * 1024)
    try:
        summary = json.loads((output / "summary.json").read_text())
    except (OSError, ValueError):
        summary = {}
    profile = summary.get("profile", {})
    column = profile_column(profile, ROWS)
    servers = sorted(((label, kib / 1024) for label, kib in peaks.values()
                      if label.startswith("robin-subdom")), key=lambda item: item[0])
    coordinator = [kib / 1024 for label, kib in peaks.values() if label.startswith("robin-run")]
    timings = summary.get("timings", {})
    result = {
        "tool": tool, "operator": operator, "linear_solver": linear_solver,
        "command": " ".join(command), "status": status,
        "stopped": stopped, "wall": wall, "column": column,
        "stages": sum(profile.get(key) or 0.0 for key in COORDINATOR_KEYS) if profile else None,
        "dofs": sum(body.get("dofs", 0) for body in summary.get("bodies", [])) or None,
        "contact_pairs": summary.get("contact_pairs"),
        "iterations": summary.get("iterations"),
        "operator_applications": summary.get("operator_applications"),
        "messaging_share": timings.get("messaging_share_of_iteration"),
        "messaging": timings.get("messaging"),
        "server_rss": [(label.split(" ", 1)[-1], mib) for label, mib in servers],
        "coordinator_rss": max(coordinator) if coordinator else None,
        "process_rss": maxrss / 1024,
        "largest_resident_sum": largest_sum,
        "factor_nonzeros": [body.get("factor_nonzeros") for body in summary.get("bodies", [])
                            if body.get("factor_nonzeros") is not None],
        "message": summary.get("message"),
        "timeline": timeline,
        "forces": contact_forces(output),
        "resultant": (summary.get("contact_force_resultant") or [None] * 3)[-1],
    }
    return result


def status_text(result):
    if result["stopped"]:
        return result["stopped"]
    if result["status"] == 0:
        return "converged"
    return f"exit {result['status']}: {result['message'] or 'no summary'}"


def solver_label(result):
    """The interface operator of a run, and its linear solver when not "direct" (results.json
    of runs before --linear-solvers have none: direct)."""
    linear_solver = result.get("linear_solver") or "direct"
    return result["operator"] + ("" if linear_solver == "direct" else f", {linear_solver}")


def print_tables(results):
    """The two Markdown tables of the module docstring; returns the number of runs that failed,
    were stopped or did not converge."""
    for r in results:
        if r.get("dofs") is None:
            r["dofs"] = 2 * body_dofs(r["n"])
    # Table 1: the stages, one column per run.
    headers = [f"n = {r['n']}, {r['dofs']} DOFs, {solver_label(r)}, "
               f"{'DD' if r['tool'] == 'robin-run' else 'mono'}" for r in results]
    print("\n" + table_row(["stage (s)"] + headers))
    print(table_rule(len(headers) + 1))
    for index, (label, _, _) in enumerate(ROWS):
        print(table_row([label.replace("  ", "&nbsp;&nbsp;")]
                        + [cell(r["column"][index]) for r in results]))
    extra = [
        ("sum of the stages (not indented)", lambda r: cell(r["stages"])),
        ("wall (measured)", lambda r: cell(r["wall"])),
        ("outer iterations (DD) / operator applications (mono)",
         lambda r: cell(r["iterations"] if r["tool"] == "robin-run"
                        else r["operator_applications"])),
        ("status", status_text),
        ("peak RSS per server (MiB)",
         lambda r: ", ".join("%s %.0f" % tuple(s) for s in r["server_rss"]) if r["server_rss"] else "–"),
        ("peak RSS, coordinator / robin-monolithic (MiB)",
         lambda r: cell(r["coordinator_rss"] if r["tool"] == "robin-run" else r["process_rss"],
                        0)),
        ("largest resident sum of the run's processes (MiB)",
         lambda r: cell(r["largest_resident_sum"], 0)),
        ("nonzeros of L per body (mono)",
         lambda r: ", ".join("%.3g" % v for v in r["factor_nonzeros"])
         if r["factor_nonzeros"] else "–"),
    ]
    for label, function in extra:
        print(table_row([label] + [function(r) for r in results]))

    # Table 2: one row per size, operator and linear solver.
    print("\n" + table_row(["DOFs (n)", "contact nodes", "F", "DD outer iterations",
                            "DD iterations (s)", "messaging share of the iterations",
                            "DD wall (s)", "mono wall (s)", "DD / mono",
                            "peak RSS per server (MiB)", "mono peak RSS (MiB)",
                            "max rel. difference of the contact forces, DD vs mono"]))
    print(table_rule(12))
    failures = 0
    pairs = []
    for r in results:
        if (r["n"], solver_label(r)) not in pairs:
            pairs.append((r["n"], solver_label(r)))
    for n, label in pairs:
        if True:
            dd = next((r for r in results if r["n"] == n and solver_label(r) == label
                       and r["tool"] == "robin-run"), None)
            mono = next((r for r in results if r["n"] == n and solver_label(r) == label
                         and r["tool"] == "robin-monolithic"), None)
            for r in (dd, mono):
                failures += r is not None and (r["status"] != 0 or r["stopped"] is not None)
            ok = lambda r: r is not None and r["status"] == 0 and not r["stopped"]  # noqa: E731
            dofs = (dd or mono or {}).get("dofs") or 2 * body_dofs(n)
            ratio = dd["wall"] / mono["wall"] if ok(dd) and ok(mono) else None
            difference = agreement(dd["forces"], mono["forces"]) if ok(dd) and ok(mono) else None
            print(table_row([
                f"{dofs} ({n})", (n + 1) ** 2, label,
                cell(dd["iterations"]) if ok(dd) else "–",
                cell(dd["column"][12]) if ok(dd) else "–",
                cell(dd["messaging_share"], 2) if ok(dd) else "–",
                cell(dd["wall"], 1) if dd else "–",
                cell(mono["wall"], 1) if mono else "–",
                cell(ratio, 2),
                ", ".join("%s %.0f" % tuple(s) for s in dd["server_rss"]) if dd else "–",
                cell(mono["process_rss"], 0) if mono else "–",
                "%.1e" % difference if difference is not None else "–",
            ]))
    return failures


def main():
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog="See the module docstring (the top of this file) and docs/benchmarks.md, "
               "\"Solid bodies (3D) at scale\".")
    parser.add_argument("--build", default=str(REPOSITORY / "build"),
                        help="build directory holding bin/robin-run, bin/robin-monolithic")
    parser.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5, 1e6],
                        help="total DOFs of both bodies, about (default 1e4 1e5 1e6)")
    parser.add_argument("--include-3e6", action="store_true",
                        help="also run 3e6 DOFs (and allow any size above 2e6); about 10 GiB "
                             "of factors per body")
    parser.add_argument("--operators", nargs="+", default=["dense", "factor"],
                        choices=["dense", "factor", "auto"],
                        help="[solver] interface_operator values to run (default dense factor)")
    parser.add_argument("--linear-solvers", nargs="+", default=["direct"],
                        choices=["direct", "multigrid", "auto"],
                        help="[solver] linear_solver values to run (default direct)")
    parser.add_argument("--tools", nargs="+", default=["robin-run", "robin-monolithic"],
                        choices=["robin-run", "robin-monolithic"], help="the tools to run")
    parser.add_argument("--timeout", type=float, default=900.0,
                        help="stop a run after this many seconds (default 900)")
    parser.add_argument("--memory-limit", type=float, default=18.0,
                        help="stop a run whose processes hold more than this many GiB "
                             "resident, summed (default 18)")
    parser.add_argument("--robin-timeout", type=float, default=1800.0,
                        help="robin-run's --timeout, the deadline of an interface-sized request "
                             "such as AssignContact, in seconds (default 1800)")
    parser.add_argument("--keep", help="keep the scratch directory here (must not exist)")
    parser.add_argument("--tabulate", nargs="+", metavar="RESULTS_JSON",
                        help="run nothing: print the tables of the results.json files of "
                             "earlier runs (their --keep directories), one after the other")
    arguments = parser.parse_args()

    if arguments.tabulate:
        results = []
        for path in arguments.tabulate:
            results += json.loads(Path(path).read_text())
        failures = print_tables(results)
        if failures:
            print(f"\n{failures} run(s) failed, were stopped or did not converge (see 'status')")
        return 0

    sizes = list(arguments.sizes)
    if arguments.include_3e6 and 3e6 not in sizes:
        sizes.append(3e6)
    too_large = [size for size in sizes if size > 2e6]
    if too_large and not arguments.include_3e6:
        parser.error(f"sizes above 2e6 DOFs ({', '.join('%g' % s for s in too_large)}) need "
                     "--include-3e6")

    exit_on_sigterm()
    binaries = tool_directory(arguments.build, ("robin-run", "robin-subdomain",
                                                "robin-monolithic"))
    print_machine_header()
    scratch = scratch_directory(arguments.keep, "robin-solid-scale-")
    print(f"scratch: {scratch}", flush=True)

    results = []
    try:
        for size in sizes:
            n = cells_for(size)
            case = write_case(scratch, n)
            for operator, linear_solver in itertools.product(arguments.operators,
                                                             arguments.linear_solvers):
                suffix = "" if linear_solver == "direct" else f"_{linear_solver}"
                for tool in arguments.tools:
                    output = scratch / f"n{n}_{operator}{suffix}_{tool}"
                    result = run_one(binaries, tool, case, operator, linear_solver, output,
                                     arguments)
                    result.update(size=size, n=n, contact_nodes=(n + 1) ** 2)
                    if result["dofs"] is None:  # no summary.json: the count the mesh gives
                        result["dofs"] = 2 * body_dofs(n)
                    results.append(result)
                    print(f"{size:g} DOFs (n = {n}, {result['dofs']} DOFs), "
                          f"{solver_label(result)}, {tool}: "
                          f"{status_text(result)}, {result['wall']:.1f} s, largest resident "
                          f"sum {result['largest_resident_sum']:.0f} MiB", flush=True)
                    if result["stopped"] or result["wall"] > 120:
                        for seconds, sample in result["timeline"]:
                            print(f"    resident at {seconds:6.0f} s (MiB): " + ", ".join(
                                f"{label} {mib}" for label, mib in sorted(sample.items())))
                    (scratch / "results.json").write_text(json.dumps(results, indent=1))
    finally:
        if not arguments.keep:
            shutil.rmtree(scratch, ignore_errors=True)

    failures = print_tables(results)
    if failures:
        print(f"\n{failures} run(s) failed, were stopped or did not converge (see 'status')")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
