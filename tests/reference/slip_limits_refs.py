#!/usr/bin/env python3
"""Reference mean velocities of the slip models at their own limits, beyond the rows of
forward_refs.csv: tests/reference/slip_limits_refs.csv.

Same method and conventions as make_refs.py, whose functions it imports (direct quadrature of
eq 51 by tanh-sinh at 40 digits, checked by Gauss-Legendre at 50 digits; every input an exact
double; alpha = asin(1/(1+xi)) at working precision):

* the slip model within 1e-3, 2e-4, 1e-6, 1e-9 and 1e-12 (relative, in delta) above its stop
  limit, where the least squared speed of the contact vanishes (the first two on either side of
  the point where fitbead switches to double-double, a least squared speed of 1e-4), for xi in {0.65, 1, 2, 10}, f in
  {0.01, 0.1, 0.5, 2} and the fitted and cos 2 alpha laws of K;
* slip and slip-approx with K = e^{-2 f alpha} (1 - eta) rounded to a double, eta in
  {1e-2, 3e-3, 1e-3, 5.5e-4, 1e-6, 1e-9, 1e-12} (1 - K^2 e^{4 f alpha} ~ 2 eta: the first two
  either side of 1e-2, where fitbead switches to double-double), at the slope where L'^2 = cos(Thetaf)/2,
  for xi in {0.65, 1, 2, 10} and f in {0.01, 0.1, 1}.

Run: python3 tests/reference/slip_limits_refs.py [--jobs N]  (mpmath; about ten minutes on
two cores).
"""
import argparse
import multiprocessing as mproc
import os
import sys
import time

import mpmath
from mpmath import mp, mpf

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_refs as M  # noqa: E402


def tasks():
    T = []
    with mp.workdps(M.PRIMARY_DPS + 10):
        for xi in (0.65, 1.0, 2.0, 10.0):
            for law in ('Kfit', 'Kcos'):
                K = M.K_law_double(law, xi)
                for f in (0.01, 0.1, 0.5, 2.0):
                    ds = M.slip_stop_delta(xi, K, f)
                    if ds is None:
                        continue
                    for eta in ('1e-3', '2e-4', '1e-6', '1e-9', '1e-12'):
                        d = float(ds * (1 + mpf(eta)))
                        T.append(('slip stop limit*(1+%s) %s' % (eta, law), 'slip', xi, d, K, None, f))
        for xi in (0.65, 1.0, 2.0, 10.0):
            for f in (0.01, 0.1, 1.0):
                a = M.alpha_of(xi)
                for eta in ('1e-2', '3e-3', '1e-3', '5.5e-4', '1e-6', '1e-9', '1e-12'):
                    K = float(mpmath.exp(-2 * mpf(f) * a) * (1 - mpf(eta)))
                    d = M.slip_delta_for_Lp2(xi, K, f, mpf('0.5'))
                    if d is None:
                        continue
                    for m in ('slip', 'slip-approx'):
                        T.append(('K e^{2f alpha}=1-%s' % eta, m, xi, float(d), K, None, f))
    return T


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--jobs', type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    mp.dps = M.PRIMARY_DPS
    t0 = time.time()
    T = tasks()
    print('%d tasks' % len(T), flush=True)
    rows = []
    with mproc.Pool(args.jobs, initializer=M._init_worker) as pool:
        for rs, dt in pool.imap(M.compute_task, T):
            rows.extend(rs)
            r = rs[0]
            print('%-34s %-11s xi=%-5s f=%-5s %s v=%s (check diff %s) %.1fs'
                  % (r['case'], r['model'], r['xi'], r['f'], r['regime'], r['v'][:20], r['rel_diff'], dt),
                  flush=True)
    M.write_csv(os.path.join(HERE, 'slip_limits_refs.csv'), M.FORWARD_COLS, rows)
    print('%d rows, %.0f s' % (len(rows), time.time() - t0))


if __name__ == '__main__':
    main()
