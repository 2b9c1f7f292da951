#!/usr/bin/env bash
# Builds the libFuzzer targets with clang and runs each for SECONDS (default 60) on a copy of
# the seed corpus (fuzz/corpus/, seeded with the fixtures and example scenes). Prints the
# executions of each run; a crash fails the script and leaves its input in build-fuzz/.
set -euo pipefail
seconds="${1:-60}"
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S fuzz -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang >/dev/null
cmake --build build-fuzz -j"$(nproc)"
for kind in obj json; do
  work="build-fuzz/corpus-$kind"
  mkdir -p "$work"
  cp -n fuzz/corpus/$kind/* "$work"/ 2>/dev/null || true
  echo "fuzz_$kind: ${seconds} s"
  (cd build-fuzz && ./fuzz_$kind -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 \
      "corpus-$kind" 2>&1 | grep -E "stat::number_of_executed_units|stat::peak_rss|ERROR|SUMMARY|Done")
done
