#!/usr/bin/env python3
"""K, K_lo and K_hi of two `fitbead k --model stick` outputs of the same input, held against
mpmath: for the cells where the two differ, the root of v̄(K) = v (K) or v ∓ σ solved at 40 digits with
the reference stick model of tests/reference/make_refs.py (its tanh-sinh quadrature of the
contact time), and the relative error of each output.

Usage: scripts/k_ends_vs_mpmath.py OLD.csv NEW.csv [N] [COLUMNS]
  Takes the N cells that differ most (default 12) and N more spread over the rest; prints one
  line per cell and, at the end, the largest error of each output and how often each is the
  closer. COLUMNS, comma-separated, are the outputs compared (default K_lo,K_hi; K is the root
  at v itself). Needs mpmath. Run from the crate root.

The root is bisected at 40 digits in [K (1 - 1e-8), K (1 + 1e-8)] around the old value (a
cell whose root is not there is reported and skipped); v and σ are the doubles of the input,
v ∓ σ the double their difference rounds to (as the Rust code computes it), δ in radians the
double δ_deg · (π/180); a row without ρ has the command's default, 0.4 (outputs of runs without
--rho).
"""
import csv
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "reference"))
import mpmath  # noqa: E402
from mpmath import mpf  # noqa: E402

import make_refs  # noqa: E402

mpmath.mp.dps = 40


def v_bar(xi, delta_rad, rho, k):
    sc = make_refs.Scene(xi, delta_rad, k, rho=rho, f=0.1)
    return make_refs.stick(sc, "ts")["v"]


def root(xi, delta_rad, rho, v, k_near):
    f = lambda k: v_bar(xi, delta_rad, rho, k) - mpf(v)
    lo, hi = mpf(k_near) * (1 - mpf("1e-8")), mpf(k_near) * (1 + mpf("1e-8"))
    flo, fhi = f(lo), f(hi)
    if flo is None or fhi is None or flo * fhi > 0:
        return None
    for _ in range(90):
        m = (lo + hi) / 2
        fm = f(m)
        if fm * flo <= 0:
            hi = m
        else:
            lo, flo = m, fm
    return (lo + hi) / 2


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 12
    columns = sys.argv[4].split(",") if len(sys.argv) > 4 else ["K_lo", "K_hi"]
    old = list(csv.DictReader(open(sys.argv[1])))
    new = list(csv.DictReader(open(sys.argv[2])))
    if len(old) != len(new):
        sys.exit("the two outputs have different rows")
    cells = []
    for ro, rn in zip(old, new):
        if ro.get("model") != "stick":
            continue
        for c in columns:
            if ro[c] != rn[c] and ro[c] and rn[c]:
                x, y = float(ro[c]), float(rn[c])
                cells.append((abs(x - y) / max(abs(x), abs(y)), c, ro, rn))
    cells.sort(key=lambda t: -t[0])
    rest = cells[n:]
    pick = cells[:n] + rest[:: max(1, len(rest) // n)][:n]
    print(f"{len(cells)} cells differ; {len(pick)} checked")
    worst = [0.0, 0.0]
    closer = [0, 0]
    for change, c, ro, rn in pick:
        # An empty (or absent) rho is the command's default, 0.4 (a run without --rho).
        xi, dd, rho = float(ro["xi"]), float(ro["delta_deg"]), float(ro.get("rho") or 0.4)
        v, s = float(ro["v"]), float(ro["sigma_v"] or "nan")
        target = {"K": v, "K_lo": v - s, "K_hi": v + s}[c]
        ref = root(xi, dd * (math.pi / 180), rho, target, float(ro[c]))
        if ref is None:
            print(f"{c} {ro[c]}: no root within 1e-8 of it")
            continue
        errs = [float(abs(mpf(float(r[c])) - ref) / ref) for r in (ro, rn)]
        for i in (0, 1):
            worst[i] = max(worst[i], errs[i])
        if errs[0] != errs[1]:
            closer[0 if errs[0] < errs[1] else 1] += 1
        print(f"{c} K = {float(ro[c]):.4g} (row K {ro['K']}, dv_dK {ro['dv_dK']}): change "
              f"{change:.2e}, error old {errs[0]:.2e}, new {errs[1]:.2e}")
    print(f"largest error: old {worst[0]:.2e}, new {worst[1]:.2e}; "
          f"closer: old {closer[0]}, new {closer[1]}")


if __name__ == "__main__":
    main()
