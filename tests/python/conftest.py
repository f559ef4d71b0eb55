"""Shared helpers of the Python module's tests: the CLI binary, the source tree, and a comparison
of documents that treats numpy arrays as the lists the CLI writes."""
import json
import os
import subprocess

import pytest

import weilgen

BINARY = os.environ["WEILGEN_BINARY"]
SOURCE = os.environ["WEILGEN_SOURCE_DIR"]
REFERENCE = os.environ["WEILGEN_REFERENCE"]


def source(*parts):
    return os.path.join(SOURCE, *parts)


class Cli:
    """Runs `weilgen` with the same arguments a test gives the module."""

    def __init__(self, tmp_path):
        self.tmp = tmp_path

    def run(self, *args):
        return subprocess.run([BINARY, *args], capture_output=True, text=True, check=False)

    def json(self, *args):
        path = self.tmp / "cli.json"
        if path.exists():
            path.unlink()
        r = self.run(*args, "--json", str(path))
        assert r.returncode in (0, 1), r.stderr
        with open(path, encoding="utf-8") as f:
            return json.load(f)

    def error(self, *args):
        """The CLI's message for bad arguments or input: stderr without 'weilgen <verb>: ' and
        ' (try weilgen <verb> --help)'."""
        r = self.run(*args)
        assert r.returncode in (2, 3), (r.returncode, r.stdout, r.stderr)
        line = r.stderr.strip().splitlines()[-1]
        verb = args[0]
        prefix = f"weilgen {verb}: "
        if line.startswith(prefix):
            line = line[len(prefix):]
        suffix = f" (try weilgen {verb} --help)"
        if line.endswith(suffix):
            line = line[: -len(suffix)]
        return r.returncode, line


@pytest.fixture
def cli(tmp_path):
    return Cli(tmp_path)


def same_document(module_doc, cli_doc, path="", ignore=()):
    """Every key and number equal (bit for bit: the CLI writes round-trip numbers)."""
    a = weilgen.plain(module_doc)
    _compare(a, cli_doc, path or "document", set(ignore))


def _compare(a, b, where, ignore):
    if isinstance(b, dict):
        assert isinstance(a, dict), where
        keys = set(b) - ignore
        assert set(a) - ignore == keys, (where, sorted(set(a) ^ set(b)))
        for k in keys:
            _compare(a[k], b[k], f"{where}.{k}", ignore)
    elif isinstance(b, list):
        assert isinstance(a, list) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _compare(x, y, f"{where}[{i}]", ignore)
    elif isinstance(b, float) or isinstance(a, float):
        assert a == b, (where, a, b)
    else:
        assert a == b and type(a) is type(b), (where, a, b)
