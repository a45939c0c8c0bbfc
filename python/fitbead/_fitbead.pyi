"""Type stubs of the compiled core (``fitbead._fitbead``); the documented API is the package's
(``fitbead/_api.py``, re-exported by ``fitbead/__init__.py``), which broadcasts arrays and wraps these results."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
TextColumn = Tuple[npt.NDArray[np.uint32], List[str]]

class FitbeadError(ValueError): ...

def version() -> str: ...
def record_columns(kind: str) -> List[str]: ...
def output_columns(command: str, model: str, slopes: bool = False) -> List[str]: ...
def design(fit: str, **settings: Any) -> Dict[str, Any]: ...
def threads() -> int: ...
def forward(
    model: str,
    xi: F64,
    delta_deg: F64,
    rho: F64,
    f: F64,
    k: Optional[F64] = None,
    law: str = "adjusted",
    lam: Optional[F64] = None,
    mu: Optional[F64] = None,
    a1: Optional[F64] = None,
    a2: Optional[F64] = None,
    a3: Optional[F64] = None,
    branch: str = "upper",
    spin: str = "roll",
    tol: float = 1e-14,
) -> Dict[str, Any]: ...
def invert_k(
    model: str, xi: F64, delta_deg: F64, v: F64, sigma_v: F64, rho: F64, f: F64, tol: float = 1e-10
) -> Dict[str, Any]: ...
def regimes(xi: F64, law: str = "adjusted", rho: float = 0.4) -> Dict[str, Any]: ...

class _Dataset:
    @staticmethod
    def from_csv(path: str, rho: float = 0.4, f: float = 0.1, g: float = 9.81) -> "_Dataset": ...
    @staticmethod
    def from_text(text: str, source: str, rho: float = 0.4, f: float = 0.1, g: float = 9.81) -> "_Dataset": ...
    @staticmethod
    def default_data() -> "_Dataset": ...
    @staticmethod
    def from_arrays(
        series: List[str],
        xi: F64,
        delta_deg: F64,
        v: F64,
        sigma_v: F64,
        rho: F64,
        f: F64,
        sigma_delta_deg: F64,
    ) -> "_Dataset": ...
    @property
    def column_warnings(self) -> List[str]: ...
    def check_strict_columns(self) -> None: ...
    def invert_k(self, model: str, tol: float = 1e-10) -> Dict[str, Any]: ...
    def with_defaults(
        self,
        rho: Optional[float] = None,
        f: Optional[float] = None,
        g: Optional[float] = None,
        sigma_delta: Optional[float] = None,
    ) -> "_Dataset": ...
    def __len__(self) -> int: ...
    @property
    def labels(self) -> List[str]: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def has_sigma(self) -> bool: ...
    def columns(self) -> Dict[str, np.ndarray]: ...
    def file_columns(self) -> List[Tuple[str, List[str]]]: ...
    def state(self) -> Dict[str, Any]: ...

class _FitResult:
    def report(self) -> str: ...
    def name(self) -> Tuple[str, str]: ...
    def params(self) -> List[Dict[str, Any]]: ...
    def param_bounds(self) -> List[Tuple[float, float]]: ...
    def param_fixed(self) -> List[bool]: ...
    def param_starts(self) -> List[Optional[float]]: ...
    def stats(self) -> Dict[str, Any]: ...
    def correlation(self) -> Optional[List[List[float]]]: ...
    def points(self) -> Dict[str, Any]: ...
    def residual_records(self) -> List[Dict[str, Any]]: ...
    def correlation_records(self) -> List[Dict[str, Any]]: ...
    def absurd_misfit(self) -> Optional[str]: ...
    def misfit_warning(self) -> Optional[str]: ...
    def chi2_p_value(self) -> Optional[float]: ...
    def draws(self) -> Optional[Tuple[np.ndarray, np.ndarray, int, int, bool]]: ...

def fit_klaw(
    data: _Dataset,
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
    thin: Optional[int] = None,
    priors: List[Tuple[str, str]] = ...,
    fit_scatter: bool = False,
    skip_unsteady: bool = False,
    draws: bool = False,
    fix: List[Tuple[str, float]] = ...,
    init: List[Tuple[str, float]] = ...,
    bounds: List[Tuple[str, Tuple[float, float]]] = ...,
    scale_covar: bool = False,
) -> Tuple[List[_FitResult], List[str], Optional[bytes], Optional[BaseException]]: ...
def fit_jan(
    data: _Dataset,
    method: str = "lsq",
    level: float = 0.95,
    profile: bool = True,
    seed: int = 1,
    walkers: Optional[int] = None,
    max_steps: Optional[int] = None,
    min_ess: Optional[float] = None,
    thin: Optional[int] = None,
    priors: List[Tuple[str, str]] = ...,
    fit_scatter: bool = False,
    draws: bool = False,
    fix: List[Tuple[str, float]] = ...,
    init: List[Tuple[str, float]] = ...,
    bounds: List[Tuple[str, Tuple[float, float]]] = ...,
    scale_covar: bool = False,
) -> Tuple[List[_FitResult], List[str], Optional[bytes], Optional[BaseException]]: ...
def fit_jaeger(
    data: _Dataset,
    branch: str = "upper",
    method: str = "lsq",
    level: float = 0.95,
    profile: bool = True,
    seed: int = 1,
    walkers: Optional[int] = None,
    max_steps: Optional[int] = None,
    min_ess: Optional[float] = None,
    thin: Optional[int] = None,
    priors: List[Tuple[str, str]] = ...,
    fit_scatter: bool = False,
    draws: bool = False,
    fix: List[Tuple[str, float]] = ...,
    init: List[Tuple[str, float]] = ...,
    bounds: List[Tuple[str, Tuple[float, float]]] = ...,
    scale_covar: bool = False,
) -> Tuple[List[_FitResult], List[str], Optional[bytes], Optional[BaseException]]: ...
def t_quantile(p: float, dof: float) -> float: ...
def simulate(model: str = "stickslip", **settings: Any) -> str: ...
def report(
    data: _Dataset, out_dir: Optional[str] = None, method: str = "lsq", **settings: Any
) -> Tuple[List[Tuple[str, bytes]], List[str], List[str], List[str], bool, str, Optional[BaseException]]: ...
def work_precision(scenes: int = 2000, seed: int = 1) -> str: ...
