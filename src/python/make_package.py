#!/usr/bin/env python3
"""Generates the verbs' functions of the `weilgen` package from the CLI's flag table.

    make_package.py --cli build/weilgen --stub weilgen/__init__.pyi.in --out build/python/weilgen

writes into --out:
  _flags.json   `weilgen --flags-json`: every verb's flags (name, kind, default, range, help)
  _verbs.py     one function per verb (weilgen/_parity.py lists the exceptions) whose keywords are
                the verb's flags, with the CLI's defaults, a docstring listing every keyword with
                the CLI's help (units included) and a real signature
  __init__.pyi  the stub: the hand-written part (--stub) with the functions' signatures

The output is deterministic (the same table gives the same bytes)."""
import argparse
import json
import keyword
import os
import subprocess
import sys
import textwrap

sys.dont_write_bytecode = True  # a build never writes into the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "weilgen"))
import _parity  # noqa: E402  (the package's own list, read before the package exists)

POSITIONAL_DOC = {
    "machine": ("str, os.PathLike or weilgen.Model",
                "a shipped machine's name (weilgen.machines()), a machine file, or a "
                "weilgen.Model (its model is reused; order, engine, compiler and param then "
                "belong to the Model)"),
    "data": ("str or os.PathLike", "the measurement file (docs/data-format.md)"),
    "file": ("str or os.PathLike", "the file to read"),
    "trace": ("str or os.PathLike", "the ballbar trace file (docs/data-format.md)"),
}
# Text flags that name files (the others are plain text).
PATHS = {"csv", "plot", "report", "save-tolerances", "emit-params", "predict-out", "comp-table",
         "out", "data", "tolerances", "predict"}
# Text flags that also take a dict, a list or a tuple (written as the CLI's text; docs/python.md).
STRUCTURED_TEXT = {"centre", "comp_at", "travel", "outputs", "errors"}


def python_name(name):
    name = name.replace("-", "_")
    return name + "_" if keyword.iskeyword(name) else name


def default_value(flag):
    """The flag's default as a Python value: the CLI's text read as its kind."""
    kind, text = flag["kind"], flag["default"]
    if kind == "switch":
        return False
    if text is None:
        return None
    if kind == "whole":
        return int(float(text)) if "e" in text.lower() else int(text)
    if kind == "number":
        return float(text)
    return text


def annotation(flag):
    kind, name = flag["kind"], python_name(flag["name"])
    if kind == "switch":
        return "bool"
    if kind == "number":
        return "Optional[float]"
    if kind == "whole":
        return "Optional[int]"
    if name == "machine":  # ballbar's --machine: a name, a file or a weilgen.Model
        return "Optional[_Machine]"
    if kind == "repeatable" or name in STRUCTURED_TEXT:
        return "Optional[_Items]"
    return "Optional[_Text]" if flag["name"] in PATHS else "Optional[_Value]"


def type_words(flag):
    if flag["kind"] == "repeatable":
        return ("str, os.PathLike or list (the flag repeated)" if flag["name"] in PATHS
                else "str, dict or list (the flag repeated)")
    if flag["kind"] == "text":
        if flag["name"] == "machine":
            return "str, os.PathLike or weilgen.Model"
        if flag["name"] in PATHS:
            return "str or os.PathLike"
        return "str, dict, list or tuple" if python_name(flag["name"]) in STRUCTURED_TEXT else "str"
    return {"switch": "bool", "number": "float", "whole": "int"}[flag["kind"]]


def keywords(table):
    return [f for f in table["flags"] if f["name"] not in _parity.CLI_ONLY]


def docstring(verb, table, positional):
    about = table["about"].strip()
    lines = [about, "", "This is `weilgen %s` with its flags as keywords (docs/python.md)." % verb,
             "", "Parameters", "----------"]
    if positional:
        kind, what = POSITIONAL_DOC.get(positional, ("str", "the %s" % positional))
        lines += ["%s : %s" % (positional, kind), "    " + what]
    for f in keywords(table):
        default = default_value(f)
        head = "%s : %s" % (python_name(f["name"]), type_words(f))
        head += ", optional" if default is None else ", default %r" % (default,)
        help_text = " ".join(f["help"].split())
        check = "; " + f["range"]["text"] if f["range"] else ""
        body = "%s (--%s%s)" % (help_text, f["name"], check)
        lines.append(head)
        lines += textwrap.wrap(body, 92, initial_indent="    ", subsequent_indent="    ",
                               break_on_hyphens=False, break_long_words=False)
    lines += ["", "Returns", "-------", "dict",
              "    the document `weilgen %s --json` writes: numbers as numpy arrays, records as"
              % verb,
              "    lists of dicts (weilgen.to_frame(doc) for a table, weilgen.plain(doc) for "
              "json.dump)."]
    return "\n".join(lines)


def function_source(verb, table):
    name = _parity.function_name(verb)
    positional = table["positional"]
    params, passed = [], []
    if positional:
        params.append(positional)
    params.append("*")
    for f in keywords(table):
        py = python_name(f["name"])
        params.append("%s=%r" % (py, default_value(f)))
        passed.append("%r: %s" % (f["name"].replace("-", "_"), py))
    doc = docstring(verb, table, positional).replace('"""', "'''")
    body = ["def %s(%s):" % (name, ", ".join(params)),
            textwrap.indent('"""' + doc + '\n"""', "    "),
            "    return _run(%r, %s, {%s})" % (name, positional or "None", ", ".join(passed))]
    return "\n".join(body) + "\n"


def stub_source(verb, table):
    name = _parity.function_name(verb)
    positional = table["positional"]
    params = []
    if positional:
        params.append("%s: %s" % (positional, "_Machine" if positional == "machine" else "_Text"))
    params.append("*")
    for f in keywords(table):
        params.append("%s: %s = %r" % (python_name(f["name"]), annotation(f), default_value(f)))
    return "def %s(%s) -> Dict[str, Any]: ...\n" % (name, ", ".join(params))


def verbs(tables):
    return [v for v in sorted(tables) if v not in _parity.NOT_FUNCTIONS]


def write(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cli", required=True, help="the weilgen executable")
    ap.add_argument("--stub", required=True, help="the stub's hand-written part (__init__.pyi.in)")
    ap.add_argument("--out", required=True, help="the package directory")
    a = ap.parse_args()
    text = subprocess.run([a.cli, "--flags-json"], check=True, capture_output=True,
                          text=True).stdout
    tables = json.loads(text)
    os.makedirs(a.out, exist_ok=True)
    write(os.path.join(a.out, "_flags.json"), json.dumps(tables, indent=1, sort_keys=True) + "\n")

    out = ['"""The verbs of `weilgen` as functions: GENERATED by src/python/make_package.py from',
           '`weilgen --flags-json` (every flag a keyword, with the CLI\'s default; do not edit)."""',
           "from . import _weilgen", "",
           "__all__ = %r" % [_parity.function_name(v) for v in verbs(tables)], "", "",
           "def _run(name, positional, keywords):",
           "    function = getattr(_weilgen, name, None)",
           "    if function is None:",
           "        raise NotImplementedError(",
           "            'weilgen.%s: the extension does not implement this verb yet '",
           "            \"(docs/architecture.md, 'A verb', step 5)\" % name)",
           "    if positional is None:",
           "        return function(**keywords)",
           "    return function(positional, **keywords)", ""]
    for v in verbs(tables):
        out += ["", function_source(v, tables[v])]
    write(os.path.join(a.out, "_verbs.py"), "\n".join(out))

    with open(a.stub, encoding="utf-8") as f:
        stub = f.read()
    functions = "".join(stub_source(v, tables[v]) + "\n" for v in verbs(tables))
    marker = "# @VERBS@\n"
    if marker not in stub:
        sys.exit("make_package.py: %s has no line '# @VERBS@'" % a.stub)
    write(os.path.join(a.out, "__init__.pyi"), stub.replace(marker, functions))


if __name__ == "__main__":
    main()
