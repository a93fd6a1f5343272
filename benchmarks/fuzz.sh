#!/usr/bin/env bash
# The long fuzzing run (docs/fuzzing.md): configures and builds build-fuzz with clang and
# ROBIN_FUZZ=ON, runs each libFuzzer harness for RUNS inputs (default 10^6) from a fresh copy of
# its seed corpus in a scratch directory, and prints a table: harness, inputs executed, crashes
# (artifacts written), coverage (libFuzzer's final cov: and ft:), corpus size, wall time.
#
# Usage: benchmarks/fuzz.sh [harness...]   harnesses: server case_file mesh_data mesh_file (default all)
# Environment: RUNS (inputs per harness, default 1000000), BUILD (build directory, default
# build-fuzz), SCRATCH (scratch directory, default a new mktemp -d; kept, with each harness's
# log, corpus and crash artifacts), JOBS (build parallelism, default 2), TIMEOUT (seconds per
# input before libFuzzer reports a timeout, default 10), MAX_RESTARTS (after a crash the harness
# is started again on its grown corpus until RUNS inputs ran, at most this often, default 5).
set -euo pipefail
cd "$(dirname "$0")/.."

runs=${RUNS:-1000000}
build=${BUILD:-build-fuzz}
jobs=${JOBS:-2}
timeout=${TIMEOUT:-10}
max_restarts=${MAX_RESTARTS:-5}
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then harnesses=(server case_file mesh_data mesh_file); fi
for harness in "${harnesses[@]}"; do
  case "$harness" in
    server | case_file | mesh_data | mesh_file) ;;
    *) echo "fuzz.sh: unknown harness '$harness' (server, case_file, mesh_data, mesh_file)" >&2; exit 2 ;;
  esac
done
scratch=${SCRATCH:-$(mktemp -d "${TMPDIR:-/tmp}/robin-fuzz-run-XXXXXX")}
mkdir -p "$scratch"

targets=()
for harness in "${harnesses[@]}"; do targets+=("robin-fuzz-${harness//_/-}"); done
echo "fuzz.sh: building ${targets[*]} in $build" >&2
CC=clang CXX=clang++ cmake -S . -B "$build" -DROBIN_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DROBIN_BUILD_TESTS=OFF -DROBIN_BUILD_BENCHMARKS=OFF >"$scratch/configure.log"
cmake --build "$build" -j"$jobs" --target "${targets[@]}" >"$scratch/build.log"

# stat::NAME of a libFuzzer log (its -print_final_stats=1 lines); 0 when absent.
final_stat() { grep -a "^stat::$1:" "$2" | tail -n 1 | awk '{print $2}' || true; }

rows=()
for harness in "${harnesses[@]}"; do
  fuzzer="$build/bin/robin-fuzz-${harness//_/-}"
  corpus="$scratch/$harness/corpus"
  artifacts="$scratch/$harness/artifacts"
  rm -rf "${scratch:?}/$harness"
  mkdir -p "$corpus" "$artifacts"
  cp tests/fuzz/corpus/"$harness"/* "$corpus"/
  executed=0
  session=0
  cov="?"
  ft="?"
  start=$(date +%s.%N)
  echo "fuzz.sh: $harness: $runs inputs (log: $scratch/$harness/session-*.log)" >&2
  while [ "$executed" -lt "$runs" ] && [ "$session" -le "$max_restarts" ]; do
    log="$scratch/$harness/session-$session.log"
    status=0
    "$fuzzer" -runs=$((runs - executed)) -timeout="$timeout" -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" >"$log" 2>&1 || status=$?
    units=$(final_stat number_of_executed_units "$log")
    executed=$((executed + ${units:-0}))
    last=$(grep -a -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -n 1 || true)
    if [ -n "$last" ]; then
      cov=$(echo "$last" | awk '{print $2}')
      ft=$(echo "$last" | awk '{print $4}')
    fi
    session=$((session + 1))
    if [ "$status" -eq 0 ]; then break; fi
    echo "fuzz.sh: $harness: exit $status after ${units:-0} inputs (see $log)" >&2
    if [ -z "$units" ] || [ "$units" -eq 0 ]; then break; fi
  done
  seconds=$(awk -v start="$start" -v end="$(date +%s.%N)" 'BEGIN {print end - start}')
  crashes=$(find "$artifacts" -type f | wc -l)
  corpus_files=$(find "$corpus" -type f | wc -l)
  corpus_kib=$(find "$corpus" -type f -printf '%s\n' | awk '{s += $1} END {printf "%.0f", s / 1024}')
  rows+=("$(printf '| %-9s | %9s | %7s | %6s | %7s | %-22s | %8.0f s |' "$harness" "$executed" \
    "$crashes" "$cov" "$ft" "$corpus_files files, ${corpus_kib} KiB" "$seconds")")
done

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo)"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "command: RUNS=$runs benchmarks/fuzz.sh ${harnesses[*]}"
echo "scratch: $scratch"
echo
printf '| %-9s | %9s | %7s | %6s | %7s | %-22s | %10s |\n' harness inputs crashes cov ft corpus "wall time"
echo "|-----------|-----------|---------|--------|---------|------------------------|------------|"
for row in "${rows[@]}"; do echo "$row"; done
