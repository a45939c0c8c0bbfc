"""An interrupted posterior run keeps its draws (fitbead.Interrupted); velocities in m/s from
arrays, in eval, eval_band and plot; counts as integers; a run too short to assess says NaN;
errors in the words of the keyword arguments; the joined log likelihoods of a FitSet; the
numpydoc sections of the documented calls."""

import inspect
import math
import pickle
import time
import warnings

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA, ctrl_c_after

G = 9.81


@pytest.fixture(scope="module")
def data():
    return fitbead.Dataset.read_csv(str(DEFAULT_DATA))


def quiet(fn, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fitbead.FitbeadWarning)
        return fn(*args, **kwargs)


def shipped():
    c = fitbead.Dataset.default().columns()
    return c["series"], c["xi"], c["delta_deg"], c["v"], c["sigma_v"]


def si_data(radius):
    """The shipped points in m/s, the row beads of series `s` of radius `radius(s)`."""
    series, xi, d, v, s = shipped()
    r_m = np.array([radius(lab) for lab in series])
    unit = np.sqrt(G * r_m * (1 + xi))
    return fitbead.Dataset.from_arrays(xi, d, v_m_s=v * unit, sigma_v_m_s=s * unit, R_m=r_m, series=series), unit


# ---- Ctrl-C during a posterior run --------------------------------------------------------


def test_an_interrupted_mcmc_keeps_its_draws(data, tmp_path):
    """Ctrl-C during a posterior run that would take minutes stops it within seconds and
    raises fitbead.Interrupted (a KeyboardInterrupt) carrying the fits with the draws so far,
    every one marked interrupted; the draws file asked for is written with those draws."""
    path = tmp_path / "draws.csv"
    t0 = time.perf_counter()
    with ctrl_c_after(1.0), pytest.raises(fitbead.Interrupted) as e:
        quiet(fitbead.fit_jaeger, data, method="mcmc", min_ess=1e9, max_steps=1_000_000, draws=path)
    assert time.perf_counter() - t0 < 6.0
    assert isinstance(e.value, KeyboardInterrupt)
    assert "draws so far" in str(e.value)
    fits = e.value.result
    assert isinstance(fits, fitbead.FitSet) and [f.series for f in fits] == data.labels
    kept = 0
    for f in fits:
        # Every fit says it was cut short, those not started yet (the series run a few at a
        # time) with no draws.
        assert f.interrupted and not f.converged
        assert f.stats["mcmc_status"] == "interrupted"
        assert all(p.note.startswith("interrupted") for p in f.params.values())
        kept += f.draws.shape[0] * f.draws.shape[1]
    sampled = [f for f in fits if f.draws.size]
    assert sampled and f"({len(sampled)} of 4 fits sampled)" in str(e.value)
    for f in sampled:
        assert f.draws.shape[2] == 3 and np.isfinite(f.draws).all()
        assert f.stats["steps"] > f.burn_in
    # One row per kept draw of every fit, after the header.
    assert len(path.read_text().splitlines()) == 1 + kept


def test_an_interrupted_klaw_run_returns_its_fit(data):
    with ctrl_c_after(1.0), pytest.raises(fitbead.Interrupted) as e:
        quiet(fitbead.fit_klaw, data, model="stick", method="mcmc", min_ess=1e9, max_steps=1_000_000)
    fit = e.value.result
    assert isinstance(fit, fitbead.FitResult) and fit.name == "klaw-c"
    assert fit.interrupted and fit.draws.shape[1] > 0
    again = pickle.loads(pickle.dumps(e.value))
    assert isinstance(again, fitbead.Interrupted) and again.result == fit


def test_an_interrupted_report_keeps_its_tables(data, tmp_path):
    """report(method="mcmc") cut short by Ctrl-C: the report of the draws so far, in the
    exception and in the directory, every posterior row marked interrupted."""
    with ctrl_c_after(1.0), pytest.raises(fitbead.Interrupted) as e:
        quiet(fitbead.report, data, tmp_path / "r", method="mcmc", min_ess=1e9, max_steps=1_000_000)
    rep = e.value.result
    assert isinstance(rep, fitbead.Report)
    assert set(rep["stats"]["mcmc_status"]) == {"interrupted"}
    assert (tmp_path / "r" / "stats.csv").read_bytes() == rep.files["stats.csv"]


# ---- velocities in m/s ---------------------------------------------------------------------


def test_from_arrays_takes_si_columns_as_the_csv_reader_does():
    series, xi, d, v, s = shipped()
    ds, _ = si_data(lambda lab: 0.0025)
    c = ds.columns()
    # v = v_m_s / sqrt(g R (1 + ξ)) gives back the dimensionless velocities.
    np.testing.assert_allclose(c["v"], v, rtol=1e-14)
    np.testing.assert_allclose(c["sigma_v"], s, rtol=1e-14)
    assert list(ds.labels) == list(dict.fromkeys(series))
    assert np.all(ds.file_columns()["R_m"] == 0.0025)
    with pytest.raises(fitbead.FitbeadError, match="both v"):
        fitbead.Dataset.from_arrays(xi, d, v, v_m_s=v, R_m=0.0025)
    with pytest.raises(fitbead.FitbeadError, match="R_m"):
        fitbead.Dataset.from_arrays(xi, d, v_m_s=v)
    with pytest.raises(fitbead.FitbeadError, match="sigma_v_m_s"):
        fitbead.Dataset.from_arrays(xi, d, sigma_v=s, v_m_s=v, R_m=0.0025)
    with pytest.raises(fitbead.FitbeadError, match="v_m_s with R_m"):
        fitbead.Dataset.from_arrays(xi, d)
    # The reader's checks apply: a negative radius is refused, naming the column.
    with pytest.raises(fitbead.FitbeadError, match="R_m"):
        fitbead.Dataset.from_arrays(xi, d, v_m_s=v, R_m=-1.0)


def test_eval_and_eval_band_answer_in_m_s_for_si_data():
    ds, _ = si_data(lambda lab: 0.0025)
    fit = quiet(fitbead.fit_klaw, ds, model="stickslip", law="c")
    grid = np.linspace(8.0, 14.0, 7)
    unit = np.sqrt(G * 0.0025 * (1 + 1.6))
    np.testing.assert_allclose(fit.eval(grid, 1.6, units="si"), fit.eval(grid, 1.6) * unit, rtol=1e-15)
    band, si = fit.eval_band(grid, 1.6), fit.eval_band(grid, 1.6, units="si")
    for k in ("v", "v_low", "v_high"):
        np.testing.assert_allclose(si[k], band[k] * unit, rtol=1e-15)
    np.testing.assert_array_equal(si["delta_deg"], band["delta_deg"])
    # The unit travels with the fit through pickling.
    again = pickle.loads(pickle.dumps(fit))
    np.testing.assert_array_equal(again.eval(grid, 1.6, units="si"), fit.eval(grid, 1.6, units="si"))


def test_si_units_need_one_radius_per_series():
    radii = {"0.8": 0.002, "1": 0.0025, "1.6": 0.003, "2": 0.0035}
    ds, _ = si_data(lambda lab: radii[lab])
    fit = quiet(fitbead.fit_klaw, ds, model="stickslip", law="c")
    with pytest.raises(fitbead.FitbeadError, match="give series"):
        fit.eval([10.0], 1.6, units="si")
    got = fit.eval([10.0], 1.6, series="1.6", units="si")
    np.testing.assert_allclose(got, fit.eval([10.0], 1.6) * math.sqrt(G * 0.003 * 2.6), rtol=1e-15)
    # A per-series fit converts with its own series' radius.
    jan = quiet(fitbead.fit_jan, ds, profile=False).get("jan-series", "2")
    np.testing.assert_allclose(jan.eval([20.0], units="si"), jan.eval([20.0]) * math.sqrt(G * 0.0035 * 3.0), rtol=1e-15)


def test_units_are_checked(data):
    fit = quiet(fitbead.fit_klaw, data, model="stick", law="c")
    for call in (lambda: fit.plot(units="bogus"), lambda: fit.eval([10.0], 1.0, units="bogus")):
        with pytest.raises(fitbead.FitbeadError, match="expected 'dimensionless' or 'si'"):
            call()
    with pytest.raises(fitbead.FitbeadError, match="given dimensionless"):
        fit.plot(units="si")
    with pytest.raises(fitbead.FitbeadError, match="given dimensionless"):
        fit.eval_band([10.0], 1.0, units="si")


def test_plot_in_si_units_draws_m_s():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    radii = {"0.8": 0.002, "1": 0.0025, "1.6": 0.003, "2": 0.0035}
    ds, unit = si_data(lambda lab: radii[lab])
    fit = quiet(fitbead.fit_klaw, ds, model="stickslip", law="c")
    fig = fit.plot(units="si")
    ax = fig.axes[0]
    assert "m/s" in ax.get_ylabel()
    # The error bars' points are the velocities in m/s, series by series.
    drawn = np.concatenate([c.lines[0].get_ydata() for c in ax.containers])
    np.testing.assert_allclose(np.sort(drawn), np.sort(fit.residuals["v"] * unit), rtol=1e-12)
    plt.close(fig)


def test_a_klaw_curve_is_drawn_with_the_datas_rho_and_f(data):
    """eval at the fitted points gives the fit's own v_fit with ρ and f other than the
    defaults (they were 0.4 and 0.1 whatever the data said), also after pickling."""
    for kw in ({"rho": 0.6}, {"f": 0.2}):
        fit = quiet(fitbead.fit_klaw, data, model="stickslip", law="c", profile=False, **kw)
        r = fit.residuals
        for one in (fit, pickle.loads(pickle.dumps(fit))):
            got = np.concatenate(
                [one.eval(r["delta_deg"][r["series"] == s], float(r["xi"][r["series"] == s][0])) for s in dict.fromkeys(r["series"])]
            )
            np.testing.assert_allclose(got, r["v_fit"], rtol=1e-12)
    series, xi, d, v, s = shipped()
    mixed = fitbead.Dataset.from_arrays(xi, d, v, s, series=series, rho=np.where(xi > 1.2, 0.5, 0.4))
    fit = quiet(fitbead.fit_klaw, mixed, model="stickslip", law="c", profile=False)
    with pytest.raises(fitbead.FitbeadError, match="several values of rho or f"):
        fit.eval([10.0], 1.0)


# ---- counts, diagnostics, words --------------------------------------------------------------


def test_counts_are_integers(data):
    fit = quiet(fitbead.fit_klaw, data, model="stickslip", law="c")
    st = fit.to_pandas("stats")
    for c in ("n_points", "n_params", "dof", "iterations", "residual_evals"):
        assert st[c].dtype == np.int64, c
    assert st["n_points"].iloc[0] == 36
    # Columns with empty cells stay float64 with NaN.
    assert st["walkers"].dtype == np.float64
    assert quiet(fitbead.fit_jan, data, profile=False).to_pandas("stats")["n_points"].dtype == np.int64
    rep = quiet(fitbead.report, data)
    for table, cols in (("models", ("rank", "n_points", "n_params")), ("models_by_series", ("rank", "n_points"))):
        for c in cols:
            assert rep[table][c].dtype == np.int64, (table, c)
    assert sorted(rep["models"]["rank"]) == list(range(1, len(rep["models"]["rank"]) + 1))


def test_a_run_too_short_to_assess_says_nan_not_inf(data):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        fit = fitbead.fit_klaw(data, model="stick", method="mcmc", max_steps=10)
    report = fit.report()
    assert "ESS min NaN" in report and "ESS min inf" not in report
    # The statistics' cell is empty (as in stats.csv); R̂ could be estimated.
    assert fit.stats["ess_min"] is None and math.isfinite(fit.stats["rhat_max"])
    said = [str(w.message) for w in rec if issubclass(w.category, fitbead.ConvergenceWarning)]
    assert any("bulk ESS NaN" in m for m in said)


def test_errors_name_the_keyword_not_the_flag(cli, data):
    with pytest.raises(fitbead.FitbeadError) as e:
        fitbead.fit_klaw(data, level=2)
    assert str(e.value) == "level = '2': confidence level 2 is not in (0, 1)"
    with pytest.raises(fitbead.FitbeadError) as e:
        quiet(fitbead.fit_jaeger, data, fix={"a4": 0})
    fix = str(e.value)
    assert fix.startswith("fix = 'a4=0': no parameter 'a4'")
    with pytest.raises(fitbead.FitbeadError) as e:
        fitbead.design(fit="jaeger", criterion="T")
    assert "vs=MODEL" in str(e.value) and "--" not in str(e.value)
    with pytest.raises(fitbead.FitbeadError) as e:
        fitbead.fit_klaw(data, model="slip")
    assert "skip_unsteady=True" in str(e.value) and "--" not in str(e.value)
    # The command line keeps its own words, the rest of the message the same.
    code, _, err = cli("jaeger", "--fix", "a4=0", "--input", DEFAULT_DATA, check=False)
    assert code == 2 and "<command line>, flag '--fix', value 'a4=0': " + fix.split(": ", 1)[1] in err


# ---- the joined log likelihoods of a fit set ---------------------------------------------------


def test_a_fit_sets_joined_log_likelihoods_compare_with_the_global_fit(data):
    az = pytest.importorskip("arviz")
    fits = quiet(fitbead.fit_jan, data, method="mcmc", seed=1)
    joined = fits.to_arviz(joined=True)
    assert list(joined) == ["jan-series", "jan-global"]
    per = [f for f in fits if f.name == "jan-series"]
    steps = min(f.draws.shape[1] for f in per)
    ll = joined["jan-series"].log_likelihood["v"].values
    # Each series' pointwise log likelihoods, over the last kept steps all the runs have.
    want = np.concatenate([f.log_likelihood()[:, -steps:, :] for f in per], axis=-1)
    np.testing.assert_array_equal(ll, want)
    post = joined["jan-series"].posterior["lambda"].values
    np.testing.assert_array_equal(post[:, :, 2], per[2].draws[:, -steps:, per[2].param_names.index("lambda")])
    assert ll.shape[-1] == joined["jan-global"].log_likelihood["v"].shape[-1] == len(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        table = az.compare(joined)
    assert set(table.index) == {"jan-series", "jan-global"}
    # Without joining: one InferenceData per fit, as before.
    assert list(fits.to_arviz()) == [f"{f.name}[{f.series}]" for f in fits]


# ---- documentation -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "fn",
    [
        fitbead.Dataset.from_pandas,
        fitbead.Dataset.from_arrays,
        fitbead.regimes,
        fitbead.FitResult.eval,
        fitbead.FitResult.eval_band,
        fitbead.FitResult.plot,
        fitbead.FitSet.to_pandas,
        fitbead.FitSet.to_arviz,
    ],
    ids=lambda f: f.__qualname__,
)
def test_numpydoc_parameters_name_every_argument(fn):
    doc = inspect.getdoc(fn)
    assert "Parameters\n----------\n" in doc
    section = doc.split("Parameters\n----------\n", 1)[1]
    names = [p for p in inspect.signature(fn).parameters if p not in ("self", "cls")]
    for name in names:
        assert any(
            line.split(":")[0].replace(" ", "").split(",").count(name) for line in section.splitlines() if line and not line.startswith(" ")
        ), name
