#!/usr/bin/env bash
# Starts lcm-spy on a running auvrl system with the project's types jar, so that every channel
# is decoded field by field (lcm-spy matches messages to classes by fingerprint).
#
#   scripts/spy.sh RUN_DIR          join the system whose namespace pid is in RUN_DIR/netns.pid
#                                   (what `scripts/netns.sh --pidfile RUN_DIR/netns.pid ...` writes)
#   scripts/spy.sh --join PID       join the network namespace of process PID
#   scripts/spy.sh --network host   watch the host's network instead (explicit opt-out)
# options:
#   --jar JARS        types jar(s), ':'-separated (default build/share/java/auvrl_lcmtypes.jar)
#   --lcm-url URL     (default udpm://239.255.76.67:7667?ttl=0, the project's group)
#
# Debian 12's lcm-spy wrapper passes -Xincgc, which Java 17 rejects, and needs jchart2d.jar
# without depending on its package: this script runs lcm.spy.Spy directly and installs
# liblcm-java, libjchart2d-java and default-jre (apt-get) if they are missing. lcm-spy needs an
# X display (DISPLAY); on a headless machine run it under Xvfb (xvfb-run or Xvfb :99 &).
set -euo pipefail

usage() { sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }

root=$(cd "$(dirname "$0")/.." && pwd)
jar="$root/build/share/java/auvrl_lcmtypes.jar"
url="udpm://239.255.76.67:7667?ttl=0"
mode=""
pid=""
while [ $# -gt 0 ]; do
  case "$1" in
    --jar) [ $# -ge 2 ] || usage; jar=$2; shift 2 ;;
    --lcm-url) [ $# -ge 2 ] || usage; url=$2; shift 2 ;;
    --join) [ $# -ge 2 ] || usage; mode="join"; pid=$2; shift 2 ;;
    --network)
      if [ $# -lt 2 ] || [ "$2" != host ]; then usage; fi
      mode="host"; shift 2 ;;
    -h|--help) usage ;;
    -*) echo "spy.sh: unknown option $1" >&2; usage ;;
    *)
      [ -z "$mode" ] || usage
      pidfile="$1/netns.pid"
      if [ ! -r "$pidfile" ]; then
        echo "spy.sh: no $pidfile: start the system with scripts/netns.sh --pidfile $pidfile ..." >&2
        exit 1
      fi
      mode="join"; pid=$(cat "$pidfile"); shift ;;
  esac
done
[ -n "$mode" ] || { echo "spy.sh: say which system to watch (RUN_DIR, --join PID or --network host)" >&2; usage; }
if [ "$mode" = join ] && ! kill -0 "$pid" 2>/dev/null; then
  echo "spy.sh: process $pid is not running: is the system still up?" >&2
  exit 1
fi

# What lcm-spy needs: lcm.jar, jchart2d.jar, a Java runtime with AWT (not only headless).
missing=()
[ -r /usr/share/java/lcm.jar ] || missing+=(liblcm-java)
[ -r /usr/share/java/jchart2d.jar ] || missing+=(libjchart2d-java)
java_bin=$(command -v java || true)
if [ -z "$java_bin" ] || ! ls "$(dirname "$(dirname "$(readlink -f "$java_bin")")")"/lib/libawt_xawt.so >/dev/null 2>&1; then
  missing+=(default-jre)
fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "spy.sh: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get install -y "${missing[@]}" || { $sudo apt-get update && $sudo apt-get install -y "${missing[@]}"; }
fi

for j in ${jar//:/ }; do
  if [ ! -r "$j" ]; then
    echo "spy.sh: no types jar $j: build it with 'cmake --build build --target auvrl_lcmtypes_jar'" >&2
    exit 1
  fi
done
if [ -z "${DISPLAY:-}" ]; then
  echo "spy.sh: no X display (DISPLAY is unset): run it on a desktop, or under Xvfb" >&2
  exit 1
fi

spy=(java -Djava.net.preferIPv4Stack=true -Xmx512m -ea
     -cp "$jar:/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar" lcm.spy.Spy --lcm-url="$url")
if [ "$mode" = join ]; then
  exec "$root/scripts/netns.sh" --join "$pid" "${spy[@]}"
fi
exec "$root/scripts/netns.sh" --network host "${spy[@]}"
