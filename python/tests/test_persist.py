"""Results that persist and cross processes: every result pickles to an equal object,
``save``/``fitbead.load`` round-trip through a plain JSON document, and process pools (fork
and spawn) work after a fitbead call."""

import json
import math
import os
import pickle
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA


def quiet(fn, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args, **kwargs)


@pytest.fixture(scope="module")
def results():
    """One of every result type: data sets made each way, least-squares fits (one with slope
    errors), a posterior, fit sets, tables of every shape, a design, a report."""
    data = fitbead.Dataset.default()
    arrays = quiet(
        fitbead.Dataset.from_arrays,
        xi=1.0,
        delta_deg=[9.0, 11.0, 13.0, 15.0, 17.0],
        v=[0.30, 0.42, 0.50, 0.58, 0.64],
        series=["a"] * 5,
        sigma_delta_deg=[0.0, 0.5, 0.5, 0.0, 0.2],
    )
    pd = pytest.importorskip("pandas")
    frame = fitbead.Dataset.from_pandas(pd.read_csv(DEFAULT_DATA))
    slopes = data.__class__(data._core.with_defaults(sigma_delta=0.3))
    out = {
        "dataset default": data,
        "dataset csv": fitbead.Dataset.read_csv(DEFAULT_DATA),
        "dataset arrays (no sigma)": arrays,
        "dataset pandas": frame,
        "dataset with defaults": slopes,
        "klaw": quiet(fitbead.fit_klaw, data),
        "klaw free per series": quiet(fitbead.fit_klaw, data, model="stick", law="free-per-series"),
        "klaw with slope errors": quiet(fitbead.fit_klaw, data, model="stick", sigma_delta=0.3),
        "posterior": quiet(fitbead.fit_klaw, data, model="stick", method="mcmc", seed=3, min_ess=100, max_steps=2000, thin=2),
        "jan": quiet(fitbead.fit_jan, data),
        "jaeger": quiet(fitbead.fit_jaeger, data),
        "forward 0-d": fitbead.forward("stick", 1.0, 12.0),
        "forward 2-d": fitbead.forward("stickslip", [[0.8], [1.6]], np.linspace(5, 30, 7)),
        "regimes": fitbead.regimes(),
        "invert_k": fitbead.invert_k("stick", data),
        "simulate": fitbead.simulate("stick", series=[1.0], points=4, seed=2),
        "design": fitbead.design("klaw", points=5),
        "report": quiet(fitbead.report, data),
    }
    out["param"] = out["klaw"].params["c"]
    return out


SAVED = ("dataset", "klaw", "posterior", "jan", "jaeger", "forward", "regimes", "invert_k", "simulate", "design")


def test_every_result_pickles_to_an_equal_object(results):
    """pickle.loads(pickle.dumps(r)) == r for every result type (floats bit for bit, NaN equal
    to NaN), of the same type, and what is computed from it (the curve of a fit, the draws, the
    K of a data set) is the same."""
    for name, r in results.items():
        for protocol in (2, pickle.HIGHEST_PROTOCOL):
            back = pickle.loads(pickle.dumps(r, protocol=protocol))
            assert type(back) is type(r), name
            assert back == r and not (back != r), name
    post = pickle.loads(pickle.dumps(results["posterior"]))
    want = results["posterior"]
    assert post.draws.view(np.uint64).tolist() == want.draws.view(np.uint64).tolist()
    assert post.log_posterior.tobytes() == want.log_posterior.tobytes()
    assert (post.burn_in, post.thin, post.interrupted) == (want.burn_in, want.thin, want.interrupted)
    assert post.report() == want.report() and post.to_pandas("stats").equals(want.to_pandas("stats"))
    fit = pickle.loads(pickle.dumps(results["klaw"]))
    assert fit.eval([10.0, 12.0], xi=1.0).tobytes() == results["klaw"].eval([10.0, 12.0], xi=1.0).tobytes()
    assert fit._core.chi2_p_value() == results["klaw"]._core.chi2_p_value()
    d = pickle.loads(pickle.dumps(results["dataset arrays (no sigma)"]))
    assert d.warnings == results["dataset arrays (no sigma)"].warnings
    assert fitbead.invert_k("stick", d) == fitbead.invert_k("stick", results["dataset arrays (no sigma)"])
    rep = pickle.loads(pickle.dumps(results["report"]))
    assert rep.files == results["report"].files and rep.markdown == results["report"].markdown
    assert rep["params"] == results["report"]["params"]
    fits = pickle.loads(pickle.dumps(results["jan"]))
    assert fits.notes == results["jan"].notes and [f.name for f in fits] == [f.name for f in results["jan"]]
    slopes = pickle.loads(pickle.dumps(results["klaw with slope errors"]))
    assert slopes.delta_fit is not None and slopes.delta_fit.tobytes() == results["klaw with slope errors"].delta_fit.tobytes()


def test_equality_sees_a_difference(results):
    """The equality the round trips are held to is not trivially true."""
    t = results["forward 2-d"]
    u = pickle.loads(pickle.dumps(t))
    u["v"] = u["v"].copy()
    i = int(np.flatnonzero(np.isfinite(u["v"]))[0])
    u["v"].flat[i] = np.nextafter(u["v"].flat[i], 1.0)
    assert u != t
    z = fitbead.forward("stick", 1.0, [0.0, 12.0])
    w = pickle.loads(pickle.dumps(z))
    w["delta_deg"] = np.array([-0.0, 12.0])
    assert w != z  # -0.0 is not 0.0
    assert results["jan"] != results["jaeger"] and results["jan"][0] != results["jan"][1]
    assert results["dataset default"] != results["dataset csv"]  # another source name
    other = quiet(fitbead.fit_klaw, results["dataset default"], model="stick", method="mcmc", seed=4, min_ess=100, max_steps=2000, thin=2)
    assert other != results["posterior"]


def test_save_and_load_give_an_equal_object(results, tmp_path):
    """result.save(path) then fitbead.load(path) gives an equal object of the same type, for
    every kind the format holds."""
    for name, r in results.items():
        if not name.startswith(SAVED):
            continue
        path = tmp_path / (name.replace(" ", "_") + ".json")
        r.save(path)
        back = fitbead.load(path)
        assert type(back) is type(r), name
        assert back == r, name
        back.save(tmp_path / "again.json")
        assert (tmp_path / "again.json").read_bytes() == path.read_bytes(), name
    loaded = fitbead.load(tmp_path / "posterior.json")
    assert loaded.to_pandas("draws").equals(results["posterior"].to_pandas("draws"))
    with pytest.raises(fitbead.FitbeadError, match="cannot save.*dtype"):
        fitbead.Table(x=np.array(["a"])).save(tmp_path / "bad.json")


def test_the_saved_file_is_plain_json(results, tmp_path):
    """The document reads with the json module alone (no NaN or Infinity tokens), says its
    format, version and kind, and holds the records of the command line's CSV files and the
    draws as nested lists."""
    path = tmp_path / "post.json"
    results["posterior"].save(path)

    def refuse(token):
        raise AssertionError(f"a bare {token} in the JSON")

    doc = json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)
    assert (doc["format"], doc["version"], doc["kind"]) == ("fitbead-result", 1, "fit")
    fit = doc["fit"]
    assert [p["parameter"] for p in fit["params"]] == results["posterior"].param_names
    assert set(fit["params"][0]) == set(fitbead._api._core.record_columns("params"))
    chains = np.array(fit["draws"]["chains"])
    assert list(chains.shape) == fit["draws"]["shape"] and chains.tobytes() == results["posterior"].draws.tobytes()
    path = tmp_path / "arrays.json"
    results["dataset arrays (no sigma)"].save(path)
    doc = json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)
    assert doc["dataset"]["sigma_v"] == ["NaN"] * 5


def test_load_refuses_what_it_cannot_read(results, tmp_path):
    """A damaged, foreign or newer file is a FitbeadError naming the file and what is wrong."""
    good = tmp_path / "good.json"
    results["klaw"].save(good)
    doc = json.loads(good.read_text())

    def write(name, text):
        p = tmp_path / name
        p.write_text(text, encoding="utf-8")
        return p

    def edited(**changes):
        d = json.loads(json.dumps(doc))
        for k, v in changes.items():
            if v is None:
                d["fit"].pop(k)
            else:
                d["fit"][k] = v
        return json.dumps(d)

    cases = {
        "missing.json": (None, "cannot read"),
        "notjson.json": ("{not json", "not JSON"),
        "other.json": (json.dumps({"format": "something-else"}), "format is 'something-else'"),
        "newer.json": (good.read_text().replace('"version":1', '"version":2', 1), "version 2 is newer"),
        "kind.json": (good.read_text().replace('"kind":"fit"', '"kind":"spline"', 1), "kind 'spline'"),
        "noparams.json": (edited(params=None), "fit: no 'params'"),
        "badnumber.json": (edited(param_bounds=[["wide", 1.0]]), "fit.param_bounds[0]: expected a number"),
        "badpoints.json": (edited(points={"xi": [1.0, {"a": 1}]}), "fit.points.xi"),
    }
    for name, (text, message) in cases.items():
        path = tmp_path / name if text is None else write(name, text)
        with pytest.raises(fitbead.FitbeadError) as e:
            fitbead.load(path)
        assert str(path) in str(e.value) and message in str(e.value), (name, str(e.value))
    post = tmp_path / "post.json"
    results["posterior"].save(post)
    text = post.read_text()
    d = json.loads(text)
    d["fit"]["draws"]["shape"][1] += 1
    with pytest.raises(fitbead.FitbeadError, match=r"fit.draws.chains: shape"):
        fitbead.load(write("shape.json", json.dumps(d)))
    d = json.loads(text)
    d["fit"]["draws"]["chains"][0][0][0] = "lots"
    with pytest.raises(fitbead.FitbeadError, match=r"fit.draws.chains: expected a number, found text 'lots'"):
        fitbead.load(write("draw.json", json.dumps(d)))
    ds = tmp_path / "ds.json"
    results["dataset csv"].save(ds)
    d = json.loads(ds.read_text())
    d["dataset"]["text"] = "series,xi\n"
    with pytest.raises(fitbead.FitbeadError, match="dataset: "):
        fitbead.load(write("ds_bad.json", json.dumps(d)))
    with pytest.raises(fitbead.FitbeadError, match="pickle of version 9"):
        results["klaw"].__class__.__new__(results["klaw"].__class__).__setstate__({"version": 9})


# A script run in its own process (and process group, so that a hung pool can be killed whole):
# a fit and a K inversion here start rayon's pool, then a pool of worker processes of the start
# method given runs the same calls, and Dask's process scheduler with that start method.
POOL_SCRIPT = r"""
import concurrent.futures as cf, multiprocessing as mp, sys, time, warnings
warnings.simplefilter("ignore")
import fitbead
method, data = sys.argv[1], sys.argv[2]
here = fitbead.fit_jan(data)
ds = fitbead.Dataset.read_csv(data)
k_here = fitbead.invert_k("stick", ds)
start = time.monotonic()
with cf.ProcessPoolExecutor(2, mp_context=mp.get_context(method)) as ex:
    fits = [ex.submit(fitbead.fit_jan, data) for _ in range(2)]
    k = ex.submit(fitbead.invert_k, "stick", ds)
    n = ex.submit(fitbead.threads)
    got, k, n = [f.result() for f in fits], k.result(), n.result()
assert all(g == here for g in got), "a worker's fits differ"
assert k == k_here, "a worker's K differs"
assert n == fitbead.threads(), ("threads", n, fitbead.threads())
try:
    import dask
except ImportError:
    dask = None
if dask is not None:
    with dask.config.set({"multiprocessing.context": method}):
        (d,) = dask.compute(dask.delayed(fitbead.fit_jan)(data), scheduler="processes", num_workers=2)
    assert d == here, "Dask's fits differ"
print(f"ok {method}: {time.monotonic() - start:.2f} s, {n} threads in a worker")
"""


def run_pool(method):
    t0 = time.monotonic()
    p = subprocess.Popen(
        [sys.executable, "-c", POOL_SCRIPT, method, str(DEFAULT_DATA)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        out, err = p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, err = p.communicate()
        pytest.fail(f"the {method} pool hung (killed after 30 s): {out}{err}")
    elapsed = time.monotonic() - t0
    assert p.returncode == 0, err
    assert out.startswith(f"ok {method}"), out + err
    return elapsed


def test_a_fork_pool_after_a_fit_finishes_in_under_30_s():
    """A fork-based ProcessPoolExecutor (and Dask's process scheduler on fork) after fitbead
    calls in the parent: the workers fit, invert K and report the parent's thread count (a
    pool of their own), with the parent's numbers, in under 30 s."""
    if "fork" not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip("no fork on this platform")
    assert run_pool("fork") < 30


def test_a_spawn_pool_gives_the_same_numbers():
    """The same with spawn (the workers import fitbead afresh; arguments and results are
    pickled both ways)."""
    assert run_pool("spawn") < 60
