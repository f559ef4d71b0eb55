"""weilgen.to_frame for every document (issue 30, row 9): a pandas DataFrame when pandas is
installed, else a dict of numpy columns with the same names and values; per-error entries in
Model.errors order."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import weilgen
from conftest import source

POINTS = source("examples", "data", "vmc_3axis_points.csv")
DOCS = {
    "sensitivity": lambda: weilgen.sensitivity("vmc_3axis", grid="X=0:400:2,Y=-200,Z=-100",
                                               samples=256, quiet=True),
    "reliability": lambda: weilgen.reliability("vmc_3axis", grid="X=0:400:3,Y=-200,Z=-100",
                                               tolerance="dx=0.03mm,dy=0.03mm", quiet=True),
    "allocate": lambda: weilgen.allocate("gantry_grinder", grid="X=0,Y=-1500:1500:3,Z=600:1400:3",
                                         tolerance="dx=0.03mm", limit="one-sided", quiet=True),
    "iso230-2": lambda: weilgen.iso230_2(source("examples", "data", "iso230_2_drift.csv")),
    "fit-pdge": lambda: weilgen.fit_pdge(source("examples", "data", "line6d_x.csv")),
    "identify": lambda: weilgen.identify("vmc_3axis", data=POINTS, quiet=True),
    "gap": lambda: weilgen.gap("vmc_3axis", data=POINTS, quiet=True),
}


@pytest.fixture(scope="module")
def docs():
    return {verb: make() for verb, make in DOCS.items()}


def rows(frame):
    return len(frame) if hasattr(frame, "iloc") else len(next(iter(frame.values())))


def column(frame, name):
    return frame[name].to_numpy() if hasattr(frame, "iloc") else frame[name]


def test_every_document_has_a_table(docs):
    pytest.importorskip("pandas")
    import pandas
    expected_rows = {
        "sensitivity": lambda d: len(d["results"]),
        "reliability": lambda d: len(d["results"]),
        "allocate": lambda d: len(d["steps"]),
        "iso230-2": lambda d: len(d["positions_mm"]),
        "fit-pdge": lambda d: sum(len(p["fits"]) for p in d["profiles"]),
        "identify": lambda d: len(d["parameters"]),
        "gap": lambda d: len(d["effects"]),
    }
    for verb, doc in docs.items():
        frame = weilgen.to_frame(doc)
        assert isinstance(frame, pandas.DataFrame), verb
        assert rows(frame) == expected_rows[verb](doc) > 0, verb


def test_columns_carry_the_documents_values(docs):
    s = weilgen.to_frame(docs["sensitivity"])
    r0 = docs["sensitivity"]["results"][0]
    assert list(s.columns[:5]) == ["X", "Y", "Z", "output", "error"]  # the pose first
    assert s["ST_ci_lo"].iloc[0] == r0["ST_ci"][0] and s["ST_ci_hi"].iloc[0] == r0["ST_ci"][1]
    assert s["X"].tolist() == [r["pose"]["X"] for r in docs["sensitivity"]["results"]]
    rel = weilgen.to_frame(docs["reliability"])
    errors = weilgen.Model("vmc_3axis").errors
    assert [c[len("dR_dmu."):] for c in rel.columns if c.startswith("dR_dmu.")] == errors
    assert rel["reliability"].tolist() == [r["reliability"] for r in docs["reliability"]["results"]]
    iso = weilgen.to_frame(docs["iso230-2"])
    np.testing.assert_array_equal(iso["target_mm"], docs["iso230-2"]["positions_mm"])
    np.testing.assert_array_equal(iso["drift_eliminated.mean_up_um"],
                                  docs["iso230-2"]["drift_eliminated"]["mean_up_um"])
    drift = weilgen.to_frame(docs["iso230-2"], "drift_per_cycle")
    np.testing.assert_array_equal(drift["time_h"], docs["iso230-2"]["drift_per_cycle"]["time_h"])
    summary = weilgen.to_frame(docs["reliability"], "summary")
    assert summary["min"].tolist() == [x["min"] for x in docs["reliability"]["summary"]]
    with pytest.raises(KeyError, match="no table 'nonsense'"):
        weilgen.to_frame(docs["gap"], "nonsense")


def test_per_error_entries_are_in_the_models_order(docs):
    errors = weilgen.Model("vmc_3axis").errors
    for r in docs["reliability"]["results"]:
        assert list(r["dR_dmu"]) == errors and list(r["dR_dsigma"]) == errors
    assert list(docs["reliability"]["derivative_units"]) == errors
    grinder = weilgen.Model("gantry_grinder").errors
    for step in docs["allocate"]["steps"]:
        assert list(step["stddev"]) == [e for e in grinder if e in step["stddev"]]


def test_without_pandas_the_columns_are_numpy(tmp_path):
    """A child interpreter where `import pandas` fails: a dict of numpy columns, the same names
    and values as the DataFrame's."""
    doc = weilgen.reliability("vmc_3axis", grid="X=0:400:3,Y=-200,Z=-100", tolerance="dx=0.03mm",
                              quiet=True)
    path = tmp_path / "doc.json"
    path.write_text(json.dumps(weilgen.plain(doc)))
    script = ("import sys, json; sys.modules['pandas'] = None\n"
              "import weilgen, numpy as np\n"
              f"f = weilgen.to_frame(json.load(open({str(path)!r})))\n"
              "assert isinstance(f, dict), type(f)\n"
              "assert all(isinstance(v, np.ndarray) for v in f.values())\n"
              "print(json.dumps({k: v.tolist() for k, v in f.items()}))\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=os.environ.copy())
    assert out.returncode == 0, out.stderr
    columns = json.loads(out.stdout)
    assert columns["reliability"] == [r["reliability"] for r in doc["results"]]
    assert columns["X"] == [0.0, 200.0, 400.0] and columns["output"] == ["dx"] * 3
    try:
        import pandas  # noqa: F401
    except ImportError:
        return
    frame = weilgen.to_frame(doc)
    assert list(frame.columns) == list(columns)
