"""simulate, report and the work-precision table from Python, against the command line: the
same rows bit for bit, table keys equal to the CSV headers it writes; the data set keeps the
file's SI columns, and data given as arrays get the command line's unit warnings."""

import csv
import io
import warnings

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA, assert_bits_equal, assert_text_equal, read_csv_text


def header(text):
    return next(csv.reader(io.StringIO(text)))


def assert_table_equals_csv(table, text):
    """Every column of `table` equals the CSV's (numbers bit for bit, text as written), in the
    CSV's order."""
    cols = read_csv_text(text)
    assert list(table) == header(text)
    for k, cells in cols.items():
        if table[k].dtype == object:
            assert_text_equal(k, table[k], cells)
        else:
            assert_bits_equal(k, table[k], cells)


@pytest.mark.parametrize(
    "model, flags, kwargs",
    [
        ("stickslip", ["--series", "0.8,1.6", "--points", "5", "--seed", "7"], dict(series=[0.8, 1.6], points=5, seed=7)),
        ("jan", ["--series", "1", "--points", "4", "--noise", "0"], dict(series=[1.0], points=4, noise=0.0)),
    ],
)
def test_simulate_equals_the_command_line_bit_for_bit(cli, model, flags, kwargs):
    _, text, _ = cli("simulate", "--model", model, *flags)
    sim = fitbead.simulate(model, **kwargs)
    assert_table_equals_csv(sim, text)
    assert sim["series"].dtype == object


def test_simulate_from_a_design_equals_the_command_line(cli, tmp_path):
    p = tmp_path / "design.csv"
    p.write_text("series,xi,delta_deg,replicates\nA,1,10,2\nB,2,5,1\n")
    _, text, _ = cli("simulate", "--model", "stick", "--design", p, "--seed", "3")
    assert_table_equals_csv(fitbead.simulate("stick", design=p, seed=3), text)


def test_simulate_refuses_a_bad_setting_as_the_command_line_does(cli):
    code, _, err = cli("simulate", "--points", "0", check=False)
    assert code == 2
    with pytest.raises(fitbead.FitbeadError, match="^points = '0': ") as e:
        fitbead.simulate(points=0)
    # The command line's message, the flag named as the keyword argument.
    assert "flag '--points', value '0': " + str(e.value).split(": ", 1)[1] in err
    with pytest.raises(fitbead.FitbeadError, match="given twice"):
        fitbead.simulate(series=[1.0, 1.0])


@pytest.fixture(scope="module")
def cli_report(cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli_report")
    cli("report", "--input", DEFAULT_DATA, "--out-dir", out)
    return out


def test_report_tables_are_the_command_lines_files(cli_report, tmp_path):
    """Python's report of the same data: one table per CSV file, keyed by its header, equal
    to it; the directory it writes holds the command line's files, byte for byte."""
    d = fitbead.Dataset.read_csv(str(DEFAULT_DATA))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fitbead.FitbeadWarning)
        rep = fitbead.report(d, out_dir=tmp_path / "py")
    csvs = sorted(p.name for p in cli_report.glob("*.csv"))
    assert sorted(f"{k}.csv" for k in rep) == csvs
    for name in csvs:
        text = (cli_report / name).read_text()
        assert list(rep[name[:-4]]) == header(text), name
        assert_table_equals_csv(rep[name[:-4]], text)
    for p in sorted(cli_report.iterdir()):
        if p.name.startswith("."):
            continue
        assert (tmp_path / "py" / p.name).read_bytes() == p.read_bytes(), p.name
        assert rep.files[p.name] == p.read_bytes(), p.name
    assert rep.markdown == (cli_report / "report.md").read_text()


def test_report_without_a_directory_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fitbead.FitbeadWarning)
        with pytest.raises(fitbead.FitbeadError, match="^units = 'si': "):
            fitbead.report(None, units="si")
    assert list(tmp_path.iterdir()) == []


def test_work_precision_keys_are_the_bench_header(cli, tmp_path):
    p = tmp_path / "wp.csv"
    cli("bench", "--scenes", "3", "--output", p)
    text = p.read_text()
    wp = fitbead.work_precision(scenes=3)
    assert list(wp) == header(text)
    cols = read_csv_text(text)
    # The errors depend on the scenes only (the times are measured).
    assert_text_equal("model", wp["model"], cols["model"])
    assert_bits_equal("err_max", wp["err_max"], cols["err_max"])


def test_the_data_set_keeps_the_files_R_m_and_g(tmp_path):
    p = tmp_path / "si.csv"
    p.write_text(
        "series,xi,delta_deg,v_m_s,R_m,g\n"
        "a,1,10,0.06,0.0025,9.81\n"
        "a,1,11,0.065,0.0025,9.81\n"
        "b,2,6,0.05,0.003,9.80\n"
    )
    d = fitbead.Dataset.read_csv(str(p))
    c = d.columns()
    assert list(c["R_m"]) == [0.0025, 0.0025, 0.003]
    assert list(c["g"]) == [9.81, 9.81, 9.80]
    assert list(c["v_m_s"]) == [0.06, 0.065, 0.05]
    df = d.to_pandas()
    assert list(df["R_m"]) == [0.0025, 0.0025, 0.003] and list(df["g"]) == [9.81, 9.81, 9.80]
    # Dimensionless data have no such columns.
    assert "R_m" not in fitbead.Dataset.default().columns()


def default_columns():
    cols = read_csv_text(DEFAULT_DATA.read_text())
    return {k: (v if k == "series" else np.array([float(x) for x in v])) for k, v in cols.items()}


def test_from_arrays_warns_on_velocities_in_mm_per_s():
    c = default_columns()
    with pytest.warns(fitbead.FitbeadWarning, match="velocit") as rec:
        d = fitbead.Dataset.from_arrays(c["xi"], c["delta_deg"], c["v"] * 1000, series=c["series"])
    assert all(issubclass(w.category, fitbead.UnitWarning) for w in rec if "velocit" in str(w.message))
    assert d.warnings and d.warnings[0].startswith("<arrays>: column 'v'")


def test_from_arrays_warns_on_slopes_in_radians():
    c = default_columns()
    with pytest.warns(fitbead.FitbeadWarning, match="radians"):
        fitbead.Dataset.from_arrays(c["xi"], np.radians(c["delta_deg"]), c["v"], c["sigma_v"], series=c["series"])


def test_from_arrays_of_plausible_data_is_quiet():
    c = default_columns()
    with warnings.catch_warnings():
        warnings.simplefilter("error", fitbead.FitbeadWarning)
        d = fitbead.Dataset.from_arrays(c["xi"], c["delta_deg"], c["v"], c["sigma_v"], series=c["series"])
    assert d.warnings == []


def test_forward_md_equals_the_command_line(cli, tmp_path):
    """md through forward: the command line's `forward --model md` rows, bit for bit."""
    p = tmp_path / "scenes.csv"
    p.write_text("xi,delta_deg\n1,20\n2,8\n")
    _, text, _ = cli("forward", "--model", "md", "--input", p)
    out = fitbead.forward("md", xi=[1.0, 2.0], delta_deg=[20.0, 8.0])
    cols = read_csv_text(text)
    # The scenes go in with their rho and f columns, which pass through.
    assert [k for k in out if k not in ("rho", "f")] == header(text)
    for k, cells in cols.items():
        if out[k].dtype == object:
            assert_text_equal(k, out[k], cells)
        else:
            assert_bits_equal(k, out[k], cells)
