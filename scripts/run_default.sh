#!/usr/bin/env bash
# Set-up command (1): install what the CLI needs, build the `weilgen` executable only, generate
# the shipped default machine's model (the gantry grinder of the reliability seed) and print its
# closed-form volumetric error, Sobol' indices and reliability. The test command
# (scripts/test.sh) installs and builds everything else.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh --cli
bash scripts/build.sh --cli
build/weilgen generate gantry_grinder --out build/models
echo
echo "Closed-form volumetric error of gantry_grinder (dx dy dz in mm, da db dc in rad):"
build/weilgen show gantry_grinder
echo
echo "Sobol' sensitivity of dx at X=500, Y=750, Z=1000 (mm):"
build/weilgen sensitivity gantry_grinder --at X=500,Y=750,Z=1000 --outputs dx --top 8
echo
echo "Machining-accuracy reliability of dx over the seed's grid, tolerance 0.03 mm:"
build/weilgen reliability gantry_grinder --grid X=0,Y=-1500:1500:5,Z=600:1400:5 --tolerance dx=0.03mm
