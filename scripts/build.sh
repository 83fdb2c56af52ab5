#!/usr/bin/env bash
# Configures and builds auvrl (Release by default) into build/; executables land in build/bin/.
#   scripts/build.sh [extra cmake -D options...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${AUVRL_BUILD_DIR:-$root/build}
jobs=${AUVRL_JOBS:-$(nproc)}
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE="${AUVRL_BUILD_TYPE:-Release}" "$@" >/dev/null
cmake --build "$build_dir" -j "$jobs"
