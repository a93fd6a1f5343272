#!/usr/bin/env bash
# Checks of the deployment recipes in deploy/ that need no Docker engine, cluster or SLURM:
#
#   tests/network/recipes_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]
#
#  - shellcheck on every shell script of deploy/ and tests/network/;
#  - the compose files and the Kubernetes manifests parse (PyYAML) and agree with each other and
#    with the shipped cases, one server per body: two bodies by default, four with
#    compose.four-bodies.yaml and kubernetes/four-bodies (check_manifests.py), and the checks
#    find a server too few (manifests-mutations); `docker compose config` (or docker-compose)
#    validates the compose files; `kubectl kustomize` renders both kustomizations, and
#    check_manifests.py checks what it rendered;
#  - remote-servers.sh starts one server per body (stub server and coordinator: two for
#    two_blocks.toml, four for arch.toml, three --listen for a three-body case) and refuses a
#    number of servers other than the case's bodies (exit 2);
#  - deploy/slurm/robin-contact.sbatch places one server per body on the nodes of the
#    allocation's tasks (stub scontrol and remote-servers.sh);
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

# check_manifests.py on copies of the recipes with one server too few: each must be found.
check_manifest_mutations() {
  local copy=$work/mutated name
  for name in statefulset job compose; do
    rm -rf "$copy"
    mkdir -p "$copy/tests"
    cp -r deploy examples "$copy/"
    case $name in
      statefulset) sed -i 's/count: 4/count: 3/' "$copy/deploy/kubernetes/four-bodies/kustomization.yaml" ;;
      job) sed -i '/- tcp:\/\/robin-subdomain-3/{N;d}' \
        "$copy/deploy/kubernetes/four-bodies/coordinator-job-patch.yaml"
        sed -i '/- tcp:\/\/robin-subdomain-2/{n;d}' \
          "$copy/deploy/kubernetes/four-bodies/coordinator-job-patch.yaml" ;;
      compose) sed -i '/- --subdomain$/{N;/server-4/d}' "$copy/deploy/compose.four-bodies.yaml" ;;
    esac
    if "$python" tests/network/check_manifests.py "$copy" > "$work/mutation.log" 2>&1; then
      echo "$name: a server too few was not found:"; cat "$work/mutation.log"; return 1
    fi
    grep -q 'one server per body' "$work/mutation.log" ||
      { echo "$name: no 'one server per body' problem:"; cat "$work/mutation.log"; return 1; }
    echo "$name with a server too few: $(grep -m 1 'one server per body' "$work/mutation.log")"
  done
}

# remote-servers.sh with a stub server (announces a port, then sleeps) and a stub coordinator
# (records its arguments): one server per body of the case, in body order.
check_remote_servers() {
  local stubs=$work/remote-stubs three=$work/three.toml status count
  mkdir -p "$stubs"
  cat > "$stubs/server" << 'STUB'
#!/usr/bin/env bash
echo "listening on tcp://127.0.0.1:$((20000 + RANDOM % 20000))"
exec sleep 60
STUB
  cat > "$stubs/coordinator" << 'STUB'
#!/usr/bin/env bash
echo "$*" > "$STUB_RECORD"
STUB
  chmod +x "$stubs/server" "$stubs/coordinator"
  printf '[[body]]\nname = "a"\n\n[[body]]\nname = "b"\n\n[[ body ]]\nname = "c"\n' > "$three"
  run_remote() {  # EXPECTED_STATUS EXPECTED_SERVERS ARGUMENTS...
    local expected=$1 servers=$2
    shift 2
    rm -f "$stubs/record"
    status=0
    STUB_RECORD=$stubs/record deploy/remote-servers.sh --subdomain-binary "$stubs/server" \
      --coordinator-binary "$stubs/coordinator" --log-dir "$stubs/logs" --grace 2 "$@" \
      --output "$stubs/out" > "$stubs/log" 2>&1 || status=$?
    [ "$status" -eq "$expected" ] ||
      { echo "remote-servers.sh $*: status $status, expected $expected"; cat "$stubs/log"; return 1; }
    [ "$expected" -eq 0 ] || return 0
    count=$(grep -o -- '--subdomain tcp://127.0.0.1:[0-9]*' "$stubs/record" | sort -u | wc -l)
    [ "$count" -eq "$servers" ] ||
      { echo "remote-servers.sh $*: $count servers, expected $servers"; cat "$stubs/log"; return 1; }
    grep -q "servers stopped" "$stubs/log" || { echo "servers not stopped"; return 1; }
    echo "remote-servers.sh $*: $count servers, endpoints: $(cat "$stubs/record")"
  }
  run_remote 0 2 examples/two_blocks.toml || return 1
  [ ! -f examples/arch.toml ] || run_remote 0 4 examples/arch.toml || return 1
  run_remote 0 3 --listen 'tcp://127.0.0.1:*' --listen 'tcp://127.0.0.1:*' \
    --listen 'tcp://127.0.0.1:*' "$three" || return 1
  run_remote 0 3 --servers 3 "$three" || return 1
  run_remote 2 0 --servers 2 "$three" || return 1
  grep -q "the case $three has 3 bodies, but 2 servers were declared" "$stubs/log" ||
    { cat "$stubs/log"; return 1; }
  run_remote 2 0 --listen 'tcp://127.0.0.1:*' --listen 'tcp://127.0.0.1:*' "$three" || return 1
  echo "refused: 2 servers for 3 bodies (--servers 2, two --listen), exit 2"
}

# deploy/slurm/robin-contact.sbatch outside SLURM: a stub scontrol (node names of a node list)
# and a stub remote-servers.sh (prints its arguments) under ROBIN_HOME; the srun prefixes it
# builds put server i on the node of task i.
check_slurm_script() {
  local home=$work/slurm-home three=$work/slurm-three.toml nodes
  mkdir -p "$home/deploy" "$home/bin"
  # scontrol show hostnames node[1-3] -> node1, node2, node3 (one a line); node1 -> node1.
  cat > "$home/bin/scontrol" << 'STUB'
#!/usr/bin/env bash
list=$3 prefix=${3%%[*} range=${3#*[}
if [ "$range" = "$list" ]; then echo "$list"; exit 0; fi
range=${range%]}
for ((i = ${range%-*}; i <= ${range#*-}; ++i)); do echo "$prefix$i"; done
STUB
  cat > "$home/deploy/remote-servers.sh" << 'STUB'
#!/usr/bin/env bash
printf "%s\n" "$@"
STUB
  chmod +x "$home/bin/scontrol" "$home/deploy/remote-servers.sh"
  printf '[[body]]\n[[body]]\n[[body]]\n' > "$three"
  placement() {  # NODELIST TASKS_PER_NODE CASE EXPECTED_NODES
    nodes=$(PATH=$home/bin:$PATH ROBIN_HOME=$home SLURM_JOB_NODELIST=$1 \
      SLURM_TASKS_PER_NODE=$2 SLURM_JOB_ID=1 bash deploy/slurm/robin-contact.sbatch "$3" \
      2> /dev/null | sed -n 's/^srun .*--nodelist=\([^ ]*\) .*/\1/p' | tr '\n' ' ')
    [ "$nodes" = "$4 " ] || { echo "$1 ($2 tasks per node), $3: servers on '$nodes', expected '$4'"; return 1; }
    echo "$1 ($2 tasks per node), $(basename "$3"): servers on $nodes"
  }
  placement 'node[1-2]' '1(x2)' examples/two_blocks.toml "node1 node2" || return 1
  placement 'node[1-3]' '1(x3)' "$three" "node1 node2 node3" || return 1
  placement 'node1' '3' "$three" "node1 node1 node1" || return 1
  placement 'node[1-2]' '2,1' "$three" "node1 node1 node2" || return 1
  placement 'node[1-2]' '1(x2)' "$three" "node1 node2 node1" || return 1
}

# The Compose file against the schema of the installed Compose (v2 plugin, else v1); no engine.
check_compose_schema() {
  local compose=(docker-compose)
  if docker compose version > /dev/null 2>&1; then compose=(docker compose); fi
  ROBIN_UID=1000 ROBIN_GID=1000 "${compose[@]}" -f deploy/compose.yaml config --quiet || return 1
  ROBIN_UID=1000 ROBIN_GID=1000 "${compose[@]}" -f deploy/compose.yaml \
    -f deploy/compose.four-bodies.yaml config --quiet || return 1
  echo "${compose[*]} config: valid ($("${compose[@]}" version --short 2> /dev/null || true))"
}

check_kustomize() {
  local kinds name count
  for name in . four-bodies; do
    kubectl kustomize "deploy/kubernetes/$name" > "$work/rendered-$name.yaml" || return 1
    kinds=$(grep '^kind:' "$work/rendered-$name.yaml" | sort | uniq -c | tr -s ' ' | tr '\n' ';')
    echo "deploy/kubernetes/$name rendered:$kinds"
    count=$(grep -c '^kind:' "$work/rendered-$name.yaml")
    case $name in
      .) [ "$count" -eq 6 ] || return 1 ;;
      four-bodies) [ "$count" -eq 7 ] || return 1 ;;  # and the four-body case's ConfigMap
    esac
  done
  if "$python" -c 'import yaml' 2> /dev/null; then
    "$python" tests/network/check_manifests.py "$source_directory" \
      --rendered . "$work/rendered-..yaml" --rendered four-bodies "$work/rendered-four-bodies.yaml"
  fi
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
  mapfile -t tools < <(grep -o '/src/build/bin/robin-[a-z-]*' deploy/Dockerfile | sed 's|.*/||' | sort -u)
  [ ${#tools[@]} -eq 6 ] || { echo "expected 6 executables in deploy/Dockerfile: ${tools[*]}"; return 1; }
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
if "$python" -c 'import yaml' 2> /dev/null; then
  run_check manifests check_manifests
  run_check manifests-mutations check_manifest_mutations
else leave_out manifests "$python has no yaml module (Debian package python3-yaml)"; fi
run_check remote-servers check_remote_servers
run_check slurm-script check_slurm_script
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
