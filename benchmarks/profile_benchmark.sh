#!/usr/bin/env bash
# The stage-by-stage profile (summary.json "profile", docs/outputs.md) of the partial-contact
# two-block case (examples/two_blocks_partial.toml, .geo bodies) at several mesh sizes (about
# 1e4, 1e5 and 1e6 DOFs by default), solved by robin-run (two robin-subdomain servers on this
# machine) and by robin-monolithic. Prints a markdown table: one row per stage, one column per
# size and tool, in seconds. Body stages ("server: ...": in robin-monolithic, its own) are
# the larger of the two bodies' (robin-run sets them up in parallel); "–" is a stage the tool does
# not have. "wall" is measured by this script around the process; "rest" is the wall time outside
# the coordinator's stages (process start-up before the clock, stopping the servers, exit).
# The default sizes take about 3 minutes on 2 cores (the 1e6 column: 1.5 minutes per tool, most
# of it Gmsh meshing the .geo bodies).
# Usage: benchmarks/profile_benchmark.sh [build directory] [mesh sizes...]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then sizes=(0.033 0.0104 0.0033); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(uname -m), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "command: benchmarks/profile_benchmark.sh $build ${sizes[*]}"
echo

# run TOOL SIZE: TOOL on the case at SIZE into $work/TOOL_SIZE; writes the wall time beside it.
run() {
  local tool=$1 size=$2
  local case_file="$work/case_$size.toml" output="$work/${tool}_$size"
  sed -e "s|^mesh_size = .*|mesh_size = $size|" \
      -e "s|^mesh = \"meshes/|mesh = \"$PWD/examples/meshes/|" examples/two_blocks_partial.toml \
      > "$case_file"
  local start end
  start=$(date +%s.%N)
  "$build/bin/$tool" "$case_file" --output "$output" --quiet > "$output.log" 2>&1 ||
    echo "$tool at h = $size: exit $? ($(tail -n 1 "$output.log"))" >&2
  end=$(date +%s.%N)
  echo "$start $end" | awk '{print $2 - $1}' > "$output.wall"
}

columns=()
for size in "${sizes[@]}"; do
  for tool in robin-run robin-monolithic; do
    run "$tool" "$size"
    columns+=("$work/${tool}_$size")
  done
done

/usr/bin/python3 - "${columns[@]}" <<'PY'
import json, os, sys

rows = [  # (label, where, key): where "run" = profile[key], "body" = max over profile.bodies
    ("launch", "run", "launch"),
    ("meshing (.geo)", "run", "meshing"),
    ("setup (both bodies)", "run", "setup"),
    ("  transfer", "body", "transfer"),
    ("  server: setup request", "body", "server_setup"),
    ("  server: mesh decoding", "body", "mesh"),
    ("  server: assembly", "body", "assembly"),
    ("  server: ordering", "body", "ordering"),
    ("  server: factorization", "body", "factorization"),
    ("contact coupling", "run", "contact_coupling"),
    ("contact assignment", "run", "contact_assignment"),
    ("  server: interface operator", "body", "interface_operator"),
    ("iterations", "run", "iterations"),
    ("fields", "run", "fields"),
    ("  server: fields", "body", "fields"),
    ("output", "run", "output"),
]
coordinator_keys = ["launch", "meshing", "setup", "contact_coupling", "contact_assignment",
                    "iterations", "fields", "output"]


def cell(value):
    return "–" if value is None else "%.3f" % value


headers, columns = [], []
for path in sys.argv[1:]:
    name = os.path.basename(path)
    tool, size = name.rsplit("_", 1)
    try:
        summary = json.load(open(os.path.join(path, "summary.json")))
    except (OSError, ValueError):
        summary = {}
    profile = summary.get("profile", {})
    dofs = sum(body.get("dofs", 0) for body in summary.get("bodies", []))
    label = "DD" if tool == "robin-run" else "mono"
    headers.append("h = %s, %s DOFs, %s" % (size, dofs or "?", label))
    column = []
    for _, where, key in rows:
        if where == "run":
            column.append(profile.get(key))
        else:
            values = [body.get(key) for body in profile.get("bodies", [])]
            values = [value for value in values if value is not None]
            column.append(max(values) if values else None)
    stages = [profile.get(key) or 0.0 for key in coordinator_keys]
    column.append(sum(stages) if profile else None)
    wall = float(open(path + ".wall").read())
    column.append(wall)
    column.append(wall - column[-2] if column[-2] is not None else None)
    columns.append(column)

labels = [row[0] for row in rows] + ["sum of the stages (not indented)", "wall (measured)",
                                    "rest (wall - sum)"]
print("| stage (s) | " + " | ".join(headers) + " |")
print("|---|" + "---|" * len(headers))
for index, label in enumerate(labels):
    print("| %s | %s |" % (label.replace("  ", "&nbsp;&nbsp;"),
                           " | ".join(cell(column[index]) for column in columns)))
PY
