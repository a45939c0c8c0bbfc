#!/usr/bin/env python3
"""Equal work of `fitbead k` and its scipy peer (scripts/peer_k.py), row by row.

Usage: peer_k_check.py FITBEAD_K.csv PEER.csv [--k-tol 1e-9] [--dv-tol 1e-6] [--list 20]

Rows are matched in order (the peer reads the first rows of the same input). Per row: the
statuses must be equal; where both give a value, K, K_lo and K_hi must agree to --k-tol
relative and dv_dK (a finite difference on both sides) to --dv-tol relative; a value given by
one side only is a disagreement. Prints the count of agreeing rows, the worst relative
difference of each column over the rows whose statuses agree, and the disagreeing rows by class
(`cause`: near a crawl end, ill-conditioned, other; then the first difference), up to --list
per class, with their bracket ends and what limits them. Exits 1 when a row disagrees.
"""
import argparse
import csv
import math
import sys
from collections import Counter, defaultdict

VALUES = ["K", "K_lo", "K_hi", "dv_dK"]


def num(x):
    x = (x or "").strip()
    return float(x) if x else None


def rel(a, b):
    if a == b:
        return 0.0
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def cause(f):
    """Where a disagreeing row sits, from fitbead's row: `near-crawl` when K or K_lo is within
    1e-4 relative of a crawl end (or, without K, v < 0.05 there). The peer works in K: its
    launch speed w0^2 - 2B sin^2(Theta0/2) cancels as K -> K_min, so scipy's contact time keeps
    few digits within ~1e-8 of K_min (statuses, K_lo), and its dv/dK steps d h (d = K - K_min,
    h = 1e-5) carry a rounding error eps K / (d h), above 1e-6 within ~1e-4 of K_min; fitbead
    takes the launch-speed path there (src/fit/k/launch.rs: the unknown is the top speed
    itself, differences in its logarithm). `ill-conditioned` when |v / (K dv/dK)| > 1e4
    (a relative error e of v moves K by e times that: at K -> 0 with Theta0 > 0 v hardly
    depends on K); else `other`."""
    k, lo, dv, v = num(f["K"]), num(f["K_min"]), num(f["dv_dK"]), num(f["v"])
    if f["lower_limit"] == "crawl-over-top" and lo:
        ks = [x for x in (k, num(f["K_lo"])) if x is not None]
        if any((x - lo) / lo < 1e-4 for x in ks) or (k is None and v < 0.05):
            return "near-crawl"
    if k and dv and abs(v / (k * dv)) > 1e4:
        return "ill-conditioned"
    return "other"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("fitbead")
    ap.add_argument("peer")
    ap.add_argument("--k-tol", type=float, default=1e-9)
    ap.add_argument("--dv-tol", type=float, default=1e-6)
    ap.add_argument("--list", type=int, default=20)
    a = ap.parse_args()
    fb = list(csv.DictReader(open(a.fitbead, newline="")))
    pe = list(csv.DictReader(open(a.peer, newline="")))
    n = min(len(fb), len(pe))
    if n == 0:
        sys.exit("peer_k_check.py: no rows to compare")
    worst = {c: (0.0, None) for c in VALUES}
    classes = defaultdict(list)
    statuses = Counter()
    agree = 0
    for i in range(n):
        f, p = fb[i], pe[i]
        for c in ["xi", "delta_deg", "v"]:
            if rel(float(f[c]), float(p[c])) > 1e-15:
                sys.exit(f"row {i + 1}: {c} differs ({f[c]} vs {p[c]}): not the same input")
        statuses[f["status"]] += 1
        why = []
        if f["status"] != p["status"]:
            why.append(f"status {f['status']} vs {p['status']}")
        else:
            for c in VALUES:
                x, y = num(f[c]), num(p[c])
                if (x is None) != (y is None):
                    why.append(f"{c} {'empty' if x is None else 'given'} in fitbead only")
                    continue
                if x is None:
                    continue
                r = rel(x, y)
                if r > worst[c][0]:
                    worst[c] = (r, i + 1)
                tol = a.dv_tol if c == "dv_dK" else a.k_tol
                if r > tol:
                    why.append(f"{c} rel {r:.1e}")
        if why:
            classes[cause(f) + ": " + why[0].split(" rel ")[0]].append((i + 1, why, f, p))
        else:
            agree += 1
    print(f"rows compared: {n} (fitbead statuses: "
          + ", ".join(f"{k} {v}" for k, v in sorted(statuses.items())) + ")")
    print(f"rows agreeing (status equal, K/K_lo/K_hi within {a.k_tol:g}, dv_dK within "
          f"{a.dv_tol:g} relative): {agree}")
    print("worst relative difference over rows with equal statuses:")
    for c in VALUES:
        r, at = worst[c]
        print(f"  {c:6s} {r:.2e}" + (f" (row {at})" if at else ""))
    for key, rows in sorted(classes.items(), key=lambda kv: -len(kv[1])):
        print(f"disagreement: {key}: {len(rows)} row(s)")
        for line, why, f, p in rows[: a.list]:
            print(f"  row {line}: {'; '.join(why)} | xi {float(f['xi']):.4g} delta "
                  f"{float(f['delta_deg']):.4g} v {float(f['v']):.4g} | fitbead K {f['K'] or '-'}"
                  f" [{f['K_min']}, {f['K_max']}] {f['lower_limit']}/{f['upper_limit']} | peer K "
                  f"{p['K'] or '-'} [{p['K_min']}, {p['K_max']}] {p['lower_limit']}/"
                  f"{p['upper_limit']}" + (f" | {f['message']}" if f.get("message") else ""))
    sys.exit(0 if agree == n else 1)


if __name__ == "__main__":
    main()
