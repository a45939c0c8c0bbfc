#!/usr/bin/env python3
"""Reference regime limits, bulk friction and mean velocities for the named collision laws at
large radius ratios: tests/reference/named_law_refs.csv.

For a law given by name fitbead receives xi (and rho), not K: K is a function of
alpha = asin(1/(1+xi)), evaluated here at working precision from the exact double xi and never
rounded.  As xi grows, 1 - K ~ 2 sin^2(alpha) ~ 2/xi^2, so these rows test that 1 - K is
carried without cancellation.  Laws (docs/PHYSICS.md, Collision laws): cos2a = cos 2 alpha;
adjusted = cos 2 alpha + 1/2 sin^2 alpha sin 2 alpha; impact = (cos 2 alpha + rho)/(1 + rho);
c=0.3 = cos 2 alpha + 0.3 sin^2 alpha sin 2 alpha.  xi in {10, 100, 1000}, rho in {0, 0.4, 1}.

Rows (column quantity):
  delta_m_rad  eq 32; check: bisection of "squared top speed = 0" (make_refs.delta_m_root)
  delta_d_rad  eq 31; check: bisection of N(Thetaf) = 0 (make_refs.delta_d_root)
  mu_eq79      eq 79; check: tan(delta_m) (eq 78)
  v            mean velocity of the stick, stick-approx and stickslip models (f = 0.1) at
               delta = double(delta_m + frac (delta_d - delta_m)), frac in {0.1, 0.5, 0.9}, by
               make_refs.run_model: value by tanh-sinh at 40 digits, check by Gauss-Legendre at 50
               digits (stickslip: all fixed points by scanning and bisecting its map, the one
               reached from the rolling steady state; at these xi it is on the no-slip branch).
               cond (stick and stick-approx rows) is the relative condition number of v with
               respect to the double inputs xi, delta, rho: sum of |x dv/dx| / v by central
               differences with relative steps 2^-50.

Run: python3 tests/reference/named_law_refs.py [--jobs N]  (mpmath).
"""
import argparse
import multiprocessing as mproc
import os
import sys

import mpmath
from mpmath import mp, mpf

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_refs as M  # noqa: E402

XI = [10.0, 100.0, 1000.0]
RHO = [0.0, 0.4, 1.0]
LAWS = ['cos2a', 'adjusted', 'impact', 'c=0.3']
FRACS = [0.1, 0.5, 0.9]
F = 0.1
STEP = mpf(2) ** -50

COLS = ['quantity', 'law', 'xi', 'rho', 'model', 'f', 'delta_rad', 'value', 'check', 'rel_diff', 'regime',
        'cond', 'note']


def law_k(name, alpha, rho):
    c2 = mpmath.cos(2 * alpha)
    s = mpmath.sin(alpha)
    s2 = mpmath.sin(2 * alpha)
    if name == 'cos2a':
        return c2
    if name == 'adjusted':
        return c2 + s * s * s2 / 2
    if name == 'impact':
        return (c2 + rho) / (1 + rho)
    if name.startswith('c='):
        return c2 + mpf(name[2:]) * s * s * s2
    raise ValueError(name)


def limit_rows(law, xi, rho):
    rows = []
    with mp.workdps(M.PRIMARY_DPS):
        a = M.alpha_of(xi)
        r = mpf(rho)
        K = law_k(law, a, r)
        dm = M.delta_m_eq32(a, K)
        dd = M.delta_d_eq31(a, K, r)
        mu = M.mu_eq79(a, K)
        with mp.workdps(M.CHECK_DPS):
            a2 = M.alpha_of(xi)
            K2 = law_k(law, a2, r)
            dm2 = M.delta_m_root(a2, K2, r)
            dd2 = M.delta_d_root(a2, K2, r)
            mu2 = mpmath.tan(dm2)
        for q, v, c, note in (('delta_m_rad', dm, dm2, 'eq 32 | check: bisection of the top speed^2'),
                              ('delta_d_rad', dd, dd2, 'eq 31 | check: bisection of N(Thetaf)'),
                              ('mu_eq79', mu, mu2, 'eq 79 | check: tan(delta_m) by bisection')):
            rows.append(dict(quantity=q, law=law, xi=M.R(xi), rho=M.R(rho), value=M.S(v), check=M.S(c),
                             rel_diff=mpmath.nstr(abs(c - v) / abs(v), 3), note=note + '; 1-K = %s'
                             % mpmath.nstr(1 - K, 6)))
        deltas = [float(dm + mpf(fr) * (dd - dm)) for fr in FRACS]
    return rows, deltas


def v_of(model, law, xi, d, rho, method='ts', dps=M.PRIMARY_DPS):
    with mp.workdps(dps + 10):
        K = law_k(law, M.alpha_of(xi), mpf(rho))
    f = F if model == 'stickslip' else None
    return M.run_model(model, (xi, d, K, rho, f), method, dps)


def v_task(t):
    model, law, xi, rho, d, fr = t
    prim = v_of(model, law, xi, d, rho)
    chk = v_of(model, law, xi, d, rho, 'gl', M.CHECK_DPS)
    row = dict(quantity='v', law=law, xi=M.R(xi), rho=M.R(rho), model=model, delta_rad=M.R(d),
               f=M.R(F) if model == 'stickslip' else '')
    if model == 'stickslip':
        att = [i for i, r in enumerate(prim) if r.get('attractor')]
        if len(att) != 1:
            # no steady state reached from the rolling one: the verdict only, no value
            row.update(regime=prim[0]['regime'], note='delta frac %s of [delta_m, delta_d]; %s'
                       % (fr, prim[0]['note']))
            return row
        p, c = prim[att[0]], chk[att[0]]
    else:
        p, c = prim[0], chk[0]
    row.update(regime=p['regime'], note='delta frac %s of [delta_m, delta_d]; %s' % (fr, p['note']))
    if p['v'] is None:
        return row
    with mp.workdps(M.PRIMARY_DPS):
        v = p['v']
        row['value'] = M.S(v)
        row['check'] = M.S(c['v'])
        row['rel_diff'] = mpmath.nstr(abs(mpf(c['v']) - v) / v, 3)
        if model != 'stickslip':
            cond = mpf(0)
            for idx in range(3):
                x = [mpf(xi), mpf(d), mpf(rho)]
                if x[idx] == 0:
                    continue
                h = x[idx] * STEP
                up, dn = list(x), list(x)
                up[idx] += h
                dn[idx] -= h
                vu = v_of(model, law, up[0], up[1], up[2])[0]['v']
                vd = v_of(model, law, dn[0], dn[1], dn[2])[0]['v']
                cond += abs((vu - vd) / (2 * h) * x[idx] / v)
            row['cond'] = mpmath.nstr(cond, 4)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--jobs', type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    mp.dps = M.PRIMARY_DPS
    rows, tasks = [], []
    for xi in XI:
        for law in LAWS:
            for rho in RHO:
                lr, deltas = limit_rows(law, xi, rho)
                rows.extend(lr)
                for fr, d in zip(FRACS, deltas):
                    for model in ('stick', 'stick-approx', 'stickslip'):
                        tasks.append((model, law, xi, rho, d, fr))
    print('%d limit rows, %d velocity tasks' % (len(rows), len(tasks)), flush=True)
    with mproc.Pool(args.jobs, initializer=M._init_worker) as pool:
        for r in pool.imap(v_task, tasks):
            rows.append(r)
            print('%-12s %-8s xi=%-6s rho=%-3s %s v=%s check diff %s cond %s' % (
                r['model'], r['law'], r['xi'], r['rho'], r['regime'], r.get('value', '')[:20], r.get('rel_diff', ''),
                r.get('cond', '')), flush=True)
    M.write_csv(os.path.join(HERE, 'named_law_refs.csv'), COLS, rows)
    print('%d rows' % len(rows))


if __name__ == '__main__':
    main()
