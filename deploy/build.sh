#!/usr/bin/env bash
# Configures and builds robin-contact.
#   deploy/build.sh              Release build in build/ (binaries in build/bin)
#   deploy/build.sh --sanitize   AddressSanitizer + UBSan build in build-sanitize/ (the tools,
#                                unit and verification tests: what the sanitizer tier runs)
#   deploy/build.sh --fuzz       clang build of the libFuzzer harnesses in build-fuzz/
#                                (ASan + UBSan + libFuzzer; docs/fuzzing.md)
# Warnings are errors in all three.
set -euo pipefail
cd "$(dirname "$0")/.."

build_directory=build
options=(-DCMAKE_BUILD_TYPE=Release -DROBIN_WERROR=ON)
targets=()
case "${1:-}" in
  --sanitize)
    build_directory=build-sanitize
    # Only what the sanitizer tier runs (unit and verification tests, and the tools they
    # start): no integration tests, no benchmarks.
    options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DROBIN_WERROR=ON -DROBIN_SANITIZE=ON
             -DROBIN_BUILD_INTEGRATION_TESTS=OFF -DROBIN_BUILD_BENCHMARKS=OFF)
    ;;
  --fuzz)
    build_directory=build-fuzz
    export CC=clang CXX=clang++
    options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DROBIN_WERROR=ON -DROBIN_FUZZ=ON
             -DROBIN_BUILD_TESTS=OFF -DROBIN_BUILD_BENCHMARKS=OFF)
    targets=(--target robin-fuzz-server robin-fuzz-case-file robin-fuzz-mesh-data robin-fuzz-mesh-file)
    ;;
  "") ;;
  *) echo "build.sh: unknown option '$1' (--sanitize, --fuzz)" >&2; exit 2 ;;
esac
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build_directory" "${options[@]}" > /dev/null
cmake --build "$build_directory" -j "$jobs" "${targets[@]}"
