#!/usr/bin/env bash
# Starts robin-subdomain servers, one per body of the case, through a command prefix (ssh, srun,
# ip netns exec, ...), runs robin-coordinator against the endpoints they announce (in body
# order), and stops the servers on exit, failure or interruption (SIGINT, SIGTERM, SIGHUP).
#
# Usage:
#   deploy/remote-servers.sh [SERVER OPTIONS] CASE --output DIR [robin-coordinator options]
#
# Server options (before CASE); --launch and --connect-host apply to the servers declared by
# the --listen options that follow them, in body order (the first server gets body 1):
#   --launch PREFIX         command prefix of the next servers, split into words, e.g.
#                           "ssh -tt node1" or "srun --nodes=1 --ntasks=1 --nodelist=node1";
#                           "" runs them here. Default: $ROBIN_LAUNCH (empty: here).
#   --listen ENDPOINT       declares one server binding ENDPOINT (on its own host), e.g.
#                           tcp://10.0.0.7:5555 or 'tcp://*:5555'; give one per body. Without
#                           any --listen: one server per body (see --servers) on
#                           tcp://127.0.0.1:* (ephemeral ports) through the last --launch
#                           (default $ROBIN_LAUNCH) and --connect-host.
#   --servers N             the number of servers (one per body). Default: the number of
#                           --listen options, else the number of [[body]] tables of CASE when
#                           it is readable here, else 2. When CASE is readable here, a number
#                           of servers that is not its number of bodies is refused (exit 2).
#   --connect-host HOST     the coordinator connects to HOST (with the announced port) instead
#                           of the announced address; needed when a server binds a wildcard.
#   --coordinator-launch PREFIX
#                           command prefix of robin-coordinator. Default: $ROBIN_COORDINATOR_LAUNCH.
#   --subdomain-binary PATH robin-subdomain as seen by the prefix command (e.g. on the remote
#                           host). Default: $ROBIN_SUBDOMAIN, else build/bin/robin-subdomain of
#                           this checkout when it exists, else robin-subdomain (from PATH).
#   --coordinator-binary PATH
#                           Default: $ROBIN_COORDINATOR, else build/bin/robin-coordinator, else
#                           robin-coordinator.
#   --log-dir DIR           server output and logs (server-N.out, server-N.log), on this host.
#                           Default: DIR/logs for the coordinator's --output DIR.
#   --server-log-level L    --log-level of the servers (default info).
#   --server-arguments WORDS
#                           more options for every server, split into words, e.g. CurveZMQ's
#                           "--curve-secret-key /etc/robin-contact/server.secret --curve-allow
#                           /etc/robin-contact/allowed" (paths as seen by the server; see
#                           docs/security.md). Default: none.
#   --startup-timeout S     seconds to wait for each "listening on" line (default 60).
#   --grace S               seconds between SIGTERM and SIGKILL when stopping (default 5).
#
# What a prefix must do (the contract of the launcher's command_prefix, see
# coordinator/remote/child_process.hpp): run the rest of its arguments as a command line, pass
# the command's standard output through, and end the command when it receives SIGTERM itself.
# `ip netns exec NS` and `srun` do; plain `ssh host` does not end the remote command, `ssh -tt
# host` does (the remote server gets SIGHUP when its terminal closes). `ssh` joins its
# arguments into one remote shell command line: paths with spaces need quoting for that shell.
#
# Exit code: robin-coordinator's (0 converged, 1 error, 2 bad command line, 3 iteration limit,
# 4 diverged, 5 stagnated), 1 when a server could not be started, 2 for a bad command line of
# this script (an unknown option, a number of servers other than the case's bodies), 128 +
# signal when interrupted. Progress goes to standard error, prefixed "remote-servers:".
set -euo pipefail

script_directory=$(cd "$(dirname "$0")" && pwd)
repository=$(dirname "$script_directory")

log() { echo "remote-servers: $*" >&2; }
die() {
  log "$*"
  exit 1
}
usage_error() {
  log "$*"
  exit 2
}

# The number of [[body]] tables of a case file (0 when it cannot be read here).
case_body_count() {
  [ -r "$1" ] || { echo 0; return; }
  grep -c '^[[:space:]]*\[\[[[:space:]]*body[[:space:]]*\]\]' "$1" || true
}

default_binary() {  # NAME ENVIRONMENT_VALUE
  if [ -n "$2" ]; then
    echo "$2"
  elif [ -x "$repository/build/bin/$1" ]; then
    echo "$repository/build/bin/$1"
  else
    echo "$1"
  fi
}

launch=${ROBIN_LAUNCH:-}
connect_host=""
coordinator_launch=${ROBIN_COORDINATOR_LAUNCH:-}
subdomain_binary=$(default_binary robin-subdomain "${ROBIN_SUBDOMAIN:-}")
coordinator_binary=$(default_binary robin-coordinator "${ROBIN_COORDINATOR:-}")
log_directory=""
server_log_level=info
server_arguments=""
startup_timeout=60
grace=5
server_listen=()   # per server: the endpoint it binds
server_launch=()   # per server: its prefix (one string)
server_connect=()  # per server: the host the coordinator connects to ("" = announced)
server_count=""    # --servers

require_value() {  # OPTION COUNT_OF_REMAINING_ARGUMENTS
  [ "$2" -ge 2 ] || usage_error "option $1 needs a value"
}

while [ $# -gt 0 ]; do
  case "$1" in
    --launch) require_value "$1" $#; launch=$2; shift 2 ;;
    --listen)
      require_value "$1" $#
      server_listen+=("$2"); server_launch+=("$launch"); server_connect+=("$connect_host")
      shift 2 ;;
    --connect-host) require_value "$1" $#; connect_host=$2; shift 2 ;;
    --servers)
      require_value "$1" $#
      [[ $2 =~ ^[1-9][0-9]*$ ]] || usage_error "--servers needs a positive number, got '$2'"
      server_count=$2; shift 2 ;;
    --coordinator-launch) require_value "$1" $#; coordinator_launch=$2; shift 2 ;;
    --subdomain-binary) require_value "$1" $#; subdomain_binary=$2; shift 2 ;;
    --coordinator-binary) require_value "$1" $#; coordinator_binary=$2; shift 2 ;;
    --log-dir) require_value "$1" $#; log_directory=$2; shift 2 ;;
    --server-log-level) require_value "$1" $#; server_log_level=$2; shift 2 ;;
    --server-arguments) require_value "$1" $#; server_arguments=$2; shift 2 ;;
    --startup-timeout) require_value "$1" $#; startup_timeout=$2; shift 2 ;;
    --grace) require_value "$1" $#; grace=$2; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed -e '$d' -e 's/^# \{0,1\}//'; exit 0 ;;
    --) shift; break ;;
    -*) usage_error "unknown option $1 (robin-coordinator options go after CASE; see --help)" ;;
    *) break ;;
  esac
done
[ $# -ge 1 ] || usage_error "missing CASE (see --help)"
coordinator_arguments=("$@")

# One server per body: the case's [[body]] tables, when the case is readable here.
bodies=$(case_body_count "$1")
if [ ${#server_listen[@]} -gt 0 ]; then
  if [ -n "$server_count" ] && [ "$server_count" -ne ${#server_listen[@]} ]; then
    usage_error "--servers $server_count, but ${#server_listen[@]} servers declared with --listen"
  fi
  server_count=${#server_listen[@]}
elif [ -z "$server_count" ]; then
  server_count=2
  [ "$bodies" -lt 2 ] || server_count=$bodies
fi
if [ "$bodies" -ge 2 ] && [ "$server_count" -ne "$bodies" ]; then
  usage_error "the case $1 has $bodies bodies, but $server_count servers were declared: give" \
    "one --listen per body (body order), or --servers $bodies"
fi
if [ ${#server_listen[@]} -eq 0 ]; then
  for ((index = 0; index < server_count; ++index)); do
    server_listen+=("tcp://127.0.0.1:*")
    server_launch+=("$launch")
    server_connect+=("$connect_host")
  done
fi

if [ -z "$log_directory" ]; then
  for ((index = 0; index < ${#coordinator_arguments[@]} - 1; ++index)); do
    case "${coordinator_arguments[index]}" in
      --output | -o) log_directory="${coordinator_arguments[index + 1]}/logs" ;;
    esac
  done
  [ -n "$log_directory" ] || log_directory=$(mktemp -d -t robin-servers.XXXXXX)
fi
mkdir -p "$log_directory"

# --- Stopping -------------------------------------------------------------------------------

server_pids=()
coordinator_pid=""

# Sends SIGTERM to the given processes, SIGKILL to those still running after $grace seconds,
# and reaps them all. (The functions below run from traps, which shellcheck does not follow.)
# shellcheck disable=SC2317
terminate() {
  local pid deadline
  [ $# -gt 0 ] || return 0
  for pid in "$@"; do kill -TERM "$pid" 2> /dev/null || true; done
  deadline=$((SECONDS + grace))
  for pid in "$@"; do
    while kill -0 "$pid" 2> /dev/null && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.1; done
    if kill -0 "$pid" 2> /dev/null; then
      log "process $pid did not stop within ${grace} s: SIGKILL"
      kill -KILL "$pid" 2> /dev/null || true
    fi
    wait "$pid" 2> /dev/null || true
  done
}

# shellcheck disable=SC2317
stop_everything() {
  trap '' INT TERM HUP
  if [ -n "$coordinator_pid" ]; then
    terminate "$coordinator_pid"
    coordinator_pid=""
  fi
  if [ ${#server_pids[@]} -gt 0 ]; then
    terminate "${server_pids[@]}"
    log "servers stopped"
    server_pids=()
  fi
}

trap stop_everything EXIT
trap 'log "interrupted (SIGINT)"; exit 130' INT
trap 'log "interrupted (SIGTERM)"; exit 143' TERM
trap 'log "interrupted (SIGHUP)"; exit 129' HUP

# --- Starting -------------------------------------------------------------------------------

# Starts server INDEX through its prefix, its standard output in server-N.out (where the
# "listening on" line arrives) and its standard error in server-N.log.
start_server() {
  local index=$1 number=$(($1 + 1)) prefix_words=() extra_words=()
  read -r -a prefix_words <<< "${server_launch[index]}"
  read -r -a extra_words <<< "$server_arguments"
  "${prefix_words[@]}" "$subdomain_binary" --listen "${server_listen[index]}" \
    --name "server-$number" --log-level "$server_log_level" "${extra_words[@]}" \
    > "$log_directory/server-$number.out" 2> "$log_directory/server-$number.log" < /dev/null &
  server_pids+=($!)
  log "server $number: ${server_launch[index]:+${server_launch[index]} }$subdomain_binary" \
    "--listen ${server_listen[index]} (pid $!)"
}

# The end of a server's output and log, for error messages.
server_tail() {
  local number=$1
  tail -n 5 "$log_directory/server-$number.out" "$log_directory/server-$number.log" 2> /dev/null |
    sed 's/^/    /' || true
}

# Waits for the "listening on" line of server INDEX and prints the endpoint to connect to.
await_endpoint() {
  local index=$1 number=$(($1 + 1)) line endpoint host deadline=$((SECONDS + startup_timeout))
  # The line starts with "listening on"; through a terminal (ssh -tt) the server's log lines,
  # which also contain "listening on", arrive in the same stream.
  until line=$(grep -a -m 1 '^listening on ' "$log_directory/server-$number.out" 2> /dev/null); do
    if ! kill -0 "${server_pids[index]}" 2> /dev/null; then
      die "server $number (${server_listen[index]}) exited before listening:"$'\n'"$(server_tail "$number")"
    fi
    if [ $SECONDS -ge "$deadline" ]; then
      die "server $number (${server_listen[index]}): no 'listening on' line within" \
        "${startup_timeout} s:"$'\n'"$(server_tail "$number")"
    fi
    sleep 0.1
  done
  endpoint=${line##*listening on }
  endpoint=${endpoint%$'\r'}  # a terminal (ssh -tt) ends lines with CR LF
  host=${endpoint#*://}
  host=${host%:*}
  if [ -n "${server_connect[index]}" ]; then
    endpoint="${endpoint%%://*}://${server_connect[index]}:${endpoint##*:}"
  elif [ "$host" = "0.0.0.0" ] || [ "$host" = "*" ] || [ "$host" = "[::]" ]; then
    die "server $number announced $endpoint (a wildcard address): give --connect-host HOST"
  fi
  echo "$endpoint"
}

for index in "${!server_listen[@]}"; do start_server "$index"; done
subdomain_options=()
for index in "${!server_listen[@]}"; do
  endpoint=$(await_endpoint "$index") || exit 1
  log "server $((index + 1)) listening on $endpoint"
  subdomain_options+=(--subdomain "$endpoint")
done

# --- The coordinator ------------------------------------------------------------------------

coordinator_words=()
read -r -a coordinator_words <<< "$coordinator_launch"
log "coordinator: ${coordinator_launch:+$coordinator_launch }$coordinator_binary" \
  "${coordinator_arguments[*]} ${subdomain_options[*]}"
"${coordinator_words[@]}" "$coordinator_binary" "${coordinator_arguments[@]}" \
  "${subdomain_options[@]}" < /dev/null &
coordinator_pid=$!
status=0
wait "$coordinator_pid" || status=$?
coordinator_pid=""
log "coordinator exited with status $status"
exit "$status"
