"""The implementation of the ``fitbead`` package (its public names are re-exported by
``fitbead/__init__.py``, which lists them in ``__all__``)."""

from __future__ import annotations

import html as _html
import math
import re
import os
import warnings
from dataclasses import dataclass, field
from statistics import NormalDist
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _fitbead as _core
from . import _persist
from ._persist import same as _same

__version__: str = _core.version()

ArrayLike = Union[float, Sequence[float], np.ndarray]

MODELS = ("stick", "stick-approx", "slip", "slip-approx", "stickslip", "contact", "jan", "jaeger", "auto")
"""The models :func:`forward` evaluates (the command line's names)."""

K_MODELS = ("stick", "stick-approx", "slip", "slip-approx", "stickslip", "contact", "auto")
"""The models :func:`invert_k` inverts."""


FitbeadError = _core.FitbeadError
FitbeadError.__module__ = "fitbead"
"""Raised on bad input or a computation that cannot be done (a ``ValueError``): the command
line's message, naming the file, line, column and value where it has them."""


class FitbeadWarning(UserWarning):
    """Base class of every warning fitbead gives (the command line prints the same text on
    stderr)."""


class UnitWarning(FitbeadWarning):
    """The data look like a unit mistake: slopes in radians, velocities in m/s, mm/s or cm/s
    in the dimensionless column, radii in millimetres, or a reduced χ² far above 1 with σ
    given."""


class MisfitWarning(FitbeadWarning):
    """A fit with σ given does not describe the data within their σ: the χ² tail probability
    P(χ²_dof ≥ χ²) is below 0.001, so its intervals, which assume the model holds, are too
    narrow."""


class OutlierWarning(MisfitWarning):
    """A few points lie far from the fitted curve (normalised residual beyond 4, and 4 robust
    standard deviations from the others): the warning names each (series, slope, velocity,
    residual) and the misfit of the others. A misread value, or a run that had not reached
    its steady state, is the usual cause; the fit, which those points pull, is suspect until
    they are checked."""


class ConvergenceWarning(FitbeadWarning):
    """A fit stopped without converging (least squares: its termination; MCMC: R̂ or ESS
    short of the target, or the run cut short)."""


class BoundWarning(FitbeadWarning):
    """A fitted parameter sits on a bound of its box (its interval is one-sided)."""


class ColumnWarning(FitbeadWarning):
    """A column of the data that fitbead does not read looks misspelt or misnamed: close to
    a known name (``sigma`` for ``sigma_v``), or named like an uncertainty (``sigma…``,
    ``err…``, ``sd…``, ``std…``, ``unc…``) while the data lack the uncertainty column it
    most likely means. Such a column is ignored, which can change the weighting silently;
    ``strict_columns=True`` refuses any column fitbead does not read."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped a posterior run (``method="mcmc"``) of :func:`fit_klaw`,
    :func:`fit_jan`, :func:`fit_jaeger` or :func:`report`: a ``KeyboardInterrupt`` that keeps
    what the run made, as the command line writes its outputs when interrupted.

    ``result`` is the partial result, what the call would have returned (a
    :class:`FitResult`, a :class:`FitSet` or a :class:`Report`): the draws so far,
    ``interrupted`` True on each fit (those the run had not started yet have no draws), every
    parameter row's note starting ``interrupted``, not converged (a ``draws`` file or a
    report directory, when asked for, is written first)::

        try:
            post = fitbead.fit_jaeger(data, method="mcmc", min_ess=4000)
        except fitbead.Interrupted as e:
            post = e.result

    An exception a signal handler of the program raises itself (a ``TimeoutError`` from a
    SIGALRM handler) stops the run as Ctrl-C does and reaches the caller unchanged, without
    the draws."""

    def __init__(self, message: str, result: Any = None) -> None:
        super().__init__(message)
        self.result = result
        """The partial result: the draws so far (see the class)."""

    def __reduce__(self):
        return (type(self), (str(self), self.result))


def _stopped(signal: Optional[BaseException], result: Any) -> None:
    """Raises the exception of the signal that stopped a fit (None: none did): Ctrl-C as
    :class:`Interrupted` carrying ``result``, a handler's own exception unchanged."""
    if signal is None:
        return
    if isinstance(signal, KeyboardInterrupt):
        if isinstance(result, Report):
            what = "the report of the draws so far"
        else:
            fits = result if isinstance(result, list) else [result]
            sampled = sum(1 for f in fits if f.draws is not None and f.draws.size > 0)
            what = f"the draws so far ({sampled} of {len(fits)} fits sampled)"
        raise Interrupted(f"interrupted: {what}, in this exception's result", result) from None
    raise signal


_PACKAGE_DIR = __file__.rsplit("/", 1)[0] if "/" in __file__ else ""


def _warn(message: str, category: type) -> None:
    """``warnings.warn`` attributed to the first caller outside this package (the user's
    line, not fitbead's)."""
    import sys

    level, frame = 2, sys._getframe(1)
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE_DIR):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)


def threads() -> int:
    """Number of threads the vectorised functions use (rayon's pool; in a process forked
    after a fitbead call, the pool of its own that the process builds on its first call, of
    the same size)."""
    return _core.threads()


class Table(dict):
    """The columns of a vectorised result: a dict of numpy arrays of one shape.

    Numeric columns are float64 with NaN where the command line leaves a cell empty; text
    columns (``status``, ``regime``, ``message``, ...) are object arrays of ``str``. The column
    names are the command line's CSV columns.
    """

    shape: Tuple[int, ...] = ()

    def to_pandas(self):
        """The columns as a pandas DataFrame (flattened; needs pandas)."""
        import pandas as pd

        return pd.DataFrame({k: np.ravel(v) for k, v in self.items()})

    def __repr__(self) -> str:
        cols = ", ".join(self.keys())
        return f"Table(shape={self.shape}, columns=[{cols}])"

    def __eq__(self, other: Any) -> bool:
        """The same columns, each of one shape and dtype and equal element by element (floats
        bit for bit, NaN equal to NaN), and against a Table the same ``shape`` and attributes
        (``critical_xi``); against a plain dict the columns only."""
        if isinstance(other, Table):
            return _same(self, other) if type(self) is type(other) else False
        if isinstance(other, dict):
            return _same(dict(self), dict(other))
        return NotImplemented

    def __ne__(self, other: Any) -> bool:
        eq = self.__eq__(other)
        return eq if eq is NotImplemented else not eq

    __hash__ = None  # type: ignore[assignment]

    def save(self, path: Any) -> None:
        """Writes the table to a JSON file that :func:`load` reads back (the format:
        :func:`load`): its columns with their dtypes and shapes, ``shape`` and
        ``critical_xi``; written atomically.

        Parameters
        ----------
        path : str or path-like
            The file to write (replaced if it exists).

        Raises
        ------
        FitbeadError
            A column fitbead cannot save (a dtype other than float, integer, bool or text).
        """
        _save(path, "table", lambda: self._json("table"))

    def _json(self, where: str) -> Dict[str, Any]:
        return _persist.encode_table(self, self.shape, getattr(self, "critical_xi", _persist._MISSING), where)


def _as_f64(name: str, x: Any) -> np.ndarray:
    """``x`` as float64; a masked array with masked entries and complex numbers are refused
    (their mask or imaginary part would otherwise be dropped silently)."""
    if isinstance(x, np.ma.MaskedArray) and np.ma.getmaskarray(x).any():
        raise FitbeadError(
            f"{name}: a masked array with {int(np.ma.count_masked(x))} masked entries; "
            "fill them (e.g. .filled(np.nan)) or leave those points out"
        )
    try:
        complex_input = np.iscomplexobj(x)
    except (TypeError, ValueError):
        complex_input = False
    if complex_input:
        raise FitbeadError(f"{name}: complex numbers are not accepted; pass real numbers (e.g. .real)")
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise FitbeadError(f"{name}: expected numbers ({e})") from None
    return a


def _model_name(model: Any) -> Any:
    """A model name in any case, as the command line takes it."""
    return model.strip().lower() if isinstance(model, str) else model


def _flat(a: np.ndarray) -> np.ndarray:
    """``a`` flattened to a C-contiguous, aligned float64 array (arrays unpickled from
    out-of-band buffers, as Dask's workers receive them, may be unaligned)."""
    return np.require(np.ascontiguousarray(a, dtype=np.float64).reshape(-1), requirements=["C", "A"])


def _broadcast(named: Mapping[str, Any]) -> Tuple[Tuple[int, ...], Dict[str, Optional[np.ndarray]]]:
    """Broadcasts the non-None arrays together; returns the shape and flat contiguous arrays."""
    keys = [k for k, v in named.items() if v is not None]
    arrays = [_as_f64(k, named[k]) for k in keys]
    try:
        b = np.broadcast_arrays(*arrays)
    except ValueError as e:
        shapes = ", ".join(f"{k} {a.shape}" for k, a in zip(keys, arrays))
        raise FitbeadError(f"arguments do not broadcast together: {shapes}") from e
    shape = b[0].shape if b else ()
    flat: Dict[str, Optional[np.ndarray]] = {k: None for k in named}
    for k, a in zip(keys, b):
        flat[k] = _flat(a)
    return shape, flat


def _table(raw: Mapping[str, Any], shape: Tuple[int, ...]) -> Table:
    t = Table()
    for k, v in raw.items():
        if isinstance(v, tuple) and len(v) == 3:
            at, values, n = v
            # empty + fill: np.full(n, "", dtype=object) takes 4 times as long
            # (17 against 4.4 ms for 1,000,000 rows).
            arr = np.empty(n, dtype=object)
            arr.fill("")
            if len(values):
                arr[at] = np.asarray(values, dtype=object)
            t[k] = arr.reshape(shape)
        elif isinstance(v, tuple):
            codes, names = v
            arr = np.asarray(names, dtype=object)[codes] if len(names) else np.empty(0, dtype=object)
            t[k] = arr.reshape(shape)
        else:
            t[k] = np.asarray(v).reshape(shape)
    t.shape = shape
    return t


def _ordered(t: Table, names: Sequence[str]) -> Table:
    """``t`` with its columns in the command line's order ``names`` (every name must be a
    column of ``t`` and every column a name: the binding and the command line share the list)."""
    missing = [n for n in names if n not in t]
    extra = [k for k in t if k not in names]
    if missing or extra:
        raise RuntimeError(f"fitbead: columns differ from the command line's: missing {missing}, extra {extra}")
    out = Table((n, t[n]) for n in names)
    out.shape = t.shape
    return out


def forward(
    model: str,
    xi: ArrayLike,
    delta_deg: ArrayLike,
    K: Union[str, ArrayLike] = "adjusted",
    rho: ArrayLike = 0.4,
    f: ArrayLike = 0.1,
    *,
    mu: Optional[ArrayLike] = None,
    a1: Optional[ArrayLike] = None,
    a2: Optional[ArrayLike] = None,
    a3: Optional[ArrayLike] = None,
    c: Optional[float] = None,
    branch: str = "upper",
    spin: str = "roll",
    tol: float = 1e-14,
    **params: Any,
) -> Table:
    """The steady state of every scene under one model (``fitbead forward``).

    Parameters
    ----------
    model : str
        ``stick`` (pure rolling), ``stick-approx``, ``slip``, ``slip-approx``, ``stickslip``,
        ``contact`` (the general contact model), ``jan`` (eq 74), ``jaeger`` (eqs 80–84),
        ``auto`` (the simplest model meeting ``tol``) or ``md`` (molecular dynamics, one run per
        scene: seconds each; the columns of ``fitbead forward --model md``: the scene's ``xi``,
        ``delta_deg``, ``rho``, ``f``, then the md run's).
    xi, delta_deg : array_like
        Radius ratio ξ = r/R (> 0) and slope δ in degrees; arrays broadcast together with
        every other array argument.
    K : str or array_like, default "adjusted"
        The collision law: numbers (K per scene) or a law name — ``adjusted`` (the paper's
        fitted law), ``cos2a``, ``impact`` or ``c=VALUE``.
    rho, f : array_like
        Gyration parameter ρ (0.4 a sphere) and Coulomb friction f.
    mu : array_like, optional
        Jan's μ (eq 74); with ``lambda`` (a keyword Python reserves: pass it as
        ``**{"lambda": x}`` or through ``**fit.values``). Default: the paper's eqs 75–76 at
        each scene's α; NaN entries take the default too.
    a1, a2, a3 : array_like, optional
        Jaeger's coefficients (required for ``jaeger``).
    c : float, optional
        The K(α) law's c (eq 69's law K = cos 2α + c sin²α sin 2α): the same as
        ``K=f"c={c}"``.
    branch : str, default "upper"
        Jaeger's root of eq 84 when there are two: ``upper`` or ``lower``.
    spin : str, default "roll"
        The contact model's spin rule at a collision: ``roll``, ``keep``, ``impact`` or
        ``factor=L``.
    tol : float, default 1e-14
        The contact model's quadrature tolerance; the target tolerance of ``auto``.
    **params
        ``lambda`` (Jan's λ), under the name the command line and the fit reports use;
        ``md_preset`` (``ristow``, the default, or ``steel``) for ``md``.

    Returns
    -------
    Table
        The command line's columns, in its order: ``xi``, ``delta_deg`` (broadcast), ``v``
        (mean velocity v̄, NaN without a steady state), ``regime`` (A, B, C), ``status``
        (``ok``, ``stops``, ``lift-off``, ``no-steady-state``, ``invalid``,
        ``no-fixed-point``), ``K_used``, ``final_velocity``, ``initial_velocity``,
        ``contact_time``, ``theta_G_deg`` (Θ_G, eq 36), ``map_slope``,
        ``other_fixed_point``, ``phases``, ``message``; the contact model adds its energy
        budget and phase columns, ``auto`` adds ``model_used`` and ``reason``.

    Raises
    ------
    FitbeadError
        A bad value, naming the argument, the row and the value.

    Examples
    --------
    >>> import numpy as np, fitbead
    >>> out = fitbead.forward("stick", xi=1.0, delta_deg=np.linspace(5, 25, 5))
    >>> list(out["status"])
    ['stops', 'ok', 'ok', 'ok', 'lift-off']
    """
    lam = params.pop("lambda", None)
    if "lam" in params:
        if lam is not None:
            raise TypeError("forward: give lambda once (lam is its old name)")
        warnings.warn("forward: lam is now lambda (the command line's name)", DeprecationWarning, stacklevel=2)
        lam = params.pop("lam")
    params.pop("sigma_scale", None)
    model = _model_name(model)
    md_preset = params.pop("md_preset", "ristow")
    if params:
        raise TypeError(f"forward: unexpected arguments {sorted(params)}")
    if model == "md":
        return _forward_md(xi, delta_deg, rho, f, md_preset)
    if model not in MODELS:
        raise FitbeadError(f"model = {model!r}: expected one of {', '.join(MODELS)}, md")
    k_arr = None
    law = "adjusted"
    if c is not None:
        if not (isinstance(K, str) and K == "adjusted"):
            raise TypeError("forward: give K or c, not both")
        K = f"c={float(c)!r}"
    if isinstance(K, str):
        law = K
    else:
        k_arr = K
    shape, a = _broadcast(
        {"xi": xi, "delta_deg": delta_deg, "rho": rho, "f": f, "K": k_arr, "lam": lam, "mu": mu, "a1": a1, "a2": a2, "a3": a3}
    )
    raw = _core.forward(
        model,
        a["xi"],
        a["delta_deg"],
        a["rho"],
        a["f"],
        k=a["K"],
        law=law,
        lam=a["lam"],
        mu=a["mu"],
        a1=a["a1"],
        a2=a["a2"],
        a3=a["a3"],
        branch=branch,
        spin=spin,
        tol=tol,
    )
    t = _table(raw, shape)
    t["xi"] = a["xi"].reshape(shape).copy()  # type: ignore[union-attr]
    t["delta_deg"] = a["delta_deg"].reshape(shape).copy()  # type: ignore[union-attr]
    return _ordered(t, ["xi", "delta_deg", *_core.output_columns("forward", model)])


def _forward_md(xi: ArrayLike, delta_deg: ArrayLike, rho: ArrayLike, f: ArrayLike, md_preset: str) -> Table:
    """``forward("md", ...)``: one molecular-dynamics run per scene (``fitbead forward --model
    md`` on the scenes written as its CSV input)."""
    shape, a = _broadcast({"xi": xi, "delta_deg": delta_deg, "rho": rho, "f": f})
    lines = ["xi,delta_deg,rho,f"]
    for i in range(a["xi"].size):  # type: ignore[union-attr]
        lines.append(",".join(repr(float(a[k][i])) for k in ("xi", "delta_deg", "rho", "f")))  # type: ignore[index]
    t = _csv_table(_core.forward_md("\n".join(lines) + "\n", md_preset=str(md_preset)))
    for k in t:
        t[k] = t[k].reshape(shape)
    t.shape = shape
    return t


def invert_k(
    model: str,
    xi: Union[ArrayLike, "Dataset"],
    delta_deg: Optional[ArrayLike] = None,
    v: Optional[ArrayLike] = None,
    sigma_v: Optional[ArrayLike] = None,
    rho: ArrayLike = 0.4,
    f: ArrayLike = 0.1,
    *,
    tol: float = 1e-10,
) -> Table:
    """The collisional parameter K of every measured point (eq 69; ``fitbead k``).

    Either arrays (``xi``, ``delta_deg``, ``v`` and optionally ``sigma_v``, ``rho``, ``f``,
    broadcast together) or measurements as the second argument: a :class:`Dataset`, a CSV
    path, a pandas DataFrame or a :class:`Table` (what :func:`simulate` returns).

    Parameters
    ----------
    model:
        ``stick``, ``stick-approx``, ``slip``, ``slip-approx``, ``stickslip``, ``contact`` or
        ``auto`` (per row the model chosen at the stick K, to the tolerance ``tol``).
    v, sigma_v:
        Measured mean velocity (> 0, units sqrt(g (R + r))) and its standard error (> 0, or
        NaN / None for none).

    Returns
    -------
    Table
        The command line's columns in its order: the inputs ``series`` (a Dataset's labels;
        not for arrays), ``xi``, ``delta_deg``, ``v``, ``sigma_v``, then ``model``, ``K`` (at v), ``K_lo`` (at v − σ), ``K_hi`` (at v + σ), ``dv_dK``,
        ``final_velocity``, ``theta_G_deg``, the named laws' ``K_cos2a``, ``K_adjusted``,
        ``K_impact``, ``iterations``, the bracket ``K_min``/``K_max`` and what sets its ends
        (``lower_limit``, ``upper_limit``), ``regime``, ``status`` (``ok``,
        ``below-range``, ``above-range``, ``invalid``) and ``message``; a Dataset whose points
        carry slope errors (``sigma_delta_deg``) adds ``sigma_K``, the standard uncertainty
        of K from the velocity's and the slope's, and its ``K_lo``/``K_hi`` are at
        v ∓ σ_eff, σ_eff² = σ_v² + (∂v̄/∂δ σ_δ)²; ``auto`` adds ``model_used`` and
        ``reason``.
    """
    model = _model_name(model)
    if model not in K_MODELS:
        raise FitbeadError(f"model = {model!r}: expected one of {', '.join(K_MODELS)}")
    if delta_deg is None and v is None and _is_data(xi):
        xi = _dataset(xi)
    if isinstance(xi, Dataset):
        t = _table(xi._core.invert_k(model, tol=tol), (len(xi),))
        cols = xi.columns()
        for k in ("series", "xi", "delta_deg", "v", "sigma_v"):
            t[k] = cols[k]
        t["model"] = np.full(len(xi), model, dtype=object)
        return _ordered(t, _core.output_columns("k", model, slopes="sigma_K" in t))
    if delta_deg is None or v is None:
        raise FitbeadError("invert_k needs xi, delta_deg and v (or a Dataset)")
    if sigma_v is None:
        sigma_v = np.nan
    shape, a = _broadcast({"xi": xi, "delta_deg": delta_deg, "v": v, "sigma_v": sigma_v, "rho": rho, "f": f})
    raw = _core.invert_k(model, a["xi"], a["delta_deg"], a["v"], a["sigma_v"], a["rho"], a["f"], tol=tol)
    t = _table(raw, shape)
    for k in ("xi", "delta_deg", "v", "sigma_v"):
        t[k] = a[k].reshape(shape).copy()  # type: ignore[union-attr]
    t["model"] = np.full(shape, model, dtype=object)
    names = [n for n in _core.output_columns("k", model) if n != "series"]
    return _ordered(t, names)


def regimes(xi: ArrayLike = (0.8, 1.0, 1.6, 2.0), law: str = "adjusted", rho: float = 0.4) -> Table:
    """The regime limits of a collision law (``fitbead regimes``).

    Parameters
    ----------
    xi : array_like, default (0.8, 1.0, 1.6, 2.0)
        Radius ratios ξ = r/R (flattened to one row each).
    law : str, default "adjusted"
        The collision law K(α): ``adjusted`` (the paper's fit), ``impact``, ``cos2a``, a
        number (one K for every ξ) or ``c=VALUE`` (K = cos 2α + c sin²α sin 2α), as the
        command line's ``--law``.
    rho : float, default 0.4
        Density ratio ρ.

    Returns
    -------
    Table
        The command line's columns: ``xi``, ``alpha_deg``, ``K``, ``delta_m_deg`` (δ_m,
        eq 32: below it the bead stops), ``delta_d_deg`` (δ_d, eq 31: above it the bead
        lifts off), ``mu_eq79`` (the bulk friction of eq 79), ``steady_range`` (``yes``
        where δ_m < δ_d) and ``critical_xi`` (the ξ below which no steady regime exists,
        NaN if there is none); the table's attribute ``critical_xi`` holds it too (None if
        there is none).

    Raises
    ------
    FitbeadError
        An unknown law, ξ ≤ 0, ρ < 0, or a law whose K is not above 0 at some ξ.
    """
    x = _flat(np.atleast_1d(_as_f64("xi", xi)))
    raw, crit = _core.regimes(x, law=law, rho=float(rho))
    t = _ordered(_table(raw, x.shape), _core.record_columns("regimes"))
    t.critical_xi = crit  # type: ignore[attr-defined]
    return t


class Dataset:
    """Measured mean velocities grouped in series (the command line's measurement CSV).

    Build one with :meth:`read_csv` (same columns, units and error messages as the command
    line: ``series,xi,delta_deg,v[,sigma_v][,rho][,f]`` or dimensional ``v_m_s`` with
    ``R_m``), :meth:`from_arrays`, :meth:`from_pandas` or :meth:`default`.
    """

    def __init__(self, core: Any) -> None:
        self._core = core
        for w in core.warnings:
            _warn(w, UnitWarning)

    @classmethod
    def read_csv(
        cls, path: str, *, rho: float = 0.4, f: float = 0.1, g: float = 9.81, strict_columns: bool = False
    ) -> "Dataset":
        """Reads a measurement CSV as the command line does.

        Parameters
        ----------
        path : str or path-like
            The file: columns ``series,xi,delta_deg,v[,sigma_v][,rho][,f]`` (dimensionless
            velocities) or ``v_m_s`` with ``R_m`` (SI), optionally ``sigma_delta_deg``.
        rho, f, g : float
            Values for the columns the file leaves out; ``g`` in m/s² for SI files.
        strict_columns : bool, default False
            Refuse any column fitbead does not read (the command line's
            ``--strict-columns``), instead of warning about those that look misnamed.

        Returns
        -------
        Dataset

        Raises
        ------
        FitbeadError
            The command line's text: file, line, column, value, message.

        Warns
        -----
        UnitWarning
            Each of the command line's plausibility warnings (slopes in radians, velocities
            in m/s or mm/s in the dimensionless column, radii in millimetres).
        ColumnWarning
            A column fitbead does not read that looks misspelt or misnamed (``sigma`` for
            ``sigma_v``), with the name it most likely means.
        """
        return cls._checked(_core._Dataset.from_csv(str(path), rho=rho, f=f, g=g), strict_columns)

    @classmethod
    def _checked(cls, core: Any, strict_columns: bool) -> "Dataset":
        """The data set of a file read, its columns checked as the command line checks them."""
        if strict_columns:
            core.check_strict_columns()
        out = cls(core)
        for w in core.column_warnings:
            _warn(w, ColumnWarning)
        return out

    @classmethod
    def default(cls) -> "Dataset":
        """The shipped synthetic data set (36 points in 4 series; data/default.csv)."""
        return cls(_core._Dataset.default_data())

    @classmethod
    def from_arrays(
        cls,
        xi: ArrayLike,
        delta_deg: ArrayLike,
        v: Optional[ArrayLike] = None,
        sigma_v: Optional[ArrayLike] = None,
        *,
        series: Optional[Iterable[Any]] = None,
        rho: ArrayLike = 0.4,
        f: ArrayLike = 0.1,
        sigma_delta_deg: ArrayLike = 0.0,
        v_m_s: Optional[ArrayLike] = None,
        sigma_v_m_s: Optional[ArrayLike] = None,
        R_m: Optional[ArrayLike] = None,
        g: ArrayLike = 9.81,
    ) -> "Dataset":
        """From arrays (broadcast together), dimensionless (``v``) or in SI units (``v_m_s``
        with ``R_m``), with the names of the CSV's columns (:meth:`read_csv`).

        Parameters
        ----------
        xi, delta_deg : array_like
            Radius ratio ξ = r/R and slope δ in degrees, per point.
        v, sigma_v : array_like, optional
            Mean velocity v̄ / sqrt(g (R + r)) and its standard uncertainty (dimensionless).
            Without ``sigma_v`` (or ``sigma_v_m_s``) the fits weight relatively.
        series : iterable, optional
            Labels grouping the points (default: grouped by ξ).
        rho, f : array_like
            Density ratio ρ and friction f per point (defaults 0.4, 0.1).
        sigma_delta_deg : array_like, default 0
            Standard uncertainty of each slope in degrees (0: exact); where it is above 0 the
            least-squares fits are orthogonal distance regressions, and their residual tables
            gain ``delta_fit_deg`` and ``delta_residual``.
        v_m_s, sigma_v_m_s : array_like, optional
            Instead of ``v`` and ``sigma_v``: the velocities and their uncertainty in m/s,
            converted as the CSV reader does, v = v_m_s / sqrt(g R_m (1 + ξ)).
        R_m : array_like, optional
            With ``v_m_s``: the radius R of the row beads, metres.
        g : array_like, default 9.81
            With ``v_m_s``: the acceleration of gravity, m/s².

        Returns
        -------
        Dataset

        Raises
        ------
        FitbeadError
            Velocities given both ways or neither, ``v_m_s`` without ``R_m``, ``sigma_v``
            beside ``v_m_s`` (or ``sigma_v_m_s`` beside ``v``), or a value the CSV reader
            refuses (its message; point ``i`` is "line" ``i + 2``).

        Warns
        -----
        UnitWarning
            The command line's plausibility warnings, as for :meth:`read_csv` (slopes in
            radians, velocities in m/s or mm/s, radii in millimetres); the data are named
            ``<arrays>`` and the point at index ``i`` is "line" ``i + 2``, as if written to a
            CSV file.
        """
        if v_m_s is not None or R_m is not None or sigma_v_m_s is not None:
            return cls._from_si_arrays(xi, delta_deg, v, sigma_v, series, rho, f, sigma_delta_deg, v_m_s, sigma_v_m_s, R_m, g)
        if v is None:
            raise FitbeadError("v: give the velocities, dimensionless (v) or in m/s (v_m_s with R_m)")
        shape, a = _broadcast(
            {
                "xi": xi,
                "delta_deg": delta_deg,
                "v": v,
                "sigma_v": np.nan if sigma_v is None else sigma_v,
                "rho": rho,
                "f": f,
                "sigma_delta_deg": sigma_delta_deg,
            }
        )
        n = a["xi"].size  # type: ignore[union-attr]
        labels = [""] * n if series is None else [str(s) for s in np.ravel(np.asarray(list(series), dtype=object))]
        return cls(
            _core._Dataset.from_arrays(
                labels, a["xi"], a["delta_deg"], a["v"], a["sigma_v"], a["rho"], a["f"], a["sigma_delta_deg"]
            )
        )

    @classmethod
    def _from_si_arrays(
        cls, xi: Any, delta_deg: Any, v: Any, sigma_v: Any, series: Any, rho: Any, f: Any, sigma_delta_deg: Any,
        v_m_s: Any, sigma_v_m_s: Any, R_m: Any, g: Any,
    ) -> "Dataset":
        """From arrays in SI units: the points written as the CSV they would be (every number
        in its shortest round-trip form) and read by the CSV reader, conversion and checks
        included."""
        import csv
        import io

        if v is not None:
            raise FitbeadError("v: both v (dimensionless) and v_m_s with R_m (m/s) are given: keep one velocity")
        if sigma_v is not None:
            raise FitbeadError("sigma_v: it is dimensionless but the velocities are v_m_s (m/s): give sigma_v_m_s")
        if v_m_s is None or R_m is None:
            raise FitbeadError(f"{'R_m' if R_m is None else 'v_m_s'}: velocities in m/s need v_m_s with R_m (the row beads' radius, m)")
        named = {"xi": xi, "delta_deg": delta_deg, "v_m_s": v_m_s, "R_m": R_m, "g": g, "rho": rho, "f": f}
        if sigma_v_m_s is not None:
            named["sigma_v_m_s"] = sigma_v_m_s
        if np.any(np.asarray(sigma_delta_deg, dtype=float) != 0):
            named["sigma_delta_deg"] = sigma_delta_deg
        shape, a = _broadcast(named)
        n = a["xi"].size  # type: ignore[union-attr]
        labels = [""] * n if series is None else [str(s) for s in np.ravel(np.asarray(list(series), dtype=object))]
        if len(labels) != n:
            raise FitbeadError(f"series: {len(labels)} labels for {n} points")
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        w.writerow(["series", *named])
        cols = [_flat(a[k]) for k in named]  # type: ignore[arg-type]
        for i in range(n):
            w.writerow([labels[i], *(repr(float(c[i])) for c in cols)])
        return cls(_core._Dataset.from_text(out.getvalue(), "<arrays>", rho=0.4, f=0.1, g=9.81))

    @classmethod
    def from_pandas(
        cls, df: Any, *, rho: float = 0.4, f: float = 0.1, g: float = 9.81, strict_columns: bool = False
    ) -> "Dataset":
        """From a DataFrame with the CSV's columns, checked as the command line checks a file
        (errors name the DataFrame's line as the CSV would have it: header on line 1).

        Parameters
        ----------
        df : pandas.DataFrame
            The columns of a measurement CSV (:meth:`read_csv`): ``series``, ``xi``,
            ``delta_deg`` and ``v`` (dimensionless, optionally ``sigma_v``) or ``v_m_s``
            with ``R_m`` (SI, optionally ``sigma_v_m_s`` and ``g``), optionally ``rho``,
            ``f`` and ``sigma_delta_deg``; the index is not used.
        rho, f, g : float
            Values for the columns the frame leaves out (defaults 0.4, 0.1, 9.81); ``g`` in
            m/s² for SI columns.
        strict_columns : bool, default False
            Refuse any column fitbead does not read, instead of warning (``ColumnWarning``)
            about those that look misnamed.

        Returns
        -------
        Dataset

        Raises
        ------
        FitbeadError
            The CSV reader's message (line, column, value).

        Warns
        -----
        UnitWarning, ColumnWarning
            As :meth:`read_csv`.
        """
        text = df.to_csv(index=False)
        core = _core._Dataset.from_text(text, "<DataFrame>", rho=rho, f=f, g=g)
        return cls._checked(core, strict_columns)

    @property
    def warnings(self) -> List[str]:
        """The plausibility warnings given when the data were read (also given as
        :class:`UnitWarning`)."""
        return list(self._core.warnings)

    def __len__(self) -> int:
        return len(self._core)

    @property
    def labels(self) -> List[str]:
        """The series labels, in order of first appearance."""
        return self._core.labels

    @property
    def has_sigma(self) -> bool:
        """Whether the points carry σ (absolute weights) or not (relative weights)."""
        return self._core.has_sigma

    def columns(self) -> Dict[str, np.ndarray]:
        """The points as arrays: series (labels), series_index, xi, delta_deg, v, sigma_v
        (NaN without), rho, f; velocities dimensionless.

        The data set holds δ in radians: ``delta_deg`` is converted back and may differ from
        the file's degrees in the last bit (:func:`invert_k` on a Dataset uses the radians
        themselves)."""
        c = dict(self._core.columns())
        labels = np.asarray(self.labels, dtype=object)
        c["series"] = labels[c["series_index"]]
        c.update(self.file_columns())
        return c

    def file_columns(self) -> Dict[str, np.ndarray]:
        """The file's columns that the dimensionless data set converts away, as float64 (NaN
        where a row leaves the cell empty): ``v_m_s``, ``sigma_v_m_s``, ``R_m`` and ``g``,
        those the file has (none for data without SI velocities)."""
        return {name: np.array([float(x) if x != "" else np.nan for x in cells], dtype=np.float64) for name, cells in self._core.file_columns()}

    def to_pandas(self):
        """The points as a DataFrame (needs pandas): the columns of :meth:`columns` but
        ``series_index``, the file's ``R_m`` and ``g`` (and ``v_m_s``, ``sigma_v_m_s``) kept."""
        import pandas as pd

        c = self.columns()
        cols = ["series", "xi", "delta_deg", "v", "sigma_v", "rho", "f", *self.file_columns()]
        return pd.DataFrame({k: c[k] for k in cols})

    def __repr__(self) -> str:
        return f"Dataset({len(self)} points, series {self.labels})"

    # ---- pickling, equality, saving -------------------------------------------------------

    def __getstate__(self) -> Dict[str, Any]:
        # What the data set was made from (CSV text and defaults, or arrays); unpickling makes
        # it again the same way, without repeating its warnings.
        return {"version": _persist.VERSION, "dataset": dict(self._core.state())}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        _check_pickle(state, "Dataset")
        self._core = _dataset_core(state["dataset"])

    def __eq__(self, other: Any) -> bool:
        """Made from the same thing: the same CSV text, source name and defaults, or the same
        arrays (bit for bit)."""
        if not isinstance(other, Dataset):
            return NotImplemented
        return _same(dict(self._core.state()), dict(other._core.state()))

    __hash__ = None  # type: ignore[assignment]

    def save(self, path: Any) -> None:
        """Writes the data set to a JSON file that :func:`load` reads back (the format:
        :func:`load`): the CSV text it was read from with its name and the defaults, or the
        arrays it was made from; written atomically.

        Parameters
        ----------
        path : str or path-like
            The file to write (replaced if it exists).
        """
        _save(path, "dataset", lambda: _persist.encode(dict(self._core.state()), "dataset"))


def _dataset_core(state: Mapping[str, Any]) -> Any:
    """The compiled data set made again from its state (``_Dataset.state()``)."""
    if state["origin"] == "text":
        rho, f, g, sd = (float(state[k]) for k in ("rho", "f", "g", "sigma_delta"))
        core = _core._Dataset.from_text(state["text"], state["source"], rho=rho, f=f, g=g)
        if sd != 0.0 or math.copysign(1.0, sd) < 0:
            core = core.with_defaults(rho=rho, f=f, g=g, sigma_delta=sd)
        return core
    cols = [_flat(np.asarray(state[k], dtype=np.float64)) for k in _persist.DATASET_ARRAYS]
    return _core._Dataset.from_arrays([str(s) for s in state["series"]], *cols)


def _check_pickle(state: Any, what: str) -> None:
    """A pickled state this fitbead can read: a dict of a version it knows."""
    v = state.get("version") if isinstance(state, dict) else None
    if not isinstance(v, int) or not 1 <= v <= _persist.VERSION:
        raise FitbeadError(f"{what}: a pickle of version {v!r}; this fitbead reads 1 to {_persist.VERSION}")


def _save(path: Any, kind: str, body: Any) -> None:
    """Writes the JSON document of a ``kind`` result (``body()``) to ``path``; a value that
    cannot be saved is a FitbeadError naming where it is."""
    try:
        _persist.write(path, kind, body(), __version__)
    except _persist._Bad as e:
        raise FitbeadError(f"{path}: cannot save: {e}") from None


def _dataset(data: Any, strict_columns: bool = False) -> Dataset:
    """The data of a call: a Dataset as it is, None for the shipped data, a CSV path, a
    pandas DataFrame or a :class:`Table` (what :func:`simulate` returns), the last three read
    and checked as the command line reads a file."""
    if isinstance(data, Dataset):
        return data
    if data is None:
        return Dataset.default()
    if isinstance(data, str) or hasattr(data, "__fspath__"):
        return Dataset.read_csv(str(data), strict_columns=strict_columns)
    if isinstance(data, Table):
        core = _core._Dataset.from_text(_table_csv(data), "<Table>")
        return Dataset._checked(core, strict_columns)
    if hasattr(data, "to_csv") and hasattr(data, "columns"):
        return Dataset.from_pandas(data, strict_columns=strict_columns)
    raise FitbeadError("data: expected a Dataset, a CSV path, a pandas DataFrame or a Table (simulate's)")


def _is_data(x: Any) -> bool:
    """Whether `x` is measurements as :func:`_dataset` takes them (not an array of ξ)."""
    return (
        isinstance(x, (Dataset, Table, str))
        or hasattr(x, "__fspath__")
        or (hasattr(x, "to_csv") and hasattr(x, "columns"))
    )


def _table_csv(t: "Table") -> str:
    """A one-dimensional Table as CSV text: numbers written so that they read back to the same
    float64 (``repr``), NaN as an empty cell, text as it is."""
    import csv
    import io

    names = list(t)
    cols = [np.asarray(t[n]).ravel() for n in names]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(names)

    def cell(x: Any) -> str:
        if isinstance(x, (float, np.floating)):
            return "" if math.isnan(x) else repr(float(x))
        if isinstance(x, (int, np.integer)):
            return str(int(x))
        return str(x)

    for i in range(len(cols[0]) if cols else 0):
        w.writerow([cell(c[i]) for c in cols])
    return buf.getvalue()


def _nan(x: Any) -> float:
    """A record's number as a float: NaN for an empty cell (None)."""
    return math.nan if x is None else float(x)


@dataclass(frozen=True)
class Param:
    """One fitted parameter: a row of the command line's params.csv.

    Numbers the report leaves empty are NaN (never None), so that arrays and DataFrames built
    from parameters stay numeric.
    """

    name: str
    series: str
    """The series the parameter belongs to (``all`` for a parameter of every series)."""
    value: float
    """Least-squares optimum, or the posterior median."""
    stderr: float
    """Standard error (covariance), or the posterior standard deviation; NaN where none."""
    low: float
    high: float
    """The interval at ``level`` (NaN where none was found: see ``note``)."""
    method: str
    """How the interval was obtained (``profile``, ``covariance``, ``posterior``, ``none``)."""
    level: float
    unit: str
    at_bound: bool
    """The optimum sits on a bound of the parameter (see the report's warning)."""
    bounds: Tuple[float, float]
    paper_value: float
    paper_source: str
    lsq_value: float
    note: str
    rhat: float = math.nan
    ess_bulk: float = math.nan
    ess_tail: float = math.nan
    cov_low: float = math.nan
    cov_high: float = math.nan
    """The covariance (Wald) interval, beside the profile one."""
    profile_low: float = math.nan
    profile_high: float = math.nan
    profile_low_status: str = ""
    profile_high_status: str = ""
    """Whether each end of the profile interval was found, and if not why."""
    mean: float = math.nan
    sd: float = math.nan
    q2_5: float = math.nan
    q50: float = math.nan
    q97_5: float = math.nan
    """Posterior mean, standard deviation and quantiles (MCMC; NaN under least squares)."""
    tau: float = math.nan
    """Integrated autocorrelation time of the posterior draws (MCMC)."""
    prior_sensitivity: float = math.nan
    likelihood_sensitivity: float = math.nan
    prior_diagnosis: str = ""
    """Power-scaling sensitivity of the posterior to the prior and to the likelihood, and
    ``prior-driven`` or ``prior-data conflict`` where it is flagged (MCMC)."""
    record: Dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    """The whole row as the command line writes it (keys: params.csv's columns)."""
    vary: bool = True
    """False for a parameter held at its value (``fix``): no stderr or interval (lmfit's
    ``vary``)."""
    init_value: float = math.nan
    """The value the least-squares fit started from (lmfit's ``init_value``; NaN where the
    fit does not say)."""

    @property
    def min(self) -> float:
        """Lower end of the parameter's box (lmfit's ``min``)."""
        return self.bounds[0]

    @property
    def max(self) -> float:
        """Upper end of the parameter's box (lmfit's ``max``)."""
        return self.bounds[1]

    def _fields(self) -> Tuple[Any, ...]:
        return tuple(getattr(self, f) for f in self.__dataclass_fields__ if f != "record")

    def __eq__(self, other: Any) -> bool:
        """Every field but ``record`` equal, floats bit for bit and NaN equal to NaN."""
        if not isinstance(other, Param):
            return NotImplemented
        return _same(self._fields(), other._fields())

    def __hash__(self) -> int:
        def key(x: Any) -> Any:
            if isinstance(x, tuple):
                return tuple(key(v) for v in x)
            return "nan" if isinstance(x, float) and math.isnan(x) else x

        return hash(key(self._fields()))


def _param(r: Dict[str, Any], bounds: Tuple[float, float], fixed: bool = False, start: Optional[float] = None) -> Param:
    """A :class:`Param` from one row of the parameter report (the keys of params.csv)."""
    return Param(
        name=r["parameter"],
        series=r["series"],
        value=_nan(r["value"]),
        stderr=_nan(r["stderr"]),
        low=_nan(r["ci_low"]),
        high=_nan(r["ci_high"]),
        method=r["ci_method"],
        level=_nan(r["level"]),
        unit=r["unit"],
        at_bound=r["at_bound"],
        bounds=(float(bounds[0]), float(bounds[1])),
        paper_value=_nan(r["paper_value"]),
        paper_source=r["paper_source"],
        lsq_value=_nan(r["lsq_value"]),
        note=r["note"],
        rhat=_nan(r["rhat"]),
        ess_bulk=_nan(r["ess_bulk"]),
        ess_tail=_nan(r["ess_tail"]),
        cov_low=_nan(r["cov_low"]),
        cov_high=_nan(r["cov_high"]),
        profile_low=_nan(r["profile_low"]),
        profile_high=_nan(r["profile_high"]),
        profile_low_status=r["profile_low_status"] or "",
        profile_high_status=r["profile_high_status"] or "",
        mean=_nan(r["mean"]),
        sd=_nan(r["sd"]),
        q2_5=_nan(r["q2.5"]),
        q50=_nan(r["q50"]),
        q97_5=_nan(r["q97.5"]),
        tau=_nan(r["tau"]),
        prior_sensitivity=_nan(r["prior_sensitivity"]),
        likelihood_sensitivity=_nan(r["likelihood_sensitivity"]),
        prior_diagnosis=r["prior_diagnosis"] or "",
        record=dict(r),
        vary=not fixed,
        init_value=_nan(start),
    )


def _frame(records: Sequence[Mapping[str, Any]], columns: Sequence[str]):
    """A DataFrame of report records with the command line's columns: a column of numbers
    and empty cells is float64 with NaN (never object with None); a count
    (:data:`_COUNT_COLUMNS`) with every cell given is int64."""
    import pandas as pd

    df = pd.DataFrame(list(records), columns=list(columns))
    for c in df.columns:
        vals = [x for x in df[c] if x is not None and not (isinstance(x, float) and math.isnan(x))]
        numeric = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in vals)
        if numeric and (vals or df[c].isna().all()) and c not in _TEXT_COLUMNS:
            col = pd.to_numeric(df[c].astype(object).where(df[c].notna(), np.nan), errors="coerce").astype("float64")
            if c in _COUNT_COLUMNS and len(col) and col.notna().all() and bool((col == np.round(col)).all()):
                col = col.astype("int64")
            df[c] = col
    return df


# Text columns of the reports that may be empty in every row of a table (kept as text).
_TEXT_COLUMNS = frozenset(
    [
        "prior_diagnosis", "note", "paper_source", "profile_low_status", "profile_high_status", "mcmc_status", "method",
        "ci_method", "unit", "fit", "series", "parameter", "parameter_1", "parameter_2", "model",
    ]
)

# Columns of the reports that count (points, parameters, steps, a rank): integers.
_COUNT_COLUMNS = frozenset(
    ["n_points", "n_params", "dof", "iterations", "residual_evals", "walkers", "steps", "burn_in", "draws", "rank", "replicates"]
)

# What each fit evaluates: fit name -> how its parameters make a curve.
_JAEGER = "jaeger"


class FitResult:
    """One fit: parameters with errors and intervals, correlations, residuals, statistics.

    ``print(result)`` shows the fit report the command line prints; in a notebook the report
    renders as HTML. The lmfit habits hold: :attr:`params` by name (``value``, ``stderr``,
    ``vary``, ``min``, ``max``, ``init_value``), :attr:`covar`, :attr:`residual`,
    :attr:`chisqr`, :attr:`redchi`, :attr:`nfev`, :attr:`success`, :attr:`ndata`,
    :attr:`nvarys`, :attr:`nfree`, :attr:`var_names`, :attr:`best_fit`, :attr:`init_values`,
    :meth:`eval`, :meth:`eval_band`, :meth:`eval_uncertainty`, :meth:`conf_interval`,
    :meth:`fit_report`, :meth:`plot`. For
    an MCMC fit, :attr:`draws` holds the posterior draws and :meth:`to_arviz` makes an
    ``arviz.InferenceData`` with a pointwise log likelihood (so ``az.loo`` and
    ``az.compare`` work).
    """

    def __init__(self, core: Any, context: Optional[Dict[str, Any]] = None) -> None:
        self._core = core
        self._context: Dict[str, Any] = dict(context or {})
        # How to make the fit again at another level (conf_interval): the fit function and its
        # keywords, for a fit made here (not kept by pickling or saving).
        self._refit: Optional[Tuple[Any, Dict[str, Any]]] = None
        self.name, self.series = core.name()
        rows = [
            _param(r, b, fixed, start)
            for r, b, fixed, start in zip(core.params(), core.param_bounds(), core.param_fixed(), core.param_starts())
        ]
        names = [p.name for p in rows]
        unique = len(set(names)) == len(names)
        self.params: Dict[str, Param] = {(p.name if unique else f"{p.name}[{p.series}]"): p for p in rows}
        """The parameters in the fit's order, by name; where a name repeats (one K per
        series), by ``name[series]``."""
        self.stats: Dict[str, Any] = dict(core.stats())
        """χ², reduced χ², AIC, BIC, termination, iterations, ... (and MCMC diagnostics):
        the keys and cells of the command line's stats.csv (an empty cell is None)."""
        corr = core.correlation()
        self.correlation: Optional[np.ndarray] = None if corr is None else np.asarray(corr, dtype=float)
        """Correlation matrix of the parameters (order of :attr:`params`), or None."""
        pts = dict(core.points())
        pts["series"] = np.asarray(pts["series"], dtype=object)
        self.residuals: Dict[str, np.ndarray] = pts
        """The fitted points: series, xi, delta_deg, v, sigma_v, v_fit, residual,
        normalised_residual (the columns of the report's residuals.csv)."""
        d = core.draws()
        self.draws: Optional[np.ndarray] = None
        """Posterior draws ``[walker, kept step, parameter]`` (MCMC), else None."""
        self.log_posterior: Optional[np.ndarray] = None
        self.burn_in = self.thin = 0
        self.interrupted = False
        if d is not None:
            self.draws, self.log_posterior, self.burn_in, self.thin, self.interrupted = d

    # ---- pickling, equality, saving -------------------------------------------------------

    def _state(self) -> Dict[str, Any]:
        """Everything the fit's core gives (parameter, statistics, residual and correlation
        records, the points, the draws, the report): what makes the fit again."""
        if isinstance(self._core, _persist.StoredFit):
            return self._core.state()
        return _persist.fit_state(self._core)

    def __getstate__(self) -> Dict[str, Any]:
        return {"version": _persist.VERSION, "fit": self._state(), "context": dict(self._context)}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        _check_pickle(state, "FitResult")
        self.__init__(_persist.StoredFit(state["fit"]), state["context"])  # type: ignore[misc]

    def __eq__(self, other: Any) -> bool:
        """The same fit: name, series, every record of the report (parameters, statistics,
        residuals, correlations), the points, the draws and the report's text, floats bit for
        bit (NaN equal to NaN)."""
        if not isinstance(other, FitResult):
            return NotImplemented
        return _same(self._context, other._context) and _same(self._state(), other._state())

    __hash__ = None  # type: ignore[assignment]

    def save(self, path: Any) -> None:
        """Writes the fit to a JSON file that :func:`load` reads back as an equal fit (the
        format: :func:`load`), draws included; written atomically.

        Parameters
        ----------
        path : str or path-like
            The file to write (replaced if it exists).
        """
        _save(path, "fit", lambda: self._json("fit"))

    def _json(self, where: str) -> Dict[str, Any]:
        return _persist.encode_fit(self._state(), self._context, where)

    def _warn(self) -> None:
        """Gives the command line's warnings on this fit as Python warnings."""
        absurd = self._core.absurd_misfit()
        label = f"{self.name} [{self.series}]"
        if absurd:
            _warn(f"{label}: {absurd}", UnitWarning)
        else:
            misfit = self._core.misfit_warning()
            if misfit:
                outliers = re.match(r"\d+ outlier\(s\)", misfit) is not None
                _warn(f"{label}: {misfit}", OutlierWarning if outliers else MisfitWarning)
        if not self.stats.get("converged", True):
            why = self.stats.get("note") or self.stats.get("termination")
            _warn(f"{label}: not converged: {why}", ConvergenceWarning)
        for key, p in self.params.items():
            if p.at_bound:
                _warn(f"{label}: {key} = {p.value:.6g} is on a bound of {p.bounds}: {p.note}", BoundWarning)

    @property
    def param_names(self) -> List[str]:
        """The parameters' keys in the fit's order (the order of :attr:`covar`)."""
        return list(self.params)

    @property
    def values(self) -> Dict[str, float]:
        """``{name: value}`` of the parameters that set the curve (not the scatter's scale),
        with the names :func:`forward` takes: ``fitbead.forward(model, xi, d, **fit.values)``
        evaluates a Jan, Jaeger or K-law ``c`` fit."""
        return {p.name: p.value for p in self.params.values() if p.name != "sigma_scale" and p.name != "K"}

    @property
    def covar(self) -> Optional[np.ndarray]:
        """Covariance matrix of the parameters that vary (order of :attr:`var_names`, as
        lmfit's; every parameter unless some are held by ``fix``): from the least-squares
        covariance, or of the posterior draws (MCMC); None where a standard error is missing
        (an undetermined fit)."""
        idx = self._varying()
        se = np.array([list(self.params.values())[i].stderr for i in idx], dtype=float)
        if se.size == 0 or np.isnan(se).any():
            return None
        if self.correlation is not None:
            r = self.correlation[np.ix_(idx, idx)]
        elif se.size == 1:
            r = np.eye(1)
        else:
            return None
        return r * np.outer(se, se)

    def _varying(self) -> List[int]:
        """Positions in :attr:`params` of the parameters that vary."""
        return [i for i, p in enumerate(self.params.values()) if p.vary]

    @property
    def residual(self) -> np.ndarray:
        """The normalised residuals (v − v̄_fit)/σ of the fitted points (lmfit's
        ``residual``; divided by the relative weight where no σ is given)."""
        return np.asarray(self.residuals["normalised_residual"], dtype=float)

    @property
    def delta_fit(self) -> Optional[np.ndarray]:
        """The adjusted slopes δ_fit in degrees, one per fitted point, when the fit took the
        slopes as measured with error (``sigma_delta_deg``: orthogonal distance regression, or
        a posterior integrated over the slopes); None when it took them as exact."""
        d = self.residuals.get("delta_fit_deg")
        return None if d is None else np.asarray(d, dtype=float)

    @property
    def correlations(self) -> Dict[Tuple[str, str], float]:
        """Correlation of each pair of parameters ``{(a, b): r}`` with a before b."""
        if self.correlation is None:
            return {}
        n = self.param_names
        return {(n[i], n[j]): float(self.correlation[i, j]) for i in range(len(n)) for j in range(i + 1, len(n))}

    @property
    def chi2(self) -> float:
        return self.stats["chi2"]

    @property
    def reduced_chi2(self) -> float:
        return self.stats["reduced_chi2"]

    @property
    def aic(self) -> float:
        return _nan(self.stats["aic"])

    @property
    def bic(self) -> float:
        return _nan(self.stats["bic"])

    @property
    def converged(self) -> bool:
        return self.stats["converged"]

    # ---- lmfit's names ----------------------------------------------------------------------

    @property
    def chisqr(self) -> float:
        """χ² at the estimate (lmfit's name for :attr:`chi2`)."""
        return self.chi2

    @property
    def redchi(self) -> float:
        """χ²/dof (lmfit's name for :attr:`reduced_chi2`)."""
        return self.reduced_chi2

    @property
    def nfev(self) -> int:
        """Residual evaluations, profiles included (lmfit's ``nfev``)."""
        return int(self.stats["residual_evals"])

    @property
    def success(self) -> bool:
        """Whether the fit converged (lmfit's ``success``)."""
        return bool(self.converged)

    @property
    def ndata(self) -> int:
        """Number of data points (lmfit's ``ndata``)."""
        return int(self.stats["n_points"])

    @property
    def nvarys(self) -> int:
        """Number of parameters that vary (lmfit's ``nvarys``)."""
        return len(self.var_names)

    @property
    def nfree(self) -> int:
        """Degrees of freedom, ndata − free parameters (lmfit's ``nfree``)."""
        return int(self.stats["dof"])

    @property
    def var_names(self) -> List[str]:
        """Keys of the parameters that vary, in the fit's order (lmfit's ``var_names``; the
        order of :attr:`covar`)."""
        keys = list(self.params)
        return [keys[i] for i in self._varying()]

    @property
    def best_fit(self) -> np.ndarray:
        """The fitted v̄ at the data points (lmfit's ``best_fit``)."""
        return np.asarray(self.residuals["v_fit"], dtype=float)

    @property
    def best_values(self) -> Dict[str, float]:
        """``{key: value}`` of every parameter (lmfit's ``best_values``)."""
        return {k: p.value for k, p in self.params.items()}

    @property
    def init_values(self) -> Dict[str, float]:
        """``{key: start}`` of the parameters whose start the fit gives (lmfit's
        ``init_values``: the fit's own start, or ``init``)."""
        return {k: p.init_value for k, p in self.params.items() if not math.isnan(p.init_value)}

    @property
    def scale_covar(self) -> bool:
        """Whether the covariance was scaled by the reduced χ² (``scale_covar=True``, or data
        without sigma_v, whose scale is always estimated)."""
        return bool(self._context.get("scale_covar", False)) or self.stats.get("sigma") == "estimated"

    def __getitem__(self, name: str) -> Param:
        return self.params[name]

    # ---- evaluating the fitted model -------------------------------------------------------

    def _series_xi(self, series: Optional[str]) -> float:
        r = self.residuals
        labels = [series] if series is not None else ([self.series] if self.series not in ("", "all") else [])
        for lab in labels:
            m = r["series"] == lab
            if m.any():
                return float(np.asarray(r["xi"])[m][0])
        xs = np.unique(np.asarray(r["xi"], dtype=float))
        if xs.size == 1:
            return float(xs[0])
        raise FitbeadError(f"{self.name}: give xi (the fit covers several: {', '.join(f'{x:g}' for x in xs)})")

    def _curve(self, theta: np.ndarray, xi: np.ndarray, delta_deg: np.ndarray, series: Optional[np.ndarray] = None) -> np.ndarray:
        """The fitted model's v̄ at parameter rows ``theta[draw, parameter]`` (fit order) and
        points ``xi``, ``delta_deg`` (1-D, same length): an array ``[draw, point]``."""
        names = [p.name for p in self.params.values()]
        th = np.atleast_2d(np.asarray(theta, dtype=float))
        col = {n: th[:, i : i + 1] for i, n in enumerate(names)}
        xi2, d2 = xi[None, :], delta_deg[None, :]
        ctx = self._context
        if ctx.get("mixed_material"):
            raise FitbeadError(
                f"{self.name}: the data's rows have several values of rho or f, and the curve is drawn for one: "
                "fit the rows of each rho and f apart"
            )
        rho, f = ctx.get("rho", 0.4), ctx.get("f", 0.1)
        if self.name.startswith("klaw-"):
            model = ctx["model"]
            if self.name == "klaw-impact":
                v = np.asarray(forward(model, xi2, d2, K="impact", rho=rho, f=f)["v"])
                return np.broadcast_to(v, (th.shape[0], v.shape[1])).copy()
            if self.name == "klaw-c":
                alpha = np.radians(np.asarray(regimes(xi)["alpha_deg"], dtype=float))[None, :]
                a, b = np.cos(2 * alpha), np.sin(alpha) ** 2 * np.sin(2 * alpha)
                return np.asarray(forward(model, xi2, d2, K=a + b * col["c"], rho=rho, f=f)["v"])
            # One K per series: the series of each point picks its K.
            keys = self.param_names
            if series is None:
                raise FitbeadError(f"{self.name}: give series (one K per series: {', '.join(keys)})")
            idx = np.array([keys.index(f"K[{s}]") if f"K[{s}]" in keys else -1 for s in series])
            if (idx < 0).any():
                raise FitbeadError(f"{self.name}: series {series[idx < 0][0]!r} is not one of the fit's ({', '.join(keys)})")
            return np.asarray(forward(model, xi2, d2, K=th[:, idx], rho=rho, f=f)["v"])
        if self.name == "jan-series":
            return np.asarray(forward("jan", xi2, d2, **{"lambda": col["lambda"]}, mu=col["mu"])["v"])
        if self.name == "jan-global":
            s = np.sin(np.radians(np.asarray(regimes(xi)["alpha_deg"], dtype=float)))[None, :]
            lam = col["lambda0"] * np.exp(col["lambda1"] * s)
            mu = col["mu0"] * np.exp(col["mu1"] * s)
            return np.asarray(forward("jan", xi2, d2, **{"lambda": lam}, mu=mu)["v"])
        if self.name == _JAEGER:
            return np.asarray(
                forward("jaeger", xi2, d2, a1=col["a1"], a2=col["a2"], a3=col["a3"], branch=ctx.get("branch", "upper"))["v"]
            )
        raise FitbeadError(f"{self.name}: no curve to evaluate")

    def _points(self, delta_deg: ArrayLike, xi: Optional[ArrayLike], series: Optional[str]):
        d = np.atleast_1d(_as_f64("delta_deg", delta_deg))
        x = self._series_xi(series) if xi is None else xi
        shape, a = _broadcast({"xi": x, "delta_deg": d})
        lab = None
        if series is not None:
            lab = np.full(a["xi"].size, str(series), dtype=object)  # type: ignore[union-attr]
        elif self.name == "klaw-free-per-series" and xi is None and self.series not in ("", "all"):
            lab = np.full(a["xi"].size, self.series, dtype=object)  # type: ignore[union-attr]
        return shape, a["xi"], a["delta_deg"], lab

    def eval(
        self, delta_deg: ArrayLike, xi: Optional[ArrayLike] = None, *, series: Optional[str] = None, units: str = "dimensionless"
    ) -> np.ndarray:
        """The fitted model's mean velocity v̄ at new slopes (lmfit's ``eval``).

        Parameters
        ----------
        delta_deg : array_like
            Slopes in degrees.
        xi : array_like, optional
            Radius ratios (broadcast with ``delta_deg``); default: the ξ of the fit's series
            (or of ``series``).
        series : str, optional
            For a fit with one K per series, the series whose K to use; with
            ``units="si"``, the series whose R_m and g convert to m/s.
        units : {"dimensionless", "si"}, default "dimensionless"
            ``dimensionless``: v̄ / sqrt(g (R + r)), the library's unit; ``si``: m/s, for a fit
            of data given in m/s (``v_m_s`` with ``R_m``), as v̄·sqrt(g R_m (1 + ξ)) with the
            R_m and g of the series (``series``, the fit's own, or the one all series
            share).

        Returns
        -------
        numpy.ndarray
            v̄ (NaN where the model has no steady state), shaped as the broadcast arguments.

        Raises
        ------
        FitbeadError
            An unknown ``units``; ``units="si"`` for data given dimensionless, or with no one
            R_m and g for the points asked (series that differ and no ``series``).
        """
        si = _units(units)
        shape, x, d, lab = self._points(delta_deg, xi, series)
        theta = np.array([[p.value for p in self.params.values()]])
        v = self._curve(theta, x, d, lab)[0]
        if si:
            v = v * self._si_unit(x, series)
        return v.reshape(shape)

    def _si_unit(self, xi: np.ndarray, series: Optional[Any]) -> np.ndarray:
        """The velocity unit sqrt(g R (1 + ξ)) in m/s at ``xi``, with the g·R of ``series``
        (else of the fit's series, else the one every series of the fit shares)."""
        gr = {k[4:-1]: float(v) for k, v in self._context.items() if k.startswith("g_R[") and k.endswith("]")}
        if not gr:
            raise FitbeadError(
                f"units = 'si': the data of {self.name} were given dimensionless (column v): velocities in m/s need "
                "data with v_m_s and R_m"
            )
        lab = str(series) if series is not None else (self.series if self.series not in ("", "all") else None)
        if lab is not None:
            if lab not in gr:
                raise FitbeadError(
                    f"units = 'si': series {lab} has rows of different R_m or g (or velocities not in m/s), so no one unit "
                    "converts its velocities to m/s"
                )
            return np.sqrt(gr[lab] * (1.0 + xi))
        fitted = list(dict.fromkeys(str(x) for x in self.residuals["series"]))
        values = {gr.get(x) for x in fitted}
        if len(values) != 1 or None in values:
            raise FitbeadError(
                f"units = 'si': the series of {self.name} do not share one R_m and g: give series= (one of "
                f"{', '.join(fitted)})"
            )
        return np.sqrt(values.pop() * (1.0 + xi))

    def eval_band(
        self,
        delta_deg: ArrayLike,
        xi: Optional[ArrayLike] = None,
        *,
        level: float = 0.95,
        series: Optional[str] = None,
        draws: int = 400,
        units: str = "dimensionless",
    ) -> Table:
        """A confidence (least squares) or credible (MCMC) band of the fitted curve.

        Under least squares: the delta method, v̄ ± z σ_v̄ with σ_v̄² = J C Jᵀ, J the
        derivatives of v̄ in the parameters (central differences, step 10⁻⁴ standard
        errors) and C :attr:`covar`. Under MCMC: the quantiles (1 ∓ level)/2 of v̄ over up to
        ``draws`` posterior draws evenly spaced through the kept ones.

        Parameters
        ----------
        delta_deg : array_like
            Slopes in degrees.
        xi : array_like, optional
            Radius ratios (broadcast with ``delta_deg``); default: the ξ of the fit's series
            (or of ``series``).
        level : float, default 0.95
            Probability of the band, in (0, 1).
        series : str, optional
            As in :meth:`eval`: the series whose K (one K per series) or whose R_m and g
            (``units="si"``) to use.
        draws : int, default 400
            MCMC: the most posterior draws the quantiles are taken over.
        units : {"dimensionless", "si"}, default "dimensionless"
            The unit of ``v``, ``v_low`` and ``v_high``, as in :meth:`eval`.

        Returns
        -------
        Table
            ``xi``, ``delta_deg``, ``v`` (the fit's curve), ``v_low``, ``v_high``.

        Raises
        ------
        FitbeadError
            A level outside (0, 1), no covariance (an undetermined least-squares fit), or
            ``units`` as in :meth:`eval`.
        """
        si = _units(units)
        if not (0.0 < level < 1.0):
            raise FitbeadError(f"level = {level}: expected a value in (0, 1)")
        shape, x, d, lab = self._points(delta_deg, xi, series)
        theta0 = np.array([p.value for p in self.params.values()])
        v = self._curve(theta0[None, :], x, d, lab)[0]
        if self.draws is not None:
            flat = self.draws.reshape(-1, self.draws.shape[-1])
            pick = flat[np.unique(np.linspace(0, len(flat) - 1, min(draws, len(flat))).astype(int))]
            curves = self._curve(pick, x, d, lab)
            lo = np.nanquantile(curves, (1 - level) / 2, axis=0)
            hi = np.nanquantile(curves, (1 + level) / 2, axis=0)
        else:
            sd = self._curve_sd(theta0, x, d, lab)
            z = NormalDist().inv_cdf((1 + level) / 2)
            lo, hi = v - z * sd, v + z * sd
        if si:
            unit = self._si_unit(x, series)
            v, lo, hi = v * unit, lo * unit, hi * unit
        t = Table(xi=x.reshape(shape), delta_deg=d.reshape(shape), v=v.reshape(shape), v_low=lo.reshape(shape), v_high=hi.reshape(shape))
        t.shape = shape
        return t

    def _curve_sd(self, theta0: np.ndarray, x: np.ndarray, d: np.ndarray, lab: Optional[np.ndarray]) -> np.ndarray:
        """σ of the curve at the points (x, d) by the delta method: sqrt(J C Jᵀ), J the
        derivatives of v̄ in the parameters that vary (central differences, step 10⁻⁴
        standard errors), C :attr:`covar`; the scatter's scale does not enter the curve."""
        cov = self.covar
        if cov is None:
            raise FitbeadError(f"{self.name}: no covariance (an undetermined fit): no band")
        names = [list(self.params.values())[i].name for i in self._varying()]
        pos = self._varying()
        keep = [k for k, n in enumerate(names) if n != "sigma_scale"]
        jac = np.zeros((len(keep), x.size))
        for row, k in enumerate(keep):
            i = pos[k]
            h = 1e-4 * cov[k, k] ** 0.5 if cov[k, k] > 0 else 1e-8 * max(abs(theta0[i]), 1.0)
            up, dn = theta0.copy(), theta0.copy()
            up[i] += h
            dn[i] -= h
            jac[row] = (self._curve(up[None, :], x, d, lab)[0] - self._curve(dn[None, :], x, d, lab)[0]) / (2 * h)
        c = cov[np.ix_(keep, keep)]
        return np.sqrt(np.einsum("ip,ij,jp->p", jac, c, jac))

    def eval_uncertainty(
        self, sigma: float = 1, delta_deg: Optional[ArrayLike] = None, xi: Optional[ArrayLike] = None, *, series: Optional[str] = None
    ) -> np.ndarray:
        """Half-widths of the confidence band of the fitted curve (lmfit's
        ``eval_uncertainty``): ``scale · sqrt(J C Jᵀ)`` with J the derivatives of v̄ in the
        parameters that vary and C :attr:`covar`, at the data points (default) or at
        ``delta_deg`` (and ``xi``, ``series`` as in :meth:`eval`).

        ``sigma`` ≥ 1 is a number of standard deviations (probability erf(sigma/√2): 0.6827,
        0.9545, 0.9973 for 1, 2, 3), ``sigma`` < 1 the probability itself; the scale is the
        Student-t quantile at (1 + probability)/2 on :attr:`nfree` degrees of freedom, as
        lmfit's rule (whatever the σ convention of the covariance).

        Returns
        -------
        numpy.ndarray
            One half-width per point (``best_fit ± dely`` is the band at the data).
        """
        if not (sigma > 0):
            raise FitbeadError(f"sigma = {sigma}: expected a number of standard deviations (≥ 1) or a probability in (0, 1)")
        prob = float(sigma) if sigma < 1 else math.erf(sigma / math.sqrt(2))
        if self.nfree < 1:
            raise FitbeadError(f"{self.name}: no degree of freedom left: no band")
        scale = _core.t_quantile((1 + prob) / 2, float(self.nfree))
        if delta_deg is None:
            r = self.residuals
            x = np.asarray(r["xi"], dtype=float)
            d = np.asarray(r["delta_deg"], dtype=float)
            lab = np.asarray(r["series"], dtype=object) if self.name == "klaw-free-per-series" else None
            shape = x.shape
        else:
            shape, x, d, lab = self._points(delta_deg, xi, series)
        theta0 = np.array([p.value for p in self.params.values()])
        return (scale * self._curve_sd(theta0, x, d, lab)).reshape(shape)

    def conf_interval(self, sigmas: Sequence[float] = (1, 2, 3)) -> Dict[str, List[Tuple[float, float]]]:
        """Profile-likelihood intervals of the parameters that vary at several levels, in
        lmfit's shape: ``{key: [(p3, low3), (p2, low2), (p1, low1), (0.0, value), (p1,
        high1), (p2, high2), (p3, high3)]}`` for probabilities p = erf(sigma/√2) (a sigma < 1
        is the probability itself), sorted.

        Under least squares each level is the fit's profile interval at that level (the fit is
        made again per level): with σ given the end is where Δχ² reaches the χ²₁ quantile;
        without σ, or with ``scale_covar=True``, where it reaches χ²_min/dof times the F₁,dof
        quantile (lmfit's F-test). An end the likelihood does not reach within the search is
        ±inf (as lmfit's), an end on the parameter's box is the bound. Under MCMC the central
        posterior intervals of the draws.
        """
        probs = sorted(float(s) if s < 1 else math.erf(s / math.sqrt(2)) for s in sigmas)
        if not probs or not all(0 < p < 1 for p in probs):
            raise FitbeadError(f"sigmas = {list(sigmas)}: expected positive numbers of standard deviations or probabilities")
        keys = self.var_names
        ends: Dict[str, List[Tuple[float, float, float]]] = {k: [] for k in keys}
        for p in probs:
            for k, (lo, hi) in self._interval_at(p).items():
                if k in ends:
                    ends[k].append((p, lo, hi))
        out = {}
        for k in keys:
            lows = [(p, lo) for p, lo, _ in ends[k]]
            highs = [(p, hi) for p, _, hi in ends[k]]
            out[k] = lows[::-1] + [(0.0, self.params[k].value)] + highs
        return out

    def _interval_at(self, prob: float) -> Dict[str, Tuple[float, float]]:
        """(low, high) of every parameter that varies at level `prob` (see
        :meth:`conf_interval`)."""
        if self.draws is not None:
            flat = self.draws.reshape(-1, self.draws.shape[-1])
            keys = list(self.params)
            return {
                keys[i]: (float(np.quantile(flat[:, i], (1 - prob) / 2)), float(np.quantile(flat[:, i], (1 + prob) / 2)))
                for i in self._varying()
            }
        refit = self._refit
        if refit is None:
            raise FitbeadError(
                f"{self.name}: conf_interval needs the fit as fit_klaw, fit_jan or fit_jaeger made it (an unpickled or "
                "loaded fit cannot be made again)"
            )
        func, kwargs = refit
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            again = func(**{**kwargs, "level": prob, "profile": True})
        if isinstance(again, FitSet):
            again = again.get(self.name, self.series)
        if again is None:
            raise FitbeadError(f"{self.name} [{self.series}]: the fit could not be made again at level {prob}")
        out = {}
        for k, p in again.params.items():
            if not p.vary:
                continue
            lo = _profile_end(p.profile_low, p.profile_low_status, -math.inf)
            hi = _profile_end(p.profile_high, p.profile_high_status, math.inf)
            out[k] = (lo, hi)
        return out

    # ---- reports --------------------------------------------------------------------------

    def report(self) -> str:
        """The fit report (the command line's text)."""
        return self._core.report()

    def fit_report(self, min_correl: float = 0.1) -> str:
        """The fit report (lmfit's name for :meth:`report`), its correlations those above
        ``min_correl`` in magnitude (the command line's report shows those above 0.1)."""
        text = self.report()
        if min_correl == 0.1:
            return text
        return _with_correlations(text, self.correlations, self.var_names, min_correl)

    def __str__(self) -> str:
        return self.report()

    def __repr__(self) -> str:
        ps = ", ".join(f"{p.name}={p.value:.6g}" for p in self.params.values())
        s = f" [{self.series}]" if self.series else ""
        return f"FitResult({self.name}{s}: {ps})"

    def _repr_html_(self) -> str:
        rows = []
        for p in self.params.values():
            err = "" if math.isnan(p.stderr) else f"{p.stderr:.3g}"
            iv = "" if math.isnan(p.low) else f"[{p.low:.6g}, {p.high:.6g}] ({p.method})"
            paper = "" if math.isnan(p.paper_value) else f"{p.paper_value:.6g}"
            rows.append(
                f"<tr><td>{_html.escape(p.name)}</td><td>{p.value:.6g}</td><td>{err}</td><td>{_html.escape(iv)}</td>"
                f"<td>{paper}</td></tr>"
            )
        table = (
            "<table><thead><tr><th>parameter</th><th>value</th><th>stderr</th><th>interval</th><th>paper</th></tr></thead>"
            f"<tbody>{''.join(rows)}</tbody></table>"
        )
        return f"<div>{table}<details><summary>fit report</summary><pre>{_html.escape(self.report())}</pre></details></div>"

    def to_pandas(self, what: str = "params"):
        """A DataFrame (needs pandas) with the command line's columns and numeric dtypes
        (NaN for an empty cell).

        Parameters
        ----------
        what : {"params", "stats", "residuals", "correlations", "draws"}
            ``params`` (params.csv: one row per parameter), ``stats`` (stats.csv: one row),
            ``residuals`` (residuals.csv: one row per point), ``correlations``
            (correlations.csv: one row per pair), ``draws`` (one row per kept draw, with
            walker and step).
        """
        import pandas as pd

        if what == "params":
            return _frame(self._core.params(), _core.record_columns("params"))
        if what == "stats":
            return _frame([self._core.stats()], _core.record_columns("stats"))
        if what == "residuals":
            records = self._core.residual_records()
            columns = list(_core.record_columns("residuals"))
            if any("delta_fit_deg" in r for r in records):
                columns += ["delta_fit_deg", "delta_residual"]
            return _frame(records, columns)
        if what == "correlations":
            return _frame(self._core.correlation_records(), _core.record_columns("correlations"))
        if what == "draws":
            if self.draws is None:
                raise FitbeadError("no draws: a least-squares fit")
            w, s, k = self.draws.shape
            df = pd.DataFrame(self.draws.reshape(w * s, k), columns=self.param_names)
            df.insert(0, "step", np.tile(np.arange(s) * max(self.thin, 1) + self.burn_in + 1, w))
            df.insert(0, "walker", np.repeat(np.arange(w), s))
            return df
        raise FitbeadError(f"what = {what!r}: expected params, stats, residuals, correlations or draws")

    def log_likelihood(self) -> np.ndarray:
        """The pointwise log likelihood ``[walker, kept step, point]`` of the posterior draws
        (MCMC): ln N(v_i | v̄_i(θ), (s σ_i)²), with σ_i the point's σ (1 without) and s the
        scatter's scale where it is sampled (``sigma_scale``), constants included."""
        if self.draws is None:
            raise FitbeadError("no draws: the log likelihood per draw needs an MCMC fit (method='mcmc')")
        r = self.residuals
        w, s, k = self.draws.shape
        flat = self.draws.reshape(w * s, k)
        x = np.asarray(r["xi"], dtype=float)
        d = np.asarray(r["delta_deg"], dtype=float)
        lab = np.asarray(r["series"], dtype=object) if self.name == "klaw-free-per-series" else None
        vfit = np.concatenate([self._curve(flat[i : i + 4096], x, d, lab) for i in range(0, len(flat), 4096)])
        sig = np.asarray(r["sigma_v"], dtype=float)
        sig = np.where(np.isnan(sig), 1.0, sig)[None, :]
        names = [p.name for p in self.params.values()]
        scale = flat[:, names.index("sigma_scale")][:, None] if "sigma_scale" in names else 1.0
        sd = scale * sig
        z = (np.asarray(r["v"], dtype=float)[None, :] - vfit) / sd
        ll = -0.5 * z * z - np.log(sd) - 0.5 * math.log(2 * math.pi)
        return ll.reshape(w, s, -1)

    def to_arviz(self):
        """The posterior as an ``arviz.InferenceData`` (needs ArviZ): ``posterior`` (one
        chain per walker), ``log_likelihood`` (``v``, per point: :meth:`log_likelihood`, so
        ``az.loo``, ``az.waic`` and ``az.compare`` work), ``sample_stats`` (``lp``: the log
        posterior), ``observed_data`` (``v``) and ``constant_data`` (``xi``, ``delta_deg``,
        ``sigma_v``)."""
        import arviz as az

        if self.draws is None:
            raise FitbeadError("no draws: to_arviz needs an MCMC fit (method='mcmc')")
        post = {n: self.draws[:, :, i] for i, n in enumerate(self.param_names)}
        r = self.residuals
        return az.from_dict(
            posterior=post,
            log_likelihood={"v": self.log_likelihood()},
            sample_stats={"lp": self.log_posterior},
            observed_data={"v": r["v"]},
            constant_data={"xi": r["xi"], "delta_deg": r["delta_deg"], "sigma_v": r["sigma_v"]},
            dims={"v": ["point"], "xi": ["point"], "delta_deg": ["point"], "sigma_v": ["point"]},
            attrs={"fit": self.name, "series": self.series, "burn_in": self.burn_in, "thin": self.thin},
        )

    def plot(self, ax: Any = None, *, level: float = 0.95, units: str = "dimensionless"):
        """Data with error bars, the fitted curve and its band (:meth:`eval_band`) per
        series, and the normalised residuals below (needs matplotlib).

        Parameters
        ----------
        ax : matplotlib Axes, or a sequence of two, optional
            Where to draw: one Axes gets the data, curves and bands only (as lmfit's
            ``plot_fit``); two get the curves and the residuals; default: a new figure with
            both.
        level : float
            Level of the band.
        units : {"dimensionless", "si"}, default "dimensionless"
            Velocities (data, error bars, curves, bands) in the library's unit or in m/s
            (``si``: for data given in m/s, each series with its own R_m and g, as in
            :meth:`eval`); the residuals stay normalised by σ.

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        FitbeadError
            An unknown ``units``, or ``si`` where the data were not given in m/s (as in
            :meth:`eval`).
        """
        si = _units(units)
        r = self.residuals
        labels = list(dict.fromkeys(r["series"]))
        # The unit of each series, checked before anything is drawn.
        scale = {lab: float(self._si_unit(np.asarray(r["xi"])[r["series"] == lab][:1], lab)[0]) if si else 1.0 for lab in labels}
        import matplotlib.pyplot as plt

        single = ax is not None and hasattr(ax, "errorbar")
        if ax is None:
            fig, ax = plt.subplots(2, 1, sharex=True, height_ratios=[3, 1], figsize=(6.4, 5.6))
        elif single:
            fig = ax.figure
            ax = [ax, None]
        else:
            fig = ax[0].figure
        for lab in labels:
            m = r["series"] == lab
            d, v, s = np.asarray(r["delta_deg"])[m], np.asarray(r["v"])[m] * scale[lab], np.asarray(r["sigma_v"])[m] * scale[lab]
            xi = float(np.asarray(r["xi"])[m][0])
            pts = ax[0].errorbar(d, v, yerr=None if np.isnan(s).all() else s, fmt="o", ms=4, capsize=2, label=f"ξ = {xi:g}")
            grid = np.linspace(d.min(), d.max(), 120)
            try:
                band = self.eval_band(grid, xi, level=level, series=lab if self.name == "klaw-free-per-series" else None)
            except FitbeadError:
                band = None
            color = pts[0].get_color()
            if band is not None:
                k = scale[lab]
                ax[0].plot(grid, band["v"] * k, color=color, lw=1.2)
                ax[0].fill_between(grid, band["v_low"] * k, band["v_high"] * k, color=color, alpha=0.2, lw=0)
            if ax[1] is not None:
                ax[1].plot(d, np.asarray(r["normalised_residual"])[m], "o", ms=4, color=color)
        ax[0].set_ylabel("mean velocity v̄ (m/s)" if si else "mean velocity v̄ / √(g(R+r))")
        if ax[1] is not None:
            ax[1].axhline(0, color="0.5", lw=0.8)
            ax[1].set_ylabel("residual / σ")
            ax[1].set_xlabel("slope δ (degrees)")
        else:
            ax[0].set_xlabel("slope δ (degrees)")
        ax[0].set_title(f"{self.name}" + (f" [{self.series}]" if self.series not in ("", "all") else "") + f", band {level:.0%}")
        ax[0].legend(fontsize="small")
        return fig


def _profile_end(value: float, status: str, beyond: float) -> float:
    """An end of a profile interval as lmfit's ``conf_interval`` gives it: the end found (or
    the box's bound, or the edge of the feasible region), ±inf where the likelihood does not
    fall to the level within the search."""
    if status in ("found", "bound", "edge") and not math.isnan(value):
        return float(value)
    return beyond


def _with_correlations(text: str, correlations: Dict[Tuple[str, str], float], names: Sequence[str], min_correl: float) -> str:
    """The fit report `text` with its correlations section made again for the pairs of
    `names` above `min_correl` in magnitude (the command line's format)."""
    lines = text.split("\n")
    start = next((i for i, ln in enumerate(lines) if ln.startswith("[[Correlations]]")), None)
    if start is not None:
        end = next((j for j in range(start + 1, len(lines)) if lines[j].startswith("[[")), len(lines))
        del lines[start:end]
        at = start
    else:
        at = next((i for i, ln in enumerate(lines) if ln.startswith("[[Warnings]]")), None)
        if at is None:
            at = len(lines) - 1 if lines and lines[-1] == "" else len(lines)
    pairs = [(r, a, b) for (a, b), r in correlations.items() if a in names and b in names and abs(r) > min_correl]
    pairs.sort(key=lambda t: -abs(t[0]))
    if pairs:
        block = [f"[[Correlations]] (unreported correlations are < {min_correl:g})"]
        block += [f"    C({a}, {b}) = {r:+.4f}" for r, a, b in pairs]
        lines[at:at] = block
    return "\n".join(lines)


class FitSet(list):
    """The fits of one run (Jan's per-series fits and global laws; Jaeger's per series), with
    the run's notes. A list of :class:`FitResult`."""

    def __init__(self, fits: Iterable[FitResult], notes: Iterable[str]) -> None:
        super().__init__(fits)
        self.notes: List[str] = list(notes)

    def __eq__(self, other: Any) -> bool:
        """The same fits in the same order (:meth:`FitResult.__eq__`), and against a FitSet
        the same notes."""
        if isinstance(other, FitSet):
            return _same(self, other) if type(self) is type(other) else False
        if isinstance(other, list):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other))
        return NotImplemented

    def __ne__(self, other: Any) -> bool:
        eq = self.__eq__(other)
        return eq if eq is NotImplemented else not eq

    __hash__ = None  # type: ignore[assignment]

    def save(self, path: Any) -> None:
        """Writes the fits and the notes to a JSON file that :func:`load` reads back as an equal
        FitSet (the format: :func:`load`); written atomically.

        Parameters
        ----------
        path : str or path-like
            The file to write (replaced if it exists).
        """
        _save(path, "fitset", lambda: {"fits": [fr._json(f"fitset.fits[{i}]") for i, fr in enumerate(self)], "notes": list(self.notes)})

    def get(self, name: str, series: Any = None, default: Any = None) -> Optional[FitResult]:
        """The fit named ``name`` (``jan-series``, ``jan-global``, ``jaeger``) for ``series``,
        or ``default`` when there is none.

        Parameters
        ----------
        name : str
            The fit's name.
        series : str or float, optional
            The series: its label, or a number matched against the labels read as numbers
            and against the series' ξ (``1.0`` finds the series labelled ``"1"``); ``all``
            for a global fit. None: the first fit of that name.
        default : optional
            What to return when no fit matches (None).
        """
        for fr in self:
            if fr.name == name and (series is None or _same_series(fr, series)):
                return fr
        return default

    def __getitem__(self, key: Any) -> Any:
        """A fit by position (as a list), by name (the first fit of that name) or by
        ``(name, series)`` (as :meth:`get`); KeyError naming the fits there are when none
        matches."""
        if isinstance(key, (int, slice, np.integer)):
            return list.__getitem__(self, key)
        name, series = (key, None) if isinstance(key, str) else tuple(key)
        fr = self.get(name, series)
        if fr is None:
            have = ", ".join(f"({f.name!r}, {f.series!r})" for f in self)
            raise KeyError(f"no fit {key!r}; the fits are {have}")
        return fr

    def __contains__(self, key: Any) -> bool:
        if isinstance(key, FitResult):
            return list.__contains__(self, key)
        try:
            self[key]
        except (KeyError, TypeError, ValueError):
            return False
        return True

    def keys(self) -> List[Tuple[str, str]]:
        """``(name, series)`` of every fit, in order."""
        return [(f.name, f.series) for f in self]

    def to_arviz(self, joined: bool = False):
        """The posteriors of the run's fits as ``arviz.InferenceData`` (needs ArviZ and MCMC
        fits).

        Parameters
        ----------
        joined : bool, default False
            False: one InferenceData per fit, keyed ``name[series]``, each as
            :meth:`FitResult.to_arviz`. True: one per fit name, keyed by it
            (``jan-series``, ``jan-global``; ``jaeger``), the fits of one name joined over
            the points of all their series, so that ``az.compare`` weighs the per-series
            fits against the global one on the same points (``az.compare`` needs the same
            points in every model: a series with too few points for its own fit is left out
            of the joined fits but not of the global one).

        Returns
        -------
        dict of str to arviz.InferenceData

        Notes
        -----
        The fits of one name are independent posteriors, so draw ``(w, s)`` of each series
        together is a draw of their joint posterior: the joined ``posterior`` has each
        parameter over ``(chain, draw, series)``, the ``log_likelihood`` ``v`` the pointwise
        log likelihoods of every series (``point``: the series in the set's order, each in
        its fit's order of points), ``sample_stats`` ``lp`` the sum of the log posteriors.
        Runs of different lengths are joined over the last kept steps they all have, and
        over the walkers they all have.
        """
        if not joined:
            return {f"{f.name}[{f.series}]": f.to_arviz() for f in self}
        names = list(dict.fromkeys(f.name for f in self))
        return {name: _joined_arviz([f for f in self if f.name == name]) for name in names}

    def plot(self, **kwargs: Any):
        """Every fit's :meth:`FitResult.plot`, one figure each; returns the figures."""
        return [f.plot(**kwargs) for f in self]

    def __str__(self) -> str:
        parts = [str(fr) for fr in self]
        if self.notes:
            parts.append("notes:\n" + "\n".join(f"  {n}" for n in self.notes))
        return "\n\n".join(parts)

    def _repr_html_(self) -> str:
        return "".join(fr._repr_html_() for fr in self)

    def to_pandas(self, what: str = "params"):
        """Every fit's table in one DataFrame (needs pandas), with the command line's columns
        (its CSV of the whole run), numeric dtypes and NaN for empty cells.

        Parameters
        ----------
        what : {"params", "stats", "residuals", "correlations"}, default "params"
            Which table, as :meth:`FitResult.to_pandas` (the draws are per fit:
            ``fits[i].to_pandas("draws")``).

        Returns
        -------
        pandas.DataFrame
            One fit's rows after another, in the order of the set.
        """
        import pandas as pd

        if what == "draws":
            raise FitbeadError("draws: take them from each fit (fits[i].to_pandas('draws'))")
        frames = [fr.to_pandas(what) for fr in self]
        if not frames:
            return _frame([], _core.record_columns(what))
        return pd.concat(frames, ignore_index=True)


def _joined_arviz(fits: List[FitResult]):
    """One ``arviz.InferenceData`` of the fits of one name, independent posteriors joined
    draw by draw over their common walkers and last kept steps (see
    :meth:`FitSet.to_arviz`)."""
    import arviz as az

    if len(fits) == 1:
        return fits[0].to_arviz()
    missing = [f"{f.name}[{f.series}]" for f in fits if f.draws is None]
    if missing:
        raise FitbeadError(f"no draws in {', '.join(missing)}: to_arviz needs MCMC fits (method='mcmc')")
    walkers = min(f.draws.shape[0] for f in fits)  # type: ignore[union-attr]
    steps = min(f.draws.shape[1] for f in fits)  # type: ignore[union-attr]
    labels = [f.series for f in fits]
    names = list(dict.fromkeys(n for f in fits for n in f.param_names))
    post = {}
    for n in names:
        cols = []
        for f in fits:
            d = f.draws[:walkers, -steps:, :]  # type: ignore[index]
            cols.append(d[:, :, f.param_names.index(n)] if n in f.param_names else np.full(d.shape[:2], np.nan))
        post[n] = np.stack(cols, axis=-1)
    ll = np.concatenate([f.log_likelihood()[:walkers, -steps:, :] for f in fits], axis=-1)
    lp = sum(f.log_posterior[:walkers, -steps:] for f in fits)  # type: ignore[index]
    col = lambda k: np.concatenate([np.asarray(f.residuals[k], dtype=float) for f in fits])  # noqa: E731
    point_series = np.concatenate([np.asarray(f.residuals["series"], dtype=str) for f in fits])
    return az.from_dict(
        posterior=post,
        log_likelihood={"v": ll},
        sample_stats={"lp": lp},
        observed_data={"v": col("v")},
        constant_data={"xi": col("xi"), "delta_deg": col("delta_deg"), "sigma_v": col("sigma_v"), "point_series": point_series},
        coords={"series": labels},
        dims={**{n: ["series"] for n in names}, "v": ["point"], "xi": ["point"], "delta_deg": ["point"], "sigma_v": ["point"], "point_series": ["point"]},
        attrs={"fit": fits[0].name, "series": ",".join(labels), "joined": 1},
    )


def _same_series(fr: "FitResult", series: Any) -> bool:
    """Whether `fr` is the fit of `series`: its label, or a number equal to the label read as
    a number or to the series' ξ."""
    if isinstance(series, str):
        return fr.series == series
    try:
        x = float(series)
    except (TypeError, ValueError):
        return False
    try:
        if float(fr.series) == x:
            return True
    except ValueError:
        pass
    xi = fr.residuals.get("xi")
    return xi is not None and len(xi) > 0 and bool(np.all(np.asarray(xi, dtype=float) == x))


def _fitted(core: Any, context: Dict[str, Any], refit: Optional[Tuple[Any, Dict[str, Any]]] = None) -> FitResult:
    fr = FitResult(core, context)
    fr._refit = refit
    fr._warn()
    return fr


_UNITS = ("dimensionless", "si")


def _units(units: Any) -> bool:
    """Whether ``units`` asks for SI velocities (m/s); FitbeadError for an unknown value."""
    if units not in _UNITS:
        raise FitbeadError(f"units = {units!r}: expected 'dimensionless' or 'si'")
    return units == "si"


def _si_context(d: Dataset) -> Dict[str, float]:
    """For data given in m/s (``v_m_s`` with ``R_m``): ``g_R[LABEL]``, the product g·R
    (m²/s²) of each series whose rows share one R_m and one g, so that a velocity of the
    series in m/s is v·sqrt(g R (1 + ξ)); empty for dimensionless data."""
    fc = d.file_columns()
    if "R_m" not in fc or "v_m_s" not in fc:
        return {}
    g_default = float(dict(d._core.state()).get("g", 9.81))
    r = fc["R_m"]
    g = fc.get("g", np.full(r.shape, np.nan))
    g = np.where(np.isnan(g), g_default, g)
    labels = d.columns()["series"]
    out: Dict[str, float] = {}
    for lab in dict.fromkeys(labels):
        m = labels == lab
        pairs = set(zip(r[m].tolist(), g[m].tolist()))
        if len(pairs) == 1:
            (rr, gg), = pairs
            if not (math.isnan(rr) or math.isnan(gg)):
                out[f"g_R[{lab}]"] = gg * rr
    return out


def _material_context(d: Dataset) -> Dict[str, Any]:
    """ρ and f of the data's rows, which a K(α) law's curve is drawn with: ``rho`` and ``f``
    where every row has the same, else ``mixed_material``."""
    c = d.columns()
    rho, f = np.unique(c["rho"]), np.unique(c["f"])
    if rho.size == 1 and f.size == 1:
        return {"rho": float(rho[0]), "f": float(f[0])}
    return {"mixed_material": True}


def _controlled(context: Dict[str, Any], scale_covar: bool) -> Dict[str, Any]:
    """`context` with ``scale_covar`` where it is on (a context holds text, numbers and
    booleans only: it is saved with the fit)."""
    return {**context, "scale_covar": True} if scale_covar else context


def _fit_data(
    data: Any,
    rho: Optional[float],
    f: Optional[float],
    g: Optional[float],
    sigma_delta: Optional[float] = None,
    strict_columns: bool = False,
) -> Dataset:
    """The data of a fit, read again with the defaults given for the columns rows leave out."""
    d = _dataset(data, strict_columns)
    if rho is None and f is None and g is None and sigma_delta is None:
        return d
    return Dataset(d._core.with_defaults(rho=rho, f=f, g=g, sigma_delta=sigma_delta))


def _counts(**given: Any) -> None:
    """Refuses a sampler setting that is not a whole number in its range, naming it: ``seed``
    ≥ 0, ``walkers``/``max_steps``/``thin`` ≥ 1 (None: the default) — instead of the
    OverflowError or TypeError of the conversion to the library's unsigned integers."""
    for name, x in given.items():
        if x is None and name != "seed":
            continue
        low = 0 if name == "seed" else 1
        ok = isinstance(x, (int, np.integer)) and not isinstance(x, bool) and low <= x < 2**64
        if not ok:
            why = "a run is reproducible from its seed: give one" if x is None else f"expected a whole number >= {low}"
            raise FitbeadError(f"{name} = {x!r}: {why}")


def _priors(priors: Any) -> List[Tuple[str, str]]:
    """Priors as (name, distribution) pairs, from a mapping or from ``NAME=DIST`` strings."""
    if priors is None:
        return []
    if isinstance(priors, Mapping):
        return [(str(k), str(v)) for k, v in priors.items()]
    if isinstance(priors, str):
        priors = [priors]
    out = []
    for p in priors:
        name, sep, dist = str(p).partition("=")
        if not sep:
            raise FitbeadError(f"prior = '{p}': expected NAME=DIST, e.g. 'c=normal(0.5,0.1)'")
        out.append((name.strip(), dist.strip()))
    return out


def _named_values(what: str, given: Any) -> List[Tuple[str, float]]:
    """``fix`` or ``init`` as (name, value) pairs, from a mapping ``{"a2": 0.0}`` or pairs."""
    if given is None:
        return []
    items = given.items() if isinstance(given, Mapping) else given
    out = []
    for item in items:
        try:
            name, value = item
            out.append((str(name), float(value)))
        except (TypeError, ValueError):
            raise FitbeadError(f"{what} = {given!r}: expected {{name: value}}, e.g. {{'a2': 0.0}}") from None
    return out


def _named_bounds(given: Any) -> List[Tuple[str, Tuple[float, float]]]:
    """``bounds`` as (name, (low, high)) pairs, from ``{"c": (0.3, 0.9)}``; None for an open
    side."""
    if given is None:
        return []
    items = given.items() if isinstance(given, Mapping) else given
    out = []
    for item in items:
        try:
            name, (lo, hi) = item
            lo = -math.inf if lo is None else float(lo)
            hi = math.inf if hi is None else float(hi)
        except (TypeError, ValueError):
            raise FitbeadError(f"bounds = {given!r}: expected {{name: (low, high)}}, e.g. {{'c': (0.3, 0.9)}}") from None
        out.append((str(name), (lo, hi)))
    return out


def _draws_wanted(path: Any, method: str) -> bool:
    """Whether the draws CSV is asked for; an error before the fit when the method has none."""
    if path is None:
        return False
    if str(method).lower() != "mcmc":
        raise FitbeadError("draws: applies to method = 'mcmc' only")
    return True


def _write_draws(path: Any, text: Optional[bytes]) -> None:
    """Writes the draws CSV to `path` atomically (a temporary file renamed over it)."""
    if path is None or text is None:
        return
    import tempfile

    target = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(target))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".fitbead-draws-")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(bytes(text))
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def fit_klaw(
    data: Any = None,
    *,
    model: str = "stickslip",
    law: str = "c",
    method: str = "lsq",
    level: float = 0.95,
    profile: bool = True,
    seed: int = 1,
    walkers: Optional[int] = None,
    max_steps: Optional[int] = None,
    min_ess: Optional[float] = None,
    tol: float = 1e-10,
    skip_unsteady: bool = False,
    thin: Optional[int] = None,
    priors: Any = None,
    fit_scatter: bool = False,
    draws: Any = None,
    rho: Optional[float] = None,
    f: Optional[float] = None,
    g: Optional[float] = None,
    sigma_delta: Optional[float] = None,
    strict_columns: bool = False,
    fix: Optional[Mapping[str, float]] = None,
    init: Optional[Mapping[str, float]] = None,
    bounds: Optional[Mapping[str, Tuple[Optional[float], Optional[float]]]] = None,
    scale_covar: bool = False,
) -> FitResult:
    """A law K(α) fitted to every series at once (``fitbead klaw``).

    Parameters
    ----------
    data : Dataset, str, path, DataFrame or Table, optional
        The measurements (default: the shipped data); a Table is what :func:`simulate`
        returns.
    model : str, default "stickslip"
        The contact model: ``stick``, ``stick-approx``, ``slip``, ``slip-approx``,
        ``stickslip``, ``contact``, or ``auto`` (the most general model any point needs at
        its stick K, for all points; said in a :class:`FitbeadWarning`).
    law : str, default "c"
        ``c`` (K = cos 2α + c sin²α sin 2α), ``free-per-series`` (one K per series) or
        ``impact`` (nothing fitted: scored).
    method : {"lsq", "mcmc"}, default "lsq"
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum: the
        result's value is the posterior median, ``draws`` the kept draws).
    level : float, default 0.95
        Confidence level of the intervals, in (0, 1).
    profile : bool, default True
        Least squares: profile-likelihood intervals (else the covariance's).
    seed : int, default 1
        MCMC: the seed (the same draws on any machine and thread count).
    walkers, max_steps : int, optional
        MCMC: the walkers (default: the library's choice) and the step limit.
    min_ess : float, optional
        MCMC: the bulk and tail ESS every parameter must reach (with rank-normalised split-R̂
        ≤ 1.01) before the run stops (default 1000). The run is also at least 50
        autocorrelation times long and is checked every 500 steps, so a ``min_ess`` below
        the ESS those give (on the shipped data, thousands at 1,000 steps)
        does not shorten it; ``stats["steps"]`` and ``stats["ess_min"]`` say what it did.
    tol : float, default 1e-10
        With ``model="auto"``: the target relative tolerance on v.
    skip_unsteady : bool, default False
        Leave out the points no K makes steady under the model (each named in a
        :class:`FitbeadWarning`) instead of raising.
    thin : int, optional
        MCMC: keep one step in ``thin`` (default 1).
    priors : mapping or sequence, optional
        MCMC: priors by parameter, as ``{"c": "normal(0.5,0.1)"}`` or ``["c=normal(0.5,0.1)"]``;
        a distribution is ``flat``, ``jeffreys``, ``uniform(a,b)``, ``normal(mean,sd)``,
        ``lognormal(mu,sigma)`` or ``halfnormal(scale)`` (the command line's ``--prior``).
    fit_scatter : bool, default False
        MCMC: also sample an error scale ``sigma_scale`` multiplying every sigma_v.
    draws : str or path, optional
        MCMC: write the kept draws to this CSV (the command line's ``--draws`` file),
        atomically.
    rho, f, g : float, optional
        ρ, f and g (m/s²) of the rows whose columns leave them out (defaults 0.4, 0.1, 9.81):
        the data are read again with them.
    sigma_delta : float, optional
        Standard uncertainty of the slope, degrees, for rows without a ``sigma_delta_deg``
        value (the command line's ``--sigma-delta``; default 0: slopes exact). Above 0 a
        least-squares fit is an orthogonal distance regression.
    strict_columns : bool, default False
        A path, DataFrame or Table as ``data``: refuse any column fitbead does not read (the
        command line's ``--strict-columns``) instead of warning (:class:`ColumnWarning`) about
        those that look misnamed.
    fix : mapping, optional
        Parameters held at a value, ``{"a2": 0.0}`` (lmfit's ``vary=False``; the command
        line's ``--fix``): ``NAME`` in every fit that has it, ``"NAME[SERIES]"`` in that
        series' fit alone. A held parameter is not fitted: no stderr or interval, no degree
        of freedom (``vary`` is False on its :class:`Param`).
    init : mapping, optional
        Starting values, ``{"c": 0.6}`` (``--init``), instead of the fit's own start; each
        must lie in the parameter's box.
    bounds : mapping, optional
        Bounds, ``{"c": (0.3, 0.9)}`` (``--bounds``; None leaves a side open), intersected
        with the parameter's box.
    scale_covar : bool, default False
        Least squares: scale the covariance by the reduced χ² even with sigma_v given, as
        lmfit's ``scale_covar=True`` (``--scale-covar``); without sigma_v it is scaled
        already.

    Returns
    -------
    FitResult

    Raises
    ------
    FitbeadError
        Bad data or settings (the command line's message).
    Interrupted
        Ctrl-C stops a run cleanly and raises; a posterior run's draws so far are the
        exception's ``result`` (a ``KeyboardInterrupt`` where nothing was kept yet).

    Warns
    -----
    UnitWarning, ConvergenceWarning, BoundWarning, ColumnWarning
        The command line's warnings on the data and the fit.
    """
    _counts(seed=seed, walkers=walkers, max_steps=max_steps, thin=thin)
    d = _fit_data(data, rho, f, g, sigma_delta, strict_columns)
    fits, notes, text, signal = _core.fit_klaw(
        d._core, model=_model_name(model), law=law, method=method, level=level, profile=profile, seed=seed, walkers=walkers,
        max_steps=max_steps, min_ess=min_ess, tol=tol, thin=thin, priors=_priors(priors), fit_scatter=fit_scatter,
        skip_unsteady=skip_unsteady, draws=_draws_wanted(draws, method), fix=_named_values("fix", fix),
        init=_named_values("init", init), bounds=_named_bounds(bounds), scale_covar=scale_covar,
    )
    _write_draws(draws, text)
    again = dict(
        data=d, model=model, law=law, method=method, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps,
        min_ess=min_ess, tol=tol, skip_unsteady=skip_unsteady, thin=thin, priors=priors, fit_scatter=fit_scatter,
        fix=fix, init=init, bounds=bounds, scale_covar=scale_covar,
    )
    context = _controlled({"model": _model_name(model), **_material_context(d), **_si_context(d)}, scale_covar)
    out = _fitted(fits[0], context, (fit_klaw, again))
    _stopped(signal, out)
    return out


def fit_jan(
    data: Any = None,
    *,
    method: str = "lsq",
    level: float = 0.95,
    profile: bool = True,
    seed: int = 1,
    walkers: Optional[int] = None,
    max_steps: Optional[int] = None,
    min_ess: Optional[float] = None,
    thin: Optional[int] = None,
    priors: Any = None,
    fit_scatter: bool = False,
    draws: Any = None,
    rho: Optional[float] = None,
    f: Optional[float] = None,
    g: Optional[float] = None,
    sigma_delta: Optional[float] = None,
    strict_columns: bool = False,
    fix: Optional[Mapping[str, float]] = None,
    init: Optional[Mapping[str, float]] = None,
    bounds: Optional[Mapping[str, Tuple[Optional[float], Optional[float]]]] = None,
    scale_covar: bool = False,
) -> FitSet:
    """Jan's energy balance (eq 74): λ and μ per series (at least 3 points), then the global
    laws of eqs 75–76 (``fitbead jan``).

    Parameters
    ----------
    data : Dataset, str, path, DataFrame or Table, optional
        The measurements (default: the shipped data); a Table is what :func:`simulate`
        returns.
    method : {"lsq", "mcmc"}, default "lsq"
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum).
    level : float, default 0.95
        Confidence level of the intervals, in (0, 1).
    profile : bool, default True
        Least squares: profile-likelihood intervals (else the covariance's).
    seed, walkers, max_steps, min_ess, thin, priors, fit_scatter, draws
        MCMC settings, as in :func:`fit_klaw`.
    rho, f, g, sigma_delta, strict_columns : optional
        As in :func:`fit_klaw`.
    fix, init, bounds, scale_covar
        As in :func:`fit_klaw`; the names are ``lambda``, ``mu`` (per series) and
        ``lambda0``, ``lambda1``, ``mu0``, ``mu1`` (the global laws).

    Returns
    -------
    FitSet
        ``jan-series`` fits (λ, μ) per series, then ``jan-global`` (λ0, λ1, μ0, μ1 of
        λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α}).

    Raises
    ------
    FitbeadError
        Bad data or settings (the command line's message).
    Interrupted
        Ctrl-C, as in :func:`fit_klaw`: the run's draws so far are the exception's
        ``result``, a FitSet.

    Warns
    -----
    UnitWarning, ConvergenceWarning, BoundWarning, ColumnWarning
        The command line's warnings on the data and the fits.
    """
    _counts(seed=seed, walkers=walkers, max_steps=max_steps, thin=thin)
    d = _fit_data(data, rho, f, g, sigma_delta, strict_columns)
    fits, notes, text, signal = _core.fit_jan(
        d._core, method=method, level=level, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps,
        min_ess=min_ess, thin=thin, priors=_priors(priors), fit_scatter=fit_scatter, draws=_draws_wanted(draws, method),
        fix=_named_values("fix", fix), init=_named_values("init", init), bounds=_named_bounds(bounds), scale_covar=scale_covar,
    )
    _write_draws(draws, text)
    again = dict(
        data=d, method=method, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps, min_ess=min_ess, thin=thin,
        priors=priors, fit_scatter=fit_scatter, fix=fix, init=init, bounds=bounds, scale_covar=scale_covar,
    )
    context = _controlled(_si_context(d), scale_covar)
    out = FitSet([_fitted(x, context, (fit_jan, again)) for x in fits], notes)
    _stopped(signal, out)
    return out


def fit_jaeger(
    data: Any = None,
    *,
    branch: str = "upper",
    method: str = "lsq",
    level: float = 0.95,
    profile: bool = True,
    seed: int = 1,
    walkers: Optional[int] = None,
    max_steps: Optional[int] = None,
    min_ess: Optional[float] = None,
    thin: Optional[int] = None,
    priors: Any = None,
    fit_scatter: bool = False,
    draws: Any = None,
    rho: Optional[float] = None,
    f: Optional[float] = None,
    g: Optional[float] = None,
    sigma_delta: Optional[float] = None,
    strict_columns: bool = False,
    fix: Optional[Mapping[str, float]] = None,
    init: Optional[Mapping[str, float]] = None,
    bounds: Optional[Mapping[str, Tuple[Optional[float], Optional[float]]]] = None,
    scale_covar: bool = False,
) -> FitSet:
    """Jaeger's heuristic law (eqs 80–84): a1, a2, a3 per series with at least 4 points
    (``fitbead jaeger``).

    Parameters
    ----------
    data : Dataset, str, path, DataFrame or Table, optional
        The measurements (default: the shipped data); a Table is what :func:`simulate`
        returns.
    branch : {"upper", "lower"}, default "upper"
        The root of eq 84 when there are two.
    method : {"lsq", "mcmc"}, default "lsq"
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum).
    level : float, default 0.95
        Confidence level of the intervals, in (0, 1).
    profile : bool, default True
        Least squares: profile-likelihood intervals (else the covariance's).
    seed, walkers, max_steps, min_ess, thin, priors, fit_scatter, draws
        MCMC settings, as in :func:`fit_klaw`.
    rho, f, g, sigma_delta, strict_columns : optional
        As in :func:`fit_klaw`.
    fix, init, bounds, scale_covar
        As in :func:`fit_klaw`; the names are ``a1``, ``a2``, ``a3`` (``fix={"a2": 0}`` is
        Jan's law, eq 74).

    Returns
    -------
    FitSet
        One ``jaeger`` fit per series.

    Raises
    ------
    FitbeadError
        Bad data or settings (the command line's message).
    Interrupted
        Ctrl-C, as in :func:`fit_klaw`: the run's draws so far are the exception's
        ``result``, a FitSet.

    Warns
    -----
    UnitWarning, ConvergenceWarning, BoundWarning, ColumnWarning
        The command line's warnings on the data and the fits.
    """
    _counts(seed=seed, walkers=walkers, max_steps=max_steps, thin=thin)
    d = _fit_data(data, rho, f, g, sigma_delta, strict_columns)
    fits, notes, text, signal = _core.fit_jaeger(
        d._core, branch=branch, method=method, level=level, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps,
        min_ess=min_ess, thin=thin, priors=_priors(priors), fit_scatter=fit_scatter, draws=_draws_wanted(draws, method),
        fix=_named_values("fix", fix), init=_named_values("init", init), bounds=_named_bounds(bounds), scale_covar=scale_covar,
    )
    _write_draws(draws, text)
    again = dict(
        data=d, branch=branch, method=method, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps,
        min_ess=min_ess, thin=thin, priors=priors, fit_scatter=fit_scatter, fix=fix, init=init, bounds=bounds,
        scale_covar=scale_covar,
    )
    context = _controlled({"branch": branch, **_si_context(d)}, scale_covar)
    out = FitSet([_fitted(x, context, (fit_jaeger, again)) for x in fits], notes)
    _stopped(signal, out)
    return out


class Design:
    """An experimental design (:func:`design`): where to measure and what it buys.

    Attributes
    ----------
    table : Table
        The design: ``series``, ``xi``, ``delta_deg``, ``replicates`` (the columns of
        ``fitbead design --output``; ``simulate --design`` reads them).
    even : Table
        Evenly spaced slopes over the same ranges with the same points per series.
    errors : dict
        Per parameter: ``{"guess", "stderr_design", "stderr_even"}`` (predicted standard
        errors; NaN where the design does not determine the parameter).
    target : str or None
        The c-criterion's parameter.
    efficiency : float
        Efficiency of the evenly spaced slopes relative to the design (D: (det M_even /
        det M)^(1/p); c: Var / Var_even; T: T_even / T).
    gap : float
        Equivalence gap of the approximate design (0 at the optimum).
    discrimination, points_needed : tuple of float or None
        T criterion: the noncentrality at the design and at evenly spaced slopes, and the
        points needed in all for power 0.8 at significance 0.05.
    ranges : list of (float, float)
        The slope range of each series, degrees.
    bayes : tuple of int or None
        A Bayesian design: the prior draws averaged over and the draws redrawn (a series
        without a steady slope in its range).
    steady : list of dict
        Per row of ``table``, the range ``(low, high)`` of each parameter that moves its
        series over which its slope stays steady (regime B), the others at the guess; an
        end is None where the steady state holds to the end of the parameter's domain.
    """

    def __init__(self, raw: Mapping[str, Any]) -> None:
        def table(d: Mapping[str, Any]) -> Table:
            t = Table(
                series=np.asarray(d["series"], dtype=object),
                xi=np.asarray(d["xi"], dtype=float),
                delta_deg=np.asarray(d["delta_deg"], dtype=float),
                replicates=np.asarray(d["replicates"], dtype=np.int64),
            )
            t.shape = t["xi"].shape
            return t

        self.table = table(raw["design"])
        self.even = table(raw["even"])
        self.errors: Dict[str, Dict[str, float]] = {
            e["parameter"]: {"guess": e["guess"], "stderr_design": e["stderr_design"], "stderr_even": e["stderr_even"]}
            for e in raw["errors"]
        }
        self.target: Optional[str] = raw["target"]
        self.efficiency: float = raw["efficiency"]
        self.gap: float = raw["gap"]
        self.discrimination: Optional[Tuple[float, float]] = raw["discrimination"]
        self.points_needed: Optional[Tuple[float, float]] = raw["points_needed"]
        self.ranges: List[Tuple[float, float]] = [tuple(r) for r in raw["ranges"]]  # type: ignore[misc]
        self.bayes: Optional[Tuple[int, int]] = None if raw.get("bayes") is None else tuple(raw["bayes"])  # type: ignore[assignment]
        self.steady: List[Dict[str, Tuple[Optional[float], Optional[float]]]] = [
            {k: (v[0], v[1]) for k, v in row.items()} for row in raw.get("steady", [])
        ]

    def to_pandas(self):
        """The design as a DataFrame (series, xi, delta_deg, replicates; needs pandas)."""
        return self.table.to_pandas()

    def _raw(self) -> Dict[str, Any]:
        """The dict the design is made from (as the compiled core gives it)."""

        def rows(t: Table) -> Dict[str, Any]:
            return {
                "series": [str(x) for x in t["series"]],
                "xi": [float(x) for x in t["xi"]],
                "delta_deg": [float(x) for x in t["delta_deg"]],
                "replicates": [int(x) for x in t["replicates"]],
            }

        return {
            "design": rows(self.table),
            "even": rows(self.even),
            "errors": [{"parameter": k, **v} for k, v in self.errors.items()],
            "target": self.target,
            "efficiency": self.efficiency,
            "gap": self.gap,
            "discrimination": self.discrimination,
            "points_needed": self.points_needed,
            "ranges": list(self.ranges),
            "bayes": self.bayes,
            "steady": [{k: [lo, hi] for k, (lo, hi) in row.items()} for row in self.steady],
        }

    def __eq__(self, other: Any) -> bool:
        """Every attribute equal, floats bit for bit (NaN equal to NaN)."""
        if not isinstance(other, Design):
            return NotImplemented
        return _same(vars(self), vars(other))

    __hash__ = None  # type: ignore[assignment]

    def save(self, path: Any) -> None:
        """Writes the design to a JSON file that :func:`load` reads back as an equal Design
        (the format: :func:`load`); written atomically.

        Parameters
        ----------
        path : str or path-like
            The file to write (replaced if it exists).
        """
        _save(path, "design", lambda: _persist.encode(self._raw(), "design"))

    def to_csv(self, path: str) -> None:
        """Writes the design as ``fitbead design --output`` does (for ``simulate --design``)."""
        lines = ["series,xi,delta_deg,replicates"]
        t = self.table
        for i in range(len(t["xi"])):
            lines.append(f"{t['series'][i]},{float(t['xi'][i])!r},{float(t['delta_deg'][i])!r},{int(t['replicates'][i])}")
        with open(path, "w", encoding="utf-8") as fh:
            fh.write("\n".join(lines) + "\n")

    def __repr__(self) -> str:
        errs = ", ".join(f"{k}: {v['stderr_design']:.3g} (even {v['stderr_even']:.3g})" for k, v in self.errors.items())
        return f"Design({len(self.table['xi'])} slopes, {int(self.table['replicates'].sum())} points; {errs}; efficiency of even {self.efficiency:.3g})"


def design(
    fit: str = "klaw",
    *,
    model: Optional[str] = None,
    law: str = "c=0.5",
    series: Sequence[float] = (0.8, 1.0, 1.6, 2.0),
    points: int = 9,
    noise: Union[float, str] = 0.02,
    delta_range: Optional[Tuple[float, float]] = None,
    criterion: str = "d",
    target: Optional[str] = None,
    vs: Optional[str] = None,
    branch: str = "upper",
    rho: float = 0.4,
    f: float = 0.1,
    prior: Optional[Mapping[str, str]] = None,
    draws: int = 64,
    seed: int = 1,
    total: Optional[int] = None,
    sigma_delta: float = 0.0,
    margin: float = 0.05,
) -> Design:
    """Where to measure (``fitbead design``): locally optimal slopes for a fit's parameters,
    or slopes that tell two models apart, from the Fisher information at a guess.

    Parameters
    ----------
    fit : {"klaw", "jan", "jaeger"}
        The fit the data are for.
    model : str, optional
        The model the data follow (a contact model for ``klaw``; default stickslip).
    law : str, default "c=0.5"
        For ``klaw``, the fitted law with its guess: ``c=VALUE``, or a number (one K per
        series).
    series : sequence of float
        The radius ratios ξ of the series.
    points : int
        Points per series.
    noise : float or str
        Relative noise σ = noise · v̄ (as ``simulate --noise``), or ``"abs=S"`` for an
        absolute σ of v̄.
    delta_range : (float, float), optional
        Slopes in degrees (cut to regime B of the guess); default regime B; either way kept
        ``margin`` of its width (and 2 ``sigma_delta``) from each end.
    criterion : {"d", "c", "t"}
        D-optimal, c-optimal for ``target``, or T-optimal against ``vs``.
    target : str, optional
        The parameter of the c criterion; for ``klaw`` also the bulk friction μ of eq 79 at
        the fitted K (``"mu"`` for one series, ``"mu of series 'xi=X'"`` for several), its
        standard error by the delta method.
    vs : str, optional
        The rival of the T criterion: a contact model for ``klaw``; ``"jan"`` for
        ``jaeger`` (``jan`` against ``jaeger`` is refused: Jan's model is Jaeger's with
        a2 = 0, so no design tells them apart when Jan's holds).
    branch : {"upper", "lower"}
        Jaeger's root of eq 84.
    rho, f : float
        Gyration parameter and friction coefficient.
    prior : mapping of str to str, optional
        Priors by parameter name (``{"c": "normal(0.5,0.1)"}``; uniform, normal, lognormal or
        halfnormal, as ``--prior``) for a Bayesian design: the criterion averaged over
        ``draws`` draws; the other parameters stay at the guess.
    draws : int
        Prior draws of a Bayesian design.
    seed : int
        Seed of the prior draws.
    total : int, optional
        Points over all series, shared out by the design (replaces ``points``).
    sigma_delta : float, default 0
        Standard uncertainty of a set slope, degrees (``--sigma-delta``): each point's
        variance becomes σ_v² + (∂v̄/∂δ)² σ_δ² (the effective variance the fits with slope
        errors minimise), and the ranges keep 2 σ_δ from their ends. 0: exact slopes.
    margin : float, default 0.05
        The fraction of each range's width kept from either end (``--margin``;
        0 <= margin < 0.5).

    Returns
    -------
    Design

    Raises
    ------
    FitbeadError
        A setting the design cannot work with (e.g. a series without a regime-B range),
        named as the command line names it.
    """
    absolute = False
    if isinstance(noise, str):
        text = noise.strip()
        if not text.startswith("abs="):
            raise FitbeadError(f"noise = {noise!r}: expected a number or abs=VALUE")
        noise, absolute = float(text[4:]), True
    raw = _core.design(
        fit,
        model=model,
        law=law,
        series=[float(x) for x in series],
        points=int(points),
        noise=float(noise),
        noise_absolute=absolute,
        delta_range=None if delta_range is None else (float(delta_range[0]), float(delta_range[1])),
        criterion=criterion,
        target=target,
        vs=vs,
        branch=branch,
        rho=float(rho),
        f=float(f),
        priors=[(str(k), str(v)) for k, v in (prior or {}).items()],
        draws=int(draws),
        seed=int(seed),
        total=None if total is None else int(total),
        sigma_delta=float(sigma_delta),
        margin=float(margin),
    )
    return Design(raw)


def _csv_table(text: str) -> Table:
    """A CSV text of the command line as a :class:`Table`: one column per header name, in
    its order; a column whose every cell is a number or empty is float64 (NaN for empty),
    a count (``n_points``, ``rank``, ...) with every cell given int64, any other, and the
    text columns (``series``: labels, even those that read as numbers), an object array of
    ``str``."""
    import csv
    import io

    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], rows[1:]
    t = Table()
    for j, name in enumerate(header):
        cells = [r[j] if j < len(r) else "" for r in body]
        col: Optional[np.ndarray] = None
        if name not in _TEXT_COLUMNS:
            try:
                col = np.array([float(c) if c != "" else np.nan for c in cells], dtype=np.float64)
            except ValueError:
                col = None
        # A count with every cell given is int64.
        if col is not None and name in _COUNT_COLUMNS and not np.isnan(col).any() and (col == np.round(col)).all():
            col = col.astype(np.int64)
        t[name] = col if col is not None else np.array(cells, dtype=object)
    t.shape = (len(body),)
    return t


def simulate(
    model: str = "stickslip",
    *,
    law: str = "adjusted",
    series: Sequence[float] = (0.8, 1.0, 1.6, 2.0),
    points: int = 9,
    noise: float = 0.02,
    seed: int = 1,
    rho: float = 0.4,
    f: float = 0.1,
    jan: Optional[Sequence[float]] = None,
    jaeger: Optional[Sequence[float]] = None,
    branch: str = "upper",
    delta_range: Optional[Tuple[float, float]] = None,
    design: Optional[Any] = None,
    v0: Optional[float] = None,
    delta_deg: Optional[float] = None,
    beads: Optional[int] = None,
    spin: str = "roll",
    md_preset: str = "ristow",
    sigma_delta: float = 0.0,
) -> Table:
    """Synthetic measurements inside regime B, reproducible from a seed (``fitbead simulate``).

    The keyword arguments are the command line's flags (``--delta-range`` is
    ``delta_range``); the rows are those it writes for the same settings, to the last bit.

    Parameters
    ----------
    model : str, default "stickslip"
        The forward model that makes the data: ``stick``, ``stick-approx``, ``slip``,
        ``slip-approx``, ``stickslip``, ``contact`` (with ``v0``: the bead-by-bead transient
        instead), ``jan``, ``jaeger`` or ``md`` (molecular dynamics: slow, minutes per
        series).
    law : str, default "adjusted"
        Collision law: a number, ``cos2a``, ``adjusted``, ``impact`` or ``c=VALUE``.
    series : sequence of float
        Radius ratios ξ of the series, each once.
    points : int, default 9
        Points per series, spread over 5 %–95 % of the steady range.
    noise : float, default 0.02
        Relative noise: v = v_true (1 + noise · N(0,1)), σ = noise · v_true.
    seed : int, default 1
        Seed of the random stream (ChaCha8).
    rho, f : float
        Gyration parameter ρ and friction coefficient f.
    jan : sequence of 4 float, optional
        Jan's global laws λ0, λ1, μ0, μ1 for ``jan`` (default: the paper's eqs 75–76).
    jaeger : sequence of 3 float, optional
        Jaeger's a1, a2, a3 for ``jaeger``, every series (default: the paper's Fig. 9 values
        of each ξ, for ξ = 0.8, 1, 1.6, 2).
    branch : {"upper", "lower"}
        Jaeger's root of eq 84.
    delta_range : (float, float), optional
        Slopes LO, HI in degrees, cut to the steady range.
    design : Design, str or path-like, optional
        A :class:`Design` (what :func:`design` returns) or a design file
        (``series,xi,delta_deg,replicates``, as :meth:`Design.to_csv` writes it): the data
        are made at its slopes.
    v0, delta_deg, beads : optional
        ``contact`` only: the launch speed, slope (degrees) and row beads (default 50) of the
        bead-by-bead transient.
    spin : str, default "roll"
        The contact model's spin rule: ``roll``, ``keep``, ``impact`` or ``factor=L``.
    md_preset : {"ristow", "steel"}
        The md model's parameter set.
    sigma_delta : float, default 0
        Standard uncertainty of the slope, degrees (``--sigma-delta``): the recorded slope
        ``delta_deg`` is drawn around the true one, ``delta_true_deg``, at which the velocity
        is made. 0: the slopes are exact.

    Returns
    -------
    Table
        The command line's CSV columns in its order: ``series``, ``xi``, ``delta_deg``,
        ``v``, ``sigma_v`` (NaN with no noise), ``v_true``; md adds ``v_md_stderr`` and
        ``v_m_s``; ``sigma_delta`` above 0 adds ``sigma_delta_deg`` and
        ``delta_true_deg``; the transient has the columns of ``simulate --v0``. ``to_pandas()`` gives
        a DataFrame.

    Raises
    ------
    FitbeadError
        A setting that cannot be used, named by its command-line flag.

    Examples
    --------
    >>> import fitbead
    >>> sim = fitbead.simulate("stick", series=[1.0], points=3, seed=2)
    >>> list(sim)
    ['series', 'xi', 'delta_deg', 'v', 'sigma_v', 'v_true']
    """
    scratch = None
    if isinstance(design, Design):
        import os
        import tempfile

        scratch = tempfile.TemporaryDirectory(prefix="fitbead-design-")
        path = os.path.join(scratch.name, "design.csv")
        design.to_csv(path)
        design = path
    try:
        text = _core.simulate(
            model=_model_name(model),
            law=law,
            series=[float(x) for x in series],
            points=int(points),
            noise=float(noise),
            seed=int(seed),
            rho=float(rho),
            f=float(f),
            jan=None if jan is None else [float(x) for x in jan],
            jaeger=None if jaeger is None else [float(x) for x in jaeger],
            branch=branch,
            delta_range=None if delta_range is None else (float(delta_range[0]), float(delta_range[1])),
            design=None if design is None else str(design),
            v0=None if v0 is None else float(v0),
            delta_deg=None if delta_deg is None else float(delta_deg),
            beads=None if beads is None else int(beads),
            spin=spin,
            md_preset=md_preset,
            sigma_delta=float(sigma_delta),
        )
    finally:
        if scratch is not None:
            scratch.cleanup()
    return _csv_table(text)


class Report(dict):
    """The tables of a report (:func:`report`), by the name of their CSV file without
    ``.csv`` (``params``, ``stats``, ``bulk_friction``, ...), each a :class:`Table` whose
    columns are that file's header.

    Attributes
    ----------
    markdown : str
        The text of report.md.
    files : dict of str to bytes
        Every file of the report directory (tables, figures, report.md), by name.
    summary : str
        The summary the command line prints.
    """

    markdown: str = ""
    files: Dict[str, bytes] = {}
    summary: str = ""

    def __repr__(self) -> str:
        return f"Report(tables=[{', '.join(self)}])"

    def __eq__(self, other: Any) -> bool:
        """The same tables (:meth:`Table.__eq__`), files, markdown and summary."""
        if not isinstance(other, Report):
            return NotImplemented
        return _same(self, other) if type(self) is type(other) else False

    def __ne__(self, other: Any) -> bool:
        eq = self.__eq__(other)
        return eq if eq is NotImplemented else not eq

    __hash__ = None  # type: ignore[assignment]


def report(
    data: Any = None,
    out_dir: Optional[Any] = None,
    method: str = "lsq",
    *,
    format: str = "svg",
    units: str = "dimensionless",
    figure_width: Optional[Union[str, float]] = None,
    level: float = 0.95,
    seed: Optional[int] = None,
    min_ess: Optional[float] = None,
    max_steps: Optional[int] = None,
    keep_going: bool = False,
    g: float = 9.81,
) -> Report:
    """Every model fitted to one data set and the paper's comparisons (``fitbead report``).

    The tables are computed as the command line computes them; with ``out_dir`` the report
    directory is written as the command line writes it (one unit: every file or none).

    Parameters
    ----------
    data : Dataset, str, path-like, DataFrame or Table, optional
        The measurements (default: the shipped synthetic data set).
    out_dir : str or path-like, optional
        Directory for the tables, figures and report.md (created if missing); ``None`` writes
        nothing.
    method : {"lsq", "mcmc"}
        Least squares, or posteriors for every fit (slow: minutes).
    format : str, default "svg"
        Figure files: ``svg``, ``png``, ``pdf``, ``both`` or ``all``.
    units : {"dimensionless", "si"}
        Velocities on the figures (``si`` needs data given as ``v_m_s`` with ``R_m``).
    figure_width : str or float, optional
        Print width of the figures: ``single``, ``double`` or a width in mm.
    level : float, default 0.95
        The level of every interval.
    seed, min_ess, max_steps : optional
        MCMC settings (``method="mcmc"`` only).
    keep_going : bool, default False
        Report data that fail a fit command's input check, leaving out what fails (else an
        error).
    g : float, default 9.81
        Gravity (m/s²) of SI rows without a ``g`` column (for ``units="si"``).

    Returns
    -------
    Report
        A dict of :class:`Table` by CSV file name without ``.csv``: ``bulk_friction``,
        ``energy``, ``regime_map``, ``points``, ``models``, ``models_by_series``,
        ``params``, ``stats``, ``residuals``, ``correlations``; the columns are each file's
        header. ``Report.files`` holds every file's bytes, ``Report.markdown`` report.md.

    Raises
    ------
    FitbeadError
        Data or settings the command line refuses, with its message.
    Interrupted
        Ctrl-C during a posterior run: the report of the draws so far (written to
        ``out_dir`` too) is the exception's ``result``.

    Warns
    -----
    UnitWarning
        A fit whose misfit is implausible for the σ given (the command line's warning).
    MisfitWarning
        A fit whose χ² tail probability is below 0.001 with σ given.
    ConvergenceWarning
        A posterior run that did not converge, or was interrupted.
    """
    d = _dataset(data)
    files, unit_warnings, misfit_warnings, convergence_warnings, interrupted, summary, signal = _core.report(
        d._core,
        out_dir=None if out_dir is None else str(out_dir),
        method=method,
        format=format,
        units=units,
        figure_width=None if figure_width is None else str(figure_width),
        level=float(level),
        seed=None if seed is None else int(seed),
        min_ess=None if min_ess is None else float(min_ess),
        max_steps=None if max_steps is None else int(max_steps),
        keep_going=bool(keep_going),
        g=float(g),
    )
    for w in unit_warnings:
        _warn(w, UnitWarning)
    for w in misfit_warnings:
        _warn(w, MisfitWarning)
    for w in convergence_warnings:
        _warn(w, ConvergenceWarning)
    if interrupted:
        _warn("a posterior run was interrupted: its tables hold the draws so far", ConvergenceWarning)
    out = Report()
    out.files = {name: bytes(b) for name, b in files}
    for name, b in out.files.items():
        if name.endswith(".csv"):
            out[name[: -len(".csv")]] = _csv_table(b.decode("utf-8"))
    out.markdown = out.files.get("report.md", b"").decode("utf-8")
    out.summary = summary
    _stopped(signal, out)
    return out


def work_precision(scenes: int = 2000, seed: int = 1) -> Table:
    """The work-precision table (``fitbead bench --output``): error against time of every
    model and method variant, and of ``auto``, over scenes drawn across regime B.

    Parameters
    ----------
    scenes : int, default 2000
        Scenes drawn (about 30 % of them a hard subset).
    seed : int, default 1
        Seed of the scene draw.

    Returns
    -------
    Table
        The columns of ``fitbead bench --output``, one row per variant. The errors depend on
        the scenes only; the times are measured on this machine.
    """
    return _csv_table(_core.work_precision(scenes=int(scenes), seed=int(seed)))


def load(path: Any) -> Union[FitResult, FitSet, Dataset, Table, Design]:
    """Reads a result that ``save`` wrote: a :class:`FitResult`, :class:`FitSet`,
    :class:`Dataset`, :class:`Table` or :class:`Design` equal to the one saved.

    The file is one JSON document (UTF-8) that the ``json`` module reads without fitbead::

        {"format": "fitbead-result", "version": 1, "kind": KIND,
         "fitbead_version": "...", KIND: {...}}

    with ``KIND`` one of ``fit``, ``fitset``, ``dataset``, ``table``, ``design``:

    - ``fit``: ``name``, ``series``, ``context`` (what :meth:`FitResult.eval` needs: the
      model or branch), ``params`` (one object per parameter, keyed by params.csv's columns),
      ``param_bounds`` (``[low, high]`` per parameter), ``stats`` (stats.csv's columns),
      ``residuals`` (residuals.csv's), ``correlations`` (correlations.csv's),
      ``correlation`` (the matrix, or null), ``points`` (the fitted points by column),
      ``draws`` (null, or ``chains`` ``[walker][kept step][parameter]``, ``log_posterior``
      ``[walker][kept step]``, their ``shape``, ``burn_in``, ``thin``, ``interrupted``),
      ``report`` (the fit report's text), ``absurd_misfit``, ``misfit_warning``,
      ``chi2_p_value``;
    - ``fitset``: ``fits`` (a list of ``fit`` objects) and ``notes``;
    - ``dataset``: ``origin`` ``"text"`` with ``source``, ``text`` (the CSV) and the defaults
      ``rho``, ``f``, ``g``, ``sigma_delta``; or ``origin`` ``"arrays"`` with ``series``
      and the arrays of :meth:`Dataset.from_arrays`;
    - ``table``: ``shape``, ``columns`` (by name: ``dtype``, ``shape``, ``values`` as nested
      lists) and ``critical_xi`` where the table has one;
    - ``design``: the attributes of :class:`Design`, its tables as ``design`` and ``even``
      (lists by column).

    Numbers are JSON numbers that read back the same doubles; one that is not finite is the
    string ``"NaN"``, ``"Infinity"`` or ``"-Infinity"``; a report record's empty cell is
    ``null``. A newer version than this fitbead reads is refused. For ArviZ's netCDF, use
    ``fit.to_arviz().to_netcdf(path)``.

    Parameters
    ----------
    path : str or path-like
        The file ``save`` wrote.

    Returns
    -------
    FitResult, FitSet, Dataset, Table or Design
        The type that was saved; nothing is warned again (a loaded data set's warnings are in
        its ``warnings``).

    Raises
    ------
    FitbeadError
        The file cannot be read, is not a fitbead result, has a version this fitbead does not
        read, or is damaged: the message names the file and what is wrong.
    """
    try:
        kind, body = _persist.read(path)
        if kind == "fit":
            ctx = _persist.decode_context(_persist._get(body, "context", "fit"), "fit.context")
            return FitResult(_persist.StoredFit(_persist.decode_fit(body, "fit")), ctx)
        if kind == "fitset":
            fits = []
            for i, x in enumerate(_persist._list(_persist._get(body, "fits", "fitset"), "fitset.fits")):
                where = f"fitset.fits[{i}]"
                ctx = _persist.decode_context(_persist._get(x, "context", where), f"{where}.context")
                fits.append(FitResult(_persist.StoredFit(_persist.decode_fit(x, where)), ctx))
            notes = [_persist._text(n, "fitset.notes") for n in _persist._list(_persist._get(body, "notes", "fitset"), "fitset.notes")]
            return FitSet(fits, notes)
        if kind == "table":
            return _persist.decode_table(body, "table", Table)
        if kind == "design":
            return Design(_persist.decode_design(body, "design"))
        state = _persist.decode_dataset(body, "dataset")
        try:
            core = _dataset_core(state)
        except FitbeadError as e:
            raise _persist._Bad(f"dataset: {e}") from None
        d = Dataset.__new__(Dataset)
        d._core = core
        return d
    except _persist._Bad as e:
        raise FitbeadError(f"{os.fspath(path)}: {e}") from None
