"""Running a case through the robin-contact tools and reading a result directory into NumPy."""

import csv
import json
import math
import numbers
import os
import pathlib
import re
import shutil
import subprocess
import tempfile
import xml.etree.ElementTree as ElementTree

import numpy as np

from .vtu import read_vtu

TOOLS = ("robin-run", "robin-monolithic")


class RunError(Exception):
    """A tool run that failed: `exit_code`, `command`, `output_directory` and `log` (the tool's
    standard error) say how."""

    def __init__(self, message, exit_code, command, output_directory, log):
        super().__init__(message)
        self.exit_code = exit_code
        self.command = command
        self.output_directory = output_directory
        self.log = log


class Interface:
    """One contact interface of a run (docs/outputs.md, "Several bodies"):

    - `number`: its number k, 1-based, in the order of the case's [[interface]] tables;
    - `bodies`: its two bodies (a, b), `boundaries`: their contact boundaries (a's, b's), each
      a tuple of two names (None when the result directory does not say: an older run);
    - `file`: its contact file, `contact_<k>_<a>_<b>.csv` (`contact.csv` for a run of one
      interface);
    - `contact`: that file, one NumPy array per column as `Results.contact` (un1, lambda1 and
      nx, ny are body a's; un2, lambda2 body b's);
    - `summary`: its entry of summary.json's "interfaces" array (contact_pairs, active_pairs,
      largest_pressure, excluded_pairs, initial_overlap, contact_force_resultant, ...), {}
      when there is none.
    """

    def __init__(self, number, bodies, boundaries, file, contact, summary=None):
        self.number = number
        self.bodies = tuple(bodies) if bodies is not None else None
        self.boundaries = tuple(boundaries) if boundaries is not None else None
        self.file = file
        self.contact = contact
        self.summary = summary if summary is not None else {}

    def __repr__(self):
        between = " / ".join(self.bodies) if self.bodies else self.file
        return "<Interface %d: %s, %d rows>" % (self.number, between, len(self.contact["pair"]))


class Results:
    """The results of one run (README.md, "Results"):

    - `summary`: summary.json as a dict;
    - `interfaces`: the contact interfaces, a list of Interface in the case's order
      (`interfaces[0]` is interface 1): its bodies, boundaries and contact table; one entry for
      a run of two bodies;
    - `contact`: the contact table of a run of one interface (contact.csv), one NumPy array per
      column (pair, x, y, nx, ny, gap0, un1, un2, lambda1, lambda2, pressure), one entry per
      contact pair. With several interfaces there is no single table: reading `contact` raises
      ValueError naming `interfaces` (use `interfaces[k].contact` or `interface(a, b)`);
    - `history`: history.csv the same way (residuals per iteration), None when the run wrote
      none (robin-monolithic);
    - `bodies`: the body files named in solution.pvd, by body name, each a VtuFile (points,
      cells, point_data and cell_data arrays, field_data);
    - `directory`, `exit_code` and `log` (the tool's standard error; empty for read_results).
    """

    def __init__(self, directory, summary, contact, history, bodies, exit_code=0, log="",
                 interfaces=None):
        self.directory = directory
        self.summary = summary
        if interfaces is None:
            interfaces = [] if contact is None else [Interface(1, None, None, "contact.csv",
                                                               contact)]
        self.interfaces = list(interfaces)
        self.history = history
        self.bodies = bodies
        self.exit_code = exit_code
        self.log = log

    @property
    def contact(self):
        if len(self.interfaces) == 1:
            return self.interfaces[0].contact
        if not self.interfaces:
            return None
        raise ValueError(
            "the run has %d contact interfaces, so no single contact table: use "
            "results.interfaces[k].contact (k from 0) or results.interface(a, b); files: %s"
            % (len(self.interfaces), ", ".join(interface.file for interface in self.interfaces)))

    def interface(self, body_a, body_b):
        """The Interface between the bodies named body_a and body_b (either order). Raises
        KeyError when there is none, ValueError when they touch on several interfaces (use
        `interfaces`)."""
        found = [interface for interface in self.interfaces if interface.bodies is not None
                 and set(interface.bodies) == {body_a, body_b} and body_a != body_b]
        if not found:
            raise KeyError("no contact interface between %r and %r (interfaces: %s)"
                           % (body_a, body_b, ", ".join(
                               " / ".join(i.bodies) if i.bodies else i.file
                               for i in self.interfaces)))
        if len(found) > 1:
            raise ValueError("%r and %r touch on %d interfaces (%s): pick one from "
                             "results.interfaces" % (body_a, body_b, len(found),
                                                     ", ".join(i.file for i in found)))
        return found[0]


def toml_value(value):
    """The TOML text of a Python value for --set: numbers, booleans, strings and (nested)
    sequences of them. A str is quoted; pass a "KEY=VALUE" string to run_case for raw TOML."""
    if isinstance(value, bool) or isinstance(value, np.bool_):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        number = float(value)
        if math.isnan(number):
            return "nan"
        if math.isinf(number):
            return "inf" if number > 0 else "-inf"
        return repr(number)
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string with ASCII escapes is a TOML basic string
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(toml_value(item) for item in value) + "]"
    raise TypeError("no TOML text for %r (%s)" % (value, type(value).__name__))


def override_arguments(overrides):
    """The --set arguments of `overrides`: a mapping KEY -> Python value (toml_value), or a
    sequence of "KEY=VALUE" strings (VALUE as TOML text), or None."""
    if not overrides:
        return []
    if isinstance(overrides, dict):
        texts = ["%s=%s" % (key, toml_value(value)) for key, value in overrides.items()]
    else:
        texts = list(overrides)
    arguments = []
    for text in texts:
        arguments += ["--set", text]
    return arguments


def find_bin_directory(bin_directory=None):
    """The directory of the robin-contact executables: `bin_directory` if given, else the
    environment variable ROBIN_CONTACT_BIN, else the repository's build/bin next to this
    package, else the directory of robin-run on PATH. Raises FileNotFoundError."""
    candidates = []
    if bin_directory is not None:
        candidates.append(pathlib.Path(bin_directory))
    elif os.environ.get("ROBIN_CONTACT_BIN"):
        candidates.append(pathlib.Path(os.environ["ROBIN_CONTACT_BIN"]))
    else:
        candidates.append(pathlib.Path(__file__).resolve().parent.parent.parent / "build" / "bin")
        on_path = shutil.which("robin-run")
        if on_path:
            candidates.append(pathlib.Path(on_path).parent)
    for candidate in candidates:
        if (candidate / "robin-run").is_file():
            return candidate.resolve()
    raise FileNotFoundError(
        "robin-run not found in %s: build the project (deploy/build.sh) or give bin_directory "
        "or ROBIN_CONTACT_BIN" % ", ".join(str(candidate) for candidate in candidates))


def _number(text):
    return float(text) if text != "" else math.nan


def _columns(path):
    """A CSV file with a header line as {column: NumPy array}: integer columns as int64, other
    numeric columns as float64 (an empty cell is NaN), anything else as str."""
    with open(path, newline="", encoding="utf-8") as file:
        rows = list(csv.reader(file))
    if not rows:
        raise ValueError("%s is empty" % path)
    header, body = rows[0], rows[1:]
    columns = {}
    for index, name in enumerate(header):
        texts = [row[index] for row in body]
        try:
            columns[name] = np.array([int(text) for text in texts], dtype=np.int64)
        except ValueError:
            try:
                columns[name] = np.array([_number(text) for text in texts], dtype=np.float64)
            except ValueError:
                columns[name] = np.array(texts)
    return columns


_INTERFACE_FILE = re.compile(r"^contact_([0-9]+)_.+[.]csv$")


def _read_interfaces(directory, summary):
    """The Interface list of a result directory: the files summary.json's "interfaces" names,
    else contact.csv, else the contact_<k>_*.csv files on disk (in the order of k)."""
    entries = summary.get("interfaces") or []
    if entries and all(entry.get("file") for entry in entries):
        return [Interface(number, entry.get("bodies"), entry.get("boundaries"), entry["file"],
                          _columns(directory / entry["file"]), entry)
                for number, entry in enumerate(entries, start=1)]
    if (directory / "contact.csv").is_file():
        return [Interface(1, None, None, "contact.csv", _columns(directory / "contact.csv"))]
    on_disk = sorted((int(match.group(1)), path.name) for path in directory.iterdir()
                     for match in [_INTERFACE_FILE.match(path.name)] if match)
    if not on_disk:
        raise FileNotFoundError("%s holds no contact file (contact.csv, or contact_<k>_<a>_<b>.csv "
                                "for a run of several interfaces)" % directory)
    return [Interface(number, None, None, name, _columns(directory / name))
            for number, name in on_disk]


def read_results(directory):
    """The Results of a result directory written by robin-run, robin-coordinator or
    robin-monolithic: two bodies (contact.csv) or a contact graph (one contact_<k>_<a>_<b>.csv
    per interface, listed in summary.json's "interfaces")."""
    directory = pathlib.Path(directory)
    with open(directory / "summary.json", encoding="utf-8") as file:
        summary = json.load(file)
    interfaces = _read_interfaces(directory, summary)
    history_path = directory / "history.csv"
    history = _columns(history_path) if history_path.is_file() else None
    bodies = {}
    pvd = ElementTree.parse(directory / "solution.pvd").getroot()
    for dataset in pvd.iter("DataSet"):
        file_name = dataset.get("file")
        bodies[pathlib.Path(file_name).stem] = read_vtu(directory / file_name)
    if len(interfaces) == 1 and interfaces[0].bodies is None and len(bodies) == 2:
        interfaces[0].bodies = tuple(bodies)  # an older two-body run: body 1, body 2
    return Results(directory, summary, None, history, bodies, interfaces=interfaces)


def run_case(case, overrides=None, output=None, tool="robin-run", bin_directory=None,
             arguments=(), quiet=True, timeout=None):
    """Runs the case file `case` with `tool` ("robin-run": the coupled Robin solve with one
    local server per body; "robin-monolithic": the single-process reference) and returns its
    Results.

    `overrides`: case-file keys to change for this run (--set, docs/case-format.md,
    "Overrides"), e.g. {"coupling.tolerance": 1e-10, "body[2].dirichlet[1].y": -0.02}.
    `output`: the result directory; it must not exist or be empty. None: a fresh directory
    under the system's temporary directory (robin-contact-*); the caller removes it.
    `bin_directory`: where the executables are (find_bin_directory). `arguments`: more
    command-line options (e.g. ["--algorithm", "robin-constant", "--alpha", "1e-4"]).
    `quiet`: pass --quiet (the tool logs only warnings and errors). `timeout`: seconds.

    Raises RunError when the tool exits with a non-zero status (bad input: 1, bad command
    line: 2, not converged: 3, diverged: 4, stagnated: 5; the results of 3 to 5 are in
    `output_directory`, readable with read_results)."""
    if tool not in TOOLS:
        raise ValueError("tool must be one of %s, got %r" % (", ".join(TOOLS), tool))
    executable = find_bin_directory(bin_directory) / tool
    if output is None:
        output = tempfile.mkdtemp(prefix="robin-contact-")
    output = pathlib.Path(output)
    command = [str(executable), str(case), "--output", str(output)]
    command += override_arguments(overrides)
    if quiet:
        command.append("--quiet")
    command += [str(argument) for argument in arguments]
    completed = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=timeout, check=False)
    log = completed.stderr
    if completed.returncode != 0:
        last_lines = "\n".join(log.strip().splitlines()[-5:])
        raise RunError("%s exited with status %d:\n%s" % (tool, completed.returncode, last_lines),
                       completed.returncode, command, output, log)
    results = read_results(output)
    results.exit_code = completed.returncode
    results.log = log
    return results
