#!/usr/bin/env bash
# Prints the numerical-core benchmark table (docs/benchmarks.md) for the two-block case at about
# 1e4, 1e5 and 1e6 degrees of freedom. Each size runs in its own process so that the peak
# memory is that size's. Usage: benchmarks/core_benchmark.sh [build directory] [mesh sizes...]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.033 0.0104 0.0033); fi

echo "machine: $(uname -m), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "command: benchmarks/core_benchmark.sh $build ${sizes[*]}"
echo
printf '| %-7s | %-8s | %-6s | %-9s | %-9s | %-11s | %-8s | %-9s | %-9s | %-15s | %-15s | %-14s | %-8s |\n' \
  h DOFs pairs "assembly" "factor" "factor nnz" "peak MB" "1 solve" "dense F" "contact (dense)" "contact (fact.)" "monolithic" "total"
printf '|%s|\n' "---------|----------|--------|-----------|-----------|-------------|----------|-----------|-----------|-----------------|-----------------|----------------|----------"
for size in "${sizes[@]}"; do
  line=$("$build/benchmarks/core_benchmark" examples/two_blocks_partial.toml "$size")
  value() { echo "$line" | tr ' ' '\n' | grep "^$1=" | cut -d= -f2; }
  printf '| %-7s | %-8s | %-6s | %-9s | %-9s | %-11s | %-8s | %-9s | %-9s | %-15s | %-15s | %-14s | %-8s |\n' \
    "$size" "$(value dofs)" "$(value contact_pairs)" "$(value assembly_seconds) s" \
    "$(value factorization_seconds) s" "$(value factor_nonzeros)" "$(value peak_memory_mb)" \
    "$(value one_solve_seconds) s" "$(value dense_interface_seconds) s" \
    "$(value dense_contact_iterations) it $(value dense_contact_seconds) s" \
    "$(value factor_contact_iterations) it $(value factor_contact_seconds) s" \
    "$(value monolithic_iterations) it $(value monolithic_seconds) s" "$(value total_seconds) s"
done
