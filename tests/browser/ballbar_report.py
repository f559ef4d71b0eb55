#!/usr/bin/python3
"""The ballbar HTML report in a real browser (Debian's chromium, headless).

Usage: ballbar_report.py <weilgen> <trace.csv> <out_dir>

Writes <out_dir>/ballbar_report.html with `weilgen ballbar --report`, lets chromium render it with
the network cut off (--dump-dom, --screenshot <out_dir>/ballbar_report.png, 1240 px wide) and
checks what a reader sees: the ISO 230-4 table, the polar plot with both directions (blue ccw, red
cw) and the minimum zone, the ranked diagnosis, nothing fetched from elsewhere, and a page that
ends before the window does. Look at the PNG after changing the report (docs/ballbar.md).
"""
import os
import sys

sys.dont_write_bytecode = True  # a test writes nothing into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from iso230_2_report import count_near, fail, rendered  # noqa: E402  (one browser helper)

WIDTH, HEIGHT = 1240, 2600


def main():
    weilgen, data, out_dir = sys.argv[1:4]
    os.makedirs(out_dir, exist_ok=True)
    html = os.path.join(out_dir, "ballbar_report.html")
    png = os.path.join(out_dir, "ballbar_report.png")
    dom, img, last = rendered([weilgen, "ballbar", data, "--report", html], html, png, WIDTH,
                              HEIGHT)

    # The DOM the browser built.
    for what, n in (("<svg", 1), ("<table", 3), ('class="run"', 2), ('class="zone"', 4)):
        if dom.count(what) < n:
            fail("rendered DOM has %d '%s', expected >= %d" % (dom.count(what), what, n))
    for needle in ("Circular test", "ISO 230-4 figures", "Circular deviation G (minimum zone)",
                   "Polar plot", "Diagnosis", "squareness XY", "Tested by"):
        if needle not in dom:
            fail("rendered DOM lacks '%s'" % needle)

    # What the screenshot shows: both directions in the polar plot.
    blue, red = (0x1F, 0x77, 0xB4), (0xD6, 0x27, 0x28)
    nb, nr = count_near(img, (0, 0, WIDTH, HEIGHT), blue), count_near(img, (0, 0, WIDTH, HEIGHT), red)
    print("polar plot: %d blue, %d red pixels; last ink at %d px" % (nb, nr, last))
    if nb < 800 or nr < 800:
        fail("the polar plot lacks one of its directions")
    print("ok: %s" % png)


if __name__ == "__main__":
    main()
