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
#  3b. robin-run itself in the coordinator namespace, starting the servers through
#     --server-command "ip netns exec NS" with --server-listen on their own addresses: same
#     comparison, and no server process is left in the namespaces.
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

# shellcheck source=tests/network/network_namespaces.sh
source "$(dirname "$0")/network_namespaces.sh"
remote_servers=$source_directory/deploy/remote-servers.sh
created_privilege_directory=""  # /run/sshd, when the ssh check had to create it
# shellcheck disable=SC2317  # run by the cleanup
cleanup_hook() {
  [ -z "$created_privilege_directory" ] || rmdir "$created_privilege_directory" 2> /dev/null || true
}
require_namespace_tools

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

# --- 3b. robin-run with --server-command ------------------------------------------------------

check_robin_run_server_command() {
  local status=0 comparison
  timeout 120 ip netns exec "$coordinator_namespace" "$binary_directory/robin-run" "$case_file" \
    --output "$work/robin-run-prefix" --log-level info \
    --server-command "ip netns exec ${server_namespaces[0]}" \
    --server-command "ip netns exec ${server_namespaces[1]}" \
    --server-listen "tcp://${server_addresses[0]}:5559" \
    --server-listen "tcp://${server_addresses[1]}:5559" \
    2> "$work/robin-run-prefix.stderr" || status=$?
  [ "$status" -eq 0 ] || fail "robin-run --server-command exited with status $status: $(tail -5 "$work/robin-run-prefix.stderr")"
  comparison=$(compare_contact "$work/local" "$work/robin-run-prefix") ||
    fail "contact.csv of robin-run --server-command differs from the local run: $comparison"
  grep -q "listening on tcp://${server_addresses[1]}:5559" "$work/robin-run-prefix.stderr" ||
    fail "robin-run did not report server 2 on its namespace's address"
  echo "robin-run --server-command 'ip netns exec NS': $comparison"
  [ -z "$(processes_in_namespaces)" ] ||
    fail "processes left in the namespaces after robin-run: $(processes_in_namespaces)"
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

remove_stale_namespaces
create_network
"$binary_directory/robin-run" "$case_file" --output "$work/local" --log-level warn \
  2> "$work/robin-run.log" || fail "robin-run exited with status $?"
check_coordinator_across_namespaces
check_remote_servers_script
check_interruption
check_bind_failure
check_robin_run_server_command
check_ssh_prefix
echo "PASSED: runs across network namespaces"
