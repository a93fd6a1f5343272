#!/usr/bin/env bash
# robin-run with its servers' BLAS and OpenMP threads set by --threads-per-server (issue 16
# item 2; docs/benchmarks.md, "One BLAS thread per local server on two cores"): whole runs of one
# case, the wall, user and system seconds measured around the process by /usr/bin/time, the
# thread counts interleaved round by round so that a changing machine load spreads over them.
# Prints every run and the median wall time of each thread count.
# Usage: benchmarks/threads_per_server_benchmark.sh RUNS CASE [BUILD] [THREADS...]
#   e.g. benchmarks/threads_per_server_benchmark.sh 5 case_0.0104.toml build 1 2
set -euo pipefail
runs=${1:?usage: benchmarks/threads_per_server_benchmark.sh RUNS CASE [BUILD] [THREADS...]}
case_file=${2:?usage: benchmarks/threads_per_server_benchmark.sh RUNS CASE [BUILD] [THREADS...]}
build=${3:-build}
shift $(($# < 3 ? $# : 3))
counts=("$@")
if [ ${#counts[@]} -eq 0 ]; then counts=(1 2); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "command: benchmarks/threads_per_server_benchmark.sh $runs $case_file $build ${counts[*]}"
for round in $(seq "$runs"); do
  for threads in "${counts[@]}"; do
    /usr/bin/time -f "$threads %e %U %S" -a -o "$work/times" \
      "$build/bin/robin-run" "$case_file" --output "$work/out_$threads" --overwrite --quiet \
      --threads-per-server "$threads" > /dev/null
    echo "round $round, $threads thread(s) per server: $(tail -1 "$work/times" | cut -d' ' -f2-) (wall user system, s)"
  done
done
for threads in "${counts[@]}"; do
  median=$(awk -v t="$threads" '$1 == t { print $2 }' "$work/times" | sort -g |
    awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }')
  echo "$threads thread(s) per server: median wall $median s over $runs runs"
done
