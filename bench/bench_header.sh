#!/usr/bin/env bash
# Cost of compiling and of evaluating generated headers, one row per header (docs/performance.md,
# "Compiling the order-3 header"): for each compiler, `<compiler> -std=c++17 -O2 -c` of a file
# that instantiates Deviation, Coefficients and (with higher terms) HigherOrder for double (CPU
# seconds and peak memory of the compiler, GNU time); then bench/header_eval.cpp compiled with
# g++ -O2 against the header: CPU ns per call of each function, and with --instructions the
# instructions per call of Deviation and HigherOrder (callgrind: independent of the load).
#
#   bench/bench_header.sh [--compilers "g++ clang++"] [--instructions] HEADER [HEADER ...]
#
# Two headers of one model (say, from two builds of weilgen) print the same checksum.
set -euo pipefail
export LC_ALL=C
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
compilers="g++ clang++"
instructions=0
headers=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --compilers) compilers=$2; shift 2 ;;
    --instructions) instructions=1; shift ;;
    -h|--help) sed -n '2,11p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) headers+=("$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"); shift ;;
  esac
done
[[ ${#headers[@]} -gt 0 ]] || { echo "bench_header.sh: no header given" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "bench_header.sh: needs GNU time (Debian package time)" >&2; exit 1; }
if [[ $instructions == 1 ]] && ! command -v valgrind >/dev/null; then
  echo "bench_header.sh: --instructions needs valgrind" >&2
  exit 1
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "start: $(uptime)"
for h in "${headers[@]}"; do
  # The model's namespace: the first one opened inside weilgen_models (Pack comes before it).
  ns=$(grep -E '^namespace [A-Za-z_][A-Za-z0-9_]* \{$' "$h" | grep -v -m1 '^namespace weilgen_models {' |
    sed 's/namespace \(.*\) {/\1/')
  higher=0
  grep -q '^void HigherOrder' "$h" && higher=1
  n="weilgen_models::$ns"
  {
    echo "#include \"$h\""
    echo "template void $n::Deviation<double>(const std::array<double, $n::kNumAxes>&,"
    echo "  const std::array<double, $n::kNumErrors>&, const std::array<double, $n::kNumParams>&,"
    echo "  std::array<double, 3>*, std::array<double, 3>*);"
    echo "template void $n::Coefficients<double>(const std::array<double, $n::kNumAxes>&,"
    echo "  const std::array<double, $n::kNumParams>&, std::array<double, 3 * $n::kNumErrors>*,"
    echo "  std::array<double, 3 * $n::kNumErrors>*);"
    if [[ $higher == 1 ]]; then
      echo "template void $n::HigherOrder<double>(const std::array<double, $n::kNumAxes>&,"
      echo "  const std::array<double, $n::kNumParams>&,"
      echo "  std::array<double, $n::kNumOutputs * $n::kNumHigherTerms>*);"
    fi
  } >"$tmp/instantiate.cpp"
  echo
  echo "## $h ($(stat -c %s "$h") bytes, namespace $ns)"
  echo
  echo "| compiler -O2 | CPU s | peak MiB |"
  echo "| --- | ---: | ---: |"
  for c in $compilers; do
    if ! command -v "$c" >/dev/null; then echo "| $c | n/a | n/a |"; continue; fi
    if /usr/bin/time -f "%U %M" -o "$tmp/t.txt" "$c" -std=c++17 -O2 -c "$tmp/instantiate.cpp" \
      -o "$tmp/o.o" >"$tmp/log.txt" 2>&1; then
      awk -v c="$c" '{ printf "| %s | %.1f | %.0f |\n", c, $1, $2 / 1024 }' "$tmp/t.txt"
    else
      echo "| $c | FAILED | |"
      head -n 20 "$tmp/log.txt" >&2
    fi
  done
  defs=(-DWEILGEN_HEADER="\"$h\"" -DWEILGEN_NS="$ns")
  [[ $higher == 1 ]] && defs+=(-DWEILGEN_HIGHER)
  g++ -std=c++17 -O2 "${defs[@]}" "$root/bench/header_eval.cpp" -o "$tmp/eval"
  echo
  "$tmp/eval"
  if [[ $instructions == 1 ]]; then
    count() {
      valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$tmp/eval" --only "$1" \
        >/dev/null 2>&1
      grep -E '^(summary|totals):' "$tmp/cg.out" | head -1 | awk '{print $2}'
    }
    none=$(count none)
    echo
    echo "| function | instructions per call (callgrind, 64 poses) |"
    echo "| --- | ---: |"
    fs="Deviation DeviationAndCoefficients Coefficients"
    [[ $higher == 1 ]] && fs+=" HigherOrder"
    for f in $fs; do
      echo "| $f | $(( ($(count "$f") - none) / 64 )) |"
    done
  fi
done
echo
echo "end: $(uptime)"
