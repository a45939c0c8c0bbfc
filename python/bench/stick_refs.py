#!/usr/bin/env python3
"""mpmath references for the stick model's v̄ just above the stop limit δ_m, and the errors of
the numpy/scipy peer (stick_numpy.py) and of `fitbead forward --model stick` against them.

    stick_refs.py make                 writes stick_refs_near_dm.csv (about a minute)
    stick_refs.py compare [FITBEAD]    prints the error table below (FITBEAD: the binary,
                                       default /work/tasks/fitbead-65f4f2f)

Needs mpmath (and numpy, scipy for `compare`); run from anywhere (it imports
tests/reference/make_refs.py of this repository).

Scenes: ξ = 0.8, 1, 2; K = the adjusted law cos 2α + ½ sin²α sin 2α at the exact α, rounded to a
double (given to both codes as that number); ρ = 0.4; f = 0.1 (unused by rolling);
δ_deg = double(degrees(δ_m (1 + ε))), ε = 1e-2 … 1e-12, δ_m = 2 atan(tan(α/2)(1−K)/(1+K)) (eq 32)
at 60 digits. Each reference is for exactly that double δ_deg, i.e. δ = δ_deg·π/180 exactly, and
α = asin(1/(1+ξ)) at working precision from the double ξ (not rounded).

Method. Primary (column v_ref): tests/reference/make_refs.py's `stick` — tanh-sinh quadrature of
the defining integral τ = ∫ dθ / sqrt(Θ̇_top² + 2B sin²(θ/2)) over [Θ0, Θf], split at the peak
θ = 0 with geometric break points at its width — at mp.dps = 50, v̄ = 2 sin α / τ. Check (v_check):
the corrected closed form (eqs 12–15) with mpmath.ellipf at mp.dps = 80,
τ = γ [F(Ω_f|m) + F(Ω_0|m)], tan Ω = sqrt((A+B)/(A−B)) |tan(Θ/2)|, A − B = Θ̇_top² taken directly.
Further columns: v_ref_dbl_rad, the reference at δ = double(δ_deg · double(π/180)), the slope
radians() in numpy and to_radians() in Rust both compute (so a code's error against it is its
own); sens_delta_ulp and sens_alpha_ulp, |v̄(x (1 + 2⁻⁵²)) / v̄ − 1| for x = δ and x = α (the
problem's conditioning: an f64 code given δ or α to a rounding cannot do much better).

tests/reference/forward_refs.csv has stick rows at δ_m (1 + 1e-6), δ_m (1 + 1e-9) and δ_m (1 − 1e-9)
(ξ = 0.8, 1, 10, the same K law; δ given in radians), made by the same quadrature: they cover two of
the ε here, in radians; this table extends them to ε = 1e-2 … 1e-12 with δ in degrees, the input
of the CLI and of the Python binding.

Errors (|v̄ − v_ref| / v_ref; `stick_refs.py compare`, fitbead 65f4f2f, scipy 1.17.1, numpy
2.4.6). Every row is regime B for all three; v_check agrees with v_ref to < 1e-40 on every row.
peer = stick_numpy.stick, fitbead = forward --model stick; "vs dbl rad" is the error against the
reference at the double slope both codes compute from δ_deg; sens = sens_delta_ulp.

| ξ | ε | peer | fitbead | peer vs dbl rad | fitbead vs dbl rad | sens |
|---|---|---|---|---|---|---|
| 0.8 | 0.01 | 5.1e-16 | 5.1e-16 | 1.2e-15 | 1.2e-15 | 3.7e-15 |
| 0.8 | 0.001 | 3.5e-14 | 1.5e-14 | 2.9e-14 | 9.3e-15 | 2.7e-14 |
| 0.8 | 0.0001 | 4.5e-14 | 5.3e-15 | 4.0e-14 | 1.6e-16 | 2.1e-13 |
| 0.8 | 1e-05 | 1.2e-12 | 8.6e-14 | 1.3e-12 | 6.2e-18 | 1.7e-12 |
| 0.8 | 1e-06 | 1.4e-11 | 4.7e-12 | 9.4e-12 | 1.1e-18 | 1.5e-11 |
| 0.8 | 1e-07 | 1.5e-10 | 4.0e-11 | 1.1e-10 | 2.6e-16 | 1.3e-10 |
| 0.8 | 1e-08 | 7.5e-10 | 3.2e-10 | 4.3e-10 | 5.5e-18 | 1.1e-9 |
| 0.8 | 1e-09 | 3.9e-9 | 1.3e-9 | 5.3e-9 | 1.5e-16 | 1.0e-8 |
| 0.8 | 1e-10 | 5.1e-8 | 2.1e-9 | 4.9e-8 | 5.1e-18 | 9.1e-8 |
| 0.8 | 1e-11 | 1.2e-6 | 1.5e-7 | 1.4e-6 | 2.1e-16 | 8.3e-7 |
| 0.8 | 1e-12 | 6.6e-6 | 4.7e-7 | 6.2e-6 | 1.3e-17 | 7.6e-6 |
| 1.0 | 0.01 | 5.2e-15 | 2.2e-15 | 3.6e-15 | 6.3e-16 | 3.7e-15 |
| 1.0 | 0.001 | 2.1e-14 | 1.6e-14 | 1.8e-14 | 1.4e-14 | 2.7e-14 |
| 1.0 | 0.0001 | 7.3e-14 | 6.6e-15 | 6.6e-14 | 1.8e-16 | 2.1e-13 |
| 1.0 | 1e-05 | 3.4e-13 | 2.1e-13 | 5.4e-13 | 2.1e-16 | 1.7e-12 |
| 1.0 | 1e-06 | 6.8e-12 | 2.1e-12 | 9.0e-12 | 1.3e-16 | 1.5e-11 |
| 1.0 | 1e-07 | 3.2e-11 | 1.9e-11 | 1.3e-11 | 5.3e-18 | 1.3e-10 |
| 1.0 | 1e-08 | 7.8e-10 | 3.8e-10 | 4.0e-10 | 1.7e-16 | 1.1e-9 |
| 1.0 | 1e-09 | 6.9e-9 | 5.2e-10 | 6.4e-9 | 1.9e-16 | 1.0e-8 |
| 1.0 | 1e-10 | 6.2e-8 | 1.5e-8 | 4.7e-8 | 2.0e-16 | 9.1e-8 |
| 1.0 | 1e-11 | 5.4e-7 | 2.9e-7 | 8.3e-7 | 5.4e-18 | 8.3e-7 |
| 1.0 | 1e-12 | 8.3e-6 | 3.4e-7 | 8.6e-6 | 1.1e-17 | 7.6e-6 |
| 2.0 | 0.01 | 2.1e-15 | 2.5e-15 | 1.0e-15 | 1.5e-15 | 3.7e-15 |
| 2.0 | 0.001 | 4.3e-14 | 8.4e-15 | 5.2e-14 | 3.4e-18 | 2.7e-14 |
| 2.0 | 0.0001 | 1.1e-14 | 2.9e-14 | 1.8e-14 | 1.2e-16 | 2.1e-13 |
| 2.0 | 1e-05 | 8.6e-13 | 3.6e-14 | 8.3e-13 | 1.9e-18 | 1.7e-12 |
| 2.0 | 1e-06 | 1.0e-12 | 7.5e-12 | 8.5e-12 | 1.8e-16 | 1.5e-11 |
| 2.0 | 1e-07 | 3.0e-10 | 2.7e-11 | 2.7e-10 | 9.6e-18 | 1.3e-10 |
| 2.0 | 1e-08 | 9.6e-10 | 4.0e-10 | 5.6e-10 | 2.3e-16 | 1.1e-9 |
| 2.0 | 1e-09 | 8.5e-9 | 2.1e-9 | 6.5e-9 | 6.4e-19 | 1.0e-8 |
| 2.0 | 1e-10 | 2.7e-8 | 4.4e-8 | 7.1e-8 | 1.5e-16 | 9.1e-8 |
| 2.0 | 1e-11 | 2.1e-7 | 1.0e-7 | 1.1e-7 | 1.4e-16 | 8.3e-7 |
| 2.0 | 1e-12 | 4.9e-7 | 8.0e-7 | 3.1e-7 | 2.3e-17 | 7.6e-6 |

Reading: against the reference at the double slope it is given, fitbead is exact to 1.5e-14 at
every ε (2.6e-16 or better for ε <= 1e-4, where it takes the squared top speed in double-double);
its error against the degree input (columns 3 and 4) is the rounding of radians(δ_deg) times the
conditioning, below sens on every row. The peer's error grows like the conditioning, to 8.6e-6 at
ε = 1e-12. Redoing the peer's formula in mpmath with one quantity rounded to a double, at
ε = 1e-12: α = arcsin(1/(1+ξ)) rounded gives 1.0e-6 … 4.0e-6, the parameter m of ellipkinc rounded
3.8e-7 … 8.4e-7, and the squared top speed Θ̇0² − 2B sin²(Θ0/2) formed in double (at the same
double α) 1.6e-6 … 5.8e-6 (ε = 1e-10: 1.2e-8 … 4.7e-8, 1.2e-9 … 8.9e-9 and 4.4e-9 … 5.5e-8).
"""
import csv
import math
import os
import subprocess
import sys

import mpmath
from mpmath import mp, mpf

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "reference"))
import make_refs  # noqa: E402

CSV = os.path.join(HERE, "stick_refs_near_dm.csv")
XIS = (0.8, 1.0, 2.0)
EPS = tuple(10.0 ** -e for e in range(2, 13))
RHO = 0.4
F = 0.1
ULP = mpf(2) ** -52
COLS = ["xi", "delta_deg", "K", "rho", "f", "v_ref", "eps", "delta_m_deg", "v_ref_dbl_rad",
        "v_check", "check_rel_diff", "sens_delta_ulp", "sens_alpha_ulp"]


def s17(x):
    return mpmath.nstr(mpf(x), 17, min_fixed=-30, max_fixed=30)


def v_quad(xi, delta, K, alpha_scale=0.0):
    """v̄ by make_refs' tanh-sinh quadrature at 50 digits; delta in radians (mpf or float)."""
    with mp.workdps(50):
        sc = make_refs.Scene(xi, mpf(delta), K, RHO, F, alpha_scale)
        r = make_refs.stick(sc, "ts")
        assert r["regime"] == "B", r
        return +r["v"]


def v_ellipf(xi, delta, K):
    """v̄ by the corrected closed form with mpmath.ellipf at 80 digits."""
    with mp.workdps(80):
        a = mpmath.asin(1 / (1 + mpf(xi)))
        d, K, B = mpf(delta), mpf(K), 2 / (1 + mpf(RHO))
        t0, tf = d - a, d + a
        l2 = 2 * B * mpmath.sin(d) * mpmath.sin(a) / (1 - K * K)
        amb = K * K * l2 - 2 * B * mpmath.sin(t0 / 2) ** 2
        assert t0 < 0 and amb > 0
        apb = amb + 2 * B
        m = 2 * B / apb
        om = lambda t: mpmath.atan(mpmath.sqrt(apb / amb) * abs(mpmath.tan(t / 2)))
        tau = 2 / mpmath.sqrt(apb) * (mpmath.ellipf(om(tf), m) + mpmath.ellipf(om(t0), m))
        return +(2 * mpmath.sin(a) / tau)


def make():
    rows = []
    for xi in XIS:
        K = make_refs.K_law_double("Kfit", xi)
        with mp.workdps(60):
            a = make_refs.alpha_of(xi)
            dm = make_refs.delta_m_eq32(a, mpf(K))
            dm_deg = mpmath.degrees(dm)
        for eps in EPS:
            with mp.workdps(60):
                dg = float(mpmath.degrees(dm * (1 + mpf(eps))))
                d_exact = mpf(dg) * mpmath.pi / 180
            d_dbl = dg * (math.pi / 180)
            v = v_quad(xi, d_exact, K)
            with mp.workdps(50):
                v_dbl = v_quad(xi, d_dbl, K)
                v_chk = v_ellipf(xi, d_exact, K)
                sd = abs(v_quad(xi, d_exact * (1 + ULP), K) / v - 1)
                sa = abs(v_quad(xi, d_exact, K, alpha_scale=ULP) / v - 1)
                rd = abs(v_chk / v - 1)
            rows.append([repr(xi), repr(dg), repr(K), repr(RHO), repr(F), s17(v), repr(eps),
                         s17(dm_deg), s17(v_dbl), s17(v_chk), mpmath.nstr(rd, 3),
                         mpmath.nstr(sd, 3), mpmath.nstr(sa, 3)])
            print("xi=%s eps=%s v=%s check %s sens_delta %s" % (xi, eps, rows[-1][5], rows[-1][10],
                                                               rows[-1][11]), file=sys.stderr)
    with open(CSV, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(COLS)
        w.writerows(rows)


def compare(exe):
    import numpy as np
    import stick_numpy

    with open(CSV, newline="") as fh:
        refs = list(csv.DictReader(fh))
    col = lambda c: np.array([float(r[c]) for r in refs])
    xi, dg, K, rho, f = (col(c) for c in ("xi", "delta_deg", "K", "rho", "f"))
    peer = stick_numpy.stick(xi, dg, K, rho, f)
    tmp_in = os.path.join(HERE, "out", "near_dm_scenes.csv")
    tmp_out = os.path.join(HERE, "out", "near_dm_fitbead.csv")
    os.makedirs(os.path.dirname(tmp_in), exist_ok=True)
    with open(tmp_in, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["xi", "delta_deg", "K", "rho", "f"])
        for r in refs:
            w.writerow([r[c] for c in ("xi", "delta_deg", "K", "rho", "f")])
    subprocess.run([exe, "forward", "--model", "stick", "--input", tmp_in, "--output", tmp_out],
                   check=True)
    with open(tmp_out, newline="") as fh:
        fb = list(csv.DictReader(fh))
    head = ("| ξ | ε | peer | fitbead | peer vs dbl rad | fitbead vs dbl rad | sens |\n"
            "|---|---|---|---|---|---|---|")
    print(head)
    for j, r in enumerate(refs):
        assert fb[j]["status"] == "ok" and peer["status"][j] == 0, (r, fb[j]["status"])
        with mp.workdps(30):
            ref, ref_d = mpf(r["v_ref"]), mpf(r["v_ref_dbl_rad"])
            e = lambda v, rf: mpmath.nstr(abs(mpf(v) / rf - 1), 2)
            pv, fv = float(peer["v"][j]), float(fb[j]["v"])
            print("| %s | %s | %s | %s | %s | %s | %s |" % (
                r["xi"], r["eps"], e(pv, ref), e(fv, ref), e(pv, ref_d), e(fv, ref_d),
                mpmath.nstr(mpf(r["sens_delta_ulp"]), 2)))


def main():
    cmd = sys.argv[1] if len(sys.argv) > 1 else "make"
    if cmd == "make":
        make()
    elif cmd == "compare":
        compare(sys.argv[2] if len(sys.argv) > 2 else "/work/tasks/fitbead-65f4f2f")
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
