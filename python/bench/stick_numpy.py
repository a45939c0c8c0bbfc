#!/usr/bin/env python3
"""Vectorised numpy/scipy peer of `fitbead forward --model stick` (pure rolling, Ancey, Evesque
& Coussot 1996, §3; the corrected equations of docs/PHYSICS.md).

`stick(xi, delta_deg, K, rho=0.4, f=0.1)` takes arrays (or scalars, broadcast together) and
returns a dict of arrays: `v` (steady mean velocity v̄ = 2 sin α / τ, eq 10), `final_velocity`
(L, eq 19), `initial_velocity` (K L, eq 20), `contact_time` (τ, eq 11), `status` (int8 codes,
names in STATUS) and `regime` (b"A", b"B", b"C"). Rows that are not steady have NaN in the
velocity columns, as fitbead leaves them empty. f is accepted for the same signature as
fitbead's binding and is not used by pure rolling.

Per scene, in dimensionless units (length R + r, time sqrt((R + r)/g)):
  α = asin(1/(1+ξ)), Θ0 = δ − α, Θf = δ + α, B = 2/(1+ρ),
  L² = 2B sin δ sin α / (1 − K²), Θ̇0² = K² L²,
  A − B = Θ̇0² − 2B sin²(Θ0/2)      (squared speed at the top, taken directly, not as a
                                      difference of A and B),
  status: K outside (0, 1) -> invalid; Θ0 < 0 and A − B <= 0, or L² = 0 -> stops (regime A);
          cos Θf < L² -> lift-off (regime C); otherwise ok (regime B).
Contact time (corrected eqs 12–15) with scipy.special.ellipkinc(φ, m):
  A > B:  m = 2B/(A+B), γ = 2/sqrt(A+B), tan Ω(Θ) = sqrt(A+B) |sin(Θ/2)| / (sqrt(A−B) cos(Θ/2)),
          τ = γ [F(Ω(Θf), m) − sgn(Θ0) F(Ω(Θ0), m)];
  A <= B (only with Θ0 >= 0: the bead starts past the top):
          m = (A+B)/(2B), γ = sqrt(2/B),
          tan φ(Θ) = sqrt(A − B cos Θ) / (sqrt(B − A) cos(Θ/2)),  τ = γ [F(φ(Θf), m) − F(φ(Θ0), m)]
          (Byrd & Friedman 217.00 with x = sin(Θ/2)).
The angles are taken by arctan2 of the two factors, never by asin of sin²Ω, so they keep their
digits where Ω → π/2. What stays double is the parameter m passed to ellipkinc: near δ_m,
1 − m = k'² = (A − B)/(A + B) → 0 and the rounding of m (absolute ~1e-16) is a relative error
~1e-16/k'² in k'², which F(Ω, m) ≈ ln(4/k') turns into a relative error of v̄ that grows as
δ → δ_m; α and δ = radians(δ_deg) are double as well (see stick_refs.py for the errors).

Script use: stick_numpy.py IN.csv OUT.csv reads xi,delta_deg,K,rho,f (K a number) and writes
xi,delta_deg,K,rho,f,v,regime,status,final_velocity with repr() floats.
"""
import csv
import sys

import numpy as np
from scipy.special import ellipkinc

STATUS = ("ok", "stops", "lift-off", "no-steady-state", "invalid")
OK, STOPS, LIFT_OFF, NO_STEADY, INVALID = range(5)
REGIME = np.array([b"B", b"A", b"C", b"C", b""])


def stick(xi, delta_deg, K, rho=0.4, f=0.1):
    """Steady pure rolling over arrays of scenes (see the module docstring)."""
    xi, delta_deg, K, rho, _ = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (xi, delta_deg, K, rho, f)))
    shape = xi.shape
    xi, delta_deg, K, rho = (a.ravel() for a in (xi, delta_deg, K, rho))
    n = xi.size

    with np.errstate(all="ignore"):
        alpha = np.arcsin(1.0 / (1.0 + xi))
        delta = np.radians(delta_deg)
        t0 = delta - alpha
        tf = delta + alpha
        b = 2.0 / (1.0 + rho)
        sin_alpha = np.sin(alpha)
        l2 = 2.0 * b * np.sin(delta) * sin_alpha / (1.0 - K * K)
        w0sq = K * K * l2
        s0 = np.sin(0.5 * t0)
        amb = w0sq - 2.0 * b * s0 * s0

        status = np.full(n, OK, dtype=np.int8)
        status[np.cos(tf) < l2] = LIFT_OFF
        status[((t0 < 0.0) & (amb <= 0.0)) | (l2 == 0.0)] = STOPS
        status[~((K > 0.0) & (K < 1.0))] = INVALID

        v = np.full(n, np.nan)
        tau = np.full(n, np.nan)
        i = np.flatnonzero(status == OK)
        bi, ambi, t0i, tfi = b[i], amb[i], t0[i], tf[i]
        s0i, c0i = s0[i], np.cos(0.5 * t0i)
        sfi, cfi = np.sin(0.5 * tfi), np.cos(0.5 * tfi)
        apb = ambi + 2.0 * bi
        up = ambi > 0.0
        # A > B: modulus k² = 2B/(A+B) < 1 (the usual case, always when Θ0 < 0).
        r_apb, r_amb = np.sqrt(apb), np.sqrt(ambi)
        m = 2.0 * bi / apb
        om_f = np.arctan2(r_apb * np.abs(sfi), r_amb * cfi)
        om_0 = np.arctan2(r_apb * np.abs(s0i), r_amb * c0i)
        tau_up = 2.0 / r_apb * (ellipkinc(om_f, m) - np.sign(t0i) * ellipkinc(om_0, m))
        if not up.all():
            # A <= B with Θ0 >= 0: reciprocal modulus, x = sin(Θ/2) from sin(Θ0/2) up.
            dn = ~up
            bd, ambd = bi[dn], ambi[dn]
            r_bma = np.sqrt(-ambd)
            md = apb[dn] / (2.0 * bd)
            ph_f = np.arctan2(np.sqrt(l2[i][dn]), r_bma * cfi[dn])
            ph_0 = np.arctan2(np.sqrt(w0sq[i][dn]), r_bma * c0i[dn])
            tau_up[dn] = np.sqrt(2.0 / bd) * (ellipkinc(ph_f, md) - ellipkinc(ph_0, md))
        tau[i] = tau_up
        bad = ~(np.isfinite(tau_up) & (tau_up > 0.0))
        status[i[bad]] = INVALID
        tau[i[bad]] = np.nan
        v[i] = 2.0 * sin_alpha[i] / tau[i]
        ok = status == OK
        fv = np.where(ok, np.sqrt(l2), np.nan)
        iv = np.where(ok, K * fv, np.nan)

    return {
        "v": v.reshape(shape),
        "final_velocity": fv.reshape(shape),
        "initial_velocity": iv.reshape(shape),
        "contact_time": tau.reshape(shape),
        "status": status.reshape(shape),
        "regime": REGIME[status].reshape(shape),
    }


def status_names(codes):
    """The status names of an array of int8 codes."""
    return np.asarray(STATUS, dtype=object)[np.asarray(codes)]


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: stick_numpy.py IN.csv OUT.csv (columns xi,delta_deg,K,rho,f)")
    with open(sys.argv[1], newline="") as fh:
        rows = list(csv.DictReader(fh))
    cols = {c: np.array([float(r[c]) for r in rows]) for c in ("xi", "delta_deg", "K", "rho", "f")}
    out = stick(cols["xi"], cols["delta_deg"], cols["K"], cols["rho"], cols["f"])
    names = status_names(out["status"])
    with open(sys.argv[2], "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["xi", "delta_deg", "K", "rho", "f", "v", "regime", "status", "final_velocity"])
        for j, r in enumerate(rows):
            v, fv = out["v"][j], out["final_velocity"][j]
            w.writerow([r["xi"], r["delta_deg"], r["K"], r["rho"], r["f"],
                        "" if np.isnan(v) else repr(float(v)), out["regime"][j].decode(),
                        names[j], "" if np.isnan(fv) else repr(float(fv))])


if __name__ == "__main__":
    main()
