#!/usr/bin/env bash
# Soak test: auvrl train with many actors for a long time (default 8 actors, 600 s, the fast
# preset, inside its private network namespace), then a table of every process's resident
# memory (VmRSS) at the start (after WARMUP s) and at the end, to show that no queue or buffer
# grows without bound. The learner's replay buffer legitimately grows until it is full
# (learner.replay_capacity transitions); everything else should stay flat.
#   scripts/soak.sh [--actors N] [--seconds S] [--warmup S] [--preset NAME] [--run-dir DIR]
#                   [-- extra auvrl train options]
# Exit status: auvrl train's. The table also goes to RUN/soak_memory.txt.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${AUVRL_BIN_DIR:-$root/build/bin}
actors=8 seconds=600 warmup=30 preset=fast run_dir=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --actors) actors=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --preset) preset=$2; shift 2 ;;
    --run-dir) run_dir=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
done
[ -n "$run_dir" ] || run_dir="$root/runs/soak-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$(dirname "$run_dir")"
[ -x "$bin/auvrl" ] || { echo "soak: $bin/auvrl missing (scripts/build.sh)" >&2; exit 1; }

# The processes of the run, seen from here: descendants of the namespace's first process.
descendants() {
  local pid=$1 child
  for child in $(pgrep -P "$pid" || true); do
    echo "$child"
    descendants "$child"
  done
}
# "role pid rss_kb" for every process of the run.
snapshot() {
  local ns_pid pid cmd role
  ns_pid=$(cat "$run_dir/netns.pid" 2>/dev/null || true)
  [ -n "$ns_pid" ] || return 0
  for pid in $(descendants "$ns_pid"); do
    [ -r "/proc/$pid/cmdline" ] || continue
    cmd=$(tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null || true)
    case "$cmd" in
      *auv_sim\ *) role=sim$(sed -n 's/.*--first-vehicle-id \([0-9]*\).*/\1/p' <<<"$cmd") ;;
      *auv_actor\ *) role=actor$(sed -n 's/.*--actor-id \([0-9]*\).*/\1/p' <<<"$cmd") ;;
      *auv_learner\ *) role=learner ;;
      *auv_logger\ *) role=logger ;;
      *auvrl\ train*) role=launcher ;;
      *) continue ;;
    esac
    # taskset execs the program: the same pid, but count each process once.
    echo "$role $pid $(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || echo 0)"
  done | sort -u -k1,1
}

echo "soak: $actors actors, ${seconds} s, preset $preset, run $run_dir (load: $(cut -d' ' -f1-3 /proc/loadavg))"
"$bin/auvrl" train --preset "$preset" --actors "$actors" --max-seconds "$seconds" --no-eval \
  --run-dir "$run_dir" "${extra[@]}" >"$run_dir.log" 2>&1 &
train=$!
trap 'kill -INT "$train" 2>/dev/null || true' INT TERM
sleep "$warmup"
start_table=$(snapshot)
# The last snapshot before the launcher starts stopping its processes.
end_table=$start_table
deadline=$((SECONDS + seconds - warmup - 5))
while kill -0 "$train" 2>/dev/null && [ "$SECONDS" -lt "$deadline" ]; do
  sleep 5
  now=$(snapshot)
  [ -n "$now" ] && end_table=$now
done
status=0
wait "$train" || status=$?

{
  echo "soak: $actors actors for ${seconds} s (preset $preset), auvrl train exit $status"
  echo "load at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
  printf '%-10s %8s %14s %14s %10s\n' role pid "VmRSS start" "VmRSS end" change
  # role pid_start rss_start pid_end rss_end (a role restarted meanwhile has two pids)
  join <(sort <<<"$start_table") <(sort <<<"$end_table") | sort -V |
    awk '{ printf "%-10s %8s %11.1f MB %11.1f MB %+8.1f %%%s\n", $1, $4, $3 / 1024, $5 / 1024,
           ($5 - $3) * 100 / ($3 > 0 ? $3 : 1), ($2 != $4 ? "  (restarted)" : "") }' 
  # The learner's replay buffer (legitimate growth until it is full), at the same moments.
  awk -F, -v w="$warmup" 'NR > 1 && $1 >= w && !first { first = $6 } NR > 1 { last = $6 }
    END { print "learner replay buffer: " first " transitions at the start, " last " at the end" }' \
    "$run_dir/learner.csv"
  grep -E "restarting|silent for|times within" "$run_dir.log" || echo "no process restarted"
  tail -n 3 "$run_dir/progress.csv" 2>/dev/null || true
} | tee "$run_dir/soak_memory.txt"
exit "$status"
