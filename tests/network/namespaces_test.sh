#!/usr/bin/env bash
# A run across "machines": three Linux network namespaces (a coordinator and two servers), each
# with its own network stack, joined by veth links through a bridge on a private test subnet.
#
#   tests/network/namespaces_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]
#
# Checks, for examples/two_blocks.toml:
#  1. robin-subdomain in each server namespace, bound to that namespace's own address, and
#     robin-coordinator in the coordinator namespace: contact.csv equals the local robin-run's
#     (lambda1, lambda2, un1, un2 to 1e-12 relative); the same servers serve a second run.
#  2. deploy/remote-servers.sh with `ip netns exec NS` as the command prefix of the servers and
#     of the coordinator: same comparison, and no server process is left in the namespaces.
#  3. deploy/remote-servers.sh interrupted by SIGTERM while the coordinator runs: exit code 143
#     and every process it started is gone; a server that cannot bind its address: exit code 1,
#     a message naming the endpoint, and the other server stopped.
#  4. Where OpenSSH (server and client) is installed: an sshd in each server namespace and
#     remote-servers.sh in the coordinator's namespace with `ssh -tt ADDRESS` as the prefix:
#     same comparison, and the remote servers end when the script does. Left out otherwise.
# Exit code 77 (skipped for CTest) when network namespaces cannot be created here (not root, no
# iproute2, no kernel support). The namespaces, their links and every process are removed on
# any exit. The namespaces hold their own addresses, so nothing is added to the host's network.
set -euo pipefail

binary_directory=$(cd "${1:?usage: namespaces_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]}" && pwd)
source_directory=$(cd "${2:-$(dirname "$0")/../..}" && pwd)
case_file=$source_directory/examples/two_blocks.toml
remote_servers=$source_directory/deploy/remote-servers.sh
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

for tool in robin-run robin-coordinator robin-subdomain; do
  [ -x "$binary_directory/$tool" ] || fail "$binary_directory/$tool is missing (build it first)"
done
[ -x "$python" ] || skip "$python is missing (the comparison of contact.csv needs it)"
[ "$(id -u)" -eq 0 ] || skip "network namespaces need root (running as uid $(id -u))"
command -v ip > /dev/null || skip "iproute2's ip is missing"

work=$(mktemp -d -t robin-namespaces.XXXXXX)
created_namespaces=()
started_pids=()
created_privilege_directory=""  # /run/sshd, when the ssh check had to create it

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
  if [ "$status" -ne 0 ] && [ "$status" -ne 77 ]; then
    echo "--- logs of the failed test ($work) ---" >&2
    find "$work" -name '*.log' -o -name '*.out' -o -name '*.stderr' | sort | while read -r file; do
      echo "== $file" >&2
      tail -n 20 "$file" >&2
    done
  fi
  rm -rf "$work"
  [ -z "$created_privilege_directory" ] || rmdir "$created_privilege_directory" 2> /dev/null || true
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP

# Namespaces of earlier runs of this test that were killed (SIGKILL, e.g. at a CTest timeout)
# before their cleanup: removed when the run that created them is gone.
remove_stale_namespaces() {
  local namespace owner remaining
  for namespace in $(ip netns list 2> /dev/null | awk '/^robin-test-/ { print $1 }'); do
    owner=${namespace##*-}
    if [ "$owner" != $$ ] && ! kill -0 "$owner" 2> /dev/null; then
      remaining=$(ip netns pids "$namespace" 2> /dev/null || true)
      # shellcheck disable=SC2086  # one pid per word
      [ -z "$remaining" ] || kill -KILL $remaining 2> /dev/null || true
      if ip netns delete "$namespace" 2> /dev/null; then echo "removed stale namespace $namespace"; fi
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

# --- Servers started by the test ---------------------------------------------------------------

# start_server NAME NAMESPACE ENDPOINT: robin-subdomain in NAMESPACE, its pid in server_pid
# (`ip netns exec` executes the server in its own process).
start_server() {
  ip netns exec "$2" "$binary_directory/robin-subdomain" --listen "$3" --name "$1" \
    > "$work/$1.out" 2> "$work/$1.log" < /dev/null &
  server_pid=$!
  started_pids+=("$server_pid")
}

# await_listening NAME PID EXPECTED_ENDPOINT: fails unless the server announces that endpoint.
await_listening() {
  local line deadline=$((SECONDS + 30))
  until line=$(grep -m 1 'listening on ' "$work/$1.out"); do
    kill -0 "$2" 2> /dev/null || fail "server $1 exited before listening: $(cat "$work/$1.log")"
    [ "$SECONDS" -lt "$deadline" ] || fail "server $1 did not listen within 30 s"
    sleep 0.1
  done
  [ "$line" = "listening on $3" ] || fail "server $1 announced '$line', expected 'listening on $3'"
  echo "server $1 (pid $2): $line"
}

# stop_server NAME PID: SIGTERM; the server must exit with status 0 within 10 s.
stop_server() {
  local status=0
  kill -TERM "$2"
  for _ in $(seq 100); do kill -0 "$2" 2> /dev/null || break; sleep 0.1; done
  wait "$2" || status=$?
  [ "$status" -eq 0 ] || fail "server $1 exited with status $status after SIGTERM"
}

compare_contact() {  # REFERENCE_DIRECTORY DIRECTORY
  "$python" "$source_directory/tests/network/compare_contact.py" "$1/contact.csv" "$2/contact.csv"
}

# --- 1. Servers bound to their namespaces' addresses, the coordinator in its own --------------

check_coordinator_across_namespaces() {
  local pids=() index name endpoints=() run comparison
  for index in 0 1; do
    name=server$((index + 1))
    endpoints+=("tcp://${server_addresses[index]}:5555")
    start_server "$name" "${server_namespaces[index]}" "${endpoints[index]}"
    pids+=("$server_pid")
  done
  for index in 0 1; do await_listening "server$((index + 1))" "${pids[index]}" "${endpoints[index]}"; done
  for run in first second; do  # long-running servers: a second run on the same processes
    timeout 120 ip netns exec "$coordinator_namespace" "$binary_directory/robin-coordinator" \
      "$case_file" --subdomain "${endpoints[0]}" --subdomain "${endpoints[1]}" \
      --output "$work/namespaces-$run" --log-level warn 2> "$work/coordinator-$run.log" ||
      fail "robin-coordinator ($run run) across the namespaces exited with status $?"
    comparison=$(compare_contact "$work/local" "$work/namespaces-$run") ||
      fail "contact.csv across the namespaces ($run run) differs from the local run: $comparison"
    echo "robin-coordinator in $coordinator_namespace, $run run: $comparison"
  done
  for index in 0 1; do stop_server "server$((index + 1))" "${pids[index]}"; done
}

# --- 2. deploy/remote-servers.sh with `ip netns exec` as the prefixes -------------------------

# The options of deploy/remote-servers.sh with the namespaces as the hosts and the test's
# binaries (server 2 binds a wildcard; --connect-host names its address).
remote_server_options=(
  --subdomain-binary "$binary_directory/robin-subdomain"
  --coordinator-launch "ip netns exec $coordinator_namespace"
  --launch "ip netns exec ${server_namespaces[0]}" --listen "tcp://${server_addresses[0]}:5556"
  --launch "ip netns exec ${server_namespaces[1]}" --connect-host "${server_addresses[1]}"
  --listen "tcp://*:5556" --startup-timeout 30 --grace 3
)

check_remote_servers_script() {
  local status=0 comparison
  timeout 120 "$remote_servers" "${remote_server_options[@]}" \
    --coordinator-binary "$binary_directory/robin-coordinator" \
    --log-dir "$work/script-logs" "$case_file" --output "$work/script" --log-level warn \
    2> "$work/script.stderr" || status=$?
  [ "$status" -eq 0 ] || fail "remote-servers.sh exited with status $status"
  comparison=$(compare_contact "$work/local" "$work/script") ||
    fail "contact.csv of remote-servers.sh differs from the local run: $comparison"
  echo "deploy/remote-servers.sh through ip netns exec: $comparison"
  grep -q "server 2 listening on tcp://${server_addresses[1]}:5556" "$work/script.stderr" ||
    fail "remote-servers.sh did not connect to server 2 through --connect-host"
  [ -z "$(processes_in_namespaces)" ] ||
    fail "processes left in the namespaces after remote-servers.sh: $(processes_in_namespaces)"
}

# --- 3. Interruption and a server that cannot start ------------------------------------------

check_interruption() {
  local stub=$work/stub-coordinator.sh script_pid status=0 deadline=$((SECONDS + 30))
  printf '#!/bin/sh\necho "$@" > "%s/stub.arguments"\nexec sleep 300\n' "$work" > "$stub"
  chmod +x "$stub"
  "$remote_servers" "${remote_server_options[@]}" \
    --coordinator-binary "$stub" --log-dir "$work/interrupt-logs" \
    "$case_file" --output "$work/interrupted" 2> "$work/interrupt.stderr" &
  script_pid=$!
  until [ -s "$work/stub.arguments" ]; do
    kill -0 "$script_pid" 2> /dev/null || fail "remote-servers.sh ended before its coordinator ran"
    [ "$SECONDS" -lt "$deadline" ] || fail "the coordinator stub did not start within 30 s"
    sleep 0.1
  done
  grep -q -- "--subdomain tcp://${server_addresses[0]}:5556 --subdomain tcp://${server_addresses[1]}:5556" \
    "$work/stub.arguments" || fail "coordinator arguments: $(cat "$work/stub.arguments")"
  kill -TERM "$script_pid"
  wait "$script_pid" || status=$?
  [ "$status" -eq 143 ] || fail "remote-servers.sh exited with $status after SIGTERM, expected 143"
  [ -z "$(processes_in_namespaces)" ] ||
    fail "processes left in the namespaces after SIGTERM: $(processes_in_namespaces)"
  echo "deploy/remote-servers.sh stopped by SIGTERM: status 143, no process left"
}

check_bind_failure() {
  local status=0
  timeout 60 "$remote_servers" --subdomain-binary "$binary_directory/robin-subdomain" \
    --launch "ip netns exec ${server_namespaces[0]}" --listen "tcp://${server_addresses[0]}:5557" \
    --launch "ip netns exec ${server_namespaces[1]}" --listen "tcp://$subnet.9:5557" \
    --log-dir "$work/failure-logs" "$case_file" --output "$work/failure" \
    2> "$work/failure.stderr" || status=$?
  [ "$status" -eq 1 ] || fail "remote-servers.sh with an unbindable address exited with $status"
  grep -q "server 2 (tcp://$subnet.9:5557) exited before listening" "$work/failure.stderr" ||
    fail "no message naming the unbindable endpoint: $(cat "$work/failure.stderr")"
  [ -z "$(processes_in_namespaces)" ] ||
    fail "processes left in the namespaces after a failed start: $(processes_in_namespaces)"
  echo "deploy/remote-servers.sh with an unbindable address: status 1, message names it"
}

# --- 4. ssh as the prefix (when OpenSSH's server and client are installed) ----------------------

# An sshd in each server namespace (key login for this user, files in the work directory), and
# remote-servers.sh run inside the coordinator's namespace with `ssh -tt ADDRESS` as the prefix:
# the servers must answer, and be gone once the script ends (SIGHUP when ssh's terminal closes).
check_ssh_prefix() {
  local index config ssh_options=() status=0 comparison
  if [ ! -x /usr/sbin/sshd ] || ! command -v ssh > /dev/null || ! command -v ssh-keygen > /dev/null; then
    echo "left out: ssh as the prefix (needs openssh-server and openssh-client)"
    return 0
  fi
  [ -d /run/sshd ] || { mkdir -p /run/sshd && created_privilege_directory=/run/sshd; }
  ssh-keygen -q -t ed25519 -N '' -f "$work/ssh_host_key"
  ssh-keygen -q -t ed25519 -N '' -f "$work/ssh_client_key"
  cp "$work/ssh_client_key.pub" "$work/ssh_authorized_keys"
  for index in 0 1; do
    config=$work/sshd_config_$index
    printf '%s\n' "ListenAddress ${server_addresses[index]}:22" "HostKey $work/ssh_host_key" \
      "PidFile $work/sshd_$index.pid" "AuthorizedKeysFile $work/ssh_authorized_keys" \
      "PermitRootLogin prohibit-password" "PasswordAuthentication no" \
      "KbdInteractiveAuthentication no" "UsePAM no" "StrictModes no" > "$config"
    ip netns exec "${server_namespaces[index]}" /usr/sbin/sshd -D -e -f "$config" \
      2> "$work/sshd_$index.log" &
    started_pids+=($!)
  done
  ssh_options=(ssh -tt -i "$work/ssh_client_key" -o BatchMode=yes -o StrictHostKeyChecking=no
    -o UserKnownHostsFile=/dev/null -o LogLevel=ERROR -o ConnectTimeout=10)
  for index in 0 1; do  # until each sshd accepts a login
    for _ in $(seq 50); do
      ip netns exec "$coordinator_namespace" "${ssh_options[@]}" "$(id -un)@${server_addresses[index]}" \
        true > /dev/null 2>&1 < /dev/null && break
      sleep 0.2
    done
  done
  timeout 120 ip netns exec "$coordinator_namespace" "$remote_servers" \
    --subdomain-binary "$binary_directory/robin-subdomain" \
    --coordinator-binary "$binary_directory/robin-coordinator" \
    --launch "${ssh_options[*]} $(id -un)@${server_addresses[0]}" \
    --listen "tcp://${server_addresses[0]}:5558" \
    --launch "${ssh_options[*]} $(id -un)@${server_addresses[1]}" \
    --connect-host "${server_addresses[1]}" --listen "tcp://0.0.0.0:5558" \
    --log-dir "$work/ssh-logs" "$case_file" --output "$work/ssh" --log-level warn \
    2> "$work/ssh.stderr" || status=$?
  [ "$status" -eq 0 ] || fail "remote-servers.sh through ssh exited with status $status"
  comparison=$(compare_contact "$work/local" "$work/ssh") ||
    fail "contact.csv of remote-servers.sh through ssh differs from the local run: $comparison"
  echo "deploy/remote-servers.sh through ssh -tt: $comparison"
  for _ in $(seq 50); do  # the remote servers end on SIGHUP, shortly after ssh exits
    pgrep -f "robin-subdomain --listen tcp://[0-9.]*:5558" > /dev/null || break
    sleep 0.1
  done
  ! pgrep -af "robin-subdomain --listen tcp://[0-9.]*:5558" ||
    fail "servers started through ssh are still running after remote-servers.sh ended"
}

# --- Main ---------------------------------------------------------------------------------------

"$binary_directory/robin-run" "$case_file" --output "$work/local" --log-level warn \
  2> "$work/robin-run.log" || fail "robin-run exited with status $?"
remove_stale_namespaces
create_network
check_coordinator_across_namespaces
check_remote_servers_script
check_interruption
check_bind_failure
check_ssh_prefix
echo "PASSED: runs across network namespaces"
