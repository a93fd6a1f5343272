#!/usr/bin/env bash
# Configures and builds robin-contact.
#   deploy/build.sh              Release build in build/ (binaries in build/bin)
#   deploy/build.sh --sanitize   AddressSanitizer + UBSan build in build-sanitize/
# Warnings are errors in both.
set -euo pipefail
cd "$(dirname "$0")/.."

build_directory=build
options=(-DCMAKE_BUILD_TYPE=Release -DROBIN_WERROR=ON)
if [ "${1:-}" = "--sanitize" ]; then
  build_directory=build-sanitize
  options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DROBIN_WERROR=ON -DROBIN_SANITIZE=ON)
fi
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build_directory" "${options[@]}" > /dev/null
cmake --build "$build_directory" -j "$jobs"
