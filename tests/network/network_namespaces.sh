# Shared by the tests of this directory (sourced, not run): three Linux network namespaces, a
# coordinator's and two servers', joined by veth links through a bridge (in the coordinator's
# namespace) on the private subnet 10.231.77.0/24, which exists only inside the namespaces.
#
# The sourcing script sets binary_directory and source_directory, may define cleanup_hook (run
# by the cleanup once the processes and namespaces are gone), then calls
# require_namespace_tools, remove_stale_namespaces and create_network. Every exit removes the
# namespaces (and so their links), kills what runs in them and the processes listed in
# started_pids, prints the logs of the work directory when the test failed, and removes it. A
# run killed by SIGKILL cannot do that: the next run's remove_stale_namespaces removes its
# namespaces, the processes in them and its work directory (named after its process id).
# shellcheck shell=bash disable=SC2154  # binary_directory, source_directory: set by the caller

python=/usr/bin/python3
subnet=10.231.77
coordinator_address=$subnet.1
server_addresses=("$subnet.2" "$subnet.3")
coordinator_namespace=robin-test-coordinator-$$
server_namespaces=("robin-test-server1-$$" "robin-test-server2-$$")
all_namespaces=("$coordinator_namespace" "${server_namespaces[@]}")

skip() {
  echo "SKIPPED: $*"
  exit 77
}
fail() {
  echo "FAILED: $*" >&2
  exit 1
}

# Fails without the executables, skips (77) where namespaces cannot be made; then makes the work
# directory and installs the cleanup.
require_namespace_tools() {
  local tool
  for tool in robin-run robin-coordinator robin-subdomain; do
    [ -x "$binary_directory/$tool" ] || fail "$binary_directory/$tool is missing (build it first)"
  done
  [ -x "$python" ] || skip "$python is missing (the comparison of contact.csv needs it)"
  [ "$(id -u)" -eq 0 ] || skip "network namespaces need root (running as uid $(id -u))"
  command -v ip > /dev/null || skip "iproute2's ip is missing"
  work=$(mktemp -d -t "robin-namespaces-$$.XXXXXX")  # $$: see remove_stale_namespaces
  trap cleanup EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
  trap 'exit 129' HUP
}

work=""
created_namespaces=()
started_pids=()

# Stops what this test started, then removes the namespaces (which removes their links) and
# kills anything still running inside them. Runs on every exit.
# shellcheck disable=SC2317  # invoked by the EXIT trap
cleanup() {
  local status=$? pid namespace remaining
  trap '' INT TERM HUP
  for pid in "${started_pids[@]}"; do kill -TERM "$pid" 2> /dev/null || true; done
  for pid in "${started_pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
  done
  for namespace in "${created_namespaces[@]}"; do
    remaining=$(ip netns pids "$namespace" 2> /dev/null || true)
    if [ -n "$remaining" ]; then
      echo "cleanup: killing processes left in $namespace: $remaining" >&2
      # shellcheck disable=SC2086  # one pid per word
      kill -KILL $remaining 2> /dev/null || true
      sleep 0.2
    fi
    ip netns delete "$namespace" 2> /dev/null || echo "cleanup: could not delete $namespace" >&2
  done
  if declare -F cleanup_hook > /dev/null; then cleanup_hook; fi
  if [ "$status" -ne 0 ] && [ "$status" -ne 77 ] && [ -n "$work" ]; then
    echo "--- logs of the failed test ($work) ---" >&2
    find "$work" -name '*.log' -o -name '*.out' -o -name '*.stderr' | sort | while read -r file; do
      echo "== $file" >&2
      tail -n 20 "$file" >&2
    done
  fi
  [ -z "$work" ] || rm -rf "$work"
  exit "$status"
}

# Namespaces of earlier runs of this test that were killed (SIGKILL, e.g. at a CTest timeout)
# before their cleanup, with the processes still in them, and their work directories: removed
# when the run that created them is gone.
remove_stale_namespaces() {
  local namespace owner remaining directory
  for namespace in $(ip netns list 2> /dev/null | awk '/^robin-test-/ { print $1 }'); do
    owner=${namespace##*-}
    if [ "$owner" != $$ ] && ! kill -0 "$owner" 2> /dev/null; then
      remaining=$(ip netns pids "$namespace" 2> /dev/null || true)
      # shellcheck disable=SC2086  # one pid per word
      [ -z "$remaining" ] || kill -KILL $remaining 2> /dev/null || true
      if ip netns delete "$namespace" 2> /dev/null; then echo "removed stale namespace $namespace"; fi
    fi
  done
  for directory in "${TMPDIR:-/tmp}"/robin-namespaces-*.*; do
    [ -d "$directory" ] || continue
    owner=${directory##*/robin-namespaces-}
    owner=${owner%%.*}
    [[ $owner =~ ^[0-9]+$ ]] || continue
    if [ "$owner" != $$ ] && ! kill -0 "$owner" 2> /dev/null; then
      if rm -rf "$directory"; then echo "removed stale work directory $directory"; fi
    fi
  done
}

# --- The network ------------------------------------------------------------------------------

# Creates the namespaces: the coordinator's holds the bridge (and the address .1), each server's
# one end of a veth link whose other end is a port of the bridge.
create_network() {
  local index namespace port
  ip netns add "$coordinator_namespace" 2> "$work/netns.stderr" ||
    skip "cannot create a network namespace: $(cat "$work/netns.stderr")"
  created_namespaces+=("$coordinator_namespace")
  for namespace in "${server_namespaces[@]}"; do
    ip netns add "$namespace"
    created_namespaces+=("$namespace")
  done
  for namespace in "${all_namespaces[@]}"; do ip -n "$namespace" link set lo up; done
  ip -n "$coordinator_namespace" link add bridge0 type bridge forward_delay 0
  ip -n "$coordinator_namespace" address add "$coordinator_address/24" dev bridge0
  ip -n "$coordinator_namespace" link set bridge0 up
  for index in 0 1; do
    namespace=${server_namespaces[index]}
    port=port$((index + 1))
    ip link add "$port" netns "$coordinator_namespace" type veth peer name eth0 netns "$namespace"
    ip -n "$coordinator_namespace" link set "$port" master bridge0 up
    ip -n "$namespace" address add "${server_addresses[index]}/24" dev eth0
    ip -n "$namespace" link set eth0 up
  done
  echo "network: $coordinator_namespace ($coordinator_address, bridge), ${server_namespaces[0]}" \
    "(${server_addresses[0]}), ${server_namespaces[1]} (${server_addresses[1]})"
}

# Prints the pids of the processes running in the server and coordinator namespaces.
processes_in_namespaces() {
  local namespace
  for namespace in "${all_namespaces[@]}"; do ip netns pids "$namespace"; done | tr '\n' ' '
}

compare_contact() {  # REFERENCE_DIRECTORY DIRECTORY
  "$python" "$source_directory/tests/network/compare_contact.py" "$1/contact.csv" "$2/contact.csv"
}
