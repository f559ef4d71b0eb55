#!/usr/bin/env bash
# A stand-in for `weilgen gap` to test the benchmark's runner and scorer before the verb exists:
#   fake_gap.sh gap <machine> --data D.csv --json F [ignored options]
# writes a JSON of the verb's schema. FAKE_GAP_MODE: oracle (default: reads the truth.json next
# to the data, i.e. cheats, so every target passes) or none (always `none`: the effect-free
# target passes, attribution fails).
set -euo pipefail
[[ ${1:-} == gap ]] || { echo "fake_gap.sh: only the gap verb" >&2; exit 2; }
shift 2
data= json=
while [[ $# -gt 0 ]]; do
  case $1 in
    --data) data=$2; shift 2 ;;
    --json) json=$2; shift 2 ;;
    *) shift ;;
  esac
done
truth=$(dirname "$data")/truth.json
get() { grep -m1 "\"$1\":" "$truth" | sed 's/.*": *//; s/[",]//g'; }
# The "localise" object's fields (truth.json is written with 2-space indentation).
loc() {
  awk -v k="\"$1\":" '/^  "localise": \{/{f=1} f&&/^  \}/{f=0} f&&index($0,k){sub(/.*": */,"");gsub(/[",]/,"");print;exit}' "$truth"
}
# The hottest bin of the truth's held-out signal: "from to" (empty without bins).
hot_bin() {
  awk '/^  "localise": \{/{f=1} f&&/^  \}/{f=0} !f{next}
       /"bins": \[/{b=1} b&&/^    \]/{b=0}
       b&&/"from":/{v=$2;gsub(/,/,"",v);fr=v} b&&/"rms_um":/{v=$2;gsub(/,/,"",v);r=v+0}
       b&&/"to":/{v=$2;gsub(/,/,"",v);if(r>best){best=r;bf=fr;bt=v}}
       END{if(best>0)print bf, bt}' "$truth"
}
loc_by() { awk '/^  "localise": \{/{f=1} f&&/^  \}/{f=0} f&&/"by": \[/{getline;gsub(/[ ",]/,"");print;exit}' "$truth"; }
noise=$(get noise_rms_um)
verdict=none
[[ ${FAKE_GAP_MODE:-oracle} == oracle ]] && verdict=$(get expected_verdict)
by=$(loc_by); out=$(loc output)
read -r from to <<<"$(hot_bin)" || true
[[ -n $by ]] || by=output
[[ -n $out ]] || out=dx
# Two effects: "a+b" names both, the verdict the first.
names=$(printf '%s' "$verdict" | awk -F+ '{for(i=1;i<=NF;i++)printf "%s\"%s\"", (i>1?", ":""), $i}')
verdict=${verdict%%+*}
after=$(awk -v n="$noise" 'BEGIN{printf "%.6f", 1.05*n}')
cat >"$json" <<JSON
{"baseline": {"heldout_rms_um": {"$out": $(awk -v n="$noise" 'BEGIN{printf "%.6f", 1.1*n}')}, "holdout": "cycle"},
 "noise_floor_um": $noise, "noise_floor_source": "repeats",
 "where": [{"by": "$by", "output": "$out", "from": ${from:-0}, "to": ${to:-0}, "excess_um": 1.0, "p_value": 1e-6}],
 "effects": [{"name": "$verdict", "params": {}, "heldout_rms_before_um": 2.0, "heldout_rms_after_um": $after, "shrink_pct": 40, "significant": true, "p_value": 1e-6}],
 "verdict": {"effect": "$verdict", "explanation": [$names]}}
JSON
