#!/usr/bin/env bash
# The cost of a quasi-static load step against a fresh run of the same load (docs/benchmarks.md,
# "Load steps"): robin-run on examples/hertz_steps.toml (the Hertz cylinder pressed down in four
# steps, factors 0.25, 0.5, 0.75, 1) at several mesh sizes, three ways:
#   steps, warm   the case as shipped: one setup, each step starting from the previous one;
#   steps, cold   the same with [loading] warm_start = false: each step from the gap;
#   fresh         examples/hertz.toml (the same case at load factor 1, no [loading]): a whole
#                 run of the final load, setup included.
# Prints, per mesh size, one row per step (iterations; the step's wall time: SetLoadFactor, the
# iteration and the fields) and the fresh run (iterations; its wall time after the setup: the
# iteration and the fields), with each run's setup (meshing, assembly, factorization, F) and
# total wall times.
# Usage: benchmarks/load_steps_benchmark.sh [build directory] [mesh sizes...]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.1 0.05 0.025); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u +%Y-%m-%d)"
echo "command: benchmarks/load_steps_benchmark.sh $build ${sizes[*]}"
echo
echo "| h | DOFs | run | step (factor) | iterations | step: iteration + fields (s) | setup (s) | total (s) |"
echo "|---|---|---|---|---|---|---|---|"
for size in "${sizes[@]}"; do
  for name in hertz_steps hertz; do
    sed -e "s|^mesh_size = .*|mesh_size = $size|" \
        -e "s|^mesh = \"meshes/|mesh = \"$PWD/examples/meshes/|" "examples/$name.toml" \
        > "$work/$name.toml"
  done
  sed -e "s|^factors = .*|factors = [0.25, 0.5, 0.75, 1.0]\nwarm_start = false|" \
      "$work/hertz_steps.toml" > "$work/hertz_cold.toml"
  for run in warm cold fresh; do
    case $run in
      warm) case_file="$work/hertz_steps.toml" ;;
      cold) case_file="$work/hertz_cold.toml" ;;
      fresh) case_file="$work/hertz.toml" ;;
    esac
    "$build/bin/robin-run" "$case_file" --output "$work/$run-$size" > "$work/$run-$size.log" 2>&1 \
      || { echo "robin-run failed on $case_file:"; tail -5 "$work/$run-$size.log"; exit 1; }
    /usr/bin/python3 - "$work/$run-$size" "$size" "$run" <<'PYTHON'
import json, sys
directory, size, run = sys.argv[1:4]
summary = json.load(open(directory + "/summary.json"))
dofs = sum(body["dofs"] for body in summary["bodies"])
timings = summary["timings"]
label = {"warm": "steps, warm", "cold": "steps, cold", "fresh": "fresh (factor 1)"}[run]
if "load_steps" in summary:
    for step in summary["load_steps"]:
        print("| %s | %d | %s | %d (%g) | %d | %.3f | %.3f | %.3f |" % (
            size, dofs, label, step["step"], step["load_factor"], step["iterations"],
            step["seconds"], timings["setup"], timings["total"]))
else:
    print("| %s | %d | %s | – (1) | %d | %.3f | %.3f | %.3f |" % (
        size, dofs, label, summary["iterations"], timings["total"] - timings["setup"],
        timings["setup"], timings["total"]))
PYTHON
  done
done
