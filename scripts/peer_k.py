#!/usr/bin/env python3
"""The scipy peer of `fitbead k` for the speed comparison (docs/PERFORMANCE.md): per measured
row the same work as `fitbead k --model stick|stickslip` on a row with sigma_v — the bracket
of K, K at v, K_lo at v - sigma_v, K_hi at v + sigma_v (each by scipy's brentq to 1e-15 in K)
and dv/dK (a central difference) — with the contact time from scipy's ellipkinc (rolling,
corrected eqs 12-15 of MODEL.md) and scipy's quad (the slip phase of stick/slip, eqs 64-68).

Usage: peer_k.py stick|stickslip INPUT.csv [ROWS] > out.csv
Reads series,xi,delta_deg,v,sigma_v (rho 0.4, f 0.1), the first ROWS rows (default all);
writes series,xi,delta_deg,v,sigma_v,K,K_lo,K_hi,dv_dK,status and, on stderr, the seconds per
row of the loop (reading and writing included).

Needs numpy and scipy (a venv: python3 -m venv /tmp/peervenv &&
/tmp/peervenv/bin/pip install scipy numpy).
"""
import csv
import math
import sys
import time

from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import ellipkinc

RHO = 0.4
F = 0.1


class NotSteady(Exception):
    pass


def roll_time(b, ta, tb, wa2):
    """Rolling time from ta to tb launched at speed^2 wa2 (corrected eqs 12-15)."""
    a = b * math.cos(ta) + wa2
    if not a > b:
        raise NotSteady("stops")
    m = 2.0 * b / (a + b)
    g = 2.0 / math.sqrt(a + b)

    def big_f(t):
        s2 = (a + b) * math.sin(0.5 * t) ** 2 / (a - b * math.cos(t))
        om = math.asin(math.sqrt(min(max(s2, 0.0), 1.0)))
        return math.copysign(1.0, t) * ellipkinc(om, m)

    return g * (big_f(tb) - big_f(ta))


class Scene:
    def __init__(self, xi, delta_deg, rho=RHO, f=F):
        self.alpha = math.asin(1.0 / (1.0 + xi))
        self.delta = math.radians(delta_deg)
        self.t0 = self.delta - self.alpha
        self.tf = self.delta + self.alpha
        self.rho = rho
        self.f = f
        self.b = 2.0 / (1.0 + rho)
        self.drop = 2.0 * self.b * math.sin(self.delta) * math.sin(self.alpha)
        self.crawl = 2.0 * self.b * math.sin(0.5 * self.t0) ** 2 if self.t0 < 0 else 0.0
        fs = 1.0 + 4.0 * f * f
        self.sb = -6.0 * f / fs
        self.sc = (4.0 * f * f - 2.0) / fs


# --- stick -----------------------------------------------------------------------------------


def stick_bracket(s):
    lo = -math.sin(0.5 * s.t0) / math.sin(0.5 * s.tf) if s.t0 < 0 else 0.0
    cf = math.cos(s.tf)
    k2 = 1.0 - 4.0 * math.sin(s.delta) * math.sin(s.alpha) / ((1.0 + s.rho) * cf)
    if not (cf > 0 and k2 > 0):
        raise NotSteady("lift-off for every K")
    return lo, math.sqrt(k2)


def stick_v(s, k):
    l2 = 4.0 * math.sin(s.delta) * math.sin(s.alpha) / ((1.0 + s.rho) * (1.0 - k * k))
    w0sq = k * k * l2
    return 2.0 * math.sin(s.alpha) / roll_time(s.b, s.t0, s.tf, w0sq)


# --- stick/slip ------------------------------------------------------------------------------


def theta_g(s, w0sq):
    th = 2.0 * math.cos(s.t0) + (1.0 + s.rho) * w0sq
    p = 3.0 + s.rho
    disc = s.rho * s.rho + s.f * s.f * (p - th) * (p + th)
    if disc < 0 or p - th < 0:
        return None
    return 2.0 * math.atan(s.f * (p - th) / (s.rho + math.sqrt(disc)))


def slip_speed_sq(s, ts, us):
    a = (us - s.sb * math.sin(ts) - s.sc * math.cos(ts)) * math.exp(-2.0 * s.f * ts)
    return lambda t: a * math.exp(2.0 * s.f * t) + s.sb * math.sin(t) + s.sc * math.cos(t)


def contact(s, w0sq):
    """One contact launched at speed^2 w0sq: (final speed^2, start of slip, its speed^2)."""
    tg = theta_g(s, w0sq)
    if tg is None:
        raise NotSteady("lift-off")
    if s.t0 < 0 and tg > 0 and w0sq <= s.crawl:
        raise NotSteady("stops")
    if tg >= s.tf:
        return w0sq + s.drop, None, None
    if tg <= s.t0:
        ts, us = s.t0, w0sq
    else:
        ts, us = tg, w0sq + s.b * (math.cos(s.t0) - math.cos(tg))
    xf2 = slip_speed_sq(s, ts, us)(s.tf)
    if not xf2 > 0:
        raise NotSteady("stops")
    if math.cos(s.tf) - xf2 < 0:
        raise NotSteady("lift-off")
    return xf2, ts, us


def fixed_point(s, k):
    """The steady final speed: the root of H(x) - x (H the final-velocity map)."""
    x_lo = math.sqrt(s.crawl) / k * (1.0 + 1e-12) if s.t0 < 0 else 1e-9
    x_hi = math.sqrt(max(math.cos(s.tf), 0.0))

    def g(x):
        try:
            return math.sqrt(contact(s, k * k * x * x)[0]) - x
        except NotSteady as e:
            return -x if str(e) == "stops" else 1.0

    if not (g(x_lo) > 0 and g(x_hi) < 0):
        raise NotSteady("no fixed point")
    return brentq(g, x_lo, x_hi, xtol=1e-15)


def stickslip_v(s, k):
    x = fixed_point(s, k)
    w0sq = k * k * x * x
    _, ts, us = contact(s, w0sq)
    if ts is None:
        tau = roll_time(s.b, s.t0, s.tf, w0sq)
    else:
        t1 = roll_time(s.b, s.t0, ts, w0sq) if ts > s.t0 else 0.0
        u = slip_speed_sq(s, ts, us)
        t2 = quad(lambda t: 1.0 / math.sqrt(u(t)), ts, s.tf, epsabs=0.0, epsrel=1e-13)[0]
        tau = t1 + t2
    return 2.0 * math.sin(s.alpha) / tau


def stickslip_bracket(s):
    lo = -math.sin(0.5 * s.t0) / math.sin(0.5 * s.tf) if s.t0 < 0 else 0.0

    def steady(k):
        try:
            fixed_point(s, k)
            return True
        except NotSteady:
            return False

    a, b = lo + 1e-9, 1.0
    if not steady(a):
        raise NotSteady("no K")
    for _ in range(50):
        m = 0.5 * (a + b)
        if steady(m):
            a = m
        else:
            b = m
    return lo, a


# --- one row ---------------------------------------------------------------------------------


def invert(v_of, lo, hi, v):
    k_lo = lo + 1e-12 * (hi - lo)
    v_lo, v_hi = v_of(k_lo), v_of(hi)
    if v < v_lo:
        return None, "below-range"
    if v > v_hi:
        return None, "above-range"
    return brentq(lambda k: v_of(k) - v, k_lo, hi, xtol=1e-15), "ok"


def row(model, xi, d, v, sg):
    s = Scene(xi, d)
    v_of = (lambda k: stick_v(s, k)) if model == "stick" else (lambda k: stickslip_v(s, k))
    try:
        lo, hi = stick_bracket(s) if model == "stick" else stickslip_bracket(s)
    except NotSteady:
        return None, None, None, None, "invalid"
    k, status = invert(v_of, lo, hi, v)
    if k is None:
        return None, None, None, None, status
    k_lo = invert(v_of, lo, hi, v - sg)[0] if v - sg > 0 else lo
    k_hi = invert(v_of, lo, hi, v + sg)[0]
    k_lo = lo if k_lo is None else k_lo
    k_hi = hi if k_hi is None else k_hi
    h = 1e-6 * (k - lo)
    if k + h <= hi:
        dv = (v_of(k + h) - v_of(k - h)) / (2 * h)
    else:
        dv = (v_of(k) - v_of(k - h)) / h
    return k, k_lo, k_hi, dv, status


def main():
    model = sys.argv[1]
    path = sys.argv[2]
    limit = int(sys.argv[3]) if len(sys.argv) > 3 else None
    t0 = time.perf_counter()
    n = 0
    w = csv.writer(sys.stdout, lineterminator="\n")
    w.writerow(["series", "xi", "delta_deg", "v", "sigma_v", "K", "K_lo", "K_hi", "dv_dK",
                "status"])
    with open(path, newline="") as fh:
        for r in csv.DictReader(fh):
            if limit is not None and n >= limit:
                break
            xi, d, v = float(r["xi"]), float(r["delta_deg"]), float(r["v"])
            sg = float(r["sigma_v"])
            out = row(model, xi, d, v, sg)
            w.writerow([r["series"], r["xi"], r["delta_deg"], r["v"], r["sigma_v"]]
                       + ["" if x is None else repr(float(x)) for x in out[:4]] + [out[4]])
            n += 1
    dt = time.perf_counter() - t0
    print(f"{model}: {n} rows in {dt:.3f} s: {1e6 * dt / max(n, 1):.1f} us per row",
          file=sys.stderr)


if __name__ == "__main__":
    main()
