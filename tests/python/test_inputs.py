"""weilgen.Model's inputs by name, their checks and pickling (issue 30, rows 3, 4 and 7)."""
import multiprocessing
import pickle
import warnings

import numpy as np
import pytest

import weilgen


@pytest.fixture(scope="module")
def vmc():
    return weilgen.Model("vmc_3axis")


def test_axes_and_errors_by_name_equal_the_columns(vmc):
    assert vmc.axes == ["Y", "X", "Z"]  # machine-specific order: names avoid it
    rng = np.random.default_rng(5)
    q = np.column_stack([rng.uniform(lo, hi, 50) for lo, hi in vmc.axis_ranges])
    e = rng.standard_normal((50, len(vmc.errors))) * 1e-3
    want = vmc.deviation(q, e)
    by_name = {name: q[:, k] for k, name in enumerate(vmc.axes)}
    errors = {name: e[:, k] for k, name in enumerate(vmc.errors)}
    np.testing.assert_array_equal(vmc.deviation(by_name, errors), want)
    # A numpy structured array, columns in any order.
    rec = np.zeros(50, dtype=[("Z", float), ("X", float), ("Y", float)])
    for name in ("X", "Y", "Z"):
        rec[name] = by_name[name]
    np.testing.assert_array_equal(vmc.deviation(rec, e), want)
    np.testing.assert_array_equal(vmc.coefficients(rec), vmc.coefficients(q))
    # Errors not named are zero; a number is used for every row.
    one = vmc.deviation({"X": 100, "Y": -200, "Z": -300}, {"E_XX": 0.005})
    np.testing.assert_array_equal(
        one, vmc.deviation(np.array([-200, 100, -300]),
                           np.eye(len(vmc.errors))[vmc.errors.index("E_XX")] * 0.005))
    assert one.shape == (6,)
    grid = vmc.deviation({"X": np.linspace(0, 500, 7), "Y": -100, "Z": -50}, {"E_XX": 0.001})
    assert grid.shape == (7, 6)


def test_a_pandas_dataframe_by_name(vmc):
    pandas = pytest.importorskip("pandas")
    frame = pandas.DataFrame({"X": [0.0, 250.0], "Z": [-100.0, -200.0], "Y": [-50.0, -10.0]})
    errors = pandas.DataFrame({"E_XX": [0.001, 0.002], "E_CX": [1e-5, 0.0]})
    want = vmc.deviation(frame[vmc.axes].to_numpy(),
                         errors.reindex(columns=vmc.errors, fill_value=0.0).to_numpy())
    np.testing.assert_array_equal(vmc.deviation(frame, errors), want)


def test_names_that_are_not_the_machines_are_refused(vmc):
    with pytest.raises(weilgen.ArgumentError, match=r"deviation: axes: no column 'Z' \(the axes of "
                                                    r"vmc_3axis: Y, X, Z\)"):
        vmc.deviation({"X": 0, "Y": 0}, np.zeros(21))
    with pytest.raises(weilgen.ArgumentError, match=r"deviation: errors: unknown name 'E_QQ'"):
        vmc.deviation({"X": 0, "Y": 0, "Z": 0}, {"E_QQ": 1})


def test_outside_the_travel_is_a_warning(vmc):
    assert vmc.axis_ranges[0] == (-400.0, 0.0)  # Y
    with pytest.warns(weilgen.Warning, match=r"deviation: axes row 1: Y = 100 mm is outside the "
                                             r"axis range \[-400, 0\] mm \(1 of 2 rows outside\)"):
        vmc.deviation({"X": [0, 0], "Y": [-100, 100], "Z": [0, 0]}, np.zeros(21))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vmc.deviation({"X": 0, "Y": -100, "Z": 0}, np.zeros(21))  # inside: no warning
        vmc.deviation({"X": 0, "Y": 100, "Z": 0}, np.zeros(21), check=False)
    assert issubclass(weilgen.Warning, UserWarning)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, None])
def test_nan_inf_and_none_name_row_and_column(vmc, bad):
    axes = [[-100.0, 0.0, 0.0], [-100.0, 0.0, 0.0], [-100.0, 50.0, bad]]
    with pytest.raises(ValueError, match=r"deviation: axes row 2, column Z \(mm\): .* is not a "
                                         r"finite number") as e:
        vmc.deviation(axes, np.zeros(21))
    assert isinstance(e.value, weilgen.ArgumentError)
    errors = np.zeros((3, 21), dtype=object)
    errors[1, 4] = bad
    with pytest.raises(ValueError, match=r"deviation: errors row 1, column E_BY \(rad\)"):
        vmc.deviation(np.array(axes[:2] * 2)[:3] * 0 - 10, errors)
    with pytest.raises(ValueError, match=r"coefficients: axes row 0, column X \(mm\)"):
        vmc.coefficients({"X": [bad], "Y": [-1], "Z": [0]})
    with pytest.raises(ValueError, match=r"deviation: params: tool_length is nan"):
        vmc.deviation(np.zeros(3) - 1, np.zeros(21), params={"tool_length": float("nan")})
    # check=False: no check, the value goes through (hot loops).
    out = vmc.deviation(np.array(axes, dtype=float), np.zeros(21), check=False)
    assert np.isfinite(out[:2]).all()


def test_a_model_pickles_by_how_it_was_opened(tmp_path):
    m = weilgen.Model("gantry_grinder", param={"tool_length": 150}, quiet=True)
    copy = pickle.loads(pickle.dumps(m))
    assert type(copy) is weilgen.Model and copy.name == m.name and copy.order == m.order
    np.testing.assert_array_equal(copy.param_values, m.param_values)
    q = np.array([[500.0, 1000.0, 750.0]])
    e = np.full(21, 1e-3)
    np.testing.assert_array_equal(copy.deviation(q, e), m.deviation(q, e))
    numeric = weilgen.Model("two_axis", engine="numeric", quiet=True)
    assert pickle.loads(pickle.dumps(numeric)).engine == "numeric chain"


def _dx(args):
    model, y = args
    return float(model.deviation({"X": 500, "Z": 1000, "Y": y}, np.full(21, 1e-3))[0])


def test_multiprocessing_workers_get_the_model():
    m = weilgen.Model("gantry_grinder")
    ys = [-1500.0, 0.0, 1500.0]
    with multiprocessing.get_context("spawn").Pool(2) as pool:  # a fresh interpreter: real pickling
        got = pool.map(_dx, [(m, y) for y in ys])
    assert got == [_dx((m, y)) for y in ys]
