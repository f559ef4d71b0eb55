"""The PEP 517 build backend of `pip install .` (pyproject.toml; docs/python.md, 'Installing
with pip'): the same CMake build as `cmake -S . -B build`, its Python package packed as a wheel.
It needs nothing from PyPI (Debian's cmake, compiler, pybind11-dev and numpy; no network) and
writes nothing into the source tree: the build directory is a temporary one, or the one given by

    pip install . --config-settings build-dir=/path/to/build   (kept; reused when configured)

and the CMake options come from --config-settings cmake-args="-DFOO=1 -DBAR=2" or the
environment variable WEILGEN_CMAKE_ARGS."""
import base64
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import zipfile

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
NAME = "weilgen"
SUMMARY = "Machine-tool error models: generation, sensitivity, reliability, ISO 230-2, " \
          "identification and gap diagnosis"


def _version():
    with open(os.path.join(SOURCE, "CMakeLists.txt"), encoding="utf-8") as f:
        return re.search(r"project\(weilgen VERSION ([0-9.]+)", f.read()).group(1)


def _tag():
    """cp311-cp311-linux_x86_64: the interpreter running the build is the module's."""
    py = "cp%d%d" % sys.version_info[:2]
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return "%s-%s-%s" % (py, py, platform)


def _metadata():
    return ("Metadata-Version: 2.1\nName: %s\nVersion: %s\nSummary: %s\nRequires-Python: >=3.9\n"
            "Requires-Dist: numpy\nLicense: see the source tree\n" % (NAME, _version(), SUMMARY))


def _dist_info(directory):
    info = os.path.join(directory, "%s-%s.dist-info" % (NAME, _version()))
    os.makedirs(info, exist_ok=True)
    files = {
        "METADATA": _metadata(),
        "WHEEL": "Wheel-Version: 1.0\nGenerator: weilgen_build\nRoot-Is-Purelib: false\n"
                 "Tag: %s\n" % _tag(),
        "top_level.txt": NAME + "\n",
    }
    for name, text in files.items():
        with open(os.path.join(info, name), "w", encoding="utf-8") as f:
            f.write(text)
    return os.path.basename(info)


def _run(cmd):
    print("weilgen_build:", " ".join(shlex.quote(c) for c in cmd), flush=True)
    subprocess.run(cmd, check=True)


def _setting(config_settings, key, env=None):
    value = (config_settings or {}).get(key)
    if value is None and env:
        value = os.environ.get(env)
    return value


def _build_package(build_dir, config_settings, staging):
    """Configures (unless build_dir already is a configured build), builds the Python package's
    target and installs its component into staging/wheel/weilgen."""
    if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
        args = ["-DCMAKE_BUILD_TYPE=Release", "-DWEILGEN_BUILD_TESTS=OFF",
                "-DWEILGEN_BUILD_BENCH=OFF", "-DWEILGEN_BUILD_PYTHON=ON",
                "-DPython3_EXECUTABLE=" + sys.executable]
        if shutil.which("ccache"):
            args += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
        args += shlex.split(_setting(config_settings, "cmake-args", "WEILGEN_CMAKE_ARGS") or "")
        _run(["cmake", "-S", SOURCE, "-B", build_dir] + args)
    jobs = _setting(config_settings, "jobs", "CMAKE_BUILD_PARALLEL_LEVEL") or \
        str(os.cpu_count() or 1)
    _run(["cmake", "--build", build_dir, "--target", "weilgen_python", "-j", jobs])
    # The package alone (component python), at a known place under the staging prefix.
    _run(["cmake", "--install", build_dir, "--prefix", staging, "--component", "python"])
    return os.path.join(staging, "lib", "weilgen_wheel", NAME)


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return "%s,sha256=%s,%d" % (path, digest, len(data))


# ---- PEP 517 hooks ---------------------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return _dist_info(metadata_directory)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    given = _setting(config_settings, "build-dir", "WEILGEN_WHEEL_BUILD_DIR")
    temporary = tempfile.mkdtemp(prefix="weilgen-wheel-")
    try:
        build_dir = os.path.abspath(given) if given else os.path.join(temporary, "build")
        package = _build_package(build_dir, config_settings, os.path.join(temporary, "staging"))
        info = _dist_info(os.path.join(temporary, "meta"))
        wheel = "%s-%s-%s.whl" % (NAME, _version(), _tag())
        records = []
        with zipfile.ZipFile(os.path.join(wheel_directory, wheel), "w",
                             zipfile.ZIP_DEFLATED) as z:
            entries = []
            for root, _, files in os.walk(package):
                for name in files:
                    full = os.path.join(root, name)
                    entries.append((os.path.join(NAME, os.path.relpath(full, package)), full))
            meta = os.path.join(temporary, "meta", info)
            for name in sorted(os.listdir(meta)):
                entries.append((info + "/" + name, os.path.join(meta, name)))
            for arc, full in sorted(entries):
                with open(full, "rb") as f:
                    data = f.read()
                z.writestr(arc, data)
                records.append(_record_line(arc, data))
            records.append(info + "/RECORD,,")
            z.writestr(info + "/RECORD", "\n".join(records) + "\n")
        return wheel
    finally:
        shutil.rmtree(temporary, ignore_errors=True)


def build_sdist(sdist_directory, config_settings=None):
    """The tracked files of the source tree (git ls-files) as NAME-VERSION.tar.gz."""
    files = subprocess.run(["git", "-C", SOURCE, "ls-files", "-z"], check=True,
                           capture_output=True).stdout.decode().split("\0")
    base = "%s-%s" % (NAME, _version())
    path = os.path.join(sdist_directory, base + ".tar.gz")
    with tarfile.open(path, "w:gz") as tar:
        for f in filter(None, files):
            if os.path.exists(os.path.join(SOURCE, f)):
                tar.add(os.path.join(SOURCE, f), arcname=base + "/" + f, recursive=False)
        info = tarfile.TarInfo(base + "/PKG-INFO")
        data = _metadata().encode()
        info.size = len(data)
        import io
        tar.addfile(info, io.BytesIO(data))
    return os.path.basename(path)
