#!/usr/bin/env python3
"""Random scenes for the batch timing of `fitbead forward` (docs/PERFORMANCE.md, "Batch forward").

Usage: python3 scripts/gen_scenes.py N SEED > scenes.csv

Columns xi,delta_deg,K,rho,f: xi uniform in [0.65, 10], delta_deg uniform in [0, 30],
K uniform in (0, 1), rho = 0.4, f = 0.1. The same N and SEED give the same file.
"""
import random
import sys


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    rng = random.Random(seed)
    out = sys.stdout
    out.write("xi,delta_deg,K,rho,f\n")
    lines = []
    for _ in range(n):
        xi = rng.uniform(0.65, 10.0)
        d = rng.uniform(0.0, 30.0)
        k = rng.random()
        while k == 0.0:
            k = rng.random()
        lines.append(f"{xi!r},{d!r},{k!r},0.4,0.1\n")
        if len(lines) >= 65536:
            out.write("".join(lines))
            lines.clear()
    out.write("".join(lines))


if __name__ == "__main__":
    main()
