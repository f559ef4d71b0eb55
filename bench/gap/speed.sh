#!/usr/bin/env bash
# Speed of `weilgen gap` against the number of observations (docs/performance.md, "Gap diagnosis
# speed"): wall and CPU time, peak memory, the scaling exponent, and instruction counts.
#
#   bench/gap/speed.sh WEILGEN [WORKDIR] [--sizes 1000,5000,10000,20000,50000] [--threads 2]
#                      [--baseline OTHER_WEILGEN] [--instructions 5000,10000] [--repeat 1]
#                      [--machine vmc_3axis] [--effect reversal]
#
# Data: weilgen_gap_synth's grid layout of --machine (3 outputs per pose) with --effect (default a
# reversal of one axis; SNR 5, noise 0.5 µm, seed 7), its cycles repeated until --observations N
# (issue 32's thermal set: --machine gantry_grinder --effect thermal_drift --sizes 14886). Each size is
# run with /usr/bin/time -v (wall, user+sys CPU, peak RSS); `uptime` is recorded beside the
# numbers because the machine may be shared. --baseline runs another build on the same files
# (the previous implementation: same verdicts expected). --instructions counts instructions
# with valgrind --tool=callgrind at the given sizes (slow, but independent of the load), with
# --threads and per thread: the main thread's count is the serial part, and total / (main +
# the busiest worker slot) estimates the CPU/wall ratio a quiet machine gives (valgrind runs the
# threads one at a time, so it cannot measure it; it assumes each parallel loop's work splits
# like the slots' totals). Results: WORKDIR/speed.md and WORKDIR/speed.tsv (default WORKDIR:
# build/gap-speed).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
usage() { sed -n '2,15p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
[[ $# -ge 1 && $1 != -h && $1 != --help ]] || { usage; exit 2; }

abs() { echo "$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; }
weilgen=$(abs "$1")
shift
work=$root/build/gap-speed
if [[ $# -ge 1 && $1 != --* ]]; then work=$1; shift; fi
sizes=1000,5000,10000,20000,50000
threads=2
baseline=
instructions=
repeat=1
machine=vmc_3axis
effect=reversal
while [[ $# -gt 0 ]]; do
  case $1 in
    --sizes) sizes=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --baseline) baseline=$(abs "$2"); shift 2 ;;
    --instructions) instructions=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    --machine) machine=$2; shift 2 ;;
    --effect) effect=$2; shift 2 ;;
    *) echo "speed.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
for b in "$weilgen" $baseline; do
  [[ -x $b ]] || { echo "speed.sh: $b is not executable" >&2; exit 2; }
done
synth=${WEILGEN_GAP_BIN:-$(dirname "$weilgen")/bench/gap}/weilgen_gap_synth
[[ -x $synth ]] || synth=$root/build/bench/gap/weilgen_gap_synth
[[ -x $synth ]] || { echo "speed.sh: build weilgen_gap_synth first" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "speed.sh: needs /usr/bin/time (Debian package time)" >&2; exit 1; }
work=$work/$machine-$effect
mkdir -p "$work"
tsv=$work/speed.tsv
echo -e "build\tobservations\trun\twall_s\tcpu_s\tpeak_rss_mb\tverdict\tload_1min" >"$tsv"

field() { grep -F "$2" "$1" | head -1 | awk -F': ' '{print $2}'; }
seconds() { awk -F: '{ s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; print s }' <<<"$1"; }

IFS=, read -r -a size_list <<<"$sizes"
echo "start: $(uptime)" | tee "$work/uptime.txt"
for n in "${size_list[@]}"; do
  d=$work/n$n
  mkdir -p "$d"
  [[ -f $d/data.csv ]] || "$synth" --machine "$machine" --effect "$effect" --factor 5 \
    --noise-um 0.5 --layout grid --seed 7 --observations "$n" --out "$d" >/dev/null
  for label in new ${baseline:+baseline}; do
    bin=$weilgen
    [[ $label == baseline ]] && bin=$baseline
    for ((k = 1; k <= repeat; ++k)); do
      load=$(awk '{print $1}' /proc/loadavg)
      /usr/bin/time -v "$bin" gap "$machine" --data "$d/data.csv" --threads "$threads" \
        --json "$d/$label.json" >"$d/$label.log" 2>"$d/$label.time"
      wall=$(seconds "$(field "$d/$label.time" 'Elapsed (wall clock)')")
      cpu=$(awk -v u="$(field "$d/$label.time" 'User time')" \
        -v s="$(field "$d/$label.time" 'System time')" 'BEGIN{printf "%.2f", u + s}')
      rss=$(awk -v k="$(field "$d/$label.time" 'Maximum resident')" 'BEGIN{printf "%.0f", k / 1024}')
      verdict=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["verdict"]["effect"])' "$d/$label.json")
      echo -e "$label\t$n\t$k\t$wall\t$cpu\t$rss\t$verdict\t$load" | tee -a "$tsv"
    done
  done
done
echo "end: $(uptime)" | tee -a "$work/uptime.txt"

if [[ -n $instructions ]]; then
  command -v valgrind >/dev/null || { echo "speed.sh: --instructions needs valgrind" >&2; exit 1; }
  echo -e "build\tobservations\tinstructions\tmain_thread\tbusiest_worker" >"$work/instructions.tsv"
  IFS=, read -r -a isizes <<<"$instructions"
  for n in "${isizes[@]}"; do
    d=$work/n$n
    [[ -f $d/data.csv ]] || "$synth" --machine "$machine" --effect "$effect" --factor 5 \
      --noise-um 0.5 --layout grid --seed 7 --observations "$n" --out "$d" >/dev/null
    for label in new ${baseline:+baseline}; do
      bin=$weilgen
      [[ $label == baseline ]] && bin=$baseline
      rm -f "$d/$label.callgrind"*
      valgrind --tool=callgrind --separate-threads=yes --callgrind-out-file="$d/$label.callgrind" \
        "$bin" gap "$machine" --data "$d/data.csv" --threads "$threads" \
        --json "$d/$label.cg.json" >/dev/null 2>"$d/$label.cg.log"
      counts=$(for f in "$d/$label.callgrind"-*; do
        grep -E '^(summary|totals):' "$f" | head -1 | awk '{print $2}'
      done)
      ir=$(awk '{ s += $1 } END { printf "%.0f", s }' <<<"$counts")
      main=$(head -1 <<<"$counts")
      busiest=$(tail -n +2 <<<"$counts" | sort -n | tail -1)
      echo -e "$label\t$n\t$ir\t$main\t${busiest:-0}" | tee -a "$work/instructions.tsv"
    done
  done
fi

# The table and the scaling exponents (least squares of log time on log n over sizes >= 5000).
/usr/bin/python3 - "$work" <<'EOF'
import csv, math, os, sys
work = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(work, "speed.tsv")), delimiter="\t"))
def best(label, n, key):
    v = [float(r[key]) for r in rows if r["build"] == label and int(r["observations"]) == n]
    return min(v) if v else None
def exponent(points):
    pts = [(math.log(n), math.log(t)) for n, t in points if n >= 5000 and t > 0]
    if len(pts) < 2: return float("nan")
    mx = sum(p[0] for p in pts) / len(pts); my = sum(p[1] for p in pts) / len(pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
labels = [l for l in ("new", "baseline") if any(r["build"] == l for r in rows)]
sizes = sorted({int(r["observations"]) for r in rows})
out = []
head = "| observations |" + "".join(f" {l} wall s | {l} CPU s | {l} peak MB |" for l in labels)
out += [head, "|" + " ---: |" * (1 + 3 * len(labels))]
for n in sizes:
    line = f"| {n} |"
    for l in labels:
        line += f" {best(l, n, 'wall_s'):.2f} | {best(l, n, 'cpu_s'):.2f} | {best(l, n, 'peak_rss_mb'):.0f} |"
    out.append(line)
out.append("")
for l in labels:
    ew = exponent([(n, best(l, n, "wall_s")) for n in sizes])
    ec = exponent([(n, best(l, n, "cpu_s")) for n in sizes])
    out.append(f"{l}: time ~ n^{ec:.2f} (CPU), n^{ew:.2f} (wall), sizes >= 5000")
verdicts = {(r["build"], r["observations"]): r["verdict"] for r in rows}
same = all(verdicts.get(("new", str(n))) == verdicts.get(("baseline", str(n))) for n in sizes)
if "baseline" in labels:
    out.append("verdicts: " + ("the same for both builds" if same else "DIFFER"))
ip = os.path.join(work, "instructions.tsv")
if os.path.exists(ip):
    ir = list(csv.DictReader(open(ip), delimiter="\t"))
    out.append("")
    out.append("| build | observations | instructions (callgrind) | main thread (serial) | "
               "busiest worker slot | estimated CPU/wall |")
    out.append("| --- | ---: | ---: | ---: | ---: | ---: |")
    for r in ir:
        total, main, busy = (int(r[k]) for k in ("instructions", "main_thread", "busiest_worker"))
        ratio = total / (main + busy) if main + busy > 0 else float("nan")
        out.append(f"| {r['build']} | {r['observations']} | {total:,} | {main:,} "
                   f"({100 * main / total:.1f} %) | {busy:,} | {ratio:.2f} |")
    for l in labels:
        pts = [(int(r["observations"]), float(r["instructions"])) for r in ir if r["build"] == l]
        if len(pts) >= 2:
            (n0, i0), (n1, i1) = pts[0], pts[-1]
            out.append(f"{l}: instructions ~ n^{math.log(i1 / i0) / math.log(n1 / n0):.2f}")
out.append("")
out.append(open(os.path.join(work, "uptime.txt")).read().strip())
text = "\n".join(out) + "\n"
open(os.path.join(work, "speed.md"), "w").write(text)
print(text)
EOF
