# Drives a halrun session of the LinuxCNC tests: run as `loadusr -Wn weilgen_driver
# /usr/bin/python3 hal_driver.py PROGRAM.json RESULTS.jsonl`, it creates its HAL component (and,
# when the program asks, stand-ins for motion's joint and motion pins and for the drives), becomes
# ready, waits for the servo thread to run the component under test, then executes the program's
# steps and appends one JSON line per read to RESULTS. The .hal file ends with
# `waitusr weilgen_driver`.
#
# PROGRAM: {"component": NAME, "joints": N (stand-ins, optional), "steps": [...]}, each step one
# of
#   {"set": {"name": value, ...}}   a pin or parameter (hal.set_p), or a stand-in's own output pin
#                                   (joint.N.pos-cmd, joint.N.motor-pos-cmd, motion.motion-enabled,
#                                   motion.is-all-homed, drive.N.position-fb)
#   {"settle": N}                   wait until NAME.cycles has advanced by N and NAME.ramping is 0
#   {"cycles": N}                   wait until NAME.cycles has advanced by N
#   {"drive": true}                 the perfect drive: drive.N.position-fb = drive.N.position-cmd
#   {"read": LABEL, "pins": [...]}  record the values (full names) at full double precision
#   {"copy": [FROM, TO]}            replace the file TO by FROM's text (atomically: a parameter
#                                   file the component reloads)
# halcmd getp prints 7 digits; hal.get_value gives the double.
#
# The stand-ins own the pins motion (motmod) owns in a real configuration, so that the
# configuration `weilgen linuxcnc` writes can be sourced unchanged: joint.N.pos-cmd and
# joint.N.motor-pos-cmd out, joint.N.motor-pos-fb in; motion.motion-enabled and
# motion.is-all-homed out; drive.N.position-cmd in and drive.N.position-fb out stand for a drive.
import json
import os
import shutil
import sys
import time

import hal

program_file, results_file = sys.argv[1:3]
with open(program_file) as f:
    program = json.load(f)
component = program["component"]
joints = program.get("joints", 0)

me = hal.component("weilgen_driver")
own = {}  # full stand-in pin name -> the driver component's local name
for j in range(joints):
    me.setprefix("joint")
    for pin, kind, direction in (("pos-cmd", hal.HAL_FLOAT, hal.HAL_OUT),
                                 ("motor-pos-cmd", hal.HAL_FLOAT, hal.HAL_OUT),
                                 ("motor-pos-fb", hal.HAL_FLOAT, hal.HAL_IN)):
        me.newpin("%d.%s" % (j, pin), kind, direction)
        own["joint.%d.%s" % (j, pin)] = "%d.%s" % (j, pin)
    me.setprefix("drive")
    me.newpin("%d.position-cmd" % j, hal.HAL_FLOAT, hal.HAL_IN)
    me.newpin("%d.position-fb" % j, hal.HAL_FLOAT, hal.HAL_OUT)
    own["drive.%d.position-cmd" % j] = "%d.position-cmd" % j
    own["drive.%d.position-fb" % j] = "%d.position-fb" % j
if joints:
    me.setprefix("motion")
    for pin in ("motion-enabled", "is-all-homed"):
        me.newpin(pin, hal.HAL_BIT, hal.HAL_OUT)
        own["motion." + pin] = pin
me.ready()


def value(name):
    return me[own[name]] if name in own else hal.get_value(name)


def wait(cycles, settle, timeout=60.0):
    start = hal.get_value(component + ".cycles")
    deadline = time.monotonic() + timeout
    while True:
        advanced = (hal.get_value(component + ".cycles") - start) % (1 << 32)
        if advanced >= cycles and not (settle and hal.get_value(component + ".ramping")):
            return
        if time.monotonic() > deadline:
            sys.exit("hal_driver: %s does not %s within %.0f s" % (
                component, "settle" if settle else "run", timeout))
        time.sleep(0.002)


# The servo thread runs once the .hal file has said `start`.
deadline = time.monotonic() + 60
while not hal.component_exists(component) or hal.get_value(component + ".cycles") < 2:
    if time.monotonic() > deadline:
        sys.exit("hal_driver: %s.cycles does not advance: the servo thread is not running" % component)
    time.sleep(0.01)

with open(results_file, "a") as out:
    for step in program["steps"]:
        if "set" in step:
            for name, v in step["set"].items():
                if name in own:
                    me[own[name]] = v
                else:
                    hal.set_p(name, repr(v) if isinstance(v, float) else str(int(v)))
        elif "settle" in step:
            wait(step["settle"], True)
        elif "cycles" in step:
            wait(step["cycles"], False)
        elif "drive" in step:
            for j in range(joints):
                me["%d.position-fb" % j] = me["%d.position-cmd" % j]
        elif "copy" in step:
            source, target = step["copy"]
            shutil.copyfile(source, target + ".tmp")
            os.replace(target + ".tmp", target)
        elif "read" in step:
            out.write(json.dumps({"label": step["read"],
                                  "values": {p: value(p) for p in step["pins"]}}) + "\n")
        else:
            sys.exit("hal_driver: unknown step %r" % step)
me.exit()
