"""K per measurement (eq 69) for a data set larger than one machine, on Dask.

Each partition of a ``dask.dataframe`` is one ``fitbead.invert_k`` call (``map_partitions``):
rows are independent, so the result equals one in-process call on the whole table, bit for
bit, however the rows are partitioned and wherever the partitions run. The same code runs on
a local cluster (below), on any Dask cluster, or on SLURM with dask-jobqueue, by changing only
the cluster line::

    from dask_jobqueue import SLURMCluster
    cluster = SLURMCluster(cores=16, memory="32GB", walltime="01:00:00"); cluster.scale(jobs=8)

Run: ``python dask_k.py [ROWS] [PARTITIONS]`` (needs ``dask[dataframe]`` and ``distributed``).
Input from Parquet or CSV in practice: ``dd.read_parquet("measurements/*.parquet")``.
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd

import fitbead

MODEL = "stick"

# The columns invert_k adds, with their dtypes: what map_partitions needs to know without
# running a partition (text columns are object).
TEXT = {"model", "regime", "status", "lower_limit", "upper_limit", "message"}


def k_partition(df: pd.DataFrame, model: str = MODEL) -> pd.DataFrame:
    """K of every row of one partition: the input columns, then fitbead's (``fitbead k``'s
    CSV columns), on the partition's own index."""
    out = fitbead.invert_k(model, df["xi"].to_numpy(), df["delta_deg"].to_numpy(), df["v"].to_numpy(), df["sigma_v"].to_numpy())
    res = pd.DataFrame({k: v for k, v in out.items()}, index=df.index)
    return res


def meta(model: str = MODEL) -> pd.DataFrame:
    """An empty frame with the result's columns and dtypes."""
    cols = [c for c in fitbead.invert_k(model, [1.0], [12.0], [0.3]).keys()]
    return pd.DataFrame({c: pd.Series(dtype=object if c in TEXT else "float64") for c in cols})


def measurements(n: int, seed: int = 1) -> pd.DataFrame:
    """Synthetic measured rows: the stick model's v̄ at random ξ, δ in regime B and K, with
    2 % noise (the shape of a real campaign's table)."""
    rng = np.random.default_rng(seed)
    xi = rng.uniform(0.8, 3.0, n)
    d = rng.uniform(8.0, 20.0, n)
    k = rng.uniform(0.3, 0.8, n)
    v = fitbead.forward("stick", xi, d, K=k)["v"]
    v = np.where(np.isnan(v), 0.3, v) * rng.normal(1.0, 0.02, n)
    return pd.DataFrame({"xi": xi, "delta_deg": d, "v": v, "sigma_v": 0.02 * v})


def main(n: int = 1_000_000, partitions: int = 4) -> pd.DataFrame:
    import dask.dataframe as dd
    from dask.distributed import Client, LocalCluster

    df = measurements(n)
    with LocalCluster(n_workers=partitions, threads_per_worker=1, processes=True) as cluster, Client(cluster):
        ddf = dd.from_pandas(df, npartitions=partitions)
        result = ddf.map_partitions(k_partition, meta=meta()).compute()
    return result


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    parts = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    r = main(n, parts)
    print(r["status"].value_counts().to_string())
    print(r[["K", "K_lo", "K_hi"]].describe().to_string())
