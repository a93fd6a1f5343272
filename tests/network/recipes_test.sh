#!/usr/bin/env bash
# Checks of the deployment recipes in deploy/ that need no Docker engine, cluster or SLURM:
#
#   tests/network/recipes_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]
#
#  - shellcheck on every shell script of deploy/ and tests/network/;
#  - the compose file and the Kubernetes manifests parse (PyYAML) and agree with each other and
#    with the shipped case (check_manifests.py); `docker compose config` (or docker-compose)
#    validates the compose file; `kubectl kustomize` renders the manifests;
#  - the systemd unit passes `systemd-analyze verify` without a message (with ExecStart pointed
#    at the built robin-subdomain) and its offline security exposure is at most 2.0 ("OK");
#  - the runtime stage of deploy/Dockerfile installs packages whose dependency closure holds
#    every shared library the executables it copies load here (ldd, dpkg, apt-cache).
# A check whose tool is missing is reported and left out; exit 77 (skipped) when none could run,
# 1 when one failed. (The checks run inside `if`, where set -e does not apply: each step
# returns on failure explicitly.)
set -euo pipefail

binary_directory=$(cd "${1:?usage: recipes_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]}" && pwd)
source_directory=$(cd "${2:-$(dirname "$0")/../..}" && pwd)
python=/usr/bin/python3
cd "$source_directory"

work=$(mktemp -d -t robin-recipes.XXXXXX)
trap 'rm -rf "$work"' EXIT
ran=()
left_out=()
failed=()

run_check() {  # NAME FUNCTION
  if "$2" > "$work/$1.log" 2>&1; then
    ran+=("$1")
    echo "passed: $1"
  else
    failed+=("$1")
    echo "FAILED: $1"
  fi
  sed 's/^/    /' "$work/$1.log"
}

leave_out() {  # NAME REASON
  left_out+=("$1")
  echo "left out: $1 ($2)"
}

check_shell_scripts() {
  local scripts=(deploy/*.sh deploy/slurm/*.sbatch tests/network/*.sh)
  shellcheck --shell=bash --external-sources "${scripts[@]}" || return 1
  echo "${#scripts[@]} scripts: ${scripts[*]}"
}

check_manifests() {
  "$python" tests/network/check_manifests.py "$source_directory"
}

# The Compose file against the schema of the installed Compose (v2 plugin, else v1); no engine.
check_compose_schema() {
  local compose=(docker-compose)
  if docker compose version > /dev/null 2>&1; then compose=(docker compose); fi
  ROBIN_UID=1000 ROBIN_GID=1000 "${compose[@]}" -f deploy/compose.yaml config --quiet || return 1
  echo "${compose[*]} config: valid ($("${compose[@]}" version --short 2> /dev/null || true))"
}

check_kustomize() {
  local kinds
  kubectl kustomize deploy/kubernetes > "$work/rendered.yaml" || return 1
  kinds=$(grep '^kind:' "$work/rendered.yaml" | sort | uniq -c | tr -s ' ' | tr '\n' ';')
  echo "rendered:$kinds"
  [ "$(grep -c '^kind:' "$work/rendered.yaml")" -eq 6 ]
}

check_systemd_unit() {
  local unit_directory=$work/units exposure
  mkdir -p "$unit_directory"
  sed "s|/usr/local/bin/robin-subdomain|$binary_directory/robin-subdomain|" \
    deploy/systemd/robin-subdomain@.service > "$unit_directory/robin-subdomain@.service"
  ln -s robin-subdomain@.service "$unit_directory/robin-subdomain@5555.service"
  # verify exits 0 after "ignoring" a bad setting: any output is a failure too.
  systemd-analyze verify "$unit_directory/robin-subdomain@5555.service" > "$work/verify.log" 2>&1 ||
    { cat "$work/verify.log"; return 1; }
  [ ! -s "$work/verify.log" ] || { cat "$work/verify.log"; return 1; }
  exposure=$(systemd-analyze security --offline=yes "$unit_directory/robin-subdomain@5555.service" |
    sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p')
  echo "verify: no complaint; offline security exposure $exposure (0 = best, 10 = worst)"
  awk -v value="$exposure" 'BEGIN { exit !(value != "" && value <= 2.0) }'
}

# Prints "LIBRARY PACKAGE" for every shared library the executables copied by deploy/Dockerfile
# load here (the package owning its resolved path, else the path ldd printed; one dpkg call).
library_owners() {
  local tools=() libraries=() resolved=() index
  declare -A owner
  mapfile -t tools < <(grep -o '/src/build/bin/robin-[a-z]*' deploy/Dockerfile | sed 's|.*/||' | sort -u)
  [ ${#tools[@]} -eq 5 ] || { echo "expected 5 executables in deploy/Dockerfile: ${tools[*]}"; return 1; }
  for index in "${!tools[@]}"; do ldd "$binary_directory/${tools[index]}" || return 1; done |
    awk '$3 ~ /^\// { print $3 }' | sort -u > "$work/libraries"
  mapfile -t libraries < "$work/libraries"
  mapfile -t resolved < <(readlink -f "${libraries[@]}")
  while read -r package path; do
    owner[$path]=${package%%:*}
  done < <(dpkg -S "${resolved[@]}" "${libraries[@]}" 2> /dev/null |
    sed -n 's/^\([^ ,]*\)\(, [^:]*\)\{0,1\}: \(\/.*\)$/\1 \3/p')
  for index in "${!libraries[@]}"; do
    echo "${libraries[index]} ${owner[${resolved[index]}]:-${owner[${libraries[index]}]:-unknown}}"
  done
}

check_runtime_packages() {
  local packages closure library package missing=0 count=0
  packages=$(sed -n 's/^ARG RUNTIME_PACKAGES="\(.*\)"$/\1/p' deploy/Dockerfile)
  [ -n "$packages" ] || { echo "no ARG RUNTIME_PACKAGES line in deploy/Dockerfile"; return 1; }
  # shellcheck disable=SC2086  # one package per word
  closure=$(apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
    --no-replaces --no-enhances $packages | grep -v '^ ' | sed 's/:any$//' | sort -u) || return 1
  library_owners > "$work/owners" || { cat "$work/owners"; return 1; }
  while read -r library package; do
    count=$((count + 1))
    # The sanitizer runtimes of a --sanitize build are not part of the image's release binaries.
    case "$package" in libasan[0-9]* | libubsan[0-9]*) continue ;; esac
    if ! grep -qx "$package" <<< "$closure"; then
      echo "$library (package '$package') is not in the closure of: $packages"
      missing=1
    fi
  done < "$work/owners"
  [ "$count" -gt 0 ] || { echo "no shared library found"; return 1; }
  echo "$count shared libraries of the copied executables, all from: $packages (and dependencies)"
  return "$missing"
}

if command -v shellcheck > /dev/null; then run_check shellcheck check_shell_scripts
else leave_out shellcheck "shellcheck is not installed (Debian package shellcheck)"; fi
if "$python" -c 'import yaml' 2> /dev/null; then run_check manifests check_manifests
else leave_out manifests "$python has no yaml module (Debian package python3-yaml)"; fi
if docker compose version > /dev/null 2>&1 || command -v docker-compose > /dev/null; then
  run_check compose-schema check_compose_schema
else leave_out compose-schema "neither docker compose nor docker-compose is installed"; fi
if command -v kubectl > /dev/null; then run_check kustomize check_kustomize
else leave_out kustomize "kubectl is not installed"; fi
if command -v systemd-analyze > /dev/null; then run_check systemd-unit check_systemd_unit
else leave_out systemd-unit "systemd-analyze is not installed (Debian package systemd)"; fi
if command -v apt-cache > /dev/null && command -v dpkg > /dev/null &&
  [ -x "$binary_directory/robin-subdomain" ]; then
  run_check runtime-packages check_runtime_packages
else leave_out runtime-packages "needs apt-cache, dpkg and the built executables"; fi
echo "hadolint (Dockerfile lint), a Docker engine, a Kubernetes cluster and a SLURM cluster are" \
  "not used by this test."

if [ ${#failed[@]} -gt 0 ]; then
  echo "FAILED: ${failed[*]}"
  exit 1
fi
if [ ${#ran[@]} -eq 0 ]; then
  echo "SKIPPED: no check could run (left out: ${left_out[*]})"
  exit 77
fi
echo "PASSED: ${ran[*]}${left_out[*]:+ (left out: ${left_out[*]})}"
