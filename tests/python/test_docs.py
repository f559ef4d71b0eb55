"""docs/python.md's notebook session and the README's Python snippet, run as doctests (issue
30, row 10): every output the documentation shows is what the package gives. They run in a
temporary directory where examples/ is the source tree's, so their files go there."""
import doctest
import os
import re

import pytest

from conftest import source


def pycon_blocks(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"```pycon\n(.*?)```", text, flags=re.S)


def run_doctest(path, tmp_path, monkeypatch):
    blocks = pycon_blocks(path)
    assert blocks, f"{path} has no pycon examples"
    os.symlink(source("examples"), tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    parser = doctest.DocTestParser()
    test = parser.get_doctest("\n".join(blocks), {}, os.path.basename(path), path, 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples of {path} failed"
    assert result.attempted >= len(blocks)


def test_python_md_session(tmp_path, monkeypatch):
    pytest.importorskip("pandas")  # the session shows DataFrames
    run_doctest(source("docs", "python.md"), tmp_path, monkeypatch)


def test_readme_snippet(tmp_path, monkeypatch):
    run_doctest(source("README.md"), tmp_path, monkeypatch)
