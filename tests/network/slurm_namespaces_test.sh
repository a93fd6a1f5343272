#!/usr/bin/env bash
# deploy/slurm/robin-contact.sbatch on a SLURM cluster made of network namespaces: slurmctld in
# the coordinator's namespace (host "ctl"), one slurmd in each server namespace (nodes "node1"
# and "node2", each with its own host name), munged (in the coordinator's namespace, reached
# through its socket file) for authentication. Every SLURM and munge file (slurm.conf, key,
# socket, state, spool, logs) lives in the work directory, and the host names are in an
# /etc/hosts bound over the real one inside the daemons' own mount namespaces only; no system
# daemon, configuration or port is used (a munged, slurmctld or slurmd of the host's, Debian's
# munge.service for one, neither serves nor disturbs this cluster).
#
#   tests/network/slurm_namespaces_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]
#
# Checks, for examples/two_blocks.toml:
#  1. sbatch: the job completes with exit code 0, its servers ran as job steps on node1 and
#     node2 and were reached by node name, contact.csv equals that of robin-run on this machine
#     computed by this test (lambda1, lambda2, un1, un2 to 1e-12 relative), and no server is
#     left.
#  2. scancel while the coordinator runs (a stub that sleeps): the job is cancelled,
#     remote-servers.sh receives SIGTERM, and neither the servers nor the coordinator are left
#     (SLURM also ends the server steps itself).
# It takes about 15 s; every wait is bounded (nodes idle 60 s, the job 60 s, the cancelled job
# 30 s), well inside CTest's timeout. Exit code 77 (skipped) without root or where network namespaces cannot be created. Without
# the SLURM programs (Debian packages slurmctld, slurmd, slurm-client, munge; deploy/setup.sh
# installs them) it skips too, unless ROBIN_REQUIRE_SLURM=1 (set by deploy/test.sh, so CI
# cannot skip it silently): then it fails. Everything it started (daemons, job processes,
# namespaces, and with them the bind mounts) is removed on any exit; a run killed by SIGKILL
# leaves its namespaces and the processes in them to the next run's remove_stale_namespaces.
set -euo pipefail

binary_directory=$(cd "${1:?usage: slurm_namespaces_test.sh BINARY_DIRECTORY [SOURCE_DIRECTORY]}" && pwd)
source_directory=$(cd "${2:-$(dirname "$0")/../..}" && pwd)
case_file=examples/two_blocks.toml
batch_script=$source_directory/deploy/slurm/robin-contact.sbatch
coordinator_override=""  # the coordinator of the next job, when not the built one

# shellcheck source=tests/network/network_namespaces.sh
source "$(dirname "$0")/network_namespaces.sh"
require_namespace_tools

# Skips (77) without the SLURM and munge programs, or fails with ROBIN_REQUIRE_SLURM=1: where
# deploy/setup.sh ran, a missing program is a setup bug, not a reason to skip.
require_slurm() {
  local tool message
  for tool in slurmctld slurmd sbatch squeue scancel scontrol sinfo munged nsenter unshare; do
    command -v "$tool" > /dev/null && continue
    message="$tool is missing (Debian packages slurmctld slurmd slurm-client munge;"
    message+=" deploy/setup.sh installs them)"
    [ "${ROBIN_REQUIRE_SLURM:-0}" != 1 ] || fail "$message, and ROBIN_REQUIRE_SLURM=1"
    skip "$message"
  done
}

# host_prefix NAMESPACE HOST: sets `prefix` to the command words that run a command in
# NAMESPACE's network with host name HOST and the test's /etc/hosts (in their own UTS and mount
# namespaces: the real /etc/hosts is untouched). Each program execs the next, so a background
# command's $! is the command itself.
host_prefix() {
  # shellcheck disable=SC2016  # expanded by that sh
  prefix=(nsenter --net="/run/netns/$1" unshare --uts --mount
    sh -c 'mount --bind "$0" /etc/hosts && hostname "$1" && shift 2 && exec "$@"' "$work/hosts" "$2" --)
}
controller() {
  local prefix
  host_prefix "$coordinator_namespace" ctl
  "${prefix[@]}" "$@"
}

# munged with its own key and socket; slurm.conf for the controller and the two nodes.
write_configuration() {
  local slurm=$work/slurm
  mkdir -p "$slurm/state" "$slurm/spool/node1" "$slurm/spool/node2"
  printf '127.0.0.1 localhost\n%s ctl\n%s node1\n%s node2\n' \
    "$coordinator_address" "${server_addresses[0]}" "${server_addresses[1]}" > "$work/hosts"
  dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 status=none
  chmod 600 "$work/munge.key"
  cat > "$slurm/slurm.conf" << EOF
ClusterName=robintest
SlurmctldHost=ctl($coordinator_address)
AuthType=auth/munge
AuthInfo=socket=$work/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$slurm/state
SlurmdSpoolDir=$slurm/spool/%n
SlurmctldPidFile=$slurm/slurmctld.pid
SlurmdPidFile=$slurm/slurmd-%n.pid
SlurmctldLogFile=$slurm/slurmctld.log
SlurmdLogFile=$slurm/slurmd-%n.log
ProctrackType=proctrack/pgid
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SlurmdParameters=config_overrides
KillWait=5
NodeName=node1 NodeAddr=${server_addresses[0]} CPUs=2 State=UNKNOWN
NodeName=node2 NodeAddr=${server_addresses[1]} CPUs=2 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF=$slurm/slurm.conf
}

start_cluster() {
  # munged in the coordinator's namespace, so that a run killed before its cleanup leaves it to
  # the next run's remove_stale_namespaces; clients reach it through the socket file.
  nsenter --net="/run/netns/$coordinator_namespace" munged --force --foreground \
    --key-file="$work/munge.key" --socket="$work/munge.socket" --pid-file="$work/munged.pid" \
    --seed-file="$work/munge.seed" --log-file="$work/munged.log" 2> "$work/munged.stderr" &
  started_pids+=($!)
  for _ in $(seq 50); do [ -S "$work/munge.socket" ] && break; sleep 0.1; done
  [ -S "$work/munge.socket" ] || fail "munged did not start: $(cat "$work/munged.stderr")"
  local prefix index states=""
  host_prefix "$coordinator_namespace" ctl
  "${prefix[@]}" slurmctld -D -i > "$work/slurmctld.out" 2>&1 &
  started_pids+=($!)
  for index in 1 2; do
    host_prefix "${server_namespaces[index - 1]}" "node$index"
    "${prefix[@]}" slurmd -D -N "node$index" > "$work/slurmd-node$index.out" 2>&1 &
    started_pids+=($!)
  done
  for _ in $(seq 120); do
    states=$(controller sinfo --noheader --format=%T 2> /dev/null | sort -u | tr '\n' ' ')
    [ "$states" = "idle " ] && break
    sleep 0.5
  done
  [ "$states" = "idle " ] || fail "the nodes are not idle after 60 s: '$states'"
  echo "SLURM: $(controller sinfo --noheader --format='%P %D nodes %N %T')"
}

# submit OUTPUT_DIRECTORY: sbatch the batch script; prints the job id.
# The job inherits this environment (sbatch --export=ALL): SLURM_CONF and the executables.
submit() {
  local prefix
  host_prefix "$coordinator_namespace" ctl
  (cd "$source_directory" && env ROBIN_HOME="$source_directory" \
    ROBIN_SUBDOMAIN="$binary_directory/robin-subdomain" \
    ROBIN_COORDINATOR="${coordinator_override:-$binary_directory/robin-coordinator}" \
    "${prefix[@]}" sbatch --parsable --output="$work/job-%j.out" --cpus-per-task=1 \
    "$batch_script" "$case_file" "$1")
}

await_job_end() {  # JOB_ID SECONDS
  for _ in $(seq $(($2 * 2))); do
    [ -z "$(controller squeue --noheader --jobs="$1" 2> /dev/null)" ] && return 0
    sleep 0.5
  done
  fail "job $1 still in the queue after $2 s: $(controller squeue --jobs="$1")"
}

job_field() {  # JOB_ID FIELD
  controller scontrol show job "$1" | tr ' ' '\n' | sed -n "s/^$2=//p"
}

servers_left() {
  local namespace pid
  for namespace in "${server_namespaces[@]}" "$coordinator_namespace"; do
    for pid in $(ip netns pids "$namespace"); do
      case "$(cat "/proc/$pid/comm" 2> /dev/null)" in
        robin-subdomain | robin-coordina* | sleep) echo -n "$pid " ;;
      esac
    done
  done
}

check_batch_job() {
  local job comparison node
  job=$(submit "$work/slurm-run")
  await_job_end "$job" 60
  echo "job $job: $(job_field "$job" JobState), exit code $(job_field "$job" ExitCode)," \
    "nodes $(job_field "$job" NodeList)"
  if [ "$(job_field "$job" JobState)" != COMPLETED ] || [ "$(job_field "$job" ExitCode)" != 0:0 ]; then
    fail "job $job: $(cat "$work/job-$job.out")"
  fi
  # The coordinator reached the servers by node name (node1 resolves to an address that exists
  # only in node1's namespace), and each node's slurmd launched a step of the job.
  if ! grep -q "server 1 listening on tcp://node1:5555" "$work/job-$job.out" ||
    ! grep -q "server 2 listening on tcp://node2:5556" "$work/job-$job.out"; then
    fail "the servers did not run on node1 and node2: $(cat "$work/job-$job.out")"
  fi
  for node in node1 node2; do
    grep -q "launch task StepId=$job\\." "$work/slurm/slurmd-$node.log" ||
      fail "no step of job $job was launched on $node: $(cat "$work/slurm/slurmd-$node.log")"
  done
  [ "$(job_field "$job" BatchHost)" = node1 ] || fail "job $job: batch host $(job_field "$job" BatchHost)"
  grep -q "remote-servers: servers stopped" "$work/job-$job.out" ||
    fail "remote-servers.sh did not stop the servers: $(cat "$work/job-$job.out")"
  comparison=$(compare_contact "$work/local" "$work/slurm-run") ||
    fail "contact.csv of the SLURM job differs from the local run: $comparison"
  echo "sbatch deploy/slurm/robin-contact.sbatch: $comparison"
  [ -z "$(servers_left)" ] || fail "processes left after the job: $(servers_left)"
}

check_cancel() {
  local job stub=$work/stub-coordinator.sh
  printf '#!/bin/sh\necho "$@" > "%s/stub.arguments"\nexec sleep 300\n' "$work" > "$stub"
  chmod +x "$stub"
  job=$(coordinator_override=$stub submit "$work/slurm-cancelled")
  for _ in $(seq 60); do [ -s "$work/stub.arguments" ] && break; sleep 0.5; done
  [ -s "$work/stub.arguments" ] || fail "the coordinator of job $job did not start: $(cat "$work/job-$job.out")"
  controller scancel "$job"
  await_job_end "$job" 30
  for _ in $(seq 50); do [ -z "$(servers_left)" ] && break; sleep 0.2; done
  [ -z "$(servers_left)" ] || fail "processes left after scancel: $(servers_left)"
  # SLURM cancels the server steps itself; the batch script is signalled too.
  grep -q "remote-servers: interrupted (SIGTERM)" "$work/job-$job.out" ||
    fail "remote-servers.sh was not signalled: $(cat "$work/job-$job.out")"
  # The batch script execs remote-servers.sh: its cleanup ran to the end (before KillWait).
  grep -q "remote-servers: servers stopped" "$work/job-$job.out" ||
    fail "remote-servers.sh did not finish stopping the servers: $(cat "$work/job-$job.out")"
  [ "$(job_field "$job" JobState)" = CANCELLED ] || fail "job $job: $(job_field "$job" JobState)"
  echo "scancel of job $job while its coordinator ran: CANCELLED, remote-servers.sh got" \
    "SIGTERM and stopped the servers, no server or coordinator left"
}

remove_stale_namespaces
create_network
require_slurm
timeout 60 "$binary_directory/robin-run" "$source_directory/$case_file" --output "$work/local" \
  --log-level warn 2> "$work/robin-run.log" || fail "robin-run exited with status $?"
write_configuration
start_cluster
check_batch_job
check_cancel
echo "PASSED: the SLURM batch script on a cluster of network namespaces"
