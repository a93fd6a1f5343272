#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run; the README's test command), after
# deploy/setup.sh:
#   1. the Release build (warnings are errors) and every test: unit, verification, integration
#      (real processes), Python server, network recipes;
#   2. the AddressSanitizer + UBSan build and the unit and verification tiers under it;
#   3. the libFuzzer harnesses (clang, ASan + UBSan) and a short smoke run of each over its seed
#      corpus (docs/fuzzing.md; the long runs are benchmarks/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
# deploy/setup.sh installed SLURM and munge: the slurm_namespaces test fails without them
# instead of skipping (it still skips where it cannot make network namespaces or is not root).
export ROBIN_REQUIRE_SLURM=1
# It installed ParaView (paraview, python3-paraview) and xvfb: robin_paraview_script fails
# without them instead of skipping.
export ROBIN_REQUIRE_PARAVIEW=1

./deploy/build.sh
ctest --test-dir build --output-on-failure -j "$jobs"

./deploy/build.sh --sanitize
ctest --test-dir build-sanitize -L 'unit|verification' --output-on-failure -j "$jobs"

./deploy/build.sh --fuzz
ctest --test-dir build-fuzz -L fuzz --output-on-failure -j "$jobs"
