#!/usr/bin/env python3
"""The layout rules of docs/architecture.md, checked on the source tree (CTest `layout`):

  - every #include "weilgen/<layer>/..." in src/<from>/ names <from> or a layer <from> may use
    (the build enforces the same arrows through include paths; this names the file and line);
  - no source folder holds more than 20 .cpp files;
  - every src/cli/verb_*.cpp has at most 200 lines;
  - the codegen layer's CMake file links no NLopt and no Eigen;
  - nothing under src/ includes another layer's internal headers ("../", "src/");
  - a layer's internal headers (beside its .cpp files, e.g. src/uq/reliability_detail.hpp) are
    included only from their own folder: never from a public header (include/weilgen/...) nor
    from tests/, bench/, fuzz/ or examples/;
  - no function (or method defined in its class) in src/ is longer than 150 lines, except the
    named ones of LONG_FUNCTIONS, each with its reason (an exception that is no longer needed is
    reported too, so the list only shrinks);
  - no doctest case name in tests/*.cpp or tests/gap/*.cpp contains ';' (CMake splits the name at
    it, and CTest then runs no test of that case).

Usage: check_layout.py SOURCE_DIR. Prints each violation as file:line: message; exit 1 if any.
"""
import os
import re
import sys

ALLOWED = {
    "base": set(),
    "machine": {"base"},
    "codegen": {"machine", "base"},
    "model": {"machine", "base"},
    "uq": {"base"},
    "measure": {"machine", "uq", "base"},
    "analysis": {"model", "uq", "measure", "codegen", "machine", "base"},
    "report": {"analysis", "model", "uq", "measure", "codegen", "machine", "base"},
    "cli": {"report", "analysis", "model", "uq", "measure", "codegen", "machine", "base"},
    # The Python module: a front end like cli (nothing depends on either).
    "python": {"report", "analysis", "model", "uq", "measure", "codegen", "machine", "base"},
}
# Functions over MAX_FUNCTION_LINES: (file, name) -> why it is still one function. Split them
# by their steps (named helpers or a class with one method per step, as GapSearch) and delete
# the entry.
MAX_FUNCTION_LINES = 150
LONG_FUNCTIONS = {
    ("src/uq/sobol_bootstrap.cpp", "bootstrap_pass"):
        "one pass over the blocks accumulating every resample's sums (a hot loop kept together)",
}
SKIP_DECLARATION = re.compile(r"^(namespace|struct|class|enum|union|extern|template|using|typedef|"
                              r"static_assert|#|//|/\*|\*|\}|\{)")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
TEST_CASE = re.compile(r'^\s*TEST_CASE\("((?:[^"\\]|\\.)*)"')


# Tests that check a layer's internals directly, each with its reason.
WHITE_BOX_TESTS = {
    "tests/gap/engine.cpp": "the gap diagnosis' least-squares engine against dense least "
                                 "squares, below the public diagnosis",
}


def functions(lines):
    """(name, first line, length) of every function defined at namespace level: a declaration
    starting in column 0 whose body opens at the end of a line and closes with a "}" alone in
    column 0 (clang-format's layout; functions defined inside a class are methods())."""
    out, i, n = [], 0, len(lines)
    while i < n:
        line = lines[i]
        if line and not line[0].isspace() and not SKIP_DECLARATION.match(line):
            j, text = i, ""
            while j < n:
                code = lines[j].split("//")[0].rstrip()
                text += code + " "
                if code.endswith(";") or (j > i and lines[j] and not lines[j][0].isspace()):
                    j = -1
                    break
                if code.endswith("{"):
                    break
                j += 1
            if 0 <= j < n and "(" in text and not re.search(r"=\s*\{\s*$", text.strip()):
                k = j + 1
                while k < n and lines[k] != "}":
                    k += 1
                m = re.search(r"([~\w:]+)\s*\(", text)
                out.append((m.group(1) if m else "?", i + 1, k - i + 1))
                i = k + 1
                continue
        i += 1
    return out


CLASS_START = re.compile(r"^(?:class|struct) (\w+)[^;]*\{$")
STATEMENT = re.compile(r"^\s*(?:if|for|while|switch|else|return|catch|do)\b")


def methods(lines):
    """(Class::name, first line, length) of every function defined inside the body of a class or
    struct declared at namespace level: a declaration indented by two spaces whose body opens at
    the end of a line and closes with "  }" (clang-format's layout), so that splitting a long
    function into a class's methods does not take it out of the rule."""
    out, i, n = [], 0, len(lines)
    while i < n:
        m = CLASS_START.match(lines[i])
        i += 1
        if not m:
            continue
        while i < n and lines[i] != "};":
            line = lines[i]
            if (line.startswith("  ") and not line.startswith("   ") and "(" in line
                    and not STATEMENT.match(line) and not line.lstrip().startswith("//")):
                j, text = i, ""
                while j < n:
                    code = lines[j].split("//")[0].rstrip()
                    text += code + " "
                    if code.endswith(";") or code.endswith("}"):
                        j = -1
                        break
                    if code.endswith("{"):
                        break
                    j += 1
                if 0 <= j < n and "=" not in text.split("(")[0]:
                    k = j + 1
                    while k < n and lines[k] != "  }":
                        k += 1
                    name = re.search(r"([~\w]+)\s*\(", text)
                    out.append((f"{m.group(1)}::{name.group(1) if name else '?'}", i + 1,
                                k - i + 1))
                    i = k + 1
                    continue
            i += 1
    return out


def internal_includes_outside_src(root, src):
    """Includes of a layer's internal header (by name or by path) from tests, benchmarks,
    fuzzers and examples."""
    internal = set()
    for layer in os.listdir(src):
        layer_dir = os.path.join(src, layer)
        if os.path.isdir(layer_dir):
            for dirpath, _, files in os.walk(layer_dir):
                if os.sep + "include" not in dirpath[len(layer_dir):]:
                    internal |= {f for f in files if f.endswith((".hpp", ".h"))}
    problems = []
    for top in ("tests", "bench", "fuzz", "examples"):
        for dirpath, _, files in os.walk(os.path.join(root, top)):
            for f in files:
                if not f.endswith((".cpp", ".hpp", ".h")):
                    continue
                path = os.path.join(dirpath, f)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8", errors="replace") as fh:
                    for number, line in enumerate(fh, 1):
                        m = INCLUDE.match(line)
                        if not m or m.group(1).startswith("weilgen/"):
                            continue
                        target = m.group(1)
                        local = os.path.exists(os.path.join(dirpath, target))
                        if rel in WHITE_BOX_TESTS:
                            continue
                        if "src/" in target or (not local and
                                                os.path.basename(target) in internal):
                            problems.append(f"{rel}:{number}: includes '{target}', a layer's "
                                            "internal header: use the public weilgen/<layer>/...")
    return problems


def main(root):
    problems = []
    seen_long = set()
    src = os.path.join(root, "src")
    for layer in sorted(os.listdir(src)):
        layer_dir = os.path.join(src, layer)
        if not os.path.isdir(layer_dir):
            continue
        if layer not in ALLOWED:
            problems.append(f"src/{layer}: a folder that is not a layer of docs/architecture.md")
            continue
        for dirpath, _, files in os.walk(layer_dir):
            cpps = [f for f in files if f.endswith(".cpp")]
            if len(cpps) > 20:
                rel = os.path.relpath(dirpath, root)
                problems.append(f"{rel}: {len(cpps)} .cpp files (at most 20: split by job)")
            for f in files:
                if not f.endswith((".cpp", ".hpp", ".h")):
                    continue
                path = os.path.join(dirpath, f)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8") as fh:
                    lines = fh.read().split("\n")
                if layer == "cli" and f.startswith("verb_") and f.endswith(".cpp"):
                    n = len(lines) - (1 if lines and lines[-1] == "" else 0)
                    if n > 200:
                        problems.append(f"{rel}: {n} lines (a verb parses and prints: <= 200)")
                for name, first, length in functions(lines) + methods(lines):
                    key = (rel.replace(os.sep, "/"), name)
                    if length > MAX_FUNCTION_LINES and key not in LONG_FUNCTIONS:
                        problems.append(f"{rel}:{first}: {name} has {length} lines (at most "
                                        f"{MAX_FUNCTION_LINES}: split it by its steps)")
                    if key in LONG_FUNCTIONS:
                        seen_long.add(key)
                        if length <= MAX_FUNCTION_LINES:
                            problems.append(f"{rel}:{first}: {name} has {length} lines now: "
                                            "remove it from LONG_FUNCTIONS")
                for number, line in enumerate(lines, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    target = m.group(1)
                    if "/include/weilgen/" in path and not target.startswith("weilgen/"):
                        problems.append(f"{rel}:{number}: a public header includes '{target}': "
                                        "internal headers stay beside their .cpp files")
                    if target.startswith("../") or target.startswith("src/"):
                        problems.append(f"{rel}:{number}: includes '{target}' by path: use the "
                                        "layer's public header weilgen/<layer>/...")
                    parts = target.split("/")
                    if len(parts) >= 3 and parts[0] == "weilgen":
                        to = parts[1]
                        if to != layer and to not in ALLOWED[layer]:
                            problems.append(f"{rel}:{number}: {layer} may not include {to} "
                                            f"('{target}'; allowed: "
                                            f"{', '.join(sorted(ALLOWED[layer])) or 'none'})")
    for file, name in sorted(set(LONG_FUNCTIONS) - seen_long):
        problems.append(f"{file}: LONG_FUNCTIONS names {name}, which is not there any more")
    problems += internal_includes_outside_src(root, src)
    cmake = os.path.join(src, "codegen", "CMakeLists.txt")
    with open(cmake, encoding="utf-8") as fh:
        text = "\n".join(l.split("#")[0] for l in fh.read().split("\n"))  # without comments
    for lib in ("NLopt", "Eigen3", "nlopt"):
        if lib in text:
            problems.append(f"src/codegen/CMakeLists.txt: links {lib} (codegen uses GiNaC only)")
    tests = os.path.join(root, "tests")
    test_files = sorted(n for n in os.listdir(tests) if n.endswith(".cpp"))
    test_files += sorted("gap/" + n for n in os.listdir(os.path.join(tests, "gap"))
                         if n.endswith(".cpp"))
    for name in test_files:
        with open(os.path.join(tests, name), encoding="utf-8") as fh:
            for number, line in enumerate(fh, 1):
                m = TEST_CASE.match(line)
                if m and ";" in m.group(1):
                    problems.append(f"tests/{name}:{number}: test case name contains ';' (CMake "
                                    "splits it and CTest never runs the case): use ','")
    for p in problems:
        print(p)
    print(f"layout: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
