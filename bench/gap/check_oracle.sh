#!/usr/bin/env bash
# The oracle reference of the benchmark, for a CTest (bench/gap/CMakeLists.txt):
#   check_oracle.sh WORKDIR        (weilgen_gap_synth and weilgen_gap_score in $WEILGEN_GAP_BIN)
# 1. the scorer: three scenarios written by the synth, with gap.json and gap_oracle.json of known
#    numbers, give the expected shrink_ratio_oracle, target row and consistency check; without
#    oracle files the row is absent (an older suite scores as before);
# 2. the runner (against fake_gap.sh): every scenario gets data_oracle.csv and gap_oracle.json,
#    --resume reruns nothing that is current and adds the oracle files to a suite without them.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
work=$1
bin=${WEILGEN_GAP_BIN:?set WEILGEN_GAP_BIN to the directory of weilgen_gap_synth}
rm -rf "$work"
mkdir -p "$work/score"
s=$work/score
fail() { echo "FAIL: $*"; exit 1; }

# 1. The scorer. s0001: a reversal diagnosed right, after {dx 2, dy 3}, oracle {dx 2.4, dy 2}:
# 3 / 2.4 = 1.25 (over 1.2). s0002: effect-free, `none`, baseline {dx 2}, oracle the same: 1.0.
# s0003: effect-free, `none`, no oracle run (counted, not within 1.2).
"$bin/weilgen_gap_synth" --effect reversal --factor 5 --noise-um 1 --layout small --seed 1 \
  --out "$s/s0001"
"$bin/weilgen_gap_synth" --effect none --noise-um 1 --layout small --seed 2 --out "$s/s0002"
"$bin/weilgen_gap_synth" --effect none --noise-um 1 --layout small --seed 3 --out "$s/s0003"
cmp -s "$s/s0002/data.csv" "$s/s0002/data_oracle.csv" || fail "effect-free: oracle file differs"
cmp -s "$s/s0001/data.csv" "$s/s0001/data_oracle.csv" && fail "reversal: oracle file = data"
printf '# dir\tid\tmodel_machine\n' >"$s/manifest.tsv"
for i in 1 2 3; do printf 's000%d\tvmc_3axis/small/x/f0/r%d\tvmc_3axis\n' $i $i >>"$s/manifest.tsv"; done
verdict() { grep -m1 '"expected_verdict"' "$s/$1/truth.json" | sed 's/.*": *"//; s/".*//'; }
[[ $(verdict s0001) == reversal ]] || fail "s0001 expects $(verdict s0001)"
cat >"$s/s0001/gap.json" <<'JSON'
{"baseline": {"heldout_rms_um": {"dx": 5.0, "dy": 6.0}, "holdout": "cycle:3"},
 "verdict": {"effect": "reversal", "explanation": ["reversal"],
             "heldout_rms_after_um": {"dx": 2.0, "dy": 3.0}}}
JSON
cat >"$s/s0001/gap_oracle.json" <<'JSON'
{"baseline": {"heldout_rms_um": {"dx": 2.4, "dy": 2.0}, "holdout": "cycle:3"},
 "verdict": {"effect": "none", "explanation": []}}
JSON
for i in 2 3; do
  cat >"$s/s000$i/gap.json" <<'JSON'
{"baseline": {"heldout_rms_um": {"dx": 2.0, "dy": 1.5}, "holdout": "cycle:3"},
 "verdict": {"effect": "none", "explanation": []}}
JSON
done
cp "$s/s0002/gap.json" "$s/s0002/gap_oracle.json"
"$bin/weilgen_gap_score" "$s" >"$s/score.log" || [[ $? == 3 ]] || fail "scorer: $(cat "$s/score.log")"
/usr/bin/python3 - "$s/results.json" "$s/results.md" <<'PY' || fail "scorer results"
import json, math, sys
r = json.load(open(sys.argv[1])); md = open(sys.argv[2]).read()
per = {p["dir"]: p for p in r["per_scenario"]}
ok = True
def want(what, got, expect):
    global ok
    good = (got is None and expect is None) or (
        got is not None and expect is not None and math.isclose(got, expect, rel_tol=1e-12))
    print("ok  " if good else "FAIL", what, got, "want", expect)
    ok = ok and good
want("s0001 shrink_ratio_oracle", per["s0001"]["shrink_ratio_oracle"], 3.0 / 2.4)
want("s0002 shrink_ratio_oracle", per["s0002"]["shrink_ratio_oracle"], 1.0)
want("s0003 shrink_ratio_oracle", per["s0003"]["shrink_ratio_oracle"], None)
want("s0001 oracle_heldout_rms_um", per["s0001"]["oracle_heldout_rms_um"], 2.4)
row = [t for t in r["targets"] if t["name"] == "... <= 1.2 x the oracle's"]
want("oracle target rows", len(row), 1)
want("oracle target value", row[0]["value"], 1 / 3)
want("oracle target n", row[0]["n"], 3)
names = [t["name"] for t in r["targets"]]
want("oracle row after the ideal row", names.index(row[0]["name"]),
     names.index("... <= 1.2 x what a right model leaves") + 1)
want("oracle runs found", r["oracle"]["found"], 2)
want("oracle runs expected", r["oracle"]["expected"], 3)
want("effect-free baselines agree", r["oracle"]["effect_free_baseline_agrees"]["correct"], 1)
want("small layout: oracle within 1.2", r["shrinkage_by_layout"]["small"]["oracle"]["correct"], 1)
good = "| ... <= 1.2 x the oracle's |" in md and "| small | 3 |" in md
print("ok  " if good else "FAIL", "results.md has the row and the layout table")
sys.exit(0 if ok and good else 1)
PY
# An older suite (no oracle files): the row is absent.
rm -f "$s"/s000?/gap_oracle.json "$s"/s000?/data_oracle.csv
"$bin/weilgen_gap_score" "$s" >"$s/score.log" || [[ $? == 3 ]] || fail "scorer without oracle"
grep -q "the oracle's" "$s/results.md" && fail "the oracle row is there without oracle files"
echo "ok   without oracle files: no oracle row"

# 2. The runner, against fake_gap.sh.
r=$work/run
sel=(--no-spindle --jobs 1 --quick --machines vmc_3axis --layouts small --effects reversal,none)
# Exit 3: some target fails (fake_gap.sh reports no ideal, and the selection has no step).
"$here/run_benchmark.sh" "$here/fake_gap.sh" "$r" "${sel[@]}" >"$work/run1.log" 2>&1 ||
  [[ $? == 3 ]] || fail "runner: $(tail -5 "$work/run1.log")"
n=$(grep -vc '^#' "$r/manifest.tsv")
[[ $(ls "$r"/s*/gap_oracle.json | wc -l) == "$n" ]] || fail "runner: not every gap_oracle.json"
grep -q "| ... <= 1.2 x the oracle's |" "$r/results.md" || fail "runner: no oracle row"
echo "ok   runner: $n scenarios, $n oracle runs, the row in results.md"
# --resume: a suite without s0001's oracle files gets them; nothing current runs again (the
# synth leaves unchanged files untouched, so every gap.json stays newer than its data).
rm -f "$r/s0001/data_oracle.csv" "$r/s0001/gap_oracle.json"
sleep 1
touch "$work/marker"
sleep 1
"$here/run_benchmark.sh" "$here/fake_gap.sh" "$r" "${sel[@]}" --resume >"$work/run2.log" 2>&1 ||
  [[ $? == 3 ]] || fail "runner --resume: $(tail -5 "$work/run2.log")"
rerun=$(cd "$r" && find . -name 'gap*.json' -newer "$work/marker" | sort | tr '\n' ' ')
[[ $rerun == "./s0001/gap_oracle.json " ]] || fail "--resume ran: '$rerun', want s0001's oracle"
echo "ok   --resume: ran only s0001's missing oracle"
