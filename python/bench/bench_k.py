#!/usr/bin/env python3
"""Times the vectorised K inversion (eq 69: K, K_lo, K_hi, dv/dK per row) of N stick rows held
in numpy arrays: `fitbead.invert_k("stick", xi, delta_deg, v, sigma_v, rho, f)`.

Usage: bench_k.py [--n 1000000] [--runs 5] [--seed 20251125]

Rows (seeded): ξ uniform in [0.8, 3], ρ = 0.4, f = 0.1, K uniform in [0.3, 0.9], δ uniform in
(δ_m, δ_d) of that K; v = the stick model's v̄ there times (1 + 0.01 z), z standard normal, and
σ_v = 0.01 v — measured points in regime B as an experiment gives them. One warm-up run, then
--runs timed runs (time.perf_counter): best and median, the statuses, the machine and
os.getloadavg() before and after.
"""
import argparse
import os
import platform
import statistics
import time

import numpy as np

import fitbead


def rows(n, seed):
    rng = np.random.default_rng(seed)
    xi = rng.uniform(0.8, 3.0, n)
    k = rng.uniform(0.3, 0.9, n)
    alpha = np.arcsin(1.0 / (1.0 + xi))
    rho = np.full(n, 0.4)
    f = np.full(n, 0.1)
    lim_m = 2 * np.arctan(np.tan(alpha / 2) * (1 - k) / (1 + k))
    c = (1 + rho) * (1 - k * k)
    lim_d = np.arctan(c / (np.tan(alpha) * (4 + c)))
    d = np.degrees(lim_m + rng.uniform(0.05, 0.95, n) * (lim_d - lim_m))
    v = fitbead.forward("stick", xi, d, K=k, rho=rho, f=f)["v"]
    ok = ~np.isnan(v)
    xi, d, v, rho, f = xi[ok], d[ok], v[ok], rho[ok], f[ok]
    v = v * (1 + 0.01 * rng.standard_normal(v.size))
    return xi, d, v, 0.01 * v, rho, f


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--seed", type=int, default=20251125)
    a = ap.parse_args()
    print(f"machine: os.cpu_count() = {os.cpu_count()}, {platform.platform()}; fitbead {fitbead.__version__} on {fitbead.threads()} threads")
    print("load average before:", os.getloadavg())
    xi, d, v, s, rho, f = rows(a.n, a.seed)
    n = xi.size
    fitbead.invert_k("stick", xi, d, v, s, rho=rho, f=f)
    times = []
    for _ in range(a.runs):
        t = time.perf_counter()
        out = fitbead.invert_k("stick", xi, d, v, s, rho=rho, f=f)
        times.append(time.perf_counter() - t)
    st, counts = np.unique(out["status"], return_counts=True)
    print(f"rows: {n}; statuses: {dict(zip(st, counts.tolist()))}")
    print(f"invert_k stick (K, K_lo, K_hi, dv_dK): best {min(times):.3f} s, median {statistics.median(times):.3f} s ({statistics.median(times) / n * 1e6:.2f} us per row)")
    print("load average after:", os.getloadavg())


if __name__ == "__main__":
    main()
