#!/usr/bin/env bash
# Runs every verb on the shipped machines and examples with fixed seeds and writes each
# verb's JSON, CSV, stdout and generated files into OUT, so that two builds can be compared
# byte for byte (a refactor must not change any of them):
#
#   bash scripts/snapshot_outputs.sh build-before /tmp/before
#   bash scripts/snapshot_outputs.sh build-after  /tmp/after
#   diff -r /tmp/before /tmp/after && echo identical
#
# Timings (elapsed seconds) are removed from stdout and JSON before writing; nothing else is.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:?usage: snapshot_outputs.sh BUILD_DIR OUT_DIR}
out=${2:?usage: snapshot_outputs.sh BUILD_DIR OUT_DIR}
wg="$build/weilgen"
synth="$build/bench/gap/weilgen_gap_synth"
rm -rf "$out" && mkdir -p "$out"
data="$out/.data" && mkdir -p "$data"

# Runs `weilgen ARGS...` as case NAME; stdout/stderr/exit code go to OUT/NAME.{out,err,rc}.
# Every `@` in ARGS is replaced by OUT/NAME (the case's own output prefix).
run() {
  local name=$1
  shift
  local args=()
  for a in "$@"; do args+=("${a//@/$out/$name}"); done
  set +e
  "$wg" "${args[@]}" >"$out/$name.out" 2>"$out/$name.err"
  echo $? >"$out/$name.rc"
  set -e
  # Strip run times.
  sed -i -E 's/[0-9]+(\.[0-9]+)? s\b/<t> s/g' "$out/$name.out" "$out/$name.err"
}

# The generated files at orders 1 and 2 (and 3 for the small machines).
for m in machines/*.yaml; do
  n=$(basename "$m" .yaml)
  run "generate_${n}_o1" generate "$m" --out "$out/generated_o1"
  run "generate_${n}_o2" generate "$m" --order 2 --out "$out/generated_o2"
  run "show_${n}" show "$n" --format json
  run "show_${n}_latex" show "$n" --format latex
done
run generate_two_axis_o3 generate machines/two_axis.yaml --order 3 --out "$out/generated_o3"
run show_grinder_alias show gantry_grinder --notation alias --output dx
run list list

# Sensitivity.
run sens_grinder sensitivity gantry_grinder --at X=500,Y=750,Z=1000 --samples 4096 --json @.json --csv @.csv --top 0
run sens_grinder_grid sensitivity gantry_grinder --grid X=0,Y=-1500:1500:3,Z=600:1400:2 --method exact --json @.json --csv @.csv
run sens_grinder_mc sensitivity gantry_grinder --at X=0,Y=1500,Z=600 --sampling mc --samples 2048 --bootstrap 50 --seed 3 --json @.json
run sens_vmc sensitivity vmc_3axis --at X=250,Y=-200,Z=-150 --samples 2048 --json @.json
run sens_5ax sensitivity five_axis_ac --at X=100,Y=50,Z=-100,A=30,C=45 --samples 2048 --json @.json
run sens_pipe sensitivity pipe_cutter --at X=800,Y231=20,A04=0,Y451=20,Z453=20 --samples 1024 --json @.json
run sens_two sensitivity two_axis --at Y=100,A=30 --samples 1024 --json @.json --outputs dx,dy,dz,dp

# Reliability.
run rel_grinder reliability gantry_grinder --grid X=0,Y=-1500:1500:5,Z=600:1400:5 --tolerance dx=0.03mm --limit one-sided --json @.json --csv @.csv
run rel_grinder_form reliability gantry_grinder --grid X=0,Y=-1500:1500:3,Z=600 --tolerance dx=0.03mm,dy=0.03mm --method form --json @.json
run rel_grinder_is reliability gantry_grinder --at X=0,Y=1500,Z=1400 --tolerance dp=0.04mm --limit radial --samples 4096 --json @.json
run rel_grinder_mc reliability gantry_grinder --at X=0,Y=1500,Z=1400 --tolerance dx=0.03mm --method mc --samples 4096 --json @.json
run rel_vmc reliability vmc_3axis --grid X=0:500:3,Y=-200,Z=-150 --tolerance dx=20um,dy=20um --json @.json

# Allocation.
run alloc_grinder allocate gantry_grinder --grid X=0,Y=-1500:1500:5,Z=600:1400:3 --tolerance dx=0.03mm --limit one-sided --min 0.95 --mean 0.97 --json @.json --save-tolerances @.tol.yaml
run alloc_grinder_cost allocate gantry_grinder --grid X=0,Y=-1500:1500:3,Z=600:1400:2 --tolerance dx=0.03mm --limit one-sided --min 0.95 --mean 0.97 --cost-aware --json @.json

# Measurements.
run iso_drift iso230-2 examples/data/iso230_2_drift.csv --json @.json
run iso_small iso230-2 examples/data/iso230_2_small.csv --json @.json
run fit_line6d fit-pdge examples/data/line6d_x.csv --json @.json
run fit_line6d_sel fit-pdge examples/data/line6d_x.csv --basis fourier:3,poly:7 --column E_XX --json @.json
run fit_line6d_auto fit-pdge examples/data/line6d_x.csv --basis fourier:auto:auto,poly --column E_AX,E_CX --curves
run fit_iso fit-pdge examples/data/iso230_2_small.csv --json @.json
run ident_vmc identify vmc_3axis --data examples/data/vmc_3axis_points.csv --predict examples/data/vmc_3axis_ballbar.csv --json @.json --emit-params @.params.hpp
run ident_vmc_pdge identify vmc_3axis --data examples/data/vmc_3axis_points.csv --pdge E_YY=fourier:3 --predict examples/data/ballbar_xy.csv --json @.json
run ident_vmc_pred identify vmc_3axis --data examples/data/vmc_3axis_points.csv --predict examples/data/vmc_3axis_points.csv --predict-out @.pred.csv --csv @.csv

# Gap diagnosis on synthetic withheld effects (fixed seeds).
for e in reversal:grid periodic:line thermal_drift:grid none:ballbar pdge_shape:grid missing_error:grid; do
  eff=${e%%:*}
  lay=${e##*:}
  "$synth" --effect "$eff" --factor 5 --noise-um 0.5 --layout "$lay" --seed 7 --out "$data/$eff" >/dev/null
  cp "$data/$eff/truth.json" "$out/gap_${eff}_truth.json"
  run "gap_${eff}" gap vmc_3axis --data "$data/$eff/data.csv" --json @.json --report @.md
done
# The generated data sets are compared too (the truth generator is part of the refactor).
for f in "$data"/*/data.csv; do cp "$f" "$out/gapdata_$(basename "$(dirname "$f")").csv"; done
rm -rf "$data"
# Remove timing fields from JSON documents and the snapshot directory from every text file.
for f in "$out"/*.json; do
  sed -i -E 's/"(elapsed|seconds|time)_?s?": [0-9.e+-]+/"\1": 0/g' "$f"
done
grep -rlF "$out" "$out" | xargs -r sed -i "s#$out#OUT#g"
echo "wrote $(ls "$out" | wc -l) files to $out"
