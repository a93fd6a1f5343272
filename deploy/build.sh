#!/usr/bin/env bash
# Configures and builds robin-contact.
#   deploy/build.sh              Release build in build/ (binaries in build/bin)
#   deploy/build.sh --sanitize   AddressSanitizer + UBSan build in build-sanitize/ (the unit and
#                                verification tests: what the sanitizer tier runs)
#   deploy/build.sh --fuzz       clang build of the libFuzzer harnesses in build-fuzz/
#                                (ASan + UBSan + libFuzzer; docs/fuzzing.md)
# Warnings are errors in all three. All three link with lld and, in a new build directory, build
# with Ninja (deploy/setup.sh installs both); the sanitizer and fuzzing builds keep line tables
# only as debug information (-g1, clang's -gline-tables-only: file:line and inlined frames in
# every sanitizer report, at about two thirds of the compile time of full -g).
set -euo pipefail
cd "$(dirname "$0")/.."

build_directory=build
options=(-DCMAKE_BUILD_TYPE=Release -DROBIN_WERROR=ON)
targets=()
case "${1:-}" in
  --sanitize)
    build_directory=build-sanitize
    # Only what the sanitizer tier runs: the unit and verification tests (and what they depend
    # on), no tools, integration tests or benchmarks.
    options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
             -DROBIN_WERROR=ON -DROBIN_SANITIZE=ON
             -DROBIN_BUILD_INTEGRATION_TESTS=OFF -DROBIN_BUILD_BENCHMARKS=OFF)
    targets=(--target robin-unit-tests robin-verification-tests)
    ;;
  --fuzz)
    build_directory=build-fuzz
    export CC=clang CXX=clang++
    options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo
             "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG"
             -DROBIN_WERROR=ON -DROBIN_FUZZ=ON -DROBIN_BUILD_TESTS=OFF -DROBIN_BUILD_BENCHMARKS=OFF)
    targets=(--target robin-fuzz-server robin-fuzz-case-file robin-fuzz-mesh-data robin-fuzz-mesh-file)
    ;;
  "") ;;
  *) echo "build.sh: unknown option '$1' (--sanitize, --fuzz)" >&2; exit 2 ;;
esac
if command -v ld.lld > /dev/null; then
  options+=(-DROBIN_LINKER=lld)
fi
# Ninja for a new build directory (a directory configured before keeps its generator).
if [ ! -f "$build_directory/CMakeCache.txt" ] && command -v ninja > /dev/null; then
  options+=(-G Ninja)
fi
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build_directory" "${options[@]}" > /dev/null
cmake --build "$build_directory" -j "$jobs" "${targets[@]}"
