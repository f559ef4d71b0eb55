#!/usr/bin/python3
"""CTest linuxcnc_component: the HAL components of `weilgen linuxcnc`, built the LinuxCNC way
(Makefile.modinc) and run in halrun with a 1 ms servo thread, against the C++ model's
Compensate, and every safety behaviour of docs/controllers.md.

For each case the test writes the component, builds it, checks that the module needs no
allocator and no C++ runtime (nm), installs it (removed again at the end) and runs a halrun
session driven by hal_driver.py: LinuxCNC-convention joint commands (joint.N.pos-cmd, the tool
relative to the workpiece) and motor commands (pos-cmd + a home offset, as motion adds) set on the
input pins, the outputs read at full double precision. Every pos-comp must equal motor-pos-cmd +
sign * (Compensate(target) - target) / scale within 1e-9 mm (deg, inch), target = offset + sign *
scale * pos-cmd, with the reference program's iteration count (tests/linuxcnc/reference.cpp: the
model header's Compensate with the same errors and parameters); the signs, scales and offsets the
component reports must be the physical ones written here (a table axis -1).

  vmc_3axis       --params <build>/generated/vmc_3axis_params.hpp (identified errors built in),
                  an error pin and a parameter pin set; then the safety sequence: homed and
                  enable off, NaN error / command / motor command, a huge command, a huge error,
                  a pose outside the travel (errors held at the span's ends), a bad limit, the
                  fault latch and its reset, the ramps
  five_axis_ac    --params errors.json (const errors in mixed units, converted here)
  vmc_3axis inch  --units inch --offset ... --params-file P.json (identify --emit-params-json):
                  the file read at load, reloaded on a rising reload pin (a changed file, then
                  one of another model: refused, the old parameters stay); a component loaded
                  with another model's file refuses to load

Exit 0 pass, 1 fail; 77 (skip) only when LinuxCNC is missing and CI is not set.
"""
import argparse
import json
import math
import os
import random
import re
import subprocess
import sys

sys.dont_write_bytecode = True  # a test writes nothing into the source tree
import halsession  # noqa: E402

TOLERANCE = 1e-9  # mm (deg, inch)
check = halsession.check


def reference(program, params, errors, targets):
    """(iterations, command) per target: the model header's Compensate (model units)."""
    text = " ".join(repr(p) for p in params) + "\n" + " ".join(repr(e) for e in errors) + "\n"
    text += "".join(" ".join(repr(t) for t in target) + "\n" for target in targets)
    out = subprocess.run([program], input=text, stdout=subprocess.PIPE, text=True, check=True).stdout
    return [(int(l.split()[0]), [float(x) for x in l.split()[1:]]) for l in out.splitlines()]


class Case:
    """A component and the physical joint mapping of its machine (written here, not read back)."""

    def __init__(self, name, machine, pins, sign, scale, offset, motor_offset):
        self.name, self.machine, self.pins = name, machine, pins
        self.sign, self.scale, self.offset, self.motor_offset = sign, scale, offset, motor_offset

    def pin(self, axis, what):
        return "%s.%s.%s" % (self.name, self.pins[axis], what)

    def joint(self, model):  # LinuxCNC's joint position of model coordinates
        return [(t - o) / (s * c) for t, o, s, c in zip(model, self.offset, self.sign, self.scale)]

    def target(self, joint):
        return [o + s * c * p for p, o, s, c in zip(joint, self.offset, self.sign, self.scale)]

    def set_pose(self, joint):
        values = {}
        for a, p in enumerate(joint):
            values[self.pin(a, "pos-cmd")] = p
            values[self.pin(a, "motor-pos-cmd")] = p + self.motor_offset[a]
            values[self.pin(a, "pos-fb-in")] = p + self.motor_offset[a] + 0.0123
        return {"set": values}

    def axis_pins(self):
        return [self.pin(a, w) for a in range(len(self.pins))
                for w in ("pos-cmd", "motor-pos-cmd", "pos-comp", "correction", "pos-fb-in",
                          "pos-fb", "sign", "scale", "offset")]

    def status_pins(self):
        return [self.name + "." + p for p in
                ("status", "active", "ramping", "fault", "fault-code", "failures", "nan-inputs",
                 "limit-hits", "range-hits", "cycles", "reloads", "reload-failures",
                 "params-source", "compensate.time")]

    def read(self, label, extra=()):
        return {"read": label, "pins": self.axis_pins() + self.status_pins() + list(extra)}


def session(s, case, out, steps, loadrt_args=""):
    """One halrun session of `steps`; the readings by label."""
    program = os.path.join(out, "program.json")
    results = os.path.join(out, "results.jsonl")
    with open(program, "w") as f:
        json.dump({"component": case.name, "steps": steps}, f)
    if os.path.exists(results):
        os.remove(results)
    hal = os.path.join(out, "test.hal")
    with open(hal, "w") as f:
        f.write("\n".join([
            "loadrt threads name1=servo-thread period1=1000000",
            ("loadrt %s %s" % (case.name, loadrt_args)).strip(),
            "addf %s.feedback servo-thread" % case.name,
            "addf %s.compensate servo-thread" % case.name,
            halsession.driver_line(program, results),
            "start",
            "waitusr weilgen_driver",
            "stop"]) + "\n")
    code, log = s.halrun(hal)
    print("halrun %s: exit %d\n%s" % (case.name, code, log))
    check(code == 0, "%s: halrun exit %d" % (case.name, code))
    return halsession.driver_readings(results)


def check_mapping(case, v):
    for a in range(len(case.pins)):
        for what, want in (("sign", case.sign[a]), ("scale", case.scale[a]),
                           ("offset", case.offset[a])):
            got = v[case.pin(a, what)]
            check(abs(got - want) <= 1e-12 * max(1, abs(want)),
                  "%s axis %s: %s %r, the machine's is %r" % (case.name, case.pins[a], what, got, want))


def check_poses(case, readings, joints, ref, label="pose", fault=False):
    """Every reading against motor + sign * (Compensate - target) / scale."""
    worst, largest, clocks = 0.0, 0.0, []
    for k, (joint, (iterations, command)) in enumerate(zip(joints, ref)):
        v = readings.get("%s%d" % (label, k))
        check(v is not None, "%s %s%d: no reading" % (case.name, label, k))
        if v is None:
            continue
        target = case.target(joint)
        check(iterations >= 1, "%s %s%d: the reference did not compensate" % (case.name, label, k))
        check(v[case.name + ".status"] == iterations and v[case.name + ".active"] is True,
              "%s %s%d: status %s, the reference used %d iterations"
              % (case.name, label, k, v[case.name + ".status"], iterations))
        for a in range(len(case.pins)):
            correction = case.sign[a] * (command[a] - target[a]) / case.scale[a]
            want = joint[a] + case.motor_offset[a] + correction
            got = v[case.pin(a, "pos-comp")]
            worst = max(worst, abs(got - want))
            largest = max(largest, abs(correction))
            check(abs(got - want) <= TOLERANCE, "%s %s%d axis %s: pos-comp %r, expected %r"
                  % (case.name, label, k, case.pins[a], got, want))
            check(v[case.pin(a, "pos-comp")] == v[case.pin(a, "motor-pos-cmd")] +
                  v[case.pin(a, "correction")], "%s %s%d axis %s: pos-comp is not motor-pos-cmd + "
                  "correction" % (case.name, label, k, case.pins[a]))
            check(v[case.pin(a, "pos-fb")] == v[case.pin(a, "pos-fb-in")] -
                  v[case.pin(a, "correction")], "%s %s%d axis %s: feedback"
                  % (case.name, label, k, case.pins[a]))
        clocks.append(v[case.name + ".compensate.time"])
        check(v[case.name + ".fault"] is fault, "%s %s%d: fault %s" % (case.name, label, k, v[case.name + ".fault"]))
    check(largest > 1e-5, "%s: the corrections are too small to show anything (%g)" % (case.name, largest))
    clocks = sorted(clocks) or [0]
    print("%s: %d poses, largest correction %.4g (joint units), largest difference to Compensate %.2e; "
          "%s.compensate took %d CPU clocks (median; min %d, max %d)"
          % (case.name, len(joints), largest, worst, case.name, clocks[len(clocks) // 2],
             clocks[0], clocks[-1]))


def uncorrected(case, v, label, status, code=0):
    """The command went out uncorrected: pos-comp = motor-pos-cmd, correction 0, fault code."""
    if v is None:
        check(False, "%s %s: no reading" % (case.name, label))
        return
    check(v[case.name + ".status"] == status and v[case.name + ".active"] is False,
          "%s %s: status %s (want %d), active %s" % (case.name, label, v[case.name + ".status"],
                                                     status, v[case.name + ".active"]))
    for a in range(len(case.pins)):
        check(v[case.pin(a, "pos-comp")] == v[case.pin(a, "motor-pos-cmd")] and
              v[case.pin(a, "correction")] == 0.0,
              "%s %s axis %s: the output is not the uncorrected command" % (case.name, label, case.pins[a]))
    faulted(case, v, label, code)


def faulted(case, v, label, code):
    got = v[case.name + ".fault-code"]
    check(v[case.name + ".fault"] is bool(code) and (got & code) == code and (code or got == 0),
          "%s %s: fault %s fault-code %d, want code %d" % (case.name, label, v[case.name + ".fault"],
                                                           got, code))


def random_targets(ranges, count, seed):
    rng = random.Random(seed)
    return [[lo + (hi - lo) * rng.random() for lo, hi in ranges] for _ in range(count)]


def vmc_safety(case, ref_program, params, extra, settled_joint):
    """The safety sequence's steps and the checks that read it."""
    name = case.name
    big = {case.pin(a, "max-step"): 1e9 for a in range(3)}
    mark = lambda label: case.read(label)
    reset_steps = lambda: [{"set": {name + ".fault-reset": 1}}, {"cycles": 3},
                           {"set": {name + ".fault-reset": 0}}, {"settle": 3}]
    j = settled_joint
    x = case.pins.index("x")
    steps = [{"set": big}, case.set_pose(j), {"settle": 3}, mark("start")]
    steps += [{"set": {name + ".homed": 0}}, {"settle": 3}, mark("homed0"),
              {"set": {name + ".homed": 1, name + ".enable": 0}}, {"settle": 3}, mark("enable0"),
              {"set": {name + ".enable": 1}}, {"settle": 3}, mark("on-again")]
    steps += [{"set": {name + ".error.E_YY": float("nan")}}, {"settle": 3}, mark("nan-error")]
    steps += reset_steps() + [mark("reset-while-nan")]
    steps += [{"set": {name + ".error.E_YY": 0.0}}] + reset_steps() + [mark("reset")]
    steps += [{"set": {case.pin(x, "pos-cmd"): float("inf")}}, {"settle": 3}, mark("nan-pos"),
              case.set_pose(j)] + reset_steps()
    steps += [{"set": {case.pin(x, "motor-pos-cmd"): float("nan")}}, {"settle": 3}, mark("nan-motor"),
              case.set_pose(j)] + reset_steps()
    huge = list(j)
    huge[x] = case.joint([0, 1e6, 0])[x]  # model X = 1e6 mm
    steps += [case.set_pose(huge), {"settle": 3}, mark("huge-command"), case.set_pose(j)]
    steps += reset_steps()
    steps += [{"set": {name + ".error.E_C0Y": 0.5}}, {"settle": 3}, mark("huge-error"),
              {"set": {name + ".error.E_C0Y": 0.0}}] + reset_steps()
    outside = list(j)
    outside[x] = case.joint([0, -10.0, 0])[x]  # model X = -10 mm, the travel is 0 ... 500
    steps += [case.set_pose(outside), {"settle": 3}, mark("outside"), case.set_pose(j)]
    steps += reset_steps()
    steps += [{"set": {case.pin(x, "max-correction"): float("nan")}}, {"settle": 3}, mark("bad-limit"),
              {"set": {case.pin(x, "max-correction"): 0.1}}] + reset_steps() + [mark("clean")]
    # Ramps: 0.1 um per period; off, then on again.
    steps += [{"set": {case.pin(a, "max-step"): 1e-4 for a in range(3)}},
              {"set": {name + ".enable": 0}}, {"cycles": 2}, mark("ramp-out-1"), {"cycles": 10},
              mark("ramp-out-2"), {"settle": 3}, mark("ramp-out-done"),
              {"set": {name + ".enable": 1}}, {"cycles": 2}, mark("ramp-in-1"), {"cycles": 10},
              mark("ramp-in-2"), {"settle": 3}, mark("ramp-in-done")]
    # The reference for the pose outside the travel (errors held at X = 0).
    held = reference(ref_program, params, extra, [case.target(outside)])[0]

    def checks(r):
        for label in ("homed0", "enable0", "nan-error", "reset-while-nan", "reset", "nan-pos",
                      "nan-motor", "huge-command", "huge-error", "outside", "bad-limit", "clean",
                      "ramp-out-1", "ramp-out-2", "ramp-in-1", "ramp-in-2"):
            v = r.get(label, {})
            print("%-16s status %3s fault %-5s code %2s  correction %s  pos-comp - motor %s" % (
                label, v.get(name + ".status"), v.get(name + ".fault"), v.get(name + ".fault-code"),
                " ".join("%.3e" % v.get(case.pin(a, "correction"), float("nan")) for a in range(3)),
                " ".join("%.3e" % (v.get(case.pin(a, "pos-comp"), float("nan")) -
                                   v.get(case.pin(a, "motor-pos-cmd"), float("nan"))) for a in range(3))))
        start = r.get("start")
        check(start is not None and start[name + ".fault"] is False, "vmc safety: not clean at start")
        for label, status in (("homed0", 0), ("enable0", 0)):
            uncorrected(case, r.get(label), label, status)
        check(r.get("on-again", {}).get(name + ".status", 0) >= 1, "vmc: on again")
        uncorrected(case, r.get("nan-error"), "nan-error", -1, 1)
        check(r.get("nan-error", {}).get(name + ".nan-inputs", 0) >= 1, "nan-inputs not counted")
        faulted(case, r.get("reset-while-nan"), "reset while the NaN persists", 1)
        faulted(case, r.get("reset"), "reset", 0)
        uncorrected(case, r.get("nan-pos"), "nan-pos", -1, 1)
        v = r.get("nan-motor")
        if v:
            pc = v[case.pin(x, "pos-comp")]
            check(math.isfinite(pc) and pc == start[case.pin(x, "pos-comp")],
                  "nan-motor: pos-comp %r, it must keep its last value %r" % (pc, start[case.pin(x, "pos-comp")]))
            faulted(case, v, "nan-motor", 1)
        uncorrected(case, r.get("huge-command"), "huge-command", -1, 4 | 8)
        check(r.get("huge-command", {}).get(name + ".limit-hits", 0) >= 1 and
              r.get("huge-command", {}).get(name + ".range-hits", 0) >= 1, "huge-command: counters")
        uncorrected(case, r.get("huge-error"), "huge-error", -1, 4)
        v = r.get("outside")
        if v:
            faulted(case, v, "outside", 8)
            target = case.target(outside)
            for a in range(3):
                want = outside[a] + case.motor_offset[a] + case.sign[a] * (held[1][a] - target[a]) / case.scale[a]
                check(abs(v[case.pin(a, "pos-comp")] - want) <= TOLERANCE,
                      "outside the travel: pos-comp %r, Compensate with held errors %r" % (v[case.pin(a, "pos-comp")], want))
            check(v[name + ".status"] == held[0], "outside: status")
        uncorrected(case, r.get("bad-limit"), "bad-limit", -1, 32 | 4)
        faulted(case, r.get("clean"), "clean", 0)
        # Ramps: at most 1e-4 per period (+ 2 periods for the asynchronous reads), never a step.
        for a in range(3):
            c0 = start[case.pin(a, "correction")]
            for first, second, final in (("ramp-out-1", "ramp-out-2", 0.0), ("ramp-in-1", "ramp-in-2", c0)):
                v1, v2 = r.get(first), r.get(second)
                if not (v1 and v2):
                    check(False, "ramp readings missing")
                    continue
                dc = abs(v2[case.pin(a, "correction")] - v1[case.pin(a, "correction")])
                dn = (v2[name + ".cycles"] - v1[name + ".cycles"]) % (1 << 32)
                check(dc <= 1e-4 * (dn + 2) + 1e-15, "ramp axis %s: %g in %d periods" % (case.pins[a], dc, dn))
                if abs(c0) > 5e-3:
                    check(v1[name + ".ramping"] is True, "ramp axis %s: not ramping" % case.pins[a])
            check(r["ramp-out-done"][case.pin(a, "correction")] == 0.0, "ramped out")
            check(abs(r["ramp-in-done"][case.pin(a, "correction")] - c0) <= 1e-12, "ramped in")
        check(max(abs(start[case.pin(a, "correction")]) for a in range(3)) > 5e-3,
              "the ramp needs a correction of some um to show")
    return steps, checks


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--weilgen", required=True)
    p.add_argument("--generated", required=True, help="the build's generated/ directory")
    p.add_argument("--work", required=True)
    p.add_argument("--reference", action="append", default=[], help="machine=program")
    args = p.parse_args()
    refs = dict(r.split("=", 1) for r in args.reference)
    halsession.require_linuxcnc("linuxcnc_component")
    os.makedirs(args.work, exist_ok=True)
    src = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

    # The five-axis machine's errors as a JSON tolerance file of const entries, in mixed units;
    # the component must hold them in base units (mm, rad).
    json_errors = {"E_XX": ({"const": 4, "unit": "um"}, 4e-3),
                   "E_ZZ": ({"const": -0.006, "unit": "mm"}, -6e-3),
                   "E_C0Y": ({"const": 15, "unit": "urad"}, 15e-6),
                   "E_X0C": ({"const": 0.012, "unit": "mm"}, 0.012),
                   "E_B0A": ({"const": 4, "unit": "arcsec"}, 4 * math.pi / (180 * 3600))}
    json_path = os.path.join(args.work, "five_axis_errors.json")
    with open(json_path, "w") as f:
        json.dump({"weilgen_tolerances": 1, "machine": "five_axis_ac",
                   "errors": {k: v[0] for k, v in json_errors.items()}}, f, indent=1)
    with open(os.path.join(args.generated, "five_axis_ac_c.h")) as f:
        five_names = re.findall(r"FIVE_AXIS_AC_ERROR_(\w+) = \d+", f.read())
    with open(os.path.join(args.generated, "vmc_3axis_c.h")) as f:
        vmc_errors = re.findall(r"VMC_3AXIS_ERROR_(\w+) = \d+", f.read())
    # Identified parameters as JSON and as the header the reference includes, from one run.
    params_json = os.path.join(args.work, "vmc_params.json")
    halsession.run([args.weilgen, "identify", "vmc_3axis", "-q", "--data",
                    os.path.join(src, "examples/data/vmc_3axis_points.csv"),
                    "--emit-params-json", params_json])

    # kAxes: vmc Y, X, Z; five-axis X, Z, Y, A, C. Physical signs: the table's axes -1.
    vmc = Case("wgtest_vmc_3axis", "vmc_3axis", ["y", "x", "z"], [-1, -1, 1], [1, 1, 1],
               [0, 0, 0], [3.25, -1.5, 0.75])
    five = Case("wgtest_five_axis_ac", "five_axis_ac", ["x", "z", "y", "a", "c"],
                [1, 1, -1, -1, -1], [1] * 5, [0] * 5, [0.5, -2.0, 1.0, 0.25, -0.5])
    inch = Case("wgtest_vmc_inch", "vmc_3axis", ["y", "x", "z"], [-1, -1, 1], [25.4] * 3,
                [-200.0, 250.0, -150.0], [0.1, -0.2, 0.05])
    vmc_extra = [0.0] * len(vmc_errors)
    vmc_extra[vmc_errors.index("E_XX")] = 0.0015  # 1.5 um on top of the identified E_XX
    builds = {
        vmc: halsession.build(args.weilgen, "vmc_3axis", os.path.join(args.work, vmc.name), vmc.name,
                              ["--params", os.path.join(args.generated, "vmc_3axis_params.hpp")]),
        five: halsession.build(args.weilgen, "five_axis_ac", os.path.join(args.work, five.name),
                               five.name, ["--params", json_path]),
        inch: halsession.build(args.weilgen, "vmc_3axis", os.path.join(args.work, inch.name), inch.name,
                               ["--units", "inch", "--offset", "X=250,Y=-200,Z=-150",
                                "--params-file", params_json]),
    }
    for case, so in builds.items():
        banned = halsession.banned_symbols(so)
        check(not banned, "%s: the module uses an allocator or the C++ runtime: %s" % (case.name, banned))

    vmc_targets = random_targets([(-400, 0), (0, 500), (-300, 0)], 12, 1)
    five_targets = random_targets([(-300, 300), (-400, 0), (-250, 250), (-110, 110), (-360, 360)],
                                  10, 2) + [[120.0, -150.0, 80.0, 35.0, 30.0]]
    with halsession.Session("linuxcnc_component") as s:
        # vmc_3axis, identified errors built in.
        out = os.path.dirname(builds[vmc])
        s.install(out)
        joints = [vmc.joint(t) for t in vmc_targets]
        ref = reference(refs["vmc_3axis"], [25.0], vmc_extra, vmc_targets)
        safety_steps, safety_checks = vmc_safety(vmc, refs["vmc_3axis"], [25.0], vmc_extra, joints[0])
        steps = [{"set": {vmc.name + ".enable": 1, vmc.name + ".homed": 1,
                          vmc.name + ".error.E_XX": 0.0015, vmc.name + ".param.tool_length": 25.0}},
                 {"set": {vmc.pin(a, "max-step"): 1e9 for a in range(3)}}]
        for k, j in enumerate(joints):
            steps += [vmc.set_pose(j), {"settle": 3}, vmc.read("pose%d" % k)]
        r = session(s, vmc, out, steps + safety_steps)
        if "pose0" in r:
            check_mapping(vmc, r["pose0"])
        check_poses(vmc, r, joints, ref)
        safety_checks(r)

        # five_axis_ac, constant errors from a tolerance file.
        out = os.path.dirname(builds[five])
        s.install(out)
        joints = [five.joint(t) for t in five_targets]
        ref_errors = [json_errors[e][1] if e in json_errors else 0.0 for e in five_names]
        ref = reference(refs["five_axis_ac"], [120.0, 60.0], ref_errors, five_targets)
        steps = [{"set": {five.name + ".enable": 1, five.name + ".homed": 1}},
                 {"set": {five.pin(a, "max-step"): 1e9 for a in range(5)}}]
        for k, j in enumerate(joints):
            steps += [five.set_pose(j), {"settle": 3},
                      five.read("pose%d" % k, [five.name + ".error." + e for e in json_errors])]
        steps += [{"set": {five.name + ".error.E_XX": float("nan")}}, {"settle": 3}, five.read("failed")]
        r = session(s, five, out, steps)
        if "pose0" in r:
            check_mapping(five, r["pose0"])
            for e, (_, want) in json_errors.items():
                got = r["pose0"][five.name + ".error." + e]
                check(abs(got - want) <= 1e-15 * max(1.0, abs(want)),
                      "%s: error.%s = %r, the JSON says %r" % (five.name, e, got, want))
        check_poses(five, r, joints, ref)
        uncorrected(five, r.get("failed"), "failed", -1, 1)

        # vmc_3axis in inch with offsets, the identified parameters from a file, reloaded.
        out = os.path.dirname(builds[inch])
        s.install(out)
        inch_targets = vmc_targets[:6]
        joints = [inch.joint(t) for t in inch_targets]
        ref = reference(refs["vmc_3axis"], [0.0], [0.0] * len(vmc_errors), inch_targets)
        shifted = [0.0] * len(vmc_errors)
        shifted[vmc_errors.index("E_C0Y")] = 5e-6
        ref_shifted = reference(refs["vmc_3axis"], [0.0], shifted, inch_targets)
        with open(params_json) as f:
            original = f.read()
        doc = json.loads(original)
        for e in doc["errors"]:
            if e["name"] == "E_C0Y":
                e["value"] += 5e-6
        changed = os.path.join(out, "changed.json")
        with open(changed, "w") as f:
            json.dump(doc, f)
        other = dict(doc, machine="five_axis_ac")
        other_path = os.path.join(out, "other_model.json")
        with open(other_path, "w") as f:
            json.dump(other, f)
        live = os.path.join(out, "live_params.json")
        with open(live, "w") as f:
            f.write(original)
        # The files the component opens, where its unprivileged uid can read them.
        live, other_path = s.readable(live), s.readable(other_path)
        pulse = lambda: [{"set": {inch.name + ".reload": 1}}, {"cycles": 3},
                         {"set": {inch.name + ".reload": 0}}, {"cycles": 40}]
        steps = [{"set": {inch.name + ".enable": 1, inch.name + ".homed": 1}},
                 {"set": {inch.pin(a, "max-step"): 1e9 for a in range(3)}}]
        for k, j in enumerate(joints):
            steps += [inch.set_pose(j), {"settle": 3}, inch.read("pose%d" % k)]
        # The component reloads live_params.json; the driver replaces it between the reloads.
        steps += [{"copy": [changed, live]}] + pulse()
        for k, j in enumerate(joints):
            steps += [inch.set_pose(j), {"settle": 3}, inch.read("changed%d" % k)]
        steps += [{"copy": [other_path, live]}] + pulse() + [inch.read("refused")]
        for k, j in enumerate(joints[:2]):
            steps += [inch.set_pose(j), {"settle": 3}, inch.read("kept%d" % k)]
        r = session(s, inch, out, steps, "params_file=" + live)
        if "pose0" in r:
            check_mapping(inch, r["pose0"])
            check(r["pose0"][inch.name + ".params-source"] == 2, "inch: params-source")
        check_poses(inch, r, joints, ref)
        check_poses(inch, r, joints, ref_shifted, "changed")
        check_poses(inch, r, joints[:2], ref_shifted[:2], "kept", fault=True)
        v = r.get("changed0", {})
        check(v.get(inch.name + ".reloads") == 1, "inch: reloads %r" % v.get(inch.name + ".reloads"))
        v = r.get("refused", {})
        check(v.get(inch.name + ".reload-failures") == 1 and v.get(inch.name + ".fault") is True and
              (v.get(inch.name + ".fault-code", 0) & 16) == 16,
              "inch: a reload of another model's file must fail and fault: %r" % {
                  k: v.get(inch.name + "." + k) for k in ("reload-failures", "fault", "fault-code")})

        # Another model's file at load: the module refuses to load, saying why.
        hal = os.path.join(out, "refuse.hal")
        with open(hal, "w") as f:
            f.write("loadrt %s params_file=%s\n" % (inch.name, other_path))
        code, log = s.halrun(hal)
        print("halrun %s params_file=%s: exit %d\n%s" % (inch.name, other_path, code, log))
        check(code != 0 and "machine: 'five_axis_ac' is not this component's model 'vmc_3axis'" in log,
              "a params file of another model must refuse the load")
        s.unload()
    halsession.finish("linuxcnc_component")


if __name__ == "__main__":
    main()
