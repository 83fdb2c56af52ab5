#!/usr/bin/env bash
# The README's main command: installs what is missing, builds (Release), and runs the main job.
# For now the main job is the simulator demo: Nessie VII flown open loop through a manoeuvre
# (full surge, a turn, a dive, a sideways push, drift), written to runs/demo-<time>/ as CSV and
# a plot, then a lockstep session served by auv_sim in a private network namespace.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"

bin="${AUVRL_BUILD_DIR:-$root/build}/bin"
run_dir="$root/runs/demo-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$run_dir"
"$bin/auv_sim" --vehicle "$root/config/vehicles/nessie7.yaml" \
  --open-loop "$root/config/demo/open_loop_manoeuvre.csv" --out "$run_dir/open_loop.csv"
/usr/bin/python3 "$root/scripts/plot_open_loop.py" "$run_dir/open_loop.csv" "$run_dir/open_loop.png"
/usr/bin/python3 - "$run_dir/open_loop.csv" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
speed = max(math.hypot(float(r["u"]), float(r["v"])) for r in rows if float(r["t"]) <= 20)
last = rows[-1]
print(f"open loop: {len(rows)} steps; surge speed after 20 s of full thrust {speed:.3f} m/s; "
      f"final position x={float(last['x']):.2f} y={float(last['y']):.2f} z={float(last['z']):.2f} m")
PY
echo "lockstep over LCM (private network namespace):"
"$root/scripts/netns.sh" "$bin/bench_lockstep" --steps 5000
echo "written: $run_dir/open_loop.csv, $run_dir/open_loop.png"
