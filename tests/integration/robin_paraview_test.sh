#!/bin/sh
# robin-paraview end to end (registered only where pvpython is installed): robin-monolithic
# solves examples/two_blocks.toml, robin-paraview renders its result directory without a window.
# Checks: exit status 0, a PNG file (its 8-byte signature) of the requested 640 x 480 pixels
# (the IHDR width and height), a state file naming solution.pvd, and the printed scale factor.
# Usage: robin_paraview_test.sh BIN_DIRECTORY EXAMPLES_DIRECTORY
set -eu
bin=$1
examples=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/robin-monolithic" "$examples/two_blocks.toml" --output "$work/result" > "$work/solve.log"
"$bin/robin-paraview" "$work/result" --screenshot "$work/view.png" --state "$work/view.pvsm" \
  --size 640x480 > "$work/paraview.log" 2>&1 || { cat "$work/paraview.log"; exit 1; }
cat "$work/paraview.log"
grep -q "displacements scaled by" "$work/paraview.log"
/usr/bin/python3 - "$work/view.png" <<'PYTHON'
import struct, sys
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG file"
width, height = struct.unpack(">II", data[16:24])
assert (width, height) == (640, 480), (width, height)
print("robin_paraview_test: PNG %d x %d, %d bytes" % (width, height, len(data)))
PYTHON
grep -q "solution.pvd" "$work/view.pvsm"
echo "robin_paraview_test: passed"
