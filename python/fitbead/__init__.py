"""fitbead: a bead rolling down a row of beads, in numpy.

Forward models, the inversion of eq 69 for the collisional parameter K, the regime limits and
the fits (K(α) laws, Jan's λ/μ, Jaeger's a1–a3, by least squares or MCMC) of Ancey, Evesque &
Coussot, "Motion of a single bead on a bead row: theoretical investigations", J. Phys. I
France 6 (1996) 725–751, computed by the fitbead Rust library: the same numbers, to the last
bit, as the ``fitbead`` command line.

Units are the library's: lengths in R + r, velocities in sqrt(g (R + r)) (a measured velocity
v in m/s converts as v / sqrt(g R (1 + ξ))), slopes δ in degrees. Equation numbers are the
paper's.

Quick start::

    import numpy as np, fitbead
    out = fitbead.forward("stick", xi=1.0, delta_deg=np.linspace(5, 25, 201))
    out["v"], out["status"]                       # mean velocity v̄, "ok"/"stops"/...
    data = fitbead.Dataset.default()              # the shipped synthetic data set
    k = fitbead.invert_k("stick", data)           # K per point (eq 69), K_lo, K_hi
    fit = fitbead.fit_klaw(data, model="stickslip", law="c")
    print(fit)                                    # the fit report
    post = fitbead.fit_klaw(data, model="stickslip", law="c", method="mcmc", seed=1)
    post.to_arviz()                               # an arviz.InferenceData

Every array function broadcasts its array arguments (numpy rules), releases the GIL and runs
in parallel over rows on rayon's threads (``RAYON_NUM_THREADS`` before the first call sets
their number; :func:`threads` says it).
"""

from __future__ import annotations

import html as _html
import io as _io
from dataclasses import dataclass
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _fitbead as _core

__all__ = [
    "Dataset",
    "FitResult",
    "FitSet",
    "Param",
    "Table",
    "fit_jaeger",
    "fit_jan",
    "fit_klaw",
    "forward",
    "invert_k",
    "regimes",
    "threads",
]

__version__: str = _core.version()

ArrayLike = Union[float, Sequence[float], np.ndarray]

MODELS = ("stick", "stick-approx", "slip", "slip-approx", "stickslip", "contact", "jan", "jaeger", "auto")
"""The models :func:`forward` evaluates (the command line's names)."""

K_MODELS = ("stick", "stick-approx", "slip", "slip-approx", "stickslip", "contact", "auto")
"""The models :func:`invert_k` inverts."""


def threads() -> int:
    """Number of threads the vectorised functions use (rayon's pool)."""
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


def _as_f64(name: str, x: Any) -> np.ndarray:
    """``x`` as float64; a masked array with masked entries and complex numbers are refused
    (their mask or imaginary part would otherwise be dropped silently)."""
    if isinstance(x, np.ma.MaskedArray) and np.ma.getmaskarray(x).any():
        raise ValueError(
            f"{name}: a masked array with {int(np.ma.count_masked(x))} masked entries; "
            "fill them (e.g. .filled(np.nan)) or leave those points out"
        )
    try:
        complex_input = np.iscomplexobj(x)
    except (TypeError, ValueError):
        complex_input = False
    if complex_input:
        raise ValueError(f"{name}: complex numbers are not accepted; pass real numbers (e.g. .real)")
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: expected numbers ({e})") from None
    return a


def _model_name(model: Any) -> Any:
    """A model name in any case, as the command line takes it."""
    return model.strip().lower() if isinstance(model, str) else model


def _broadcast(named: Mapping[str, Any]) -> Tuple[Tuple[int, ...], Dict[str, Optional[np.ndarray]]]:
    """Broadcasts the non-None arrays together; returns the shape and flat contiguous arrays."""
    keys = [k for k, v in named.items() if v is not None]
    arrays = [_as_f64(k, named[k]) for k in keys]
    try:
        b = np.broadcast_arrays(*arrays)
    except ValueError as e:
        shapes = ", ".join(f"{k} {a.shape}" for k, a in zip(keys, arrays))
        raise ValueError(f"arguments do not broadcast together: {shapes}") from e
    shape = b[0].shape if b else ()
    flat: Dict[str, Optional[np.ndarray]] = {k: None for k in named}
    for k, a in zip(keys, b):
        flat[k] = np.ascontiguousarray(a, dtype=np.float64).reshape(-1)
    return shape, flat


def _table(raw: Mapping[str, Any], shape: Tuple[int, ...]) -> Table:
    t = Table()
    for k, v in raw.items():
        if isinstance(v, tuple) and len(v) == 3:
            at, values, n = v
            arr = np.full(n, "", dtype=object)
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


def forward(
    model: str,
    xi: ArrayLike,
    delta_deg: ArrayLike,
    K: Union[str, ArrayLike] = "adjusted",
    rho: ArrayLike = 0.4,
    f: ArrayLike = 0.1,
    *,
    lam: Optional[ArrayLike] = None,
    mu: Optional[ArrayLike] = None,
    a1: Optional[ArrayLike] = None,
    a2: Optional[ArrayLike] = None,
    a3: Optional[ArrayLike] = None,
    branch: str = "upper",
    spin: str = "roll",
    tol: float = 1e-14,
) -> Table:
    """The steady state of every scene under one model (``fitbead forward``).

    Parameters
    ----------
    model:
        ``stick`` (pure rolling), ``stick-approx``, ``slip``, ``slip-approx``, ``stickslip``,
        ``contact`` (the general contact model), ``jan`` (eq 74), ``jaeger`` (eqs 80–84) or
        ``auto`` (the simplest model meeting ``tol``).
    xi, delta_deg:
        Radius ratio ξ = r/R (> 0) and slope δ in degrees; arrays broadcast together with
        every other array argument.
    K:
        The collision law: numbers (K per scene) or a law name — ``adjusted`` (the paper's
        fitted law), ``cos2a``, ``impact`` or ``c=VALUE``.
    rho, f:
        Gyration parameter ρ (0.4 a sphere) and Coulomb friction f.
    lam, mu:
        Jan's λ and μ (default: the paper's eqs 75–76 at each scene's α); NaN entries take the
        default too.
    a1, a2, a3:
        Jaeger's coefficients (required for ``jaeger``).
    branch:
        Jaeger's root of eq 84 when there are two: ``upper`` or ``lower``.
    spin:
        The contact model's spin rule at a collision: ``roll``, ``keep``, ``impact`` or
        ``factor=L``.
    tol:
        The contact model's quadrature tolerance; the target tolerance of ``auto``.

    Returns
    -------
    Table
        ``v`` (mean velocity v̄, NaN without a steady state), ``regime`` (A, B, C), ``status``
        (``ok``, ``stops``, ``lift-off``, ``no-steady-state``, ``invalid``,
        ``no-fixed-point``), ``K_used``, ``final_velocity``, ``initial_velocity``,
        ``contact_time``, ``theta_G_deg`` (Θ_G, eq 36), ``map_slope``,
        ``other_fixed_point``, ``phases``, ``message``; the contact model adds its energy
        budget and phase columns, ``auto`` adds ``model_used`` and ``reason``.

    Raises
    ------
    ValueError
        A bad value, naming the argument, the row and the value.
    """
    model = _model_name(model)
    if model not in MODELS:
        if model == "md":
            raise ValueError("model md is not vectorised; use the command line's `fitbead forward --model md`")
        raise ValueError(f"model = {model!r}: expected one of {', '.join(MODELS)}")
    k_arr = None
    law = "adjusted"
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
    return _table(raw, shape)


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
    broadcast together) or a :class:`Dataset` as the second argument.

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
        ``K`` (at v), ``K_lo`` (at v − σ), ``K_hi`` (at v + σ), ``dv_dK``,
        ``final_velocity``, ``theta_G_deg``, the named laws' ``K_cos2a``, ``K_adjusted``,
        ``K_impact``, ``iterations``, the bracket ``K_min``/``K_max`` and what sets its ends
        (``lower_limit``, ``upper_limit``), ``regime``, ``status`` (``ok``,
        ``below-range``, ``above-range``, ``invalid``) and ``message``; ``auto`` adds
        ``model_used`` and ``reason``.
    """
    model = _model_name(model)
    if model not in K_MODELS:
        raise ValueError(f"model = {model!r}: expected one of {', '.join(K_MODELS)}")
    if isinstance(xi, Dataset):
        raw = xi._core.invert_k(model, tol=tol)
        return _table(raw, (len(xi),))
    if delta_deg is None or v is None:
        raise ValueError("invert_k needs xi, delta_deg and v (or a Dataset)")
    if sigma_v is None:
        sigma_v = np.nan
    shape, a = _broadcast({"xi": xi, "delta_deg": delta_deg, "v": v, "sigma_v": sigma_v, "rho": rho, "f": f})
    raw = _core.invert_k(model, a["xi"], a["delta_deg"], a["v"], a["sigma_v"], a["rho"], a["f"], tol=tol)
    return _table(raw, shape)


def regimes(xi: ArrayLike = (0.8, 1.0, 1.6, 2.0), law: str = "adjusted", rho: float = 0.4) -> Table:
    """The regime limits of a collision law (``fitbead regimes``).

    Returns ``xi``, ``alpha_deg``, ``K``, ``delta_m_deg`` (δ_m, eq 32: below it the bead
    stops), ``delta_d_deg`` (δ_d, eq 31: above it the bead lifts off), ``mu_eq79`` (the bulk
    friction of eq 79), ``steady_range`` (``yes`` where δ_m < δ_d); the table's attribute
    ``critical_xi`` is the ξ below which no steady regime exists (None if there is none).
    """
    x = np.ascontiguousarray(np.atleast_1d(_as_f64("xi", xi)), dtype=np.float64).reshape(-1)
    raw = dict(_core.regimes(x, law=law, rho=float(rho)))
    crit = raw.pop("critical_xi")
    t = _table(raw, x.shape)
    t = Table({"xi": x.copy(), **t})
    t.shape = x.shape
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

    @classmethod
    def read_csv(cls, path: str, *, rho: float = 0.4, f: float = 0.1, g: float = 9.81) -> "Dataset":
        """Reads a measurement CSV; ``rho``, ``f``, ``g`` fill the columns it leaves out.

        Raises ValueError with the command line's text: file, line, column, value, message.
        """
        return cls(_core._Dataset.from_csv(str(path), rho=rho, f=f, g=g))

    @classmethod
    def default(cls) -> "Dataset":
        """The shipped synthetic data set (36 points in 4 series; data/default.csv)."""
        return cls(_core._Dataset.default_data())

    @classmethod
    def from_arrays(
        cls,
        xi: ArrayLike,
        delta_deg: ArrayLike,
        v: ArrayLike,
        sigma_v: Optional[ArrayLike] = None,
        *,
        series: Optional[Iterable[Any]] = None,
        rho: ArrayLike = 0.4,
        f: ArrayLike = 0.1,
    ) -> "Dataset":
        """From arrays (broadcast together). ``series`` labels group the points (default:
        grouped by ξ); without ``sigma_v`` the fits weight relatively."""
        shape, a = _broadcast(
            {"xi": xi, "delta_deg": delta_deg, "v": v, "sigma_v": np.nan if sigma_v is None else sigma_v, "rho": rho, "f": f}
        )
        n = a["xi"].size  # type: ignore[union-attr]
        labels = [""] * n if series is None else [str(s) for s in np.ravel(np.asarray(list(series), dtype=object))]
        return cls(_core._Dataset.from_arrays(labels, a["xi"], a["delta_deg"], a["v"], a["sigma_v"], a["rho"], a["f"]))

    @classmethod
    def from_pandas(cls, df: Any, *, rho: float = 0.4, f: float = 0.1, g: float = 9.81) -> "Dataset":
        """From a DataFrame with the CSV's columns, checked as the command line checks a file
        (errors name the DataFrame's line as the CSV would have it: header on line 1)."""
        text = df.to_csv(index=False)
        return cls(_core._Dataset.from_text(text, "<DataFrame>", rho=rho, f=f, g=g))

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
        return c

    def to_pandas(self):
        """The points as a DataFrame (needs pandas)."""
        import pandas as pd

        c = self.columns()
        cols = ["series", "xi", "delta_deg", "v", "sigma_v", "rho", "f"]
        return pd.DataFrame({k: c[k] for k in cols})

    def __repr__(self) -> str:
        return f"Dataset({len(self)} points, series {self.labels})"


def _dataset(data: Any) -> Dataset:
    if isinstance(data, Dataset):
        return data
    if data is None:
        return Dataset.default()
    if isinstance(data, str) or hasattr(data, "__fspath__"):
        return Dataset.read_csv(str(data))
    if hasattr(data, "to_csv") and hasattr(data, "columns"):
        return Dataset.from_pandas(data)
    raise ValueError("data: expected a Dataset, a CSV path or a pandas DataFrame")


@dataclass(frozen=True)
class Param:
    """One fitted parameter."""

    name: str
    series: str
    """The series the parameter belongs to (``all`` for a parameter of every series)."""
    value: float
    """Least-squares optimum, or the posterior median."""
    stderr: Optional[float]
    """Standard error (covariance), or the posterior standard deviation."""
    low: Optional[float]
    high: Optional[float]
    """The interval at ``level``."""
    method: str
    """How the interval was obtained (profile likelihood, covariance, posterior)."""
    level: float
    unit: str
    at_bound: bool
    """The optimum sits on a bound of the parameter (see the report's warning)."""
    bounds: Tuple[float, float]
    paper_value: Optional[float]
    paper_source: str
    lsq_value: Optional[float]
    note: str
    rhat: Optional[float] = None
    ess_bulk: Optional[float] = None
    ess_tail: Optional[float] = None


def _param(r: Dict[str, Any], bounds: Tuple[float, float]) -> Param:
    """A :class:`Param` from one row of the parameter report (the keys of params.csv)."""
    return Param(
        name=r["parameter"],
        series=r["series"],
        value=r["value"],
        stderr=r["stderr"],
        low=r["ci_low"],
        high=r["ci_high"],
        method=r["ci_method"],
        level=r["level"],
        unit=r["unit"],
        at_bound=r["at_bound"],
        bounds=tuple(bounds),
        paper_value=r["paper_value"],
        paper_source=r["paper_source"],
        lsq_value=r["lsq_value"],
        note=r["note"],
        rhat=r["rhat"],
        ess_bulk=r["ess_bulk"],
        ess_tail=r["ess_tail"],
    )


class FitResult:
    """One fit: parameters with errors and intervals, correlations, residuals, statistics.

    ``print(result)`` shows the fit report the command line prints; in a notebook the report
    renders as HTML. For an MCMC fit, :attr:`draws` holds the posterior draws and
    :meth:`to_arviz` makes an ``arviz.InferenceData``.
    """

    def __init__(self, core: Any) -> None:
        self._core = core
        self.name, self.series = core.name()
        rows = [_param(r, b) for r, b in zip(core.params(), core.param_bounds())]
        names = [p.name for p in rows]
        unique = len(set(names)) == len(names)
        self.params: Dict[str, Param] = {(p.name if unique else f"{p.name}[{p.series}]"): p for p in rows}
        """The parameters in the fit's order, by name; where a name repeats (one K per
        series), by ``name[series]``."""
        self.stats: Dict[str, Any] = dict(core.stats())
        """χ², reduced χ², AIC, BIC, termination, iterations, ... (and MCMC diagnostics)."""
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

    @property
    def param_names(self) -> List[str]:
        return list(self.params)

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
        return self.stats["aic"]

    @property
    def bic(self) -> float:
        return self.stats["bic"]

    @property
    def converged(self) -> bool:
        return self.stats["converged"]

    def __getitem__(self, name: str) -> Param:
        return self.params[name]

    def report(self) -> str:
        """The fit report (the command line's text)."""
        return self._core.report()

    def __str__(self) -> str:
        return self.report()

    def __repr__(self) -> str:
        ps = ", ".join(f"{p.name}={p.value:.6g}" for p in self.params.values())
        s = f" [{self.series}]" if self.series else ""
        return f"FitResult({self.name}{s}: {ps})"

    def _repr_html_(self) -> str:
        rows = []
        for p in self.params.values():
            err = "" if p.stderr is None else f"{p.stderr:.3g}"
            iv = "" if p.low is None else f"[{p.low:.6g}, {p.high:.6g}] ({p.method})"
            rows.append(
                f"<tr><td>{_html.escape(p.name)}</td><td>{p.value:.6g}</td><td>{err}</td><td>{_html.escape(iv)}</td>"
                f"<td>{'' if p.paper_value is None else f'{p.paper_value:.6g}'}</td></tr>"
            )
        table = (
            "<table><thead><tr><th>parameter</th><th>value</th><th>stderr</th><th>interval</th><th>paper</th></tr></thead>"
            f"<tbody>{''.join(rows)}</tbody></table>"
        )
        return f"<div>{table}<details><summary>fit report</summary><pre>{_html.escape(self.report())}</pre></details></div>"

    def to_pandas(self, what: str = "params"):
        """A DataFrame (needs pandas): ``params`` (one row per parameter), ``residuals`` (one
        row per point) or ``draws`` (one row per kept draw, with walker and step)."""
        import pandas as pd

        if what == "params":
            return pd.DataFrame([p.__dict__ for p in self.params.values()]).set_index("name")
        if what == "residuals":
            return pd.DataFrame(self.residuals)
        if what == "draws":
            if self.draws is None:
                raise ValueError("no draws: a least-squares fit")
            w, s, k = self.draws.shape
            df = pd.DataFrame(self.draws.reshape(w * s, k), columns=self.param_names)
            df.insert(0, "step", np.tile(np.arange(s) * max(self.thin, 1) + self.burn_in + 1, w))
            df.insert(0, "walker", np.repeat(np.arange(w), s))
            return df
        raise ValueError(f"what = {what!r}: expected params, residuals or draws")

    def to_arviz(self):
        """The posterior as an ``arviz.InferenceData`` (needs ArviZ): ``posterior`` (one
        chain per walker), ``sample_stats`` (``lp``: the log posterior) and
        ``observed_data`` (``v``, with ``v_fit`` and ``sigma_v`` as constant data)."""
        import arviz as az

        if self.draws is None:
            raise ValueError("no draws: to_arviz needs an MCMC fit (method='mcmc')")
        post = {n: self.draws[:, :, i] for i, n in enumerate(self.param_names)}
        r = self.residuals
        return az.from_dict(
            posterior=post,
            sample_stats={"lp": self.log_posterior},
            observed_data={"v": r["v"]},
            constant_data={"xi": r["xi"], "delta_deg": r["delta_deg"], "sigma_v": r["sigma_v"]},
            dims={"v": ["point"], "xi": ["point"], "delta_deg": ["point"], "sigma_v": ["point"]},
            attrs={"fit": self.name, "series": self.series, "burn_in": self.burn_in, "thin": self.thin},
        )


class FitSet(list):
    """The fits of one run (Jan's per-series fits and global laws; Jaeger's per series), with
    the run's notes. A list of :class:`FitResult`."""

    def __init__(self, fits: Iterable[FitResult], notes: Iterable[str]) -> None:
        super().__init__(fits)
        self.notes: List[str] = list(notes)

    def get(self, name: str, series: Optional[str] = None) -> Optional[FitResult]:
        """The fit named ``name`` (``jan-series``, ``jan-global``, ``jaeger``) for ``series``
        (a series label; ``all`` for a global fit), or the first fit of that name when
        ``series`` is None."""
        for fr in self:
            if fr.name == name and (series is None or fr.series == series):
                return fr
        return None

    def __str__(self) -> str:
        parts = [str(fr) for fr in self]
        if self.notes:
            parts.append("notes:\n" + "\n".join(f"  {n}" for n in self.notes))
        return "\n\n".join(parts)

    def _repr_html_(self) -> str:
        return "".join(fr._repr_html_() for fr in self)

    def to_pandas(self):
        """Every fit's parameters in one DataFrame (needs pandas)."""
        import pandas as pd

        frames = []
        for fr in self:
            df = fr.to_pandas().reset_index()
            df.insert(0, "series", fr.series)
            df.insert(0, "fit", fr.name)
            frames.append(df)
        return pd.concat(frames, ignore_index=True)


_METHOD_DOC = """
    method:
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum: the
        result's value is the posterior median, ``draws`` the kept draws).
    level:
        Confidence level of the intervals, in (0, 1).
    seed, walkers, max_steps, min_ess:
        MCMC: the seed (the same draws on any machine and thread count), the walkers
        (default: the library's choice), the step limit, and the bulk and tail ESS every
        parameter must reach (with rank-normalised split-R̂ ≤ 1.01) before the run stops
        (default 1000).

    Ctrl-C (``KeyboardInterrupt``) stops an MCMC run cleanly and raises.
"""


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
) -> FitResult:
    """A law K(α) fitted to every series at once (``fitbead klaw``).

    data:
        A :class:`Dataset`, a CSV path or a DataFrame (default: the shipped data).
    model:
        The contact model: ``stick``, ``stick-approx``, ``slip``, ``slip-approx``,
        ``stickslip`` or ``contact``.
    law:
        ``c`` (K = cos 2α + c sin²α sin 2α), ``free-per-series`` (one K per series) or
        ``impact`` (nothing fitted: scored).
    """
    d = _dataset(data)
    return FitResult(
        _core.fit_klaw(d._core, model=_model_name(model), law=law, method=method, level=level, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps, min_ess=min_ess)
    )


fit_klaw.__doc__ = (fit_klaw.__doc__ or "") + _METHOD_DOC


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
) -> FitSet:
    """Jan's energy balance (eq 74): λ and μ per series (at least 3 points), then the global
    laws of eqs 75–76 (``fitbead jan``)."""
    d = _dataset(data)
    fits, notes = _core.fit_jan(d._core, method=method, level=level, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps, min_ess=min_ess)
    return FitSet([FitResult(x) for x in fits], notes)


fit_jan.__doc__ = (fit_jan.__doc__ or "") + _METHOD_DOC


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
) -> FitSet:
    """Jaeger's heuristic law (eqs 80–84): a1, a2, a3 per series with at least 4 points, on
    the ``upper`` or ``lower`` root of eq 84 (``fitbead jaeger``)."""
    d = _dataset(data)
    fits, notes = _core.fit_jaeger(
        d._core, branch=branch, method=method, level=level, profile=profile, seed=seed, walkers=walkers, max_steps=max_steps,
        min_ess=min_ess,
    )
    return FitSet([FitResult(x) for x in fits], notes)


fit_jaeger.__doc__ = (fit_jaeger.__doc__ or "") + _METHOD_DOC
