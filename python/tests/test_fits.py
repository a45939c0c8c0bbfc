"""Fits through the bindings equal the command line's: the same report text and the same
parameter values bit for bit; data from CSV, arrays and DataFrames; errors as the command
line words them; posteriors to ArviZ; Ctrl-C stops an MCMC run."""

import re
import signal
import time

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA, assert_bits_equal, ctrl_c_after, numbers, read_csv_text


@pytest.fixture(scope="module")
def data():
    return fitbead.Dataset.read_csv(str(DEFAULT_DATA))


def params_csv(cli, *args):
    _, text, _ = cli(*args, "--output", "-")
    return read_csv_text(text)


def test_klaw_report_and_values_equal_cli(cli, data):
    for model, law in [("stickslip", "c"), ("stick", "free-per-series"), ("stick-approx", "c")]:
        fit = fitbead.fit_klaw(data, model=model, law=law)
        _, report, _ = cli("klaw", "--model", model, "--law", law, "--input", DEFAULT_DATA)
        assert str(fit) in report
        cols = params_csv(cli, "klaw", "--model", model, "--law", law, "--input", DEFAULT_DATA)
        rows = [i for i, f in enumerate(cols["fit"]) if f == fit.name]
        assert [cols["parameter"][i] for i in rows] == [p.name for p in fit.params.values()]
        assert [cols["series"][i] for i in rows] == [p.series for p in fit.params.values()]
        assert_bits_equal("value", [p.value for p in fit.params.values()], [cols["value"][i] for i in rows])
        assert fit.converged


def test_jan_and_jaeger_reports_equal_cli(cli, data):
    jan = fitbead.fit_jan(data)
    _, report, _ = cli("jan", "--input", DEFAULT_DATA)
    assert len(jan) == 5
    for fr in jan:
        assert str(fr) in report
    assert jan.get("jan-global") is jan[-1] and jan.get("jan-series", "1.6") is jan[2]
    assert jan.get("jan-series", "9") is None
    jae = fitbead.fit_jaeger(data)
    _, report, _ = cli("jaeger", "--input", DEFAULT_DATA)
    assert len(jae) == 4
    for fr in jae:
        assert str(fr) in report
    cols = params_csv(cli, "jaeger", "--input", DEFAULT_DATA)
    want = [cols["value"][i] for i in range(len(cols["value"]))]
    got = [p.value for fr in jae for p in fr.params.values()]
    assert_bits_equal("jaeger values", got, want)


def test_result_object(data):
    fit = fitbead.fit_klaw(data, model="stickslip", law="c")
    c = fit["c"]
    assert c.low < c.value < c.high and c.method == "profile" and c.stderr > 0
    assert c.paper_value == 0.5
    r = fit.residuals
    assert np.allclose(r["residual"], r["v"] - r["v_fit"], rtol=0, atol=0)
    assert np.array_equal(r["normalised_residual"], r["residual"] / r["sigma_v"])
    assert fit.stats["n_points"] == len(data) == 36
    assert "klaw" in fit._repr_html_() and "<table>" in fit._repr_html_()
    jan = fitbead.fit_jan(data)
    g = [fr for fr in jan if fr.correlation is not None and len(fr.params) == 2][0]
    (pair, r), = g.correlations.items()
    assert -1.0 <= r <= 1.0 and pair == tuple(g.param_names)


def test_to_pandas(data):
    pd = pytest.importorskip("pandas")
    fit = fitbead.fit_klaw(data, model="stick", law="c")
    df = fit.to_pandas()
    assert list(df["parameter"]) == ["c"] and df.loc[0, "value"] == fit["c"].value
    res = fit.to_pandas("residuals")
    assert len(res) == 36 and set(res.columns) >= {"v", "v_fit", "residual"}
    # A DataFrame in: the same data set, the same fit, bit for bit.
    # Built from the file's text with Python's float() (correctly rounded), so that the frame
    # holds the file's doubles whatever pandas' own CSV parser does.
    cols = read_csv_text(DEFAULT_DATA.read_text())
    frame = pd.DataFrame({k: (v if k == "series" else [float(x) for x in v]) for k, v in cols.items()})
    again = fitbead.fit_klaw(frame, model="stick", law="c")
    assert again["c"].value == fit["c"].value
    # Arrays in (the file's numbers: Dataset.columns() gives δ back from radians).
    c = {k: frame[k].to_numpy() for k in ("xi", "delta_deg", "v", "sigma_v")}
    arr = fitbead.Dataset.from_arrays(c["xi"], c["delta_deg"], c["v"], c["sigma_v"], series=frame["series"].astype(str))
    assert fitbead.fit_klaw(arr, model="stick", law="c")["c"].value == fit["c"].value


def test_mcmc_draws_and_arviz(data):
    az = pytest.importorskip("arviz")
    post = fitbead.fit_klaw(data, model="stick", law="c", method="mcmc", seed=3)
    w, s, k = post.draws.shape
    assert k == 1 and w >= 32 and s > 100 and post.log_posterior.shape == (w, s)
    assert post.stats["mcmc_status"] == "converged"
    # The reported value is the posterior median (over every draw after burn-in; the result
    # keeps at most 10,000 of them, so their median is close, not equal).
    sd = post.draws[:, :, 0].std()
    assert abs(post["c"].value - np.median(post.draws[:, :, 0])) < 0.05 * sd
    idata = post.to_arviz()
    assert {"posterior", "sample_stats", "observed_data"} <= set(idata.groups())
    summ = az.summary(idata, kind="stats", round_to="none")
    assert summ.loc["c", "mean"] == pytest.approx(post.draws[:, :, 0].mean(), abs=1e-3)
    assert summ.loc["c", "sd"] == pytest.approx(post.draws[:, :, 0].std(), rel=1e-2)
    assert idata.posterior["c"].shape == (w, s)
    assert np.array_equal(idata.observed_data["v"].values, post.residuals["v"])
    # Same seed, same draws.
    again = fitbead.fit_klaw(data, model="stick", law="c", method="mcmc", seed=3)
    assert np.array_equal(again.draws, post.draws)
    with pytest.raises(ValueError, match="needs an MCMC fit"):
        fitbead.fit_klaw(data, model="stick", law="c").to_arviz()


def test_keyboard_interrupt_stops_mcmc(data):
    t0 = time.perf_counter()
    with ctrl_c_after(0.3), pytest.raises(KeyboardInterrupt):
        # A run that cannot converge (ESS 10⁹) and would take minutes: only the interrupt ends it.
        fitbead.fit_jaeger(data, method="mcmc", min_ess=1e9, max_steps=1_000_000)
    assert time.perf_counter() - t0 < 5.0


def test_a_signal_handlers_own_exception_passes_through(data):
    """A handler that raises (a timeout by SIGALRM) stops the run, and its exception, not a
    KeyboardInterrupt, reaches the caller."""

    def timeout(signum, frame):
        raise TimeoutError("budget spent")

    previous = signal.signal(signal.SIGALRM, timeout)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        t0 = time.perf_counter()
        with pytest.raises(TimeoutError, match="budget spent"):
            fitbead.fit_jaeger(data, method="mcmc", min_ess=1e9, max_steps=1_000_000)
        assert time.perf_counter() - t0 < 5.0
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_bad_input_raises_with_the_cli_message(cli, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("series,xi,delta_deg,v,sigma_v\na,1,12,0.3,0.01\na,1,13,-0.3,0.01\n")
    code, _, err = cli("klaw", "--model", "stick", "--input", bad, check=False)
    assert code == 2
    with pytest.raises(ValueError) as e:
        fitbead.Dataset.read_csv(str(bad))
    msg = str(e.value)
    assert msg == f"{bad}, line 3, column 'v', value '-0.3': v must be > 0"
    assert msg in err
    with pytest.raises(ValueError, match="cannot read"):
        fitbead.Dataset.read_csv(str(tmp_path / "missing.csv"))
    with pytest.raises(ValueError, match="method = 'bayes'"):
        fitbead.fit_klaw(fitbead.Dataset.default(), model="stick", method="bayes")
    with pytest.raises(ValueError, match="law = 'd'"):
        fitbead.fit_klaw(fitbead.Dataset.default(), model="stick", law="d")


def test_regimes_equal_cli(cli):
    _, text, _ = cli("regimes", "--law", "adjusted", "--xi", "0.8,1,1.6,2")
    cols = read_csv_text(text)
    t = fitbead.regimes([0.8, 1, 1.6, 2], law="adjusted")
    assert list(t) == list(cols), "the command line's columns, in its order"
    for c in ["xi", "alpha_deg", "K", "delta_m_deg", "delta_d_deg", "mu_eq79", "critical_xi"]:
        assert_bits_equal(c, t[c], cols[c])
    assert list(t["steady_range"]) == cols["steady_range"]
    assert_bits_equal("critical_xi", [t.critical_xi] * 4, cols["critical_xi"])


def test_parameter_and_statistics_records_are_the_cli_columns_and_cells(cli, data, tmp_path):
    """The binding's parameter and statistics dicts are the records the command line writes
    to params.csv and stats.csv: the same keys in the same order, and every cell equal (an
    empty cell is None), for a least-squares and a posterior fit."""
    for method in ["lsq", "mcmc"]:
        extra = ["--method", "mcmc", "--min-ess", "100", "--seed", "3"] if method == "mcmc" else []
        p, s = tmp_path / f"p_{method}.csv", tmp_path / f"s_{method}.csv"
        cli("klaw", "--model", "stick", "--input", DEFAULT_DATA, *extra, "--output", p, "--output-stats", s)
        kw = dict(method="mcmc", min_ess=100, seed=3) if method == "mcmc" else {}
        fit = fitbead.fit_klaw(data, model="stick", **kw)
        for rows, path in [(fit._core.params(), p), (fit._core.stats(), s)]:
            rows = rows if isinstance(rows, list) else [rows]
            cols = read_csv_text(path.read_text())
            for i, r in enumerate(rows):
                assert list(r) == list(cols), (method, path.name)
                for k, v in r.items():
                    cell = cols[k][i]
                    if v is None:
                        assert cell == "", (method, k, cell)
                    elif isinstance(v, bool):
                        assert cell == str(v).lower(), (method, k)
                    elif isinstance(v, float):
                        assert float(cell) == v, (method, k, cell, v)
                    else:
                        assert cell == str(v), (method, k, cell, v)


def test_slope_errors_fit_by_odr_as_the_command_line():
    """A file with sigma_delta_deg, and the same points from arrays: orthogonal distance
    regression, the adjusted slopes in the residual table, and the same c as ODRPACK's on
    these data (tests/reference/odr/bead_stick.json, c = 0.5036345)."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "tests" / "reference" / "odr" / "bead_stick.csv"
    fit = fitbead.fit_klaw(str(path), model="stick", law="c")
    assert fit.stats["method"] == "odr"
    assert fit["c"].value == pytest.approx(0.5036345041006788, rel=1e-6)
    res = fit.to_pandas("residuals")
    assert {"delta_fit_deg", "delta_residual"} <= set(res.columns)
    assert res["delta_residual"].abs().max() < 4
    assert np.array_equal(fit.delta_fit, res["delta_fit_deg"].to_numpy())
    # The column wins over the keyword (which covers rows without it); exact slopes: no δ_fit.
    assert fitbead.fit_klaw(str(path), model="stick", law="c", sigma_delta=0.0).delta_fit is not None
    assert fitbead.fit_klaw(None, model="stick", law="c").delta_fit is None
    cols = read_csv_text(path.read_text())
    c = {k: np.array([float(x) for x in cols[k]]) for k in ("xi", "delta_deg", "v", "sigma_v", "sigma_delta_deg")}
    arr = fitbead.Dataset.from_arrays(
        c["xi"], c["delta_deg"], c["v"], c["sigma_v"], series=cols["series"], sigma_delta_deg=c["sigma_delta_deg"]
    )
    again = fitbead.fit_klaw(arr, model="stick", law="c")
    assert again["c"].value == fit["c"].value
    with pytest.raises(ValueError, match="sigma_delta_deg"):
        fitbead.Dataset.from_arrays(c["xi"], c["delta_deg"], c["v"], c["sigma_v"], sigma_delta_deg=-0.1)
    with pytest.raises(fitbead.FitbeadError, match="posterior sampling with slope errors|slope errors"):
        fitbead.fit_klaw(str(path), model="stick", law="c", method="mcmc", fit_scatter=True)


def test_k_with_slope_errors_as_the_command_line(cli):
    """K per point of a Dataset with slope errors: the command line's columns, sigma_K
    included, bit for bit; without slope errors there is no sigma_K."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "tests" / "reference" / "odr" / "bead_stick.csv"
    _, text, _ = cli("k", "--model", "stick", str(path))
    want = read_csv_text(text)
    got = fitbead.invert_k("stick", fitbead.Dataset.read_csv(str(path)))
    assert list(got)[: list(want).index("sigma_K") + 1] == list(want)[: list(want).index("sigma_K") + 1]
    for k in ("K", "K_lo", "K_hi", "dv_dK", "sigma_K"):
        assert_bits_equal(k, got[k], want[k])
    # The slope's share widens σ_K beyond the velocity's alone, σ_v/|dv̄/dK|.
    velocity_only = numbers(want["sigma_v"]) / np.abs(numbers(want["dv_dK"]))
    assert (np.asarray(got["sigma_K"]) > velocity_only).all()
    assert "sigma_K" not in fitbead.invert_k("stick", fitbead.Dataset.default())


def test_simulate_with_slope_errors_as_the_command_line(cli):
    """simulate(sigma_delta=…) writes the command line's rows, bit for bit, with the columns
    sigma_delta_deg and delta_true_deg."""
    _, text, _ = cli("simulate", "--model", "stick", "--law", "c=0.5", "--series", "0.8,1", "--points", "5",
                     "--noise", "0.01", "--sigma-delta", "0.1", "--seed", "3")
    want = read_csv_text(text)
    got = fitbead.simulate("stick", law="c=0.5", series=[0.8, 1.0], points=5, noise=0.01, sigma_delta=0.1, seed=3)
    assert list(got) == list(want) and list(got)[-2:] == ["sigma_delta_deg", "delta_true_deg"]
    for k in ("delta_deg", "v", "sigma_v", "sigma_delta_deg", "delta_true_deg"):
        assert_bits_equal(k, got[k], want[k])
    with pytest.raises(fitbead.FitbeadError, match="^sigma_delta = "):
        fitbead.simulate("stick", sigma_delta=-1.0)


@pytest.mark.parametrize("call", ["forward", "invert_k"])
def test_ctrl_c_stops_a_large_batch_within_a_second(call):
    """Ctrl-C during a batch of millions of rows raises KeyboardInterrupt within a second (the
    rows check a stop flag), instead of when the batch ends."""
    n = 3_000_000
    d = np.linspace(8.0, 20.0, n)
    if call == "forward":
        run = lambda: fitbead.forward("contact", 1.0, d)  # noqa: E731
    else:
        run = lambda: fitbead.invert_k("stickslip", 1.0, d, np.full(n, 0.3))  # noqa: E731
    t0 = time.perf_counter()
    with ctrl_c_after(0.3):
        with pytest.raises(KeyboardInterrupt):
            run()
        elapsed = time.perf_counter() - t0
    assert elapsed < 1.3, elapsed


def test_bad_sampler_counts_name_the_setting():
    """max_steps=-5, seed=None, thin=1.5 or walkers=True are refused as FitbeadError naming
    the setting (not an OverflowError or TypeError of the conversion)."""
    for kw, match in [
        ({"max_steps": -5}, "max_steps = -5"),
        ({"seed": None}, "seed = None"),
        ({"seed": -1}, "seed = -1"),
        ({"thin": 1.5}, "thin = 1.5"),
        ({"walkers": True}, "walkers = True"),
    ]:
        for fit in (fitbead.fit_klaw, fitbead.fit_jan, fitbead.fit_jaeger):
            with pytest.raises(fitbead.FitbeadError, match=re.escape(match)):
                fit(method="mcmc", **kw)
