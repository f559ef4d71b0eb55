#!/usr/bin/python3
"""The ISO 230-2 HTML report in a real browser (Debian's chromium, headless).

Usage: iso230_2_report.py <weilgen> <data.csv> <out_dir>

Writes <out_dir>/iso230_2_report.html with `weilgen iso230-2 --report`, lets chromium render it
with the network cut off (--dump-dom: the DOM the browser built; --screenshot: the page as a
1240 px wide PNG, <out_dir>/iso230_2_report.png) and checks what a reader sees: the three charts
and the tables are in the rendered DOM, nothing is fetched from elsewhere, and the screenshot
shows the forward (blue) and reverse (red) series in both deviation charts side by side, the
green PASS verdict, and a page that ends before the window does. Look at the PNG yourself after
changing the report (docs/iso230-2.md, "The report").
"""
import os
import shutil
import subprocess
import sys
import tempfile

from PIL import Image

WIDTH, HEIGHT = 1240, 4000


def fail(why):
    print("FAIL:", why)
    sys.exit(1)


def chromium(args, profile):
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if not exe:
        fail("chromium not found on PATH: install it (scripts/install_deps.sh does)")
    cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           "--no-first-run", "--user-data-dir=" + profile,
           # No network: a self-contained report needs none.
           "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9"] + args
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    if r.returncode != 0:
        fail("chromium exited %d: %s" % (r.returncode, r.stderr[-2000:]))
    return r.stdout


def rendered(weilgen_args, html, png, width, height):
    """Writes `html` with weilgen (its arguments), lets chromium render it: the DOM it built,
    and the screenshot `png` (width x height) as an RGB image with the row of its last ink."""
    for f in (html, png):
        if os.path.exists(f):
            os.remove(f)
    r = subprocess.run(weilgen_args, capture_output=True, text=True)
    if r.returncode != 0:
        fail("weilgen exited %d: %s" % (r.returncode, r.stdout + r.stderr))
    url = "file://" + os.path.abspath(html)
    with tempfile.TemporaryDirectory() as profile:
        dom = chromium(["--dump-dom", url], profile)
        chromium(["--window-size=%d,%d" % (width, height), "--screenshot=" + png, url], profile)
    for external in ("src=\"http", "href=\"http", "@import", "<script src", "url(http"):
        if external in dom:
            fail("the report fetches something from elsewhere: '%s'" % external)
    img = Image.open(png).convert("RGB")
    if img.size != (width, height):
        fail("screenshot is %s, expected %s" % (img.size, (width, height)))
    gray = img.convert("L")
    rows = [y for y in range(height) if gray.crop((0, y, width, y + 1)).getextrema()[0] < 200]
    if not rows:
        fail("blank page")
    if rows[-1] > height - 40:
        fail("the page does not end within %d px (last ink at %d px)" % (height, rows[-1]))
    return dom, img, rows[-1]


def count_near(img, box, rgb, tol=40):
    n = 0
    for p in img.crop(box).getdata():
        if all(abs(p[k] - rgb[k]) <= tol for k in range(3)):
            n += 1
    return n


def main():
    weilgen, data, out_dir = sys.argv[1:4]
    os.makedirs(out_dir, exist_ok=True)
    html = os.path.join(out_dir, "iso230_2_report.html")
    png = os.path.join(out_dir, "iso230_2_report.png")
    dom, img, last = rendered(
        [weilgen, "iso230-2", data, "--tolerance", "20,A=30", "--uncertainty", "auto", "--report",
         html], html, png, WIDTH, HEIGHT)

    # The DOM the browser built.
    for what, n in (("<svg", 3), ("<table", 7)):
        if dom.count(what) < n:
            fail("rendered DOM has %d '%s', expected >= %d" % (dom.count(what), what, n))
    for needle in ("Positioning accuracy and repeatability", "Drift-eliminated evaluation",
                   "VMC 850 (synthetic)", "Normalised to 20", "Measurement uncertainty",
                   "expansion coefficient", "Tested by"):
        if needle not in dom:
            fail("rendered DOM lacks '%s'" % needle)

    # What the screenshot shows.
    if last < 1500:
        fail("the page is suspiciously short (last ink at %d px)" % last)
    blue, red, green = (0x1F, 0x77, 0xB4), (0xD6, 0x27, 0x28), (0x1A, 0x7F, 0x37)
    half = WIDTH // 2
    for name, box in (("left (ISO 230-2)", (0, 0, half, HEIGHT)),
                      ("right (drift-eliminated)", (half, 0, WIDTH, HEIGHT))):
        nb, nr = count_near(img, box, blue), count_near(img, box, red)
        print("%s half: %d blue, %d red pixels" % (name, nb, nr))
        if nb < 500 or nr < 500:
            fail("the %s chart lacks its forward/reverse series" % name)
    ng = count_near(img, (0, 0, WIDTH, HEIGHT), green, 30)
    print("green (PASS) pixels: %d; last ink at %d px" % (ng, last))
    if ng < 30:
        fail("no PASS verdict visible")
    print("ok: %s" % png)


if __name__ == "__main__":
    main()
