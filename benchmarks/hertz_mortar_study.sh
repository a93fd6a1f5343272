#!/usr/bin/env bash
# Hertz on non-matching meshes with a true curved boundary (examples/hertz_cylinder.toml): the
# half-width a and the peak pressure p0 of the mortar solution against Hertz's, over several mesh
# sizes, with the observed order of convergence (docs/verification.md).
#   a and p0 of the solution: least-squares fit of p^2 = p0^2 (1 - x^2 / a^2) to the pressures of
#   the loaded constraints (contact.csv), the two outermost loaded ones left out;
#   Hertz: a_H = sqrt(4 P R / (pi E*)), p0_H = 2 P / (pi a_H), P the contact resultant, R = 1,
#   E* = E / (2 (1 - nu^2)) for the identical bodies.
# Usage: benchmarks/hertz_mortar_study.sh [build directory] [tool] [mesh sizes...]
#   tool: robin-monolithic (default) or robin-run
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
tool=${2:-robin-monolithic}
shift 2 || shift $# || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.2 0.1 0.05 0.025); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "machine: $(uname -m), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u +%Y-%m-%d)"
echo "command: benchmarks/hertz_mortar_study.sh $build $tool ${sizes[*]}"
echo
for size in "${sizes[@]}"; do
  case_file="$work/case_$size.toml"
  sed -e "s|^mesh_size = .*|mesh_size = $size|" \
      -e "s|^mesh = \"meshes/|mesh = \"$PWD/examples/meshes/|" examples/hertz_cylinder.toml > "$case_file"
  "$build/bin/$tool" "$case_file" --output "$work/out_$size" --log-level warn > "$work/log_$size" 2>&1 ||
    { echo "h = $size: $tool failed: $(tail -n 1 "$work/log_$size")"; continue; }
done
/usr/bin/python3 - "$work" "${sizes[@]}" <<'PY'
import csv, json, math, os, sys
import numpy as np
work, sizes = sys.argv[1], sys.argv[2:]
young, poisson, radius = 1000.0, 0.3, 1.0
effective = young / (2 * (1 - poisson**2))
rows = []
for size in sizes:
    directory = os.path.join(work, "out_" + size)
    if not os.path.exists(os.path.join(directory, "contact.csv")):
        continue
    with open(os.path.join(directory, "contact.csv")) as table:
        data = [(float(r["x"]), float(r["pressure"])) for r in csv.DictReader(table)]
    summary = json.load(open(os.path.join(directory, "summary.json")))
    load = abs(summary["contact_force_resultant"][1])
    loaded = sorted((x, p) for x, p in data if p > 1e-9 * max(p for _, p in data))
    inner = loaded[1:-1] if len(loaded) > 4 else loaded
    x = np.array([x for x, _ in inner]); p = np.array([p for _, p in inner])
    slope, intercept = np.polyfit(x**2, p**2, 1)
    peak, half_width = math.sqrt(intercept), math.sqrt(-intercept / slope)
    hertz_width = math.sqrt(4 * load * radius / (math.pi * effective))
    hertz_peak = 2 * load / (math.pi * hertz_width)
    rows.append((float(size), len(data), len(loaded), load, half_width, hertz_width, peak, hertz_peak))
print("| h | constraints | loaded | P | a | a (Hertz) | error a | p0 | p0 (Hertz) | error p0 | order a | order p0 |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
previous = None
for row in rows:
    size, count, loaded, load, a, a_h, p0, p0_h = row
    error_a, error_p = abs(a - a_h) / a_h, abs(p0 - p0_h) / p0_h
    order_a = order_p = ""
    if previous is not None:
        ratio = math.log(previous[0] / size)
        order_a = "%.2f" % (math.log(previous[1] / error_a) / ratio)
        order_p = "%.2f" % (math.log(previous[2] / error_p) / ratio)
    print(f"| {size:g} | {count} | {loaded} | {load:.5g} | {a:.5f} | {a_h:.5f} | {100 * error_a:.2f} % | "
          f"{p0:.4f} | {p0_h:.4f} | {100 * error_p:.2f} % | {order_a} | {order_p} |")
    previous = (size, error_a, error_p)
PY
