# Type stubs of the package's implementation, made by `stubgen -p fitbead --include-docstrings`
# (mypy) from the installed package; python/tests/test_habits.py checks them against it.
import numpy as np
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

__version__: str
ArrayLike = float | Sequence[float] | np.ndarray
MODELS: tuple[str, ...]
K_MODELS: tuple[str, ...]

class FitbeadError(ValueError):
    """Raised on bad input or a computation that cannot be done: the command line's message,
    naming the file, line, column and value where it has them."""

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
    """A few points lie far from the fitted curve; the warning names each (series, slope,
    velocity, normalised residual)."""
class ConvergenceWarning(FitbeadWarning):
    """A fit stopped without converging (least squares: its termination; MCMC: R̂ or ESS
    short of the target, or the run cut short)."""
class BoundWarning(FitbeadWarning):
    """A fitted parameter sits on a bound of its box (its interval is one-sided)."""
class ColumnWarning(FitbeadWarning):
    """A column of the data that fitbead does not read looks misspelt or misnamed (close to a
    known name, or named like an uncertainty); ``strict_columns=True`` refuses it."""

class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped a posterior run of fit_klaw, fit_jan, fit_jaeger or report: a
    ``KeyboardInterrupt`` whose ``result`` is the partial result (the draws so far, each fit
    marked ``interrupted``); a signal handler's own exception passes unchanged."""
    result: Any
    def __init__(self, message: str, result: Any = None) -> None: ...

def threads() -> int:
    """Number of threads the vectorised functions use (rayon's pool)."""

class Table(dict):
    """The columns of a vectorised result: a dict of numpy arrays of one shape.

    Numeric columns are float64 with NaN where the command line leaves a cell empty; text
    columns (``status``, ``regime``, ``message``, ...) are object arrays of ``str``. The column
    names are the command line's CSV columns.
    """
    shape: tuple[int, ...]
    def to_pandas(self):
        """The columns as a pandas DataFrame (flattened; needs pandas)."""
    def __eq__(self, other: object) -> bool: ...
    def __ne__(self, other: object) -> bool: ...
    __hash__: None  # type: ignore[assignment]
    def save(self, path: Any) -> None:
        """Writes the table to a JSON file that :func:`load` reads back."""

def forward(model: str, xi: ArrayLike, delta_deg: ArrayLike, K: str | ArrayLike = 'adjusted', rho: ArrayLike = 0.4, f: ArrayLike = 0.1, *, mu: ArrayLike | None = None, a1: ArrayLike | None = None, a2: ArrayLike | None = None, a3: ArrayLike | None = None, c: float | None = None, branch: str = 'upper', spin: str = 'roll', tol: float = 1e-14, **params: Any) -> Table:
    '''The steady state of every scene under one model (``fitbead forward``).

    Parameters
    ----------
    model : str
        ``stick`` (pure rolling), ``stick-approx``, ``slip``, ``slip-approx``, ``stickslip``,
        ``contact`` (the general contact model), ``jan`` (eq 74), ``jaeger`` (eqs 80–84) or
        ``auto`` (the simplest model meeting ``tol``).
    xi, delta_deg : array_like
        Radius ratio ξ = r/R (> 0) and slope δ in degrees; arrays broadcast together with
        every other array argument.
    K : str or array_like, default "adjusted"
        The collision law: numbers (K per scene) or a law name — ``adjusted`` (the paper\'s
        fitted law), ``cos2a``, ``impact`` or ``c=VALUE``.
    rho, f : array_like
        Gyration parameter ρ (0.4 a sphere) and Coulomb friction f.
    mu : array_like, optional
        Jan\'s μ (eq 74); with ``lambda`` (a keyword Python reserves: pass it as
        ``**{"lambda": x}`` or through ``**fit.values``). Default: the paper\'s eqs 75–76 at
        each scene\'s α; NaN entries take the default too.
    a1, a2, a3 : array_like, optional
        Jaeger\'s coefficients (required for ``jaeger``).
    c : float, optional
        The K(α) law\'s c (eq 69\'s law K = cos 2α + c sin²α sin 2α): the same as
        ``K=f"c={c}"``.
    branch : str, default "upper"
        Jaeger\'s root of eq 84 when there are two: ``upper`` or ``lower``.
    spin : str, default "roll"
        The contact model\'s spin rule at a collision: ``roll``, ``keep``, ``impact`` or
        ``factor=L``.
    tol : float, default 1e-14
        The contact model\'s quadrature tolerance; the target tolerance of ``auto``.
    **params
        ``lambda`` (Jan\'s λ), under the name the command line and the fit reports use.

    Returns
    -------
    Table
        The command line\'s columns, in its order: ``xi``, ``delta_deg`` (broadcast), ``v``
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
    [\'stops\', \'ok\', \'ok\', \'ok\', \'lift-off\']
    '''
def invert_k(model: str, xi: ArrayLike | Dataset, delta_deg: ArrayLike | None = None, v: ArrayLike | None = None, sigma_v: ArrayLike | None = None, rho: ArrayLike = 0.4, f: ArrayLike = 0.1, *, tol: float = 1e-10) -> Table:
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
        The command line's columns in its order: the inputs ``series`` (a Dataset's labels;
        not for arrays), ``xi``, ``delta_deg``, ``v``, ``sigma_v``, then ``model``, ``K`` (at v), ``K_lo`` (at v − σ), ``K_hi`` (at v + σ), ``dv_dK``,
        ``final_velocity``, ``theta_G_deg``, the named laws' ``K_cos2a``, ``K_adjusted``,
        ``K_impact``, ``iterations``, the bracket ``K_min``/``K_max`` and what sets its ends
        (``lower_limit``, ``upper_limit``), ``regime``, ``status`` (``ok``,
        ``below-range``, ``above-range``, ``invalid``) and ``message``; ``auto`` adds
        ``model_used`` and ``reason``.
    """
def regimes(xi: ArrayLike = (0.8, 1.0, 1.6, 2.0), law: str = 'adjusted', rho: float = 0.4) -> Table:
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

class Dataset:
    """Measured mean velocities grouped in series (the command line's measurement CSV).

    Build one with :meth:`read_csv` (same columns, units and error messages as the command
    line: ``series,xi,delta_deg,v[,sigma_v][,rho][,f]`` or dimensional ``v_m_s`` with
    ``R_m``), :meth:`from_arrays`, :meth:`from_pandas` or :meth:`default`.
    """
    def __init__(self, core: Any) -> None: ...
    @classmethod
    def read_csv(cls, path: str, *, rho: float = 0.4, f: float = 0.1, g: float = 9.81, strict_columns: bool = False) -> Dataset:
        """Reads a measurement CSV as the command line does.

        Parameters
        ----------
        path : str or path-like
            The file: columns ``series,xi,delta_deg,v[,sigma_v][,rho][,f]`` (dimensionless
            velocities) or ``v_m_s`` with ``R_m`` (SI).
        rho, f, g : float
            Values for the columns the file leaves out; ``g`` in m/s² for SI files.

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
        """
    @classmethod
    def default(cls) -> Dataset:
        """The shipped synthetic data set (36 points in 4 series; data/default.csv)."""
    @classmethod
    def from_arrays(cls, xi: ArrayLike, delta_deg: ArrayLike, v: ArrayLike | None = None, sigma_v: ArrayLike | None = None, *, series: Iterable[Any] | None = None, rho: ArrayLike = 0.4, f: ArrayLike = 0.1, sigma_delta_deg: ArrayLike = 0.0, v_m_s: ArrayLike | None = None, sigma_v_m_s: ArrayLike | None = None, R_m: ArrayLike | None = None, g: ArrayLike = 9.81) -> Dataset:
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
    @classmethod
    def from_pandas(cls, df: Any, *, rho: float = 0.4, f: float = 0.1, g: float = 9.81, strict_columns: bool = False) -> Dataset:
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
    @property
    def warnings(self) -> list[str]:
        """The plausibility warnings given when the data were read (also given as
        :class:`UnitWarning`)."""
    def __len__(self) -> int: ...
    @property
    def labels(self) -> list[str]:
        """The series labels, in order of first appearance."""
    @property
    def has_sigma(self) -> bool:
        """Whether the points carry σ (absolute weights) or not (relative weights)."""
    def columns(self) -> dict[str, np.ndarray]:
        """The points as arrays: series (labels), series_index, xi, delta_deg, v, sigma_v
        (NaN without), rho, f; velocities dimensionless.

        The data set holds δ in radians: ``delta_deg`` is converted back and may differ from
        the file's degrees in the last bit (:func:`invert_k` on a Dataset uses the radians
        themselves)."""
    def file_columns(self) -> dict[str, np.ndarray]:
        """The file's columns that the dimensionless data set converts away, as float64 (NaN
        where a row leaves the cell empty): ``v_m_s``, ``sigma_v_m_s``, ``R_m`` and ``g``,
        those the file has (none for data without SI velocities)."""
    def to_pandas(self):
        """The points as a DataFrame (needs pandas): the columns of :meth:`columns` but
        ``series_index``, the file's ``R_m`` and ``g`` (and ``v_m_s``, ``sigma_v_m_s``) kept."""
    def __getstate__(self) -> dict[str, Any]: ...
    def __setstate__(self, state: dict[str, Any]) -> None: ...
    def __eq__(self, other: object) -> bool: ...
    __hash__: None  # type: ignore[assignment]
    def save(self, path: Any) -> None:
        """Writes the data set (its CSV text and defaults, or its arrays) to a JSON file that
        :func:`load` reads back."""

@dataclass(frozen=True)
class Param:
    """One fitted parameter: a row of the command line's params.csv.

    Numbers the report leaves empty are NaN (never None), so that arrays and DataFrames built
    from parameters stay numeric.
    """
    name: str
    series: str
    value: float
    stderr: float
    low: float
    high: float
    method: str
    level: float
    unit: str
    at_bound: bool
    bounds: tuple[float, float]
    paper_value: float
    paper_source: str
    lsq_value: float
    note: str
    rhat: float = ...
    ess_bulk: float = ...
    ess_tail: float = ...
    cov_low: float = ...
    cov_high: float = ...
    profile_low: float = ...
    profile_high: float = ...
    profile_low_status: str = ...
    profile_high_status: str = ...
    mean: float = ...
    sd: float = ...
    q2_5: float = ...
    q50: float = ...
    q97_5: float = ...
    tau: float = ...
    prior_sensitivity: float = ...
    likelihood_sensitivity: float = ...
    prior_diagnosis: str = ...
    record: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...
    vary: bool = ...
    init_value: float = ...
    @property
    def min(self) -> float:
        """Lower end of the parameter's box (lmfit's ``min``)."""
    @property
    def max(self) -> float:
        """Upper end of the parameter's box (lmfit's ``max``)."""

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
    params: dict[str, Param]
    stats: dict[str, Any]
    correlation: np.ndarray | None
    residuals: dict[str, np.ndarray]
    draws: np.ndarray | None
    log_posterior: np.ndarray | None
    burn_in: int
    interrupted: bool
    def __init__(self, core: Any, context: dict[str, Any] | None = None) -> None: ...
    def __getstate__(self) -> dict[str, Any]: ...
    def __setstate__(self, state: dict[str, Any]) -> None: ...
    def __eq__(self, other: object) -> bool: ...
    __hash__: None  # type: ignore[assignment]
    def save(self, path: Any) -> None:
        """Writes the fit (draws included) to a JSON file that :func:`load` reads back."""
    @property
    def param_names(self) -> list[str]:
        """The parameters' keys in the fit's order (the order of :attr:`covar`)."""
    @property
    def values(self) -> dict[str, float]:
        """``{name: value}`` of the parameters that set the curve (not the scatter's scale),
        with the names :func:`forward` takes: ``fitbead.forward(model, xi, d, **fit.values)``
        evaluates a Jan, Jaeger or K-law ``c`` fit."""
    @property
    def covar(self) -> np.ndarray | None:
        """Covariance matrix of the parameters that vary (order of :attr:`var_names`, as
        lmfit's; every parameter unless some are held by ``fix``): from the least-squares
        covariance, or of the posterior draws (MCMC); None where a standard error is missing
        (an undetermined fit)."""
    @property
    def residual(self) -> np.ndarray:
        """The normalised residuals (v − v̄_fit)/σ of the fitted points (lmfit's
        ``residual``; divided by the relative weight where no σ is given)."""
    @property
    def delta_fit(self) -> np.ndarray | None:
        """The adjusted slopes δ_fit in degrees, one per fitted point, when the fit took the
        slopes as measured with error (``sigma_delta_deg``: orthogonal distance regression, or
        a posterior integrated over the slopes); None when it took them as exact."""
    @property
    def correlations(self) -> dict[tuple[str, str], float]:
        """Correlation of each pair of parameters ``{(a, b): r}`` with a before b."""
    @property
    def chi2(self) -> float: ...
    @property
    def reduced_chi2(self) -> float: ...
    @property
    def aic(self) -> float: ...
    @property
    def bic(self) -> float: ...
    @property
    def converged(self) -> bool: ...
    @property
    def chisqr(self) -> float:
        """χ² at the estimate (lmfit's name for :attr:`chi2`)."""
    @property
    def redchi(self) -> float:
        """χ²/dof (lmfit's name for :attr:`reduced_chi2`)."""
    @property
    def nfev(self) -> int:
        """Residual evaluations, profiles included (lmfit's ``nfev``)."""
    @property
    def success(self) -> bool:
        """Whether the fit converged (lmfit's ``success``)."""
    @property
    def ndata(self) -> int:
        """Number of data points (lmfit's ``ndata``)."""
    @property
    def nvarys(self) -> int:
        """Number of parameters that vary (lmfit's ``nvarys``)."""
    @property
    def nfree(self) -> int:
        """Degrees of freedom, ndata − free parameters (lmfit's ``nfree``)."""
    @property
    def var_names(self) -> list[str]:
        """Keys of the parameters that vary, in the fit's order (lmfit's ``var_names``; the
        order of :attr:`covar`)."""
    @property
    def best_fit(self) -> np.ndarray:
        """The fitted v̄ at the data points (lmfit's ``best_fit``)."""
    @property
    def best_values(self) -> dict[str, float]:
        """``{key: value}`` of every parameter (lmfit's ``best_values``)."""
    @property
    def init_values(self) -> dict[str, float]:
        """``{key: start}`` of the parameters whose start the fit gives (lmfit's
        ``init_values``: the fit's own start, or ``init``)."""
    @property
    def scale_covar(self) -> bool:
        """Whether the covariance was scaled by the reduced χ² (``scale_covar=True``, or data
        without sigma_v, whose scale is always estimated)."""
    def __getitem__(self, name: str) -> Param: ...
    def eval(self, delta_deg: ArrayLike, xi: ArrayLike | None = None, *, series: str | None = None, units: str = 'dimensionless') -> np.ndarray:
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
    def eval_band(self, delta_deg: ArrayLike, xi: ArrayLike | None = None, *, level: float = 0.95, series: str | None = None, draws: int = 400, units: str = 'dimensionless') -> Table:
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
    def eval_uncertainty(self, sigma: float = 1, delta_deg: ArrayLike | None = None, xi: ArrayLike | None = None, *, series: str | None = None) -> np.ndarray:
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
    def conf_interval(self, sigmas: Sequence[float] = (1, 2, 3)) -> dict[str, list[tuple[float, float]]]:
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
    def report(self) -> str:
        """The fit report (the command line's text)."""
    def fit_report(self, min_correl: float = 0.1) -> str:
        """The fit report (lmfit's name for :meth:`report`), its correlations those above
        ``min_correl`` in magnitude (the command line's report shows those above 0.1)."""
    def to_pandas(self, what: str = 'params'):
        '''A DataFrame (needs pandas) with the command line\'s columns and numeric dtypes
        (NaN for an empty cell).

        Parameters
        ----------
        what : {"params", "stats", "residuals", "correlations", "draws"}
            ``params`` (params.csv: one row per parameter), ``stats`` (stats.csv: one row),
            ``residuals`` (residuals.csv: one row per point), ``correlations``
            (correlations.csv: one row per pair), ``draws`` (one row per kept draw, with
            walker and step).
        '''
    def log_likelihood(self) -> np.ndarray:
        """The pointwise log likelihood ``[walker, kept step, point]`` of the posterior draws
        (MCMC): ln N(v_i | v̄_i(θ), (s σ_i)²), with σ_i the point's σ (1 without) and s the
        scatter's scale where it is sampled (``sigma_scale``), constants included."""
    def to_arviz(self):
        """The posterior as an ``arviz.InferenceData`` (needs ArviZ): ``posterior`` (one
        chain per walker), ``log_likelihood`` (``v``, per point: :meth:`log_likelihood`, so
        ``az.loo``, ``az.waic`` and ``az.compare`` work), ``sample_stats`` (``lp``: the log
        posterior), ``observed_data`` (``v``) and ``constant_data`` (``xi``, ``delta_deg``,
        ``sigma_v``)."""
    def plot(self, ax: Any = None, *, level: float = 0.95, units: str = 'dimensionless'):
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

class FitSet(list):
    """The fits of one run (Jan's per-series fits and global laws; Jaeger's per series), with
    the run's notes. A list of :class:`FitResult`."""
    notes: list[str]
    def __init__(self, fits: Iterable[FitResult], notes: Iterable[str]) -> None: ...
    def __eq__(self, other: object) -> bool: ...
    def __ne__(self, other: object) -> bool: ...
    __hash__: None  # type: ignore[assignment]
    def save(self, path: Any) -> None:
        """Writes the fits and the notes to a JSON file that :func:`load` reads back."""
    def get(self, name: str, series: Any = None, default: Any = None) -> FitResult | None:
        """The fit named ``name`` (``jan-series``, ``jan-global``, ``jaeger``) for ``series``
        (a series label; ``all`` for a global fit), or the first fit of that name when
        ``series`` is None."""
    def __getitem__(self, key: Any) -> Any:
        """A fit by position, by name, or by ``(name, series)``; KeyError when none matches."""
    def __contains__(self, key: Any) -> bool: ...
    def keys(self) -> list[tuple[str, str]]:
        """``(name, series)`` of every fit, in order."""
    def to_arviz(self, joined: bool = False) -> dict[str, Any]:
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
    def plot(self, **kwargs: Any) -> list[Any]:
        """Every fit's plot, one figure each."""
    def to_pandas(self, what: str = 'params'):
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

def fit_klaw(data: Any = None, *, model: str = 'stickslip', law: str = 'c', method: str = 'lsq', level: float = 0.95, profile: bool = True, seed: int = 1, walkers: int | None = None, max_steps: int | None = None, min_ess: float | None = None, tol: float = 1e-10, skip_unsteady: bool = False, thin: int | None = None, priors: Any = None, fit_scatter: bool = False, draws: Any = None, rho: float | None = None, f: float | None = None, g: float | None = None, sigma_delta: float | None = None, strict_columns: bool = False, fix: Mapping[str, float] | None = None, init: Mapping[str, float] | None = None, bounds: Mapping[str, tuple[float | None, float | None]] | None = None, scale_covar: bool = False) -> FitResult:
    '''A law K(α) fitted to every series at once (``fitbead klaw``).

    Parameters
    ----------
    data : Dataset, str, path or DataFrame, optional
        The measurements (default: the shipped data).
    model : str, default "stickslip"
        The contact model: ``stick``, ``stick-approx``, ``slip``, ``slip-approx``,
        ``stickslip`` or ``contact``.
    law : str, default "c"
        ``c`` (K = cos 2α + c sin²α sin 2α), ``free-per-series`` (one K per series) or
        ``impact`` (nothing fitted: scored).
    method : {"lsq", "mcmc"}, default "lsq"
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum: the
        result\'s value is the posterior median, ``draws`` the kept draws).
    level : float, default 0.95
        Confidence level of the intervals, in (0, 1).
    profile : bool, default True
        Least squares: profile-likelihood intervals (else the covariance\'s).
    seed : int, default 1
        MCMC: the seed (the same draws on any machine and thread count).
    walkers, max_steps : int, optional
        MCMC: the walkers (default: the library\'s choice) and the step limit.
    min_ess : float, optional
        MCMC: the bulk and tail ESS every parameter must reach (with rank-normalised split-R̂
        ≤ 1.01) before the run stops (default 1000). The run is also at least 50
        autocorrelation times long and is checked every 500 steps, so a ``min_ess`` below
        the ESS those give (on the shipped data, thousands at 1,000 steps)
        does not shorten it; ``stats["steps"]`` and ``stats["ess_min"]`` say what it did.
    fix, init, bounds : mapping, optional
        Parameters held at a value (``{"c": 0.5}``, lmfit\'s ``vary=False``), started at a
        value (``{"c": 0.6}``) or bounded (``{"c": (0.3, 0.9)}``) by name: ``NAME`` in every fit
        that has it, ``"NAME[SERIES]"`` in that series\' fit alone (the command line\'s
        ``--fix``, ``--init``, ``--bounds``).
    scale_covar : bool, default False
        Least squares: scale the covariance by the reduced χ² even with sigma_v given (lmfit\'s
        ``scale_covar=True``, ``--scale-covar``).

    Returns
    -------
    FitResult

    Raises
    ------
    FitbeadError
        Bad data or settings (the command line\'s message).
    Interrupted
        Ctrl-C stops a run cleanly and raises; a posterior run\'s draws so far are the
        exception\'s ``result`` (a ``KeyboardInterrupt`` where nothing was kept yet).

    Warns
    -----
    UnitWarning, ConvergenceWarning, BoundWarning
        The command line\'s warnings on the data and the fit.
    '''
def fit_jan(data: Any = None, *, method: str = 'lsq', level: float = 0.95, profile: bool = True, seed: int = 1, walkers: int | None = None, max_steps: int | None = None, min_ess: float | None = None, thin: int | None = None, priors: Any = None, fit_scatter: bool = False, draws: Any = None, rho: float | None = None, f: float | None = None, g: float | None = None, sigma_delta: float | None = None, strict_columns: bool = False, fix: Mapping[str, float] | None = None, init: Mapping[str, float] | None = None, bounds: Mapping[str, tuple[float | None, float | None]] | None = None, scale_covar: bool = False) -> FitSet:
    '''Jan\'s energy balance (eq 74): λ and μ per series (at least 3 points), then the global
    laws of eqs 75–76 (``fitbead jan``).

    Parameters
    ----------
    data : Dataset, str, path or DataFrame, optional
        The measurements (default: the shipped data).
    method : {"lsq", "mcmc"}, default "lsq"
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum).
    level : float, default 0.95
        Confidence level of the intervals, in (0, 1).
    profile : bool, default True
        Least squares: profile-likelihood intervals (else the covariance\'s).
    seed, walkers, max_steps, min_ess
        MCMC settings, as in :func:`fit_klaw`.

    Returns
    -------
    FitSet
        ``jan-series`` fits (λ, μ) per series, then ``jan-global`` (λ0, λ1, μ0, μ1 of
        λ = λ0 e^{λ1 sin α}, μ = μ0 e^{μ1 sin α}).

    Warns
    -----
    UnitWarning, ConvergenceWarning, BoundWarning
        The command line\'s warnings on the data and the fits.
    '''
def fit_jaeger(data: Any = None, *, branch: str = 'upper', method: str = 'lsq', level: float = 0.95, profile: bool = True, seed: int = 1, walkers: int | None = None, max_steps: int | None = None, min_ess: float | None = None, thin: int | None = None, priors: Any = None, fit_scatter: bool = False, draws: Any = None, rho: float | None = None, f: float | None = None, g: float | None = None, sigma_delta: float | None = None, strict_columns: bool = False, fix: Mapping[str, float] | None = None, init: Mapping[str, float] | None = None, bounds: Mapping[str, tuple[float | None, float | None]] | None = None, scale_covar: bool = False) -> FitSet:
    '''Jaeger\'s heuristic law (eqs 80–84): a1, a2, a3 per series with at least 4 points
    (``fitbead jaeger``).

    Parameters
    ----------
    data : Dataset, str, path or DataFrame, optional
        The measurements (default: the shipped data).
    branch : {"upper", "lower"}, default "upper"
        The root of eq 84 when there are two.
    method : {"lsq", "mcmc"}, default "lsq"
        ``lsq`` (least squares; intervals from profile likelihood when ``profile``, else
        the covariance) or ``mcmc`` (a posterior run from the least-squares optimum).
    level : float, default 0.95
        Confidence level of the intervals, in (0, 1).
    profile : bool, default True
        Least squares: profile-likelihood intervals (else the covariance\'s).
    seed, walkers, max_steps, min_ess
        MCMC settings, as in :func:`fit_klaw`.

    Returns
    -------
    FitSet
        One ``jaeger`` fit per series.

    Warns
    -----
    UnitWarning, ConvergenceWarning, BoundWarning
        The command line\'s warnings on the data and the fits.
    '''

class Design:
    '''An experimental design (:func:`design`): where to measure and what it buys.

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
        The c-criterion\'s parameter.
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
    '''
    table: Table
    even: Table
    errors: dict[str, dict[str, float]]
    target: str | None
    efficiency: float
    gap: float
    discrimination: tuple[float, float] | None
    points_needed: tuple[float, float] | None
    ranges: list[tuple[float, float]]
    bayes: tuple[int, int] | None
    steady: list[dict[str, tuple[float | None, float | None]]]
    def __init__(self, raw: Mapping[str, Any]) -> None: ...
    def to_pandas(self):
        """The design as a DataFrame (series, xi, delta_deg, replicates; needs pandas)."""
    def to_csv(self, path: str) -> None:
        """Writes the design as ``fitbead design --output`` does (for ``simulate --design``)."""
    def __eq__(self, other: object) -> bool: ...
    __hash__: None  # type: ignore[assignment]
    def save(self, path: Any) -> None:
        """Writes the design to a JSON file that :func:`load` reads back."""

def design(fit: str = 'klaw', *, model: str | None = None, law: str = 'c=0.5', series: Sequence[float] = (0.8, 1.0, 1.6, 2.0), points: int = 9, noise: float | str = 0.02, delta_range: tuple[float, float] | None = None, criterion: str = 'd', target: str | None = None, vs: str | None = None, branch: str = 'upper', rho: float = 0.4, f: float = 0.1, prior: Mapping[str, str] | None = None, draws: int = 64, seed: int = 1, total: int | None = None, sigma_delta: float = 0.0, margin: float = 0.05) -> Design:
    '''Where to measure (``fitbead design``): locally optimal slopes for a fit's parameters,
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
    '''

def simulate(model: str = 'stickslip', *, law: str = 'adjusted', series: Sequence[float] = (0.8, 1.0, 1.6, 2.0), points: int = 9, noise: float = 0.02, seed: int = 1, rho: float = 0.4, f: float = 0.1, jan: Sequence[float] | None = None, jaeger: Sequence[float] | None = None, branch: str = 'upper', delta_range: tuple[float, float] | None = None, design: Any | None = None, v0: float | None = None, delta_deg: float | None = None, beads: int | None = None, spin: str = 'roll', md_preset: str = 'ristow', sigma_delta: float = 0.0) -> Table:
    """Synthetic measurements inside regime B, reproducible from a seed (``fitbead simulate``);
    the keyword arguments are the command line's flags, the rows those it writes."""

class Report(dict):
    """The tables of a report (:func:`report`), by the name of their CSV file without
    ``.csv``, each a :class:`Table` whose columns are that file's header."""
    markdown: str
    files: dict[str, bytes]
    summary: str
    def __eq__(self, other: object) -> bool: ...
    def __ne__(self, other: object) -> bool: ...
    __hash__: None  # type: ignore[assignment]

def report(data: Any = None, out_dir: Any | None = None, method: str = 'lsq', *, format: str = 'svg', units: str = 'dimensionless', figure_width: str | float | None = None, level: float = 0.95, seed: int | None = None, min_ess: float | None = None, max_steps: int | None = None, keep_going: bool = False, g: float = 9.81) -> Report:
    """Every model fitted to one data set and the paper's comparisons (``fitbead report``): the
    tables, and the report directory written when ``out_dir`` is given."""

def work_precision(scenes: int = 2000, seed: int = 1) -> Table:
    """The work-precision table (``fitbead bench --output``)."""

def load(path: Any) -> FitResult | FitSet | Dataset | Table | Design:
    """Reads a result that ``save`` wrote (one JSON document: ``{"format": "fitbead-result",
    "version": 1, "kind": ..., KIND: {...}}``), as the type saved."""
