#!/usr/bin/env python3
"""Reference mean velocities of the slip approximation (eqs 54-59) near its own stop limit:
tests/reference/slip_approx_limit_refs.csv.

The approximate squared speed a' + b' sin(theta) + c' cos(theta) (eqs 56a-c) has its least value
a' - p (p = sqrt(b'^2 + c'^2), eq 58c) inside the contact, or at an end; where that least value
reaches 0 the approximate bead stops.  For a scene (xi, delta, f) this happens at a collisional
parameter K_lim (found here by bisection in K at 50 digits).  The rows are at
K = double(K_lim (1 + eta)), eta in {1e-1, 1e-2, 1e-3, 1e-6, 1e-9, 1e-12} (regime B) and
{-1e-3, -1e-9} (regime A: the approximate speed^2 vanishes on the way), for nine interior-limit
scenes (the least value inside the contact; the first is the scene of the independent check,
xi = 4, delta = 22.551947104571017 deg, f = 0.2) and three end-limit scenes (the least value at
Theta0).

Same conventions as make_refs.py, whose functions it imports: every input is an exact double
(delta in radians = math.radians(deg), the value fitbead's command line makes from degrees);
alpha = asin(1/(1+xi)) at working precision; v is the tanh-sinh quadrature of the approximate
integrand at 40 digits (make_refs.slip_approx), v_check the Gauss-Legendre route at 50 digits;
final_velocity is the exact slip model's sqrt(L'^2).

cond is the relative condition number of v with respect to the double inputs fitbead receives,
sum over x in (xi, delta, K, f) of |x dv/dx| / v, by central differences of the 40-digit
quadrature with relative steps 2^-50 (the columns cond_xi ... cond_f are the terms).  An f64
code that rounds its inputs' derived quantities (alpha, Theta0) once cannot beat cond * 2^-53
by much; fitbead's test holds v to 8 cond 2^-53.  Column min_G2hat is the least approximate
squared speed (a' - p, or its value at an end), a_prime is a'.

Run: python3 tests/reference/slip_approx_limit_refs.py [--jobs N]  (mpmath).
"""
import argparse
import math
import multiprocessing as mproc
import os
import sys

import mpmath
from mpmath import mp, mpf

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_refs as M  # noqa: E402

# (xi, delta in degrees, f, kind): kind says where the least approximate speed^2 lies at K_lim.
SCENES = [
    (4.0, 22.551947104571017, 0.2, 'interior'),
    (1.0, 15.0, 0.2, 'interior'),
    (1.0, 5.0, 0.05, 'interior'),
    (2.0, 10.0, 0.05, 'interior'),
    (2.0, 30.0, 0.2, 'interior'),
    (4.0, 15.0, 0.2, 'interior'),
    (4.0, 30.0, 0.5, 'interior'),
    (10.0, 5.0, 0.05, 'interior'),
    (10.0, 30.0, 0.5, 'interior'),
    (4.0, 25.0, 0.2, 'end'),
    (10.0, 20.0, 0.05, 'end'),
    (2.0, 25.0, 0.05, 'end'),
]
ETAS = ['1e-1', '1e-2', '1e-3', '1e-6', '1e-9', '1e-12', '-1e-3', '-1e-9']
STEP = mpf(2) ** -50

COLS = ['case', 'model', 'xi', 'delta_rad', 'K', 'f', 'eta', 'K_limit', 'kind', 'v', 'final_velocity',
        'regime', 'min_G2hat', 'a_prime', 'cond', 'cond_xi', 'cond_delta', 'cond_K', 'cond_f',
        'v_check', 'rel_diff', 'note']


def approx_coefficients(xi, delta, K, f):
    """(a', b', c', Theta0, Thetaf) of eqs 56a-c, or None when the slip model has no L'^2 > 0."""
    sc = M.Scene(xi, delta, K, None, f)
    st, _ = M.slip_state(sc)
    if st is None:
        return None
    _, a = st
    f = sc.f
    e = a * mpmath.exp(-2 * f * sc.th0)
    return e * (1 + 4 * f * f), sc.b + 2 * f * e, sc.c - 4 * f * f * e, sc.th0, sc.thf


def least_speed2(xi, delta, K, f):
    """Least value of a' + b' sin + c' cos on [Theta0, Thetaf] (a' - p when the minimum is inside)."""
    co = approx_coefficients(xi, delta, K, f)
    if co is None:
        return None
    ap, bp, cp, t0, tf = co
    p = mpmath.sqrt(bp * bp + cp * cp)
    # a' + p cos(theta - theta*) is least at theta* + pi (mod 2 pi)
    tm = mpmath.atan2(bp, cp) + mpmath.pi
    tm -= 2 * mpmath.pi * mpmath.floor((tm - t0) / (2 * mpmath.pi))
    g = lambda t: ap + bp * mpmath.sin(t) + cp * mpmath.cos(t)
    if t0 < tm < tf:
        return ap - p, 'interior', ap
    return min(g(t0), g(tf)), 'end', ap


def k_limit(xi, delta, f):
    with mp.workdps(50):
        a = M.alpha_of(xi)
        khi = mpmath.exp(-2 * mpf(f) * a) * (1 - mpf('1e-6'))
        klo = mpf('1e-4')
        h = lambda K: least_speed2(xi, delta, K, f)[0]
        hl, hh = h(klo), h(khi)
        assert hl < 0 < hh, (xi, delta, f)
        k = M.bisect_root(h, klo, khi, hl, iters=200)
        return k, least_speed2(xi, delta, k, f)[1]


def v_of(xi, delta, K, f, dps=M.PRIMARY_DPS, method='ts'):
    return M.run_model('slip-approx', (xi, delta, K, None, f), method, dps)[0]


def task(t):
    case, xi, d, f, kind, eta, klim = t
    K = float(klim * (1 + mpf(eta)))
    prim = v_of(xi, d, K, f)
    row = dict(case=case, model='slip-approx', xi=M.R(xi), delta_rad=M.R(d), K=M.R(K), f=M.R(f), eta=eta,
               K_limit=M.S(klim), kind=kind, regime=prim['regime'], note=prim['note'])
    with mp.workdps(M.PRIMARY_DPS):
        ls = least_speed2(xi, d, K, f)
        if ls is not None:
            row['min_G2hat'] = M.S(ls[0])
            row['a_prime'] = M.S(ls[2])
    if prim['regime'] != 'B':
        return row
    chk = v_of(xi, d, K, f, M.CHECK_DPS, 'gl')
    with mp.workdps(M.PRIMARY_DPS):
        v = prim['v']
        row['v'] = M.S(v)
        row['final_velocity'] = M.S(prim['final_velocity'])
        row['v_check'] = M.S(chk['v'])
        row['rel_diff'] = mpmath.nstr(abs(mpf(chk['v']) - v) / v, 3)
        terms = {}
        for name, idx in (('xi', 0), ('delta', 1), ('K', 2), ('f', 3)):
            x = [mpf(xi), mpf(d), mpf(K), mpf(f)]
            h = x[idx] * STEP
            up, dn = list(x), list(x)
            up[idx] += h
            dn[idx] -= h
            vu = v_of(*up)['v']
            vd = v_of(*dn)['v']
            terms[name] = abs((vu - vd) / (2 * h) * x[idx] / v)
        row['cond'] = mpmath.nstr(sum(terms.values()), 6)
        for name, val in terms.items():
            row['cond_' + name] = mpmath.nstr(val, 6)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--jobs', type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    mp.dps = M.PRIMARY_DPS
    tasks = []
    for xi, deg, f, kind in SCENES:
        d = math.radians(deg)
        klim, where = k_limit(xi, d, f)
        assert where == kind, (xi, deg, f, where)
        print('xi=%s delta=%s deg f=%s: K_lim = %s (%s)' % (xi, deg, f, mpmath.nstr(klim, 17), where), flush=True)
        for eta in ETAS:
            tasks.append(('approx stop limit K=K_lim*(1+%s) %s' % (eta, kind), xi, d, f, kind, eta, klim))
    rows = []
    with mproc.Pool(args.jobs, initializer=M._init_worker) as pool:
        for r in pool.imap(task, tasks):
            rows.append(r)
            print('%-44s xi=%-4s f=%-4s %s v=%s cond=%s check diff %s' % (
                r['case'], r['xi'], r['f'], r['regime'], r.get('v', '')[:20], r.get('cond', ''),
                r.get('rel_diff', '')), flush=True)
    M.write_csv(os.path.join(HERE, 'slip_approx_limit_refs.csv'), COLS, rows)
    print('%d rows' % len(rows))


if __name__ == '__main__':
    main()
