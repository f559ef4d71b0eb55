"""Bad arguments and bad files raise weilgen errors carrying the CLI's located message (the flag,
or file:line:column); nothing is written; long runs release the GIL."""
import re
import threading
import time

import pytest

import weilgen
from conftest import source

POINTS = source("examples", "data", "vmc_3axis_points.csv")


def raises_like_cli(cli, kind, call, *args):
    code, message = cli.error(*args)
    with pytest.raises(kind) as e:
        call()
    # The same message: a number out of its range too, checked against the CLI's flag table
    # ("--confidence: '1.5' is out of range (allowed: a number in (0, 1))").
    assert str(e.value) == message
    assert e.value.exit_code == code
    assert isinstance(e.value, weilgen.Error)
    return e.value


def test_bad_flags_carry_the_cli_message(cli):
    A = weilgen.ArgumentError
    raises_like_cli(cli, A, lambda: weilgen.sensitivity("gantry_grinder", grid="X=0:1000:0"),
                    "sensitivity", "gantry_grinder", "--grid", "X=0:1000:0")
    raises_like_cli(cli, A, lambda: weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600", outputs="dq"),
                    "sensitivity", "gantry_grinder", "--at", "X=0,Y=0,Z=600", "--outputs", "dq")
    raises_like_cli(cli, A,
                    lambda: weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600", confidence=1.5),
                    "sensitivity", "gantry_grinder", "--at", "X=0,Y=0,Z=600", "--confidence", "1.5")
    raises_like_cli(cli, A, lambda: weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600",
                                                        set={"E_QQ": "sigma:1um"}),
                    "sensitivity", "gantry_grinder", "--at", "X=0,Y=0,Z=600", "--set",
                    "E_QQ=sigma:1um")
    raises_like_cli(cli, A, lambda: weilgen.reliability("gantry_grinder", at="X=0,Y=0,Z=600"),
                    "reliability", "gantry_grinder", "--at", "X=0,Y=0,Z=600")
    raises_like_cli(cli, A, lambda: weilgen.reliability("gantry_grinder", at="X=0,Y=0,Z=600",
                                                        tolerance="dx=0.03mm", limit="sideways"),
                    "reliability", "gantry_grinder", "--at", "X=0,Y=0,Z=600", "--tolerance",
                    "dx=0.03mm", "--limit", "sideways")
    raises_like_cli(cli, A, lambda: weilgen.allocate("gantry_grinder", at="X=0,Y=0,Z=600",
                                                     tolerance="dx=0.03mm", min=1.5),
                    "allocate", "gantry_grinder", "--at", "X=0,Y=0,Z=600", "--tolerance", "dx=0.03mm",
                    "--min", "1.5")
    raises_like_cli(cli, A, lambda: weilgen.identify("vmc_3axis", data=POINTS, rank_tol=2),
                    "identify", "vmc_3axis", "--data", POINTS, "--rank-tol", "2")
    raises_like_cli(cli, A, lambda: weilgen.identify("vmc_3axis", data=POINTS,
                                                     pdge={"E_QQ": "poly:2"}),
                    "identify", "vmc_3axis", "--data", POINTS, "--pdge", "E_QQ=poly:2")
    raises_like_cli(cli, A, lambda: weilgen.gap("vmc_3axis", data=POINTS, holdout="weekly"),
                    "gap", "vmc_3axis", "--data", POINTS, "--holdout", "weekly")
    raises_like_cli(cli, A, lambda: weilgen.gap("vmc_3axis", data=POINTS, effects="gremlins"),
                    "gap", "vmc_3axis", "--data", POINTS, "--effects", "gremlins")
    data = source("examples", "data", "iso230_2_small.csv")
    raises_like_cli(cli, A, lambda: weilgen.iso230_2(data, alpha=1.5),
                    "iso230-2", data, "--alpha", "1.5")
    raises_like_cli(cli, A, lambda: weilgen.fit_pdge(data, rule="max"),
                    "fit-pdge", data, "--rule", "max")
    raises_like_cli(cli, A, lambda: weilgen.iso230_2(data, comp_type=1),
                    "iso230-2", data, "--comp-type", "1")
    raises_like_cli(cli, A, lambda: weilgen.iso230_2(data, normalise="sometimes"),
                    "iso230-2", data, "--normalise", "sometimes")
    raises_like_cli(cli, A, lambda: weilgen.iso230_2(data, uncertainty="lasr"),
                    "iso230-2", data, "--uncertainty", "lasr")
    trace = source("examples", "data", "ballbar_xy.csv")
    raises_like_cli(cli, A, lambda: weilgen.ballbar(trace, alpha=2),
                    "ballbar", trace, "--alpha", "2")
    raises_like_cli(cli, A, lambda: weilgen.ballbar(trace, plot="p.png"),
                    "ballbar", trace, "--plot", "p.png")
    raises_like_cli(cli, A, lambda: weilgen.identify("vmc_3axis", data=POINTS, axis="X"),
                    "identify", "vmc_3axis", "--data", POINTS, "--axis", "X")
    raises_like_cli(cli, A, lambda: weilgen.identify("vmc_3axis", data=POINTS, comp_table=POINTS,
                                                     axis="X"),
                    "identify", "vmc_3axis", "--data", POINTS, "--comp-table", POINTS, "--axis", "X")
    raises_like_cli(cli, A, lambda: weilgen.Model("gantry_grinder", engine="fast"),
                    "sensitivity", "gantry_grinder", "--at", "X=0,Y=0,Z=600", "--engine", "fast")


def test_bad_files_carry_file_line_column(cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    text = open(source("machines", "vmc_3axis.yaml"), encoding="utf-8").read()
    bad.write_text(text.replace("algebra: {order: 1}", "algebra: {order: 1, colour: red}"))
    err = raises_like_cli(cli, weilgen.InputError, lambda: weilgen.Model(str(bad)),
                          "sensitivity", str(bad), "--at", "X=0")
    assert err.file == str(bad) and err.line > 0 and err.column > 0
    assert str(err).startswith(f"{bad}:{err.line}:{err.column}: ")
    raises_like_cli(cli, weilgen.InputError, lambda: weilgen.Model("no_such_machine"),
                    "sensitivity", "no_such_machine", "--at", "X=0")
    csv = tmp_path / "bad.csv"
    csv.write_text("X,dir,cycle,dx_um\n0,1,1,0.5\n100,1,1,oops\n")
    err = raises_like_cli(cli, weilgen.InputError, lambda: weilgen.iso230_2(csv),
                          "iso230-2", str(csv))
    assert err.line == 3
    raises_like_cli(cli, weilgen.InputError, lambda: weilgen.identify("vmc_3axis", data=csv),
                    "identify", "vmc_3axis", "--data", str(csv))


def test_a_failed_compile_is_a_run_error(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("WEILGEN_CACHE_DIR", str(tmp_path / "cache"))
    copy = tmp_path / "my_vmc.yaml"  # an edited copy is not built in: compiled at run time
    copy.write_text(open(source("machines", "vmc_3axis.yaml"), encoding="utf-8").read() + "# mine\n")
    with pytest.raises(weilgen.RunError) as e:
        weilgen.Model(str(copy), engine="compiled", compiler="false", quiet=True)
    assert isinstance(e.value, RuntimeError) and e.value.exit_code == 1
    r = cli.run("sensitivity", str(copy), "--at", "X=0,Y=0,Z=0", "--engine", "compiled", "--compiler",
                "false", "--quiet")
    # The same message, up to the process id in the name of the build directory.
    same = lambda text: re.sub(r"build-([0-9a-f]+)-[0-9]+", r"build-\1", text).strip()
    assert r.returncode == 1
    assert same(r.stderr) == "weilgen sensitivity: " + same(str(e.value))
    assert not list((tmp_path / "cache").glob("*.so"))  # nothing cached


def test_python_mistakes_name_the_keyword_or_flag(tmp_path):
    # A real signature: Python's own TypeError for a keyword the function does not take.
    with pytest.raises(TypeError, match=r"sensitivity\(\) got an unexpected keyword argument 'sample'"):
        weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600", sample=10)
    # The CLI's checks of the flag (its range from `weilgen sensitivity --flags-json`).
    with pytest.raises(weilgen.ArgumentError, match=r"--samples: '-4' is out of range \(allowed: "
                                                    r"a whole number from 2 to 4294967295\)"):
        weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600", samples=-4)
    with pytest.raises(weilgen.ArgumentError, match="--samples: 'many' is not a number"):
        weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600", samples="many")
    with pytest.raises(weilgen.ArgumentError, match="--per-output: expected True or False"):
        weilgen.allocate("gantry_grinder", at="X=0,Y=0,Z=600", tolerance="dx=30um", per_output=1)
    with pytest.raises(weilgen.ArgumentError, match="--grid: nan is not a finite number"):
        weilgen.sensitivity("gantry_grinder", grid={"X": float("nan")})
    with pytest.raises(weilgen.ArgumentError, match="order= is for a machine name or file"):
        weilgen.sensitivity(weilgen.Model("gantry_grinder"), at="X=0,Y=0,Z=600", order=2)
    with pytest.raises(weilgen.ArgumentError, match="--plot: unsupported|plot"):
        weilgen.sensitivity("gantry_grinder", at="X=0,Y=0,Z=600", plot=str(tmp_path / "x.pdf"))
    assert not (tmp_path / "x.pdf").exists()
    assert issubclass(weilgen.ArgumentError, ValueError)
    assert issubclass(weilgen.InputError, ValueError)
    assert issubclass(weilgen.RunError, RuntimeError)


def test_outputs_are_untouched_on_failure(tmp_path):
    csv = tmp_path / "out.csv"
    csv.write_text("keep me\n")
    with pytest.raises(weilgen.ArgumentError):
        weilgen.sensitivity("gantry_grinder", grid="X=0:1000:0", csv=csv)
    assert csv.read_text() == "keep me\n"


def test_long_runs_release_the_gil():
    done = threading.Event()
    result = {}

    def run():
        result["doc"] = weilgen.sensitivity("gantry_grinder", grid="X=0:1000:5,Y=0,Z=600:1400:5",
                                            method="sobol", samples=1 << 13, bootstrap=0,
                                            threads=1, quiet=True)
        done.set()

    t = threading.Thread(target=run)
    start = time.perf_counter()
    t.start()
    ticks = 0
    while not done.is_set():
        ticks += 1  # runs only while the analysis has released the GIL
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - start
    assert len(result["doc"]["results"]) > 0
    # Holding the GIL would leave this loop one tick per switch interval at most.
    assert elapsed < 0.05 or ticks > 10, (elapsed, ticks)
