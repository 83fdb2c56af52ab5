# shellcheck shell=bash
# Sourced by scripts/netns.sh and scripts/multihost.sh: the two halves of running a command as
# PID 1 of fresh namespaces, so that the kernel ends everything it started when it ends.
# Bash; works under `set -euo pipefail`.

# wait_for_exit PID: waits until the background job PID has ended and returns its exit
# status. `wait` returns early (status > 128) when a trapped signal arrives; it waits on.
wait_for_exit() {
  local status=0
  while true; do
    wait "$1" && status=0 || status=$?
    kill -0 "$1" 2>/dev/null || break
  done
  return "$status"
}

# forward_to_pid1: the signal handler of unshare_supervised.
forward_to_pid1() {
  if [ -n "${unshare_supervised_pid1:-}" ]; then
    kill -TERM "$unshare_supervised_pid1" 2>/dev/null || true
  fi
}

# unshare_supervised PIDFILE UNSHARE_ARGS...: runs `unshare UNSHARE_ARGS...` (which must
# --fork into a new PID namespace) and stands in for it: writes the host PID of the new
# namespace's PID 1 (unshare's child) to PIDFILE unless it is empty, passes SIGTERM, SIGINT
# and SIGHUP on to that PID 1 (unshare blocks them while it waits), and exits with unshare's
# exit status.
unshare_supervised() {
  local pidfile=$1
  shift
  unshare "$@" &
  local unshare_pid=$!
  # Global, not local: forward_to_pid1 reads it when a signal arrives.
  unshare_supervised_pid1=""
  local _
  for _ in $(seq 1 200); do
    unshare_supervised_pid1=$(pgrep -P "$unshare_pid" || true)
    [ -n "$unshare_supervised_pid1" ] && break
    kill -0 "$unshare_pid" 2>/dev/null || break
    sleep 0.01
  done
  if [ -n "$pidfile" ] && [ -n "$unshare_supervised_pid1" ]; then
    echo "$unshare_supervised_pid1" >"$pidfile"
  fi
  trap 'forward_to_pid1' TERM INT HUP
  local status=0
  wait_for_exit "$unshare_pid" || status=$?
  exit "$status"
}
