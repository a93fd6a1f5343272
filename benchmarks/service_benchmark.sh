#!/usr/bin/env bash
# Prints the coupled-service benchmark table (docs/benchmarks.md): the partial-contact two-block
# case at several mesh sizes (about 1e4, 1e5 and 1e6 DOFs by default), solved by robin-run (two
# robin-subdomain processes over tcp://127.0.0.1) and by robin-monolithic.
# Usage: [INTERFACE_OPERATOR=auto|dense|factor] [LINEAR_SOLVER=direct|multigrid] benchmarks/service_benchmark.sh [build directory] [mesh sizes...]
# INTERFACE_OPERATOR sets [solver] interface_operator (default: the case's, i.e. auto),
# LINEAR_SOLVER [solver] linear_solver (default: the case's, i.e. "auto": direct for these bodies).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.033 0.0104 0.0033); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "command: INTERFACE_OPERATOR=${INTERFACE_OPERATOR:-} ${LINEAR_SOLVER:+LINEAR_SOLVER=$LINEAR_SOLVER }benchmarks/service_benchmark.sh $build ${sizes[*]}"
echo
printf '| %-7s | %-8s | %-5s | %-5s | %-10s | %-10s | %-10s | %-8s | %-9s | %-11s | %-10s | %-10s | %-9s |\n' \
  h DOFs pairs iter "DD wall" "DD setup" "DD iter." "mono" "DD/mono" "bytes/iter" "msg/iter." "msg/wall" "per iter"
printf '|%s|\n' "---------|----------|-------|-------|------------|------------|------------|----------|-----------|-------------|------------|------------|-----------"
for size in "${sizes[@]}"; do
  case_file="$work/case_$size.toml"
  sed -e "s|^mesh_size = .*|mesh_size = $size|" \
      -e "s|^mesh = \"meshes/|mesh = \"$PWD/examples/meshes/|" examples/two_blocks_partial.toml > "$case_file"
  if [ -n "${INTERFACE_OPERATOR:-}" ] || [ -n "${LINEAR_SOLVER:-}" ]; then
    printf '\n[solver]\n' >> "$case_file"
    if [ -n "${INTERFACE_OPERATOR:-}" ]; then
      printf 'interface_operator = "%s"\n' "$INTERFACE_OPERATOR" >> "$case_file"
    fi
    if [ -n "${LINEAR_SOLVER:-}" ]; then
      printf 'linear_solver = "%s"\n' "$LINEAR_SOLVER" >> "$case_file"
    fi
  fi
  dd_start=$(date +%s.%N)
  dd_status=0
  "$build/bin/robin-run" "$case_file" --output "$work/dd_$size" --log-level warn > "$work/dd_$size.log" 2>&1 || dd_status=$?
  dd_end=$(date +%s.%N)
  if [ ! -f "$work/dd_$size/summary.json" ]; then
    echo "| $size | robin-run failed with exit $dd_status and wrote no summary: $(tail -n 1 "$work/dd_$size.log") |"
    continue
  fi
  "$build/bin/robin-monolithic" "$case_file" --output "$work/mono_$size" --log-level warn > /dev/null 2>&1
  mono_end=$(date +%s.%N)
  /usr/bin/python3 - "$work/dd_$size/summary.json" "$size" "$dd_start" "$dd_end" "$mono_end" "$dd_status" <<'PY'
import json, sys
summary = json.load(open(sys.argv[1]))
size = sys.argv[2]
dd_start, dd_end, mono_end = (float(value) for value in sys.argv[3:6])
status = int(sys.argv[6])
dd_wall, mono_wall = dd_end - dd_start, mono_end - dd_end
timings = summary["timings"]
dofs = sum(body["dofs"] for body in summary["bodies"])
iterations = summary["iterations"]
if status != 0:  # not converged: the row says so instead of passing for a result
    iterations = "%d (exit %d: %s)" % (iterations, status, summary["status"])
per_iteration = timings["iteration"] / max(1, summary["iterations"])
print(f"| {size:<7} | {dofs:<8} | {summary['contact_pairs']:<5} | {iterations:<5} | {dd_wall:8.2f} s | "
      f"{timings['setup']:8.2f} s | {timings['iteration']:8.3f} s | {mono_wall:6.2f} s | "
      f"{dd_wall / mono_wall:9.2f} | {summary['bytes_per_iteration']:11.0f} | "
      f"{100 * timings['messaging_share_of_iteration']:8.1f} % | "
      f"{100 * timings['messaging'] / dd_wall:8.3f} % | {1000 * per_iteration:6.2f} ms |")
PY
done
