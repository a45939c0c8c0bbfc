#!/usr/bin/env python3
"""The scipy peer of `fitbead k` for the speed comparison (docs/PERFORMANCE.md): per measured
row the same work as `fitbead k --model stick|stickslip`, by scipy's brentq, ellipkinc and quad
(rolling time: corrected eqs 12-15 as docs/PHYSICS.md corrects them; slip phase of stick/slip: eqs 64-68).

Per row, as src/fit/k/ does it:
- the row's xi, delta_deg, v, sigma_v, rho and f (an empty rho or f cell takes --rho 0.4 /
  --f 0.1, as `fitbead k` does; dimensional rows, v_m_s, R_m, g, sigma_v_m_s, are made
  dimensionless with sqrt(g R_m (1 + xi)));
- the bracket of K (src/fit/k/bracket.rs): the analytic candidate (crawl over the top, K = 0,
  lift-off of the steady final speed, eq 30a), each end checked against the forward model and,
  where the model is not steady there, moved to the model's own boundary by bisection on its
  status (to 1e-15 in K); for stick/slip the probe above lift-off for a stable branch that
  lives on to the saddle-node of the final-velocity map;
- the status: `invalid` (no bracket), `below-range` (v below the slowest steady motion, 0 at a
  crawl end), `above-range`, or `ok`; K by brentq (xtol 1e-15) on v(K) = v; near a crawl end
  where no K distinguishable from K_min gives v, the first steady K above K_min; a root where
  v(K) jumps over v is `invalid`;
- K_lo and K_hi at v -/+ sigma_v (rows with a sigma_v), clamped to the bracket's ends as
  `fitbead k` writes them (also on rows without a K, except above-range rows whose lower end is
  the crawl and upper end lift-off, where `fitbead k` takes its launch-speed path and writes
  none);
- dv/dK at K by the second-order three-point difference of src/fit/k/search.rs (steps uniform in
  ln(K - K_min), h = 1e-5).
The stick/slip forward model starts, like fitbead's, from the rolling steady state (which is
the answer when rolling needs no slip, Theta_G >= Theta_f) and looks for the fixed point of the
final-velocity map on the side the map moves to, so that it finds the stable fixed point the
bead settles on.

Usage: peer_k.py stick|stickslip INPUT.csv [ROWS] > out.csv
Reads the first ROWS rows (default all); writes, under `fitbead k`'s column names,
series,xi,delta_deg,v,sigma_v,model,K,K_lo,K_hi,dv_dK,regime,status,K_min,K_max,lower_limit,
upper_limit and, on stderr, the seconds per row of the loop (reading and writing included).

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
EPS = 2.220446049250313e-16
MIN_POSITIVE = 2.2250738585072014e-308


class NotSteady(Exception):
    """Why a forward evaluation has no steady state: "stops", "lift-off" or "invalid"."""


class Invalid(Exception):
    """No K for this row (status `invalid`)."""


def roll_time(b, ta, tb, wa2):
    """Rolling time from ta to tb (ta < tb) launched at speed^2 wa2 (corrected eqs 12-15):
    the integral of d(theta) / sqrt(a - b cos(theta)), a = b cos(ta) + wa2."""
    a = b * math.cos(ta) + wa2
    if a > b:
        m = 2.0 * b / (a + b)
        g = 2.0 / math.sqrt(a + b)

        def big_f(t):
            s2 = (a + b) * math.sin(0.5 * t) ** 2 / (a - b * math.cos(t))
            om = math.asin(math.sqrt(min(max(s2, 0.0), 1.0)))
            return math.copysign(1.0, t) * ellipkinc(om, m)

        return g * (big_f(tb) - big_f(ta))
    if ta < 0:
        raise NotSteady("stops")
    # a <= b, contact past the top: with t = cos(theta/2)/k, k^2 = (a + b)/(2b), the integral
    # is (2/sqrt(2b)) [F(asin t(ta) | k^2) - F(asin t(tb) | k^2)].
    m = (a + b) / (2.0 * b)
    if not m > 0:
        raise NotSteady("stops")
    k = math.sqrt(m)

    def big_g(t):
        return ellipkinc(math.asin(min(math.cos(0.5 * t) / k, 1.0)), m)

    return 2.0 / math.sqrt(2.0 * b) * (big_g(ta) - big_g(tb))


class Scene:
    def __init__(self, xi, delta_deg, rho, f):
        self.alpha = math.asin(1.0 / (1.0 + xi))
        self.sin_alpha = math.sin(self.alpha)
        self.delta = math.radians(delta_deg)
        self.t0 = self.delta - self.alpha
        self.tf = self.delta + self.alpha
        self.cf = math.cos(self.tf)
        self.rho = rho
        self.f = f
        self.b = 2.0 / (1.0 + rho)
        self.drop = 2.0 * self.b * math.sin(self.delta) * math.sin(self.alpha)
        self.crawl = 2.0 * self.b * math.sin(0.5 * self.t0) ** 2 if self.t0 < 0 else 0.0
        fs = 1.0 + 4.0 * f * f
        self.sb = -6.0 * f / fs
        self.sc = (4.0 * f * f - 2.0) / fs


def theta_g(s, w0sq):
    """Theta_G (eq 36) of a rolling phase launched at Theta0 with speed^2 w0sq; None when the
    normal force is negative on the whole bead."""
    th = 2.0 * math.cos(s.t0) + (1.0 + s.rho) * w0sq
    p = 3.0 + s.rho
    disc = s.rho * s.rho + s.f * s.f * (p - th) * (p + th)
    if disc < 0 or p - th < 0:
        return None
    den = s.rho + math.sqrt(disc)
    if den == 0:
        return None
    return 2.0 * math.atan(s.f * (p - th) / den)


# --- stick -----------------------------------------------------------------------------------


def stick_steady(s, k):
    """(v, final speed) of the rolling steady state at K = k."""
    if not (0.0 < k < 1.0):
        raise NotSteady("invalid")
    l2 = s.drop / (1.0 - k * k)
    if s.cf - l2 < 0:
        raise NotSteady("lift-off")
    tau = roll_time(s.b, s.t0, s.tf, k * k * l2)
    if not (math.isfinite(tau) and tau > 0):
        raise NotSteady("stops")
    return 2.0 * s.sin_alpha / tau, math.sqrt(l2)


def stick_candidate(s):
    if not s.cf > s.drop:
        return None
    hi = math.sqrt(1.0 - s.drop / s.cf)
    if s.t0 < 0:
        return -math.sin(0.5 * s.t0) / math.sin(0.5 * s.tf), hi, "crawl-over-top"
    return 0.0, hi, "K=0"


# --- stick/slip ------------------------------------------------------------------------------


def slip_speed_sq(s, ts, us):
    a = (us - s.sb * math.sin(ts) - s.sc * math.cos(ts)) * math.exp(-2.0 * s.f * ts)
    return lambda t: a * math.exp(2.0 * s.f * t) + s.sb * math.sin(t) + s.sc * math.cos(t)


def contact(s, w0sq):
    """One contact launched at speed^2 w0sq: (final speed^2, start of slip, its speed^2)."""
    tg = theta_g(s, w0sq)
    if tg is None:
        raise NotSteady("lift-off")
    if s.t0 < 0 and tg > 0 and w0sq - s.crawl <= 0:
        raise NotSteady("stops")
    if tg >= s.tf:
        return w0sq + s.drop, None, None
    if tg <= s.t0:
        ts, us = s.t0, w0sq
    else:
        ts, us = tg, w0sq + s.b * (math.cos(s.t0) - math.cos(tg))
    u = slip_speed_sq(s, ts, us)
    # Strong friction can stop the bead before Theta_f: the slip speed^2 has its minimum
    # where its derivative vanishes.
    if 2.0 * s.f * (u(ts) - s.sb * math.sin(ts) - s.sc * math.cos(ts)) \
            + s.sb * math.cos(ts) - s.sc * math.sin(ts) < 0:
        d = lambda t: (2.0 * s.f * (u(t) - s.sb * math.sin(t) - s.sc * math.cos(t))
                       + s.sb * math.cos(t) - s.sc * math.sin(t))
        if d(s.tf) > 0:
            tm = brentq(d, ts, s.tf, xtol=1e-15)
            if not u(tm) > 0:
                raise NotSteady("stops")
    xf2 = u(s.tf)
    if not xf2 > 0:
        raise NotSteady("stops")
    if s.cf - xf2 < 0:
        raise NotSteady("lift-off")
    return xf2, ts, us


def phi(s, w0):
    return math.sqrt(contact(s, w0 * w0)[0])


def excess(s, k, x):
    """H(x) - x, a stop counted as slower than any fixed point, a lift-off as faster."""
    try:
        return math.sqrt(contact(s, k * k * x * x)[0]) - x
    except NotSteady as e:
        return -max(x, 1e-300) if str(e) == "stops" else math.inf


def fixed_point(s, k, x0):
    """The fixed point of the final-velocity map reached from x0: steps from x0 the way the
    map moves (doubling) to a sign change of H(x) - x, then brentq; a root where the map jumps
    is refused."""
    x_hi = math.sqrt(max(s.cf, 0.0))
    g0 = excess(s, k, x0)
    if g0 == 0:
        return x0
    if not math.isfinite(g0):
        raise NotSteady("lift-off")
    up = g0 > 0
    x, gx, step = x0, g0, g0
    for _ in range(64):
        xn = x + step
        if up:
            xn = min(xn, x_hi * (1.0 - 1e-12))
        else:
            xn = max(xn, 1e-300)
        gn = excess(s, k, xn)
        if not up and gn == -max(xn, 1e-300):
            # The step landed where the bead stops: the fixed point, if any, lies between x
            # and the boundary of that region (bisection to 1e-15, as fitbead's
            # failure_boundary); look at the map just inside it.
            ok, bad = x, xn
            for _ in range(80):
                mid = 0.5 * (ok + bad)
                if abs(ok - bad) <= 1e-15 * ok or mid in (ok, bad):
                    break
                if excess(s, k, mid) == -max(mid, 1e-300):
                    bad = mid
                else:
                    ok = mid
            g_ok = excess(s, k, ok)
            if g_ok > 0 or g_ok == 0:
                xn, gn = ok, g_ok
        if (gn > 0) != up or gn == 0:
            a, b = (x, xn) if x < xn else (xn, x)
            fa, fb = (gx, gn) if x < xn else (gn, gx)
            fa, fb = max(min(fa, 1e300), -1e300), max(min(fb, 1e300), -1e300)
            r = brentq(lambda t: max(min(excess(s, k, t), 1e300), -1e300), a, b,
                       xtol=1e-300, rtol=4 * EPS)
            if abs(excess(s, k, r)) > 1e-9 * max(r, 1e-3):
                raise NotSteady("no fixed point")
            return r
        if xn == x:
            break
        x, gx, step = xn, gn, 2.0 * step
    raise NotSteady("lift-off" if up else "stops")


def stickslip_steady(s, k):
    """(v, final speed) of the stick/slip steady state at K = k."""
    if not (0.0 < k < 1.0):
        raise NotSteady("invalid")
    x_hi = math.sqrt(max(s.cf, 0.0))
    l2 = s.drop / (1.0 - k * k)
    # The rolling steady state exists when it neither lifts off nor stops before the top.
    if s.cf - l2 >= 0 and (s.t0 >= 0 or k * k * l2 - s.crawl > 0):
        tg = theta_g(s, k * k * l2)
        if tg is not None and tg >= s.tf:
            return stick_steady(s, k)
        x0 = math.sqrt(l2)
    else:
        x0 = x_hi * (1.0 - 1e-9)
    x = fixed_point(s, k, min(x0, x_hi))
    w0sq = k * k * x * x
    _, ts, us = contact(s, w0sq)
    if ts is None:
        tau = roll_time(s.b, s.t0, s.tf, w0sq)
    else:
        t1 = roll_time(s.b, s.t0, ts, w0sq) if ts > s.t0 else 0.0
        u = slip_speed_sq(s, ts, us)
        t2 = quad(lambda t: 1.0 / math.sqrt(u(t)), ts, s.tf, epsabs=0.0, epsrel=1e-13)[0]
        tau = t1 + t2
    if not (math.isfinite(tau) and tau > 0):
        raise NotSteady("stops")
    return 2.0 * s.sin_alpha / tau, x


def stickslip_candidate(s):
    if s.t0 < 0:
        wc = math.sqrt(2.0 * s.b) * abs(math.sin(0.5 * s.t0))
        tg = theta_g(s, wc * wc)
        try:
            if not (tg is not None and tg > 0):
                raise NotSteady("slip before the top")
            h = 1e-13
            x1, x2 = phi(s, wc * (1.0 + h)), phi(s, wc * (1.0 + 2.0 * h))
            lo, kind = wc / (2.0 * x1 - x2), "crawl-over-top"
        except NotSteady:
            lo, kind = 0.0, "model-limit"
    else:
        lo, kind = 0.0, "K=0"
    xd = math.sqrt(max(s.cf, 0.0))

    def q(w0):
        try:
            return phi(s, w0) - xd
        except NotSteady as e:
            return -xd if str(e) == "stops" else xd

    w_lo = MIN_POSITIVE
    if not q(w_lo) < 0:
        return None
    w_hi = xd
    q_hi = q(w_hi)
    n = 0
    while q_hi < 0 and n < 60:
        w_hi *= 2.0
        q_hi = q(w_hi)
        n += 1
    if not q_hi > 0:
        return None
    w = brentq(q, w_lo, w_hi, xtol=1e-300, rtol=4 * EPS)
    return lo, w / xd, kind


# --- the K inversion (src/fit/k/) ------------------------------------------------------------


MODELS = {
    "stick": (stick_steady, stick_candidate),
    "stickslip": (stickslip_steady, stickslip_candidate),
}


def status_boundary(steady, good, bad):
    """Bisection on the model's status: the steady K closest to bad, and its v."""
    best = None
    for _ in range(80):
        mid = 0.5 * (good + bad)
        if abs(good - bad) <= 1e-15 + 2.0 * EPS * abs(good) or mid in (good, bad):
            break
        try:
            best = steady(mid)[0]
            good = mid
        except NotSteady:
            bad = mid
    if best is None:
        try:
            best = steady(good)[0]
        except NotSteady:
            best = 0.0
    return good, best


def bracket(model, s):
    """(lo, hi, v_lo, v_hi, lower, upper) of the K with a steady state; Invalid if none."""
    steady_of, candidate = MODELS[model]
    steady = lambda k: steady_of(s, k)
    c = candidate(s)
    if c is None:
        raise Invalid("lift-off for every K")
    lo, hi, lower = c
    if not lo < hi:
        raise Invalid("the crawl K already lifts off")
    tiny = (hi - lo) * 1e-9
    hi_in = hi * (1.0 - 4.0 * EPS)
    lo_test = MIN_POSITIVE if lo == 0 else lo + tiny

    def ok(k):
        try:
            return steady(k)
        except NotSteady:
            return None

    r_lo, r_hi = ok(lo_test), ok(hi_in)
    if r_lo is not None:
        good = lo_test
    elif r_hi is not None:
        good = hi_in
    else:
        good = next((lo + (hi - lo) * i / 32 for i in range(1, 32)
                     if ok(lo + (hi - lo) * i / 32) is not None), None)
        if good is None:
            raise Invalid("no steady K")
    upper = "lift-off"
    if r_hi is not None:
        k_hi, v_hi = hi_in, r_hi[0]
        if model == "stickslip":
            d = 1e-9 * (hi - lo)
            last_ok, bad = hi_in, None
            while hi_in + d < 1.0:
                if ok(hi_in + d) is not None:
                    last_ok = hi_in + d
                else:
                    bad = hi_in + d
                    break
                d *= 4.0
            if last_ok > hi_in:
                upper = "model-limit"
                k_hi, v_hi = status_boundary(steady, last_ok, 1.0 if bad is None else bad)
    else:
        upper = "model-limit"
        k_hi, v_hi = status_boundary(steady, good, hi)
    if r_lo is not None:
        if lower == "crawl-over-top":
            k_lo, v_lo = lo, 0.0
        elif lower == "K=0":
            k_lo, v_lo = 0.0, r_lo[0]
        else:
            r = ok(lo + (hi - lo) * 1e-13)
            k_lo, v_lo = lo, (0.0 if r is None else r[0])
    else:
        lower = "model-limit"
        k, v_lo = status_boundary(steady, good, min(lo_test, good))
        k_lo = k * (1.0 - 2.0 * EPS)
    return k_lo, k_hi, v_lo, v_hi, lower, upper


def solve(model, s, br, v):
    """(K, status) at v on the bracket br."""
    steady_of = MODELS[model][0]
    lo, hi, v_lo, v_hi, _, _ = br
    if not (v > 0 and math.isfinite(v)):
        return None, "invalid"
    if v < v_lo:
        return None, "below-range"
    if v > v_hi:
        return None, "above-range"

    def f(k):
        try:
            return steady_of(s, k)[0] - v
        except NotSteady as e:
            if str(e) == "lift-off":
                return math.inf
            return -math.inf if k < lo + 0.5 * (hi - lo) else math.inf

    # The first K above lo where the model is steady (lo itself is exclusive).
    d = 2.0 * max(lo * EPS, MIN_POSITIVE)
    k_a, f_a = None, None
    for _ in range(1100):
        k = lo + d
        fk = f(k)
        if math.isfinite(fk):
            k_a, f_a = k, fk
            break
        d *= 2.0
    if k_a is None:
        return None, "invalid"
    if f_a >= 0:
        return k_a, "ok"
    f_hi = steady_of(s, hi)[0] - v
    if f_hi <= 0:
        return hi, "ok"
    k = brentq(lambda t: max(min(f(t), 1e300), -1e300), k_a, hi, xtol=1e-15, rtol=4 * EPS)
    try:
        vk = steady_of(s, k)[0]
    except NotSteady:
        return None, "invalid"
    if abs(vk - v) > 1e-9 * v:
        # Either K is resolved to its last bits where v(K) is steep (near the crawl end), or
        # v(K) jumps over v: the neighbours two ulp away tell, as in src/fit/k/search.rs.
        u = 2.0 * EPS * k
        try:
            vm, vp = steady_of(s, k - u)[0], steady_of(s, min(k + u, hi))[0]
            resolved = (vm - v) * (vp - v) <= 0 and abs(vm - vp) <= 1e-3 * v
        except NotSteady as e:
            resolved = str(e) == "stops" and br[4] == "crawl-over-top" and k - lo <= 1e-12 \
                and vk > v
        if not resolved:
            return None, "invalid"
    return k, "ok"


def clamp_end(model, s, br, vs):
    k, status = solve(model, s, br, vs)
    if status == "ok":
        return k
    if status == "below-range" or vs <= 0:
        return br[0]
    if status == "above-range":
        return br[1]
    return None


def dv_dk(br, k0, v0, v_at):
    """dv/dK at k0: the three-point difference of src/fit/k/search.rs::dv_dk."""
    lo, hi = br[0], br[1]
    d = k0 - lo
    if not d > 0:
        return None
    h_max = math.log((hi - lo) / d) if hi > k0 else 0.0
    h = min(1e-5, 0.5 * h_max)
    if h >= 1e-7:
        k1, k2 = lo + d * math.exp(-h), lo + d * math.exp(h)
    else:
        h = 1e-5
        k1, k2 = lo + d * math.exp(-h), lo + d * math.exp(-2.0 * h)
    if not (k1 != k0 and k2 != k0 and k1 != k2):
        return None
    try:
        v1, v2 = v_at(k1), v_at(k2)
    except NotSteady:
        return None
    a1, a2 = k1 - k0, k2 - k0
    dv = -v0 * (a1 + a2) / (a1 * a2) + v1 * a2 / (a1 * (a2 - a1)) - v2 * a1 / (a2 * (a2 - a1))
    return dv if math.isfinite(dv) else None


def row(model, s, v, sg):
    """K, K_lo, K_hi, dv/dK, status and the bracket of one measurement."""
    try:
        br = bracket(model, s)
    except Invalid:
        return None, None, None, None, "invalid", None
    k, status = solve(model, s, br, v)
    k_lo = k_hi = None
    # fitbead's launch-speed path (crawl to lift-off) writes no interval on above-range rows.
    launch_above = status == "above-range" and br[4] == "crawl-over-top" and br[5] == "lift-off"
    if sg is not None and not launch_above:
        k_lo = clamp_end(model, s, br, v - sg)
        k_hi = clamp_end(model, s, br, v + sg)
    dv = None
    if k is not None:
        steady_of = MODELS[model][0]
        dv = dv_dk(br, k, steady_of(s, k)[0], lambda t: steady_of(s, t)[0])
    return k, k_lo, k_hi, dv, status, br


def measurement(r):
    """(xi, delta_deg, v, sigma_v or None, rho, f) of one input row."""
    cell = lambda name: (r.get(name) or "").strip()
    xi, d = float(cell("xi")), float(cell("delta_deg"))
    rho = float(cell("rho")) if cell("rho") else RHO
    f = float(cell("f")) if cell("f") else F
    if cell("v"):
        v = float(cell("v"))
        sg = float(cell("sigma_v")) if cell("sigma_v") else None
    else:
        scale = math.sqrt((float(cell("g")) if cell("g") else 9.81) * float(cell("R_m"))
                          * (1.0 + xi))
        v = float(cell("v_m_s")) / scale
        sg = float(cell("sigma_v_m_s")) / scale if cell("sigma_v_m_s") else None
    return xi, d, v, sg, rho, f


COLUMNS = ["series", "xi", "delta_deg", "v", "sigma_v", "model", "K", "K_lo", "K_hi", "dv_dK",
           "regime", "status", "K_min", "K_max", "lower_limit", "upper_limit"]
REGIME = {"ok": "B", "below-range": "A", "above-range": "C", "invalid": ""}


def main():
    model = sys.argv[1]
    if model not in MODELS:
        sys.exit(f"peer_k.py: unknown model {model!r} (stick or stickslip)")
    path = sys.argv[2]
    limit = int(sys.argv[3]) if len(sys.argv) > 3 else None
    t0 = time.perf_counter()
    n = 0
    failed = 0
    w = csv.writer(sys.stdout, lineterminator="\n")
    w.writerow(COLUMNS)
    num = lambda x: "" if x is None else repr(float(x))
    with open(path, newline="") as fh:
        for r in csv.DictReader(fh):
            if limit is not None and n >= limit:
                break
            xi, d, v, sg, rho, f = measurement(r)
            try:
                k, k_lo, k_hi, dv, status, br = row(model, Scene(xi, d, rho, f), v, sg)
            except RuntimeError:
                # scipy's brentq gave up (100 iterations) on this row: counted, written as
                # invalid, the run goes on.
                k = k_lo = k_hi = dv = br = None
                status = "invalid"
                failed += 1
            ends = ["", "", "", ""] if br is None else [num(br[0]), num(br[1]), br[4], br[5]]
            w.writerow([(r.get("series") or "").strip(), repr(xi), repr(d), repr(v), num(sg),
                        model, num(k), num(k_lo), num(k_hi), num(dv), REGIME[status], status]
                       + ends)
            n += 1
    dt = time.perf_counter() - t0
    print(f"{model}: {n} rows in {dt:.3f} s: {1e6 * dt / max(n, 1):.1f} us per row"
          f" ({failed} rows where scipy's brentq did not converge)", file=sys.stderr)


if __name__ == "__main__":
    main()
