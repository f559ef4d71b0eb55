"""weilgen: machine-tool error models and their analyses (docs/python.md).

Model(machine) opens a machine's model (deviation, coefficients, closed_form); machines() lists
the shipped machines; sensitivity, reliability, allocate, iso230_2, fit_pdge, identify, gap and
generate run the CLI's verbs with its flags as keywords and return the documents its --json
writes; to_frame(doc) turns a document's main table into a pandas DataFrame (or a dict of numpy
columns without pandas); plain(doc) gives the JSON the CLI writes."""
import os as _os

from . import _weilgen

_here = _os.path.dirname(_os.path.abspath(__file__))
with open(_os.path.join(_here, "_flags.json"), encoding="utf-8") as _f:
    _weilgen._use_flag_tables(_f.read())
# An installed package (cmake --install, pip install) reads the machines installed with it; in
# the build tree the source tree's machines/ (unless $WEILGEN_MACHINES_DIR says otherwise).
if _os.path.isdir(_os.path.join(_here, "machines")):
    _weilgen._use_machines_dir(_os.path.join(_here, "machines"))

from ._weilgen import ArgumentError, Error, InputError, RunError, Warning, __version__, plain  # noqa: E402,F401
from ._model import Model, machines  # noqa: E402,F401
from ._verbs import *  # noqa: E402,F401,F403
from ._verbs import __all__ as _verbs_all  # noqa: E402
from ._frame import to_frame  # noqa: E402,F401

__all__ = ["Model", "machines", "to_frame", "plain", "Error", "ArgumentError", "InputError",
           "RunError", "Warning", "__version__"] + list(_verbs_all)
