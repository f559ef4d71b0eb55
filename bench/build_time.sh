#!/usr/bin/env bash
# Build time of weilgen from a clean clone (issue 26): prints a Markdown table of wall and CPU
# seconds for
#   1. `bash scripts/run_default.sh` (the README's first command: install check, CLI build, the
#      default job), dependencies already installed;
#   2. the `weilgen` target alone from scratch with -j2 (what run_default.sh builds);
#   3. the full build of the test command (scripts/build.sh, everything) from scratch;
# and, with --per-file, the compile CPU seconds of the 15 most expensive translation units.
#
# Usage: bench/build_time.sh [--per-file] [--unity-off] [--no-full] [REPO]
#   (REPO default: this checkout; --no-full skips the third, longest row)
# No ccache (CMAKE_*_COMPILER_LAUNCHER is cleared); the machine's load is printed beside the
# numbers, because wall times on a shared machine mean little without it.
set -euo pipefail
export LC_ALL=C
per_file=0
full=1
extra=()
while [[ "${1:-}" == --* ]]; do
  case "$1" in
    --per-file) per_file=1 ;;
    --unity-off) extra+=(-DWEILGEN_UNITY_BUILD=OFF) ;;
    --no-full) full=0 ;;
    *) echo "build_time.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
repo="${1:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}"
unset CMAKE_CXX_COMPILER_LAUNCHER CMAKE_C_COMPILER_LAUNCHER
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
git clone -q "$repo" "$tmp/src"
cd "$tmp/src"
jobs=$(nproc)

# seconds of wall, user+sys CPU of the children, for a command
measure() {
  local t0 c0 t1 c1 me=$BASHPID
  t0=$EPOCHREALTIME
  c0=$(awk '{print $14+$15+$16+$17}' /proc/$me/stat)
  "$@" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; echo "build_time.sh: '$*' failed" >&2; exit 1; }
  t1=$EPOCHREALTIME
  c1=$(awk '{print $14+$15+$16+$17}' /proc/$me/stat)
  awk -v a="$t0" -v b="$t1" -v c="$c0" -v d="$c1" -v hz="$(getconf CLK_TCK)" \
    -v l="$(cut -d' ' -f1 /proc/loadavg)" 'BEGIN {printf "%.0f | %.0f | %s", b - a, (d - c) / hz, l}'
}

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'), $jobs cores;" \
  "load before: $(cut -d' ' -f1-3 /proc/loadavg); commit $(git rev-parse --short HEAD)"
echo
echo "| what | wall s | CPU s | 1-min load at the end |"
echo "| --- | ---: | ---: | ---: |"
echo "| \`bash scripts/run_default.sh\` (clean clone, dependencies installed) | $(measure bash scripts/run_default.sh) |"
rm -rf build
launcher=()
if ((per_file)); then
  cat >"$tmp/tw.sh" <<'EOS'
#!/bin/bash
out=""; for ((i=1;i<=$#;i++)); do if [ "${!i}" = "-o" ]; then j=$((i+1)); out=${!j}; fi; done
exec /usr/bin/time -f "%U %S $out" -a -o "$TIMES" "$@"
EOS
  chmod +x "$tmp/tw.sh"
  export TIMES="$tmp/times.txt"
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER="$tmp/tw.sh")
fi
read -ra generator <<<"$(bash scripts/cmake_generator.sh build-cli)"
cmake -S . -B build-cli "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DWEILGEN_BUILD_TESTS=OFF -DWEILGEN_BUILD_PYTHON=OFF \
  -DWEILGEN_BUILD_BENCH=OFF "${launcher[@]}" "${extra[@]}" >/dev/null
echo "| \`weilgen\` target from scratch, -j$jobs | $(measure cmake --build build-cli -j"$jobs" --target weilgen) |"
((full)) && echo "| full build of the test command (\`scripts/build.sh\`) from scratch, -j$jobs | $(BUILD_DIR=build-full measure bash scripts/build.sh "${extra[@]}") |"
echo
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
if ((per_file)); then
  echo
  echo "The 15 most expensive translation units of the \`weilgen\` target (CPU s, user + sys):"
  echo
  awk '{printf "%8.1f  %s\n", $1 + $2, $3}' "$TIMES" | sort -rn | head -15
fi
