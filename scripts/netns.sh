#!/usr/bin/env bash
# Runs a command inside a private network namespace, so that nothing it starts can send a
# packet off this machine: not even the IGMP membership report that an LCM subscriber on the
# host's interface sends with ttl=0. Inside: lo up, multicast on lo, 224.0.0.0/4 routed to lo.
#
#   scripts/netns.sh [--pidfile FILE] CMD [ARGS...]   run CMD in a fresh namespace
#   scripts/netns.sh --join PID CMD [ARGS...]         run CMD in the namespace of process PID
#                                                     (lcm-spy, log tools on a running system)
#   scripts/netns.sh --network host CMD [ARGS...]     explicit opt-out: run CMD on the host's
#                                                     network (also AUVRL_NETWORK=host)
#
# The namespace also has its own PID space whose first process is this script: when CMD ends
# (or this script is killed with SIGTERM/SIGINT), the kernel ends every process left inside,
# so the helper always kills what it started. The pidfile holds the host PID of that first
# process: --join enters its network namespace, and SIGTERM to it stops the run.
set -euo pipefail

usage() { sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
# shellcheck source=scripts/lib/namespace_pid1.sh
. "$(dirname "$(readlink -f "$0")")/lib/namespace_pid1.sh"

setup_loopback() {
  ip link set lo up
  ip link set lo multicast on
  ip route add 224.0.0.0/4 dev lo 2>/dev/null || true
}

[ $# -ge 1 ] || usage
pidfile=""
case "$1" in
  --inside)
    # PID 1 of the new namespaces: set up lo, run the command, pass signals on, then return
    # its exit status. Leaving ends every process still in the namespace.
    shift
    setup_loopback
    "$@" &
    child=$!
    trap 'kill -TERM "$child" 2>/dev/null || true' TERM INT HUP
    status=0
    wait_for_exit "$child" || status=$?
    exit "$status"
    ;;
  --join)
    [ $# -ge 3 ] || usage
    pid=$2; shift 2
    if [ "$(id -u)" -eq 0 ]; then
      exec nsenter -t "$pid" -n -- "$@"
    else
      exec nsenter -t "$pid" -U -n --preserve-credentials -- "$@"
    fi
    ;;
  --network)
    if [ $# -lt 3 ] || [ "$2" != host ]; then usage; fi
    shift 2
    exec "$@"
    ;;
  --pidfile)
    [ $# -ge 3 ] || usage
    pidfile=$2
    shift 2
    ;;
  -h|--help) usage ;;
esac
[ $# -ge 1 ] || usage

if [ "${AUVRL_NETWORK:-}" = host ]; then
  exec "$@"
fi

self=$(readlink -f "$0")
if [ "$(id -u)" -eq 0 ]; then
  flags=(-n -p)
else
  flags=(-r -n -p)  # a user namespace maps us to root inside, so lo can be configured
fi
# unshare enters the new network namespace and forks PID 1 of the new PID namespace (the
# --inside branch above); --kill-child ends that one if unshare itself is killed. unshare
# blocks SIGINT/SIGTERM while it waits, so signals for the run go to PID 1 directly.
unshare_supervised "$pidfile" "${flags[@]}" --fork --kill-child=TERM -- "$self" --inside "$@"
