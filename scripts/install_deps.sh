#!/usr/bin/env bash
# Installs weilgen's build and test dependencies from Debian 12 packages (run as root).
# Does nothing when everything is already installed. `--bench` adds the benchmarks' peer tools.
set -euo pipefail
packages=(
  build-essential cmake pkg-config git
  libginac-dev libeigen3-dev libboost-program-options-dev libboost-dev
  libyaml-cpp-dev nlohmann-json3-dev doctest-dev libbenchmark-dev
  libnlopt-cxx-dev time gnuplot-nox
  # LinuxCNC (halrun, halcompile, hal.h): the HAL compensation component's test (docs/controllers.md)
  linuxcnc-uspace linuxcnc-uspace-dev
  clang libclang-rt-14-dev  # libFuzzer and the sanitizer runtimes (fuzz/, scripts/fuzz.sh)
  # headless chromium and PIL: the ISO 230-2 HTML report's browser test (tests/browser)
  chromium fonts-dejavu-core python3-pil
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
)
# --bench: also the peer tools the benchmarks compare against (bench/openturns/run.sh,
# bench/sympy/run.sh).
if [[ "${1:-}" == "--bench" ]]; then packages+=(python3-openturns python3-scipy); fi
if [[ "${1:-}" == "--bench" ]]; then packages+=(python3-sympy python3-yaml); fi
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
