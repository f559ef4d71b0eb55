#!/usr/bin/python3
"""Replays hostile command lines through the weilgen CLI (issue 16, docs/robustness.md).

Every case runs in a fresh directory holding copies of the inputs (a machine file, measurement
CSVs, a tolerance file) and outputs that already exist ("previous"). A case passes when
  - the exit status is the documented one (2 bad arguments, 3 bad input file),
  - the message names what is wrong: the flag (exit 2) or the file with its line and column
    (exit 3; "file: ..." for a file that cannot be read at all),
  - the message is short (no stack of compiler errors), nothing crashed (no signal, no
    'terminate called', no sanitizer report), and it ended within the time limit,
  - nothing in the directory changed: no output written, no input replaced, no temporary left.

Usage: hostile_cli.py WEILGEN SOURCE_DIR [-v] [-k SUBSTRING]
"""
import hashlib
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

WEILGEN, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
VERBOSE = "-v" in sys.argv
ONLY = sys.argv[sys.argv.index("-k") + 1] if "-k" in sys.argv else None
TIMEOUT_S = 120

POSE = "--at X=0,Y=0,Z=600"
GRID = "--grid X=0,Y=-1500:1500:3,Z=600"
SENS = f"sensitivity m.yaml {POSE} --quiet --json keep.json"
REL = f"reliability m.yaml {POSE} --tolerance dx=30um --quiet --json keep.json"
ALLOC = f"allocate m.yaml {GRID} --tolerance dx=30um --quiet --json keep.json"
ISO = "iso230-2 d.csv --json keep.json"
FIT = "fit-pdge l.csv --json keep.json"
IDENT = "identify vmc_3axis --data p.csv --quiet --json keep.json"
GAP = "gap vmc_3axis --data p.csv --quiet --json keep.json"
BALL = "identify vmc_3axis --data p.csv --predict b.csv --quiet --json keep.json"
BB = "ballbar b.csv --json keep.json"
PLAN = "plan vmc_3axis --poses 30 --quiet --json keep.json --out plan.csv"

# Values no numeric flag accepts.
NOT_NUMBERS = ["abc", "nan", "inf", "-inf", "1e999", "12abc", "0x10", "''", "' 5'", "1,5", "--"]

# (command without the flag, flag, values out of its range). Each is expected to exit 2 naming
# the flag.
NUMERIC = [
    (SENS, "--samples", ["-5", "1", "0", "4294967296", "1e99", "2.5"]),
    (SENS, "--bootstrap", ["-1", "100000000000", "1.5"]),
    (SENS, "--confidence", ["0", "1", "-0.5", "1.5", "95"]),
    (SENS, "--top", ["-1", "1e30"]),
    (SENS, "--seed", ["-1", "18446744073709551616", "1.5"]),
    (SENS, "--threads", ["-1", "4294967295", "100000", "0.5"]),
    (SENS, "--order", ["0", "-1", "21", "1000000", "1.5"]),
    (REL, "--samples", ["0", "-1", "1000000001"]),
    (REL, "--confidence", ["0", "1", "2"]),
    (REL, "--top", ["-3"]),
    (REL, "--threads", ["-1"]),
    (ALLOC, "--min", ["0", "1", "1.5", "-0.1"]),
    (ALLOC, "--mean", ["0", "1", "97"]),
    (ALLOC, "--choose", ["0", "-1", "1e9"]),
    (PLAN, "--poses", ["0", "-1", "2.5", "1e7"]),
    (PLAN, "--restarts", ["0", "-1", "1001"]),
    (PLAN, "--random-sets", ["0", "1.5"]),
    (PLAN, "--bound", ["-1", "1e9"]),
    (PLAN, "--rank-tol", ["0", "1", "-1e-9"]),
    (PLAN, "--angles", ["3", "100001"]),
    (PLAN, "--seed", ["-1", "18446744073709551616"]),
    (ALLOC, "--max-steps", ["0", "-5"]),
    (ALLOC, "--max-loosen", ["0.5", "-1", "1e300"]),
    (ALLOC, "--samples", ["0"]),
    (ISO, "--alpha", ["0", "1", "-1", "2"]),
    (ISO, "--target-tolerance", ["0", "-1e-6", "1e9"]),
    (ISO, "--reference-cycle", ["1.5", "1e99"]),
    (ISO, "--reference-position", []),
    (BB, "--alpha", ["0", "1", "-1", "2"]),
    (BB, "--min-contribution", ["-1", "1e9"]),
    (FIT, "--min-order", ["-1", "51"]),
    (FIT, "--max-order", ["-1", "51", "1000000"]),
    (FIT, "--folds", ["0", "1", "1001", "-3"]),
    (IDENT, "--rank-tol", ["0", "1", "-1e-9", "2"]),
    (IDENT, "--order", ["0", "21"]),
    (GAP, "--alpha", ["0", "0.5", "1", "-0.01"]),
    (GAP, "--threads", ["-1", "2000"]),
    (GAP, "--order", ["0"]),
    ("generate two_axis --out out", "--order", ["0", "-1", "21", "99999999999"]),
    ("show two_axis", "--order", ["0", "-2", "21"]),
]

# (command, expected exit, words the message must contain). Strings in their grammar.
CASES = [
    # Memory and size estimates, before allocating anything.
    (SENS + " --samples 4000000000", 2, ["--samples 4000000000", "memory"]),
    (SENS + " --samples 400000000 --bootstrap 100000", 2, ["memory"]),
    (SENS + " --samples 1024 --bootstrap 1000000", 2, ["--bootstrap", "out of range"]),
    ("show pipe_cutter --order 9", 2, ["--order 9", "error monomials"]),
    ("generate pipe_cutter --order 20 --out out", 2, ["--order 20", "error monomials"]),
    ("sensitivity pipe_cutter --order 12 --at X=0 --quiet", 2, ["--order 12"]),
    # Outputs that are inputs or each other, directories as outputs.
    (SENS.replace("keep.json", "m.yaml"), 2, ["--json", "is the input"]),
    (SENS + " --csv ./m.yaml", 2, ["--csv", "is the input"]),
    (SENS + " --csv link.yaml", 2, ["--csv", "is the input"]),
    (SENS + " --csv keep.json", 2, ["--csv", "also the output of --json"]),
    (SENS + " --plot m.yaml", 2, ["--plot", "is the input"]),
    (SENS + " --csv sub", 2, ["--csv", "is a directory"]),
    (SENS + " --csv m.yaml/x.csv", 2, ["--csv", "not a directory"]),
    (SENS + " --tolerances t.yaml --csv t.yaml", 2, ["--csv", "is the input --tolerances"]),
    (REL.replace("keep.json", "m.yaml"), 2, ["--json", "is the input"]),
    (ALLOC + " --save-tolerances m.yaml", 2, ["--save-tolerances", "is the input"]),
    (ALLOC + " --tolerances t.yaml --save-tolerances ./t.yaml", 2, ["--save-tolerances"]),
    (ALLOC + " --plot m.yaml", 2, ["--plot", "is the input"]),
    ("iso230-2 d.csv --json d.csv", 2, ["--json", "is the input"]),
    ("iso230-2 d.csv --plot d.csv", 2, ["--plot", "is the input"]),
    ("iso230-2 d.csv --json sub", 2, ["--json", "is a directory"]),
    ("fit-pdge l.csv --json l.csv", 2, ["--json", "is the input"]),
    ("identify vmc_3axis --data p.csv --emit-params p.csv --quiet", 2, ["--emit-params"]),
    ("identify vmc_3axis --data p.csv --json p.csv --quiet", 2, ["--json", "is the input"]),
    ("identify vmc_3axis --data p.csv --predict b.csv --predict-out b.csv --quiet", 2,
     ["--predict-out", "is the input --predict"]),
    ("identify vmc_3axis --data p.csv --json x.json --emit-params x.json --quiet", 2,
     ["--emit-params", "also the output of --json"]),
    ("gap vmc_3axis --data p.csv --json p.csv --quiet", 2, ["--json", "is the input"]),
    ("gap vmc_3axis --data p.csv --report p.csv --quiet", 2, ["--report", "is the input"]),
    ("gap vmc_3axis --data p.csv --plot p.csv --quiet", 2, ["--plot", "p.csv"]),
    ("gap vmc_3axis --data p.csv --plot keep.json --quiet", 2, ["--plot", "not a directory"]),
    ("generate two_axis.md --out .", 2, ["--out", "is the input"]),
    ("generate two_axis --out keep.json", 2, ["--out"]),
    # Strings with a grammar: each names its flag.
    (SENS.replace(POSE, "--at X=1e999,Y=0,Z=600"), 2, ["--at"]),
    (SENS.replace(POSE, "--at X=nan,Y=0,Z=600"), 2, ["--at"]),
    (SENS.replace(POSE, "--at X=0,X=1,Y=0,Z=600"), 2, ["--at"]),
    (SENS.replace(POSE, "--at X=0,Y=0,Z=99999"), 2, ["--at"]),
    (SENS.replace(POSE, "--at X=0,Y=0,Z=600deg"), 2, ["--at"]),
    (SENS.replace(POSE, "--at ="), 2, ["--at"]),
    (SENS.replace(POSE, "--at ''"), 2, ["--at"]),
    (SENS.replace(POSE, "--grid X=0:1000:0,Y=0,Z=600"), 2, ["--grid"]),
    (SENS.replace(POSE, "--grid X=0:1000:-1,Y=0,Z=600"), 2, ["--grid"]),
    (SENS.replace(POSE, "--grid X=0:1000:1e99,Y=0,Z=600"), 2, ["--grid"]),
    (SENS.replace(POSE, "--grid X=0:1000:2.5,Y=0,Z=600"), 2, ["--grid"]),
    (SENS.replace(POSE, "--grid X=0:1000:10000,Y=-1500:1500:10000,Z=600"), 2, ["--grid"]),
    (SENS.replace(POSE, "--grid X=0:1000:5:7,Y=0,Z=600"), 2, ["--grid"]),
    (SENS.replace(POSE, "--grid X=0,Y=0,Z=600 --grid X=1,Y=0,Z=600"), 2, ["--grid"]),
    (SENS + " --set E_XX=sigma:-1um", 2, ["--set"]),
    (SENS + " --set E_XX=sigma:1e999", 2, ["--set"]),
    (SENS + " --set E_XX=uniform:1,-1", 2, ["--set"]),
    (SENS + " --set E_XX=normal:0", 2, ["--set"]),
    (SENS + " --set E_XX=sigma:1urad", 2, ["--set"]),
    (SENS + " --set E_QQ=sigma:1um", 2, ["--set"]),
    (SENS + " --set group:nothing=sigma:1um", 2, ["--set"]),
    (SENS + " --set =sigma:1um", 2, ["--set"]),
    (SENS + " --set E_XX", 2, ["--set"]),
    (SENS + " --set E_XX=truncnormal:0,1,2,1", 2, ["--set"]),
    (SENS + " --param tool_length=abc", 2, ["--param"]),
    (SENS + " --param nope=1", 2, ["--param"]),
    (SENS + " --param tool_length=1e999", 2, ["--param"]),
    (SENS + " --param tool_length", 2, ["--param"]),
    (SENS + " --outputs dq", 2, ["dq"]),
    (SENS + " --outputs dx,dx", 2, ["--outputs"]),
    (SENS + " --outputs ''", 2, ["--outputs"]),
    (SENS + " --method magic", 2, ["--method"]),
    (SENS + " --sampling lhs", 2, ["--sampling"]),
    (SENS + " --engine gpu", 2, ["--engine"]),
    (SENS + " --plot x.pdf", 2, ["x.pdf"]),
    (SENS + " --bogus 1", 2, ["bogus"]),
    (SENS + " extra.yaml", 2, ["extra.yaml"]),
    ("sensitivity --at X=0 --quiet", 2, ["machine"]),
    (REL.replace("--tolerance dx=30um", "--tolerance dx=0"), 2, ["--tolerance"]),
    (REL.replace("--tolerance dx=30um", "--tolerance dx=-1um"), 2, ["--tolerance"]),
    (REL.replace("--tolerance dx=30um", "--tolerance dx=30urad"), 2, ["--tolerance"]),
    (REL.replace("--tolerance dx=30um", "--tolerance dq=30um"), 2, ["dq"]),
    (REL.replace("--tolerance dx=30um", "--tolerance dx=1e999um"), 2, ["--tolerance"]),
    (REL.replace("--tolerance dx=30um", "--tolerance dx=30um,dx=20um"), 2, ["--tolerance"]),
    (REL.replace("--tolerance dx=30um", ""), 2, ["--tolerance"]),
    (REL + " --limit sideways", 2, ["--limit"]),
    (REL + " --limit radial", 2, ["radial"]),
    (REL + " --method magic", 2, ["magic"]),
    (REL + " --sensitivities guess", 2, ["--sensitivities"]),
    (ALLOC + " --step 200%", 2, ["--step"]),
    (ALLOC + " --step -10%", 2, ["--step"]),
    (ALLOC + " --step E_QQ=1um", 2, ["--step"]),
    (ALLOC + " --weight E_XX=-1", 2, ["--weight"]),
    (ALLOC + " --weight E_XX=abc", 2, ["--weight"]),
    (ALLOC + " --errors E_QQ", 2, ["E_QQ"]),
    (ALLOC + " --rank sideways", 2, ["--rank"]),
    ("iso230-2 d.csv --axis Q --json keep.json", 2, ["--axis"]),
    ("iso230-2 d.csv --column dq_um --json keep.json", 2, ["dq_um"]),
    ("iso230-2 d.csv --reference-cycle 99 --json keep.json", 2, ["--reference-cycle"]),
    ("iso230-2 d.csv --plot x.gif --json keep.json", 2, ["x.gif"]),
    ("iso230-2", 2, ["no data file"]),
    ("iso230-2 d.csv --normalise sometimes --json keep.json", 2, ["--normalise"]),
    ("iso230-2 d.csv --normalise never --expansion 11 --json keep.json", 2, ["--expansion"]),
    ("iso230-2 d.csv --uncertainty lasr --json keep.json", 2, ["--uncertainty"]),
    ("iso230-2 d.csv --uncertainty nothing.yaml --json keep.json", 3, ["nothing.yaml"]),
    ("iso230-2 d.csv --uncertainty badbudget.yaml --json keep.json", 3,
     ["badbudget.yaml:1:1", "unknown key 'eve'"]),
    (BB + " --plot x.png", 2, ["--plot"]),
    (BB + " --report x.pdf", 2, ["--report"]),
    (BB + " --feedrate fast", 2, ["--feedrate"]),
    (BB + " --feedrate 0", 2, ["--feedrate"]),
    (BB + " --pdge poly:2", 2, ["--pdge"]),
    (BB + " --plane XQ", 2, ["--plane"]),
    (BB + " --radius -5", 2, ["--radius"]),
    ("ballbar b.csv --json b.csv", 2, ["--json", "is the input"]),
    ("ballbar b.csv --plot sub", 2, ["--plot"]),
    ("ballbar", 2, ["no trace file"]),
    ("ballbar nothing.csv --json keep.json", 3, ["nothing.csv: cannot read the data file"]),
    ("ballbar d.csv --json keep.json", 3, ["d.csv:", "'# radius:' is missing"]),
    ("fit-pdge l.csv --basis spline:3 --json keep.json", 2, ["spline"]),
    ("fit-pdge l.csv --basis poly:-1 --json keep.json", 2, ["--basis"]),
    ("fit-pdge l.csv --basis poly:99999 --json keep.json", 2, ["--basis"]),
    ("fit-pdge l.csv --basis fourier:3:-5 --json keep.json", 2, ["--basis"]),
    ("fit-pdge l.csv --order many --json keep.json", 2, ["--order"]),
    ("fit-pdge l.csv --period nan --json keep.json", 2, ["--period"]),
    ("fit-pdge l.csv --cv random --json keep.json", 2, ["--cv"]),
    ("fit-pdge l.csv --rule max --json keep.json", 2, ["--rule"]),
    ("fit-pdge l.csv --travel 5:1 --json keep.json", 2, ["--travel"]),
    ("fit-pdge l.csv --travel abc --json keep.json", 2, ["--travel"]),
    ("fit-pdge l.csv --angular-reference first --json keep.json", 2, ["--angular-reference"]),
    ("fit-pdge l.csv --min-order 5 --max-order 2 --json keep.json", 2, ["--min-order"]),
    (IDENT + " --pdge spline:3", 2, ["spline"]),
    (IDENT + " --pdge E_QQ=poly:3", 2, ["E_QQ"]),
    (IDENT + " --fix E_QQ", 2, ["E_QQ"]),
    (IDENT + " --predict-out x.csv", 2, ["--predict-out"]),
    ("identify vmc_3axis --quiet", 2, ["--data"]),
    (BALL + " --radius -5", 2, ["--radius"]),
    (BALL + " --radius abc", 2, ["--radius"]),
    (BALL + " --plane XQ", 2, ["--plane"]),
    (BALL + " --feed sideways", 2, ["--feed"]),
    (BALL + " --centre X=nan", 2, ["--centre"]),
    (GAP + " --holdout sideways", 2, ["--holdout"]),
    (GAP + " --holdout cycle:-1", 2, ["--holdout"]),
    (GAP + " --holdout forward:2", 2, ["--holdout"]),
    (GAP + " --effects magic", 2, ["--effects"]),
    (GAP + " --at Q=0", 2, ["--at"]),
    # Issue 28, weilgen plan: every refusal names the flag (or the file), writes nothing.
    (PLAN + " --instrument laser", 2, ["--instrument", "laser"]),
    (PLAN + " --criterion Z", 2, ["--criterion"]),
    (PLAN + " --noise 1kg", 2, ["--noise", "kg"]),
    (PLAN + " --noise dq=1um", 2, ["--noise", "dq"]),
    (PLAN + " --target-sd 2um", 2, ["--poses", "--target-sd"]),
    (PLAN.replace("--poses 30", "--target-sd -1um"), 2, ["--target-sd"]),
    (PLAN.replace("--poses 30", "--target-sd 0.001um"), 2, ["--target-sd", "candidate"]),
    (PLAN.replace("--poses 30", ""), 2, ["--poses"]),
    (PLAN.replace("--poses 30", "--poses 5"), 2, ["--poses", "at least 16"]),
    (PLAN.replace("--poses 30", "--poses 4000"), 2, ["--poses", "candidates"]),
    (PLAN + " --set Q=0", 2, ["--set", "Q"]),
    (PLAN + " --candidates X=0:500:21 --set X=5", 2, ["--candidates", "--set"]),
    (PLAN + " --instrument rtest", 2, ["rtest", "no rotary axis"]),
    (PLAN + " --instrument ballbar --plane XQ", 2, ["--plane", "XQ"]),
    (PLAN + " --instrument ballbar --radius -5", 2, ["--radius"]),
    (PLAN + " --nest X=0", 2, ["--nest"]),
    (PLAN + " --time-budget 4h", 2, ["--time-budget"]),
    (PLAN + " --times t.yaml", 2, ["--times"]),
    (PLAN.replace("--poses 30", "--instruments points:1um"), 2, ["--time-budget"]),
    (PLAN.replace("--poses 30", "--instruments points:abc --time-budget 4h"), 2,
     ["--instruments", "abc"]),
    (PLAN.replace("--poses 30", "--instruments points:1um,laser:1um --time-budget 4h"), 2,
     ["--instruments", "laser"]),
    (PLAN.replace("--poses 30", "--instruments points:1um --time-budget soon"), 2,
     ["--time-budget"]),
    (PLAN + " --include missing.csv", 3, ["missing.csv:"]),
    (PLAN + " --include b.csv", 3, ["b.csv:"]),
    (PLAN.replace("--out plan.csv", "--out keep.json"), 2, ["--json", "--out"]),
    (PLAN.replace("--out plan.csv", "--out p.csv --include p.csv"), 2, ["--out", "is the input"]),
    ("show two_axis --format pdf", 2, ["--format"]),
    ("show two_axis --notation greek", 2, ["--notation"]),
    ("show two_axis --output dq", 2, ["dq"]),
    ("list extra", 2, ["list"]),
    ("frobnicate", 2, ["frobnicate"]),
    # Long, odd and non-UTF-8 values: still one short line.
    (SENS + " --set E_XX=sigma:" + "1" * 20000 + "x", 2, ["--set"]),
    (SENS.replace(POSE, "--at 'X=" + "(" * 5000 + "1" + ")" * 5000 + ",Y=0,Z=600'"), 2, ["--at"]),
    (SENS.replace(POSE, "--at $'X=\\xff\\xfe,Y=0,Z=600'"), 2, ["--at"]),
    (SENS + " --param tool_length=" + "9" * 400, 2, ["--param"]),
    (SENS + " --samples " + "9" * 400, 2, ["--samples"]),
    (SENS.replace(POSE, "--at X=0,Y=0,Z=600,Q=1"), 2, ["--at", "Q"]),
    (SENS.replace(POSE, "--grid X=0:1:100000,Y=-1500:1500:1000,Z=600"), 2, ["--grid"]),
    # Bad files: exit 3, file:line:column (or "file: why" when it cannot be read at all).
    ("sensitivity sub --at X=0 --quiet", 3, ["sub: cannot read the machine file: is a directory"]),
    ("sensitivity nothing.yaml --at X=0 --quiet", 3, ["nothing.yaml: no such machine file"]),
    ("sensitivity empty.yaml --at X=0 --quiet", 3, ["empty.yaml:"]),
    ("sensitivity binary.yaml --at X=0 --quiet", 3, ["binary.yaml:"]),
    ("show int.yaml", 3, ["int.yaml:5:7", "C++ keyword"]),
    ("show big.yaml", 3, ["big.yaml:", "out of range"]),
    ("show order0.yaml", 3, ["order0.yaml:", "from 1 to 20"]),
    ("show tabs.yaml", 3, ["tabs.yaml:"]),
    ("generate two_axis int.yaml --out out", 3, ["int.yaml:5:7"]),
    (SENS + " --tolerances sub", 3, ["sub: cannot read the tolerance file: is a directory"]),
    (SENS + " --tolerances nothing.yaml", 3, ["nothing.yaml: cannot read the tolerance file"]),
    (SENS + " --tolerances badtol.yaml", 3, ["badtol.yaml:"]),
    ("iso230-2 sub --json keep.json", 3, ["sub: cannot read the data file: is a directory"]),
    ("iso230-2 nothing.csv --json keep.json", 3, ["nothing.csv: cannot read the data file"]),
    ("iso230-2 empty.csv --json keep.json", 3, ["empty.csv: empty file"]),
    ("iso230-2 binary.yaml --json keep.json", 3, ["binary.yaml:"]),
    ("iso230-2 e.csv --json keep.json", 3, ["e.csv:10:14", "the deviation is empty"]),
    ("iso230-2 huge.csv --json keep.json", 3, ["huge.csv:7:9", "out of range"]),
    ("iso230-2 ragged.csv --json keep.json", 3, ["ragged.csv:7:", "fields"]),
    ("fit-pdge sub --json keep.json", 3, ["sub:", "is a directory"]),
    ("identify vmc_3axis --data sub --quiet", 3, ["sub:", "is a directory"]),
    ("identify vmc_3axis --data empty_x.csv --quiet", 3, ["empty_x.csv:", ":1: column 'X' is empty"]),
    ("identify vmc_3axis --data dev1e300.csv --quiet", 3, ["dev1e300.csv:", "impossible"]),
    ("identify gantry_grinder --data p.csv --quiet", 3, ["p.csv:4:", "'# machine: vmc_3axis'"]),
    ("identify vmc_3axis --data p.csv --predict sub --quiet", 3, ["sub:", "is a directory"]),
    ("gap vmc_3axis --data sub --quiet", 3, ["sub:", "is a directory"]),
    ("gap gantry_grinder --data p.csv --quiet", 3, ["p.csv:4:", "'# machine: vmc_3axis'"]),
    # Issue 14, bad input: a rotary column in radians (the reader: gap and identify alike), a
    # covariate with gaps (every empty row named, the first cell located).
    ("gap five_axis_ac --data rad.csv --quiet --json keep.json", 3,
     ["rad.csv:13:15: column 'C' looks like radians", "write it in degrees"]),
    ("identify five_axis_ac --data rad.csv --quiet --json keep.json", 3,
     ["rad.csv:13:15: column 'C' looks like radians"]),
    ("gap vmc_3axis --data gap_t.csv --quiet --json keep.json --report keep.md --plot plots", 3,
     ["gap_t.csv:", "column 't_s' is empty in 2 rows where a deviation is measured (lines "]),
    ("gap vmc_3axis --data nan_t.csv --quiet --json keep.json", 3,
     ["nan_t.csv:", "column 't_s': 'nan' is not a number"]),
]


def fixtures(d):
    """The inputs every case may name, and outputs that exist already."""
    cp = lambda src, dst: shutil.copy(os.path.join(SOURCE, src), os.path.join(d, dst))
    cp("machines/gantry_grinder.yaml", "m.yaml")
    cp("machines/two_axis.yaml", "two_axis.md")
    cp("machines/tolerances/gantry_grinder_tight.yaml", "t.yaml")
    cp("examples/data/iso230_2_small.csv", "d.csv")
    cp("examples/data/vmc_3axis_points.csv", "p.csv")
    cp("examples/data/vmc_3axis_ballbar.csv", "b.csv")
    cp("examples/data/line6d_x.csv", "l.csv")
    os.symlink("m.yaml", os.path.join(d, "link.yaml"))
    os.mkdir(os.path.join(d, "sub"))
    w = lambda name, text: open(os.path.join(d, name), "w").write(text)
    w("keep.json", "previous")
    w("empty.yaml", "")
    w("empty.csv", "")
    open(os.path.join(d, "binary.yaml"), "wb").write(bytes(range(256)) * 4)
    two = open(os.path.join(SOURCE, "machines/two_axis.yaml")).read()
    w("int.yaml", two.replace("name: two_axis", "name: int"))
    w("big.yaml", two.replace("range: [0, 500]", "range: [0, 1e400]"))
    w("order0.yaml", two.replace("algebra: {order: 1}", "algebra: {order: 0}"))
    w("tabs.yaml", two.replace("  base: {}", "\tbase: {}"))
    w("badtol.yaml", "weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: -1, unit: mm}\n")
    w("badbudget.yaml", "eve: 1\n")
    iso = open(os.path.join(SOURCE, "examples/data/iso230_2_small.csv")).read().split("\n")
    e = list(iso)
    e[9] = e[9].rsplit(",", 1)[0] + ","  # 200,-1,1,180,  (dx_um empty)
    w("e.csv", "\n".join(e))
    h = list(iso)
    h[6] = h[6].rsplit(",", 1)[0] + ",1e999"
    w("huge.csv", "\n".join(h))
    r = list(iso)
    r[6] = r[6] + ",3"
    w("ragged.csv", "\n".join(r))
    pts = open(os.path.join(SOURCE, "examples/data/vmc_3axis_points.csv")).read().split("\n")
    head = next(i for i, l in enumerate(pts) if l.startswith("X,"))
    cols = pts[head].split(",")
    x = list(pts)
    x[head + 1] = "," + x[head + 1].split(",", 1)[1]
    w("empty_x.csv", "\n".join(x))

    def points_with(path, name, cells_by_row):
        """vmc_3axis_points.csv with the cells {data row: value} of column `name` replaced."""
        out = list(pts)
        for k, value in cells_by_row.items():
            cells = out[head + k].split(",")
            cells[cols.index(name)] = value
            out[head + k] = ",".join(cells)
        w(path, "\n".join(out))

    points_with("dev1e300.csv", "dx_um", {1: "1e300"})
    points_with("gap_t.csv", "t_s", {3: "", 7: ""})  # t_s empty in two measured rows
    points_with("nan_t.csv", "t_s", {2: "nan"})
    # five_axis_ac poses with C at 0, 30 ... 330 deg written in radians (line 13: 330 deg).
    rows = ["X,Y,Z,A,C,t_s,dx_um"]
    for i, a in enumerate((-30, 0, 30)):
        for k in range(12):
            rows.append(f"10,0,-100,{a},{math.radians(30 * k):.6f},{60 * (12 * i + k)},{0.1 * k:.1f}")
    w("rad.csv", "\n".join(rows) + "\n")


def snapshot(d):
    s = {}
    for root, dirs, files in os.walk(d):
        for name in dirs + files:
            p = os.path.join(root, name)
            if os.path.islink(p):
                s[p] = "link:" + os.readlink(p)
            elif os.path.isdir(p):
                s[p] = "dir"
            else:
                s[p] = hashlib.sha256(open(p, "rb").read()).hexdigest()
    return s


def run_case(args, status, words, env):
    d = tempfile.mkdtemp(prefix="hostile_")
    try:
        fixtures(d)
        before = snapshot(d)
        cmd = f"'{WEILGEN}' {args}"
        try:
            p = subprocess.run(cmd, shell=True, executable="/bin/bash", cwd=d, env=env, capture_output=True,
                               timeout=TIMEOUT_S, text=True, errors="replace")
        except subprocess.TimeoutExpired:
            return [f"no answer within {TIMEOUT_S} s"]
        out = p.stdout + p.stderr
        problems = []
        if p.returncode != status:
            problems.append(f"exit {p.returncode}, expected {status}")
        for w in words:
            if w not in out:
                problems.append(f"message lacks {w!r}")
        for bad in ("terminate called", "Segmentation", "ERROR: AddressSanitizer", "runtime error:",
                    "LeakSanitizer", "bad_alloc", "std::", "compilation terminated"):
            if bad in out:
                problems.append(f"output shows {bad!r}")
        if re.search(r"\.(cpp|hpp|h):\d+:\d+: (fatal )?error:", out):
            problems.append("output shows compiler errors")
        lines = [l for l in p.stderr.split("\n") if l and not l.startswith("==")]
        if len(lines) > 3:
            problems.append(f"{len(lines)} lines on stderr")
        if len(p.stderr) > 2000:
            problems.append(f"{len(p.stderr)} characters on stderr")
        if status == 3 and not re.search(r"^\S[^:\n]*:(\d+:(\d+:)? )?", p.stderr, re.M):
            problems.append("no file:line:column")
        after = snapshot(d)
        if after != before:
            changed = sorted(set(before.items()) ^ set(after.items()))
            problems.append("the directory changed: " + ", ".join(os.path.relpath(k, d)
                                                                  for k, _ in changed))
        if problems and VERBOSE:
            problems.append("output:\n" + out)
        return problems
    finally:
        shutil.rmtree(d, ignore_errors=True)


def main():
    env = dict(os.environ)
    cache = tempfile.mkdtemp(prefix="hostile_cache_")
    env["WEILGEN_CACHE_DIR"] = cache
    cases = list(CASES)
    for command, flag, values in NUMERIC:
        for v in values + NOT_NUMBERS:
            cases.append((f"{command} {flag} {v}", 2, [flag]))
    failures = 0
    ran = 0
    for args, status, words in cases:
        if ONLY and ONLY not in args:
            continue
        ran += 1
        problems = run_case(args, status, words, env)
        if problems:
            failures += 1
            shown = args if len(args) < 200 else args[:200] + "..."
            print(f"FAIL weilgen {shown}\n  " + "\n  ".join(p[:2000] for p in problems))
        elif VERBOSE:
            print(f"ok   weilgen {args if len(args) < 200 else args[:200] + '...'}")
    shutil.rmtree(cache, ignore_errors=True)
    print(f"{ran - failures} of {ran} hostile command lines behave")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
