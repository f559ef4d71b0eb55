#!/usr/bin/env bash
# Set-up command (1): install what is missing, build, generate the shipped default machine's
# model (the gantry grinder of the reliability seed) and print its closed-form volumetric error.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh -DWEILGEN_BUILD_BENCH=OFF
build/weilgen generate gantry_grinder --out generated
echo
echo "Closed-form volumetric error of gantry_grinder (dx dy dz in mm, da db dc in rad):"
build/weilgen show gantry_grinder
