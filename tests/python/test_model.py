"""weilgen.Model against the generated C++ headers (to 1e-12 of each output's
largest value, bit for bit without FP contraction; through a program that includes them and
nothing else) and against Wang & Yuan 2021's closed form of the gantry grinder."""
import glob
import os
import subprocess

import numpy as np
import pytest

import weilgen
from conftest import REFERENCE, source

# Random poses over +-1500 mm and a full turn, beyond most travels: bit-for-bit comparisons with
# the headers, not the travel warning (test_inputs.py).
pytestmark = pytest.mark.filterwarnings("ignore::weilgen.Warning")

MACHINES = sorted(os.path.splitext(os.path.basename(p))[0]
                  for p in glob.glob(source("machines", "*.yaml")))


def header(machine):
    """The header's names and units (reference_model MACHINE names)."""
    out = subprocess.run([REFERENCE, machine, "names"], capture_output=True, text=True,
                         check=True).stdout
    return {line.split()[0]: line.split()[1:] for line in out.splitlines()}


def reference(machine, axes, errors, params, tmp_path):
    """Deviation and coefficients straight from the generated header."""
    n = axes.shape[0]
    files = [tmp_path / f for f in ("a.bin", "e.bin", "p.bin", "d.bin", "c.bin")]
    axes.astype(np.float64).tofile(files[0])
    errors.astype(np.float64).tofile(files[1])
    np.asarray(params, dtype=np.float64).tofile(files[2])
    subprocess.run([REFERENCE, machine, "eval", str(n), *map(str, files)], check=True)
    dev = np.fromfile(files[3]).reshape(n, 6)
    coeff = np.fromfile(files[4]).reshape(n, 6, errors.shape[1])
    return dev, coeff


def poses(model, n, rng):
    """n poses inside the axis ranges (rotary axes over a full turn), in .axis_units."""
    cols = []
    for unit in model.axis_units:
        cols.append(rng.uniform(-360, 360, n) if unit == "deg" else rng.uniform(-1500, 1500, n))
    return np.column_stack(cols)


def errors(model, n, rng):
    scale = np.array([1e-5 if u == "rad" else 1e-2 for u in model.error_units])
    return rng.standard_normal((n, len(model.errors))) * scale


def same_values(got, want):
    """True when `got` equals `want` up to floating-point contraction: the module evaluates the
    header through the batch ABI, the reference calls it directly; compiled with -ffp-contract=fast
    or -march=native the compiler fuses a*b + c differently in the two inlining contexts (half an
    ulp per operation, a few hundred operations, cancellation in small outputs), so the bound is
    1e-12 of the largest magnitude of the output column. Without contraction the two are
    identical bit for bit (scripts/test_fp_variants.sh runs both)."""
    got, want = np.asarray(got), np.asarray(want)
    if got.shape != want.shape:
        return False
    scale = np.abs(want).max(axis=0, keepdims=True) if want.ndim > 1 else np.abs(want).max()
    return bool(np.all(np.abs(got - want) <= 1e-12 * scale))


def test_shipped_machines_are_listed():
    assert {"gantry_grinder", "vmc_3axis", "five_axis_ac"} <= set(MACHINES)


@pytest.mark.parametrize("machine", MACHINES)
def test_names_and_units_are_the_headers(machine):
    m = weilgen.Model(machine)
    h = header(machine)
    assert m.name == machine and m.engine == "built-in" and m.order == 1
    assert m.axes == h["axes"] and m.axis_units == h["axis_units"]
    assert m.errors == h["errors"] and m.error_units == h["error_units"]
    assert m.params == h.get("params", []) and m.param_units == h.get("param_units", [])
    assert m.outputs == h["outputs"] == ["dx", "dy", "dz", "da", "db", "dc"]
    assert m.output_units == h["output_units"]
    assert m.info["machine"] == machine and m.info["engine"] == "built-in"


@pytest.mark.parametrize("machine", MACHINES)
def test_deviation_of_1e5_poses_is_the_headers(machine, tmp_path):
    m = weilgen.Model(machine)
    rng = np.random.default_rng(20240611)
    n = 100_000
    q, e = poses(m, n, rng), errors(m, n, rng)
    dev, coeff = reference(machine, q, e, m.param_values, tmp_path)
    got = m.deviation(q, e)
    assert got.shape == (n, 6) and got.dtype == np.float64
    assert same_values(got, dev)
    got_c = m.coefficients(q[:2000])
    assert got_c.shape == (2000, 6, len(m.errors))
    assert same_values(got_c, coeff[:2000])
    if m.params:  # other parameter values: by name or in .params order
        p = m.param_values + 37.25
        dev_p, coeff_p = reference(machine, q[:5000], e[:5000], p, tmp_path)
        assert same_values(m.deviation(q[:5000], e[:5000], params=p), dev_p)
        named = dict(zip(m.params, p))
        assert same_values(m.deviation(q[:5000], e[:5000], params=named), dev_p)
        assert same_values(m.coefficients(q[:5000], params=p), coeff_p)
        opened = weilgen.Model(machine, param={k: float(v) for k, v in named.items()})
        assert same_values(opened.deviation(q[:5000], e[:5000]), dev_p)


def test_one_row_and_broadcasting():
    m = weilgen.Model("vmc_3axis")
    rng = np.random.default_rng(1)
    q, e = poses(m, 50, rng), errors(m, 50, rng)
    full = m.deviation(q, e)
    assert m.deviation(q[3], e[3]).shape == (6,)
    assert np.array_equal(m.deviation(q[3], e[3]), full[3])
    assert np.array_equal(m.deviation(q[3].tolist(), list(e[3])), full[3])  # lists work too
    assert np.array_equal(m.deviation(q, e[7])[7], full[7])  # one error set at every pose
    assert np.array_equal(m.deviation(q[7], e)[7], full[7])  # one pose, many error sets
    assert m.coefficients(q[0]).shape == (6, len(m.errors))
    assert m.deviation(np.zeros((0, 3)), e[0]).shape == (0, 6)
    # Non-contiguous and integer input is converted.
    assert np.array_equal(m.deviation(np.asfortranarray(q), e), full)


def test_gantry_grinder_coefficients_are_the_seeds_closed_form():
    """Eqs. (16)-(18) of the reliability seed (tool_length 0), with the two corrections pinned
    in tests/test_paper_models.cpp: dx gains -y E_CZ (eq. (17) has it, (18) drops it) and dc
    gains -E_C0X (eq. (15))."""
    m = weilgen.Model("gantry_grinder")
    assert m.axes == ["X", "Z", "Y"] and list(m.param_values) == [0.0]
    rng = np.random.default_rng(5)
    q = np.column_stack([rng.uniform(0, 1000, 200), rng.uniform(600, 1400, 200),
                         rng.uniform(-1500, 1500, 200)])
    x, z, y = q[:, 0], q[:, 1], q[:, 2]
    one = np.ones_like(x)
    seed = {
        0: {"E_XX": -one, "E_BX": -z, "E_CX": y, "E_XZ": one, "E_XY": one, "E_C0X": y,
            "E_CZ": -y},
        1: {"E_YX": -one, "E_AX": z, "E_CX": x, "E_YZ": one, "E_YY": one, "E_C0X": x},
        2: {"E_ZX": -one, "E_AX": -y, "E_BX": -x, "E_ZZ": one, "E_AZ": y, "E_ZY": one,
            "E_A0Z": y},
        3: {"E_AX": -one, "E_AZ": one, "E_A0Z": one, "E_AY": one},
        4: {"E_BX": -one, "E_BZ": one, "E_B0Z": one, "E_BY": one},
        5: {"E_CX": -one, "E_CZ": one, "E_CY": one, "E_C0X": -one},
    }
    want = np.zeros((200, 6, len(m.errors)))
    for o, terms in seed.items():
        for name, value in terms.items():
            want[:, o, m.errors.index(name)] = value
    got = m.coefficients(q)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * 1500)
    # At order 1 the deviation is the coefficients times the errors.
    e = errors(m, 200, rng)
    np.testing.assert_allclose(m.deviation(q, e), np.einsum("nok,nk->no", want, e), rtol=1e-12,
                               atol=1e-15)


def test_numeric_engine_agrees_with_the_generated_model():
    built = weilgen.Model("five_axis_ac")
    chain = weilgen.Model("five_axis_ac", engine="numeric", quiet=True)
    assert chain.engine == "numeric chain"
    rng = np.random.default_rng(3)
    q = poses(built, 300, rng)
    e = errors(built, 300, rng) * 1e-2  # 0.1 um, 0.1 urad: second-order terms about 1e-9 mm
    np.testing.assert_allclose(chain.deviation(q, e), built.deviation(q, e), rtol=0, atol=1e-8)
    # The difference is the order-1 model's truncation: 10x smaller errors, 100x smaller.
    gap = np.abs(chain.deviation(q, e) - built.deviation(q, e)).max()
    gap10 = np.abs(chain.deviation(q, e / 10) - built.deviation(q, e / 10)).max()
    assert 50 < gap / gap10 < 200, (gap, gap10)
    np.testing.assert_allclose(chain.coefficients(q[:20]), built.coefficients(q[:20]), rtol=1e-7,
                               atol=1e-9)


def test_bad_shapes_and_values_raise_with_a_clear_message():
    m = weilgen.Model("gantry_grinder")
    with pytest.raises(weilgen.ArgumentError) as e:
        m.deviation(np.zeros((5, 2)), np.zeros(21))
    assert str(e.value) == ("deviation: axes must have shape (3,) or (N, 3) — X, Z, Y in mm or "
                            "deg — not (5, 2)")
    with pytest.raises(weilgen.ArgumentError, match=r"errors must have shape \(21,\) or \(N, 21\)"):
        m.deviation(np.zeros(3), np.zeros((4, 20)))
    with pytest.raises(weilgen.ArgumentError, match="axes has 4 rows but errors has 5"):
        m.deviation(np.zeros((4, 3)), np.zeros((5, 21)))
    with pytest.raises(weilgen.ArgumentError, match="must be an array of numbers"):
        m.deviation(["a", "b", "c"], np.zeros(21))
    with pytest.raises(weilgen.ArgumentError, match=r"unknown parameter \"tool\" \(machine "
                                                    r"gantry_grinder has tool_length\)"):
        m.deviation(np.zeros(3), np.zeros(21), params={"tool": 1})
    with pytest.raises(weilgen.ArgumentError, match="one set of parameters"):
        m.coefficients(np.zeros(3), params=np.zeros((2, 1)))
    with pytest.raises(ValueError):  # ArgumentError is a ValueError
        m.coefficients(np.zeros((2, 2, 3)))
