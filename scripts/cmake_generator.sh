#!/usr/bin/env bash
# Prints the CMake generator option for a new build directory: `-G Ninja` when Ninja is
# installed (install_deps.sh installs it), nothing otherwise or when BUILD_DIR is already
# configured (it keeps its generator). Ninja compiles a layer's files while the layers below
# are still compiling; Make waits for each library first (docs/performance.md, "Build time").
#   cmake_generator.sh BUILD_DIR
set -euo pipefail
if [[ ! -f "${1:?usage: cmake_generator.sh BUILD_DIR}/CMakeCache.txt" ]] && command -v ninja >/dev/null; then
  echo "-G Ninja"
fi
