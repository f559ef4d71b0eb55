#!/usr/bin/env bash
# Builds and installs weilgen into a temporary prefix, then builds and runs
# examples/controller_model against that prefix, as a user's controller project would.
#   scripts/build_example.sh [BUILD_DIR]   (default: build; reused if it exists)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath -m "${1:-build}")  # relative to the caller's directory, like scripts/test.sh
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

# Only the CLI is needed for the install.
cmake -S "$root" -B "$build" >/dev/null
cmake --build "$build" --target weilgen -j"$(nproc)"
cmake --install "$build" --prefix "$prefix"

# A fresh build directory outside the source tree: nothing may leak in from the weilgen build.
cmake -S "$root/examples/controller_model" -B "$work/example" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release
cmake --build "$work/example" -j"$(nproc)"
"$work/example/controller"
"$work/example/controller_c"
