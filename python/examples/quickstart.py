"""fitbead from Python in six steps: a forward grid, K of every measured point (eq 69), law c
fitted by least squares (the fit report) and by MCMC, the posterior in ArviZ and a corner plot.

Run from the repository's root after `pip install ./python` (ArviZ and matplotlib for the
last step: `pip install arviz`):

    python python/examples/quickstart.py
"""

import numpy as np

import fitbead

# 1. The stick model over a grid: ξ = r/R in rows, slope δ (degrees) in columns; the paper's
#    adjusted K law, a sphere (ρ = 0.4), friction f = 0.1. Arrays broadcast like numpy's.
xi = np.array([[0.8], [1.0], [2.0]])
delta = np.linspace(5.0, 25.0, 81)
grid = fitbead.forward("stick", xi, delta, K="adjusted", rho=0.4, f=0.1)
print("v̄ at ξ = 1, δ = 15°:", grid["v"][1, 40], grid["status"][1, 40])
print("regimes along ξ = 1:", "".join(r or "-" for r in grid["regime"][1, ::8]))

# 2. δ_m (the bead stops below it) and δ_d (it lifts off above it) for the same law.
lim = fitbead.regimes([0.8, 1.0, 2.0], law="adjusted")
print("δ_m:", lim["delta_m_deg"], "δ_d:", lim["delta_d_deg"])

# 3. The shipped data set (synthetic; v in units of sqrt(g (R + r))) and K per point.
data = fitbead.Dataset.default()  # or fitbead.Dataset.read_csv("my.csv")
k = fitbead.invert_k("stickslip", data)
print("K per point (first five):", k["K"][:5], "statuses:", set(k["status"]))

# 4. Law c, K = cos 2α + c sin²α sin 2α, by least squares: the fit report.
fit = fitbead.fit_klaw(data, model="stickslip", law="c")
print(fit)
c = fit["c"]
print(f"c = {c.value:.5f} ± {c.stderr:.5f}, {c.level:.0%} interval [{c.low:.5f}, {c.high:.5f}] ({c.method})")

# 5. The same law by MCMC (seed 1: the same draws on any machine and thread count).
post = fitbead.fit_klaw(data, model="stickslip", law="c", method="mcmc", seed=1)
print("posterior median c =", post["c"].value, "draws:", post.draws.shape)

# 6. ArviZ: the posterior's summary and a corner (pair) plot of Jaeger's a1–a3 for one series.
try:
    import arviz as az
    import matplotlib

    matplotlib.use("Agg")
    print(az.summary(post.to_arviz(), kind="stats"))
    jaeger = fitbead.fit_jaeger(data, method="mcmc", seed=1)
    one = jaeger.get("jaeger", "1")
    axes = az.plot_pair(one.to_arviz(), kind="kde", marginals=True, figsize=(7, 7))
    axes.ravel()[0].figure.savefig("corner_jaeger_1.png", dpi=120)
    print("wrote corner_jaeger_1.png")
except ImportError:
    print("pip install arviz for the posterior summary and the corner plot")
