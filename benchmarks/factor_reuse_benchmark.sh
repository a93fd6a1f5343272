#!/usr/bin/env bash
# A later run of the same bodies on long-running servers (docs/benchmarks.md, "Reuse of the
# factor"): two robin-subdomain servers started once, then robin-coordinator on
# examples/hertz.toml twice against them, the second time with the cylinder pressed 20 % deeper
# (--set on its top's prescribed displacement). The second SetupBody of each server keeps the
# first run's factor (and F: the contact rows are the same) and only assembles the new loads.
# Prints, per mesh size, both runs: the servers' SetupBody time (the larger of the two, from
# their logs), the coordinator's setup and meshing time (summary.json timings.setup, .meshing)
# and the run's wall time.
# Usage: benchmarks/factor_reuse_benchmark.sh [build directory] [mesh sizes...]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.05 0.025 0.0125); fi
work=$(mktemp -d)
servers=()
cleanup() {
  for pid in "${servers[@]}"; do kill "$pid" 2> /dev/null || true; done
  wait 2> /dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

# start_server NAME: a robin-subdomain on an ephemeral port; sets `endpoint`.
start_server() {
  local log=$work/$1.log
  "$build/bin/robin-subdomain" --listen 'tcp://127.0.0.1:*' --name "$1" > "$work/$1.out" \
    2> "$log" &
  servers+=($!)
  for _ in $(seq 100); do
    endpoint=$(sed -n 's/^listening on //p' "$work/$1.out")
    [ -n "$endpoint" ] && return
    sleep 0.1
  done
  echo "robin-subdomain $1 did not start: $(cat "$log")" >&2
  exit 1
}

# The duration of the last SetupBody in a server's log, in seconds.
last_setup_seconds() {
  grep 'SetupBody' "$1" | tail -1 | sed -E 's/.*\(([0-9.]+) ms\)$/\1/' |
    awk '{printf "%.2f", $1 / 1000}'
}

echo "machine: $(uname -m), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u +%Y-%m-%d)"
echo "command: benchmarks/factor_reuse_benchmark.sh $build ${sizes[*]}"
echo
echo "| h | DOFs | run | server SetupBody (s) | coordinator setup (s) | meshing (s) | wall (s) |"
echo "|---|---|---|---|---|---|---|"
for size in "${sizes[@]}"; do
  servers=()
  start_server flat
  flat=$endpoint
  start_server cylinder
  cylinder=$endpoint
  for run in first second; do
    overrides=(--set "body[1].mesh_size=$size" --set "body[2].mesh_size=$size")
    [ "$run" = second ] && overrides+=(--set 'body[2].dirichlet[1].y=-0.006')
    output=$work/$size-$run
    start=$(date +%s%N)
    "$build/bin/robin-coordinator" examples/hertz.toml --subdomain "$flat" \
      --subdomain "$cylinder" --output "$output" --quiet "${overrides[@]}" 2> "$work/run.log" ||
      { cat "$work/run.log" >&2; exit 1; }
    wall_nanoseconds=$(($(date +%s%N) - start))
    /usr/bin/python3 - "$output/summary.json" "$size" "$run" "$wall_nanoseconds" \
      "$(last_setup_seconds "$work/flat.log")" "$(last_setup_seconds "$work/cylinder.log")" << 'EOF'
import json, sys
summary = json.load(open(sys.argv[1]))
size, run, wall, flat, cylinder = sys.argv[2:7]
dofs = sum(body["dofs"] for body in summary["bodies"])
timings = summary["timings"]
print("| %s | %d | %s | %.2f | %.2f | %.2f | %.2f |" % (
    size, dofs, run, max(float(flat), float(cylinder)), timings["setup"], timings["meshing"],
    int(wall) / 1e9))
EOF
  done
  for pid in "${servers[@]}"; do kill "$pid" 2> /dev/null || true; done
  wait 2> /dev/null || true
done
