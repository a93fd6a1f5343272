#!/bin/sh
# robin-paraview end to end: robin-monolithic solves examples/two_blocks.toml, robin-paraview
# renders its result directory without a window.
# Checks: exit status 0, a PNG file (its 8-byte signature) of the requested 640 x 480 pixels
# (the IHDR width and height), a state file naming solution.pvd, and the printed scale factor.
# Needs ParaView's Python (/usr/bin/python3 importing paraview.simple, Debian's python3-paraview,
# or pvpython on PATH) and a display (DISPLAY, or xvfb-run: Debian's xvfb and xauth); deploy/
# setup.sh installs them. Without them it skips (77), or fails when ROBIN_REQUIRE_PARAVIEW=1
# (set by deploy/test.sh, so CI: after deploy/setup.sh a missing ParaView is a setup bug).
# Usage: robin_paraview_test.sh BIN_DIRECTORY EXAMPLES_DIRECTORY
set -eu
bin=$1
examples=$2
missing=""
if ! /usr/bin/python3 -c "import paraview.simple" > /dev/null 2>&1 \
    && ! command -v pvpython > /dev/null 2>&1; then
  missing="ParaView's Python (no paraview.simple in /usr/bin/python3, no pvpython on PATH)"
fi
if [ -z "${DISPLAY:-}" ] && ! command -v xvfb-run > /dev/null 2>&1; then
  missing="${missing:+$missing and }a display (DISPLAY unset, no xvfb-run on PATH)"
fi
if [ -n "$missing" ]; then
  if [ "${ROBIN_REQUIRE_PARAVIEW:-0}" = 1 ]; then
    echo "robin_paraview_test: FAILED: $missing, and ROBIN_REQUIRE_PARAVIEW=1 (deploy/setup.sh" \
         "installs paraview python3-paraview xvfb xauth)" >&2
    exit 1
  fi
  echo "robin_paraview_test: skipped: $missing (Debian: apt-get install paraview python3-paraview" \
       "xvfb xauth, or deploy/setup.sh)"
  exit 77
fi
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
