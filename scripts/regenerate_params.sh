#!/bin/bash
# Rewrites generated/vmc_3axis_params.hpp: the parameters identified from the synthetic point
# measurements examples/data/vmc_3axis_points.csv (bench/experiments/make_points_data.cpp).
# The CTest generated_params_current fails when the committed file differs from what this writes
# (the build writes it into <build>/generated; `cmake --build build --target update_generated`
# rewrites every committed generated file).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
"$BUILD_DIR/weilgen" identify vmc_3axis --data examples/data/vmc_3axis_points.csv \
  --emit-params generated/vmc_3axis_params.hpp --quiet > /dev/null
echo "wrote generated/vmc_3axis_params.hpp"
