"""The fit functions and the fit commands are one door: every flag of `fitbead klaw`, `jan`
and `jaeger` is a keyword of `fit_klaw`, `fit_jan` and `fit_jaeger` (or is answered by the
result object, as listed), and the new keywords give the command line's numbers."""

import inspect
import re

import pytest

import fitbead
from conftest import DEFAULT_DATA, read_csv_text

# Flags whose Python counterpart is not a keyword of the same name, and what it is.
ELSEWHERE = {
    "input": "data",  # the measurements: a path, a DataFrame or a Dataset
    "no-profile": "profile",  # profile=False
    "prior": "priors",
    "output": "the result itself (to_pandas, fit_report)",
    "output-stats": "the result's statistics (to_pandas, stats)",
    "plot": "the result's plot()",
    "help": "help()",
}
# Flags that have no Python keyword yet, with why.
NOT_YET: dict = {}


def flags(cli, command):
    """The long flags `fitbead COMMAND --help` lists."""
    _, text, _ = cli(command, "--help")
    return sorted(set(re.findall(r"--([a-z][a-z0-9-]*)", text)) - {"help"})


@pytest.mark.parametrize(
    "command,func",
    [("klaw", fitbead.fit_klaw), ("jan", fitbead.fit_jan), ("jaeger", fitbead.fit_jaeger)],
)
def test_every_flag_is_a_keyword(cli, command, func):
    keywords = set(inspect.signature(func).parameters)
    missing = []
    for flag in flags(cli, command):
        name = flag.replace("-", "_")
        if name in keywords or flag in NOT_YET:
            continue
        if flag in ELSEWHERE:
            target = ELSEWHERE[flag]
            if re.fullmatch(r"[a-z_]+", target):
                assert target in keywords, (command, flag, target)
            continue
        missing.append(flag)
    assert not missing, f"{command}: flags with no keyword: {missing}"
    for must in ["priors", "fit_scatter", "thin", "draws", "rho", "f"]:
        assert must in keywords, (command, must)
    if command == "klaw":
        assert {"skip_unsteady", "tol"} <= keywords


def test_auto_and_skip_unsteady_are_the_command_lines(cli, tmp_path):
    """`model="auto"` and `skip_unsteady` give the command line's parameters, bit for bit, and
    say the model chosen and the points left out as it does on stderr."""
    p = tmp_path / "auto.csv"
    _, _, err = cli("klaw", "--model", "auto", "--input", DEFAULT_DATA, "--output", p)
    with pytest.warns(fitbead.FitbeadWarning, match="model_used") as rec:
        fit = fitbead.fit_klaw(DEFAULT_DATA, model="auto")
    said = [str(w.message) for w in rec if "auto (T =" in str(w.message)]
    assert said and said[0] in err
    cols = read_csv_text(p.read_text())
    assert cols["value"][0] == repr(fit["c"].value) or float(cols["value"][0]) == fit["c"].value

    code, _, _ = cli("klaw", "--model", "slip", "--input", DEFAULT_DATA, check=False)
    assert code == 2
    with pytest.raises(fitbead.FitbeadError, match="skip_unsteady=True"):
        fitbead.fit_klaw(DEFAULT_DATA, model="slip")
    p = tmp_path / "skip.csv"
    _, _, err = cli(
        "klaw", "--model", "slip", "--law", "free-per-series", "--skip-unsteady",
        "--input", DEFAULT_DATA, "--output", p, check=False,
    )
    with pytest.warns(fitbead.FitbeadWarning) as rec:
        try:
            fitbead.fit_klaw(DEFAULT_DATA, model="slip", law="free-per-series", skip_unsteady=True)
        except fitbead.FitbeadError as e:
            assert str(e) in err
    left = [str(w.message) for w in rec if "left out" in str(w.message)]
    assert left and all(m in err for m in left)


def test_sampler_keywords_are_the_flags(cli, tmp_path):
    """thin, priors, fit_scatter and draws give the command line's posterior, draw for draw."""
    d = tmp_path / "d.csv"
    p = tmp_path / "p.csv"
    cli(
        "klaw", "--model", "stick", "--input", DEFAULT_DATA, "--method", "mcmc", "--seed", "3",
        "--min-ess", "100", "--max-steps", "2000", "--thin", "2", "--prior", "c=normal(0.5,0.2)",
        "--fit-scatter", "--draws", d, "--output", p, check=False,
    )
    d2 = tmp_path / "d2.csv"
    fit = fitbead.fit_klaw(
        DEFAULT_DATA, model="stick", method="mcmc", seed=3, min_ess=100, max_steps=2000, thin=2,
        priors={"c": "normal(0.5,0.2)"}, fit_scatter=True, draws=d2,
    )
    assert d2.read_bytes() == d.read_bytes()
    cols = read_csv_text(p.read_text())
    assert float(cols["value"][0]) == fit["c"].value
    with pytest.raises(fitbead.FitbeadError, match="applies to method = .mcmc. only"):
        fitbead.fit_klaw(DEFAULT_DATA, model="stick", thin=2)
    with pytest.raises(fitbead.FitbeadError, match="no parameter 'zz'"):
        fitbead.fit_jan(DEFAULT_DATA, method="mcmc", priors=["zz=flat"])


def test_rho_and_f_are_the_flags(cli, tmp_path):
    """rho and f read the data again as --rho and --f do."""
    p = tmp_path / "p.csv"
    cli("klaw", "--model", "stickslip", "--rho", "0.5", "--f", "0.2", "--input", DEFAULT_DATA, "--output", p)
    fit = fitbead.fit_klaw(DEFAULT_DATA, model="stickslip", rho=0.5, f=0.2)
    cols = read_csv_text(p.read_text())
    assert float(cols["value"][0]) == fit["c"].value
    assert fit["c"].value != fitbead.fit_klaw(DEFAULT_DATA, model="stickslip")["c"].value
