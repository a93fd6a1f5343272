#!/usr/bin/python3
"""robin-run, robin-monolithic and GetFEM 5.4 on the same meshes (issue 16 item 6; docs/benchmarks.md).

    /usr/bin/python3 benchmarks/getfem_peer_benchmark.py [--build build] [--sizes 0.033 0.0104]
        [--large] [--repeats 3] [--large-repeats 1] [--getfem-max-res R]
        [--getfem-dirichlet eliminate] [--no-getfem] [--timeout 3600] [--keep DIR]

The case is the partial-contact two-block case, examples/two_blocks_partial.toml (lower block
[-1, 1] x [-1, 0] clamped at its bottom, upper block [-1, 1] x [0, 1] whose top is displaced by
(0, -0.01), E = 1000, nu = 0.3, plane strain, linear triangles, node-to-node contact on y = 0
with the initial gap d(x) = 0.02 x^2). For every mesh size h (default 0.033 and 0.0104, about
1e4 and 1e5 DOFs; --large adds 0.0033, about 1e6 DOFs, run --large-repeats times, default once;
on 2 shared cores GetFEM did not finish it within 48 minutes on 2026-11-26, and --timeout, default
3600 s, bounds every run: a GetFEM run killed by it leaves that size's GetFEM cells empty) the
script meshes both .geo bodies ONCE with the gmsh command line (`gmsh -2 -setnumber h H -format
msh22`; not timed), writes the case with the two .msh files instead of the .geo scripts, and
then runs, --repeats times interleaved (robin-run, robin-monolithic, GetFEM, robin-run, ...):

  (a) build/bin/robin-run CASE --output DIR (two robin-subdomain servers on this machine);
  (b) build/bin/robin-monolithic CASE --output DIR;
  (c) GetFEM 5.4 (python3-getfem, Debian's; seen only by /usr/bin/python3), in a child process
      of this script (`--getfem-worker`): both bodies in one gf.Model, one P1 vector field per
      body (the same .msh files, imported with gf.Mesh('import', 'gmsh', ...)), the isotropic
      linearized elasticity brick (plane strain Lame coefficients, exact one-point quadrature of
      the constant P1 strains), the supports eliminated from the unknowns (--getfem-dirichlet
      eliminate, default: a partial mesh_fem without the supported dofs; the upper body's top
      displacement t = (0, -0.01) is uniform, so u_upper = v + t with v = 0 on the top, t a
      rigid translation without strain, and the contact gap shifted by t_y: exactly the same
      discrete problem; GetFEM's own add_Dirichlet_condition_with_simplification, also
      available, costs 3.5 s per Newton iteration and body at 1e5 DOFs in GetFEM 5.4, and
      `penalization` uses add_Dirichlet_condition_with_penalization with 1e12), and
      the frictionless contact as GetFEM's basic contact brick between two deformable bodies
      (add_basic_contact_brick_two_deformable_bodies: B_N1 U_1 + B_N2 U_2 <= gap, the rows the
      node pairs of the contact line, u1_y - u2_y <= 0.02 x^2, non-symmetric Alart-Curnier
      augmented Lagrangian with r = E), solved by GetFEM's Newton (Model.solve, 'lsolver'
      'mumps', 'max_res' --getfem-max-res, default 1e-10, and 1e-9 from 1e6 DOFs: there GetFEM's
      residual stalls at 2.9e-10 once the active set is found (iteration 7 at 853668 DOFs,
      measured on 2026-11-29 with 'noisy'), so that 1e-10 ran its 100 iterations without
      converging); the same discrete problem as robin-run's.
      Skipped with a message when `import getfem` fails (apt-get install -y python3-getfem).

Times: wall time around each process (meshing excluded; reading the .msh files included for
every tool; GetFEM's includes starting Python and importing getfem, and it writes no VTU, while
robin-run and robin-monolithic write theirs), the median of the repeats. Peak RSS: VmHWM of every
process of the run, polled from /proc every 0.1 s (robin-run: the coordinator, the larger
server and their sum), and the exact ru_maxrss of wait4 for the single-process tools.

Agreement, from the last repeat: the contact nodal forces (contact.csv lambda1 against GetFEM's
multipliers, matched by x) as the largest difference relative to the largest force, and the
resultant contact force (summary.json contact_force_resultant against the sum of GetFEM's
multipliers) relative; the same for robin-run against robin-monolithic.

Prints the machine, the date, the command, the meshing times and two markdown tables.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from benchmark_support import (exit_on_sigterm, print_machine_header, read_csv_rows,
                               run_measured, scratch_directory, table_rule, tool_directory)

REPOSITORY = Path(__file__).resolve().parent.parent
CASE = REPOSITORY / "examples" / "two_blocks_partial.toml"
MESHES = REPOSITORY / "examples" / "meshes"
E, NU, TOP_DISPLACEMENT, GAP_C = 1000.0, 0.3, -0.01, 0.02  # as in two_blocks_partial.toml


# --------------------------------------------------------------------------- GetFEM worker

def physical_names(path):
    """{name: tag} of an MSH 2.2 file's $PhysicalNames."""
    text = Path(path).read_text(errors="replace")
    block = text.split("$PhysicalNames", 1)[1].split("$EndPhysicalNames", 1)[0].split("\n")
    names = {}
    for line in block[2:]:
        if line.strip():
            _, tag, name = line.split(maxsplit=2)
            names[name.strip().strip('"')] = int(tag)
    return names


def getfem_max_res(given, size):
    """--getfem-max-res, or the default for mesh size h = `size`."""
    if given is not None:
        return given
    return 1e-9 if size <= 0.005 else 1e-10


def getfem_worker(lower_path, upper_path, result_path, max_res, dirichlet):
    """Solves the two-block contact problem with GetFEM; writes the answer and stages as JSON."""
    stages = {}
    start = time.monotonic()
    import numpy as np
    import getfem as gf
    stages["import"] = time.monotonic() - start

    clock = time.monotonic()
    meshes = [gf.Mesh("import", "gmsh", str(lower_path)), gf.Mesh("import", "gmsh", str(upper_path))]
    regions = [physical_names(lower_path), physical_names(upper_path)]
    stages["mesh import"] = time.monotonic() - clock

    clock = time.monotonic()
    lame_lambda = E * NU / ((1 + NU) * (1 - 2 * NU))  # plane strain: the 3D Lame coefficients
    lame_mu = E / (2 * (1 + NU))
    model = gf.Model("real")
    model.add_initialized_data("lambda", [lame_lambda])
    model.add_initialized_data("mu", [lame_mu])
    supports = [("bottom", [0.0, 0.0]), ("top", [0.0, TOP_DISPLACEMENT])]
    fems, keeps = [], []
    for index, mesh in enumerate(meshes):
        fem = gf.MeshFem(mesh, 2)
        fem.set_classical_fem(1)  # P1, as robin's linear triangles
        integration = gf.MeshIm(mesh, gf.Integ("IM_TRIANGLE(1)"))  # exact for P1 stiffness
        region, value = supports[index]
        keep = np.arange(fem.nbdof())
        if dirichlet == "eliminate":
            # The supported dofs are removed from the unknowns (a partial mesh_fem). The upper
            # body's prescribed displacement t = (0, -0.01) of its top is uniform: u1 = v1 + t
            # with v1 = 0 on the top, and t, a rigid translation, has no strain, so v1 solves
            # the same elasticity problem and only the contact gap moves by t_y (below).
            keep = np.setdiff1d(keep, fem.basic_dof_on_region(regions[index][region]))
            unknowns = gf.MeshFem("partial", fem, keep)
        else:
            unknowns = fem
        model.add_fem_variable(f"u{index}", unknowns)
        model.add_isotropic_linearized_elasticity_brick(integration, f"u{index}", "lambda", "mu")
        model.add_initialized_data(f"{region}_value", value)
        if dirichlet == "simplification":
            model.add_Dirichlet_condition_with_simplification(f"u{index}", regions[index][region],
                                                              f"{region}_value")
        elif dirichlet == "penalization":
            model.add_Dirichlet_condition_with_penalization(integration, f"u{index}", 1e12,
                                                            regions[index][region],
                                                            f"{region}_value")
        fems.append(fem)
        keeps.append(keep)

    def contact_y_dofs(fem, region):
        dofs = fem.basic_dof_on_region(region)
        nodes = fem.basic_dof_nodes(dofs)
        # vector P1: the two components of a node are consecutive dofs, x first
        return sorted((float(nodes[0, i]), int(dof)) for i, dof in enumerate(dofs) if dof % 2 == 1)

    lower = contact_y_dofs(fems[0], regions[0]["contact"])
    upper = contact_y_dofs(fems[1], regions[1]["contact"])
    if len(lower) != len(upper) or any(abs(a[0] - b[0]) > 1e-9 for a, b in zip(lower, upper)):
        raise SystemExit("the contact nodes of the two meshes do not match")
    rows = len(lower)
    bn1 = gf.Spmat("empty", rows, len(keeps[0]))
    bn2 = gf.Spmat("empty", rows, len(keeps[1]))
    for row, ((_, dof1), (_, dof2)) in enumerate(zip(lower, upper)):
        # column: the dof's place among the unknowns (keep is sorted; the contact line is not
        # supported, so every contact dof is kept)
        bn1[row, int(np.searchsorted(keeps[0], dof1))] = 1.0   # u1 . n1, n1 = (0, 1)
        bn2[row, int(np.searchsorted(keeps[1], dof2))] = -1.0  # u2 . n2, n2 = (0, -1)
    xs = np.array([x for x, _ in lower])
    gap = GAP_C * xs ** 2
    if dirichlet == "eliminate":
        gap = gap + TOP_DISPLACEMENT  # u0_y - (v1_y + t_y) <= d
    model.add_variable("lambda_n", rows)
    model.add_initialized_data("r", [E])
    model.add_initialized_data("gap", gap)
    model.add_basic_contact_brick_two_deformable_bodies("u0", "u1", "lambda_n", "r", bn1, bn2,
                                                        "gap")
    stages["model"] = time.monotonic() - clock

    clock = time.monotonic()
    # "noisy": the residual of every Newton iteration goes to the worker's log (kept with --keep)
    iterations, converged = model.solve("noisy", "max_iter", 100, "max_res", max_res, "lsolver",
                                        "mumps")
    stages["newton (assembly + MUMPS)"] = time.monotonic() - clock
    forces = -np.asarray(model.variable("lambda_n"))  # GetFEM's multiplier is <= 0 in contact
    result = {
        "dofs": int(len(keeps[0]) + len(keeps[1])), "dirichlet": dirichlet,
        "newton_iterations": int(iterations), "converged": bool(converged),
        "x": xs.tolist(), "force": forces.tolist(), "resultant": float(forces.sum()),
        "stages": stages, "in_process": time.monotonic() - start,
    }
    Path(result_path).write_text(json.dumps(result))


# --------------------------------------------------------------------------- measuring

def read_contact_csv(path):
    rows = read_csv_rows(path)
    rows.sort(key=lambda row: float(row["x"]))
    return [float(row["x"]) for row in rows], [float(row["lambda1"]) for row in rows]


def compare(reference_x, reference_force, x, force):
    """Largest nodal force difference relative to the reference's largest force."""
    if len(reference_x) != len(x) or any(abs(a - b) > 1e-9 for a, b in zip(reference_x, x)):
        return float("nan")
    scale = max(abs(value) for value in reference_force)
    return max(abs(a - b) for a, b in zip(reference_force, force)) / scale


def mib(kib):
    """MiB of a peak in KiB; "–" when the polling saw no sample (a run shorter than 0.1 s)."""
    return f"{kib / 1024:.0f}" if kib > 0 else "–"


# --------------------------------------------------------------------------- driver

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=str(REPOSITORY / "build"),
                        help="build directory holding bin/robin-run, bin/robin-monolithic")
    parser.add_argument("--sizes", type=float, nargs="+", default=[0.033, 0.0104],
                        help="mesh sizes h (default 0.033 0.0104: about 1e4 and 1e5 DOFs)")
    parser.add_argument("--large", action="store_true", help="add h = 0.0033 (about 1e6 DOFs)")
    parser.add_argument("--repeats", type=int, default=3, help="interleaved runs per size")
    parser.add_argument("--large-repeats", type=int, default=1,
                        help="interleaved runs for h <= 0.005 (about 1e6 DOFs: GetFEM takes "
                             "more than 48 minutes per run on 2 shared cores)")
    parser.add_argument("--getfem-max-res", type=float, default=None,
                        help="GetFEM Newton's residual target (its 'max_res'); default 1e-10, "
                        "1e-9 at h <= 0.005 (about 1e6 DOFs), where 1e-10 is below its "
                        "rounding floor")
    parser.add_argument("--getfem-dirichlet", default="eliminate",
                        choices=["eliminate", "simplification", "penalization"],
                        help="how GetFEM imposes the supports (default eliminate, see above)")
    parser.add_argument("--no-getfem", action="store_true", help="skip the GetFEM column")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds per run")
    parser.add_argument("--keep", help="keep the scratch directory here")
    parser.add_argument("--getfem-worker", nargs=3, metavar=("LOWER", "UPPER", "RESULT"),
                        help=argparse.SUPPRESS)
    arguments = parser.parse_args()
    if arguments.getfem_worker:
        getfem_worker(*arguments.getfem_worker, arguments.getfem_max_res or 1e-10,
                      arguments.getfem_dirichlet)
        return 0

    binaries = tool_directory(arguments.build,
                              ("robin-run", "robin-subdomain", "robin-monolithic"))
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        sys.exit("the gmsh command is needed to mesh the bodies (apt-get install -y gmsh)")
    sizes = list(arguments.sizes) + ([0.0033] if arguments.large else [])
    getfem_note = None
    if arguments.no_getfem:
        getfem_note = "GetFEM column skipped (--no-getfem)"
    else:
        probe = subprocess.run([sys.executable, "-c", "import getfem"], capture_output=True,
                               text=True, check=False)
        if probe.returncode != 0:
            getfem_note = ("GetFEM column skipped: `import getfem` failed in "
                           f"{sys.executable} ({probe.stderr.strip().splitlines()[-1]}); "
                           "install python3-getfem and run with /usr/bin/python3")
    if getfem_note:
        print(getfem_note, flush=True)
    use_getfem = getfem_note is None

    print_machine_header()

    scratch = scratch_directory(arguments.keep, "robin-getfem-peer-")
    template = CASE.read_text()
    results = []
    try:
        for size in sizes:
            work = scratch / f"h_{size}"
            work.mkdir()
            case_text = template
            for body in ("lower", "upper"):
                clock = time.monotonic()
                subprocess.run([gmsh, "-2", "-setnumber", "h", repr(size), "-format", "msh22",
                                str(MESHES / f"block_{body}.geo"), "-o", str(work / f"{body}.msh")],
                               check=True, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
                print(f"h = {size}: meshed {body} in {time.monotonic() - clock:.1f} s (not timed "
                      "below)", flush=True)
                case_text = case_text.replace(f'mesh = "meshes/block_{body}.geo"',
                                              f'mesh = "{work / (body + ".msh")}"')
            case_text = "\n".join(line for line in case_text.split("\n")
                                  if not line.startswith("mesh_size"))
            case = work / "case.toml"
            case.write_text(case_text)

            walls = {"dd": [], "mono": [], "getfem": []}
            rss = {"dd": [], "mono": [], "getfem": []}
            repeats = arguments.large_repeats if size <= 0.005 else arguments.repeats
            for repeat in range(repeats):
                out = work / f"dd_{repeat}"
                status, wall, _, peaks = run_measured(
                    [str(binaries / "robin-run"), str(case), "--output", str(out), "--quiet"],
                    work / f"dd_{repeat}.log", arguments.timeout)
                if status != 0:
                    sys.exit(f"robin-run exit {status} at h = {size}: see {work}/dd_{repeat}.log")
                walls["dd"].append(wall)
                servers = [kib for name, kib in peaks.values() if name.startswith("robin-subdom")]
                coordinator = max((kib for name, kib in peaks.values()
                                   if name.startswith("robin-run")), default=0)
                rss["dd"].append((coordinator, max(servers, default=0), coordinator + sum(servers)))

                out = work / f"mono_{repeat}"
                status, wall, maxrss, _ = run_measured(
                    [str(binaries / "robin-monolithic"), str(case), "--output", str(out),
                     "--quiet"], work / f"mono_{repeat}.log", arguments.timeout)
                if status != 0:
                    sys.exit(f"robin-monolithic exit {status} at h = {size}")
                walls["mono"].append(wall)
                rss["mono"].append(maxrss)

                if use_getfem:
                    environment = dict(os.environ)
                    status, wall, maxrss, _ = run_measured(
                        [sys.executable, str(Path(__file__).resolve()), "--getfem-max-res",
                         repr(getfem_max_res(arguments.getfem_max_res, size)), "--getfem-dirichlet",
                         arguments.getfem_dirichlet, "--getfem-worker",
                         str(work / "lower.msh"), str(work / "upper.msh"),
                         str(work / f"getfem_{repeat}.json")],
                        work / f"getfem_{repeat}.log", arguments.timeout, environment)
                    if status != 0:
                        print(f"GetFEM exit {status} at h = {size}: "
                              + (work / f"getfem_{repeat}.log").read_text()[-500:], flush=True)
                        use_getfem = False
                    else:
                        walls["getfem"].append(wall)
                        rss["getfem"].append(maxrss)
                print(f"h = {size}, run {repeat + 1}: robin-run {walls['dd'][-1]:.2f} s, "
                      f"robin-monolithic {walls['mono'][-1]:.2f} s"
                      + (f", GetFEM {walls['getfem'][-1]:.2f} s" if walls["getfem"] else ""),
                      flush=True)

            last = repeats - 1
            summary = json.loads((work / f"dd_{last}" / "summary.json").read_text())
            mono_summary = json.loads((work / f"mono_{last}" / "summary.json").read_text())
            dd_x, dd_force = read_contact_csv(work / f"dd_{last}" / "contact.csv")
            mono_x, mono_force = read_contact_csv(work / f"mono_{last}" / "contact.csv")
            dd_resultant = summary["interfaces"][0]["contact_force_resultant"][1]
            mono_resultant = mono_summary["interfaces"][0]["contact_force_resultant"][1]
            row = {
                "h": size, "dofs": sum(body["dofs"] for body in summary["bodies"]),
                "pairs": summary["contact_pairs"], "iterations": summary["iterations"],
                "mono_iterations": mono_summary.get("iterations"),
                "walls": {key: statistics.median(value) for key, value in walls.items() if value},
                "rss": rss, "dd_resultant": dd_resultant,
                "mono_force": compare(mono_x, mono_force, dd_x, dd_force),
                "mono_resultant": abs(dd_resultant - mono_resultant) / abs(mono_resultant),
                "profile": summary["profile"], "repeats": repeats,
            }
            if walls["getfem"]:
                peer = json.loads((work / f"getfem_{last}.json").read_text())
                row.update(getfem=peer,
                           getfem_force=compare(peer["x"], peer["force"], dd_x, dd_force),
                           getfem_resultant=abs(dd_resultant - peer["resultant"])
                           / abs(peer["resultant"]))
                print(f"    GetFEM: {peer['dofs']} unknowns ({peer['dirichlet']}), max_res "
                      f"{getfem_max_res(arguments.getfem_max_res, size):g}, "
                      f"{peer['newton_iterations']} Newton iterations, converged "
                      f"{peer['converged']}; stages " + ", ".join(
                          f"{name} {value:.2f} s" for name, value in peer["stages"].items()),
                      flush=True)
            profile = summary["profile"]
            print(f"    robin-run: {row['iterations']} iterations; profile " + ", ".join(
                f"{key} {profile[key]:.3f} s" for key in ("launch", "meshing", "setup",
                                                           "contact_assignment", "iterations",
                                                           "fields", "output")), flush=True)
            results.append(row)
    finally:
        if not arguments.keep:
            shutil.rmtree(scratch, ignore_errors=True)

    def median_rss(values, index=None):
        return statistics.median(value if index is None else value[index] for value in values)

    print("\nTimes (median of the interleaved runs; meshing excluded) and peak RSS (median; MiB; "
          "–: the process ended before the first 0.1 s poll):\n")
    print("| h | DOFs | runs | contact pairs | robin-run wall | robin-monolithic wall | GetFEM wall | "
          "GetFEM / robin-run | robin-run peak RSS: coordinator, larger server (sum) | "
          "robin-monolithic peak RSS | GetFEM peak RSS |")
    print(table_rule(11))
    for row in results:
        walls = row["walls"]
        getfem = "getfem" in walls
        dd_rss = row["rss"]["dd"]
        print(f"| {row['h']} | {row['dofs']} | {row['repeats']} | {row['pairs']} | "
              f"{walls['dd']:.2f} s | "
              f"{walls['mono']:.2f} s | "
              + (f"{walls['getfem']:.2f} s | {walls['getfem'] / walls['dd']:.1f} | " if getfem
                 else "– | – | ")
              + f"{mib(median_rss(dd_rss, 0))}, {mib(median_rss(dd_rss, 1))} "
              f"({mib(median_rss(dd_rss, 2))}) | {mib(median_rss(row['rss']['mono']))} | "
              + (f"{mib(median_rss(row['rss']['getfem']))} |" if getfem else "– |"))
    print("\nAnswers (last run of each size): robin-run's contact nodal forces against GetFEM's "
          "and robin-monolithic's (largest difference / largest force), and the resultant "
          "contact force (relative difference):\n")
    print("| h | DOFs | robin-run iterations | GetFEM Newton iterations | resultant (robin-run) | "
          "forces vs GetFEM | resultant vs GetFEM | forces vs robin-monolithic | "
          "resultant vs robin-monolithic |")
    print(table_rule(9))
    for row in results:
        peer = row.get("getfem")
        print(f"| {row['h']} | {row['dofs']} | {row['iterations']} | "
              + (f"{peer['newton_iterations']} | " if peer else "– | ")
              + f"{row['dd_resultant']:.6f} | "
              + (f"{row['getfem_force']:.1e} | {row['getfem_resultant']:.1e} | " if peer
                 else "– | – | ")
              + f"{row['mono_force']:.1e} | {row['mono_resultant']:.1e} |")
    if getfem_note:
        print(f"\n{getfem_note}")
    return 0


if __name__ == "__main__":
    exit_on_sigterm()
    sys.exit(main())
