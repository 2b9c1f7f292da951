#!/usr/bin/env bash
# Installs what is missing, then configures and builds bounce in build/.
#   scripts/build.sh              everything (program, tests, benchmarks, examples)
#   scripts/build.sh TARGET...    only these targets (and what they need), e.g. `bounce`
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build -j"$(nproc)" "${targets[@]}"
