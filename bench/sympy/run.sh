#!/usr/bin/env bash
# weilgen generate against SymPy doing the same truncated products (issue 17 §4):
#
#   bench/sympy/run.sh [path/to/weilgen] [machine.yaml] [--order K] [--repeats R]
#
# Defaults: build/weilgen, machines/five_axis_ac.yaml, order 2 (SymPy takes minutes there).
# bench/sympy/bench_vs_sympy.py says what SymPy computes and how it is checked against weilgen's
# model (the Python module beside weilgen, <build>/python). Installs python3-sympy and
# python3-yaml through scripts/install_deps.sh --bench when they are missing (needs root).
# Prints a Markdown table to stdout, the check and the term count to stderr.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if ! /usr/bin/python3 -c "import sympy, yaml" 2>/dev/null; then
  echo "bench/sympy: installing python3-sympy (scripts/install_deps.sh --bench)" >&2
  bash "$root/scripts/install_deps.sh" --bench
fi
weilgen="${1:-$root/build/weilgen}"
if [[ $# -gt 0 && "$1" != --* ]]; then shift; fi
machine="${1:-$root/machines/five_axis_ac.yaml}"
if [[ $# -gt 0 && "$1" != --* ]]; then shift; fi
if [[ ! -x "$weilgen" ]]; then
  echo "bench/sympy: no weilgen at $weilgen (build it: cmake --build build --target weilgen)" >&2
  exit 2
fi
if [[ " $* " != *" --order "* ]]; then set -- --order 2 "$@"; fi
exec /usr/bin/python3 "$here/bench_vs_sympy.py" "$weilgen" "$machine" "$@"
