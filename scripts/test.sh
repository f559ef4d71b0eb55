#!/usr/bin/env bash
# Set-up command (2): install what is missing, build everything and run the whole test suite:
# the doctest suite (through CTest), the golden check of the committed generated/ files, and
# the example controller project built against an installed weilgen; then, with clang, a few
# seconds of fuzzing per input reader (scripts/fuzz.sh smoke).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
export BUILD_DIR=${BUILD_DIR:-build}
# The build writes nothing into the source tree; the CTest generated_files_current compares the
# committed generated/ with fresh generation.
bash scripts/build.sh
if [ -x scripts/build_example.sh ]; then
  bash scripts/build_example.sh "$BUILD_DIR"
fi
(cd "$BUILD_DIR" && ctest --output-on-failure -j"$(nproc)")
# A few seconds of fuzzing per input reader (fuzz/README.md), when clang's libFuzzer is present.
if command -v clang++ >/dev/null 2>&1; then
  bash scripts/fuzz.sh smoke
fi
