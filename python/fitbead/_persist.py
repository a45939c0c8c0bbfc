"""Equality, pickling and the saved-result format of fitbead's results.

A saved result is one JSON document (UTF-8), readable with the ``json`` module alone::

    {"format": "fitbead-result", "version": 1, "kind": KIND, "fitbead_version": "...", KIND: {...}}

``KIND`` is ``fit`` (:class:`~fitbead.FitResult`), ``fitset`` (:class:`~fitbead.FitSet`),
``dataset`` (:class:`~fitbead.Dataset`), ``table`` (:class:`~fitbead.Table`) or ``design``
(:class:`~fitbead.Design`). Numbers are JSON numbers written as Python's ``repr`` (the shortest
text that reads back the same double); a number that is not finite is the string ``"NaN"``,
``"Infinity"`` or ``"-Infinity"`` (in numeric arrays and number fields only: the records' text
cells are text, and their empty cells are ``null``, as the CSV files leave them empty). Arrays
are nested lists, with their ``shape`` beside them where it could be lost (an empty axis).
"""

from __future__ import annotations

import json
import math
import os
from typing import Any, Callable, Dict, List, Optional

import numpy as np

FORMAT = "fitbead-result"
VERSION = 1
KINDS = ("fit", "fitset", "dataset", "table", "design")

_NONFINITE = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}


# ---- equality ---------------------------------------------------------------------------------


def _same_array(a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind == "f":
        x, y = np.ascontiguousarray(a), np.ascontiguousarray(b)
        bits = x.view(np.uint8).reshape(x.shape + (-1,)) == y.view(np.uint8).reshape(y.shape + (-1,))
        return bool((bits.all(axis=-1) | (np.isnan(x) & np.isnan(y))).all())
    if a.dtype.kind == "O":
        return all(same(x, y) for x, y in zip(a.ravel(), b.ravel()))
    return bool(np.array_equal(a, b))


def _same_float(a: float, b: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


def _same_attrs(a: Any, b: Any) -> bool:
    """The attributes of two instances of a subclass of dict, list or tuple (a Table's
    ``shape``, a FitSet's ``notes``)."""
    if type(a) in (dict, list, tuple):
        return True
    return same(dict(getattr(a, "__dict__", {})), dict(getattr(b, "__dict__", {})))


def same(a: Any, b: Any) -> bool:
    """Whether ``a`` and ``b`` are the same value: of one type, floats bit for bit (-0.0 is
    not 0.0) except that every NaN equals every NaN, arrays of one shape and dtype with such
    elements, containers element by element with their attributes (a Table's ``shape``);
    other objects by their own ``==``."""
    if a is b:
        return True
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        return _same_array(a, b)
    if isinstance(a, float):
        return _same_float(a, b)
    if isinstance(a, np.generic):
        return _same_array(np.asarray(a), np.asarray(b))
    if isinstance(a, dict):
        if a.keys() != b.keys() or not all(same(a[k], b[k]) for k in a):
            return False
        return _same_attrs(a, b)
    if isinstance(a, (list, tuple)):
        if len(a) != len(b) or not all(same(x, y) for x, y in zip(a, b)):
            return False
        return _same_attrs(a, b)
    return bool(a == b)


# ---- JSON encoding ----------------------------------------------------------------------------


def _number(x: float) -> Any:
    if math.isfinite(x):
        return x
    return "NaN" if math.isnan(x) else ("Infinity" if x > 0 else "-Infinity")


def encode(x: Any, where: str = "") -> Any:
    """``x`` as JSON values: numpy arrays as nested lists, numbers that are not finite as
    their strings, tuples as lists; anything else JSON cannot hold is a FitbeadError naming
    ``where``."""
    if x is None or isinstance(x, (str, bool)):
        return x
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return _number(float(x))
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.ndarray):
        if x.dtype.kind == "f":
            a = np.asarray(x, dtype=np.float64)
            if np.isfinite(a).all():
                return a.tolist()
            return encode(a.astype(object), where)
        if x.dtype.kind in "biu":
            return x.tolist()
        if x.dtype.kind == "O":
            return encode(x.tolist(), where)
        raise _Bad(f"{where}: an array of dtype {x.dtype} cannot be saved")
    if isinstance(x, dict):
        return {str(k): encode(v, f"{where}.{k}" if where else str(k)) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [encode(v, where) for v in x]
    raise _Bad(f"{where}: a value of type {type(x).__name__} cannot be saved")


class _Bad(Exception):
    """A value that cannot be saved, or a saved document that is not what it should be (the
    message names where; the caller adds the file)."""


# ---- JSON decoding: readers that check what they read ----------------------------------------


def _get(d: Any, key: str, where: str) -> Any:
    if not isinstance(d, dict):
        raise _Bad(f"{where}: expected an object, found {_kind(d)}")
    if key not in d:
        raise _Bad(f"{where}: no {key!r}")
    return d[key]


def _kind(x: Any) -> str:
    return {dict: "an object", list: "a list", str: "text", bool: "true/false", type(None): "null"}.get(
        type(x), "a number" if isinstance(x, (int, float)) else type(x).__name__
    )


def _typed(x: Any, types: tuple, what: str, where: str) -> Any:
    if isinstance(x, bool) and bool not in types:
        raise _Bad(f"{where}: expected {what}, found {_kind(x)}")
    if not isinstance(x, types):
        raise _Bad(f"{where}: expected {what}, found {_kind(x)}")
    return x


def _text(x: Any, where: str) -> str:
    return _typed(x, (str,), "text", where)


def _opt_text(x: Any, where: str) -> Optional[str]:
    return None if x is None else _text(x, where)


def _int(x: Any, where: str) -> int:
    return _typed(x, (int,), "an integer", where)


def _bool(x: Any, where: str) -> bool:
    return _typed(x, (bool,), "true or false", where)


def _list(x: Any, where: str) -> list:
    return _typed(x, (list,), "a list", where)


def _float(x: Any, where: str) -> float:
    if isinstance(x, str):
        if x in _NONFINITE:
            return _NONFINITE[x]
        raise _Bad(f"{where}: expected a number, found text {x!r}")
    return float(_typed(x, (int, float), "a number", where))


def _opt_float(x: Any, where: str) -> Optional[float]:
    return None if x is None else _float(x, where)


def _shape(x: Any, where: str) -> tuple:
    return tuple(_int(n, where) for n in _list(x, where))


def _objects(x: Any, where: str, shape: Optional[tuple]) -> np.ndarray:
    """Nested lists (or a scalar, for shape ``()``) as an object array of ``shape`` (default:
    the nesting's)."""
    try:
        a = np.array(x, dtype=object)
    except ValueError as e:
        raise _Bad(f"{where}: not an array ({e})") from None
    if shape is not None:
        if a.size != int(np.prod(shape)) or (a.size and a.shape != shape):
            raise _Bad(f"{where}: shape {a.shape}, expected {shape}")
        a = a.reshape(shape)
    return a


def _floats(x: Any, where: str, shape: Optional[tuple] = None) -> np.ndarray:
    """A float64 array from nested lists of numbers, those not finite as their strings (of
    ``shape`` where given: an empty axis leaves no trace in the lists)."""
    try:
        a = np.array(x, dtype=np.float64)
    except (ValueError, TypeError):
        a = None
    if a is None or (shape is not None and a.shape != shape) or np.isnan(a).any():
        # The slow way, to say what is wrong, to give an empty array its shape, or to tell a
        # NaN written as "NaN" from a null (which numpy would read as NaN too).
        o = _objects(x, where, shape)
        a = np.empty(o.shape, dtype=np.float64)
        flat = a.reshape(-1)
        for i, v in enumerate(o.ravel()):
            flat[i] = _float(v, where)
    return a


def _column(x: Any, where: str) -> np.ndarray:
    """A 1-D float64 array (a column of points)."""
    a = _floats(_list(x, where), where)
    if a.ndim != 1:
        raise _Bad(f"{where}: expected a list of numbers, found {a.ndim} dimensions")
    return a


def _records(x: Any, where: str) -> List[Dict[str, Any]]:
    """A list of report records: objects of text, numbers, true/false and null."""
    out = []
    for i, r in enumerate(_list(x, where)):
        w = f"{where}[{i}]"
        _typed(r, (dict,), "an object", w)
        for k, v in r.items():
            if v is not None and not isinstance(v, (str, int, float, bool)):
                raise _Bad(f"{w}.{k}: expected text, a number, true/false or null, found {_kind(v)}")
        out.append(dict(r))
    return out


# ---- a fit ------------------------------------------------------------------------------------


def fit_state(core: Any) -> Dict[str, Any]:
    """Everything a fit's core gives, as plain values: what makes the fit again
    (:class:`StoredFit`)."""
    d = core.draws()
    return {
        "name": core.name()[0],
        "series": core.name()[1],
        "params": core.params(),
        "param_bounds": [tuple(b) for b in core.param_bounds()],
        "param_fixed": list(core.param_fixed()),
        "param_starts": list(core.param_starts()),
        "stats": core.stats(),
        "residuals": core.residual_records(),
        "correlations": core.correlation_records(),
        "correlation": core.correlation(),
        "points": dict(core.points()),
        "draws": None
        if d is None
        else {"chains": d[0], "log_posterior": d[1], "burn_in": d[2], "thin": d[3], "interrupted": d[4]},
        "report": core.report(),
        "absurd_misfit": core.absurd_misfit(),
        "misfit_warning": core.misfit_warning(),
        "chi2_p_value": core.chi2_p_value(),
    }


class StoredFit:
    """A fit's core made again from its state (:func:`fit_state`): the same answers as the
    compiled core it was taken from, for a fit unpickled or loaded."""

    def __init__(self, state: Dict[str, Any]) -> None:
        self._s = state

    def name(self):
        return self._s["name"], self._s["series"]

    def params(self):
        return [dict(r) for r in self._s["params"]]

    def param_bounds(self):
        return [tuple(b) for b in self._s["param_bounds"]]

    def param_fixed(self):
        return list(self._s["param_fixed"])

    def param_starts(self):
        return list(self._s["param_starts"])

    def stats(self):
        return dict(self._s["stats"])

    def residual_records(self):
        return [dict(r) for r in self._s["residuals"]]

    def correlation_records(self):
        return [dict(r) for r in self._s["correlations"]]

    def correlation(self):
        c = self._s["correlation"]
        return None if c is None else [list(row) for row in c]

    def points(self):
        return {k: (list(v) if k == "series" else np.array(v, dtype=np.float64)) for k, v in self._s["points"].items()}

    def draws(self):
        d = self._s["draws"]
        if d is None:
            return None
        return (np.array(d["chains"]), np.array(d["log_posterior"]), d["burn_in"], d["thin"], d["interrupted"])

    def report(self):
        return self._s["report"]

    def absurd_misfit(self):
        return self._s["absurd_misfit"]

    def misfit_warning(self):
        return self._s["misfit_warning"]

    def chi2_p_value(self):
        return self._s["chi2_p_value"]

    def state(self) -> Dict[str, Any]:
        return self._s


def decode_fit(x: Any, where: str) -> Dict[str, Any]:
    """A fit's state from its saved JSON object (:func:`fit_state`'s keys)."""
    g = lambda k: _get(x, k, where)  # noqa: E731
    w = lambda k: f"{where}.{k}"  # noqa: E731
    bounds = []
    for i, b in enumerate(_list(g("param_bounds"), w("param_bounds"))):
        pair = _list(b, f"{w('param_bounds')}[{i}]")
        if len(pair) != 2:
            raise _Bad(f"{w('param_bounds')}[{i}]: expected [low, high]")
        bounds.append((_float(pair[0], f"{w('param_bounds')}[{i}]"), _float(pair[1], f"{w('param_bounds')}[{i}]")))
    residuals = _records(g("residuals"), w("residuals"))
    for i, r in enumerate(residuals):
        for k in ("delta_fit_deg", "delta_residual"):
            if k in r:
                r[k] = _opt_float(r[k], f"{w('residuals')}[{i}].{k}")
    corr = g("correlation")
    if corr is not None:
        corr = [[_float(v, w("correlation")) for v in _list(row, w("correlation"))] for row in _list(corr, w("correlation"))]
    pts_in = _typed(g("points"), (dict,), "an object", w("points"))
    points: Dict[str, Any] = {}
    for k, v in pts_in.items():
        if k == "series":
            points[k] = [_text(s, f"{w('points')}.series") for s in _list(v, f"{w('points')}.series")]
        else:
            points[k] = _column(v, f"{w('points')}.{k}")
    d = g("draws")
    draws = None
    if d is not None:
        wd = w("draws")
        shape = _shape(_get(d, "shape", wd), f"{wd}.shape")
        if len(shape) != 3:
            raise _Bad(f"{wd}.shape: expected [walkers, kept steps, parameters]")
        draws = {
            "chains": _floats(_get(d, "chains", wd), f"{wd}.chains", shape),
            "log_posterior": _floats(_get(d, "log_posterior", wd), f"{wd}.log_posterior", shape[:2]),
            "burn_in": _int(_get(d, "burn_in", wd), f"{wd}.burn_in"),
            "thin": _int(_get(d, "thin", wd), f"{wd}.thin"),
            "interrupted": _bool(_get(d, "interrupted", wd), f"{wd}.interrupted"),
        }
    stats = _records([g("stats")], w("stats"))[0]
    # Which parameters were held and where each fit started (absent from a file saved before
    # fits could hold parameters: none held, no start said).
    n = len(bounds)
    fixed = [_bool(v, w("param_fixed")) for v in _list(x.get("param_fixed", [False] * n), w("param_fixed"))]
    starts = [_opt_float(v, w("param_starts")) for v in _list(x.get("param_starts", [None] * n), w("param_starts"))]
    if len(fixed) != n or len(starts) != n:
        raise _Bad(f"{where}: param_fixed and param_starts need one entry per parameter ({n})")
    return {
        "name": _text(g("name"), w("name")),
        "series": _text(g("series"), w("series")),
        "params": _records(g("params"), w("params")),
        "param_bounds": bounds,
        "param_fixed": fixed,
        "param_starts": starts,
        "stats": stats,
        "residuals": residuals,
        "correlations": _records(g("correlations"), w("correlations")),
        "correlation": corr,
        "points": points,
        "draws": draws,
        "report": _text(g("report"), w("report")),
        "absurd_misfit": _opt_text(g("absurd_misfit"), w("absurd_misfit")),
        "misfit_warning": _opt_text(g("misfit_warning"), w("misfit_warning")),
        "chi2_p_value": _opt_float(g("chi2_p_value"), w("chi2_p_value")),
    }


def encode_fit(state: Dict[str, Any], context: Dict[str, Any], where: str) -> Dict[str, Any]:
    """A fit's state and context as a JSON object; the draws with their shape."""
    out = encode(state, where)
    if state["draws"] is not None:
        out["draws"]["shape"] = list(state["draws"]["chains"].shape)
    out["context"] = encode(context, f"{where}.context")
    return out


def decode_context(x: Any, where: str) -> Dict[str, Any]:
    ctx = _typed(x, (dict,), "an object", where)
    for k, v in ctx.items():
        if v is not None and not isinstance(v, (str, int, float, bool)):
            raise _Bad(f"{where}.{k}: expected text, a number, true/false or null")
    return dict(ctx)


# ---- a table ----------------------------------------------------------------------------------


def encode_table(t: Dict[str, Any], shape: tuple, critical_xi: Any, where: str) -> Dict[str, Any]:
    cols = {}
    for name, col in t.items():
        a = np.asarray(col)
        if a.dtype.kind == "O" and not all(v is None or isinstance(v, str) for v in a.ravel()):
            raise _Bad(f"{where}.{name}: an object column holds other values than text")
        if a.dtype.kind not in "fbiuO":
            raise _Bad(f"{where}.{name}: an array of dtype {a.dtype} cannot be saved")
        cols[str(name)] = {"dtype": "object" if a.dtype.kind == "O" else a.dtype.name, "shape": list(a.shape), "values": encode(a, f"{where}.{name}")}
    out: Dict[str, Any] = {"shape": [int(n) for n in shape], "columns": cols}
    if critical_xi is not _MISSING:
        out["critical_xi"] = encode(critical_xi, f"{where}.critical_xi")
    return out


_MISSING = object()


def decode_table(x: Any, where: str, make: Callable[[], Any]) -> Any:
    t = make()
    shape = _shape(_get(x, "shape", where), f"{where}.shape")
    cols = _typed(_get(x, "columns", where), (dict,), "an object", f"{where}.columns")
    for name, c in cols.items():
        w = f"{where}.columns.{name}"
        dtype = _text(_get(c, "dtype", w), f"{w}.dtype")
        cshape = _shape(_get(c, "shape", w), f"{w}.shape")
        values = _get(c, "values", w)
        if dtype == "float64":
            a = _floats(values, f"{w}.values", cshape)
        elif dtype == "object":
            a = _objects(values, f"{w}.values", cshape)
            for v in a.ravel():
                if v is not None and not isinstance(v, str):
                    raise _Bad(f"{w}.values: expected text or null, found {_kind(v)}")
        else:
            try:
                dt = np.dtype(dtype)
            except TypeError:
                raise _Bad(f"{w}.dtype: {dtype!r} is not a dtype") from None
            if dt.kind not in "biu":
                raise _Bad(f"{w}.dtype: {dtype!r}: expected float64, object or an integer or bool dtype")
            o = _objects(values, f"{w}.values", cshape)
            for v in o.ravel():
                if not isinstance(v, int) or (isinstance(v, bool) != (dt.kind == "b")):
                    raise _Bad(f"{w}.values: expected {'true/false' if dt.kind == 'b' else 'integers'}, found {_kind(v)}")
            try:
                a = o.astype(dt)
            except (ValueError, TypeError, OverflowError) as e:
                raise _Bad(f"{w}.values: not an array of {dtype} ({e})") from None
        t[name] = a
    t.shape = shape
    if "critical_xi" in x:
        t.critical_xi = _opt_float(x["critical_xi"], f"{where}.critical_xi")
    return t


# ---- a design ---------------------------------------------------------------------------------


def decode_design(x: Any, where: str) -> Dict[str, Any]:
    """The raw dict a :class:`~fitbead.Design` is made from, from its saved JSON object."""

    def rows(r: Any, w: str) -> Dict[str, Any]:
        return {
            "series": [_text(s, f"{w}.series") for s in _list(_get(r, "series", w), f"{w}.series")],
            "xi": [_float(v, f"{w}.xi") for v in _list(_get(r, "xi", w), f"{w}.xi")],
            "delta_deg": [_float(v, f"{w}.delta_deg") for v in _list(_get(r, "delta_deg", w), f"{w}.delta_deg")],
            "replicates": [_int(v, f"{w}.replicates") for v in _list(_get(r, "replicates", w), f"{w}.replicates")],
        }

    def pair(v: Any, w: str, conv: Callable[[Any, str], Any]) -> Any:
        if v is None:
            return None
        p = _list(v, w)
        if len(p) != 2:
            raise _Bad(f"{w}: expected a pair")
        return (conv(p[0], w), conv(p[1], w))

    errors = []
    for i, e in enumerate(_list(_get(x, "errors", where), f"{where}.errors")):
        w = f"{where}.errors[{i}]"
        errors.append(
            {
                "parameter": _text(_get(e, "parameter", w), w),
                "guess": _float(_get(e, "guess", w), f"{w}.guess"),
                "stderr_design": _float(_get(e, "stderr_design", w), f"{w}.stderr_design"),
                "stderr_even": _float(_get(e, "stderr_even", w), f"{w}.stderr_even"),
            }
        )
    return {
        "design": rows(_get(x, "design", where), f"{where}.design"),
        "even": rows(_get(x, "even", where), f"{where}.even"),
        "errors": errors,
        "target": _opt_text(_get(x, "target", where), f"{where}.target"),
        "efficiency": _float(_get(x, "efficiency", where), f"{where}.efficiency"),
        "gap": _float(_get(x, "gap", where), f"{where}.gap"),
        "discrimination": pair(_get(x, "discrimination", where), f"{where}.discrimination", _float),
        "points_needed": pair(_get(x, "points_needed", where), f"{where}.points_needed", _float),
        "ranges": [pair(r, f"{where}.ranges[{i}]", _float) for i, r in enumerate(_list(_get(x, "ranges", where), f"{where}.ranges"))],
        "bayes": pair(_get(x, "bayes", where), f"{where}.bayes", _int),
        "steady": [
            {
                _text(k, f"{where}.steady[{i}]"): pair(v, f"{where}.steady[{i}].{k}", _opt_float)
                for k, v in _typed(row, (dict,), "an object", f"{where}.steady[{i}]").items()
            }
            for i, row in enumerate(_list(x.get("steady", []) if isinstance(x, dict) else [], f"{where}.steady"))
        ],
    }


# ---- a data set -------------------------------------------------------------------------------

DATASET_ARRAYS = ("xi", "delta_deg", "v", "sigma_v", "rho", "f", "sigma_delta_deg")


def decode_dataset(x: Any, where: str) -> Dict[str, Any]:
    """A data set's state (the compiled core's ``state()``) from its saved JSON object."""
    origin = _text(_get(x, "origin", where), f"{where}.origin")
    if origin == "text":
        out: Dict[str, Any] = {"origin": origin}
        out["source"] = _text(_get(x, "source", where), f"{where}.source")
        out["text"] = _text(_get(x, "text", where), f"{where}.text")
        for k in ("rho", "f", "g", "sigma_delta"):
            out[k] = _float(_get(x, k, where), f"{where}.{k}")
        return out
    if origin == "arrays":
        out = {"origin": origin, "series": [_text(s, f"{where}.series") for s in _list(_get(x, "series", where), f"{where}.series")]}
        for k in DATASET_ARRAYS:
            out[k] = _column(_get(x, k, where), f"{where}.{k}")
        return out
    raise _Bad(f"{where}.origin: {origin!r}: expected 'text' or 'arrays'")


# ---- files ------------------------------------------------------------------------------------


def write(path: Any, kind: str, body: Any, version: str) -> None:
    """Writes the document of a ``kind`` result atomically (a temporary file renamed over
    ``path``)."""
    import tempfile

    doc = {"format": FORMAT, "version": VERSION, "kind": kind, "fitbead_version": version, kind: body}
    text = json.dumps(doc, allow_nan=False, ensure_ascii=False, separators=(",", ":"))
    target = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(target))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".fitbead-result-")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.write("\n")
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read(path: Any):
    """The kind and body of the document at ``path``, checked: the format, a version this
    fitbead reads, a known kind (a :class:`_Bad` otherwise)."""
    target = os.fspath(path)
    try:
        with open(target, "rb") as fh:
            raw = fh.read()
    except OSError as e:
        raise _Bad(f"cannot read: {e.strerror or e}") from None
    try:
        doc = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise _Bad(f"not a fitbead result: not UTF-8 text ({e})") from None
    except ValueError as e:
        raise _Bad(f"not a fitbead result: not JSON ({e})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        found = doc.get("format") if isinstance(doc, dict) else None
        raise _Bad(f"not a fitbead result: its format is {found!r}, expected {FORMAT!r}")
    version = doc.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise _Bad(f"version {version!r}: expected a whole number from 1")
    if version > VERSION:
        raise _Bad(f"version {version} is newer than this fitbead reads (up to {VERSION}): upgrade fitbead")
    kind = doc.get("kind")
    if kind not in KINDS:
        raise _Bad(f"kind {kind!r}: expected one of {', '.join(KINDS)}")
    if kind not in doc:
        raise _Bad(f"no {kind!r}: the {kind} is missing")
    return kind, doc[kind]
