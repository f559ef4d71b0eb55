#!/usr/bin/env bash
# Builds and runs the libFuzzer harnesses of fuzz/ (fuzz/README.md) in ${FUZZ_BUILD_DIR:-build-fuzz}.
#   bash scripts/fuzz.sh smoke            every harness for FUZZ_SECONDS (default 5) on its seeds
#   bash scripts/fuzz.sh run TARGET [N]   one harness for N executions (default 1000000), niced;
#                                         TARGET: machine_yaml measurement_csv tolerance_file
#                                         expression
# A crash, a sanitizer report or a broken oracle stops the harness: libFuzzer writes the input to
# <build>/fuzz-artifacts/TARGET-crash-* (oom-*, timeout-*); add it to fuzz/regressions/TARGET/.
# Nothing is written into the source tree (the corpus grows in <build>/fuzz-corpus/TARGET).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$PWD
dir=$(realpath -m "${FUZZ_BUILD_DIR:-build-fuzz}")
mode=${1:-smoke}
if ! command -v clang++ >/dev/null 2>&1; then
  echo "fuzz: clang++ not found (scripts/install_deps.sh installs clang and libFuzzer)" >&2
  exit 1
fi
launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DWEILGEN_FUZZ=ON -DWEILGEN_WERROR=OFF -DWEILGEN_BUILD_TESTS=OFF -DWEILGEN_BUILD_BENCH=OFF \
  "${launcher[@]}" >/dev/null
cmake --build "$dir" -j"${JOBS:-$(nproc)}" --target fuzz_harnesses
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"

seeds() {  # the seed corpus directories of a harness
  case $1 in
    machine_yaml) echo "$src/machines" ;;
    measurement_csv) echo "$src/examples/data" ;;
    tolerance_file) echo "$src/machines/tolerances" ;;
    expression) echo "$src/fuzz/corpus/expression" ;;
  esac
}
dict() { [ -f "$src/fuzz/$1.dict" ] && echo "-dict=$src/fuzz/$1.dict" || true; }
mkdir -p "$dir/fuzz-artifacts"
targets=(machine_yaml measurement_csv tolerance_file expression)

case $mode in
  smoke)
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    for t in "${targets[@]}"; do
      mkdir -p "$work/$t"
      echo "fuzz smoke: $t (${FUZZ_SECONDS:-5} s)"
      status=0
      (cd "$work" && "$dir/fuzz/fuzz_$t" $(dict "$t") -max_total_time="${FUZZ_SECONDS:-5}" \
        -max_len=8192 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="$dir/fuzz-artifacts/$t-" "$work/$t" \
        $(seeds "$t")) >"$work/$t.log" 2>&1 || status=$?
      grep -E "stat::number_of_executed_units" "$work/$t.log" || true
      if [ "$status" != 0 ]; then
        tail -40 "$work/$t.log" >&2
        echo "fuzz smoke: $t failed (exit $status)" >&2
        exit 1
      fi
    done
    ;;
  run)
    t=${2:?target}
    runs=${3:-1000000}
    mkdir -p "$dir/fuzz-corpus/$t"
    # A long run's resident size creeps up (ASan's quarantine, the allocator's caches; LeakSanitizer
    # finds no leak), so the process limit is FUZZ_RSS_MB (default 4096) while one input still may
    # not allocate more than 2 GB.
    nice -n 10 "$dir/fuzz/fuzz_$t" $(dict "$t") -runs="$runs" -max_len=8192 -timeout=10 \
      -rss_limit_mb="${FUZZ_RSS_MB:-4096}" -malloc_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$dir/fuzz-artifacts/$t-" "$dir/fuzz-corpus/$t" $(seeds "$t")
    ;;
  *)
    echo "usage: scripts/fuzz.sh smoke | run TARGET [EXECUTIONS]" >&2
    exit 2
    ;;
esac
