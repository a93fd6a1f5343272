#!/usr/bin/env bash
# The fixed costs of robin-run against robin-monolithic at small sizes (issue 16 item 2): the
# wall time of whole runs, measured around the process, of the partial-contact two-block case
# (examples/two_blocks_partial.toml at h = 0.033, 8948 DOFs, made as profile_benchmark.sh makes
# it) and of the 3D Hertz case (examples/hertz_3d.toml at h = 0.05, 8658 DOFs), and, when the
# gmsh command is installed, of the two-block case on .msh files (block_lower/upper.geo meshed by
# `gmsh -2 -format msh22` at h = 0.033 beforehand: the run reads meshes, meshes nothing). Each build
# directory given is one variant (e.g. before and after a change); the runs are interleaved
# (variant by variant, tool by tool, RUNS rounds) so that a changing machine load spreads over
# every column. Prints the median and every time of each (case, variant, tool).
# Usage: benchmarks/fixed_cost_benchmark.sh RUNS BUILD [BUILD...]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:?usage: benchmarks/fixed_cost_benchmark.sh RUNS BUILD [BUILD...]}
shift
builds=("$@")
if [ ${#builds[@]} -eq 0 ]; then builds=(build); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "command: benchmarks/fixed_cost_benchmark.sh $runs ${builds[*]}"

# make_case EXAMPLE SIZE: the example with every body's mesh_size set to SIZE, absolute meshes.
make_case() {
  local case_file="$work/$(basename "$1" .toml)_$2.toml"
  sed -e "s|^mesh_size = .*|mesh_size = $2|" \
      -e "s|^mesh = \"meshes/|mesh = \"$PWD/examples/meshes/|" "$1" > "$case_file"
  echo "$case_file"
}

# seconds TOOL BUILD CASE: the wall time of one run, in seconds.
seconds() {
  local output="$work/output" start end
  rm -rf "$output"
  start=$(date +%s.%N)
  "$2/bin/$1" "$3" --output "$output" --quiet > "$work/log" 2>&1 ||
    echo "$1 ($2) on $3: exit $? ($(tail -n 1 "$work/log"))" >&2
  end=$(date +%s.%N)
  echo "$start $end" | awk '{printf "%.3f", $2 - $1}'
}

# make_msh_case SIZE: examples/two_blocks_partial.toml on .msh files meshed by gmsh at SIZE.
make_msh_case() {
  local case_file="$work/two_blocks_partial_msh_$1.toml" body
  for body in lower upper; do
    gmsh -2 -setnumber h "$1" -format msh22 "examples/meshes/block_$body.geo" \
      -o "$work/block_${body}_$1.msh" > /dev/null
  done
  sed -e "s|^mesh = \"meshes/block_\(.*\)\.geo\"|mesh = \"$work/block_\1_$1.msh\"|" \
      -e '/^mesh_size = /d' examples/two_blocks_partial.toml > "$case_file"
  echo "$case_file"
}

cases=("$(make_case examples/two_blocks_partial.toml 0.033)" "$(make_case examples/hertz_3d.toml 0.05)")
if command -v gmsh > /dev/null; then cases+=("$(make_msh_case 0.033)"); fi
for case_file in "${cases[@]}"; do
  declare -A times=()
  for _ in $(seq "$runs"); do
    for build in "${builds[@]}"; do
      for tool in robin-run robin-monolithic; do
        times["$build $tool"]+="$(seconds "$tool" "$build" "$case_file") "
      done
    done
  done
  echo
  echo "$(basename "$case_file"):"
  for build in "${builds[@]}"; do
    for tool in robin-run robin-monolithic; do
      echo "${times["$build $tool"]}" | tr ' ' '\n' | grep . | sort -n |
        awk -v label="$build $tool" '{value[NR] = $1}
             END {printf "  %-40s median %.3f s (", label, value[int((NR + 1) / 2)];
                  for (k = 1; k <= NR; ++k) printf "%s%s", value[k], k < NR ? " " : ")\n"}'
    done
  done
  unset times
done
