#!/usr/bin/python3
"""CTest linuxcnc_configs: the configuration `weilgen linuxcnc` writes for every shipped machine
loads in halrun with its kinematics and LinuxCNC's motion module, as a user's .hal file sources it.

For each machine: weilgen linuxcnc, make, the symbol check, make install, then halrun with
trivkins (coordinates= and JOINTS from the generated file's INI lines), tpmod, homemod and motmod,
motion's two functions in the servo thread, and the generated <name>.hal sourced after them.
Checked: halrun exits 0 (every net, setp and addf of the file succeeded against motion's real
pins: a wrong joint number does not load), trivkins maps each joint to the letter the file says,
the servo thread runs motion-command-handler, <name>.feedback, motion-controller,
<name>.compensate in that order, and every input pin of the component that motion feeds is
connected.
"""
import argparse
import os
import re
import sys

sys.dont_write_bytecode = True  # a test writes nothing into the source tree
import halsession  # noqa: E402

check = halsession.check


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--weilgen", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("machines", nargs="+", help="machine files")
    args = p.parse_args()
    halsession.require_linuxcnc("linuxcnc_configs")
    os.makedirs(args.work, exist_ok=True)
    built = []
    for machine in args.machines:
        model = os.path.splitext(os.path.basename(machine))[0]
        name = "wgcfg_" + model
        out = os.path.join(args.work, name)
        so = halsession.build(args.weilgen, machine, out, name)
        banned = halsession.banned_symbols(so)
        check(not banned, "%s: the module uses an allocator or the C++ runtime: %s" % (name, banned))
        built.append((model, name, out))

    with halsession.Session("linuxcnc_configs") as s:
        for model, name, out in built:
            s.install(out)
            generated = os.path.join(out, name + ".hal")
            with open(generated) as f:
                text = f.read()
            coordinates = re.search(r"^#   \[KINS\] KINEMATICS = trivkins coordinates=(\w+)$", text, re.M)
            joints = re.search(r"^#   \[KINS\] JOINTS = (\d+)$", text, re.M)
            check(coordinates and joints, "%s: no INI lines in %s" % (model, generated))
            if not (coordinates and joints):
                continue
            letters = coordinates.group(1)
            hal = os.path.join(out, "config.hal")
            with open(hal, "w") as f:
                f.write("\n".join([
                    "loadrt trivkins coordinates=" + letters,
                    "loadrt tpmod",
                    "loadrt homemod",
                    "loadrt motmod servo_period_nsec=1000000 num_joints=" + joints.group(1),
                    "addf motion-command-handler servo-thread",
                    "addf motion-controller servo-thread",
                    "source " + generated,
                    "show thread servo-thread",
                    "show pin " + name,
                    "start",
                    "loadusr -w sleep 0.2",
                    "stop"]) + "\n")
            code, log = s.halrun(hal)
            check(code == 0, "%s: halrun exit %d\n%s" % (model, code, log))
            mapped = dict((int(j), a) for j, a in re.findall(r"Joint (\d+) ==> Axis (\w)", log))
            if not mapped and "XYZABCUVW".startswith(letters):
                mapped = {j: letters[j] for j in range(len(letters))}  # the identity: no report
            check(mapped == {j: letters[j] for j in range(len(letters))},
                  "%s: trivkins maps %s, the file says %s" % (model, mapped, letters))
            thread = re.findall(r"^\s+\d+ (\S+)$", log, re.M)
            want = ["motion-command-handler", name + ".feedback", "motion-controller",
                    name + ".compensate"]
            check(thread == want, "%s: servo thread %s, want %s" % (model, thread, want))
            for pin in ("pos-cmd", "motor-pos-cmd"):
                unconnected = [l for l in log.splitlines()
                               if l.strip().endswith("." + pin) and "<==" not in l]
                check(not unconnected, "%s: %s not connected: %s" % (model, pin, unconnected))
            for pin in ("enable", "homed"):
                check(re.search(r"%s\.%s <== " % (re.escape(name), pin), log),
                      "%s: %s.%s not connected" % (model, name, pin))
            print("%s: loads with trivkins coordinates=%s and motmod num_joints=%s; thread %s"
                  % (model, letters, joints.group(1), ", ".join(thread)))
    halsession.finish("linuxcnc_configs")


if __name__ == "__main__":
    main()
