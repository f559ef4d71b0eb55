"""weilgen.to_frame: a document's table as a pandas DataFrame, or as a dict of numpy columns
when pandas is not installed (docs/python.md, 'Tables')."""
import numbers

import numpy as np

# Each verb's main table: a key of the document holding records, or a builder.
_DEFAULT = {
    "sensitivity": "results",
    "reliability": "results",
    "allocate": "steps",
    "iso230-2": "targets",
    "fit-pdge": "fits",
    "ballbar": "runs",
    "identify": "parameters",
    "gap": "effects",
    "generate": "files",
    "plan": "poses",
}


def _targets(doc):
    """iso230-2: one row per target, the per-target arrays of every evaluation (classical
    without prefix, then student.* and drift_eliminated.*)."""
    n = len(doc["positions_mm"])
    columns = {"target_mm": doc["positions_mm"]}
    for prefix, part in (("", doc), ("student.", doc.get("student") or {}),
                         ("drift_eliminated.", doc.get("drift_eliminated") or {})):
        for key, value in part.items():
            if key != "positions_mm" and isinstance(value, np.ndarray) and value.shape == (n,):
                columns[prefix + key] = value
    return columns


def _fits(doc):
    """fit-pdge: one row per profile and basis."""
    rows = []
    for p in doc["profiles"]:
        for f in p["fits"]:
            row = {"profile": p["name"], "column": p["column"], "unit": p["unit"]}
            row.update(f)
            rows.append(row)
    return rows


def _flatten(record, prefix=""):
    """A record as one level: the pose's axes as columns of their own, other dicts as
    'key.sub', an interval (a '*ci' pair) as key_lo and key_hi."""
    out = {}
    first = [k for k in ("pose", "output", "error", "name") if k in record and not prefix]
    for key in first + [k for k in record if k not in first]:
        value = record[key]
        name = prefix + key
        if isinstance(value, dict):
            out.update(_flatten(value, "" if key == "pose" and not prefix else name + "."))
        elif (isinstance(value, (np.ndarray, list)) and len(value) == 2
              and key.lower().endswith("ci")):  # an array, or a list from json.load
            out[name + "_lo"], out[name + "_hi"] = list(value)
        else:
            out[name] = value
    return out


def _column(values):
    def number(v):
        return v is None or (isinstance(v, numbers.Number) and not isinstance(v, bool))
    if values and all(isinstance(v, bool) for v in values):
        return np.array(values, dtype=bool)
    if values and all(number(v) for v in values):
        if all(isinstance(v, numbers.Integral) for v in values):
            return np.array(values, dtype=np.int64)
        return np.array([np.nan if v is None else v for v in values], dtype=np.float64)
    column = np.empty(len(values), dtype=object)
    column[:] = values
    return column


def _select(doc, table):
    value = doc
    for part in table.split("."):
        if not isinstance(value, dict) or part not in value:
            raise KeyError("to_frame: the document has no table %r (its keys: %s)"
                           % (table, ", ".join(doc)))
        value = value[part]
    return value


def to_frame(document, table=None):
    """A document's table as a pandas DataFrame, or a dict of numpy columns without pandas.

    Parameters
    ----------
    document : dict
        a document of weilgen.sensitivity, reliability, allocate, iso230_2, fit_pdge,
        identify, gap, generate or plan (or json.load of the CLI's --json)
    table : str, optional
        which table: None for the verb's main one (sensitivity and reliability: 'results',
        one row per pose, output and error or output; allocate: 'steps'; iso230_2: 'targets',
        one row per target; fit_pdge: 'fits', one row per profile and basis; identify:
        'parameters'; gap: 'effects'; generate: 'files'; plan: 'poses'), or the key of another
        list of records ('summary', 'inputs', 'where', ...) or of a dict of equally long arrays
        ('drift_per_cycle'); dotted for nested keys

    Returns
    -------
    pandas.DataFrame, or dict of numpy.ndarray
        the columns: a record's keys, a pose's axes as columns of their own (X, Y, Z), nested
        dicts as 'key.sub' (dR_dmu.E_XX, in the model's error order), intervals as key_lo and
        key_hi; numbers keep the units the document gives them (in the key names or the
        *_unit columns)
    """
    verb = document.get("verb")
    table = table or _DEFAULT.get(verb)
    if table is None:
        raise KeyError("to_frame: no default table for verb %r: name one" % (verb,))
    if table == "targets" and verb == "iso230-2":
        columns = _targets(document)
    else:
        value = _fits(document) if (table == "fits" and verb == "fit-pdge") else \
            _select(document, table)
        if isinstance(value, dict):  # columns: equally long arrays (and scalars left out)
            columns = {k: v for k, v in value.items()
                       if isinstance(v, (np.ndarray, list)) and not isinstance(v, str)}
            lengths = {len(v) for v in columns.values()}
            if len(lengths) > 1:
                longest = max(lengths)
                columns = {k: v for k, v in columns.items() if len(v) == longest}
        elif isinstance(value, list):
            rows = [_flatten(r) if isinstance(r, dict) else {table: r} for r in value]
            names = list(dict.fromkeys(k for r in rows for k in r))
            columns = {n: [r.get(n) for r in rows] for n in names}
        else:
            raise KeyError("to_frame: %r is not a table" % table)
        columns = {k: (v if isinstance(v, np.ndarray) else _column(list(v)))
                   for k, v in columns.items()}
    try:
        import pandas
    except ImportError:
        return columns
    return pandas.DataFrame(columns)
