"""What the halrun tests of tests/linuxcnc share: building a component the LinuxCNC way, the lock
around LinuxCNC's machine-wide HAL memory, installing and removing modules, and running halrun.

As root in a container halrun needs RTAPI_UID (an unprivileged uid, 65534) and RTAPI_FIFO_PATH in
a directory that uid can write; it then runs "POSIX non-realtime". halrun sessions share HAL's
memory machine-wide, so every test holds the lock file /tmp/weilgen-linuxcnc-test.lock around
install, run and removal (scripts that run halrun by hand take it with flock(1)).

A test skips (exit 77) only when LinuxCNC is missing or its module directory is not writable and
CI is not set; under CI that is a failure (scripts/install_deps.sh installs linuxcnc-uspace and
linuxcnc-uspace-dev).
"""
import fcntl
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

LOCK = "/tmp/weilgen-linuxcnc-test.lock"
HERE = os.path.dirname(os.path.abspath(__file__))
DRIVER = os.path.join(HERE, "hal_driver.py")


failures = []  # what check() found wrong, in this process


def check(ok, what):
    """Records and prints a failure; the test goes on, finish() decides the exit code."""
    if not ok:
        failures.append(what)
        print("FAILED:", what)


def finish(test):
    """Exit 1 with the count when a check failed, else print '<test>: ok'."""
    if failures:
        print("%s: %d failure(s)" % (test, len(failures)))
        sys.exit(1)
    print("%s: ok" % test)


def unavailable(test, why):
    if os.environ.get("CI"):
        print("%s: %s, and CI is set: failing (scripts/install_deps.sh installs linuxcnc-uspace "
              "and linuxcnc-uspace-dev)" % (test, why))
        sys.exit(1)
    print("%s: skipped: %s" % (test, why))
    sys.exit(77)


def run(cmd, **kw):
    """Runs cmd; its output, or SystemExit naming the command and showing its output."""
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)
    if r.returncode != 0:
        print("$ " + " ".join(cmd) + "\n" + r.stdout)
        raise SystemExit("%s failed (exit %d)" % (os.path.basename(cmd[0]), r.returncode))
    return r.stdout


def module_dir():
    modinc = run(["halcompile", "--print-modinc"]).strip()
    with open(modinc) as f:
        dirs = re.findall(r"^RTLIBDIR := (\S+)", f.read(), re.M)
    if not dirs:
        raise SystemExit("no RTLIBDIR in " + modinc)
    return dirs[-1]


def require_linuxcnc(test):
    """The LinuxCNC tools, and LinuxCNC's module directory writable; returns the directory."""
    for tool in ("halrun", "halcompile", "make", "gcc", "g++", "nm"):
        if shutil.which(tool) is None:
            unavailable(test, "%s not found" % tool)
    rtlib = module_dir()
    if not os.access(rtlib, os.W_OK):
        unavailable(test, "LinuxCNC's module directory %s is not writable (make install needs "
                          "root)" % rtlib)
    return rtlib


def banned_symbols(so):
    """The module's strong undefined references to an allocator or the C++ runtime."""
    undefined = [l.split()[-1] for l in run(["nm", "-u", "-D", so]).splitlines()
                 if l.split()[:1] == ["U"]]  # crtbegin's weak __cxa_finalize is libc's
    return [s for s in undefined
            if re.match(r"(malloc|calloc|realloc|free|_Znw|_Zna|_Zdl|_Zda|__cxa_|__gxx_|_Unwind_)", s)]


def build(weilgen, machine, out, name, args=()):
    """weilgen linuxcnc into `out` (emptied first) and make; returns the .so's path."""
    shutil.rmtree(out, ignore_errors=True)
    run([weilgen, "linuxcnc", machine, "--out", out, "--name", name] + list(args))
    run(["make", "-C", out])
    return os.path.join(out, name + ".so")


class Session:
    """The lock, the halrun environment, the modules installed under it (removed on exit)."""

    def __init__(self, test, timeout=900):
        self.test = test
        self.rtlib = module_dir()
        self.lock = open(LOCK, "w")
        deadline = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(self.lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise SystemExit("%s: another halrun test holds %s" % (test, LOCK))
                time.sleep(1)
        self.fifo = tempfile.mkdtemp(prefix="weilgen-rtapi-")
        os.chmod(self.fifo, 0o777)
        self.env = dict(os.environ, RTAPI_UID="65534",
                        RTAPI_FIFO_PATH=os.path.join(self.fifo, "rtapi_fifo"))
        self.installed = []
        self.halted = False

    def __enter__(self):
        return self

    def readable(self, path):
        """A copy of `path` that rtapi_app can open: it runs as RTAPI_UID (65534), which cannot
        enter a clone under /root (mode 0700). In the session's directory, world-readable; gone
        with the session."""
        copy = os.path.join(self.fifo, os.path.basename(path))
        shutil.copyfile(path, copy)
        os.chmod(copy, 0o644)
        return copy

    def install(self, component_dir):
        run(["make", "-C", component_dir, "install"])
        for so in os.listdir(component_dir):
            if so.endswith(".so"):
                self.installed.append(os.path.join(self.rtlib, so))

    def halrun(self, hal_file, timeout=900):
        """halrun -f hal_file: (exit code, output without uspace's uid notes)."""
        try:
            r = subprocess.run(["halrun", "-f", hal_file], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, env=self.env, timeout=timeout)
        except subprocess.TimeoutExpired:
            self.halted = True
            return -1, "halrun: timed out after %d s" % timeout
        if r.returncode != 0:
            self.halted = True
            self.unload()
        return r.returncode, "\n".join(l for l in r.stdout.splitlines() if "fallback_uid" not in l)

    def unload(self):
        """Stops what a failed session left running (halrun -U)."""
        subprocess.run(["halrun", "-U"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       env=self.env)
        self.halted = False

    def __exit__(self, *exc):
        for so in self.installed:
            if os.path.exists(so):
                os.remove(so)
        if self.halted:
            self.unload()
        shutil.rmtree(self.fifo, ignore_errors=True)
        fcntl.flock(self.lock, fcntl.LOCK_UN)
        return False


def driver_line(program, results):
    """The .hal line that runs hal_driver.py with a program (a JSON file) and waits for it."""
    return "loadusr -Wn weilgen_driver /usr/bin/python3 %s %s %s" % (DRIVER, program, results)


def driver_readings(results):
    """What hal_driver.py recorded (one JSON object per line): label -> values; {} when the
    driver wrote nothing."""
    readings = {}
    if os.path.exists(results):
        with open(results) as f:
            for line in f:
                r = json.loads(line)
                readings[r["label"]] = r["values"]
    return readings
