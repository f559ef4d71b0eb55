#!/usr/bin/env bash
# Generation cost: runs `weilgen generate machines/<m>.yaml --order r --out <tmpdir>` for every
# shipped machine and r = 1, 2, 3, and prints a Markdown table of wall time, peak resident memory,
# size of the generated header and the operation counts from its "Operation counts" comment.
#
# Usage: bench/bench_generation.sh [path/to/weilgen]        (default: build/weilgen)
#        ORDERS="1 2" bench/bench_generation.sh             (other orders)
#        MACHINES="pipe_cutter" bench/bench_generation.sh   (some machines only)
#        COMPILERS="g++ clang++" bench/bench_generation.sh  (also the compile time of each header:
#            `<compiler> -std=c++17 -O2 -c` of a file that instantiates every generated function
#            for double; CPU seconds and peak memory of the compiler)
#
# Peak memory needs GNU time (/usr/bin/time, Debian package `time`); without it only the wall time
# is measured (bash `time`). Nothing is installed by this script.
set -euo pipefail
export LC_ALL=C  # a decimal point in EPOCHREALTIME and in awk's output

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
weilgen="${1:-build/weilgen}"
orders="${ORDERS:-1 2 3}"

if [[ ! -x "$weilgen" ]]; then
  echo "bench_generation.sh: '$weilgen' is not an executable (build it: cmake --build build" \
    "--target weilgen, or pass its path)" >&2
  exit 2
fi

gnu_time=""
if [[ -x /usr/bin/time ]] && /usr/bin/time -f "%e %M" true >/dev/null 2>&1; then
  gnu_time=/usr/bin/time
else
  echo "bench_generation.sh: GNU time (/usr/bin/time) not found, peak memory is not measured." \
    "Install it with: apt-get install time (Debian package 'time'). Falling back to bash time." >&2
fi

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

shopt -s nullglob
machines=()
if [[ -n "${MACHINES:-}" ]]; then
  for m in $MACHINES; do machines+=("$root/machines/$m.yaml"); done
else
  machines=("$root"/machines/*.yaml)
fi
compilers="${COMPILERS:-}"
if [[ ${#machines[@]} -eq 0 ]]; then
  echo "bench_generation.sh: no machine files in $root/machines" >&2
  exit 2
fi

# The count after "<what>:" in the header's "Operation counts" comment lines.
op_count() {
  sed -n "s|^//[[:space:]]*$1:[[:space:]]*\\([0-9][0-9]*\\).*|\\1|p" "$2" | head -n 1
}

status=0
# CPU seconds and peak MiB of compiling a file that instantiates every function of header $2 in
# namespace weilgen_models::$3 for double, with compiler $1; "n/a" when the compiler is missing.
compile_cost() {
  if ! command -v "$1" >/dev/null 2>&1 || [[ -z "$gnu_time" ]]; then
    echo "n/a"
    return
  fi
  local ns="weilgen_models::$3" src="$tmp/instantiate.cpp"
  {
    echo "#include \"$2\""
    echo "template void $ns::Deviation<double>(const std::array<double, $ns::kNumAxes>&,"
    echo "  const std::array<double, $ns::kNumErrors>&, const std::array<double, $ns::kNumParams>&,"
    echo "  std::array<double, 3>*, std::array<double, 3>*);"
    echo "template void $ns::Coefficients<double>(const std::array<double, $ns::kNumAxes>&,"
    echo "  const std::array<double, $ns::kNumParams>&, std::array<double, 3 * $ns::kNumErrors>*,"
    echo "  std::array<double, 3 * $ns::kNumErrors>*);"
    if grep -q "^void HigherOrder" "$2"; then
      echo "template void $ns::HigherOrder<double>(const std::array<double, $ns::kNumAxes>&,"
      echo "  const std::array<double, $ns::kNumParams>&,"
      echo "  std::array<double, $ns::kNumOutputs * $ns::kNumHigherTerms>*);"
    fi
  } >"$src"
  if "$gnu_time" -f "%U %M" -o "$tmp/ctime.txt" "$1" -std=c++17 -O2 -c "$src" -o "$tmp/o.o" \
    >"$tmp/clog.txt" 2>&1; then
    awk '{ printf "%.1f s, %.0f MiB", $1, $2 / 1024 }' "$tmp/ctime.txt"
  else
    echo "FAILED"
    sed 's/^/    /' "$tmp/clog.txt" | head -n 20 >&2
  fi
}

head_line="| machine | order | seconds | CPU s | peak RSS MiB | header KiB | Deviation ops | Coefficients ops |"
rule="| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for c in $compilers; do
  head_line+=" $c -O2 |"
  rule+=" ---: |"
done
echo "$head_line"
echo "$rule"
for file in "${machines[@]}"; do
  machine="$(basename "$file" .yaml)"
  for r in $orders; do
    out="$tmp/$machine-o$r"
    mkdir -p "$out"
    rc=0
    if [[ -n "$gnu_time" ]]; then
      # GNU time's %e has 10 ms resolution: the wall time is taken from EPOCHREALTIME instead.
      start="${EPOCHREALTIME:-}"
      "$gnu_time" -f "%e %M %U" -o "$tmp/time.txt" \
        "$weilgen" generate "$file" --order "$r" --out "$out" >"$tmp/log.txt" 2>&1 || rc=$?
      end="${EPOCHREALTIME:-}"
      read -r seconds rss_kib cpu <"$tmp/time.txt" || true
      if [[ -n "$start" ]]; then  # bash >= 5
        seconds="$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.3f", b - a }')"
      fi
      rss_mib="$(awk -v k="${rss_kib:-0}" 'BEGIN { printf "%.1f", k / 1024 }')"
    else
      TIMEFORMAT=%R
      { time "$weilgen" generate "$file" --order "$r" --out "$out" >"$tmp/log.txt" 2>&1 \
        || rc=$?; } 2>"$tmp/time.txt"
      seconds="$(tail -n 1 "$tmp/time.txt")"
      rss_mib="n/a"
      cpu="n/a"
    fi
    if [[ $rc -ne 0 ]]; then
      echo "| $machine | $r | FAILED (exit $rc) | | | | | |"
      sed 's/^/    /' "$tmp/log.txt" >&2
      status=1
      continue
    fi
    headers=("$out"/*.hpp)
    if [[ ${#headers[@]} -ne 1 ]]; then
      echo "| $machine | $r | $seconds | ${cpu:-n/a} | $rss_mib | no header written | | |"
      status=1
      continue
    fi
    header="${headers[0]}"
    kib="$(awk -v b="$(wc -c <"$header")" 'BEGIN { printf "%.1f", b / 1024 }')"
    line="| $machine | $r | $seconds | ${cpu:-n/a} | $rss_mib | $kib | $(op_count Deviation "$header") |"
    line+=" $(op_count Coefficients "$header") |"
    ns="$(sed -n 's/^namespace \([A-Za-z0-9_]*\) {$/\1/p' "$header" | grep -v '^weilgen_models$' | head -n 1)"
    for c in $compilers; do line+=" $(compile_cost "$c" "$header" "$ns") |"; done
    echo "$line"
  done
done
exit $status
