"""`pip install .` from the source tree (issue 30, row 11): the in-tree PEP 517 backend
(src/python/pep517/weilgen_build.py) builds the package with the project's CMake and installs a
wheel, offline (--no-index), into a virtual environment over Debian's packages, without writing
into the source tree. The test reuses the CTest build directory (--config-settings build-dir=),
so it packs what CMake built; WEILGEN_TEST_PIP_FULL=1 also runs the full build in a temporary
directory, as a user's `pip install .` does."""
import os
import subprocess
import sys

import pytest

import weilgen

SOURCE = os.environ["WEILGEN_SOURCE_DIR"]


def tree(root):
    """The source tree's files (without build directories and .git), with their sizes."""
    out = {}
    for d, dirs, files in os.walk(root):
        dirs[:] = [x for x in dirs if not (x.startswith("build") or x == ".git")]
        for f in files:
            p = os.path.join(d, f)
            out[os.path.relpath(p, root)] = os.path.getsize(p)
    return out


def pip_install(tmp_path, *settings):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    before = tree(SOURCE)
    r = subprocess.run([str(venv / "bin" / "pip"), "install", "--no-index", "--no-cache-dir",
                        *settings, SOURCE], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert tree(SOURCE) == before, "pip install . wrote into the source tree"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "WEILGEN_MACHINES_DIR")}
    script = ("import inspect, weilgen, numpy as np\n"
              "print(weilgen.__file__)\n"
              "m = weilgen.Model('gantry_grinder')\n"
              "print(m.source)\n"
              "print(m.deviation({'X': 500, 'Z': 1000, 'Y': 750}, {'E_XX': 0.005})[0])\n"
              "print(inspect.signature(weilgen.iso230_2).parameters['alpha'].default)\n")
    return subprocess.run([str(venv / "bin" / "python"), "-c", script], cwd=tmp_path, env=env,
                          capture_output=True, text=True, check=True).stdout.splitlines()


def test_pip_install_packs_the_cmake_build(tmp_path):
    lines = pip_install(tmp_path, "--config-settings",
                        "build-dir=" + os.environ["WEILGEN_BUILD_DIR"])
    site = str(tmp_path / "venv" / "lib")
    assert lines[0].startswith(site) and lines[0].endswith("weilgen/__init__.py")
    assert lines[1].startswith(site) and lines[1].endswith("weilgen/machines/gantry_grinder.yaml")
    # The same number as the build tree's package.
    want = weilgen.Model("gantry_grinder").deviation({"X": 500, "Z": 1000, "Y": 750},
                                                     {"E_XX": 0.005})[0]
    assert float(lines[2]) == want
    assert lines[3] == "0.01"


@pytest.mark.skipif(os.environ.get("WEILGEN_TEST_PIP_FULL") != "1",
                    reason="the full build takes minutes: WEILGEN_TEST_PIP_FULL=1 runs it")
def test_pip_install_builds_from_scratch(tmp_path):
    lines = pip_install(tmp_path)
    assert float(lines[2]) == pytest.approx(weilgen.Model("gantry_grinder").deviation(
        {"X": 500, "Z": 1000, "Y": 750}, {"E_XX": 0.005})[0], rel=1e-12)
