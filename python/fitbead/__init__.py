"""fitbead: a bead rolling down a row of beads, in numpy.

Forward models, the inversion of eq 69 for the collisional parameter K, the regime limits and
the fits (K(α) laws, Jan's λ/μ, Jaeger's a1–a3, by least squares or MCMC) of Ancey, Evesque &
Coussot, "Motion of a single bead on a bead row: theoretical investigations", J. Phys. I
France 6 (1996) 725–751, computed by the fitbead Rust library: the same numbers, to the last
bit, as the ``fitbead`` command line, and tables whose columns are its CSV columns.

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
    print(fit.fit_report())                       # the command line's fit report
    fit.params["c"].value, fit.covar              # lmfit habits
    fit.eval(delta_deg=[10, 12], xi=1.0)          # the fitted model at new slopes
    post = fitbead.fit_klaw(data, model="stickslip", law="c", method="mcmc", seed=1)
    post.to_arviz()                               # posterior + log_likelihood for az.loo

Every array function broadcasts its array arguments (numpy rules), releases the GIL and runs
in parallel over rows on rayon's threads (``RAYON_NUM_THREADS`` before the first call sets
their number; :func:`threads` says it; a process forked after a call builds a pool of its
own). Results pickle, and ``save``/:func:`load` keep them in a JSON file. Warnings the
command line prints are Python warnings (:class:`FitbeadWarning` and its subclasses); errors
are :class:`FitbeadError`, a ``ValueError``.
"""

from ._api import (
    K_MODELS,
    MODELS,
    BoundWarning,
    ColumnWarning,
    ConvergenceWarning,
    Dataset,
    Design,
    FitbeadError,
    FitbeadWarning,
    FitResult,
    FitSet,
    Interrupted,
    MisfitWarning,
    OutlierWarning,
    Param,
    Report,
    Table,
    UnitWarning,
    __version__,
    design,
    fit_jaeger,
    fit_jan,
    fit_klaw,
    forward,
    invert_k,
    load,
    regimes,
    report,
    simulate,
    threads,
    work_precision,
)

__all__ = [
    "K_MODELS",
    "MODELS",
    "BoundWarning",
    "ColumnWarning",
    "ConvergenceWarning",
    "Dataset",
    "Design",
    "FitbeadError",
    "FitbeadWarning",
    "FitResult",
    "FitSet",
    "Interrupted",
    "MisfitWarning",
    "OutlierWarning",
    "Param",
    "Report",
    "Table",
    "UnitWarning",
    "__version__",
    "design",
    "fit_jaeger",
    "fit_jan",
    "fit_klaw",
    "forward",
    "invert_k",
    "load",
    "regimes",
    "report",
    "simulate",
    "threads",
    "work_precision",
]
