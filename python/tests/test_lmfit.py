"""lmfit's controls and names on the fit functions: ``fix``, ``init``, ``bounds`` and
``scale_covar``, the result's lmfit names (``chisqr``, ``redchi``, ``eval_uncertainty``,
``fit_report(min_correl=)``, ``plot(ax=)``, ``conf_interval``, ...), Jaeger with a2 held at 0
against Jan (eq 74 is eq 80 with a2 = 0), and ``scale_covar=True`` against lmfit itself."""

import math
import warnings

import numpy as np
import pytest

import fitbead


@pytest.fixture(scope="module")
def data():
    return fitbead.Dataset.default()


def quiet(f, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*a, **k)


def test_an_lmfit_script_runs_unchanged(data):
    """What a new user writes from lmfit's documentation, on a fitbead fit."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    result = quiet(fitbead.fit_klaw, data, model="stickslip", law="c")
    print(result.params["c"].value, result.params["c"].stderr)
    assert result.params["c"].value > 0 and result.params["c"].stderr > 0
    assert result.chisqr == result.stats["chi2"] and result.redchi == result.stats["reduced_chi2"]
    assert result.success and result.nfev > 0
    assert (result.ndata, result.nvarys, result.nfree) == (36, 1, 35)
    assert result.var_names == ["c"] and result.best_fit.shape == (36,)
    assert set(result.init_values) == {"c"} and math.isfinite(result.aic) and math.isfinite(result.bic)
    dely = result.eval_uncertainty(sigma=2)
    assert dely.shape == (36,) and (dely > 0).all()
    text = result.fit_report(min_correl=0.3)
    assert "[[Variables]]" in text
    fig, ax = plt.subplots()
    result.plot(ax=ax)
    assert fig.axes == [ax] and len(ax.lines) >= 1 and len(ax.collections) >= 1
    plt.close(fig)


def test_eval_uncertainty_is_lmfits_rule(data):
    """dely = t · sqrt(J C Jᵀ), t the Student-t quantile of the probability on nfree degrees of
    freedom: sigma=1 and its probability agree, and σ of the curve is eval_band's."""
    from statistics import NormalDist

    fit = quiet(fitbead.fit_jaeger, data, profile=False).get("jaeger", "1")
    p1 = math.erf(1 / math.sqrt(2))
    one = fit.eval_uncertainty(sigma=1)
    assert np.allclose(one, fit.eval_uncertainty(sigma=p1), rtol=1e-12)
    t1 = fitbead._fitbead.t_quantile((1 + p1) / 2, fit.nfree)
    r = fit.residuals
    band = fit.eval_band(r["delta_deg"], r["xi"], level=0.9)
    sd = (band["v_high"] - band["v_low"]) / (2 * NormalDist().inv_cdf(0.95))
    assert np.allclose(one, t1 * sd, rtol=1e-9)
    three = fit.eval_uncertainty(sigma=3, delta_deg=[12.0, 14.0])
    assert three.shape == (2,) and (three > 0).all()


def test_fit_report_filters_correlations(data):
    fit = quiet(fitbead.fit_jan, data, profile=False).get("jan-global", "all")
    default = fit.fit_report()
    assert default == fit.report()
    pairs = {k: abs(v) for k, v in fit.correlations.items()}
    cut = sorted(pairs.values())[len(pairs) // 2]
    text = fit.fit_report(min_correl=cut)
    shown = [ln for ln in text.splitlines() if ln.startswith("    C(")]
    assert len(shown) == sum(1 for v in pairs.values() if v > cut)
    assert f"unreported correlations are < {cut:g}" in text
    none = fit.fit_report(min_correl=1.0)
    assert "[[Correlations]]" not in none and "[[Variables]]" in none


def test_jaeger_with_a2_held_at_zero_reproduces_jans_curve(data):
    """eq 74 is eq 80 with a2 = 0 (docs/PHYSICS.md): the fitted curves agree to 1e-10."""
    jan = quiet(fitbead.fit_jan, data, profile=False)
    jaeger = quiet(fitbead.fit_jaeger, data, profile=False, fix={"a2": 0.0})
    grid = np.linspace(9.0, 20.0, 23)
    for j in [f for f in jan if f.name == "jan-series"]:
        g = jaeger.get("jaeger", j.series)
        assert np.allclose(g.best_fit, j.best_fit, rtol=1e-10, atol=0)
        vj, vg = j.eval(grid), g.eval(grid)
        ok = ~np.isnan(vj)
        assert (np.isnan(vg) == ~ok).all()
        assert np.max(np.abs(vg[ok] / vj[ok] - 1)) < 1e-10
        a2 = g.params["a2"]
        assert not a2.vary and a2.value == 0 and math.isnan(a2.stderr) and a2.method == "none"
        assert g.var_names == ["a1", "a3"] and g.nvarys == 2 and g.nfree == j.nfree
        assert g.covar.shape == (2, 2) and g.chisqr == pytest.approx(j.chisqr, rel=1e-10)
        assert g.eval_band(grid)["v_low"].shape == grid.shape


def test_fix_init_bounds_keywords(data):
    base = quiet(fitbead.fit_klaw, data, model="stick", profile=False)
    c0 = base.params["c"].value
    started = quiet(fitbead.fit_klaw, data, model="stick", profile=False, init={"c": 0.9})
    assert started.params["c"].value == pytest.approx(c0, rel=1e-8)
    assert started.init_values == {"c": 0.9}
    bounded = quiet(fitbead.fit_klaw, data, model="stick", profile=False, bounds={"c": (None, c0 - 0.01)})
    assert bounded.params["c"].value == c0 - 0.01 and bounded.params["c"].max == c0 - 0.01
    held = quiet(fitbead.fit_klaw, data, model="stick", fix={"c": 0.5})
    assert not held.params["c"].vary and held.params["c"].value == 0.5 and held.nvarys == 0
    assert held.stats["termination"] == "scored"
    one = quiet(fitbead.fit_jan, data, fix={"mu[1]": 0.09})
    assert not one.get("jan-series", "1").params["mu"].vary
    assert one.get("jan-series", "0.8").params["mu"].vary
    with pytest.raises(fitbead.FitbeadError, match="^fix = 'a4=0': .*expected one of a1, a2, a3"):
        fitbead.fit_jaeger(data, fix={"a4": 0})
    with pytest.raises(fitbead.FitbeadError, match="^init = .*outside the box"):
        fitbead.fit_jan(data, init={"mu": 0.5})
    with pytest.raises(fitbead.FitbeadError, match="^bounds = .*leaves nothing"):
        fitbead.fit_jan(data, bounds={"mu": (-2, -1)})
    with pytest.raises(fitbead.FitbeadError, match="scale_covar"):
        fitbead.fit_jan(data, method="mcmc", scale_covar=True)


def test_conf_interval_has_lmfits_shape(data):
    fit = quiet(fitbead.fit_jan, data).get("jan-series", "1")
    ci = fit.conf_interval()
    assert list(ci) == ["lambda", "mu"]
    for key, rows in ci.items():
        probs = [p for p, _ in rows]
        assert probs == pytest.approx([0.9973, 0.9545, 0.6827, 0.0, 0.6827, 0.9545, 0.9973], abs=1e-4)
        values = [v for _, v in rows]
        assert values == sorted(values) and values[3] == fit.params[key].value
    # The 95 % level of the fit's own profile is one of them.
    two = fit.conf_interval(sigmas=[0.95])
    p = fit.params["mu"]
    assert two["mu"][0][1] == pytest.approx(p.profile_low, rel=1e-12)
    assert two["mu"][2][1] == pytest.approx(p.profile_high, rel=1e-12)


def test_held_parameters_under_mcmc_and_posterior_intervals(data):
    """A posterior run samples the free parameters: the held one is a constant column of the
    draws; conf_interval gives the posterior's central intervals in lmfit's shape."""
    fits = quiet(fitbead.fit_jaeger, data, method="mcmc", seed=2, min_ess=200, fix={"a2": 0.0})
    fit = fits.get("jaeger", "1")
    k = fit.param_names.index("a2")
    assert (fit.draws[:, :, k] == 0).all() and fit.var_names == ["a1", "a3"]
    ci = fit.conf_interval(sigmas=[1, 2])
    a1 = [v for _, v in ci["a1"]]
    assert a1 == sorted(a1) and len(a1) == 5
    flat = fit.draws[:, :, fit.param_names.index("a1")].ravel()
    assert a1[0] == pytest.approx(np.quantile(flat, (1 - math.erf(2 / math.sqrt(2))) / 2))


def _lmfit_jan(fit, scale_covar):
    """The reference: lmfit (1.x, ``Model.fit`` with ``leastsq``) fits Jan's eq 74 in closed
    form, v̄ = sqrt((2 sin α/λ)(sin δ − μ cos δ)), to the same series with weights 1/σ_v,
    sin α from fitbead.regimes at the series' ξ. Its tolerances are tightened to 1e-15 and its
    difference step to √ε (``epsfcn`` below ε; lmfit's default 1e-10 makes steps of 1e-5 and
    forward-difference errors of that size in its covariance: 1.2e-5 in μ's stderr, where
    fitbead's analytic Jacobian agrees with the closed-form covariance to 1e-14). The optimum
    is inside the box (fitbead's fit has no parameter on a bound), so lmfit gets no bounds."""
    import lmfit

    assert not any(p.at_bound for p in fit.params.values())
    r = fit.residuals
    xi = float(np.asarray(r["xi"])[0])
    sin_a = math.sin(math.radians(float(fitbead.regimes([xi])["alpha_deg"][0])))
    d = np.radians(np.asarray(r["delta_deg"], dtype=float))
    v = np.asarray(r["v"], dtype=float)
    sigma = np.asarray(r["sigma_v"], dtype=float)

    def eq74(delta, lam, mu):
        return np.sqrt(2 * sin_a / lam * (np.sin(delta) - mu * np.cos(delta)))

    model = lmfit.Model(eq74, independent_vars=["delta"])
    # Started 20 % away from fitbead's optimum (from farther, unbounded, the model leaves its
    # domain at some series): lmfit finds the optimum itself.
    lam0, mu0 = fit.params["lambda"].value, fit.params["mu"].value
    params = model.make_params(lam=1.2 * lam0, mu=0.8 * mu0)
    tight = {"ftol": 1e-15, "xtol": 1e-15, "gtol": 1e-15, "epsfcn": 1e-20}
    out = model.fit(v, params, delta=d, weights=1 / sigma, scale_covar=scale_covar, fit_kws=tight)
    assert out.success
    return out


@pytest.mark.parametrize("scale_covar", [True, False])
def test_scale_covar_is_lmfits(data, scale_covar):
    """On the shipped data, Jan's λ and μ per series and their standard errors as lmfit gives
    them (the reference is lmfit run here, `_lmfit_jan`): with ``scale_covar=True`` the
    covariance scaled by the reduced χ², without it σ_v absolute, to 1e-6 relative."""
    pytest.importorskip("lmfit")
    fits = quiet(fitbead.fit_jan, data, profile=False, scale_covar=scale_covar)
    for fit in [f for f in fits if f.name == "jan-series"]:
        ref = _lmfit_jan(fit, scale_covar)
        for ours, theirs in [("lambda", "lam"), ("mu", "mu")]:
            p, q = fit.params[ours], ref.params[theirs]
            assert p.value == pytest.approx(q.value, rel=1e-8), (fit.series, ours)
            assert p.stderr == pytest.approx(q.stderr, rel=1e-6), (fit.series, ours, p.stderr, q.stderr)
        assert fit.chisqr == pytest.approx(ref.chisqr, rel=1e-10)
        assert fit.redchi == pytest.approx(ref.redchi, rel=1e-10)
        assert fit.nfree == ref.nfree and fit.ndata == ref.ndata
        assert fit.scale_covar == scale_covar
        if scale_covar:
            assert "covariance scaled by reduced chi-square" in fit.fit_report()


def test_held_parameters_survive_pickling_and_saving(data, tmp_path):
    import pickle

    fits = quiet(fitbead.fit_jaeger, data, profile=False, fix={"a2": 0.0}, scale_covar=True)
    fit = fits.get("jaeger", "1")
    again = pickle.loads(pickle.dumps(fit))
    assert again == fit and again.var_names == ["a1", "a3"] and again.scale_covar
    assert not again.params["a2"].vary and again.init_values == fit.init_values
    path = tmp_path / "fit.json"
    fit.save(path)
    loaded = fitbead.load(path)
    assert loaded == fit and not loaded.params["a2"].vary
    with pytest.raises(fitbead.FitbeadError, match="made again"):
        loaded.conf_interval()
