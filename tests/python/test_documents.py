"""Every analysis of the module returns the document the CLI's --json writes, number for number,
on the shipped machines and examples; keywords in the CLI's text or as dicts give the same."""
import json
import os

import weilgen
from conftest import same_document, source

GRID = "X=0,Y=-1500:1500:3,Z=600:1400:3"
GRID_DICT = {"X": 0, "Y": (-1500, 1500, 3), "Z": "600:1400:3"}
POINTS = source("examples", "data", "vmc_3axis_points.csv")
BALLBAR = source("examples", "data", "vmc_3axis_ballbar.csv")


def test_sensitivity_equals_cli(cli):
    want = cli.json("sensitivity", "gantry_grinder", "--grid", GRID, "--samples", "1024",
                    "--bootstrap", "50", "--seed", "7", "--quiet")
    got = weilgen.sensitivity("gantry_grinder", grid=GRID, samples=1024, bootstrap=50, seed=7,
                              quiet=True)
    same_document(got, want)
    # The grid as a dict, and a weilgen.Model instead of the name: the same document.
    model = weilgen.Model("gantry_grinder")
    same_document(weilgen.sensitivity(model, grid=GRID_DICT, samples=1024, bootstrap=50, seed=7),
                  want)
    # Large numeric arrays are numpy arrays; plain() gives the CLI's lists.
    assert got["results"][0]["S_ci"].dtype.kind == "f"


def test_sensitivity_options_equal_cli(cli):
    want = cli.json("sensitivity", "vmc_3axis", "--at", "X=100,Y=-200,Z=-300", "--at",
                    "X=0,Y=0,Z=0", "--method", "sobol", "--outputs", "dx,dp", "--sampling", "mc",
                    "--samples", "512", "--bootstrap", "20", "--confidence", "0.9", "--set",
                    "E_XX=sigma:5um", "--set", "group:angular=sigma:2urad", "--param",
                    "tool_length=120", "--quiet")
    got = weilgen.sensitivity("vmc_3axis", at=[{"X": 100, "Y": -200, "Z": -300}, "X=0,Y=0,Z=0"],
                              method="sobol", outputs=["dx", "dp"], sampling="mc", samples=512,
                              bootstrap=20, confidence=0.9,
                              set={"E_XX": "sigma:5um", "group:angular": "sigma:2urad"},
                              param={"tool_length": 120}, quiet=True)
    same_document(got, want)


def test_reliability_equals_cli(cli):
    want = cli.json("reliability", "gantry_grinder", "--grid", GRID, "--tolerance", "dx=0.03mm",
                    "--limit", "one-sided", "--quiet")
    same_document(weilgen.reliability("gantry_grinder", grid=GRID, tolerance={"dx": "0.03mm"},
                                      limit="one-sided", quiet=True), want)
    # Sampled: importance sampling of the radial limit, same seed, same numbers.
    want = cli.json("reliability", "gantry_grinder", "--grid", GRID, "--tolerance", "dp=0.045mm",
                    "--limit", "radial", "--method", "is", "--samples", "2048", "--seed", "3",
                    "--quiet")
    same_document(weilgen.reliability("gantry_grinder", grid=GRID, tolerance="dp=0.045mm",
                                      limit="radial", method="is", samples=2048, seed=3,
                                      quiet=True), want)


def test_allocate_equals_cli(cli, tmp_path):
    args = ["--grid", "X=0,Y=-1500:1500:5,Z=600:1400:5", "--tolerance", "dx=0.03mm", "--limit",
            "one-sided", "--step", "0.005/6mm", "--step", "0.005/6000rad", "--step",
            "E_C0X=0.005/3000rad", "--rank", "raw", "--cost-aware", "--quiet"]
    want = cli.json("allocate", "gantry_grinder", *args, "--save-tolerances",
                    str(tmp_path / "cli.yaml"))
    got = weilgen.allocate("gantry_grinder", grid="X=0,Y=-1500:1500:5,Z=600:1400:5",
                           tolerance="dx=0.03mm", limit="one-sided",
                           step=["0.005/6mm", "0.005/6000rad", "E_C0X=0.005/3000rad"],
                           rank="raw", cost_aware=True, quiet=True,
                           save_tolerances=tmp_path / "module.yaml")
    same_document(got, want)
    assert got["met"] is True
    assert (tmp_path / "module.yaml").read_text() == (tmp_path / "cli.yaml").read_text()


def test_iso230_2_equals_cli(cli):
    for name in ("iso230_2_drift.csv", "iso230_2_small.csv"):
        data = source("examples", "data", name)
        same_document(weilgen.iso230_2(data), cli.json("iso230-2", data))
    data = source("examples", "data", "iso230_2_drift.csv")
    want = cli.json("iso230-2", data, "--alpha", "0.05", "--reference-cycle", "2")
    same_document(weilgen.iso230_2(data, alpha=0.05, reference_cycle=2), want)


def test_iso230_2_normalise_iso_only_uncertainty_equal_cli(cli, tmp_path):
    data = source("examples", "data", "iso230_2_small.csv")
    budget = tmp_path / "budget.yaml"
    budget.write_text("class: laser-compensated\neve_um: 0.4\nmonte_carlo_trials: 5000\n")
    want = cli.json("iso230-2", data, "--normalise", "never", "--iso-only", "--uncertainty",
                    str(budget))
    doc = weilgen.iso230_2(data, normalise="never", iso_only=True, uncertainty=budget)
    same_document(doc, want)
    assert doc["student"] is None and doc["drift_eliminated"] is None
    assert doc["normalisation"]["mode"] == "never"
    assert doc["uncertainty"]["figures"]["E"]["U_um"] > 0
    # A laser export: its compensation state decides, as on the CLI.
    carto = source("examples", "data", "carto_x.csv")
    doc = weilgen.iso230_2(carto, uncertainty="laser-compensated")
    same_document(doc, cli.json("iso230-2", carto, "--uncertainty", "laser-compensated"))
    assert doc["source_format"] == "carto"
    assert doc["normalisation"]["material"]["instrument_state"] == "none"


def test_ballbar_equals_cli(cli, tmp_path):
    data = source("examples", "data", "ballbar_xy.csv")
    same_document(weilgen.ballbar(data), cli.json("ballbar", data))
    svg, html = tmp_path / "p.svg", tmp_path / "r.html"
    want = cli.json("ballbar", data, "--machine", "vmc_3axis", "--alpha", "0.05", "--feedrate",
                    "300 mm/min")
    doc = weilgen.ballbar(data, machine="vmc_3axis", alpha=0.05, feedrate="300 mm/min", plot=svg,
                          report=html, quiet=True)
    same_document(doc, want)
    assert doc["diagnosis"]["causes"][0]["id"] == "squareness"
    assert svg.read_text().startswith("<svg")
    assert "ISO 230-4" in html.read_text()


def test_fit_pdge_equals_cli(cli):
    data = source("examples", "data", "line6d_x.csv")
    same_document(weilgen.fit_pdge(data), cli.json("fit-pdge", data))
    want = cli.json("fit-pdge", data, "--basis", "fourier:auto,poly:5", "--cv", "blocks",
                    "--folds", "5", "--column", "E_BX", "--column", "E_YX")
    got = weilgen.fit_pdge(data, basis=["fourier:auto", "poly:5"], cv="blocks", folds=5,
                           column=["E_BX", "E_YX"])
    same_document(got, want)


def test_identify_equals_cli(cli, tmp_path):
    want = cli.json("identify", "vmc_3axis", "-q", "--data", POINTS, "--predict", BALLBAR,
                    "--predict", POINTS, "--emit-params", str(tmp_path / "cli.hpp"),
                    "--emit-params-json", str(tmp_path / "cli_params.json"))
    got = weilgen.identify("vmc_3axis", quiet=True, data=POINTS, predict=[BALLBAR, POINTS],
                           emit_params=str(tmp_path / "module.hpp"),
                           emit_params_json=tmp_path / "module.json")
    same_document(got, want)
    assert got["rank"] == 46
    assert (tmp_path / "module.hpp").read_text() == (tmp_path / "cli.hpp").read_text()
    # The parameters a controller loads at run time (docs/controllers.md, params_file).
    assert (tmp_path / "module.json").read_text() == (tmp_path / "cli_params.json").read_text()
    params = json.loads((tmp_path / "module.json").read_text())
    assert params["machine"] == "vmc_3axis" and params["weilgen_params"] == 1
    want = cli.json("identify", "vmc_3axis", "-q", "--data", POINTS, "--pdge", "E_XX=fourier:2",
                    "--fix", "E_C0Y")
    same_document(weilgen.identify("vmc_3axis", quiet=True, data=POINTS,
                                   pdge={"E_XX": "fourier:2"}, fix="E_C0Y"), want)


def test_gap_equals_cli(cli):
    want = cli.json("gap", "vmc_3axis", "-q", "--data", POINTS, "--pdge", "poly:2")
    same_document(weilgen.gap("vmc_3axis", data=POINTS, pdge="poly:2", quiet=True), want)
    want = cli.json("gap", "vmc_3axis", "-q", "--data", BALLBAR)
    same_document(weilgen.gap(weilgen.Model("vmc_3axis"), data=BALLBAR, quiet=True), want)


def test_compensation_tables_equal_cli(cli, tmp_path):
    """--comp-table (docs/controllers.md): the module writes the CLI's LinuxCNC file."""
    data = source("examples", "data", "iso230_2_drift.csv")
    cli.json("iso230-2", data, "--comp-table", str(tmp_path / "cli.tbl"), "--comp-source", "drift")
    weilgen.iso230_2(data, comp_table=tmp_path / "module.tbl", comp_source="drift")
    assert (tmp_path / "module.tbl").read_text() == (tmp_path / "cli.tbl").read_text()
    cli.json("identify", "vmc_3axis", "-q", "--data", POINTS, "--comp-table",
             str(tmp_path / "cli_x.tbl"), "--axis", "X", "--comp-points", "11", "--comp-at",
             "Y=-200,Z=-150", "--comp-type", "1")
    weilgen.identify("vmc_3axis", quiet=True, data=POINTS, comp_table=tmp_path / "module_x.tbl",
                     axis="X", comp_points=11, comp_at={"Y": -200, "Z": -150}, comp_type=1)
    assert (tmp_path / "module_x.tbl").read_text() == (tmp_path / "cli_x.tbl").read_text()


CARTO = source("examples", "data", "carto_x.csv")


def test_iso230_2_every_flag_equals_cli(cli, tmp_path):
    """Issue 30, row 1: the instrument reader (a CARTO export), the normalisation to 20 degC,
    air compensation, tolerances, the HTML report and the CSV, as the CLI's flags."""
    args = ["--expansion", "11.5", "--material-temperature", "T_material_1,T_material_2",
            "--tolerance", "10,A=12,R=6", "--datum", "0", "--format", "carto"]
    want = cli.json("iso230-2", CARTO, *args, "--csv", str(tmp_path / "cli.csv"), "--report",
                    str(tmp_path / "cli.html"))
    got = weilgen.iso230_2(CARTO, expansion=11.5, material_temperature="T_material_1,T_material_2",
                           tolerance="10,A=12,R=6", datum=0, format="carto",
                           csv=tmp_path / "module.csv", report=tmp_path / "module.html")
    same_document(got, want)
    assert got["source_format"] == "carto"
    assert [c["name"] for c in got["tolerance"]["checks"]] == ["band", "A", "R"]
    assert got["normalisation"]["material"]["expansion_ppm_per_K"] == 11.5
    assert (tmp_path / "module.csv").read_text() == (tmp_path / "cli.csv").read_text()
    assert (tmp_path / "module.html").read_text() == (tmp_path / "cli.html").read_text()
    # The air: the index from the recorded air (Edlen) with an assumed index and wavelength, forced
    # over the file's statement that the instrument compensated it.
    air = ["--normalise", "force", "--air-compensation", "edlen", "--air-temperature", "20.5", "--air-pressure",
           "1009.5 hPa", "--air-humidity", "45", "--wavelength", "632.991",
           "--air-index-assumed", "1.00027"]
    want = cli.json("iso230-2", CARTO, *air)
    got = weilgen.iso230_2(CARTO, normalise="force", air_compensation="edlen", air_temperature=20.5,
                           air_pressure="1009.5 hPa", air_humidity=45, wavelength=632.991,
                           air_index_assumed=1.00027)
    same_document(got, want)


def test_csv_and_plot_where_the_cli_has_them(cli, tmp_path):
    """Issue 30, row 2: csv on fit_pdge, identify and gap; plot on identify."""
    line = source("examples", "data", "line6d_x.csv")
    cli.json("fit-pdge", line, "--csv", str(tmp_path / "cli_fit.csv"))
    weilgen.fit_pdge(line, csv=tmp_path / "fit.csv")
    assert (tmp_path / "fit.csv").read_text() == (tmp_path / "cli_fit.csv").read_text()
    cli.json("identify", "vmc_3axis", "-q", "--data", POINTS, "--csv", str(tmp_path / "cli_id.csv"),
             "--plot", str(tmp_path / "cli_id.svg"))
    weilgen.identify("vmc_3axis", data=POINTS, quiet=True, csv=tmp_path / "id.csv",
                     plot=tmp_path / "id.svg")
    assert (tmp_path / "id.csv").read_text() == (tmp_path / "cli_id.csv").read_text()
    assert (tmp_path / "id.svg").read_text().startswith("<?xml")
    cli.json("gap", "vmc_3axis", "-q", "--data", POINTS, "--csv", str(tmp_path / "cli_gap.csv"))
    weilgen.gap("vmc_3axis", data=POINTS, quiet=True, csv=tmp_path / "gap.csv")
    assert (tmp_path / "gap.csv").read_text() == (tmp_path / "cli_gap.csv").read_text()


def test_generate_equals_cli(cli, tmp_path):
    r = cli.run("generate", "two_axis", "--out", str(tmp_path / "cli"))
    assert r.returncode == 0, r.stderr
    doc = weilgen.generate("two_axis", out=tmp_path / "module")
    assert doc["verb"] == "generate" and len(doc["written"]) == 2
    for path in doc["written"]:
        name = os.path.basename(path)
        assert open(path).read() == (tmp_path / "cli" / name).read_text()
    assert weilgen.generate("two_axis", out=tmp_path / "module", check=True)["stale"] == []


def test_plan_equals_cli(cli, tmp_path):
    """weilgen.plan returns the plan --json writes and writes the same measurement template,
    which identify reads once filled (docs/planning.md)."""
    args = ("plan", "vmc_3axis", "-q", "--poses", "30", "--noise", "1um", "--random-sets", "5",
            "--restarts", "3", "--seed", "4", "--out", str(tmp_path / "cli.csv"))
    want = cli.json(*args)
    got = weilgen.plan("vmc_3axis", quiet=True, poses=30, noise="1um", random_sets=5,
                       restarts=3, seed=4, out=tmp_path / "module.csv")
    # The run time and the written file's name are the only differences.
    same_document(got, want, ignore={"seconds", "files"})
    assert got["files"] == [str(tmp_path / "module.csv")]
    assert (tmp_path / "module.csv").read_text() == (tmp_path / "cli.csv").read_text()
    assert got["poses"] and len(got["poses"]) == 30 and got["rank"] == want["rank"] > 0
    # An instrument with its own keywords: ballbar circles in one plane, with a bar length.
    want = cli.json("plan", "vmc_3axis", "-q", "--instrument", "ballbar", "--poses", "6",
                    "--plane", "XY", "--radius", "150mm", "--angles", "36", "--random-sets", "3",
                    "--restarts", "2")
    got = weilgen.plan("vmc_3axis", quiet=True, instrument="ballbar", poses=6, plane="XY",
                       radius="150mm", angles=36, random_sets=3, restarts=2)
    same_document(got, want, ignore={"seconds"})
