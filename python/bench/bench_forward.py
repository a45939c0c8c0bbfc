#!/usr/bin/env python3
"""Times the vectorised stick forward model over N scenes held in numpy arrays: (a) the
numpy/scipy peer (stick_numpy.stick, scipy.special.ellipkinc) and (b) the Python binding
`fitbead.forward("stick", xi, delta_deg, K=K, rho=rho, f=f)`, side by side in one run.

Usage: bench_forward.py [--n 1000000] [--runs 5] [--seed 20251125]

Scenes (seeded, regime-B heavy): ξ uniform in [0.8, 3]; K = the adjusted law
cos 2α + ½ sin²α sin 2α; ρ = 0.4 on half the rows, uniform in [0.2, 0.7] on the others; f = 0.1;
δ from each scene's limits δ_m (eq 32) and δ_d (eq 31): 90 % uniform in (δ_m, δ_d), 5 % in
(0.5 δ_m, δ_m) (regime A), 5 % in (δ_d, min(1.5 δ_d, 89°)) (regime C).

Each candidate runs once as a warm-up, then --runs times; the best and the median of those
(time.perf_counter) are printed, with their ratio, the largest |Δv̄|/v̄ between the two on the
rows both call steady, the rows on which they disagree about being steady, and the machine
(os.cpu_count(), platform) with os.getloadavg() before and after. Without an importable
`fitbead` module, (b) is skipped with a message.
"""
import argparse
import os
import platform
import statistics
import sys
import time

import numpy as np
import scipy

import stick_numpy


def scenes(n, seed):
    rng = np.random.default_rng(seed)
    xi = rng.uniform(0.8, 3.0, n)
    alpha = np.arcsin(1.0 / (1.0 + xi))
    k = np.cos(2 * alpha) + 0.5 * np.sin(alpha) ** 2 * np.sin(2 * alpha)
    rho = np.where(rng.random(n) < 0.5, 0.4, rng.uniform(0.2, 0.7, n))
    f = np.full(n, 0.1)
    dm = 2 * np.arctan(np.tan(alpha / 2) * (1 - k) / (1 + k))
    c = (1 + rho) * (1 - k * k)
    dd = np.arctan(c / (np.tan(alpha) * (4 + c)))
    u = rng.random(n)
    cls = rng.random(n)
    d = np.where(cls < 0.9, dm + u * (dd - dm),
        np.where(cls < 0.95, dm * (0.5 + 0.5 * u),
                 dd + u * (np.minimum(1.5 * dd, np.radians(89.0)) - dd)))
    return xi, np.degrees(d), k, rho, f


def timed(fn, runs):
    fn()
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return min(ts), statistics.median(ts), out


def field(res, name):
    """A named output of fitbead.forward, whether it returns a mapping or an object."""
    try:
        return np.asarray(res[name])
    except (TypeError, KeyError, IndexError):
        return np.asarray(getattr(res, name))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--seed", type=int, default=20251125)
    a = ap.parse_args()

    print(f"machine: os.cpu_count() = {os.cpu_count()}, {platform.platform()}, "
          f"{platform.processor() or platform.machine()}; python {platform.python_version()}, "
          f"numpy {np.__version__}, scipy {scipy.__version__}")
    print(f"load average before: {os.getloadavg()}")
    xi, dg, k, rho, f = scenes(a.n, a.seed)
    print(f"scenes: {a.n} (seed {a.seed}); best and median of {a.runs} runs after one warm-up")

    best_p, med_p, peer = timed(lambda: stick_numpy.stick(xi, dg, k, rho, f), a.runs)
    ok_p = peer["status"] == stick_numpy.OK
    print(f"(a) numpy/scipy peer: best {best_p:.4f} s, median {med_p:.4f} s "
          f"({1e9 * best_p / a.n:.1f} ns per scene); steady rows {ok_p.sum()}")

    try:
        import fitbead
    except ImportError as e:
        print(f"(b) fitbead.forward: skipped, `import fitbead` failed ({e})")
        print(f"load average after: {os.getloadavg()}")
        return
    best_f, med_f, res = timed(
        lambda: fitbead.forward("stick", xi, dg, K=k, rho=rho, f=f), a.runs)
    v_f = field(res, "v").astype(np.float64)
    try:
        st = field(res, "status")
        ok_f = (st == "ok") if st.dtype.kind in "OUS" else np.isfinite(v_f)
    except (AttributeError, KeyError):
        ok_f = np.isfinite(v_f)
    print(f"(b) fitbead.forward: best {best_f:.4f} s, median {med_f:.4f} s "
          f"({1e9 * best_f / a.n:.1f} ns per scene); steady rows {ok_f.sum()}")
    print(f"ratio peer / fitbead: best {best_p / best_f:.2f}, median {med_p / med_f:.2f}")
    both = ok_p & ok_f
    rel = np.abs(peer["v"][both] - v_f[both]) / v_f[both]
    print(f"regime B rows (both steady): {both.sum()}; max |dv|/v {rel.max():.3e}, "
          f"median {np.median(rel):.3e}; rows steady in only one: {(ok_p != ok_f).sum()}")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    sys.exit(main())
