"""The K inversion (eq 69) through the bindings equals `fitbead k` bit for bit: every model on
the shipped data set; the fast models on 10,000 random measured rows and the general contact
model and auto (about 20 ms a row on random rows) on 300."""

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA, assert_bits_equal, assert_text_equal, read_csv_text, write_csv

NUMERIC = [
    "K",
    "K_lo",
    "K_hi",
    "dv_dK",
    "final_velocity",
    "theta_G_deg",
    "K_cos2a",
    "K_adjusted",
    "K_impact",
    "iterations",
    "K_min",
    "K_max",
]
TEXT = ["regime", "status", "lower_limit", "upper_limit", "message"]


def random_rows(n, seed):
    """Measured rows around the steady range: v from the stick model at a random K, scaled by
    a factor in [0.5, 1.5] so that some rows fall below or above the range; σ on most rows."""
    rng = np.random.default_rng(seed)
    xi = rng.uniform(0.6, 4.0, n)
    d = rng.uniform(2.0, 30.0, n)
    rho = rng.uniform(0.3, 0.5, n)
    f = rng.uniform(0.02, 0.5, n)
    k = rng.uniform(0.05, 0.95, n)
    v = fitbead.forward("stick", xi, d, K=k, rho=rho, f=f)["v"]
    v = np.where(np.isnan(v), rng.uniform(0.05, 1.0, n), v) * rng.uniform(0.5, 1.5, n)
    sigma = np.where(rng.random(n) < 0.9, v * rng.uniform(0.005, 0.05, n), np.nan)
    return {"xi": xi, "delta_deg": d, "v": v, "sigma_v": sigma, "rho": rho, "f": f}


def compare(out, text, model):
    cols = read_csv_text(text)
    for c in NUMERIC:
        assert_bits_equal(f"{model} {c}", out[c], cols[c])
    text_cols = TEXT + (["model_used", "reason"] if model == "auto" else [])
    for c in text_cols:
        assert_text_equal(f"{model} {c}", out[c], cols[c])
    return cols


@pytest.mark.parametrize("model", fitbead.K_MODELS)
def test_default_data_equal_cli(model, cli):
    _, text, _ = cli("k", "--model", model, "--input", DEFAULT_DATA)
    out = fitbead.invert_k(model, fitbead.Dataset.default())
    compare(out, text, model)


@pytest.mark.parametrize(
    "model,n", [("stick", 10_000), ("stick-approx", 10_000), ("slip", 10_000), ("slip-approx", 10_000), ("stickslip", 10_000), ("contact", 300), ("auto", 300)]
)
def test_random_rows_equal_cli(model, n, cli, tmp_path):
    r = random_rows(n, seed=69)
    path = tmp_path / "rows.csv"
    cols = {"series": ["s"] * n, **r}
    # Each row its own series: the command line checks that a series keeps one ξ.
    cols["series"] = [f"s{i}" for i in range(n)]
    # An empty sigma_v cell is "no σ".
    with open(path, "w") as fh:
        fh.write("series,xi,delta_deg,v,sigma_v,rho,f\n")
        for i in range(n):
            s = "" if np.isnan(r["sigma_v"][i]) else repr(float(r["sigma_v"][i]))
            fh.write(
                f"s{i},{float(r['xi'][i])!r},{float(r['delta_deg'][i])!r},{float(r['v'][i])!r},{s},{float(r['rho'][i])!r},{float(r['f'][i])!r}\n"
            )
    _, text, _ = cli("k", "--model", model, "--input", path)
    out = fitbead.invert_k(model, r["xi"], r["delta_deg"], r["v"], r["sigma_v"], rho=r["rho"], f=r["f"])
    got = compare(out, text, model)
    statuses = set(got["status"])
    assert "ok" in statuses and len(statuses) >= 2, statuses


def test_bad_values_raise():
    with pytest.raises(ValueError, match=r"v\[1\] = -0.3: must be a finite number > 0"):
        fitbead.invert_k("stick", [1.0, 1.0], 12.0, [0.3, -0.3])
    with pytest.raises(ValueError, match=r"sigma_v\[0\] = 0"):
        fitbead.invert_k("stick", 1.0, 12.0, 0.3, sigma_v=0.0)
    with pytest.raises(ValueError, match="expected one of"):
        fitbead.invert_k("jan", 1.0, 12.0, 0.3)
