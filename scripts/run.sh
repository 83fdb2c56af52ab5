#!/usr/bin/env bash
# The README's main command: installs what is missing, builds (Release), and runs the main job:
# `auvrl train` with the fast preset (the whole system in a private network namespace: one
# simulator and actor per CPU pair, the learner, the logger), then the evaluation of the
# learned policy and the PID baseline on test1, test2, fault, current and the suite, the
# plots and the report, all in runs/fast-<time>/.
#   scripts/run.sh [auvrl train options...]   e.g. --preset paper, --max-seconds 300, --seed 2
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
exec "${AUVRL_BUILD_DIR:-$root/build}/bin/auvrl" train "$@"
