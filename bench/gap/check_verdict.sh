#!/usr/bin/env bash
# One benchmark scenario's verdict, for a CTest (bench/gap/CMakeLists.txt):
#   check_verdict.sh WEILGEN WORKDIR ID VERDICT REASON_PART -- RUN_BENCHMARK_SELECTION...
# writes the selected scenarios with run_benchmark.sh, then checks that scenario ID (as in the
# manifest, e.g. vmc_3axis/sparse/step/f3/r0) reads VERDICT with REASON_PART in its reason.
set -euo pipefail
weilgen=$1 work=$2 id=$3 verdict=$4 reason=$5
shift 5
[[ ${1-} == -- ]] && shift
rm -rf "$work"
"$(dirname "$0")/run_benchmark.sh" "$weilgen" "$work" --no-spindle --jobs 1 "$@" >"$work.log" 2>&1 ||
  [[ $? == 3 ]] || { tail -20 "$work.log"; exit 1; }
dir=$(awk -F'\t' -v id="$id" '$2 == id { print $1 }' "$work/manifest.tsv")
[[ -n $dir ]] || { echo "no scenario $id in $work/manifest.tsv"; exit 1; }
/usr/bin/python3 - "$work/$dir/gap.json" "$verdict" "$reason" <<'PY'
import json, sys
v = json.load(open(sys.argv[1]))["verdict"]
print(v["effect"], "|", v["reason"])
sys.exit(0 if v["effect"] == sys.argv[2] and sys.argv[3] in v["reason"] else 1)
PY
