#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) in build-fuzz/ and runs each for SECONDS
# (default 20) on its committed seed corpus fuzz/corpus/<target>/, one after the other. Fails
# on the first crash, leak, UB, hang or out-of-memory; the input is kept in
# build-fuzz/fuzz/work/<target>/artifacts/ (replay it: build-fuzz/bin/<target> FILE).
#   scripts/fuzz.sh [SECONDS] [TARGET...]     e.g. scripts/fuzz.sh 600 fuzz_sim_server
# AUVRL_JOBS sets the build's parallelism (default: all cores).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${AUVRL_FUZZ_BUILD_DIR:-$root/build-fuzz}
seconds=20
if [ $# -gt 0 ] && [[ $1 =~ ^[0-9]+$ ]]; then seconds=$1; shift; fi
command -v clang++ >/dev/null || { echo "fuzz: clang++ is missing (scripts/install-deps.sh)" >&2; exit 1; }

CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" -DAUVRL_FUZZ=ON -DAUVRL_BUILD_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=Fuzz >/dev/null
cmake --build "$build_dir" -j "${AUVRL_JOBS:-$(nproc)}" --target fuzz_all

wanted=("$@")
status=0
while read -r name max_len dict; do
  if [ ${#wanted[@]} -gt 0 ] && [[ ! " ${wanted[*]} " =~ " $name " ]]; then continue; fi
  echo "fuzz: $name for ${seconds}s"
  log="$build_dir/fuzz/work/$name.log"
  mkdir -p "$(dirname "$log")"
  if AUVRL_FUZZ_SECONDS=$seconds "$root/fuzz/run_target.sh" "$build_dir/bin/$name" \
      "$root/fuzz/corpus/$name" "$build_dir/fuzz/work/$name" "$max_len" "$dict" >"$log" 2>&1; then
    # libFuzzer's closing figures: executions, rate, corpus.
    grep -E '^(stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb)' "$log" |
      tr '\n' ' '
    echo
  else
    echo "fuzz: $name FAILED (log: $log)" >&2
    grep -E 'ERROR|SUMMARY|Test unit written|runtime error' "$log" | head -20 >&2 || true
    status=1
    break
  fi
done <"$build_dir/fuzz/targets.txt"
exit $status
