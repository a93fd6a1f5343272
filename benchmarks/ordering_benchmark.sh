#!/usr/bin/env bash
# Usage: benchmarks/ordering_benchmark.sh BUILD_DIR CASE MESH_SIZE... [-- --factorize]
# The fill-reducing ordering of each body's stiffness on the graph of the dofs (CHOLMOD's own
# choice) against the graph of the nodes (subdomain/numerics/fill_reducing_ordering.hpp), for
# each mesh size: one markdown table per size (benchmarks/ordering_benchmark.cpp).
# Example: benchmarks/ordering_benchmark.sh build examples/two_blocks_partial.toml 0.033 0.0104
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 BUILD_DIR CASE MESH_SIZE... [-- --factorize]" >&2
  exit 2
fi
build=$1
case_file=$2
shift 2
sizes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  sizes+=("$1")
  shift
done
extra=()
if [ $# -gt 0 ]; then
  shift
  extra=("$@")
fi
for size in "${sizes[@]}"; do
  echo "### $(basename "$case_file") at h = $size"
  echo
  "$build/benchmarks/ordering_benchmark" "$case_file" "$size" "${extra[@]}"
  echo
done
