#!/usr/bin/env bash
# Training over a lossy loopback: a run of auvrl train without and then with datagram loss and
# delay jitter (tc netem on lo), each in a private network namespace of its own (the netem
# rule exists only there; the host's interfaces are never touched), and a table of what each
# achieved: env steps/s, updates/s, episodes, success over the last 100 episodes, episodes
# ended by a lockstep timeout (auv_actor gives up on a step after 5 x 200 ms and starts a new
# episode).
#   scripts/netem.sh [--loss 10%] [--delay 5ms] [--jitter 5ms] [--seconds 60] [--actors 1]
#                    [--preset fast] [--lockstep-timeout-ms MS] [--no-baseline]
#                    [-- extra auvrl train options]
# --lockstep-timeout-ms sets actor.lockstep_timeout_ms (default 200) in both runs: each lost
# lockstep datagram costs one such timeout.
# Needs tc (iproute2) with the kernel's netem qdisc; where the kernel has no netem (this
# project's 2-core VMs: "Specified qdisc kind is unknown") it falls back to dropping the same
# share of UDP datagrams on input with nftables (apt-get install nftables), without delay or
# jitter, and says so. Root or user namespaces, as scripts/netns.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${AUVRL_BIN_DIR:-$root/build/bin}
loss=10% delay=5ms jitter=5ms seconds=60 actors=1 preset=fast baseline=1 timeout_ms=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --loss) loss=$2; shift 2 ;;
    --delay) delay=$2; shift 2 ;;
    --jitter) jitter=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --actors) actors=$2; shift 2 ;;
    --preset) preset=$2; shift 2 ;;
    --no-baseline) baseline=0; shift ;;
    --lockstep-timeout-ms) timeout_ms=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
done
command -v tc >/dev/null || { echo "netem: tc is missing (apt-get install iproute2)" >&2; exit 1; }
# Never on the host's network: a run must get a namespace of its own.
[ "${AUVRL_NETWORK:-}" != host ] || { echo "netem: refused with AUVRL_NETWORK=host" >&2; exit 1; }
out=$root/runs/netem-$(date +%Y%m%d-%H%M%S)
mkdir -p "$out"
# The preset, its vehicle path made absolute, with the lockstep timeout if one was given.
config=$out/config.yaml
sed -e "s|^vehicle: \.\./|vehicle: $root/config/|" \
  ${timeout_ms:+-e "s|^actor:|actor:\n  lockstep_timeout_ms: $timeout_ms|"} \
  "$root/config/presets/$preset.yaml" >"$config"

# Run inside the namespace before training: checks that lo is the only interface (not the
# host's network), then impairs lo (netem, or the nftables loss-only fallback).
impair='
  if awk "NR > 2 && \$1 != \"lo:\" { found = 1 } END { exit !found }" /proc/self/net/dev; then
    echo "netem: interfaces besides lo here (not a private namespace); refused" >&2; exit 1
  fi
  if [ -n "$LOSS" ]; then
    if tc qdisc add dev lo root netem loss "$LOSS" delay "$DELAY" "$JITTER" 2>/dev/null; then
      echo "netem: $(tc qdisc show dev lo)" >&2
    else
      command -v nft >/dev/null || { echo "netem: no netem in this kernel and no nft" >&2; exit 1; }
      echo "netem: no netem qdisc in this kernel: dropping ${LOSS} of UDP datagrams on input" \
           "(nftables), NO delay or jitter" >&2
      nft add table inet auvrl_loss
      nft add chain inet auvrl_loss in "{ type filter hook input priority 0; }"
      nft add rule inet auvrl_loss in meta l4proto udp numgen random mod 100 "<" "${LOSS%\%}" \
        counter drop
    fi
  fi
  exec "$0" "$@"'
# run NAME [impaired]: one training run in a fresh namespace.
run() {
  local name=$1 impaired=${2:-}
  echo "netem: $name run (${seconds} s${timeout_ms:+, lockstep timeout $timeout_ms ms}), load $(cut -d' ' -f1-3 /proc/loadavg)" >&2
  LOSS=${impaired:+$loss} DELAY=$delay JITTER=$jitter "$root/scripts/netns.sh" bash -c "$impair" \
    "$bin/auvrl" train --network host --config "$config" --actors "$actors" \
    --max-seconds "$seconds" --no-eval --run-dir "$out/$name" "${extra[@]}" \
    >"$out/$name.log" 2>&1 || echo "netem: $name run exit $? (see $out/$name.log)" >&2
}
# summary NAME: one table row from the run's CSV files.
summary() {
  local dir=$out/$1
  awk -F, -v name="$1" '
    FNR == 1 { file++; next }
    file == 1 { steps += $5; rows++; last_success = $3; last_episodes = $2; ups += $6 }
    file == 2 { episodes++; if ($11 == 5) timeouts++ }
    END { printf "%-10s %10.0f %10.0f %9d %9.0f%% %9d\n", name, rows ? steps / rows : 0,
            rows ? ups / rows : 0, episodes, 100 * last_success, timeouts }' \
    "$dir/progress.csv" "$dir/episodes.csv"
}

[ "$baseline" = 1 ] && run clean
run lossy impaired
printf '%-10s %10s %10s %9s %10s %9s\n' run "steps/s" "updates/s" episodes "success" timeouts
[ "$baseline" = 1 ] && summary clean
summary lossy
grep -h '^netem:' "$out/lossy.log" || true
echo "(steps/s and updates/s: means of progress.csv; success: last 100 episodes at the end;"
echo " timeouts: episodes ended by a lockstep timeout; runs in $out)"
