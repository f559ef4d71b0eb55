#!/usr/bin/env bash
# Configures and builds weilgen (Release) into ${BUILD_DIR:-build}.
#   build.sh [--cli] [cmake -D options...]
# --cli builds only the `weilgen` executable, without the tests, the Python module and the
# benchmarks (scripts/run_default.sh); without it, everything (scripts/test.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
read -ra generator <<<"$(bash scripts/cmake_generator.sh "$build_dir")"
if [[ "${1:-}" == "--cli" ]]; then
  shift
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DWEILGEN_BUILD_TESTS=OFF \
    -DWEILGEN_BUILD_PYTHON=OFF -DWEILGEN_BUILD_BENCH=OFF "$@" >/dev/null
  cmake --build "$build_dir" -j"$(nproc)" --target weilgen
else
  # Each layer as one unity batch: a file-private name used twice in a layer fails here, when it
  # is introduced, not later when another file shifts the CLI build's batches of 16.
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DWEILGEN_BUILD_TESTS=ON \
    -DWEILGEN_BUILD_PYTHON=ON -DWEILGEN_BUILD_BENCH=ON -DWEILGEN_UNITY_BATCH=0 "$@" >/dev/null
  cmake --build "$build_dir" -j"$(nproc)"
fi
