"""`cmake --install` puts the module where the interpreter finds it under the prefix, and the
installed module works outside the build tree."""
import os
import subprocess
import sys


def test_installed_module_imports_and_opens_a_machine(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run([os.environ["WEILGEN_CMAKE"], "--install", os.environ["WEILGEN_BUILD_DIR"],
                    "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / os.environ["WEILGEN_PYTHON_INSTALL_DIR"]
    package = site / "weilgen"
    assert any(p.name.startswith("_weilgen.") and p.suffix == ".so" for p in package.iterdir())
    for name in ("__init__.py", "__init__.pyi", "py.typed", "_flags.json", "_verbs.py"):
        assert (package / name).is_file(), name
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "WEILGEN_MACHINES_DIR")}
    env["PYTHONPATH"] = str(site)
    script = ("import weilgen, numpy as np; print(weilgen.__file__); "
              "m = weilgen.Model('vmc_3axis'); print(m.deviation(np.zeros(3), np.zeros(21))[0])")
    r = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True,
                       text=True, check=True)
    assert r.stdout.splitlines()[0].startswith(str(site))
    assert float(r.stdout.splitlines()[1]) == 0.0
    assert (prefix / "share" / "weilgen" / "machines" / "vmc_3axis.yaml").exists()
