#!/usr/bin/env python3
"""High-precision reference values for fitbead (Ancey, Evesque & Coussot 1996).

Regenerate, from the crate root:

    python3 tests/reference/make_refs.py            # all tables, all cores
    python3 tests/reference/make_refs.py --jobs 1   # single process (same output)

Needs only mpmath (pip install mpmath).  Deterministic: no randomness; rows are
produced in a fixed order whatever the number of worker processes.  Takes a few
minutes on two cores.

What it writes (next to this file; see README.md for the columns):

  forward_refs.csv            mean velocity v, final velocity, regime of the five
                              steady-state models (stick, stick-approx, slip,
                              slip-approx, stickslip) on a grid of scenes and on
                              named hard cases.
  stickslip_map_bistable.csv  the stick/slip final-velocity map H(x) on a fine grid
                              for the bistable scene of docs/PHYSICS.md (Stick/slip).
  derived_refs.csv            regime limits delta_m (eq 32) and delta_d (eq 31),
                              each checked by root finding, bulk friction mu (eq 79)
                              against tan(delta_m), Theta_G at stick steady states,
                              xi_c, and the figures of docs/PHYSICS.md (Reference figures).
  elliptic_refs.csv           Carlson R_F(x,y,z) and Legendre F(phi|m) at hard
                              points, each checked by an independent quadrature.

Conventions
-----------
* Every input is an IEEE double, printed with repr() (shortest round trip) and
  converted to mpmath exactly (mpf(float)).  Derived inputs (a K law, a slope in
  degrees, delta_m*(1+1e-6), ...) are evaluated first and rounded to a double;
  the reference is for exactly that double.  alpha = asin(1/(1+xi)) is NOT an
  input: it is evaluated at working precision from the exact double xi, so
  Theta0 = delta - alpha and Thetaf = delta + alpha are exact-ish, not the
  double-rounded values a f64 code computes.  Column sens_alpha_ulp gives the
  relative change of v when alpha is multiplied by (1 + 2^-52): a f64 code
  cannot be expected to agree better than a few times that.
* Outputs are printed with 25 significant digits (mpmath.nstr(x, 25)).
* Dimensionless units (docs/PHYSICS.md, Geometry and units): B = 2/(1+rho), v = 2 sin(alpha)/tau.

Method, per model (primary at mp.dps = 40; check at mp.dps = 50)
----------------------------------------------------------------
Every contact time is a DIRECT QUADRATURE of its defining integral
tau = int dtheta / sqrt(g(theta)), never an elliptic closed form.  The minima of
g on the interval (the peaks of the integrand) are located by sampling g' and
bisecting its sign changes to full precision; the interval is split there.
Near a peak where g is small the local width w = sqrt(2 g/g'') (or g/|g'| at an
end point) sets extra break points p +- w*4^j.
  primary : mpmath tanh-sinh on those pieces, maxdegree 10, dps 40;
  check   : everything recomputed from the same doubles at dps 50, each piece
            mapped by theta = p +- w sinh(u) anchored at the peak (which makes
            the near-singular integrand smooth), Gauss-Legendre, and the
            integrand written in its literal (cancelling) form.
The CSV v column is the primary value, v_check the check value, rel_diff their
relative difference.

a) stick (eqs 9-19): L^2 = 2B sin(delta) sin(alpha)/(1-K^2), w0 = K L,
   g = w0^2 + B(cos Theta0 - cos theta), computed in the primary as
   (w0^2 - 2B sin^2(Theta0/2)) + 2B sin^2(theta/2).  Regime A if Theta0 < 0 and
   the top velocity^2 w0^2 - 2B sin^2(Theta0/2) <= 0; C if N = cos Thetaf - L^2 < 0;
   'none' if K is not in (0,1).
b) stick-approx (eq 29 corrected): tau~ = gamma [asinh(tan Om(Thetaf))
   - sgn(Theta0) asinh(tan Om(|Theta0|))], gamma = 2/sqrt(A+B), A = B cos Theta0 + w0^2,
   sin^2 Om(T) = (A+B) sin^2(T/2)/(A - B cos T).  A formula: primary evaluates
   it through sin^2 Om as written; check through the equivalent
   tan Om = tan(T/2) sqrt((A+B)/(A-B)) at dps 50.  Only where A > B.
c) slip (docs/PHYSICS.md Slip, eqs 46-53 corrected): b = -6f/(1+4f^2),
   c = (4f^2-2)/(1+4f^2), Lp2 = (b sin Tf + c cos Tf - (b sin T0 + c cos T0) e^{4f alpha})
   / (1 - K^2 e^{4 f alpha}), a_inf = K^2 Lp2 - b sin T0 - c cos T0,
   G^2 = a_inf e^{2f(theta-T0)} + b sin theta + c cos theta.  'none' if
   K^2 e^{4f alpha} >= 1; A if Lp2 <= 0 or min G^2 <= 0 on [T0,Tf]; C if
   cos Tf - Lp2 < 0.  extra = min G^2.
d) slip-approx (eqs 54-59): G^2 ~ a' + b' sin + c' cos with e^{2f theta} ->
   1 + 4f^2 + 2f sin - 4f^2 cos; time by quadrature of the approximate integrand.
   A if that integrand is not positive on the contact.  final_velocity is the
   exact slip model's sqrt(Lp2) (the approximation only changes the time).
e) stickslip (section 4.4, eqs 64-68): final-velocity map H(x) of docs/PHYSICS.md
   (rationalised eq 36 for Theta_G; branches noslip / slip / slipfromstart /
   noreal = no real Theta_G, treated as no slip).  All fixed points are found
   by scanning H(x)-x on a grid (double precision) and bisecting every sign
   change at dps 40 (|H(x*)-x*| < 1e-30 is asserted; sign changes across a jump
   of H are reported as jumps, not roots); the map is also iterated from the
   stick steady velocity L and the attractor reached is flagged.  Slope H'(x*)
   by mpmath.diff.  tau'' = rolling quadrature on [T0, Theta_G] + slip
   quadrature on [Theta_G, Tf].  The check re-finds x* at dps 50 with the secant
   method and re-does both quadratures by the Gauss-Legendre/sinh route.

A third route (ode_spot_check, printed at the end of the run, writes nothing):
the equations of motion (eq 9, eq 37) integrated by mpmath.odefun for a few
rows of forward_refs.csv.
"""

import argparse
import csv
import math
import os
import sys
import time

import mpmath
from mpmath import mp, mpf

HERE = os.path.dirname(os.path.abspath(__file__))
PRIMARY_DPS = 40
CHECK_DPS = 50
ULP = 2.0 ** -52
# mpmath.ellipf at 40 digits loses ~26 digits at phi = double(pi/2), m = 1
# (found by the quadrature check): the elliptic tables are evaluated at 80.
ELLIPTIC_DPS = 80


def S(x, n=25):
    """25 significant digits."""
    if x is None:
        return ""
    if isinstance(x, str):
        return x
    return mpmath.nstr(mpf(x), n)


def R(x):
    """Shortest round-trip repr of a double input."""
    if x is None:
        return ""
    assert isinstance(x, float)
    return repr(x)


# ----------------------------------------------------------------------------
# quadrature of 1/sqrt(g) with peak handling
# ----------------------------------------------------------------------------

def bisect_root(h, a, b, ha=None, iters=None):
    """Root of h in [a,b] (sign change) by plain bisection to full precision."""
    if ha is None:
        ha = h(a)
    if iters is None:
        iters = mp.prec + 10
    for _ in range(iters):
        mid = (a + b) / 2
        if mid == a or mid == b:
            break
        hm = h(mid)
        if hm == 0:
            return mid
        if (hm < 0) == (ha < 0):
            a, ha = mid, hm
        else:
            b = mid
    return (a + b) / 2


def interior_minima(dg, lo, hi, nsamp=160):
    """Interior local minima of g on (lo,hi): g' changes sign from - to +."""
    xs = [lo + (hi - lo) * mpf(i) / nsamp for i in range(nsamp + 1)]
    ds = [dg(x) for x in xs]
    mins = []
    for i in range(nsamp):
        d0, d1 = ds[i], ds[i + 1]
        if d0 < 0 and d1 > 0:
            mins.append(bisect_root(dg, xs[i], xs[i + 1], d0))
        elif d0 < 0 and d1 == 0 and i + 1 < nsamp:
            mins.append(xs[i + 1])
    return [m for m in mins if lo < m < hi]


def g_minimum(g, dg, lo, hi):
    """(min value, location, interior minima) of g on [lo,hi]."""
    mins = interior_minima(dg, lo, hi)
    cands = [(g(lo), lo), (g(hi), hi)] + [(g(m), m) for m in mins]
    gv, loc = min(cands, key=lambda t: t[0])
    return gv, loc, mins


def peak_width(g, dg, d2g, p, interior):
    """Local width of the integrand peak at p."""
    gp = g(p)
    ws = []
    c = d2g(p)
    if c > 0:
        ws.append(sqrt(2 * gp / c))
    if not interior:
        s = abs(dg(p))
        if s > 0:
            ws.append(gp / s)
    if not ws:
        return None
    return min(ws)


def sqrt(x):
    return mpmath.sqrt(x)


def inv_sqrt_integral(g, dg, d2g, lo, hi, method, mins=None, glit=None):
    """int_lo^hi dtheta / sqrt(g(theta)); g > 0 on [lo,hi] assumed (caller checks).

    method 'ts': tanh-sinh, geometric break points at the peaks.
    method 'gl': sinh map anchored at every peak, Gauss-Legendre; integrand
                 glit (literal form) if given.
    """
    if hi == lo:
        return mpf(0), mpf(0)
    if mins is None:
        mins = interior_minima(dg, lo, hi)
    brk = [lo] + sorted(mins) + [hi]
    length = hi - lo
    total = mpf(0)
    errtot = mpf(0)
    if method == 'ts':
        pts = set(brk)
        for i, p in enumerate(brk):
            interior = 0 < i < len(brk) - 1
            w = peak_width(g, dg, d2g, p, interior)
            if w is None or w >= length / 20:
                continue
            j = 0
            while True:
                d = w * mpf(4) ** j
                if d >= length:
                    break
                for q in (p - d, p + d):
                    if lo < q < hi:
                        pts.add(q)
                j += 1
        pts = sorted(pts)
        f = lambda t: 1 / sqrt(g(t))
        val, err = mpmath.quad(f, pts, error=True, maxdegree=10)
        if err > mpf(10) ** (-mp.dps + 8) * abs(val):
            raise RuntimeError("tanh-sinh did not converge: err %s" % err)
        return val, err
    elif method == 'gl':
        gg = glit if glit is not None else g
        for i in range(len(brk) - 1):
            s, e = brk[i], brk[i + 1]
            mid = (s + e) / 2
            for anchor, end, interior in ((s, mid, 0 < i), (e, mid, i + 1 < len(brk) - 1)):
                half = abs(end - anchor)
                if half == 0:
                    continue
                sgn = 1 if end > anchor else -1
                w = peak_width(g, dg, d2g, anchor, interior)
                if w is None or w > half:
                    w = half
                U = mpmath.asinh(half / w)
                f = (lambda a, w, sgn: lambda u: w * mpmath.cosh(u) / sqrt(gg(a + sgn * w * mpmath.sinh(u))))(anchor, w, sgn)
                nseg = max(1, int(mpmath.ceil(U / 2)))
                upts = [U * k / nseg for k in range(nseg + 1)]
                val, err = mpmath.quad(f, upts, method='gauss-legendre', error=True, maxdegree=10)
                if err > mpf(10) ** (-mp.dps + 8) * abs(val):
                    raise RuntimeError("gauss-legendre did not converge: err %s" % err)
                total += val
                errtot += err
        return total, errtot
    raise ValueError(method)


# ----------------------------------------------------------------------------
# scene
# ----------------------------------------------------------------------------

class Scene:
    def __init__(self, xi, delta, K, rho=None, f=None, alpha_scale=0.0):
        self.xi = mpf(xi)
        self.delta = mpf(delta)
        self.K = mpf(K)
        self.rho = None if rho is None else mpf(rho)
        self.f = None if f is None else mpf(f)
        a = mpmath.asin(1 / (1 + self.xi))
        if alpha_scale:
            a = a * (1 + mpf(alpha_scale))
        self.alpha = a
        self.th0 = self.delta - a
        self.thf = self.delta + a
        if self.rho is not None:
            self.B = 2 / (1 + self.rho)
        if self.f is not None:
            f = self.f
            self.b = -6 * f / (1 + 4 * f * f)
            self.c = (4 * f * f - 2) / (1 + 4 * f * f)


def result(regime, v=None, fv=None, extra=None, extra_name="", note="", **kw):
    d = dict(regime=regime, v=v, final_velocity=fv, extra=extra, extra_name=extra_name, note=note)
    d.update(kw)
    return d


# ---------------------------- stick -----------------------------------------

def stick(sc, method):
    K, B = sc.K, sc.B
    if not (0 < K < 1):
        return result('none', note='K not in (0;1): no steady state')
    L2 = 2 * B * mpmath.sin(sc.delta) * mpmath.sin(sc.alpha) / (1 - K * K)
    w02 = K * K * L2
    m = w02 - 2 * B * mpmath.sin(sc.th0 / 2) ** 2   # velocity^2 at the top
    vmin2 = m if sc.th0 < 0 else w02
    if sc.th0 < 0 and m <= 0:
        return result('A', extra=vmin2, extra_name='min_velocity2',
                      note='stops: top velocity^2 = %s <= 0' % mpmath.nstr(m, 6))
    g = lambda t: m + 2 * B * mpmath.sin(t / 2) ** 2
    glit = lambda t: w02 + B * (mpmath.cos(sc.th0) - mpmath.cos(t))
    dg = lambda t: B * mpmath.sin(t)
    d2g = lambda t: B * mpmath.cos(t)
    mins = [mpf(0)] if sc.th0 < 0 < sc.thf else []
    tau, err = inv_sqrt_integral(g, dg, d2g, sc.th0, sc.thf, method, mins=mins,
                                 glit=glit if method == 'gl' else None)
    v = 2 * mpmath.sin(sc.alpha) / tau
    N = mpmath.cos(sc.thf) - L2
    reg = 'B' if N >= 0 else 'C'
    note = '' if reg == 'B' else 'lift-off: N(Thetaf) = %s < 0; v ignores it' % mpmath.nstr(N, 6)
    return result(reg, v, sqrt(L2), vmin2, 'min_velocity2', note, tau=tau, N=N)


def stick_approx(sc, method):
    K, B = sc.K, sc.B
    if not (0 < K < 1):
        return result('none', note='K not in (0;1): no steady state')
    L2 = 2 * B * mpmath.sin(sc.delta) * mpmath.sin(sc.alpha) / (1 - K * K)
    w02 = K * K * L2
    AmB = w02 - 2 * B * mpmath.sin(sc.th0 / 2) ** 2   # A - B, computed directly
    if sc.th0 < 0 and AmB <= 0:
        return result('A', note='stops: top velocity^2 = %s <= 0' % mpmath.nstr(AmB, 6))
    if AmB <= 0:
        return result('none', note='A <= B (k >= 1): approximation undefined')
    A = B * mpmath.cos(sc.th0) + w02
    ApB = A + B
    gamma = 2 / sqrt(ApB)
    kp2 = AmB / ApB

    def asinh_tan_omega(T):
        if method == 'ts':
            s2 = ApB * mpmath.sin(T / 2) ** 2 / (AmB + 2 * B * mpmath.sin(T / 2) ** 2)
            om = mpmath.asin(sqrt(s2))
            return mpmath.asinh(mpmath.tan(om))
        else:
            return mpmath.asinh(mpmath.tan(T / 2) / sqrt(kp2))

    tau = gamma * (asinh_tan_omega(sc.thf) - mpmath.sign(sc.th0) * asinh_tan_omega(abs(sc.th0)))
    v = 2 * mpmath.sin(sc.alpha) / tau
    N = mpmath.cos(sc.thf) - L2
    reg = 'B' if N >= 0 else 'C'
    note = '' if reg == 'B' else 'lift-off: N(Thetaf) = %s < 0; v ignores it' % mpmath.nstr(N, 6)
    return result(reg, v, sqrt(L2), kp2, 'kprime2', note, tau=tau)


# ---------------------------- slip ------------------------------------------

def slip_state(sc):
    K, f, b, c = sc.K, sc.f, sc.b, sc.c
    E = mpmath.exp(4 * f * sc.alpha)
    if not (K * K * E < 1):
        return None, 'K^2 e^{4 f alpha} = %s >= 1: no steady state' % mpmath.nstr(K * K * E, 6)
    s0 = b * mpmath.sin(sc.th0) + c * mpmath.cos(sc.th0)
    sf = b * mpmath.sin(sc.thf) + c * mpmath.cos(sc.thf)
    Lp2 = (sf - s0 * E) / (1 - K * K * E)
    if Lp2 <= 0:
        return None, 'stops: Lp2 = %s <= 0' % mpmath.nstr(Lp2, 6)
    a = K * K * Lp2 - s0
    return (Lp2, a), ''


def slip(sc, method):
    st, why = slip_state(sc)
    if st is None:
        return result('none' if 'no steady' in why else 'A', note=why)
    Lp2, a = st
    f, b, c, t0 = sc.f, sc.b, sc.c, sc.th0
    g = lambda t: a * mpmath.exp(2 * f * (t - t0)) + b * mpmath.sin(t) + c * mpmath.cos(t)
    dg = lambda t: 2 * f * a * mpmath.exp(2 * f * (t - t0)) + b * mpmath.cos(t) - c * mpmath.sin(t)
    d2g = lambda t: 4 * f * f * a * mpmath.exp(2 * f * (t - t0)) - b * mpmath.sin(t) - c * mpmath.cos(t)
    gmin, loc, mins = g_minimum(g, dg, sc.th0, sc.thf)
    if gmin <= 0:
        return result('A', extra=gmin, extra_name='min_G2',
                      note='stops: G^2 reaches %s at theta = %s' % (mpmath.nstr(gmin, 6), mpmath.nstr(loc, 6)))
    tau, err = inv_sqrt_integral(g, dg, d2g, sc.th0, sc.thf, method, mins=mins)
    v = 2 * mpmath.sin(sc.alpha) / tau
    N = mpmath.cos(sc.thf) - Lp2
    reg = 'B' if N >= 0 else 'C'
    note = '' if reg == 'B' else 'lift-off: N(Thetaf) = %s < 0; v ignores it' % mpmath.nstr(N, 6)
    return result(reg, v, sqrt(Lp2), gmin, 'min_G2', note, tau=tau)


def slip_approx(sc, method):
    st, why = slip_state(sc)
    if st is None:
        return result('none' if 'no steady' in why else 'A', note=why)
    Lp2, a = st
    f, b, c, t0 = sc.f, sc.b, sc.c, sc.th0
    e0 = mpmath.exp(-2 * f * t0)
    ap = a * (1 + 4 * f * f) * e0
    bp = b + 2 * f * a * e0
    cp = c - 4 * f * f * a * e0
    g = lambda t: ap + bp * mpmath.sin(t) + cp * mpmath.cos(t)
    dg = lambda t: bp * mpmath.cos(t) - cp * mpmath.sin(t)
    d2g = lambda t: -bp * mpmath.sin(t) - cp * mpmath.cos(t)
    gmin, loc, mins = g_minimum(g, dg, sc.th0, sc.thf)
    if gmin <= 0:
        return result('A', extra=gmin, extra_name='min_G2hat',
                      note='approximate velocity^2 reaches %s at theta = %s: not reported'
                      % (mpmath.nstr(gmin, 6), mpmath.nstr(loc, 6)))
    tau, err = inv_sqrt_integral(g, dg, d2g, sc.th0, sc.thf, method, mins=mins)
    v = 2 * mpmath.sin(sc.alpha) / tau
    N = mpmath.cos(sc.thf) - Lp2
    reg = 'B' if N >= 0 else 'C'
    note = '' if reg == 'B' else 'lift-off: N(Thetaf) = %s < 0; v ignores it' % mpmath.nstr(N, 6)
    return result(reg, v, sqrt(Lp2), gmin, 'min_G2hat', note, tau=tau)


# ---------------------------- stick/slip ------------------------------------

class MathNS:
    sin = staticmethod(math.sin)
    cos = staticmethod(math.cos)
    exp = staticmethod(math.exp)
    sqrt = staticmethod(math.sqrt)
    atan = staticmethod(math.atan)
    tan = staticmethod(math.tan)


class MpNS:
    sin = staticmethod(mpmath.sin)
    cos = staticmethod(mpmath.cos)
    exp = staticmethod(mpmath.exp)
    sqrt = staticmethod(mpmath.sqrt)
    atan = staticmethod(mpmath.atan)
    tan = staticmethod(mpmath.tan)


def ss_params(sc, ns):
    conv = float if ns is MathNS else (lambda x: x)
    return dict(K=conv(sc.K), rho=conv(sc.rho), f=conv(sc.f), B=conv(sc.B), b=conv(sc.b),
                c=conv(sc.c), t0=conv(sc.th0), tf=conv(sc.thf))


def ss_map(x, P, ns):
    """One step of the stick/slip final-velocity map.

    Returns (y = H(x)^2, branch, Theta_G or None, top_ok).  top_ok is False when
    the rolling phase crosses the top with velocity^2 <= 0 (the bead stops)."""
    K, rho, f, B, b, c, t0, tf = (P[k] for k in ('K', 'rho', 'f', 'B', 'b', 'c', 't0', 'tf'))
    w02 = (K * x) ** 2
    vt = 2 * ns.cos(t0) + (1 + rho) * w02
    disc = rho * rho + f * f * ((3 + rho) ** 2 - vt * vt)
    roll_y = w02 + B * (ns.cos(t0) - ns.cos(tf))
    if disc < 0:
        tg = None
        branch = 'noreal'
        y = roll_y
        roll_end = tf
    else:
        den = rho + ns.sqrt(disc)
        # den = 0 only when rho = 0 and vt = 3 (N = 0 at the top); then the
        # numerator f(3 - vt) is 0 too and the limit vt -> 3- is Theta_G -> 0
        tg = 2 * ns.atan(f * (3 + rho - vt) / den) if den != 0 else 0 * vt
        if tg >= tf:
            branch, y, roll_end = 'noslip', roll_y, tf
        elif tg <= t0:
            branch, roll_end = 'slipfromstart', t0
            a = w02 - b * ns.sin(t0) - c * ns.cos(t0)
            y = a * ns.exp(2 * f * (tf - t0)) + b * ns.sin(tf) + c * ns.cos(tf)
        else:
            branch, roll_end = 'slip', tg
            wg2 = w02 + B * (ns.cos(t0) - ns.cos(tg))
            a = wg2 - b * ns.sin(tg) - c * ns.cos(tg)
            y = a * ns.exp(2 * f * (tf - tg)) + b * ns.sin(tf) + c * ns.cos(tf)
    top_ok = True
    if t0 < 0 < roll_end:
        top_ok = w02 - 2 * B * ns.sin(t0 / 2) ** 2 > 0
    return y, branch, tg, top_ok


def ss_H(x, P, ns):
    y, br, tg, ok = ss_map(x, P, ns)
    if not ok or y <= 0:
        return None, br
    return ns.sqrt(y), br


def ss_fixed_points(sc, nscan=4000):
    """All fixed points of H (dps of the caller), plus the index of the one
    reached by iteration from the stick steady velocity L.  Returns
    (list of mpf roots, list of jumps (x where H-x changes sign by a jump),
     attractor info string, L)."""
    Pf = ss_params(sc, MathNS)
    Pm = ss_params(sc, MpNS)
    K = sc.K
    L = sqrt(2 * sc.B * mpmath.sin(sc.delta) * mpmath.sin(sc.alpha) / (1 - K * K))
    Lf = float(L)
    xmax = max(3.0, 3.0 * Lf)
    xs = [xmax * i / nscan for i in range(1, nscan + 1)]
    Fs = []
    for x in xs:
        h, br = ss_H(x, Pf, MathNS)
        Fs.append(None if h is None else h - x)
    roots, jumps = [], []

    def Hm(x):
        return ss_H(x, Pm, MpNS)

    def refine(a, b):
        ha, hb = Hm(mpf(a))[0], Hm(mpf(b))[0]
        if ha is None or hb is None:
            return None, False
        fa = ha - mpf(a)
        fb = hb - mpf(b)
        if fa == 0:
            return mpf(a), True
        if (fa < 0) == (fb < 0):
            return None, False
        h = lambda x: Hm(x)[0] - x
        r = bisect_root(h, mpf(a), mpf(b), fa)
        # continuity test: a true root has a tiny residual
        hr = Hm(r)[0]
        ok = hr is not None and abs(hr - r) < mpf(10) ** (-30)
        return r, ok

    for i in range(len(xs) - 1):
        F0, F1 = Fs[i], Fs[i + 1]
        if F0 is None or F1 is None:
            continue
        if F0 == 0 or (F0 < 0) != (F1 < 0):
            r, ok = refine(xs[i], xs[i + 1])
            if r is None:
                continue
            if ok:
                if not any(abs(r - q) < mpf(10) ** -20 for q in roots):
                    roots.append(r)
            else:
                jumps.append(r)
    # iterate from L in double precision
    x = Lf
    att = None
    status = 'diverges'
    for it in range(200000):
        h, br = ss_H(x, Pf, MathNS)
        if h is None:
            status = 'stops (velocity not real) after %d steps from L' % it
            break
        if not math.isfinite(h) or h > 100 * xmax:
            status = 'diverges from L'
            break
        if abs(h - x) <= 1e-14 * max(1.0, x):
            x = h
            status = 'converged'
            break
        x = h
    if status == 'converged':
        if roots:
            j = min(range(len(roots)), key=lambda k: abs(roots[k] - x))
            if abs(roots[j] - x) < 1e-8:
                att = j
        if att is None:
            # not seen by the scan (e.g. squeezed against the point where the
            # bead stops at the top): secant at full precision from the iterate
            def hs(x):
                hv = Hm(x)[0]
                if hv is None:
                    raise ValueError('map undefined')
                return hv - x
            r = None
            try:
                r = mpmath.findroot(hs, (mpf(x), mpf(x) * (1 + mpf(10) ** -12)), solver='secant')
                if abs(hs(r)) >= mpf(10) ** -30:
                    r = None
            except (ValueError, ZeroDivisionError):
                r = None
            if r is None:
                for rel in (1e-9, 1e-11, 1e-13):
                    r, ok = refine(x * (1 - rel), x * (1 + rel))
                    if r is not None and ok:
                        break
                    r = None
            if r is not None:
                roots.append(r)
                att = len(roots) - 1
    order = sorted(range(len(roots)), key=lambda k: roots[k])
    roots_sorted = [roots[k] for k in order]
    att_sorted = None if att is None else order.index(att)
    return roots_sorted, jumps, att_sorted, status, L


def ss_at_fixed_point(sc, xs, method):
    """Mean velocity etc. of one stick/slip steady state with final velocity xs."""
    Pm = ss_params(sc, MpNS)
    y, br, tg, top_ok = ss_map(xs, Pm, MpNS)
    K, B, f, b, c, t0, tf = sc.K, sc.B, sc.f, sc.b, sc.c, sc.th0, sc.thf
    w02 = (K * xs) ** 2
    roll_end = {'noreal': tf, 'noslip': tf, 'slipfromstart': t0, 'slip': tg}[br]
    slip_start = roll_end
    tau = mpf(0)
    notes = []
    minv2 = None
    if roll_end > t0:
        m = w02 - 2 * B * mpmath.sin(t0 / 2) ** 2
        g = lambda t: m + 2 * B * mpmath.sin(t / 2) ** 2
        glit = lambda t: w02 + B * (mpmath.cos(t0) - mpmath.cos(t))
        dg = lambda t: B * mpmath.sin(t)
        d2g = lambda t: B * mpmath.cos(t)
        if t0 < 0 < roll_end:
            if m <= 0:
                return None, br, tg, 'A', 'stops at the top'
            mins = [mpf(0)]
            minv2 = m
        else:
            mins = []
            minv2 = min(g(t0), g(roll_end))
        t1, _ = inv_sqrt_integral(g, dg, d2g, t0, roll_end, method, mins=mins,
                                  glit=glit if method == 'gl' else None)
        tau += t1
    if slip_start < tf:
        if br == 'slipfromstart':
            a = w02 - b * mpmath.sin(t0) - c * mpmath.cos(t0)
        else:
            wg2 = w02 + B * (mpmath.cos(t0) - mpmath.cos(tg))
            a = wg2 - b * mpmath.sin(tg) - c * mpmath.cos(tg)
        s = slip_start
        g = lambda t: a * mpmath.exp(2 * f * (t - s)) + b * mpmath.sin(t) + c * mpmath.cos(t)
        dg = lambda t: 2 * f * a * mpmath.exp(2 * f * (t - s)) + b * mpmath.cos(t) - c * mpmath.sin(t)
        d2g = lambda t: 4 * f * f * a * mpmath.exp(2 * f * (t - s)) - b * mpmath.sin(t) - c * mpmath.cos(t)
        gmin, loc, mins = g_minimum(g, dg, s, tf)
        minv2 = gmin if minv2 is None else min(minv2, gmin)
        if gmin <= 0:
            return None, br, tg, 'A', 'slip velocity^2 reaches %s' % mpmath.nstr(gmin, 6)
        t2, _ = inv_sqrt_integral(g, dg, d2g, s, tf, method, mins=mins)
        tau += t2
    v = 2 * mpmath.sin(sc.alpha) / tau
    N0 = mpmath.cos(t0) - w02
    Nf = mpmath.cos(tf) - xs * xs
    reg = 'B' if min(N0, Nf) >= 0 else 'C'
    if reg == 'C':
        notes.append('lift-off: min(N(Theta0) N(Thetaf)) = %s < 0; v ignores it' % mpmath.nstr(min(N0, Nf), 6))
    return dict(v=v, tau=tau, minv2=minv2), br, tg, reg, '; '.join(notes)


def stickslip_rows(sc, method):
    """List of results, one per fixed point (or one explaining why none)."""
    if not (0 < sc.K < 1):
        return [result('none', note='K not in (0;1)')]
    roots, jumps, att, status, L = ss_fixed_points(sc)
    Pm = ss_params(sc, MpNS)
    out = []
    jumpnote = ''
    if jumps:
        jumpnote = 'H-x changes sign by a jump (not a root) at x = ' + ' '.join(mpmath.nstr(j, 8) for j in jumps)
    if not roots:
        reg = 'A' if 'stops' in status else 'none'
        return [result(reg, note='no fixed point; iteration from L: %s%s' % (status, ('; ' + jumpnote) if jumpnote else ''))]
    for i, xs in enumerate(roots):
        if method == 'gl':
            # independent re-solve at the current (higher) precision: secant from a nearby double
            x0 = mpf(float(xs))
            h = lambda x: ss_H(x, Pm, MpNS)[0] - x
            xs = mpmath.findroot(h, (x0 * (1 - mpf(10) ** -10), x0 * (1 + mpf(10) ** -10)), solver='secant')
        H = lambda x: ss_H(x, Pm, MpNS)[0]
        resid = H(xs) - xs
        assert abs(resid) < mpf(10) ** -30, ('fixed point residual', resid)
        slope = mpmath.diff(H, xs)
        r, br, tg, reg, note = ss_at_fixed_point(sc, xs, method)
        notes = ['branch=%s' % br, '|H(x*)-x*|=%s' % mpmath.nstr(abs(resid), 3)]
        if i == att:
            notes.append('attractor reached from L')
        elif att is None:
            notes.append('iteration from L: %s' % status)
        if len(roots) > 1:
            notes.append('%d fixed points' % len(roots))
        if jumpnote:
            notes.append(jumpnote)
        if note:
            notes.append(note)
        tgdeg = None if tg is None else tg * 180 / mpmath.pi
        stable = abs(slope) < 1
        d = result(reg, None if r is None else r['v'], xs, tgdeg, 'theta_G_deg', '; '.join(notes),
                   fixed_point_index=i, slope=slope, stable='true' if stable else 'false',
                   n_fixed=len(roots), attractor=(i == att))
        out.append(d)
    return out


MODELS = {
    'stick': stick,
    'stick-approx': stick_approx,
    'slip': slip,
    'slip-approx': slip_approx,
}


def run_model(model, inputs, method, dps, alpha_scale=0.0):
    with mp.workdps(dps):
        xi, delta, K, rho, f = inputs
        sc = Scene(xi, delta, K, rho, f, alpha_scale)
        if model == 'stickslip':
            return stickslip_rows(sc, method)
        return [MODELS[model](sc, method)]


# ----------------------------------------------------------------------------
# regime limits, laws
# ----------------------------------------------------------------------------

def alpha_of(xi):
    return mpmath.asin(1 / (1 + mpf(xi)))


def K_fitted(alpha):
    return mpmath.cos(2 * alpha) + mpmath.sin(alpha) ** 2 * mpmath.sin(2 * alpha) / 2


def K_smooth(alpha):
    return mpmath.cos(2 * alpha)


def delta_m_eq32(alpha, K):
    return 2 * mpmath.atan(mpmath.tan(alpha / 2) * (1 - K) / (1 + K))


def delta_d_eq31(alpha, K, rho):
    Q = (1 + rho) * (1 - K * K)
    return mpmath.atan(Q / (mpmath.tan(alpha) * (4 + Q)))


def delta_m_root(alpha, K, rho):
    """top velocity^2 = K^2 L^2 - 2B sin^2((delta-alpha)/2) = 0 (delta < alpha)."""
    B = 2 / (1 + rho)
    h = lambda d: K * K * 2 * B * mpmath.sin(d) * mpmath.sin(alpha) / (1 - K * K) \
        - 2 * B * mpmath.sin((d - alpha) / 2) ** 2
    return bisect_root(h, mpf(0), alpha)


def delta_d_root(alpha, K, rho):
    """N(Thetaf) = cos(delta+alpha) - L^2 = 0."""
    B = 2 / (1 + rho)
    h = lambda d: mpmath.cos(d + alpha) - 2 * B * mpmath.sin(d) * mpmath.sin(alpha) / (1 - K * K)
    return bisect_root(h, mpf(0), mpmath.pi / 2 - alpha)


def mu_eq79(alpha, K):
    return (1 - K * K) * mpmath.sin(alpha) / ((1 + K * K) * mpmath.cos(alpha) + 2 * K)


def theta_G(th0, w02, rho, f):
    vt = 2 * mpmath.cos(th0) + (1 + rho) * w02
    disc = rho * rho + f * f * ((3 + rho) ** 2 - vt * vt)
    if disc < 0:
        return None
    return 2 * mpmath.atan(f * (3 + rho - vt) / (rho + sqrt(disc)))


def theta_G_eq36_printed(th0, w02, rho, f):
    vt = 2 * mpmath.cos(th0) + (1 + rho) * w02
    return 2 * mpmath.atan((-rho + sqrt(rho * rho - f * f * (vt * vt - (3 + rho) ** 2))) / (f * (3 + rho + vt)))


def K_law_double(name, xi):
    """A K law evaluated at high precision, rounded to a double."""
    with mp.workdps(PRIMARY_DPS + 10):
        a = alpha_of(xi)
        if name == 'Kfit':
            return float(K_fitted(a))
        if name == 'Kcos':
            return float(max(K_smooth(a), mpf('0.05')))
        if name == 'Kimpact':
            rho = mpf(0.4)
            return float((mpmath.cos(2 * a) + rho) / (1 + rho))
    raise ValueError(name)


# ----------------------------------------------------------------------------
# forward tasks
# ----------------------------------------------------------------------------

XI = [0.65, 0.8, 1.0, 1.6, 2.0, 4.0, 10.0]
RHO = [0.0, 0.4, 0.5, 1.0]
FF = [1e-6, 0.01, 0.1, 0.5, 2.0]
FRACS = [0.1, 0.5, 0.9]


def grid_deltas(xi, K, rho):
    with mp.workdps(PRIMARY_DPS + 10):
        a = alpha_of(xi)
        K = mpf(K)
        rho = mpf(rho)
        dm = delta_m_eq32(a, K)
        dd = delta_d_eq31(a, K, rho)
        top = min(dd, mpmath.radians(80))
        return [float(dm + mpf(fr) * (top - dm)) for fr in FRACS]


def build_grid_tasks():
    tasks = []
    # stick and stick-approx: independent of f
    for xi in XI:
        for rho in RHO:
            for kname in ('Kfit', 'Kcos', 'K0.9'):
                K = 0.9 if kname == 'K0.9' else K_law_double(kname, xi)
                for fr, d in zip(FRACS, grid_deltas(xi, K, rho)):
                    for model in ('stick', 'stick-approx'):
                        tasks.append(('grid:%s:frac%s' % (kname, fr), model, xi, d, K, rho, None))
    # slip models (independent of rho) and stickslip: rho subsampled, two per (xi,f)
    for ix, xi in enumerate(XI):
        for jf, f in enumerate(FF):
            rhos = [RHO[(ix + jf) % 4], RHO[(ix + jf + 2) % 4]]
            for rho in rhos:
                for kname in ('Kfit', 'Kcos', 'K0.9ub'):
                    if kname == 'K0.9ub':
                        with mp.workdps(PRIMARY_DPS + 10):
                            K = float(mpf('0.9') * mpmath.exp(-2 * mpf(f) * alpha_of(xi)))
                    else:
                        K = K_law_double(kname, xi)
                    for fr, d in zip(FRACS, grid_deltas(xi, K, rho)):
                        case = 'grid:%s:frac%s:deltas_rho%s' % (kname, fr, rho)
                        for model in ('slip', 'slip-approx'):
                            if rho == rhos[0]:
                                tasks.append((case, model, xi, d, K, None, f))
                        tasks.append((case, 'stickslip', xi, d, K, rho, f))
    return tasks


def build_hard_tasks():
    T = []
    ALL = ('stick', 'stick-approx', 'slip', 'slip-approx', 'stickslip')

    def add(case, xi, d, K, rho, f, models=ALL):
        for m in models:
            T.append((case, m, xi, d, K,
                      None if m in ('slip', 'slip-approx') else rho,
                      None if m in ('stick', 'stick-approx') else f))

    with mp.workdps(60):
        for xi in (0.8, 1.0, 10.0):
            K = K_law_double('Kfit', xi)
            a = alpha_of(xi)
            dm = delta_m_eq32(a, mpf(K))
            for tag, eps in (('1e-6', mpf('1e-6')), ('1e-9', mpf('1e-9'))):
                d = float(dm * (1 + eps))
                add('delta_m*(1+%s)' % tag, xi, d, K, 0.4, 0.1, ('stick', 'stick-approx', 'stickslip'))
            d = float(dm * (1 - mpf('1e-9')))
            add('delta_m*(1-1e-9)', xi, d, K, 0.4, 0.1, ('stick', 'stick-approx', 'stickslip'))
        # Theta0 = 0 and +-1e-9 relative (xi=1 Kfit is regime C there; the others are B)
        for xi, K in ((1.0, K_law_double('Kfit', 1.0)), (2.0, 0.5), (4.0, K_law_double('Kfit', 4.0)),
                      (10.0, K_law_double('Kfit', 10.0))):
            a = alpha_of(xi)
            add('Theta0=0 (delta=double(alpha))', xi, float(a), K, 0.4, 0.1)
            add('Theta0=+1e-9*alpha', xi, float(a * (1 + mpf('1e-9'))), K, 0.4, 0.1)
            add('Theta0=-1e-9*alpha', xi, float(a * (1 - mpf('1e-9'))), K, 0.4, 0.1)
        # K within 1e-6 of its upper limit
        for xi in (1.0, 2.0):
            a = alpha_of(xi)
            Ks = 1.0 - 1e-6
            dm = delta_m_eq32(a, mpf(Ks))
            dd = delta_d_eq31(a, mpf(Ks), mpf(0.4))
            add('K=1-1e-6 delta mid-B (tiny slope)', xi, float((dm + dd) / 2), Ks, 0.4, 0.1, ('stick', 'stick-approx', 'stickslip'))
            add('K=1-1e-6 delta=5deg', xi, math.radians(5.0), Ks, 0.4, 0.1, ('stick', 'stick-approx'))
            for f in (0.1, 1e-6):
                Kslip = float(mpmath.exp(-2 * mpf(f) * a) * (1 - mpf('1e-6')))
                add('K=(1-1e-6)e^{-2f alpha} (slip limit)', xi, math.radians(5.0), Kslip, 0.4, f, ('slip', 'slip-approx', 'stickslip'))
                add('K=(1-1e-6)e^{-2f alpha} tiny slope', xi, float((dm + dd) / 2), Kslip, 0.4, f, ('slip', 'slip-approx', 'stickslip'))
        # f tiny, f large
        for xi in (1.0, 2.0, 10.0):
            K = K_law_double('Kfit', xi)
            ds = grid_deltas(xi, K, 0.4)
            for f in (1e-6, 2.0, 10.0):
                add('f=%r' % f, xi, ds[1], K, 0.4, f, ('slip', 'slip-approx', 'stickslip'))
            add('f=10 reference stick', xi, ds[1], K, 0.4, None, ('stick',))
        # slip from the start: Theta0 > 0 (delta > alpha), small f
        add('slip from start (Theta_G<=Theta0)', 10.0, math.radians(7.0), 0.9, 0.4, 0.01, ('stick', 'stickslip'))
        add('slip from start (Theta_G<=Theta0)', 4.0, math.radians(13.0), 0.8, 0.4, 0.01, ('stick', 'stickslip'))
        # bistable scene, with K = 0.9842 as docs/PHYSICS.md states it, and with the
        # fitted law at xi = 10 (0.98421927813...) that 0.9842 rounds
        add('bistable (PHYSICS.md stick/slip)', 10.0, math.radians(5.767), 0.9842, 1.0, 0.2, ('stick', 'stickslip'))
        add('bistable with K=Kfit(xi=10) unrounded', 10.0, math.radians(5.767), K_law_double('Kfit', 10.0), 1.0, 0.2,
            ('stick', 'stickslip'))
        # slip and stick/slip with K e^{2 f alpha} = 1 - 1e-6 in regime B: the
        # slope where the steady final velocity^2 is half cos(Thetaf)
        for xi in (1.0, 2.0, 10.0):
            for f in (0.1, 0.01):
                a = alpha_of(xi)
                Kslip = float(mpmath.exp(-2 * mpf(f) * a) * (1 - mpf('1e-6')))
                d = slip_delta_for_Lp2(xi, Kslip, f, mpf('0.5'))
                if d is not None:
                    add('K e^{2f alpha}=1-1e-6 regime B', xi, float(d), Kslip, 0.4, f, ('slip', 'slip-approx', 'stickslip'))
        # Fig 7 scenes
        for xi, deg in ((2.0, 5.73), (1.0, 11.53)):
            K = K_law_double('Kfit', xi)
            add('Fig7 xi=%r delta=%rdeg' % (xi, deg), xi, math.radians(deg), K, 0.4, 0.1)
        # the rolling check scene of docs/PHYSICS.md (Reference figures)
        add('rolling check (v=0.39120827...)', 1.0, math.radians(12.0), K_law_double('Kfit', 1.0), 0.4, 0.1, ('stick', 'stick-approx'))
        # slip model near its own stop limit: delta where min G^2 = 0, times (1+1e-6)
        for xi in (1.0, 2.0):
            K = K_law_double('Kfit', xi)
            ds = slip_stop_delta(xi, K, 0.1)
            if ds is not None:
                add('slip stop limit*(1+1e-6)', xi, float(ds * (1 + mpf('1e-6'))), K, None, 0.1, ('slip',))
                add('slip stop limit*(1+1e-9)', xi, float(ds * (1 + mpf('1e-9'))), K, None, 0.1, ('slip',))
    return T


def slip_min_G2(xi, delta, K, f):
    sc = Scene(xi, delta, K, None, f)
    st, why = slip_state(sc)
    if st is None:
        return None if 'no steady' in why else mpf(-1)
    Lp2, a = st
    b, c, t0 = sc.b, sc.c, sc.th0
    g = lambda t: a * mpmath.exp(2 * f * (t - t0)) + b * mpmath.sin(t) + c * mpmath.cos(t)
    dg = lambda t: 2 * f * a * mpmath.exp(2 * f * (t - t0)) + b * mpmath.cos(t) - c * mpmath.sin(t)
    return g_minimum(g, dg, sc.th0, sc.thf)[0]


def slip_delta_for_Lp2(xi, K, f, frac):
    """Slope at which the slip model's Lp2 equals frac * cos(Thetaf) (bisection)."""
    a = alpha_of(xi)
    f = mpf(f)
    K = mpf(K)
    b = -6 * f / (1 + 4 * f * f)
    c = (4 * f * f - 2) / (1 + 4 * f * f)
    E = mpmath.exp(4 * f * a)

    def h(d):
        s0 = b * mpmath.sin(d - a) + c * mpmath.cos(d - a)
        sf = b * mpmath.sin(d + a) + c * mpmath.cos(d + a)
        return (sf - s0 * E) - frac * mpmath.cos(d + a) * (1 - K * K * E)
    lo, hi = mpf('1e-6'), mpmath.pi / 2 - a - mpf('1e-6')
    if not (h(lo) < 0 < h(hi)):
        return None
    return bisect_root(h, lo, hi)


def slip_stop_delta(xi, K, f):
    """Slope where the slip model's min G^2 crosses 0 (bisection on delta)."""
    a = alpha_of(xi)
    lo, hi = mpf('1e-4'), a
    glo, ghi = slip_min_G2(xi, lo, K, mpf(f)), slip_min_G2(xi, hi, K, mpf(f))
    if glo is None or ghi is None or not (glo < 0 < ghi):
        return None
    h = lambda d: slip_min_G2(xi, d, K, mpf(f))
    with mp.workdps(mp.dps):
        return bisect_root(h, lo, hi, glo, iters=120)


def compute_task(task):
    case, model, xi, d, K, rho, f = task
    inputs = (xi, d, K, rho, f)
    t0 = time.time()
    prim = run_model(model, inputs, 'ts', PRIMARY_DPS)
    chk = run_model(model, inputs, 'gl', CHECK_DPS)
    # sensitivity to one ulp in alpha
    pert = run_model(model, inputs, 'ts', 30, alpha_scale=ULP)
    rows = []
    for i, p in enumerate(prim):
        c = chk[i] if i < len(chk) else None
        q = pert[i] if i < len(pert) else None
        with mp.workdps(PRIMARY_DPS):
            th0 = mpf(d) - alpha_of(xi)
        row = dict(case=case, model=model, xi=R(xi), delta_rad=R(d), K=R(K), theta0_rad=S(th0),
                   rho=R(rho), f=R(f), v=S(p['v']), final_velocity=S(p['final_velocity']),
                   regime=p['regime'], extra=S(p['extra']), extra_name=p['extra_name'] if p['extra'] is not None else '',
                   note=p['note'],
                   fixed_point_index=str(p['fixed_point_index']) if 'fixed_point_index' in p else '',
                   slope=S(p.get('slope')) if 'slope' in p else '',
                   stable=p.get('stable', ''),
                   from_L=('true' if p.get('attractor') else 'false') if 'attractor' in p else '')
        with mp.workdps(PRIMARY_DPS):
            if p['v'] is not None and c is not None and c['v'] is not None:
                rd = abs(mpf(c['v']) - p['v']) / abs(p['v'])
                row['v_check'] = S(c['v'])
                row['rel_diff'] = mpmath.nstr(rd, 3)
                fvd = abs(mpf(c['final_velocity']) - p['final_velocity']) / abs(p['final_velocity'])
                row['fv_rel_diff'] = mpmath.nstr(fvd, 3)
            else:
                row['v_check'] = ''
                row['rel_diff'] = ''
                row['fv_rel_diff'] = ''
                if c is not None and c['regime'] != p['regime']:
                    row['note'] += ' ; CHECK REGIME DIFFERS: %s' % c['regime']
            if p['v'] is not None and q is not None and q.get('v') is not None:
                row['sens_alpha_ulp'] = mpmath.nstr(abs(mpf(q['v']) - p['v']) / abs(p['v']), 3)
            else:
                row['sens_alpha_ulp'] = ''
        if c is not None and c['regime'] != p['regime']:
            row['note'] += ' ; check method regime: %s' % c['regime']
        rows.append(row)
    return rows, time.time() - t0


FORWARD_COLS = ['case', 'model', 'xi', 'delta_rad', 'K', 'rho', 'f', 'v', 'final_velocity', 'regime',
                'extra', 'note', 'extra_name', 'fixed_point_index', 'slope', 'stable', 'from_L',
                'v_check', 'rel_diff', 'fv_rel_diff', 'sens_alpha_ulp', 'theta0_rad']


# ----------------------------------------------------------------------------
# bistable map table
# ----------------------------------------------------------------------------

BISTABLE = (10.0, math.radians(5.767), 0.9842, 1.0, 0.2)


def bistable_map_rows():
    xi, d, K, rho, f = BISTABLE
    rows = []
    with mp.workdps(PRIMARY_DPS):
        sc = Scene(xi, d, K, rho, f)
        P = ss_params(sc, MpNS)
        n = 2000
        for i in range(1, n + 1):
            x = round(i * 0.001, 3)          # exact-ish doubles 0.001 ... 2.000
            y, br, tg, ok = ss_map(mpf(x), P, MpNS)
            if not ok:
                rows.append(dict(x=R(x), H='', H_minus_x='', branch='stops', theta_G_deg='',
                                 H2=S(y)))
                continue
            h = sqrt(y) if y > 0 else None
            nmin = min(mpmath.cos(sc.th0) - (sc.K * x) ** 2, mpmath.cos(sc.thf) - y)
            rows.append(dict(x=R(x), N_min=S(nmin), H=S(h) if h is not None else '',
                             H_minus_x=S(h - mpf(x)) if h is not None else '',
                             branch=br, theta_G_deg=S(tg * 180 / mpmath.pi) if tg is not None else '',
                             H2=S(y)))
    return rows


# ----------------------------------------------------------------------------
# derived refs
# ----------------------------------------------------------------------------

def derived_rows(log):
    rows = []

    def add(q, value, check=None, xi=None, K=None, rho=None, f=None, delta=None, note=''):
        r = dict(quantity=q, xi=R(xi), K=R(K), rho=R(rho), f=R(f), delta_rad=R(delta),
                 value=S(value), value_check=S(check) if check is not None else '',
                 diff=mpmath.nstr(abs(value - check), 3) if check is not None else '', note=note)
        rows.append(r)

    mp.dps = PRIMARY_DPS
    for xi in XI:
        a = alpha_of(xi)
        for kname in ('Kfit', 'Kcos', 'Kimpact', 'K0.9'):
            K = 0.9 if kname == 'K0.9' else K_law_double(kname, xi)
            Km = mpf(K)
            dm = delta_m_eq32(a, Km)
            dmr = delta_m_root(a, Km, mpf(0.4))
            add('delta_m_rad', dm, dmr, xi, K, None, note='eq 32 | check: bisection of top velocity=0 (rho-independent); K=%s' % kname)
            add('delta_m_deg', dm * 180 / mpmath.pi, dmr * 180 / mpmath.pi, xi, K, None, note='K=%s' % kname)
            mu = mu_eq79(a, Km)
            add('mu_eq79', mu, mpmath.tan(dm), xi, K, None, note='check: tan(delta_m) (eq 78); K=%s' % kname)
            for rho in RHO:
                dd = delta_d_eq31(a, Km, mpf(rho))
                ddr = delta_d_root(a, Km, mpf(rho))
                add('delta_d_rad', dd, ddr, xi, K, rho, note='eq 31 | check: bisection of N(Thetaf)=0; K=%s' % kname)
    # Theta_G at stick steady states, rho=0.4, f=0.1, fitted K
    rho, f = mpf(0.4), mpf(0.1)
    tgs = []
    for xi in (0.8, 1.0, 1.6, 2.0):
        K = K_law_double('Kfit', xi)
        for fr, d in zip(FRACS, grid_deltas(xi, K, 0.4)):
            sc = Scene(xi, d, K, 0.4, 0.1)
            L2 = 2 * sc.B * mpmath.sin(sc.delta) * mpmath.sin(sc.alpha) / (1 - sc.K ** 2)
            w02 = sc.K ** 2 * L2
            tg = theta_G(sc.th0, w02, rho, f)
            tgp = theta_G_eq36_printed(sc.th0, w02, rho, f)
            tgs.append(tg * 180 / mpmath.pi)
            add('theta_G_deg_stick_steady', tg * 180 / mpmath.pi, tgp * 180 / mpmath.pi, xi, K, 0.4, 0.1, d,
                note='rationalised eq 36 | check: eq 36 as printed; delta frac %s of [delta_m;delta_d]; Theta0=%s deg'
                % (fr, mpmath.nstr(sc.th0 * 180 / mpmath.pi, 6)))
    add('theta_G_deg_min_over_above', min(tgs), None, note='expected: 14.7')
    add('theta_G_deg_max_over_above', max(tgs), None, note='expected: 16.8')
    # xi_c: delta_m(xi) = delta_d(xi), fitted law (K not rounded: function of xi), rho = 0.4
    def h(xi):
        a = alpha_of(xi)
        K = K_fitted(a)
        return delta_d_eq31(a, K, mpf(0.4)) - delta_m_eq32(a, K)

    def h2(xi):
        a = alpha_of(xi)
        K = K_fitted(a)
        return delta_d_root(a, K, mpf(0.4)) - delta_m_root(a, K, mpf(0.4))
    xc = mpmath.findroot(h, mpf('0.62'))
    xc2 = bisect_root(h2, mpf('0.5'), mpf('0.8'))
    add('xi_c', xc, xc2, rho=0.4, note='smallest xi with regime B; fitted law K(alpha) in full precision (not rounded); '
        'findroot(eq31-eq32) | check: bisection of the root-found limits')
    add('delta_at_xi_c_deg', delta_m_eq32(alpha_of(xc), K_fitted(alpha_of(xc))) * 180 / mpmath.pi, None, rho=0.4)
    # section 7 table
    K1 = K_law_double('Kfit', 1.0)
    dm1 = delta_m_eq32(alpha_of(1.0), mpf(K1))
    add('S7_delta_m_deg_xi1_Kfit', dm1 * 180 / mpmath.pi, delta_m_root(alpha_of(1.0), mpf(K1), mpf(0.4)) * 180 / mpmath.pi,
        1.0, K1, note='expected: 7.469')
    for xi, deg, paper in ((2.0, 5.73, '1.061'), (1.0, 11.53, '1.159')):
        K = K_law_double('Kfit', xi)
        d = math.radians(deg)
        vs = run_model('stick', (xi, d, K, 0.4, None), 'ts', PRIMARY_DPS)[0]
        vss = run_model('stickslip', (xi, d, K, 0.4, 0.1), 'ts', PRIMARY_DPS)
        vs2 = run_model('stick', (xi, d, K, 0.4, None), 'gl', CHECK_DPS)[0]
        vss2 = run_model('stickslip', (xi, d, K, 0.4, 0.1), 'gl', CHECK_DPS)
        att = [r for r in vss if r.get('attractor')]
        att2 = [r for r in vss2 if r.get('attractor')]
        ratio = att[0]['v'] / vs['v']
        ratio2 = mpf(att2[0]['v']) / mpf(vs2['v'])
        add('S7_v_stickslip_over_v_stick', ratio, ratio2, xi, K, 0.4, 0.1, d,
            note='expected: %s; %d fixed point(s); theta_G at fixed point %s deg' % (
                paper, len(vss), mpmath.nstr(att[0]['extra'], 6)))
    # eq 79 vs eq 76 (Jan's fitted mu = 0.0025 e^{7.46 sin alpha})
    for xi in (0.8, 1.0, 1.6, 2.0):
        a = alpha_of(xi)
        K = K_law_double('Kfit', xi)
        mu79 = mu_eq79(a, mpf(K))
        mu76 = mpf('0.0025') * mpmath.exp(mpf('7.46') * mpmath.sin(a))
        add('S7_mu79_over_mu76_minus_1', mu79 / mu76 - 1, None, xi, K, note='expected: +18..+26 %%; mu79=%s mu76=%s' % (
            mpmath.nstr(mu79, 8), mpmath.nstr(mu76, 8)))
        add('tan_delta_m_Kfit', mpmath.tan(delta_m_eq32(a, mpf(K))), mu79, xi, K,
            note='expected: 0.1905 0.1311 0.0555 0.0355 for xi = 0.8 1 1.6 2 | check: eq 79')
    return rows


# ----------------------------------------------------------------------------
# elliptic refs
# ----------------------------------------------------------------------------

def rf_quad(x, y, z):
    """R_F by quadrature, t = e^s: 1/2 int e^s ds / sqrt((e^s+x)(e^s+y)(e^s+z))."""
    # scale invariance R_F(lx,ly,lz) = R_F(x,y,z)/sqrt(l): quad's tolerance is absolute
    x, y, z = mpf(x), mpf(y), mpf(z)
    lam = max(x, y, z)
    x, y, z = x / lam, y / lam, z / lam
    f = lambda s: mpmath.exp(s) / sqrt((mpmath.exp(s) + x) * (mpmath.exp(s) + y) * (mpmath.exp(s) + z)) / 2
    logs = [mpmath.log(v) for v in (x, y, z) if v > 0]
    pts = set()
    for L in logs:
        for k in range(-8, 9, 4):
            pts.add(L + k)
    pts = sorted(pts)
    filled = [pts[0]]
    for p in pts[1:]:
        while p - filled[-1] > 10:
            filled.append(filled[-1] + 8)
        filled.append(p)
    pts = [-mpmath.inf] + filled + [mpmath.inf]
    return mpmath.quad(f, pts, maxdegree=12) / sqrt(lam)


def F_quad(phi, m):
    """int_0^phi dtheta / sqrt(1 - m sin^2 theta) by quadrature, sinh map at pi/2."""
    phi, m = mpf(phi), mpf(m)
    if phi == 0:
        return mpf(0)
    one_m = 1 - m   # exact at this precision (m is a double)
    if one_m == 0:
        return mpmath.asinh(mpmath.tan(phi))   # F(phi|1) = gd^-1(phi), closed form
    if m <= 0 or one_m > mpf('0.25') or phi < 1:
        # theta = phi t, t in [0,1] (scale free, also for tiny phi)
        f = lambda t: 1 / sqrt(1 - m * mpmath.sin(phi * t) ** 2)
        return phi * mpmath.quad(f, [0, 1], maxdegree=12)
    # theta = pi/2 - s; 1 - m sin^2 = cos^2 theta + (1-m) sin^2 theta = sin^2 s + (1-m) cos^2 s
    w = sqrt(one_m) if one_m > 0 else mpf(10) ** (-mp.dps)
    hp = mpmath.pi / 2
    s_lo = hp - phi
    s_hi = hp
    g = lambda s: 1 / sqrt(mpmath.sin(s) ** 2 + one_m * mpmath.cos(s) ** 2)
    # s = w sinh(u)
    u_lo = mpmath.asinh(s_lo / w)
    u_hi = mpmath.asinh(s_hi / w)
    f = lambda u: g(w * mpmath.sinh(u)) * w * mpmath.cosh(u)
    n = max(1, int(mpmath.ceil((u_hi - u_lo) / 2)))
    pts = [u_lo + (u_hi - u_lo) * k / n for k in range(n + 1)]
    return mpmath.quad(f, pts, maxdegree=12)


def elliptic_rows(log):
    rows_rf, rows_f = [], []
    tiny = [5e-324, 1e-300, 1e-200, 1e-100, 1e-30, 1e-16, 1e-8]
    trip = [(0.0, 1.0, 2.0), (2.0, 3.0, 4.0), (1.0, 1.0, 1.0), (0.5, 1.0, 1.0), (1.0, 2.0, 2.0),
            (1e-300, 1.0, 1.0), (0.0, 1.0, 1.0), (0.0, 0.0, 1.0), (1.0, 1.0 + 2 ** -52, 1.0 - 2 ** -53),
            (1e-200, 1.0, 1e200), (1e300, 1e300, 1e300), (1e-300, 1e-300, 1e-300), (3.0, 1e-10, 7.0),
            (0.25, 0.5, 1e10), (1e-20, 1e-20, 1.0), (0.0, 1e-300, 1.0), (0.0, 5e-324, 1.0),
            (123.456, 0.001, 7.89)]
    for t in tiny:
        trip.append((0.0, t, 1.0))
        trip.append((t, t, 1.0))
        trip.append((t, 1.0, 2.0))
    # forms arising from F: (cos^2 phi, 1 - m sin^2 phi, 1) with doubles
    for k in range(1, 17):
        m = 1.0 - 10.0 ** (-k)
        for j in (4, 8, 12):
            phi = math.pi / 2 - 10.0 ** (-j)
            trip.append((math.cos(phi) ** 2, 1.0 - m * math.sin(phi) ** 2, 1.0))
    seen = set()
    mp.dps = PRIMARY_DPS
    for (x, y, z) in trip:
        if (x, y, z) in seen:
            continue
        seen.add((x, y, z))
        with mp.workdps(ELLIPTIC_DPS):
            v = mpmath.elliprf(mpf(x), mpf(y), mpf(z))
        with mp.workdps(CHECK_DPS):
            if mpmath.isinf(v):
                q = mpmath.inf
            else:
                q = rf_quad(x, y, z)
        rd = '' if mpmath.isinf(v) else mpmath.nstr(abs(q - v) / abs(v), 3)
        rows_rf.append(dict(kind='rf', x=R(x), y=R(y), z=R(z), value='inf' if mpmath.isinf(v) else S(v),
                            check=('inf' if mpmath.isinf(q) else S(q)), rel_diff=rd,
                            note='R_F(0,0,z) diverges' if mpmath.isinf(v) else ''))
    phis = [0.0, 1e-300, 1e-8, 0.1, 0.5, math.pi / 4, 1.0, 1.5, math.pi / 2]
    phis += [math.pi / 2 - 10.0 ** (-j) for j in range(1, 17)]
    ms = [0.0, 1e-16, 0.1, 0.5, 0.9, -1.0, -10.0, 1.0]
    ms += [1.0 - 10.0 ** (-k) for k in range(1, 17)]
    phis = sorted(set(phis))
    for phi in phis:
        for m in ms:
            if m == 1.0 and phi >= math.pi / 2:
                # F(pi/2 double | 1) = atanh(sin(phi)) is finite but huge; keep it
                pass
            with mp.workdps(ELLIPTIC_DPS):
                v = mpmath.ellipf(mpf(phi), mpf(m))
            with mp.workdps(CHECK_DPS):
                q = F_quad(phi, m)
            rd = mpmath.nstr(abs(q - v) / abs(v), 3) if v != 0 else mpmath.nstr(abs(q - v), 3)
            rows_f.append(dict(kind='ellipf', phi=R(phi), m=R(m), value=S(v), check=S(q), rel_diff=rd,
                               note='phi=double(pi/2)-1e-? ' if 1.5 < phi < math.pi / 2 else ''))
    return rows_rf, rows_f


# ----------------------------------------------------------------------------
# main
# ----------------------------------------------------------------------------

def ode_spot_check(log):
    """Third, independent route for a few rows: integrate the equations of
    motion themselves (eq 9 rolling, eq 37 slipping) with mpmath.odefun
    (Taylor series) from Theta0 with the reference initial velocity K*x, and
    compare the time and the final velocity with forward_refs.csv."""
    rows = list(csv.DictReader(open(os.path.join(HERE, 'forward_refs.csv'))))
    picks = [('Fig7 xi=2.0 delta=5.73deg', 'stickslip'), ('Fig7 xi=1.0 delta=11.53deg', 'stickslip'),
             ('f=1e-06', 'slip'), ('Theta0=0 (delta=double(alpha))', 'slip'),
             ('rolling check (v=0.39120827...)', 'stick'), ('slip from start (Theta_G<=Theta0)', 'stickslip')]
    worst = mpf(0)
    with mp.workdps(20):
        for case, model in picks:
            r = [q for q in rows if q['case'] == case and q['model'] == model and q['regime'] == 'B'][0]
            a = alpha_of(float(r['xi']))
            d, K = mpf(float(r['delta_rad'])), mpf(float(r['K']))
            t0, tf = d - a, d + a
            x = mpf(r['final_velocity'])
            f = mpf(float(r['f'])) if r['f'] else None
            roll = (lambda B: lambda th, y: [B * mpmath.sin(th), 1 / sqrt(y[0])])
            slipf = (lambda f: lambda th, y: [2 * (mpmath.sin(th) - f * (mpmath.cos(th) - y[0])), 1 / sqrt(y[0])])
            y = [(K * x) ** 2, mpf(0)]
            th = t0
            if model in ('stick', 'stickslip'):
                B = 2 / (1 + mpf(float(r['rho'])))
                end = tf
                if model == 'stickslip' and r['extra']:
                    end = min(tf, max(t0, mpf(r['extra']) * mpmath.pi / 180))
                if end > t0:
                    if t0 < 0 < end:    # integrate through the top in two legs
                        y = mpmath.odefun(roll(B), th, y)(mpf(0))
                        th = mpf(0)
                    y = mpmath.odefun(roll(B), th, y)(end)
                    th = end
            if th < tf:
                y = mpmath.odefun(slipf(f), th, y)(tf)
            v = 2 * mpmath.sin(a) / y[1]
            dv = abs(v - mpf(r['v'])) / mpf(r['v'])
            dx = abs(sqrt(y[0]) - x) / x
            worst = max(worst, dv, dx)
            log('  ODE check %-36s %-9s v=%s (table %s) rel %s; final velocity rel %s' % (
                case, model, mpmath.nstr(v, 18), r['v'][:20], mpmath.nstr(dv, 3), mpmath.nstr(dx, 3)))
    log('ODE spot check: worst relative difference %s (odefun at dps 20)' % mpmath.nstr(worst, 3))


def write_csv(path, cols, rows):
    with open(path, 'w', newline='') as fh:
        w = csv.DictWriter(fh, fieldnames=cols, lineterminator='\n')
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, '') for k in cols})


def _init_worker():
    mp.dps = PRIMARY_DPS


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--jobs', type=int, default=os.cpu_count() or 1)
    ap.add_argument('--only', default='', help='comma list: forward,bistable,derived,elliptic,ode')
    ap.add_argument('--limit', type=int, default=0, help='debug: first N forward tasks only')
    args = ap.parse_args()
    only = set(args.only.split(',')) if args.only else {'forward', 'bistable', 'derived', 'elliptic', 'ode'}
    mp.dps = PRIMARY_DPS
    t_start = time.time()
    log = lambda *a: print(*a, flush=True)

    if 'elliptic' in only:
        t = time.time()
        rf, ef = elliptic_rows(log)
        cols = ['kind', 'x', 'y', 'z', 'phi', 'm', 'value', 'check', 'rel_diff', 'note']
        write_csv(os.path.join(HERE, 'elliptic_refs.csv'), cols, rf + ef)
        mx_rf = max(mpf(r['rel_diff']) for r in rf if r['rel_diff'])
        mx_f = max(mpf(r['rel_diff']) for r in ef if r['rel_diff'])
        log('elliptic: %d rf rows (max rel diff vs quadrature %s), %d ellipf rows (max %s), %.1f s'
            % (len(rf), mpmath.nstr(mx_rf, 3), len(ef), mpmath.nstr(mx_f, 3), time.time() - t))

    if 'derived' in only:
        t = time.time()
        rows = derived_rows(log)
        cols = ['quantity', 'xi', 'K', 'rho', 'f', 'delta_rad', 'value', 'value_check', 'diff', 'note']
        write_csv(os.path.join(HERE, 'derived_refs.csv'), cols, rows)
        for r in rows:
            if r['quantity'].startswith(('S7', 'xi_c', 'theta_G_deg_m', 'delta_at')):
                log('  %-32s xi=%-5s %s (check %s) %s' % (r['quantity'], r['xi'], r['value'], r['value_check'], r['note']))
        mx = max(mpf(r['diff']) for r in rows if r['diff'])
        log('derived: %d rows, max |value - check| %s, %.1f s' % (len(rows), mpmath.nstr(mx, 3), time.time() - t))

    if 'bistable' in only:
        t = time.time()
        rows = bistable_map_rows()
        write_csv(os.path.join(HERE, 'stickslip_map_bistable.csv'),
                  ['x', 'H', 'H_minus_x', 'branch', 'theta_G_deg', 'H2', 'N_min'], rows)
        log('bistable map: %d rows, %.1f s' % (len(rows), time.time() - t))

    if 'forward' in only:
        t = time.time()
        tasks = build_hard_tasks()
        nhard = len(tasks)
        tasks += build_grid_tasks()
        if args.limit:
            tasks = tasks[:args.limit]
        log('forward: %d tasks (%d hard)' % (len(tasks), nhard))
        if args.jobs > 1:
            import multiprocessing as mproc
            with mproc.Pool(args.jobs, initializer=_init_worker) as pool:
                results = pool.map(compute_task, tasks, chunksize=1)
        else:
            results = [compute_task(tk) for tk in tasks]
        rows = []
        slow = 0.0
        for i, (rs, dt) in enumerate(results):
            slow = max(slow, dt)
            rows.extend(rs)
            if i < nhard:
                for r in rs:
                    log('  HARD %-40s %-12s xi=%-5s regime=%s v=%s check=%s rel=%s sens=%s %s' % (
                        r['case'], r['model'], r['xi'], r['regime'], r['v'], r['v_check'], r['rel_diff'],
                        r['sens_alpha_ulp'], r['note'][:90]))
        write_csv(os.path.join(HERE, 'forward_refs.csv'), FORWARD_COLS, rows)
        # summary per model
        for model in ('stick', 'stick-approx', 'slip', 'slip-approx', 'stickslip'):
            rr = [r for r in rows if r['model'] == model]
            rd = [mpf(r['rel_diff']) for r in rr if r['rel_diff']]
            fd = [mpf(r['fv_rel_diff']) for r in rr if r['fv_rel_diff']]
            regs = {}
            for r in rr:
                regs[r['regime']] = regs.get(r['regime'], 0) + 1
            log('  %-12s rows=%4d regimes=%s max rel diff v: %s  final velocity: %s' % (
                model, len(rr), regs, mpmath.nstr(max(rd), 3) if rd else '-', mpmath.nstr(max(fd), 3) if fd else '-'))
        log('forward: %d rows, slowest task %.1f s, %.1f s' % (len(rows), slow, time.time() - t))
    if 'ode' in only:
        ode_spot_check(log)
    log('total %.1f s' % (time.time() - t_start))


if __name__ == '__main__':
    main()
