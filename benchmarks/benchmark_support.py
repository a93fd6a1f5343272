"""What the Python benchmark scripts of benchmarks/ share (docs/benchmarks.md).

Running a tool with its wall time (run_timed) or with its wall time and peak memory
(run_measured: VmHWM of every process of the run polled from /proc, and wait4's ru_maxrss),
reading a process's memory from /proc/PID/status, finding the build's tools, the scratch
directory of --keep, the machine header a benchmark prints, Markdown table rows, reading a CSV
result file, and exiting with 143 on SIGTERM. Imported by the scripts beside it (the script's
directory is the first entry of sys.path when it runs); not a script itself.
"""

import csv
import os
import platform
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path


# --------------------------------------------------------------------------- processes

def run_timed(command, log_path, timeout=None, stdin=subprocess.DEVNULL):
    """Runs command (stdout and stderr to log_path); returns (exit status, wall seconds)."""
    start = time.monotonic()
    with open(log_path, "w") as log:
        process = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, stdin=stdin,
                                 timeout=timeout, check=False)
    return process.returncode, time.monotonic() - start


def children_of(pid):
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as handle:
            return [int(child) for child in handle.read().split()]
    except OSError:
        return []


def read_hwm(pid):
    """(command name, VmHWM in KiB) of a process, or None."""
    try:
        with open(f"/proc/{pid}/status") as handle:
            fields = dict(line.split(":", 1) for line in handle if ":" in line)
        return fields["Name"].strip(), int(fields["VmHWM"].split()[0])
    except (OSError, KeyError, ValueError):
        return None


def resident_megabytes(pid):
    """The resident set size (VmRSS) of a process in MiB, NaN when /proc does not say."""
    with open("/proc/%d/status" % pid) as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def run_measured(command, log_path, timeout, environment=None):
    """Runs command; returns (exit status, wall seconds, ru_maxrss KiB, {pid: (name, VmHWM KiB)})."""
    peaks = {}
    done = threading.Event()
    with open(log_path, "w") as log:
        start = time.monotonic()
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL, env=environment)

        def poll():
            while not done.is_set():
                pending, seen = [process.pid], set()
                while pending:
                    pid = pending.pop()
                    if pid in seen:
                        continue
                    seen.add(pid)
                    value = read_hwm(pid)
                    if value is not None and value[1] >= peaks.get(pid, ("", 0))[1]:
                        peaks[pid] = value
                    pending.extend(children_of(pid))
                if time.monotonic() - start > timeout:
                    process.kill()
                done.wait(0.1)

        poller = threading.Thread(target=poll, daemon=True)
        poller.start()
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.monotonic() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        done.set()
        poller.join()
    return process.returncode, wall, usage.ru_maxrss, peaks


def exit_on_sigterm():
    """SIGTERM exits with status 143 through sys.exit, so finally blocks (scratch directories,
    network namespaces, servers) still run."""
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))


# --------------------------------------------------------------------------- the build, scratch

def tool_directory(build, required=()):
    """BUILD/bin as an absolute path; exits naming the first of `required` that is missing."""
    binaries = Path(build).resolve() / "bin"
    for tool in required:
        if not (binaries / tool).is_file():
            sys.exit(f"{binaries / tool} is missing (build it first)")
    return binaries


def scratch_directory(keep, prefix):
    """--keep DIR (created; it must not exist yet), else a new temporary directory."""
    if keep:
        scratch = Path(keep).resolve()
        scratch.mkdir(parents=True, exist_ok=False)
        return scratch
    return Path(tempfile.mkdtemp(prefix=prefix))


def print_machine_header():
    """The machine (architecture, cores, memory, CPU model, load average), the date and the
    command line, as a benchmark's output starts."""
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), "?")
    memory = int(next(line.split()[1] for line in open("/proc/meminfo")
                      if line.startswith("MemTotal"))) / 1048576
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {memory:.0f} GiB, {cpu}; "
          f"load average at start {os.getloadavg()[0]:.1f}")
    print(f"date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print("command: " + " ".join([sys.executable] + sys.argv), flush=True)


# --------------------------------------------------------------------------- tables and files

def table_row(cells):
    """One Markdown table row: | a | b | c |."""
    return "| " + " | ".join(str(cell) for cell in cells) + " |"


def table_rule(columns):
    """The Markdown header separator of a table of that many columns: |---|---|."""
    return "|" + "---|" * columns


def read_csv_rows(path):
    """The rows of a CSV file with a header row, as dicts of strings."""
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))

# --------------------------------------------------------------------------- run profiles

def profile_rows(bodies_label):
    """The rows of a stage table from summary.json's profile, as (label, where, key): "run" is
    profile[key], "body" the largest over profile.bodies. `bodies_label` names the bodies of the
    setup row ("both bodies", "all bodies")."""
    return [
        ("launch", "run", "launch"),
        ("meshing (.geo, Gmsh)", "run", "meshing"),
        (f"setup ({bodies_label})", "run", "setup"),
        ("  transfer", "body", "transfer"),
        ("  server: setup request", "body", "server_setup"),
        ("  server: mesh decoding", "body", "mesh"),
        ("  server: assembly", "body", "assembly"),
        ("  server: ordering", "body", "ordering"),
        ("  server: factorization", "body", "factorization"),
        ("contact coupling", "run", "contact_coupling"),
        ("contact assignment", "run", "contact_assignment"),
        ("  server: interface operator", "body", "interface_operator"),
        ("iterations", "run", "iterations"),
        ("fields", "run", "fields"),
        ("  server: fields", "body", "fields"),
        ("output", "run", "output"),
    ]


def profile_column(profile, rows):
    """The seconds of each row of `rows` (profile_rows) in summary.json's `profile`: the run's
    value, or the largest over its bodies; None where the profile has none."""
    column = []
    for _, where, key in rows:
        if where == "run":
            column.append(profile.get(key))
        else:
            values = [body.get(key) for body in profile.get("bodies", [])]
            values = [value for value in values if value is not None]
            column.append(max(values) if values else None)
    return column


# The coordinator's stages of summary.json's profile, whose sum is compared with the wall time.
COORDINATOR_KEYS = ["launch", "meshing", "setup", "contact_coupling", "contact_assignment",
                    "iterations", "fields", "output"]
