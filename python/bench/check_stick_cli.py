#!/usr/bin/env python3
"""Compares the numpy/scipy peer (stick_numpy.stick) with `fitbead forward --model stick` on
random scenes: status per row, and the relative difference of v̄ and of the final velocity on
the rows both call steady (regime B).

Usage: check_stick_cli.py [FITBEAD] [N] [SEED]
  FITBEAD  the fitbead binary (default /work/tasks/fitbead-65f4f2f)
  N        number of scenes (default 10000), SEED (default 20251125)

Scenes: ξ uniform in [0.5, 3]; K the adjusted law cos 2α + ½ sin²α sin 2α (rounded to a double)
on half the rows, uniform in (0, 1) on the other half; ρ = 0.4 on half the rows, uniform in
[0.2, 0.7] on the other half; f = 0.1. δ from the limits δ_m (eq 32), δ_d (eq 31) of each
scene: 20 % in (0.3 δ_m, δ_m) (regime A), 50 % in (δ_m, δ_d) (B), 20 % in (δ_d, min(2 δ_d, 89°))
(C), 10 % at δ_m (1 + 10^u), u uniform in [−12, −3] (B, crawling over the top). Where δ_d < δ_m
(no regime B at that ξ, K) the draws fall in A or C. Every number is written with repr(), so
the CLI and the peer read the same doubles. Writes the scenes, fitbead's output and the peer's
output to python/bench/out/ (not committed).

Measured (fitbead 65f4f2f, scipy 1.17.1, numpy 2.4.6; seeds 20251125 and 7): status agrees on
10,000 of 10,000 rows each (5,606 and 5,641 steady). v̄ on regime B: median difference 2.7e-16;
1.3e-13 at most where δ > δ_m (1 + 1e-3) (the largest at K < 0.01 with Θ0 > 0, where mpmath
quadrature puts the peer 1.3e-13 off and fitbead 3.3e-16); 1.4e-5 and 2.0e-5 at most within
1e-3 of δ_m (see stick_refs.py for which of the two is right there). K = 1 is not drawn: the CLI
refuses it (exit 2), the peer marks it invalid.
"""
import csv
import os
import subprocess
import sys

import numpy as np

import stick_numpy

HERE = os.path.dirname(os.path.abspath(__file__))


def scenes(n, seed):
    rng = np.random.default_rng(seed)
    xi = rng.uniform(0.5, 3.0, n)
    alpha = np.arcsin(1.0 / (1.0 + xi))
    k_adj = np.cos(2 * alpha) + 0.5 * np.sin(alpha) ** 2 * np.sin(2 * alpha)
    k = np.where(rng.random(n) < 0.5, k_adj, rng.uniform(0.0, 1.0, n))
    k = np.where(k > 0.0, k, 0.5)
    rho = np.where(rng.random(n) < 0.5, 0.4, rng.uniform(0.2, 0.7, n))
    f = np.full(n, 0.1)
    dm = 2 * np.arctan(np.tan(alpha / 2) * (1 - k) / (1 + k))
    c = (1 + rho) * (1 - k * k)
    dd = np.arctan(c / (np.tan(alpha) * (4 + c)))
    top = np.radians(89.0)
    u = rng.random(n)
    cls = rng.random(n)
    d = np.where(cls < 0.2, dm * (0.3 + 0.7 * u),
        np.where(cls < 0.7, dm + u * (dd - dm),
        np.where(cls < 0.9, dd + u * (np.minimum(2 * dd, top) - dd),
                 dm * (1 + 10.0 ** (-12 + 9 * u)))))
    d = np.clip(d, 1e-6, top)
    return xi, np.degrees(d), k, rho, f


def write_scenes(path, cols):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["xi", "delta_deg", "K", "rho", "f"])
        for row in zip(*cols):
            w.writerow([repr(float(x)) for x in row])


def read_back(path):
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    return [np.array([float(r[c]) for r in rows]) for c in ("xi", "delta_deg", "K", "rho", "f")]


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else "/work/tasks/fitbead-65f4f2f"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 10000
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 20251125
    out = os.path.join(HERE, "out")
    os.makedirs(out, exist_ok=True)
    sc_path = os.path.join(out, "scenes.csv")
    fb_path = os.path.join(out, "fitbead_stick.csv")
    write_scenes(sc_path, scenes(n, seed))
    subprocess.run([exe, "forward", "--model", "stick", "--input", sc_path, "--output", fb_path],
                   check=True)
    xi, dg, k, rho, f = read_back(sc_path)
    peer = stick_numpy.stick(xi, dg, k, rho, f)
    p_status = stick_numpy.status_names(peer["status"])
    with open(fb_path, newline="") as fh:
        fb = list(csv.DictReader(fh))
    fb_status = np.array([r["status"] for r in fb], dtype=object)
    fb_v = np.array([float(r["v"]) if r["v"] else np.nan for r in fb])
    fb_fv = np.array([float(r["final_velocity"]) if r["final_velocity"] else np.nan for r in fb])

    agree = p_status == fb_status
    print(f"scenes: {n} (seed {seed})")
    for s in stick_numpy.STATUS:
        print(f"  fitbead {s:16s} {np.sum(fb_status == s):6d}   peer {np.sum(p_status == s):6d}")
    print(f"rows agreeing in status: {agree.sum()} of {n}")
    for j in np.flatnonzero(~agree)[:20]:
        print(f"  differs: xi={float(xi[j])!r} delta_deg={float(dg[j])!r} K={float(k[j])!r} rho={float(rho[j])!r}: "
              f"fitbead {fb_status[j]}, peer {p_status[j]}")
    both = (fb_status == "ok") & (p_status == "ok")
    rel = np.abs(peer["v"][both] - fb_v[both]) / fb_v[both]
    relf = np.abs(peer["final_velocity"][both] - fb_fv[both]) / fb_fv[both]
    j = np.flatnonzero(both)[np.argmax(rel)]
    print(f"regime B rows (both ok): {both.sum()}")
    print(f"  v: max rel diff {rel.max():.3e} (xi={float(xi[j])!r} delta_deg={float(dg[j])!r} K={float(k[j])!r} "
          f"rho={float(rho[j])!r}), median {np.median(rel):.3e}, 99th pct {np.quantile(rel, 0.99):.3e}")
    near = both & (np.abs(np.radians(dg) / (2 * np.arctan(np.tan(np.arcsin(1 / (1 + xi)) / 2)
                                                        * (1 - k) / (1 + k))) - 1) < 1e-3)
    far = both & ~near
    for name, sel in (("delta > delta_m (1 + 1e-3)", far), ("delta < delta_m (1 + 1e-3)", near)):
        r = np.abs(peer["v"][sel] - fb_v[sel]) / fb_v[sel]
        if r.size:
            print(f"  v, {name}: {sel.sum()} rows, max rel diff {r.max():.3e}")
    print(f"  final velocity: max rel diff {relf.max():.3e}")
    pp = os.path.join(out, "peer_stick.csv")
    with open(pp, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["v", "status", "final_velocity"])
        for a, s, b in zip(peer["v"], p_status, peer["final_velocity"]):
            w.writerow(["" if np.isnan(a) else repr(float(a)), s,
                        "" if np.isnan(b) else repr(float(b))])


if __name__ == "__main__":
    main()
