#!/usr/bin/env bash
# Builds weilgen with AddressSanitizer and UndefinedBehaviorSanitizer into its own build directory
# (${SANITIZE_BUILD_DIR:-build-sanitize}) and runs the whole test suite under them
# (docs/robustness.md). Any sanitizer report fails the run: ASan exits 86, UBSan 87 (the tests
# expect 0, 1, 2 or 3), and leaks are reported except GiNaC's known 26-byte start-up allocation
# in libcln (scripts/lsan.supp). Slow (about 3x the normal build and suite): run it niced.
#   bash scripts/sanitize.sh [ctest arguments, e.g. -R robustness]
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${SANITIZE_BUILD_DIR:-build-sanitize}
jobs=${JOBS:-$(nproc)}
export ASAN_OPTIONS="detect_leaks=1:exitcode=86:strict_string_checks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=87"
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g"
launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# Warnings are not errors here: GCC 12's flow warnings at -O3 with ASan report false positives
# inside libstdc++ (-Wmaybe-uninitialized in std::regex and in a moved std::optional<vector>);
# the normal build, which CI runs, keeps -Werror.
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DWEILGEN_BUILD_BENCH=OFF -DWEILGEN_WERROR=OFF \
  "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$dir" -j"$jobs"
cd "$dir"
if [[ $# -gt 0 ]]; then
  ctest --output-on-failure -j"$jobs" "$@"
  echo "sanitize: the selected tests passed under ASan and UBSan ($dir)"
  exit 0
fi
# CPython is not built with the sanitizers: the Python tests load the sanitized module into it
# with the sanitizer runtimes preloaded (ASan must come first in the library list), and without
# leak detection (the interpreter keeps its objects at exit). Every other test runs as above.
python_tests='^python_'
rc=0
ctest --output-on-failure -j"$jobs" -E "$python_tests" || rc=1
runtimes="$(${CXX:-g++} -print-file-name=libasan.so) $(${CXX:-g++} -print-file-name=libubsan.so)"
LD_PRELOAD="$runtimes" ASAN_OPTIONS="${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}" \
  ctest --output-on-failure -j"$jobs" -R "$python_tests" || rc=1
[[ $rc -eq 0 ]] || exit 1
echo "sanitize: the whole suite passed under ASan and UBSan ($dir)"
