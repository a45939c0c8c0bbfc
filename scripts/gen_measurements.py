#!/usr/bin/env python3
"""Random measurements for `fitbead k` (docs/PERFORMANCE.md: byte identity and memory).

Usage: python3 scripts/gen_measurements.py N SEED > measured.csv

Columns series,xi,delta_deg,v,sigma_v,rho,f,id. 200 series, each with its own xi drawn
log-uniformly in [0.5, 12] (a few below the smallest xi with steady motion); per row delta_deg
uniform in [0.2, 35], v log-uniform in [0.02, 2] (so that many rows fall below or above the
steady range of their scene), sigma_v 0.5-10 % of v (empty on one row in 20), rho 0.4 or 0.5
(empty on one row in 10: the flag's value), f log-uniform in [0.01, 1] (empty on one row in
10), and a pass-through id (quoted when it holds a comma). The same N and SEED give the same
file.
"""
import math
import random
import sys


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    rng = random.Random(seed)
    series = [math.exp(rng.uniform(math.log(0.5), math.log(12.0))) for _ in range(200)]
    out = sys.stdout
    out.write("series,xi,delta_deg,v,sigma_v,rho,f,id\n")
    lines = []
    for i in range(n):
        s = rng.randrange(len(series))
        xi = series[s]
        d = rng.uniform(0.2, 35.0)
        v = math.exp(rng.uniform(math.log(0.02), math.log(2.0)))
        sg = "" if rng.random() < 0.05 else repr(v * rng.uniform(0.005, 0.1))
        rho = "" if rng.random() < 0.1 else rng.choice(["0.4", "0.5"])
        f = "" if rng.random() < 0.1 else repr(math.exp(rng.uniform(math.log(0.01), 0.0)))
        ident = f'"r{i},x"' if i % 997 == 0 else f"r{i}"
        lines.append(f"s{s},{xi!r},{d!r},{v!r},{sg},{rho},{f},{ident}\n")
        if len(lines) >= 65536:
            out.write("".join(lines))
            lines.clear()
    out.write("".join(lines))


if __name__ == "__main__":
    main()
