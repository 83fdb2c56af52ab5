#!/usr/bin/env bash
# Training over a lossy loopback: a run of auvrl train without and then with datagram loss and
# delay jitter on lo, each in a private network namespace of its own (the impairment exists
# only there; the host's interfaces are never touched), and a table of what each achieved: env
# steps/s, updates/s, episodes, success over the last 100 episodes, episodes ended by a
# lockstep timeout (auv_actor gives up on a step after 5 x 200 ms and starts a new episode).
#   scripts/netem.sh [--loss 10%] [--delay 5ms] [--jitter 5ms] [--seconds 60] [--actors 1]
#                    [--preset fast] [--lockstep-timeout-ms MS] [--no-baseline] [--seed 1]
#                    [-- extra auvrl train options]
# --lockstep-timeout-ms sets actor.lockstep_timeout_ms (default 200) in both runs: each lost
# lockstep datagram costs one such timeout. Each namespace's UDP echo round trip on lo
# (scripts/udp_rtt.py: p50/p99 of 300 probes) is printed before its run.
# Impairment, the first that works: tc netem (iproute2, the kernel's netem qdisc); else, where
# the kernel has no netem (this project's VMs: "Specified qdisc kind is unknown"), auv_netdelay
# (built where libnetfilter-queue-dev is installed) on an iptables NFQUEUE rule for UDP sent on
# lo: the --loss share dropped (seeded, --seed), every other datagram held --delay +- --jitter
# (uniform, clamped at 0) in user space, so a round trip on lo takes two such delays; else an
# nftables rule that drops the loss share on input, without delay or jitter (it says so).
# Root or user namespaces, as scripts/netns.sh.
# What it measured: docs/results.md (lossy network).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${AUVRL_BIN_DIR:-$root/build/bin}
loss=10% delay=5ms jitter=5ms seconds=60 actors=1 preset=fast baseline=1 timeout_ms="" seed=1
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
    --seed) seed=$2; shift 2 ;;
    --lockstep-timeout-ms) timeout_ms=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
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
# host's network), then impairs lo (netem; where the kernel has none, auv_netdelay on an
# NFQUEUE rule; failing that, the nftables loss-only fallback), measures the UDP round trip on
# lo, trains, and stops auv_netdelay (which prints what it delayed and dropped).
impair='
  if awk "NR > 2 && \$1 != \"lo:\" { found = 1 } END { exit !found }" /proc/self/net/dev; then
    echo "netem: interfaces besides lo here (not a private namespace); refused" >&2; exit 1
  fi
  tool=""
  if [ -n "$LOSS" ]; then
    if tc qdisc add dev lo root netem loss "$LOSS" delay "$DELAY" "$JITTER" 2>/dev/null; then
      echo "netem: $(tc qdisc show dev lo)" >&2
    elif [ -x "$NETDELAY" ] && command -v iptables >/dev/null &&
         iptables -A OUTPUT -o lo -p udp -j NFQUEUE --queue-num 7 --queue-bypass; then
      # Every UDP datagram sent on lo goes through queue 7 once; --queue-bypass accepts them
      # all when auv_netdelay is not there (never a blackhole).
      "$NETDELAY" --queue 7 --delay "$DELAY" --jitter "$JITTER" --loss "$LOSS" \
        --seed "$SEED" 2>"$TOOL_LOG" &
      tool=$!
      for _ in $(seq 50); do grep -q bound "$TOOL_LOG" && break; sleep 0.1; done
      grep -q bound "$TOOL_LOG" || { cat "$TOOL_LOG" >&2; exit 1; }
      echo "netem: no netem qdisc in this kernel: auv_netdelay on NFQUEUE 7 (iptables OUTPUT" \
           "-o lo -p udp): ${LOSS} of UDP datagrams dropped, the rest held ${DELAY} +- ${JITTER}" \
           "(uniform)" >&2
    else
      command -v nft >/dev/null || { echo "netem: no netem in this kernel and no nft" >&2; exit 1; }
      echo "netem: no netem qdisc in this kernel and no auv_netdelay/iptables: dropping" \
           "${LOSS} of UDP datagrams on input (nftables), NO delay or jitter" >&2
      nft add table inet auvrl_loss
      nft add chain inet auvrl_loss in "{ type filter hook input priority 0; }"
      nft add rule inet auvrl_loss in meta l4proto udp numgen random mod 100 "<" "${LOSS%\%}" \
        counter drop
    fi
  fi
  if command -v python3 >/dev/null; then
    echo "netem: $(python3 "$RTT" 300 2 50)" >&2
  fi
  status=0
  "$0" "$@" || status=$?
  if [ -n "$tool" ]; then
    kill -TERM "$tool"; wait "$tool" || true
    sed "s/^/netem: /" "$TOOL_LOG" >&2
  fi
  exit "$status"'
# run NAME [impaired]: one training run in a fresh namespace.
run() {
  local name=$1 impaired=${2:-}
  echo "netem: $name run (${seconds} s${timeout_ms:+, lockstep timeout $timeout_ms ms}), load $(cut -d' ' -f1-3 /proc/loadavg)" >&2
  LOSS=${impaired:+$loss} DELAY=$delay JITTER=$jitter SEED=$seed NETDELAY=$bin/auv_netdelay \
    RTT=$root/scripts/udp_rtt.py TOOL_LOG=$out/$name.netdelay.log \
    "$root/scripts/netns.sh" bash -c "$impair" \
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
grep -h '^netem:' "$out/clean.log" "$out/lossy.log" 2>/dev/null || true
echo "(steps/s and updates/s: means of progress.csv; success: last 100 episodes at the end;"
echo " timeouts: episodes ended by a lockstep timeout; runs in $out)"
