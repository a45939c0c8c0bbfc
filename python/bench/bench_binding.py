#!/usr/bin/env python3
"""What the Python binding adds over the library's own batch call: the stick forward model
over N scenes, (a) by the Rust example `forward_batch` (the library called from Rust, each
record written into new columns on rayon's threads) and (b) by `fitbead.forward("stick", ...)`
from numpy arrays, on the same arrays and the same number of threads.

Usage: bench_binding.py --example PATH [--n 1000000] [--runs 5] [--threads T] [--seed S]

PATH is the example's binary (`cargo build --release --example forward_batch`, then
target/release/examples/forward_batch). The scenes are bench_forward.py's (seeded); they are
written to a temporary file the example reads. Both sides run once as a warm-up, then --runs
times; the best and the median wall times are printed with the binding's overhead,
binding / library − 1, and the extension's call alone (the rows computed into numpy columns,
before `fitbead.forward` makes the text columns object arrays). --threads sets
RAYON_NUM_THREADS for both; it must be set before fitbead is imported, so this script imports
it only after setting it.
"""
import os

# One BLAS thread: scipy (imported with bench_forward) starts OpenBLAS's thread pools, whose
# idle threads spin on the cores the two sides are timed on (6 % of a 1-thread run's samples).
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse
import platform
import subprocess
import sys
import tempfile

import numpy as np

from bench_forward import scenes, timed


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--example", required=True, help="the forward_batch example's binary")
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0, help="0: one per core")
    ap.add_argument("--seed", type=int, default=20251125)
    a = ap.parse_args()
    if a.threads > 0:
        os.environ["RAYON_NUM_THREADS"] = str(a.threads)
    import fitbead

    print(f"machine: os.cpu_count() = {os.cpu_count()}, {platform.platform()}; "
          f"python {platform.python_version()}, numpy {np.__version__}")
    print(f"load average before: {os.getloadavg()}")
    xi, dg, k, rho, f = scenes(a.n, a.seed)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "arrays.f64")
        np.concatenate([xi, dg, k, rho, f]).astype("<f8").tofile(path)
        out = subprocess.run([a.example, path, str(a.runs)], check=True, capture_output=True,
                             text=True, env=os.environ).stdout
    lib = dict(zip(out.split()[0::2], out.split()[1::2]))
    best_l, med_l = float(lib["best_s"]), float(lib["median_s"])
    print(f"(a) library batch call: {lib['scenes']} scenes, {lib['threads']} threads, best "
          f"{best_l:.4f} s, median {med_l:.4f} s ({1e9 * med_l / a.n:.1f} ns per scene); "
          f"steady {lib['steady']}")

    def call():
        return fitbead.forward("stick", xi, dg, K=k, rho=rho, f=f)

    def core():
        # The extension's call alone: the rows on rayon's threads into numpy columns, text
        # columns as codes and names, before fitbead.forward makes its Table of them.
        return fitbead._api._core.forward(
            "stick", xi, dg, rho, f, k=k, law="adjusted", lam=None, mu=None, a1=None,
            a2=None, a3=None, branch="upper", spin="roll", tol=1e-14)

    best_c, med_c, _ = timed(core, a.runs)
    best_b, med_b, res = timed(call, a.runs)
    steady = int(np.isfinite(np.asarray(res["v"], dtype=np.float64)).sum())
    print(f"(b) fitbead.forward: {fitbead.threads()} threads, best {best_b:.4f} s, median "
          f"{med_b:.4f} s ({1e9 * med_b / a.n:.1f} ns per scene); steady {steady}")
    if str(steady) != lib["steady"] or int(lib["threads"]) != fitbead.threads():
        print("the two sides differ in steady scenes or threads: no comparison")
        return 1
    print(f"(b') its extension call alone: best {best_c:.4f} s, median {med_c:.4f} s "
          f"({100 * (med_c / med_l - 1):+.1f} % over the library's median)")
    print(f"binding overhead: median {100 * (med_b / med_l - 1):+.1f} %, "
          f"best {100 * (best_b / best_l - 1):+.1f} %")
    print(f"load average after: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
