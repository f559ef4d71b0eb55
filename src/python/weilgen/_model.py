"""weilgen.Model: the extension's model with named inputs, checked values, closed forms and
pickling (docs/python.md, 'weilgen.Model')."""
import math
import os
import warnings
from collections.abc import Mapping

import numpy as np

from . import _weilgen


def machines():
    """The shipped machines, as `weilgen list` lists them.

    Returns
    -------
    list of dict
        one per machine, by name: name, title, file (the machine file), axes (the axis
        coordinates in deviation()'s column order), axis_units ('mm' or 'deg' each), errors
        (how many), order (the algebra order of the file), params (the machine parameters).
    """
    return _weilgen._machines()


def _reopen(state):
    return Model(state["machine"], state["order"] or None, engine=state["engine"],
                 compiler=state["compiler"] or None, param=state["param"] or None, quiet=True)


def _named(value):
    """The columns of a mapping, a numpy structured array or a pandas DataFrame by name; None
    for anything else (an array in column order)."""
    if isinstance(value, np.ndarray):
        return {n: value[n] for n in value.dtype.names} if value.dtype.names else None
    if isinstance(value, Mapping):
        return dict(value)
    if hasattr(value, "columns") and hasattr(value, "to_numpy"):  # pandas.DataFrame
        return {str(c): value[c].to_numpy() for c in value.columns}
    return None


def _number(v):
    return repr(int(v)) if float(v).is_integer() and abs(v) < 1e15 else repr(float(v))


class Model(_weilgen.Model):
    """A machine's error model (docs/python.md, 'weilgen.Model').

    Parameters
    ----------
    machine : str or os.PathLike
        a shipped machine's name (weilgen.machines()) or a machine file
    order : int, optional
        the algebra order (None: the machine file's; another is compiled at run time and cached)
    engine : str, default 'auto'
        'auto' (built in, cached or compiled; the exact numeric chain without a compiler),
        'compiled' or 'numeric'
    compiler : str, optional
        the C++ compiler for machines that are not built in ('none': no compilation)
    param : dict, str or list, optional
        machine parameters, {'tool_length': 150} or ['tool_length=0.15m'] (mm, deg)
    quiet : bool, default False
        no model messages ('compiling model ...') on sys.stderr

    A Model pickles by how it was opened (machine, order, engine, compiler, param), so
    multiprocessing and joblib workers open the same model.
    """

    def __init__(self, machine, order=None, *, engine="auto", compiler=None, param=None,
                 quiet=False):
        super().__init__(machine, order, engine=engine, compiler=compiler, param=param,
                         quiet=quiet)

    def __reduce__(self):
        state = dict(self._state)
        if os.path.isfile(state["machine"]):  # a file: the same file from another directory
            state["machine"] = os.path.abspath(state["machine"])
        return (_reopen, (state,))

    # ---- inputs by name, checked -------------------------------------------------------------

    def _rows(self, function, value, what, names, units, fill, check):
        """`value` as a float64 (N, k) or (k,) array in `names` order."""
        columns = _named(value)
        try:
            if columns is None:
                array = np.asarray(value, dtype=np.float64)
            else:
                unknown = [k for k in columns if k not in names]
                if unknown:
                    raise _weilgen.ArgumentError(
                        "%s: %s: unknown name %r (the %s of %s: %s)"
                        % (function, what, unknown[0], what, self.name, ", ".join(names)))
                missing = [n for n in names if n not in columns]
                if missing and fill is None:
                    raise _weilgen.ArgumentError(
                        "%s: %s: no column %r (the %s of %s: %s)"
                        % (function, what, missing[0], what, self.name, ", ".join(names)))
                cols = [np.asarray(columns.get(n, fill), dtype=np.float64) for n in names]
                if any(c.ndim > 1 for c in cols):
                    raise _weilgen.ArgumentError(
                        "%s: %s: each column must be a number or a 1-d array" % (function, what))
                array = np.stack(np.broadcast_arrays(*cols), axis=-1)
        except (TypeError, ValueError) as e:
            if isinstance(e, _weilgen.Error):
                raise
            raise _weilgen.ArgumentError("%s: %s must be an array of numbers, or columns by "
                                         "name (%s)" % (function, what, e)) from None
        if check and array.ndim in (1, 2) and array.shape[-1] == len(names):
            bad = ~np.isfinite(array)
            if bad.any():
                row, col = (np.argwhere(bad)[0].tolist() + [0])[:2] if array.ndim == 2 else \
                    (0, int(np.argwhere(bad)[0][0]))
                v = array[row, col] if array.ndim == 2 else array[col]
                raise _weilgen.ArgumentError(
                    "%s: %s row %d, column %s (%s): %s is not a finite number (NaN, inf or None; "
                    "check=False skips this check)" % (function, what, row, names[col], units[col], v))
        return array

    def _check_params(self, function, params):
        if params is None:
            return
        items = params.items() if isinstance(params, Mapping) else \
            zip(self.params, np.ravel(np.asarray(params, dtype=object)))
        for name, value in items:
            try:
                finite = value is not None and math.isfinite(float(value))
            except (TypeError, ValueError):
                continue  # not a number: the extension says what is wrong
            if not finite:
                raise _weilgen.ArgumentError(
                    "%s: params: %s is %r, not a finite number (check=False skips this check)"
                    % (function, name, value))

    def _warn_travel(self, function, axes):
        rows = np.atleast_2d(axes)
        if rows.ndim != 2 or rows.shape[-1] != len(self.axes):
            return  # a shape the extension refuses
        for k, travel in enumerate(self.axis_ranges):
            if travel is None:
                continue
            lo, hi = travel
            slack = 1e-9 * max(1.0, abs(lo), abs(hi))
            outside = np.flatnonzero((rows[:, k] < lo - slack) | (rows[:, k] > hi + slack))
            if outside.size:
                i = int(outside[0])
                unit = self.axis_units[k]
                warnings.warn(
                    "%s: axes row %d: %s = %s %s is outside the axis range [%s, %s] %s "
                    "(%d of %d rows outside)" % (function, i, self.axes[k], _number(rows[i, k]),
                                                 unit, _number(lo), _number(hi), unit,
                                                 outside.size, rows.shape[0]),
                    _weilgen.Warning, stacklevel=3)

    def deviation(self, axes, errors, params=None, *, check=True):
        """The tool point's deviation: (dx, dy, dz) in mm and (da, db, dc) in rad.

        Parameters
        ----------
        axes : array (N, k) or (k,), or columns by axis name
            axis positions in .axes order and .axis_units (mm, deg); or a dict, a numpy
            structured array or a pandas DataFrame with a column per axis name (a number is
            used for every row). Positions outside an axis's travel give a weilgen.Warning.
        errors : array (N, n) or (n,), or columns by error name
            error values in .errors order and .error_units (mm, rad); or a dict, a structured
            array or a DataFrame by error name (errors not named are 0)
        params : dict or sequence, optional
            machine parameters by name, or in .params order (mm, deg); None: the model's
        check : bool, default True
            refuse NaN, inf and None with a ValueError (weilgen.ArgumentError) naming the row
            and column, and warn about positions outside the travel; False for hot loops

        Returns
        -------
        numpy.ndarray
            (N, 6), or (6,) when both inputs are one row: dx dy dz (mm), da db dc (rad)
        """
        a = self._rows("deviation", axes, "axes", self.axes, self.axis_units, None, check)
        e = self._rows("deviation", errors, "errors", self.errors, self.error_units, 0.0, check)
        if check:
            self._check_params("deviation", params)
            self._warn_travel("deviation", a)
        return _weilgen.Model.deviation(self, a, e, params)

    def coefficients(self, axes, params=None, *, check=True):
        """d(output)/d(error) at zero error: (N, 6, n), or (6, n) for one row of axes.

        Rows dx dy dz in mm per error unit, da db dc in rad per error unit (errors in
        .error_units). axes, params and check as for deviation().
        """
        a = self._rows("coefficients", axes, "axes", self.axes, self.axis_units, None, check)
        if check:
            self._check_params("coefficients", params)
            self._warn_travel("coefficients", a)
        return _weilgen.Model.coefficients(self, a, params)

    def closed_form(self, output=None, notation="iso", format="text"):
        """The closed-form deviation, as `weilgen show` prints it.

        Parameters
        ----------
        output : str, optional
            'dx', 'dy', 'dz', 'da', 'db' or 'dc'; None: every output, one line each
        notation : str, default 'iso'
            'iso' (ISO 230-1 error names) or 'alias' (each error's first alias)
        format : str, default 'text'
            'text' (`weilgen show`), 'latex' (`--format latex`), 'sympy-string' (`--format
            sympy`: Python syntax whose right-hand sides sympy.sympify reads) or 'json' (the
            document of `--format json`, as a dict)

        Returns
        -------
        str
            "dx = ..." lines, each ending in a newline; a dict for format='json'
        """
        fmt = "sympy" if format == "sympy-string" else format
        return self._closed_form(output or "", notation, fmt)
