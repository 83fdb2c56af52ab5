#!/usr/bin/env bash
# The training system on three "hosts": network namespaces A, B and C (10.77.0.1-3/24), each
# joined by a veth pair to a Linux bridge in a fourth namespace. Nothing touches the host's
# network: every namespace, link, address, route and nftables rule is created inside a private
# network + PID + mount namespace of this script's own, and vanishes with it (the kernel ends
# every process left in it when the script ends, whatever the reason).
#
#   A: auv_sim (vehicle 0) + auv_actor 0 (a lockstep pair stays on one host), probe
#   B: auv_learner, probe
#   C: auv_logger, auv_sim (vehicle 1) + auv_actor 1, probe
# (the probe, build/bin/multihost_probe, counts what reaches its namespace)
#
#   scripts/multihost.sh [--transport dds|lcm] [--links no-multicast|multicast] [--lcm-ttl N]
#                        [--loss PCT] [--seconds S] [--hidden H] [--security] [--out DIR]
#                        [--check]
#   scripts/multihost.sh --ci       the CTest form (test_multihost): DDS with --loss 5 --check,
#                                   then DDS with --security --check, then LCM on the same
#                                   links, where nothing may cross
#
# --links no-multicast (default): `ip link set eth0 multicast off` on every link, no multicast
#   route on them (224.0.0.0/4 goes to lo, as in every private namespace of this project, so
#   that LCM can start at all); multicast: multicast on, 224.0.0.0/4 routed over the link (LCM
#   then also needs --lcm-ttl 1: with the default ttl=0 nothing leaves a namespace).
# --loss PCT: each namespace drops PCT % of the UDP frames (IP packets, fragments included)
#   that arrive over its link, with nftables (numgen random), because this kernel has no netem
#   ("tc qdisc add dev eth0 root netem loss 5%" -> "Error: Specified qdisc kind is unknown.").
#   Only traffic from the other namespaces is dropped; the namespace's own looped-back
#   multicast is not. Loss starts with the run, discovery included.
# --check: exit 1 unless the run delivered what the transport promises (DDS: every transition
#   sent reached the learner, the newest weights reached both actor namespaces, episodes and
#   updates happened, the logger logged every episode; LCM with --links no-multicast: nothing
#   crossed a link). Exit 77 when namespaces cannot be made (no root, no user namespaces).
#
# --security (DDS): every process authenticated, access-controlled and encrypted (DDS Security,
#   a PKI made by scripts/pki.sh in DIR/pki), and a fourth namespace D (10.77.0.4), an
#   intruder's host, where build/bin/multihost_intruder tries to inject experience, episodes,
#   weights and thruster commands and to read the traffic, four times at once: without a
#   certificate (plain), with a certificate of another authority (other-ca), with the run's
#   certificate but a role whose permissions do not allow those topics (wrong-role), and with
#   the run's certificate and permissions it granted itself, signed by another authority
#   (self-granted). --check then also requires that nothing of theirs reached a probe, the
#   learner or the logger and that they received nothing, and that a learner given a tampered
#   permissions document is refused at start.
#
# Figures: the probes' lines (multihost_probe.cpp), the logger's channel counts (auv_log list)
# and a summary; everything stays in DIR (default runs/multihost-TIME) with the logs.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${AUVRL_BIN_DIR:-$root/build/bin}
self=$(readlink -f "$0")
# shellcheck source=scripts/lib/namespace_pid1.sh
. "$root/scripts/lib/namespace_pid1.sh"
usage() { sed -n '2,33p' "$self" | sed 's/^# \{0,1\}//'; exit 2; }

transport=dds links=no-multicast ttl=0 loss=0 seconds=20 hidden=32-32 out="" check=0 ci=0
security=0
inside=0
while [ $# -gt 0 ]; do
  case "$1" in
    --transport) transport=$2; shift 2 ;;
    --links) links=$2; shift 2 ;;
    --lcm-ttl) ttl=$2; shift 2 ;;
    --loss) loss=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --hidden) hidden=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --check) check=1; shift ;;
    --security) security=1; shift ;;
    --ci) ci=1; shift ;;
    --inside) inside=1; shift ;;
    -h|--help) usage ;;
    *) echo "multihost: unknown argument '$1'" >&2; usage ;;
  esac
done
case "$transport" in dds|lcm) ;; *) usage ;; esac
case "$links" in no-multicast|multicast) ;; *) usage ;; esac
[ "$security" = 0 ] || [ "$transport" = dds ] || { echo "multihost: --security needs DDS" >&2; usage; }
for b in auv_sim auv_actor auv_learner auv_logger auv_log multihost_probe multihost_intruder; do
  [ -x "$bin/$b" ] || { echo "multihost: $bin/$b is missing (build it first)" >&2; exit 1; }
done

# --- The CI form: two runs, each in namespaces of its own. ---------------------------------
if [ "$ci" = 1 ]; then
  base=${out:-$(mktemp -d /tmp/auvrl_multihost_XXXXXX)}
  status=0
  "$self" --transport dds --loss 5 --seconds 20 --check --out "$base/dds" || status=$?
  [ "$status" = 0 ] || exit "$status"
  "$self" --transport dds --security --seconds 15 --check --out "$base/dds-security" || status=$?
  [ "$status" = 0 ] || exit "$status"
  "$self" --transport lcm --seconds 8 --check --out "$base/lcm" || status=$?
  [ "$status" = 0 ] && rm -rf "$base"
  exit "$status"
fi

# The PKIs of --security (no network needed): the run's (DIR/pki: the system, the probes and
# two intruders' certificates), another authority's (DIR/pki-other), and the self-granted
# intruder's permissions (every topic), signed by that other authority.
make_pki() {
  local dir=$1 p subject
  rm -rf "$dir/pki" "$dir/pki-other"
  "$root/scripts/pki.sh" --out "$dir/pki" --actors 2 --controllers 0 --days 2 \
    --participant observer:probe-A --participant observer:probe-B \
    --participant observer:probe-C --participant simulator:intruder-wrong-role \
    --participant operator:intruder-self-granted >/dev/null
  "$root/scripts/pki.sh" --out "$dir/pki-other" --actors 1 --controllers 0 --days 2 >/dev/null
  p="$dir/pki/intruder-self-granted"
  subject=$(openssl x509 -in "$p/cert.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')
  cat >"$p/permissions.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds><permissions><grant name="self"><subject_name>$subject</subject_name>
<validity><not_before>$(date -u -d '-1 hour' +%Y-%m-%dT%H:%M:%S)</not_before><not_after>$(date -u -d '+1 day' +%Y-%m-%dT%H:%M:%S)</not_after></validity>
<allow_rule><domains><id_range><min>0</min><max>230</max></id_range></domains>
<publish><topics><topic>*</topic></topics></publish><subscribe><topics><topic>*</topic></topics></subscribe>
</allow_rule><default>DENY</default></grant></permissions></dds>
EOF
  openssl smime -sign -in "$p/permissions.xml" -text -out "$p/permissions.p7s" \
    -signer "$dir/pki-other/ca/ca.pem" -inkey "$dir/pki-other/ca/ca.key"
  cp "$dir/pki-other/ca/ca.pem" "$p/permissions_ca.pem"
  cp "$dir/pki-other/governance.p7s" "$p/governance.p7s"
}

# --- Outside: a private network, PID and mount namespace for everything below. -------------
if [ "$inside" = 0 ]; then
  out=${out:-$root/runs/multihost-$(date +%Y%m%d-%H%M%S)}
  mkdir -p "$out"
  out=$(cd "$out" && pwd)
  flags=(-n -p -m --fork --mount-proc --kill-child=KILL)
  [ "$(id -u)" -eq 0 ] || flags=(-r "${flags[@]}")  # a user namespace maps us to root inside
  if ! unshare "${flags[@]}" true 2>/dev/null; then
    echo "multihost: cannot create namespaces here (needs root or user namespaces); skipped" >&2
    exit 77
  fi
  check_flag=()
  [ "$check" = 0 ] || check_flag=(--check)
  security_flag=()
  [ "$security" = 0 ] || { make_pki "$out"; security_flag=(--security); }
  # unshare ignores SIGTERM/SIGINT while it waits: unshare_supervised passes them to PID 1
  # inside, which stops what it started; when PID 1 ends, the kernel ends every process left
  # in its namespace (and --kill-child ends PID 1 if unshare itself is killed).
  unshare_supervised "" "${flags[@]}" -- "$self" --inside --transport "$transport" \
    --links "$links" --lcm-ttl "$ttl" --loss "$loss" --seconds "$seconds" --hidden "$hidden" \
    --out "$out" "${check_flag[@]}" "${security_flag[@]}"
fi

# --- Inside: PID 1 of the private namespaces, in the bridge's network namespace. -----------
# Refuse to go on unless unshare made us PID 1 of new namespaces (never on the host's network).
[ "$$" = 1 ] || { echo "multihost: not PID 1 of a private namespace; refused" >&2; exit 1; }

pids=()
# shellcheck disable=SC2317  # called by the trap
cleanup() {
  # Everything this script started, newest first; the kernel ends the rest when PID 1 exits.
  local i
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -TERM "${pids[$i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
trap 'exit 130' INT TERM

log() { echo "multihost: $*" >&2; }
names=(A B C)
[ "$security" = 0 ] || names+=(D)  # the intruders' host
declare -A holder addr
ip link set lo up
ip link add br0 type bridge mcast_snooping 0
ip link set br0 up
for i in "${!names[@]}"; do
  n=${names[$i]}
  addr[$n]=10.77.0.$((i + 1))
  # A process that holds namespace n open (the processes placed there join it with nsenter).
  unshare -n sleep infinity &
  holder[$n]=$!
  pids+=("$!")
  for _ in $(seq 1 100); do
    [ "$(readlink "/proc/${holder[$n]}/ns/net")" != "$(readlink /proc/self/ns/net)" ] && break
    sleep 0.01
  done
  ip link add "v$n" type veth peer name eth0 netns "${holder[$n]}"
  ip link set "v$n" master br0
  ip link set "v$n" up
  in_ns() { nsenter -t "${holder[$n]}" -n -- "$@"; }
  in_ns ip link set lo up
  in_ns ip link set lo multicast on
  in_ns ip addr add "${addr[$n]}/24" dev eth0
  in_ns ip link set eth0 up
  if [ "$links" = multicast ]; then
    in_ns ip link set eth0 multicast on
    in_ns ip route add 224.0.0.0/4 dev eth0
  else
    in_ns ip link set eth0 multicast off
    ip link set "v$n" multicast off
    in_ns ip route add 224.0.0.0/4 dev lo
  fi
done
add_loss() {  # each namespace drops $loss % of the UDP frames arriving over its link
  local n
  for n in A B C; do
    # Before defragmentation (priority -500): every frame is lost on its own, as on a wire.
    nsenter -t "${holder[$n]}" -n -- nft -f - <<EOF
table inet auvrl_loss {
  chain in {
    type filter hook prerouting priority -500; policy accept;
    iifname "eth0" ip saddr != ${addr[$n]} meta l4proto udp numgen random mod 100 < $loss drop
  }
}
EOF
  done
}
if [ "$loss" != 0 ]; then
  netem_error=$(nsenter -t "${holder[A]}" -n -- tc qdisc add dev eth0 root netem loss "$loss%" \
    2>&1 && nsenter -t "${holder[A]}" -n -- tc qdisc del dev eth0 root) || true
  log "loss ${loss}% by nftables in each namespace (tc netem: ${netem_error:-available})"
fi
log "links: $links; A ${addr[A]}, B ${addr[B]}, C ${addr[C]} on br0"
nsenter -t "${holder[A]}" -n -- ip -br link show eth0 >"$out/links.txt"
nsenter -t "${holder[A]}" -n -- ip route show table all type multicast >>"$out/links.txt" || true
nsenter -t "${holder[A]}" -n -- ip route >>"$out/links.txt"

# Transport flags. Over DDS every namespace lists all three addresses (unicast discovery; its
# own reaches its local participants). --allow-off-host: the peers are not loopback addresses,
# which the processes refuse by default because the bus has no authentication; here that is
# correct, since these addresses exist only on the veth links of this script's private
# namespaces and no packet can reach a real network.
if [ "$transport" = dds ]; then
  common=(--transport dds --dds-peers "${addr[A]},${addr[B]},${addr[C]}")
  # Secured, the bus admits only the run's participants: off-host peers need no opt-out.
  [ "$security" = 1 ] || common+=(--allow-off-host)
  lockstep_a=(--lockstep-dds-domain 1)
  lockstep_c=(--lockstep-dds-domain 2)
else
  common=(--transport lcm --lcm-url "udpm://239.255.76.67:7667?ttl=$ttl&recv_buf_size=8388608")
  [ "$ttl" = 0 ] || common+=(--allow-off-host)  # same reason as for DDS above
  lockstep_a=(--lockstep-lcm-url "udpm://239.255.76.67:7668?ttl=0")
  lockstep_c=(--lockstep-lcm-url "udpm://239.255.76.67:7669?ttl=0")
fi

# identity NAME: the flags of participant NAME's identity (--security), in id_flags.
identity() {
  id_flags=()
  [ "$security" = 0 ] || id_flags=(--dds-security "$out/pki/$1")
}

declare -A pid_of
start() {  # start NAME NAMESPACE CMD...: runs CMD in NAMESPACE, output in $out/NAME.log
  local name=$1 ns=$2
  shift 2
  nsenter -t "${holder[$ns]}" -n -- "$@" >"$out/$name.log" 2>&1 &
  pid_of[$name]=$!
  pids+=("$!")
}
started() {  # started NAME REGEX: waits up to 20 s for NAME's log to match REGEX; exit 1 if not
  local name=$1 regex=$2
  for _ in $(seq 1 200); do
    grep -qE "$regex" "$out/$name.log" 2>/dev/null && return 0
    kill -0 "${pid_of[$name]}" 2>/dev/null || break
    sleep 0.1
  done
  echo "multihost: $name did not print /$regex/ within 20 s (it exited, or hangs); its log:" >&2
  sed 's/^/  /' "$out/$name.log" >&2
  exit 1
}
stop() {  # stop NAME...: SIGTERM, then wait up to 10 s (SIGKILL after)
  local name p
  for name in "$@"; do kill -TERM "${pid_of[$name]}" 2>/dev/null || true; done
  for name in "$@"; do
    p=${pid_of[$name]}
    for _ in $(seq 1 100); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2>/dev/null || true
    wait "$p" 2>/dev/null || true
  done
}

# Loss from the start, discovery included: DDS delivers reliably only to the readers a writer
# has discovered (volatile durability), so each actor waits for the learner's and the logger's
# readers before its first episode (--wait-for-readers).
if [ "$loss" != 0 ]; then
  add_loss
  log "loss on from the start"
fi
if [ "$security" = 1 ]; then
  # A tampered permissions document (the learner's, granting what it did not) is refused at
  # start, naming the file.
  cp -r "$out/pki/learner" "$out/tampered-learner"
  sed -i 's|<topic>auvrl_weights</topic>|<topic>auvrl_experience</topic><topic>auvrl_weights</topic>|' \
    "$out/tampered-learner/permissions.p7s"
  tampered_status=0
  nsenter -t "${holder[B]}" -n -- timeout 20 "$bin/auv_learner" "${common[@]}" \
    --dds-security "$out/tampered-learner" >"$out/tampered-learner.log" 2>&1 || tampered_status=$?
  log "learner with a tampered permissions document: exit $tampered_status: $(head -c 300 "$out/tampered-learner.log")"
fi
for n in A B C; do
  identity "probe-$n"
  start "probe$n" "$n" "$bin/multihost_probe" --label "$n" --out "$out/probe$n.txt" "${common[@]}" \
    "${id_flags[@]}"
done
identity learner
start learner B "$bin/auv_learner" "${common[@]}" "${id_flags[@]}" --algo td3 --hidden "$hidden" --batch-size 64 \
  --layout extended --replay-capacity 100000 --updates-per-transition 0.25 --warmup-transitions 500
identity logger
start logger C "$bin/auv_logger" "${common[@]}" "${id_flags[@]}" --dir "$out/logs" --heartbeat-period 0.5 \
  --channels 'EXPERIENCE|EPISODE|POLICY_.*|LEARNER_STATS|SIM_HEARTBEAT'
identity sim-0
start simA A "$bin/auv_sim" "${common[@]}" "${id_flags[@]}" "${lockstep_a[@]}" --vehicles 1 \
  --first-vehicle-id 0
identity sim-1
start simC C "$bin/auv_sim" "${common[@]}" "${id_flags[@]}" "${lockstep_c[@]}" --vehicles 1 \
  --first-vehicle-id 1
# The learner and the logger print their first line once subscribed. LCM has no discovery, so
# without this wait an actor's first episodes could go out before they listen.
started learner '^auv_learner: listening: '
started logger '^auv_logger: logging '
# An actor's first episode waits until the learner and the logger read its experience (over DDS,
# where a writer delivers only to the readers it has discovered).
# shellcheck disable=SC2054  # learner,logger is one value, a list of roles
actor_args=(--layout extended --reward shaped --max-steps 100 --noise gaussian
  --wait-for-readers learner,logger)
identity actor-0
start actorA A "$bin/auv_actor" "${common[@]}" "${id_flags[@]}" "${lockstep_a[@]}" --actor-id 0 \
  --seed 10 "${actor_args[@]}"
identity actor-1
start actorC C "$bin/auv_actor" "${common[@]}" "${id_flags[@]}" "${lockstep_c[@]}" --actor-id 1 \
  --seed 11 "${actor_args[@]}"
intruders=()
if [ "$security" = 1 ]; then
  # The intruders on their own host D, knowing every address; the system does not list D.
  intruder_peers=(--transport dds --dds-peers "${addr[A]},${addr[B]},${addr[C]},${addr[D]}")
  declare -A intruder_flags=(
    [plain]="--allow-off-host"
    [other-ca]="--dds-security $out/pki-other/actor-0"
    [wrong-role]="--dds-security $out/pki/intruder-wrong-role"
    [self-granted]="--dds-security $out/pki/intruder-self-granted")
  for n in plain other-ca wrong-role self-granted; do
    # shellcheck disable=SC2206  # the flags above split on spaces (paths have none)
    flags=(${intruder_flags[$n]})
    start "intruder-$n" D "$bin/multihost_intruder" --label "$n" --out "$out/intruder-$n.txt" \
      "${intruder_peers[@]}" "${flags[@]}"
    intruders+=("intruder-$n")
  done
fi
log "$transport: training for ${seconds} s (logs in $out)"
sleep "$seconds" &
wait $!  # (a signal's trap runs at once)
# Actors first (over DDS an exiting process waits until its experience is acknowledged), then
# time for the learner's next figures (once a second) to arrive; then the learner (over DDS it
# waits until its newest weights are acknowledged), and the probes write what they counted.
stop actorA actorC
sleep 3
stop learner
sleep 1
stop probeA probeB probeC "${intruders[@]}"
stop simA simC logger
"$bin/auv_log" list "$out/logs" >"$out/logger_channels.txt" 2>&1 || true
for n in "${names[@]}"; do  # what went over each link (the namespace's end of it)
  echo "namespace $n:"
  nsenter -t "${holder[$n]}" -n -- ip -s link show eth0
  nsenter -t "${holder[$n]}" -n -- nft list ruleset 2>/dev/null || true
  nsenter -t "${holder[$n]}" -n -- grep '^Ip:' /proc/net/snmp
done >>"$out/links.txt"
# IP reassembly in B (the learner's namespace): datagrams larger than a frame arrive as
# fragments, and one lost fragment loses the datagram.
# shellcheck disable=SC2016  # awk program
reasm=$(nsenter -t "${holder[B]}" -n -- awk '/^Ip:/ { if (!h) { for (i = 1; i <= NF; i++) k[i] = $i; h = 1 }
  else for (i = 1; i <= NF; i++) if (k[i] ~ /^Reasm/) printf "%s=%s ", k[i], $i }' /proc/net/snmp)

# --- Figures. --------------------------------------------------------------------------------
cat "$out"/probe{A,B,C}.txt
for n in "${intruders[@]}"; do cat "$out/$n.txt" 2>/dev/null || echo "intruder=$n: no figures"; done
echo "logger (namespace C), auv_log list:"
sed 's/^/  /' "$out/logger_channels.txt"
field() {  # field FILE LINE_PATTERN KEY: the KEY=value on the first line matching the pattern
  local v
  v=$(grep -E "$2" "$1" 2>/dev/null | head -1 | tr ' ' '\n' | sed -n "s/^$3=//p")
  echo "${v:-0}"
}
# What each actor sent and how many episodes it ran, in its own words (its last log line; a
# probe may join after an actor's first episode).
actor_figure() {  # actor_figure LOG WORD: the number before WORD on the "stopped after" line
  local v
  v=$(grep "stopped after" "$1" 2>/dev/null | tail -1 | grep -oE "[0-9]+ $2" | grep -oE '^[0-9]+')
  echo "${v:-0}"
}
sent_a=$(actor_figure "$out/actorA.log" "transitions sent")
sent_c=$(actor_figure "$out/actorC.log" "transitions sent")
received=$(field "$out/probeB.txt" "learner " transitions_received)
lost=$(field "$out/probeB.txt" "learner " batches_lost)
updates=$(field "$out/probeB.txt" "learner " updates)
learner_episodes=$(field "$out/probeB.txt" "learner " episodes)
published=$(field "$out/probeB.txt" "learner " weights_published)
newest=$(field "$out/probeB.txt" "weights " newest)  # B: beside the learner, nothing lost
episodes_a=$(actor_figure "$out/actorA.log" "episodes")
episodes_c=$(actor_figure "$out/actorC.log" "episodes")
policy_a=$(field "$out/probeB.txt" "episodes actor=0 " policy_last)
policy_c=$(field "$out/probeB.txt" "episodes actor=1 " policy_last)
weights_a=$(field "$out/probeA.txt" "weights " versions)
weights_c=$(field "$out/probeC.txt" "weights " versions)
newest_a=$(field "$out/probeA.txt" "weights " newest)
newest_c=$(field "$out/probeC.txt" "weights " newest)
bytes=$(field "$out/probeB.txt" "weights " bytes)
logged_episodes=$(awk '$1 == "EPISODE" {print $2}' "$out/logger_channels.txt" | head -1)
logged_episodes=${logged_episodes:-0}
logged_stats=$(awk '$1 == "LEARNER_STATS" {print $2}' "$out/logger_channels.txt" | head -1)
logged_stats=${logged_stats:-0}
pct() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.1f", 100 * a / b; else print "-" }'; }
cat <<EOF
summary transport=$transport links=$links lcm_ttl=$ttl loss=${loss}% seconds=$seconds hidden=$hidden weights_bytes=$bytes
  experience: sent A=$sent_a C=$sent_c, learner received $received ($(pct "$received" $((sent_a + sent_c)))%), batches lost (seq gaps) $lost
  episodes: A=$episodes_a C=$episodes_c, learner counted $learner_episodes, logger (C) logged $logged_episodes (and $logged_stats LEARNER_STATS)
  updates $updates, weights published $published (newest version $newest)
  weights versions received: A $weights_a ($(pct "$weights_a" "$published")%) newest $newest_a, C $weights_c ($(pct "$weights_c" "$published")%) newest $newest_c
  policy version of the last episode seen by the learner: actor 0 (A) $policy_a, actor 1 (C) $policy_c
  IP reassembly in B: $reasm
EOF

[ "$check" = 1 ] || exit 0
fail=0
expect() {  # expect DESCRIPTION TEST...
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; fail=1; fi
}
if [ "$transport" = dds ]; then
  expect "both actors sent experience" test "$sent_a" -gt 0 -a "$sent_c" -gt 0
  expect "every transition sent reached the learner" test "$received" -eq $((sent_a + sent_c))
  expect "no experience batch lost" test "$lost" -eq 0
  expect "every episode reached the learner" test "$learner_episodes" -eq $((episodes_a + episodes_c))
  expect "the learner updated and published weights" test "$updates" -gt 0 -a "$published" -gt 0
  expect "the newest weights reached A and C" test "$newest_a" -eq "$newest" -a "$newest_c" -eq "$newest"
  expect "both actors acted with the learner's weights" test "$policy_a" -gt 0 -a "$policy_c" -gt 0
  expect "the logger logged every episode" test "$logged_episodes" -eq $((episodes_a + episodes_c))
  if [ "$security" = 1 ]; then
    expect "a tampered permissions document is refused at start, naming it" \
      grep -q "tampered-learner/permissions.p7s does not verify" "$out/tampered-learner.log"
    for n in A B C; do
      expect "no intruder experience or episode reached $n" \
        test "$(grep -c "actor=99 " "$out/probe$n.txt")" -eq 0
      expect "no thruster command reached $n" \
        test "$(field "$out/probe$n.txt" "commands " received)" -eq 0
      expect "the newest weights at $n are the learner's" \
        test "$(field "$out/probe$n.txt" "weights " newest)" -eq "$newest"
    done
    for n in "${intruders[@]}"; do
      expect "$n ran" test "$(field "$out/$n.txt" "intruder=" attempts)" -gt 0
      expect "$n received nothing" test "$(field "$out/$n.txt" "intruder=" received)" -eq 0
    done
  fi
elif [ "$links" = no-multicast ]; then
  expect "the actors ran" test "$sent_a" -gt 0 -a "$sent_c" -gt 0
  expect "no experience crossed to the learner" test "$received" -eq 0
  expect "no weights crossed to A or C" test "$weights_a" -eq 0 -a "$weights_c" -eq 0
  expect "the logger (C) logged only C's episodes" test "$logged_episodes" -eq "$episodes_c"
  expect "the logger (C) logged no learner figures" test "$logged_stats" -eq 0
else
  expect "experience crossed to the learner" test "$received" -gt 0
  expect "weights crossed to A and C" test "$weights_a" -gt 0 -a "$weights_c" -gt 0
fi
exit "$fail"
