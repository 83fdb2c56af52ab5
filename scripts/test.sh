#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, and runs every test (CTest).
# Multi-process tests put themselves into private network namespaces (scripts/netns.sh).
#   scripts/test.sh [ctest options...]   e.g. -R Sim, -L unit
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "${AUVRL_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "${AUVRL_TEST_JOBS:-2}" --timeout 900 "$@"
