"""What the package's functions leave to the CLI, and which verbs are not functions: read by
make_package.py (which generates one function per verb from `weilgen --flags-json`) and by the
parity test (tests/python/test_parity.py). Everything not listed here is a keyword of the same
name (dashes as underscores), with the same default and the same check."""

# CLI flags that have no keyword, and why.
CLI_ONLY = {
    "help": "help(weilgen.<function>) shows the keywords",
    "json": "the function returns the document --json writes (weilgen.plain(doc) for json.dump)",
    "top": "the number of rows of the CLI's text tables; the document has every row",
    "curves": "the CV curves in the CLI's text; the document has them (fits[i]['cv_curve'])",
}

# Verbs that are not a function of the same name, and where they are instead.
NOT_FUNCTIONS = {
    "list": "weilgen.machines()",
    "show": "weilgen.Model(machine, order).closed_form(output, notation=..., format=...)",
    "import": "the readers of weilgen.iso230_2 (format=...) and the CLI's `weilgen import`",
    "linuxcnc": "the CLI's `weilgen linuxcnc` (writes a HAL component; no document)",
}

# The Python name of a verb's function.
def function_name(verb):
    return verb.replace("-", "_")
