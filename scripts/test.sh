#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, and runs every test (CTest).
# Multi-process tests put themselves into private network namespaces (scripts/netns.sh).
#   scripts/test.sh [ctest options...]   e.g. -R Sim, -L unit
# Without options (CI) it then runs every fuzz target briefly (scripts/fuzz.sh, clang build in
# build-fuzz/): AUVRL_FUZZ_SECONDS per target (default 5; 0 skips).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "${AUVRL_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "${AUVRL_TEST_JOBS:-2}" --timeout 900 "$@"
fuzz_seconds=${AUVRL_FUZZ_SECONDS:-5}
if [ $# -eq 0 ] && [ "$fuzz_seconds" != 0 ]; then
  "$root/scripts/fuzz.sh" "$fuzz_seconds"
fi
