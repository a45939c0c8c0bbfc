"""fitbead.design equals `fitbead design` (same library): the same slopes and replicates, and
a design written by Design.to_csv is one `simulate --design` reads."""

import numpy as np
import pytest

import fitbead
from conftest import read_csv_text


def test_design_equals_the_command_line(cli, tmp_path):
    d = fitbead.design(
        "klaw", model="stickslip", law="c=0.5", series=[0.8, 1, 1.6, 2], points=9, noise=0.02, criterion="c", target="c"
    )
    _, text, _ = cli(
        "design", "--fit", "klaw", "--model", "stickslip", "--law", "c=0.5", "--series", "0.8,1,1.6,2",
        "--points", "9", "--noise", "0.02", "--criterion", "c", "--target", "c", "--output", "-",
    )
    cols = read_csv_text(text)
    assert list(d.table) == list(cols)
    assert list(d.table["series"]) == cols["series"]
    np.testing.assert_array_equal(d.table["xi"], [float(x) for x in cols["xi"]])
    np.testing.assert_array_equal(d.table["delta_deg"], [float(x) for x in cols["delta_deg"]])
    assert list(d.table["replicates"]) == [int(x) for x in cols["replicates"]]
    assert d.table["replicates"].sum() == 4 * 9 and d.target == "c"
    e = d.errors["c"]
    assert e["stderr_design"] < e["stderr_even"] and 0 < d.efficiency < 1
    df = d.to_pandas()
    assert list(df.columns) == ["series", "xi", "delta_deg", "replicates"]
    p = tmp_path / "design.csv"
    d.to_csv(str(p))
    cli("simulate", "--design", p, "--model", "stickslip", "--law", "c=0.5", "--noise", "0.02", "--seed", "7",
        "--output", tmp_path / "data.csv")
    data = fitbead.Dataset.read_csv(str(tmp_path / "data.csv"))
    assert len(data) == 36


def test_design_errors_name_the_setting():
    with pytest.raises(fitbead.FitbeadError, match="criterion"):
        fitbead.design("klaw", criterion="x")
    with pytest.raises(fitbead.FitbeadError):
        fitbead.design("klaw", series=[0.1])


def test_new_options_equal_the_command_line(cli):
    """A Bayesian design, a total budget and the μ (eq 79) target through both doors."""
    d = fitbead.design(
        "jan", series=[1], criterion="c", target="mu", prior={"mu": "uniform(0.095,0.112)"}, draws=8, seed=5
    )
    _, text, _ = cli(
        "design", "--fit", "jan", "--series", "1", "--criterion", "c", "--target", "mu",
        "--prior", "mu=uniform(0.095,0.112)", "--draws", "8", "--seed", "5", "--output", "-",
    )
    cols = read_csv_text(text)
    np.testing.assert_array_equal(d.table["delta_deg"], [float(x) for x in cols["delta_deg"]])
    assert d.bayes == (8, 0)
    t = fitbead.design("klaw", criterion="c", target="mu of series 'xi=1'", total=24)
    assert t.table["replicates"].sum() == 24 and t.bayes is None
    assert "mu of series 'xi=1'" in t.errors
    with pytest.raises(fitbead.FitbeadError, match="improper"):
        fitbead.design("klaw", prior={"c": "flat"})


def test_slope_errors_and_margin_equal_the_command_line(cli):
    """sigma_delta and margin through both doors; the steady range of c per chosen slope; the
    default margin is 0.05; bad values name the setting."""
    d = fitbead.design("klaw", criterion="c", target="c", sigma_delta=0.1, margin=0.08)
    _, text, _ = cli(
        "design", "--criterion", "c", "--target", "c", "--sigma-delta", "0.1", "--margin", "0.08", "--output", "-",
    )
    cols = read_csv_text(text)
    np.testing.assert_array_equal(d.table["delta_deg"], [float(x) for x in cols["delta_deg"]])
    assert len(d.steady) == len(d.table["xi"])
    for row in d.steady:
        lo, hi = row["c"]
        assert lo < 0.5 < hi
    a = fitbead.design("klaw", criterion="c", target="c")
    b = fitbead.design("klaw", criterion="c", target="c", margin=0.05)
    np.testing.assert_array_equal(a.table["delta_deg"], b.table["delta_deg"])
    assert a.ranges == b.ranges
    with pytest.raises(fitbead.FitbeadError, match="margin"):
        fitbead.design("klaw", margin=0.5)
    with pytest.raises(fitbead.FitbeadError, match="^sigma_delta = "):
        fitbead.design("klaw", sigma_delta=-1.0)
