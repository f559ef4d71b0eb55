"""weilgen.machines() is `weilgen list`, Model.closed_form() is `weilgen show` (issue 30, row 6),
and the sympy-string form evaluated numerically is the model's deviation."""
import math
import re
import subprocess

import numpy as np
import pytest

import weilgen
from conftest import BINARY


def show(*args):
    return subprocess.run([BINARY, "show", *args], check=True, capture_output=True,
                          text=True).stdout


def test_machines_are_weilgen_list():
    listed = subprocess.run([BINARY, "list"], check=True, capture_output=True, text=True).stdout
    names = [line.split()[0] for line in listed.splitlines()]
    got = weilgen.machines()
    assert [m["name"] for m in got] == names
    for m, line in zip(got, listed.splitlines()):
        assert f"{m['errors']} errors, order {m['order']}" in line
        assert line.endswith(m["title"])
        model = weilgen.Model(m["name"])
        assert model.axes == m["axes"] and model.axis_units == m["axis_units"]
        assert model.source == m["file"]


@pytest.mark.parametrize("machine", ["vmc_3axis", "five_axis_ac", "two_axis"])
def test_closed_form_is_weilgen_show(machine):
    m = weilgen.Model(machine)
    assert m.closed_form() == show(machine)
    assert m.closed_form("dy", format="latex") == show(machine, "--output", "dy", "--format",
                                                         "latex")
    assert m.closed_form(notation="alias") == show(machine, "--notation", "alias")
    assert m.closed_form("dc", format="sympy-string") == show(machine, "--output", "dc",
                                                              "--format", "sympy")
    doc = m.closed_form(format="json")
    assert doc["verb"] == "show" and set(doc["outputs"]) == set(m.outputs)


def test_closed_form_at_another_order_is_the_cli_order():
    m = weilgen.Model("two_axis", order=2, quiet=True)
    assert m.closed_form("dz") == show("two_axis", "--order", "2", "--output", "dz")


def test_bad_closed_form_arguments():
    m = weilgen.Model("two_axis")
    with pytest.raises(weilgen.ArgumentError, match="unknown output 'dq'"):
        m.closed_form("dq")
    with pytest.raises(weilgen.ArgumentError, match="format must be"):
        m.closed_form(format="mathml")
    with pytest.raises(weilgen.ArgumentError, match="notation must be"):
        m.closed_form(notation="greek")


@pytest.mark.parametrize("machine", ["vmc_3axis", "five_axis_ac"])
def test_sympy_string_evaluates_to_the_deviation(machine):
    """Each right-hand side, read as Python with the errors, lower-case coordinates (angles in
    rad) and parameters bound, equals Model.deviation at order 1 (an independent path: the
    printed closed form against the generated code)."""
    m = weilgen.Model(machine)
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = np.array([rng.uniform(lo, hi) for lo, hi in m.axis_ranges])
        e = rng.standard_normal(len(m.errors)) * np.where(np.array(m.error_units) == "rad", 1e-5,
                                                          1e-3)
        names = {"sin": math.sin, "cos": math.cos, "sqrt": math.sqrt}
        names.update(zip(m.errors, e))
        for axis, unit, value in zip(m.axes, m.axis_units, q):
            names[axis.lower()] = math.radians(value) if unit == "deg" else value
        names.update(zip(m.params, m.param_values))
        want = m.deviation(q, e)
        for k, line in enumerate(m.closed_form(format="sympy-string").splitlines()):
            lhs, rhs = line.split(" = ", 1)
            assert lhs == m.outputs[k]
            assert re.fullmatch(r"[\w\s()*+\-/.]+", rhs), rhs[:80]  # Python syntax, no · or ^
            got = eval(rhs, {"__builtins__": {}}, names)  # noqa: S307 (our own closed form)
            assert got == pytest.approx(want[k], rel=1e-12, abs=1e-15), (machine, lhs)
