#!/usr/bin/env bash
# Runs one fuzz target for AUVRL_FUZZ_SECONDS (default 5) seconds on its seed corpus; exits
# non-zero on a crash, a leak, UB, a timeout (one input > 10 s) or running out of memory, with
# the input saved under WORK_DIR/artifacts/. New inputs go to WORK_DIR/corpus (not the
# committed seeds). CTest (label fuzz) and scripts/fuzz.sh call it.
#   run_target.sh BINARY SEED_DIR WORK_DIR MAX_LEN DICT|-
set -euo pipefail
[ $# -eq 5 ] || { echo "usage: $0 BINARY SEED_DIR WORK_DIR MAX_LEN DICT|-" >&2; exit 2; }
binary=$1 seeds=$2 work=$3 max_len=$4 dict=$5
seconds=${AUVRL_FUZZ_SECONDS:-5}
mkdir -p "$work/corpus" "$work/artifacts"
args=(-max_total_time="$seconds" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048
      -print_final_stats=1 -artifact_prefix="$work/artifacts/")
[ "$dict" != "-" ] && args+=(-dict="$dict")
# One thread for Eigen (OpenMP): the machine is shared.
export OMP_NUM_THREADS=1
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
exec "$binary" "${args[@]}" "$work/corpus" "$seeds"
