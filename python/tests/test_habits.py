"""The Python package as lmfit / pandas / ArviZ users expect it: every table keyed by the
command line's CSV header (taken from the command line itself), numeric dtypes with NaN,
the command line's warnings as Python warnings, covariance, residuals, evaluation of the
fitted model and its band, fit sets to pandas, and the pointwise log likelihood."""

import math
import warnings

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA, read_csv_text


def header(text):
    return text.splitlines()[0].split(",")


@pytest.fixture(scope="module")
def data():
    return fitbead.Dataset.read_csv(str(DEFAULT_DATA))


@pytest.fixture(scope="module")
def plain_data(tmp_path_factory):
    """The shipped data without its pass-through column v_true (so that the command line's
    header holds only the columns a Dataset keeps)."""
    cols = read_csv_text(DEFAULT_DATA.read_text())
    keep = ["series", "xi", "delta_deg", "v", "sigma_v"]
    p = tmp_path_factory.mktemp("d") / "plain.csv"
    lines = [",".join(keep)] + [",".join(cols[k][i] for k in keep) for i in range(len(cols["v"]))]
    p.write_text("\n".join(lines) + "\n")
    return p


@pytest.mark.parametrize("model", fitbead.MODELS)
def test_forward_keys_are_the_cli_header(cli, tmp_path, model):
    scenes = tmp_path / "s.csv"
    scenes.write_text("xi,delta_deg\n1,10\n1.6,12\n")
    extra = ["--a1", "0.1", "--a2", "5", "--a3", "0.5"] if model == "jaeger" else []
    kw = dict(a1=0.1, a2=5.0, a3=0.5) if model == "jaeger" else {}
    _, text, _ = cli("forward", "--model", model, "--input", scenes, *extra, "--output", "-")
    out = fitbead.forward(model, [1.0, 1.6], [10.0, 12.0], **kw)
    assert list(out) == header(text)
    assert list(out["status"]) == read_csv_text(text)["status"]


@pytest.mark.parametrize("model", fitbead.K_MODELS)
def test_k_keys_are_the_cli_header(cli, plain_data, model):
    _, text, _ = cli("k", "--model", model, "--input", plain_data, "--output", "-")
    out = fitbead.invert_k(model, fitbead.Dataset.read_csv(str(plain_data)))
    assert list(out) == header(text)
    cols = read_csv_text(text)
    assert list(out["series"]) == cols["series"] and list(out["model"]) == cols["model"]
    # The arrays form has the same columns but series (the arrays carry no labels).
    arr = fitbead.invert_k(model, [1.0], [12.0], [0.3], [0.01])
    assert list(arr) == [c for c in header(text) if c != "series"]


def test_report_tables_are_the_cli_headers_with_numeric_dtypes(cli, tmp_path):
    out = tmp_path / "r"
    cli("report", "--out-dir", out)
    fit = fitbead.fit_klaw(None, model="stickslip", law="c")
    jan = fitbead.fit_jan(None)
    for what in ["params", "stats", "residuals", "correlations"]:
        want = header((out / f"{what}.csv").read_text())
        for table in [fit.to_pandas(what), jan.to_pandas(what)]:
            assert list(table.columns) == want, what
    p = jan.to_pandas("params")
    # Numbers with empty cells are float64 with NaN, never object with None.
    for c in ["value", "stderr", "ci_low", "ci_high", "paper_value", "rhat", "ess_bulk", "q50"]:
        assert p[c].dtype == np.float64, c
    assert p["rhat"].isna().all()
    s = fit.to_pandas("stats")
    for c in ["chi2", "aic", "waic", "walkers"]:
        assert s[c].dtype == np.float64, c
    # The fit set holds every fit, each row naming its fit and series once.
    assert list(p["fit"].unique()) == ["jan-series", "jan-global"]
    assert len(p) == 2 * 4 + 4
    assert len(fitbead.fit_jaeger(None).to_pandas()) == 3 * 4


def test_param_numbers_are_nan_not_none(data):
    fit = fitbead.fit_klaw(data, model="stick", law="c")
    c = fit["c"]
    assert isinstance(c.rhat, float) and math.isnan(c.rhat)
    assert c.profile_low_status == "found" and c.low == c.profile_low
    assert c.cov_low < c.value < c.cov_high
    assert c.record["parameter"] == "c"


def test_covar_and_residual(data):
    fr = fitbead.fit_jaeger(data).get("jaeger", "1")  # the series with every standard error
    cov = fr.covar
    se = np.array([p.stderr for p in fr.params.values()])
    assert cov.shape == (3, 3)
    np.testing.assert_allclose(np.sqrt(np.diag(cov)), se, rtol=1e-15)
    np.testing.assert_allclose(cov / np.outer(se, se), fr.correlation, rtol=1e-12, atol=1e-15)
    r = fr.residual
    assert r.dtype == np.float64 and r.shape == (len(fr.residuals["v"]),)
    # chi2 is the sum of the squared normalised residuals (σ given on the shipped data).
    assert math.isclose(float(r @ r), fr.chi2, rel_tol=1e-12)


@pytest.mark.parametrize("which", ["klaw-c", "klaw-free", "jan-series", "jan-global", "jaeger"])
def test_eval_at_the_data_reproduces_the_fitted_values(data, which):
    """eval() at the fitted points gives the report's v_fit: within 1e-12 relative (the fit
    evaluates at δ in radians as read, eval at δ in degrees; the K law's c form is summed
    in a different order)."""
    if which == "klaw-c":
        fits = [fitbead.fit_klaw(data, model="stickslip", law="c")]
    elif which == "klaw-free":
        fits = [fitbead.fit_klaw(data, model="stick", law="free-per-series")]
    elif which == "jaeger":
        fits = list(fitbead.fit_jaeger(data))
    else:
        fits = [f for f in fitbead.fit_jan(data) if f.name == which]
    for fr in fits:
        r = fr.residuals
        for lab in dict.fromkeys(r["series"]):
            m = r["series"] == lab
            xi = np.asarray(r["xi"])[m]
            got = fr.eval(np.asarray(r["delta_deg"])[m], xi, series=lab if which == "klaw-free" else None)
            np.testing.assert_allclose(got, np.asarray(r["v_fit"])[m], rtol=1e-12)


def test_eval_matches_forward_through_values(data):
    jan = fitbead.fit_jan(data).get("jan-series", "1.6")
    d = np.linspace(12, 20, 5)
    np.testing.assert_array_equal(jan.eval(d), fitbead.forward("jan", 1.6, d, **jan.values)["v"])
    fit = fitbead.fit_klaw(data, model="stick", law="c")
    np.testing.assert_allclose(
        fit.eval(d, 1.6), fitbead.forward("stick", 1.6, d, **fit.values)["v"], rtol=1e-14
    )


def test_delta_method_band_against_sampled_parameters(data):
    """The least-squares band (delta method) against an independent estimate: the spread
    of the curve over 4000 parameter draws from N(θ̂, covar), which for the nearly linear
    K law must agree to a few per cent."""
    fit = fitbead.fit_klaw(data, model="stick", law="c")
    d = np.array([10.0, 12.0, 14.0])  # inside regime B at ξ = 1
    band = fit.eval_band(d, 1.0, level=0.6827)
    half = (band["v_high"] - band["v_low"]) / 2
    rng = np.random.default_rng(5)
    cs = rng.normal(fit["c"].value, fit["c"].stderr, 4000)
    curves = np.array([fitbead.forward("stick", 1.0, d, c=c)["v"] for c in cs])
    np.testing.assert_allclose(half, curves.std(axis=0), rtol=0.05)
    assert (band["v_low"] < band["v"]).all() and (band["v"] < band["v_high"]).all()


def test_unit_mistakes_are_python_warnings(tmp_path):
    """Velocities in mm/s in the dimensionless column: the command line's warnings arrive as
    UnitWarning, both on reading and on the fit's reduced χ²."""
    cols = read_csv_text(DEFAULT_DATA.read_text())
    p = tmp_path / "mm.csv"
    lines = ["series,xi,delta_deg,v,sigma_v"] + [
        f"{cols['series'][i]},{cols['xi'][i]},{cols['delta_deg'][i]},{float(cols['v'][i]) * 1000},{float(cols['sigma_v'][i])}"
        for i in range(len(cols["v"]))
    ]
    p.write_text("\n".join(lines) + "\n")
    with pytest.warns(fitbead.UnitWarning) as rec:
        d = fitbead.Dataset.read_csv(str(p))
    assert any("velocit" in str(w.message) for w in rec)
    assert d.warnings
    assert issubclass(fitbead.UnitWarning, fitbead.FitbeadWarning)


def test_an_absurd_misfit_is_a_unit_warning():
    """σ 40 times too small (reduced χ² of the stick c-law about 3.7 × 1600 = 5900, over the
    command line's threshold of 1000): the fit warns as the command line does."""
    c = fitbead.Dataset.default().columns()
    d = fitbead.Dataset.from_arrays(c["xi"], c["delta_deg"], c["v"], c["sigma_v"] / 40, series=c["series"])
    with pytest.warns(fitbead.UnitWarning, match="reduced chi2"):
        fit = fitbead.fit_klaw(d, model="stick", law="c")
    assert fit.reduced_chi2 > 1000


def test_errors_are_value_errors_with_the_cli_message(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("series,xi,delta_deg,v\na,1,10,0.3\na,1,abc,0.3\n")
    with pytest.raises(fitbead.FitbeadError, match=r"line 3.*delta_deg.*abc") as e:
        fitbead.Dataset.read_csv(str(p))
    assert isinstance(e.value, ValueError)


def test_namespace_is_clean():
    public = [n for n in dir(fitbead) if not n.startswith("_")]
    assert sorted(public) == sorted(n for n in fitbead.__all__ if not n.startswith("_"))
    for leak in ["np", "Dict", "Any", "Optional"]:
        assert not hasattr(fitbead, leak)
    for name in fitbead.__all__:
        obj = getattr(fitbead, name)
        if callable(obj):
            assert obj.__doc__ and len(obj.__doc__) > 40, name


def test_arviz_log_likelihood_and_compare(data):
    az = pytest.importorskip("arviz")
    kw = dict(method="mcmc", seed=2, min_ess=200)
    a = fitbead.fit_klaw(data, model="stick", law="c", **kw)
    b = fitbead.fit_klaw(data, model="stickslip", law="c", **kw)
    ia, ib = a.to_arviz(), b.to_arviz()
    ll = ia.log_likelihood["v"].values
    assert ll.shape == a.draws.shape[:2] + (len(data),)
    # At the least-squares-like centre the log likelihood is the Gaussian one: check one
    # draw by hand against the report's weighted residuals.
    w, s = 0, 0
    c = a.draws[w, s, 0]
    v = np.asarray(a.residuals["v"])
    sig = np.asarray(a.residuals["sigma_v"])
    vfit = fitbead.forward("stick", np.asarray(a.residuals["xi"]), np.asarray(a.residuals["delta_deg"]), c=c)["v"]
    want = -0.5 * ((v - vfit) / sig) ** 2 - np.log(sig) - 0.5 * np.log(2 * np.pi)
    np.testing.assert_allclose(ll[w, s], want, rtol=1e-9)
    loo = az.loo(ia)
    assert np.isfinite(loo.elpd_loo)
    cmp = az.compare({"stick": ia, "stickslip": ib})
    assert set(cmp.index) == {"stick", "stickslip"}
    # WAIC of ArviZ from this log likelihood and the library's (which drops the constant
    # −ln σᵢ − ½ ln 2π per point and uses at most 1000 draws) differ by that constant only,
    # up to the Monte Carlo error of the draw subset.
    const = float(np.sum(-np.log(sig) - 0.5 * np.log(2 * np.pi)))
    waic = az.waic(ia, scale="deviance").elpd_waic
    assert abs((waic + 2 * const) - a.stats["waic"]) < 0.5


def test_plot_draws_data_curve_band_and_residuals(data):
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    fit = fitbead.fit_jaeger(data)[0]
    fig = fit.plot()
    ax0, ax1 = fig.axes[:2]
    assert len(ax0.lines) >= 1 and len(ax0.collections) >= 1 and len(ax1.lines) >= 2


def test_stubs_name_every_public_item_with_its_parameters():
    """fitbead/__init__.pyi and _api.pyi (stubgen's, committed) list every public name and
    every public function's parameters as the package has them."""
    import ast
    import inspect
    import pathlib

    pkg = pathlib.Path(fitbead.__file__).parent
    src = pathlib.Path(__file__).resolve().parents[1] / "fitbead"
    stub_dir = pkg if (pkg / "_api.pyi").exists() else src
    init = (stub_dir / "__init__.pyi").read_text()
    for name in fitbead.__all__:
        assert f"{name} as {name}" in init, name
    tree = ast.parse((stub_dir / "_api.pyi").read_text())
    funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    for name in fitbead.__all__:
        obj = getattr(fitbead, name)
        if inspect.isfunction(obj):
            args = funcs[name].args
            stub = [a.arg for a in args.posonlyargs + args.args + args.kwonlyargs]
            real = [p.name for p in inspect.signature(obj).parameters.values() if p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]
            assert stub == real, name
        elif inspect.isclass(obj):
            assert name in classes, name


def test_prior_sensitivity_reaches_the_parameters(data):
    """The posterior's power-scaling check arrives in Param and to_pandas: Jaeger's a2 at
    ξ = 0.8 is flagged (tests/it/prior_sensitivity.rs checks the library's side)."""
    set_ = fitbead.fit_jaeger(data, method="mcmc", seed=1, min_ess=400)
    a2 = set_.get("jaeger", "0.8").params["a2"]
    assert a2.prior_sensitivity >= 0.05 and a2.prior_diagnosis in ("prior-driven", "prior-data conflict")
    p = set_.to_pandas()
    assert p["prior_sensitivity"].dtype == np.float64 and (p["prior_sensitivity"] >= 0).all()


def test_a_misfit_is_a_misfit_warning():
    """The shipped data (stick/slip) under the rolling model: χ² 129.4 on 35 degrees of freedom,
    tail probability about 1e-12 < 0.001, so the fit warns as the command line does, naming
    the probability; the stick/slip fit of the same data (p about 0.45) does not."""
    d = fitbead.Dataset.default()
    with pytest.warns(fitbead.MisfitWarning, match="chi2 tail probability") as rec:
        fit = fitbead.fit_klaw(d, model="stick", law="c")
    assert not any(issubclass(w.category, fitbead.UnitWarning) for w in rec)
    assert issubclass(fitbead.MisfitWarning, fitbead.FitbeadWarning)
    assert fit._core.chi2_p_value() < 1e-3
    with warnings.catch_warnings():
        warnings.simplefilter("error", fitbead.MisfitWarning)
        ok = fitbead.fit_klaw(d, model="stickslip", law="c")
    assert ok._core.chi2_p_value() > 1e-3


def test_a_misnamed_sigma_column_is_a_column_warning_and_strict_refuses(tmp_path):
    """Renaming sigma_v changes the weighting: the fit says so (ColumnWarning, with the name
    meant), and strict_columns=True refuses the column, as --strict-columns does."""
    import pandas as pd

    df = pd.read_csv(DEFAULT_DATA, dtype={"series": str})
    for name in ("sigma", "err_v", "SD"):
        bad = df.rename(columns={"sigma_v": name})
        with pytest.warns(fitbead.ColumnWarning, match=f"column '{name}'.*did you mean 'sigma_v'"):
            fitbead.fit_klaw(bad, model="stick", law="c", profile=False)
        with pytest.raises(fitbead.FitbeadError, match=f"'{name}'.*strict"):
            fitbead.fit_klaw(bad, model="stick", law="c", strict_columns=True)
        path = tmp_path / f"{name}.csv"
        bad.to_csv(path, index=False)
        with pytest.warns(fitbead.ColumnWarning, match="did you mean 'sigma_v'"):
            fitbead.Dataset.read_csv(path)
        with pytest.raises(fitbead.FitbeadError, match=f"{name}.csv"):
            fitbead.Dataset.read_csv(path, strict_columns=True)
    # A column far from every known name passes in silence, unless strict.
    with warnings.catch_warnings():
        warnings.simplefilter("error", fitbead.ColumnWarning)
        fitbead.Dataset.from_pandas(df.assign(run_id=1))
    with pytest.raises(fitbead.FitbeadError, match="'run_id'"):
        fitbead.Dataset.from_pandas(df.assign(run_id=1), strict_columns=True)


def test_simulated_tables_are_data():
    """What simulate returns is data for the fits, the same as its DataFrame, and its extra
    columns (v_true, delta_true_deg) are ones fitbead knows."""
    sim = fitbead.simulate("stick", law="c=0.5", series=[0.8, 1.0], points=6, noise=0.01, sigma_delta=0.1, seed=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", fitbead.ColumnWarning)
        a = fitbead.fit_klaw(sim, model="stick", law="c", strict_columns=True)
    b = fitbead.fit_klaw(sim.to_pandas(), model="stick", law="c")
    assert a.params["c"].value == b.params["c"].value
    assert a.params["c"].stderr == b.params["c"].stderr
    assert a.stats["method"] == "odr"
    k = fitbead.invert_k("stick", sim)
    assert "sigma_K" in k and np.array_equal(k["K"], fitbead.invert_k("stick", sim.to_pandas())["K"])
    # A design is the slopes simulate makes data at, as its file is.
    d = fitbead.design("klaw", model="stick", series=[1.0], points=4)
    at = fitbead.simulate("stick", law="c=0.5", series=[1.0], design=d, seed=5)
    assert sorted(set(np.round(at["delta_deg"], 9))) == sorted(set(np.round(d.table["delta_deg"], 9)))


def test_one_outlier_is_named_not_blamed_on_units():
    """One velocity at 3× its value: every fit it enters names it (OutlierWarning, with its
    series, slope and value), and none calls it a unit mistake; every velocity at 100× is a
    unit mistake (UnitWarning) with no outlier named."""
    import pandas as pd

    df = pd.read_csv(DEFAULT_DATA, dtype={"series": str})
    one = df.copy()
    one.loc[5, "v"] *= 3  # series 0.8, δ = 12.613°
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        fitbead.fit_klaw(one, model="stick", law="c", profile=False)
        fitbead.fit_jan(one, profile=False)
    outliers = [str(w.message) for w in got if w.category is fitbead.OutlierWarning]
    assert any(m.startswith("klaw-c [all]: 1 outlier(s)") and "delta 12.613 deg" in m for m in outliers), outliers
    assert any(m.startswith("jan-series [0.8]: 1 outlier(s)") for m in outliers), outliers
    assert not [w for w in got if w.category is fitbead.UnitWarning and "reduced chi2" in str(w.message)]
    assert issubclass(fitbead.OutlierWarning, fitbead.MisfitWarning)
    units = df.assign(v=df["v"] * 100, sigma_v=df["sigma_v"])
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        fitbead.fit_jan(units, profile=False)
    assert [w for w in got if w.category is fitbead.UnitWarning and "dimensionless" in str(w.message)]
    assert not [w for w in got if w.category is fitbead.OutlierWarning]


def test_fitset_is_a_mapping_by_name_and_series():
    """FitSet["jan-global"], FitSet["jan-series", 1.0] (a number finds the series labelled
    "1"), KeyError naming the fits there are, and positions as a list."""
    fits = fitbead.fit_jan(profile=False)
    assert fits["jan-global"].series == "all"
    assert fits["jan-series", 1.0].series == "1"
    assert fits.get("jan-series", 1.6) is fits["jan-series", "1.6"]
    assert fits.get("jan-series", 7.0) is None and fits.get("nope", default=0) == 0
    assert fits[0] is list(fits)[0] and len(fits[1:]) == len(fits) - 1
    assert ("jan-series", "2") in fits and ("jan-series", "3") not in fits
    assert fits.keys()[-1] == ("jan-global", "all")
    with pytest.raises(KeyError, match="jan-global"):
        fits["jan-series", 3.0]
