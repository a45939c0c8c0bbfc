"""Beyond one machine: python/examples/dask_k.py inverts K on a Dask LocalCluster, one
``invert_k`` call per partition; the result equals one in-process call bit for bit."""

import os
import pathlib
import sys

import numpy as np
import pytest

import fitbead

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def test_dask_map_partitions_equals_one_call_bit_for_bit(monkeypatch):
    pytest.importorskip("dask.dataframe")
    pytest.importorskip("distributed")
    # The workers are separate processes: they import the example module by name.
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(EXAMPLES), os.environ.get("PYTHONPATH")])))
    monkeypatch.syspath_prepend(str(EXAMPLES))
    import dask_k

    # Four partitions of 62,500 rows: every partition boundary, as at the example's default
    # of a million rows (which took 16 s of the suite on two cores).
    n = 250_000
    got = dask_k.main(n, 4)
    df = dask_k.measurements(n)
    want = fitbead.invert_k(dask_k.MODEL, df["xi"].to_numpy(), df["delta_deg"].to_numpy(), df["v"].to_numpy(), df["sigma_v"].to_numpy())
    assert len(got) == n and list(got.index) == list(range(n))
    assert list(got.columns) == list(want)
    for c, col in want.items():
        g = got[c].to_numpy()
        if col.dtype == object:
            assert (g == col).all(), c
        else:
            np.testing.assert_array_equal(g.view(np.uint64), np.ascontiguousarray(col, dtype=np.float64).view(np.uint64), err_msg=c)
    # Most rows are in range: the test inverts real K, not errors.
    assert (got["status"] == "ok").mean() > 0.9


def test_dask_process_scheduler_fits_give_the_in_process_values():
    """The documented pattern for sets of fits, ``dask.delayed(fitbead.fit_jan)(path)``, on
    Dask's process scheduler (spawned workers: the results come back pickled) equals the fit in
    this process: every record, point and the report, floats bit for bit."""
    dask = pytest.importorskip("dask")
    from conftest import DEFAULT_DATA

    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        want = fitbead.fit_jan(str(DEFAULT_DATA))
        jaeger = fitbead.fit_jaeger(str(DEFAULT_DATA))
    tasks = [dask.delayed(fitbead.fit_jan)(str(DEFAULT_DATA)), dask.delayed(fitbead.fit_jaeger)(str(DEFAULT_DATA))]
    got, got_jaeger = dask.compute(*tasks, scheduler="processes", num_workers=2)
    assert type(got) is fitbead.FitSet and got == want and got_jaeger == jaeger
    for g, w in zip(got, want):
        for name, p in w.params.items():
            assert np.float64(g.params[name].value).tobytes() == np.float64(p.value).tobytes(), name
        assert g.report() == w.report()
