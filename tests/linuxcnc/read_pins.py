# Reads pins of a HAL component at full double precision (halcmd getp prints 7 digits) and
# appends them as a JSON line to a file; run inside a halrun session by run_component_test.py
# with `loadusr -w /usr/bin/python3 read_pins.py OUT COMPONENT LABEL PINS` (PINS: a file with one
# pin or parameter name, without the component prefix, per line). It first waits
# until the component's function has run 3 more times, so that the values just set with setp have
# gone through compensate and feedback.
import json
import os
import sys
import time

import hal

out, component, label, pin_file = sys.argv[1:5]
with open(pin_file) as f:
    pins = [line.strip() for line in f if line.strip()]
reader = hal.component("weilgen_reader_%d" % os.getpid())
reader.ready()
start = hal.get_value(component + ".cycles")
deadline = time.monotonic() + 30.0
while hal.get_value(component + ".cycles") < start + 3:
    if time.monotonic() > deadline:
        sys.exit("read_pins: %s.cycles does not advance: the servo thread is not running" % component)
    time.sleep(0.002)
values = {pin: hal.get_value(component + "." + pin) for pin in pins}
with open(out, "a") as f:
    f.write(json.dumps({"label": label, "values": values}) + "\n")
reader.exit()
