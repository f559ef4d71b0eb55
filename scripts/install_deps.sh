#!/usr/bin/env bash
# Installs weilgen's dependencies from Debian 12 packages (run as root); does nothing when
# everything is already installed.
#   install_deps.sh          what the test command needs (scripts/test.sh): everything below
#   install_deps.sh --cli    only what building and running the `weilgen` CLI needs
#                            (scripts/run_default.sh)
#   install_deps.sh --bench  everything, plus the peer tools the benchmarks compare against
set -euo pipefail
mode=${1:-}
case "$mode" in "" | --cli | --bench) ;; *)
  echo "usage: install_deps.sh [--cli|--bench]" >&2
  exit 2
  ;;
esac
# The CLI: compiler, CMake and Ninja, GiNaC (generator), Eigen, Boost.Program_options and
# Boost.Math, yaml-cpp (machine files), nlohmann-json (documents), NLopt (tolerance allocation).
packages=(
  build-essential cmake ninja-build pkg-config
  libginac-dev libeigen3-dev libboost-program-options-dev libboost-dev
  libyaml-cpp-dev nlohmann-json3-dev libnlopt-cxx-dev
)
if [[ "$mode" != "--cli" ]]; then
  packages+=(
    git doctest-dev libbenchmark-dev time gnuplot-nox
    # LinuxCNC (halrun, halcompile, hal.h): the HAL compensation component's tests (docs/controllers.md)
    linuxcnc-uspace linuxcnc-uspace-dev
    clang libclang-rt-14-dev  # libFuzzer and the sanitizer runtimes (fuzz/, scripts/fuzz.sh)
    # headless chromium and PIL: the HTML reports' browser tests (tests/browser)
    chromium fonts-dejavu-core python3-pil
    python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
    # the Python package: DataFrames (weilgen.to_frame), `pip install .` into a venv (tests/python)
    python3-pandas python3-pip python3-venv
  )
fi
# --bench: also the peer tools the benchmarks compare against (bench/openturns/run.sh,
# bench/sympy/run.sh).
if [[ "$mode" == "--bench" ]]; then packages+=(python3-openturns python3-scipy python3-sympy python3-yaml); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
