"""Parity with the CLI that cannot drift (issue 30): every verb of `weilgen --flags-json` is a
function (or listed in weilgen/_parity.py with where it is instead), and every flag of it a
keyword of the same name (dashes as underscores) with the same default and the same check; the
extension implements every keyword; the stub says the same as the signatures."""
import ast
import inspect
import json
import math
import os
import subprocess

import pytest

import weilgen
from weilgen import _parity, _weilgen
from conftest import BINARY

TABLES = json.loads(subprocess.run([BINARY, "--flags-json"], check=True, capture_output=True,
                                   text=True).stdout)
VERBS = sorted(v for v in TABLES if v not in _parity.NOT_FUNCTIONS)


def keyword(flag):
    return flag["name"].replace("-", "_")


def python_default(flag):
    kind, text = flag["kind"], flag["default"]
    if kind == "switch":
        return False
    if text is None:
        return None
    return {"whole": lambda t: int(float(t)), "number": float}.get(kind, str)(text)


def test_the_package_was_built_from_this_cli():
    """The package's _flags.json is the table of the CLI next to it (no stale build)."""
    with open(os.path.join(os.path.dirname(weilgen.__file__), "_flags.json")) as f:
        assert json.load(f) == TABLES


def test_every_verb_is_a_function_or_says_where_it_is():
    for verb in TABLES:
        if verb in _parity.NOT_FUNCTIONS:
            continue
        name = _parity.function_name(verb)
        assert callable(getattr(weilgen, name, None)), f"weilgen.{name} for `weilgen {verb}`"
        assert hasattr(_weilgen, name), (
            f"`weilgen {verb}`: the extension has no {name}() (docs/architecture.md, 'A verb', "
            "step 5)")
    # The exceptions name verbs that exist.
    assert set(_parity.NOT_FUNCTIONS) <= set(TABLES)


@pytest.mark.parametrize("verb", VERBS)
def test_every_flag_is_a_keyword_with_the_cli_default(verb):
    table = TABLES[verb]
    function = getattr(weilgen, _parity.function_name(verb))
    params = inspect.signature(function).parameters
    positional = [p for p in params.values() if p.kind is p.POSITIONAL_OR_KEYWORD]
    assert [p.name for p in positional] == ([table["positional"]] if table["positional"] else [])
    keywords = {n: p for n, p in params.items() if p.kind is p.KEYWORD_ONLY}
    flags = [f for f in table["flags"] if f["name"] not in _parity.CLI_ONLY]
    assert sorted(keywords) == sorted(keyword(f) for f in flags)
    doc = inspect.getdoc(function)
    for f in flags:
        assert keywords[keyword(f)].default == python_default(f), (verb, f["name"])
        # The docstring lists every keyword with the CLI's help (units included).
        assert f"\n{keyword(f)} : " in doc, (verb, f["name"])
        assert " ".join(f["help"].split())[:40] in " ".join(doc.split()), (verb, f["name"])
    # The extension implements each keyword (a new flag must be wired, not only listed).
    assert sorted(_weilgen._implemented()[function.__name__]) == sorted(keywords)


def out_of_range(r):
    """A value the range refuses, as text: below the lower end, above the upper, or half-way
    between two whole numbers."""
    if r["lo"] is not None:
        return repr(r["lo"] if r["lo_open"] else r["lo"] - 1)
    if r["hi"] is not None:
        return repr(r["hi"] if r["hi_open"] else r["hi"] + 1)
    return "2.5" if r["whole"] else None


def cli_message(verb, args):
    r = subprocess.run([BINARY, verb, *args], capture_output=True, text=True)
    assert r.returncode == 2, (verb, args, r.stderr)
    line = r.stderr.strip().splitlines()[-1]
    return line.removeprefix(f"weilgen {verb}: ").removesuffix(f" (try weilgen {verb} --help)")


@pytest.mark.parametrize("verb", VERBS)
def test_every_check_is_the_cli_check(verb):
    """Each number out of its flag's range, each switch given a non-bool: the CLI's message."""
    table = TABLES[verb]
    function = getattr(weilgen, _parity.function_name(verb))
    positional = ["whatever.csv"] if table["positional"] else []
    checked = 0
    for f in table["flags"]:
        if f["name"] in _parity.CLI_ONLY:
            continue
        if f["range"] and out_of_range(f["range"]) is not None:
            text = out_of_range(f["range"])
            want = cli_message(verb, [*positional, f"--{f['name']}", text])
            with pytest.raises(weilgen.ArgumentError) as e:
                function(*positional, **{keyword(f): float(text) if "." in text or "e" in text
                                         else int(text)})
            assert str(e.value) == want, (verb, f["name"])
            assert e.value.exit_code == 2
            checked += 1
        elif f["kind"] == "switch":
            with pytest.raises(weilgen.ArgumentError, match=f"--{f['name']}: expected True or False"):
                function(*positional, **{keyword(f): 1})
            checked += 1
    assert checked or not [f for f in table["flags"] if f["range"] or f["kind"] == "switch"]


def test_show_is_model_closed_form():
    """`weilgen show`'s flags: output, notation and format are closed_form's, order the Model's."""
    flags = {f["name"]: f for f in TABLES["show"]["flags"]}
    params = inspect.signature(weilgen.Model.closed_form).parameters
    assert set(flags) - {"help", "order"} == {"output", "notation", "format"} <= set(params)
    assert params["notation"].default == flags["notation"]["default"]
    assert params["format"].default == flags["format"]["default"]
    assert "order" in inspect.signature(weilgen.Model).parameters


def stub_functions():
    path = os.path.join(os.path.dirname(weilgen.__file__), "__init__.pyi")
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            out[node.name] = node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and not any(
                        isinstance(d, ast.Name) and d.id == "property" for d in item.decorator_list):
                    out.setdefault(f"{node.name}.{item.name}", item)
    return out


def stub_parameters(node):
    a = node.args
    names = [x.arg for x in a.args]
    defaults = [None] * (len(a.args) - len(a.defaults)) + [ast.literal_eval(d) if not (
        isinstance(d, ast.Constant) and d.value is Ellipsis) else ... for d in a.defaults]
    out = [(n, d, "positional") for n, d in zip(names, defaults) if n != "self"]
    out += [(x.arg, ast.literal_eval(d) if d is not None else inspect.Parameter.empty, "keyword")
            for x, d in zip(a.kwonlyargs, a.kw_defaults)]
    return out


def runtime_parameters(function):
    out = []
    for p in inspect.signature(function).parameters.values():
        if p.name == "self":
            continue
        default = None if p.default is inspect.Parameter.empty and p.kind is not p.KEYWORD_ONLY \
            else p.default
        out.append((p.name, default, "keyword" if p.kind is p.KEYWORD_ONLY else "positional"))
    return out


def test_the_stub_says_what_the_functions_take():
    stub = stub_functions()
    public = ["machines", "to_frame", "plain"] + list(weilgen._verbs.__all__)
    for name in public:
        if name == "plain":
            continue  # the extension's own function (one argument)
        assert name in stub, name
        assert stub_parameters(stub[name]) == runtime_parameters(getattr(weilgen, name)), name
    for method in ("deviation", "coefficients", "closed_form", "__init__"):
        assert stub_parameters(stub[f"Model.{method}"]) == runtime_parameters(
            getattr(weilgen.Model, method)), method
    assert os.path.isfile(os.path.join(os.path.dirname(weilgen.__file__), "py.typed"))


def test_signatures_are_real():
    """inspect.signature works on every public callable (Jupyter shows the keywords)."""
    for name in weilgen.__all__:
        obj = getattr(weilgen, name)
        if callable(obj) and not isinstance(obj, type) and name != "plain":
            inspect.signature(obj)
    assert str(inspect.signature(weilgen.Model)).startswith("(machine, order=None, *, engine='auto'")
    sig = inspect.signature(weilgen.iso230_2)
    assert sig.parameters["alpha"].default == 0.01
    assert sig.parameters["target_tolerance"].default == 1e-6
    assert math.isclose(sig.parameters["confidence"].default, 0.95) if "confidence" in \
        sig.parameters else True
