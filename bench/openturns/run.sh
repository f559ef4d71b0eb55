#!/usr/bin/env bash
# weilgen against OpenTURNS (Debian's python3-openturns) at equal accuracy, in one run:
# Sobol' indices, FORM and importance sampling on the gantry grinder
# (bench/openturns/bench_vs_openturns.py says what is timed and how N is chosen).
#
#   bench/openturns/run.sh [path/to/weilgen] [--repeats R] [--threads T] [--only sobol|reliability]
#                            [--seeds S] [--ot-seeds S2]
#
# Installs python3-openturns and python3-scipy through scripts/install_deps.sh --bench when
# they are missing (needs root, like the set-up script). Prints a Markdown report to stdout.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if ! /usr/bin/python3 -c "import openturns, scipy" 2>/dev/null; then
  echo "bench/openturns: installing python3-openturns (scripts/install_deps.sh --bench)" >&2
  bash "$root/scripts/install_deps.sh" --bench
fi
weilgen="${1:-$root/build/weilgen}"
if [[ $# -gt 0 && "$1" != --* ]]; then shift; fi
if [[ ! -x "$weilgen" ]]; then
  echo "bench/openturns: no weilgen at $weilgen (build it: cmake --build build --target weilgen)" >&2
  exit 2
fi
exec /usr/bin/python3 "$here/bench_vs_openturns.py" "$weilgen" "$@"
