#!/usr/bin/env python3
"""robin-run on the two-block case with the servers writing their VTU files (this build) against
another build whose coordinator writes them (docs/benchmarks.md, "Servers write their own VTU").

For every mesh size h: both blocks meshed by Gmsh (msh 2.2), a copy of
examples/two_blocks_partial.toml naming those files, then --repeats rounds that run robin-run of
each build once, interleaved (before, after, before, after, ...). Per build and size: the median
wall time, the medians of summary.json profile "fields" and "output", the largest server's peak
RSS (VmHWM polled every 0.1 s from /proc, the larger of the two robin-subdomain processes) and,
when the servers report it (protocol 2.5), the largest profile.bodies[].peak_resident_bytes.

    benchmarks/server_written_fields_benchmark.py --before OLD/bin --after build/bin \\
        --sizes 0.0104 0.0033 --repeats 5 [--keep DIR]
"""

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from benchmark_support import exit_on_sigterm, print_machine_header, run_measured

REPOSITORY = Path(__file__).resolve().parent.parent


def case_for(size, directory):
    """Meshes both blocks at `size` (unless `directory` has them) and writes a case file naming
    them; returns its path."""
    text = (REPOSITORY / "examples/two_blocks_partial.toml").read_text()
    for body in ("lower", "upper"):
        mesh = directory / f"block_{body}.msh"
        if mesh.exists():  # meshed by an earlier run with the same --keep
            text = text.replace(f'mesh = "meshes/block_{body}.geo"', f'mesh = "{mesh}"')
            continue
        subprocess.run(["gmsh", "-2", "-setnumber", "h", str(size), "-format", "msh22",
                        str(REPOSITORY / f"examples/meshes/block_{body}.geo"), "-o", str(mesh)],
                       check=True, stdout=subprocess.DEVNULL)
        text = text.replace(f'mesh = "meshes/block_{body}.geo"', f'mesh = "{mesh}"')
    text = re.sub(r"(?m)^mesh_size = .*\n", "", text)
    path = directory / "case.toml"
    path.write_text(text)
    return path


def one_run(binaries, case, output):
    """(wall seconds, fields, output, largest server VmHWM MiB, largest reported peak MiB)."""
    status, wall, _, peaks = run_measured(
        [str(binaries / "robin-run"), str(case), "--output", str(output), "--quiet"],
        str(output) + ".log", timeout=1800)
    if status != 0:
        sys.exit(f"robin-run failed ({status}): see {output}.log")
    summary = json.loads((output / "summary.json").read_text())
    profile = summary["profile"]
    servers = [kib for name, kib in peaks.values() if name.startswith("robin-subdomain")]
    reported = [body.get("peak_resident_bytes") for body in profile["bodies"]]
    reported = max(reported) / 2**20 if all(reported) else None
    return wall, profile["fields"], profile["output"], max(servers) / 1024, reported


def median(values):
    values = [value for value in values if value is not None]
    return statistics.median(values) if values else None


def main():
    exit_on_sigterm()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="bin/ of the build before")
    parser.add_argument("--after", type=Path, required=True, help="bin/ of the build after")
    parser.add_argument("--sizes", type=float, nargs="+", default=[0.0104, 0.0033])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--keep", type=Path, help="keep the meshes and results here")
    arguments = parser.parse_args()
    scratch = arguments.keep or Path(tempfile.mkdtemp(prefix="server-written-"))
    print_machine_header()
    print("| h | build | wall (s) | profile fields (s) | profile output (s) | "
          "server VmHWM (MiB) | reported peak (MiB) |")
    print("|---|---|---|---|---|---|---|")
    try:
        for size in arguments.sizes:
            directory = scratch / f"h{size}"
            directory.mkdir(parents=True, exist_ok=True)
            case = case_for(size, directory)
            rows = {"before": [], "after": []}
            for repeat in range(arguments.repeats):
                for build in ("before", "after"):
                    output = directory / f"{build}-{repeat}"
                    shutil.rmtree(output, ignore_errors=True)
                    rows[build].append(one_run(getattr(arguments, build), case, output))
            for build, runs in rows.items():
                columns = [median([run[k] for run in runs]) for k in range(5)]
                text = ["–" if value is None else f"{value:.3f}" if k < 3 else f"{value:.0f}"
                        for k, value in enumerate(columns)]
                print(f"| {size} | {build} | " + " | ".join(text) + " |", flush=True)
        print(f"load average at end {os.getloadavg()[0]:.1f}")
    finally:
        if arguments.keep is None:
            shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
