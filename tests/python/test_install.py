"""`cmake --install` puts the package where the interpreter finds it under the prefix, and the
installed package works outside the build tree and reads its installed machines, not the source
tree's (issue 30, row 10)."""
import os
import subprocess
import sys


def test_installed_module_imports_and_reads_its_installed_data(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run([os.environ["WEILGEN_CMAKE"], "--install", os.environ["WEILGEN_BUILD_DIR"],
                    "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / os.environ["WEILGEN_PYTHON_INSTALL_DIR"]
    package = site / "weilgen"
    assert any(p.name.startswith("_weilgen.") and p.suffix == ".so" for p in package.iterdir())
    for name in ("__init__.py", "__init__.pyi", "py.typed", "_flags.json", "_verbs.py",
                 "machines/vmc_3axis.yaml"):
        assert (package / name).is_file(), name
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "WEILGEN_MACHINES_DIR")}
    env["PYTHONPATH"] = str(site)
    script = ("import weilgen, numpy as np; print(weilgen.__file__); "
              "m = weilgen.Model('vmc_3axis'); print(m.deviation(np.zeros(3) - 1, np.zeros(21))[0]);"
              "print(m.source); print(weilgen.machines()[0]['file'])")
    r = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True,
                       text=True, check=True)
    lines = r.stdout.splitlines()
    assert lines[0].startswith(str(site))
    assert float(lines[1]) == 0.0
    # The source tree's machines/ still exists: the installed package reads its own copy.
    assert os.path.isdir(os.path.join(os.environ["WEILGEN_SOURCE_DIR"], "machines"))
    assert lines[2] == str(package / "machines" / "vmc_3axis.yaml")
    assert lines[3].startswith(str(package / "machines"))
    # The installed CLI: <prefix>/share/weilgen/machines, not the source tree's.
    assert (prefix / "share" / "weilgen" / "machines" / "vmc_3axis.yaml").exists()
    r = subprocess.run([str(prefix / "bin" / "weilgen"), "list", "--help"], env=env,
                       capture_output=True, text=True, check=True)
    assert str(prefix / "share" / "weilgen" / "machines") in r.stdout
