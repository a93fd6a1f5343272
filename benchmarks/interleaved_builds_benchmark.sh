#!/usr/bin/env bash
# robin-run of several builds, interleaved, on the partial-contact two-block case on .msh files
# (examples/two_blocks_partial.toml, its .geo bodies meshed once by `gmsh -2 -setnumber h H
# -format msh22`; h = 0.0104: 87 052 DOFs, h = 0.0033: 853 668 DOFs): per round, one run of
# each build (`robin-run CASE --output DIR --overwrite --quiet`, wall time around the process).
# Prints per build the sorted wall times and their median, and the medians of summary.json's
# profile stages with the larger body's assembly + ordering + factorization (issue 16 item 2).
# Usage: benchmarks/interleaved_builds_benchmark.sh ROUNDS H BUILD [BUILD...]
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: benchmarks/interleaved_builds_benchmark.sh ROUNDS H BUILD [BUILD...]"
rounds=${1:?$usage}
size=${2:?$usage}
shift 2
builds=("$@")
if [ ${#builds[@]} -eq 0 ]; then echo "$usage" >&2; exit 2; fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "command: benchmarks/interleaved_builds_benchmark.sh $rounds $size ${builds[*]}"

for body in lower upper; do
  gmsh -2 -setnumber h "$size" -format msh22 "examples/meshes/block_$body.geo" \
    -o "$work/$body.msh" > /dev/null
done
sed -e "s|^mesh = \"meshes/block_\(.*\)\.geo\"|mesh = \"$work/\1.msh\"|" \
    -e '/^mesh_size = /d' examples/two_blocks_partial.toml > "$work/case.toml"

for round in $(seq "$rounds"); do
  for index in "${!builds[@]}"; do
    output="$work/output_$index"
    start=$(date +%s.%N)
    "${builds[$index]}/bin/robin-run" "$work/case.toml" --output "$output" --overwrite --quiet
    end=$(date +%s.%N)
    echo "$start $end" | awk '{printf "%.3f\n", $2 - $1}' >> "$work/walls_$index"
    cp "$output/summary.json" "$work/summary_${index}_$round.json"
  done
done

for index in "${!builds[@]}"; do
  /usr/bin/python3 - "$work" "$index" "${builds[$index]}" <<'PYTHON'
import glob, json, statistics, sys
work, index, build = sys.argv[1:4]
walls = sorted(float(line) for line in open(f"{work}/walls_{index}"))
profiles = [json.load(open(name))["profile"]
            for name in glob.glob(f"{work}/summary_{index}_*.json")]
stages = ("launch", "meshing", "setup", "contact_coupling", "contact_assignment", "iterations",
          "fields", "output")
print(f"\n{build}: wall (s) {' '.join(f'{wall:.2f}' for wall in walls)}; "
      f"median {statistics.median(walls):.3f}")
print("  profile medians (s): " + ", ".join(
    f"{stage} {statistics.median(p[stage] for p in profiles):.3f}" for stage in stages))
largest = []
for profile in profiles:
    bodies = profile["bodies"]
    largest.append(max(body["assembly"] + body["ordering"] + body["factorization"]
                       for body in bodies))
median_largest = statistics.median(largest)
print(f"  larger body's assembly + ordering + factorization: {median_largest:.3f} s; "
      f"wall / that: {statistics.median(walls) / median_largest:.2f}")
PYTHON
done
