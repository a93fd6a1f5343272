#!/usr/bin/env bash
# The cost of building the mortar coupling against the rest of the set-up (docs/benchmarks.md):
# robin-run on the non-matching blocks (examples/non_matching_blocks.toml) at several mesh sizes
# (about 1e4, 1e5 and 1e6 DOFs by default). Prints one table row per size: DOFs, constraints,
# meshing (coordinator side, both bodies at once), the servers' setup, the mortar coupling, its
# share of the whole set-up, iterations, wall time, and the largest deviation of the pressure from
# the patch test's exact value.
# Usage: benchmarks/mortar_benchmark.sh [build directory] [mesh sizes...]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.02 0.0063 0.002); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u +%Y-%m-%d)"
echo "command: benchmarks/mortar_benchmark.sh $build ${sizes[*]}"
echo
printf '| %-7s | %-8s | %-11s | %-9s | %-11s | %-14s | %-14s | %-4s | %-9s | %-14s |\n' \
  h DOFs constraints meshing "server setup" "mortar coupling" "share of setup" iter "wall" "pressure error"
printf '|%s|\n' "---------|----------|-------------|-----------|-------------|----------------|----------------|------|-----------|----------------"
for size in "${sizes[@]}"; do
  case_file="$work/case_$size.toml"
  sed -e "s|^mesh_size = .*|mesh_size = $size|" \
      -e "s|^mesh = \"meshes/|mesh = \"$PWD/examples/meshes/|" examples/non_matching_blocks.toml > "$case_file"
  start=$(date +%s.%N)
  status=0
  "$build/bin/robin-run" "$case_file" --output "$work/run_$size" --log-level warn > "$work/run_$size.log" 2>&1 || status=$?
  end=$(date +%s.%N)
  if [ ! -f "$work/run_$size/summary.json" ]; then
    echo "| $size | robin-run failed with exit $status: $(tail -n 1 "$work/run_$size.log") |"
    continue
  fi
  /usr/bin/python3 - "$work/run_$size" "$size" "$start" "$end" "$status" <<'PY'
import csv, json, sys
directory, size = sys.argv[1], sys.argv[2]
wall = float(sys.argv[4]) - float(sys.argv[3])
status = int(sys.argv[5])
summary = json.load(open(directory + "/summary.json"))
timings = summary["timings"]
dofs = sum(body["dofs"] for body in summary["bodies"])
exact = 0.01 / (0.5 * (1 - 0.3**2) / 1000 + 0.4 * (1 - 0.25**2) / 400)
with open(directory + "/contact.csv") as table:
    error = max(abs(float(row["pressure"]) - exact) / exact for row in csv.DictReader(table))
servers = timings["setup"] - timings["meshing"] - timings["contact_coupling"]
iterations = summary["iterations"] if status == 0 else "%d (exit %d)" % (summary["iterations"], status)
print(f"| {size:<7} | {dofs:<8} | {summary['contact_pairs']:<11} | {timings['meshing']:7.2f} s | "
      f"{servers:9.2f} s | {1000 * timings['contact_coupling']:11.1f} ms | "
      f"{100 * timings['contact_coupling'] / timings['setup']:12.2f} % | {iterations:<4} | "
      f"{wall:7.2f} s | {error:14.1e} |")
PY
done
