"""Input the command line refuses is refused here too, with a ValueError naming the argument:
sampler settings out of range, masked arrays with masked entries, complex numbers. Model and
method names are taken in any case, as the command line takes them."""

import numpy as np
import pytest

import fitbead
from conftest import DEFAULT_DATA


@pytest.fixture(scope="module")
def data():
    return fitbead.Dataset.read_csv(str(DEFAULT_DATA))


@pytest.mark.parametrize(
    "kwargs, flag, word",
    [
        ({"walkers": 3}, "--walkers=3", "walkers = 3"),
        ({"walkers": 2}, "--walkers=2", "walkers = 2"),
        ({"max_steps": 0}, "--max-steps=0", "max_steps = 0"),
        ({"min_ess": -1.0}, "--min-ess=-1", "min_ess = -1"),
    ],
)
def test_sampler_settings_the_cli_refuses_raise_value_error(cli, data, kwargs, flag, word):
    code, _, err = cli("klaw", "--model", "stick", "--method", "mcmc", flag, "--input", DEFAULT_DATA, check=False)
    assert code == 2, err
    for fit in (
        lambda: fitbead.fit_klaw(data, model="stick", method="mcmc", **kwargs),
        lambda: fitbead.fit_jan(data, method="mcmc", **kwargs),
        lambda: fitbead.fit_jaeger(data, method="mcmc", **kwargs),
    ):
        with pytest.raises(ValueError, match=word):
            fit()


def test_model_and_method_names_are_taken_in_any_case(data):
    lower = fitbead.forward("stick", xi=1.0, delta_deg=[10.0, 20.0])
    upper = fitbead.forward("STICK", xi=1.0, delta_deg=[10.0, 20.0])
    assert np.array_equal(lower["v"], upper["v"], equal_nan=True)
    k_lower = fitbead.invert_k("stickslip", data)
    k_upper = fitbead.invert_k("StickSlip", data)
    assert np.array_equal(k_lower["K"], k_upper["K"], equal_nan=True)
    a = fitbead.fit_klaw(data, model="stick", profile=False)
    b = fitbead.fit_klaw(data, model="STICK", method="LSQ", profile=False)
    assert [p.value for p in a.params.values()] == [p.value for p in b.params.values()]


def test_masked_array_with_masked_entries_is_refused_naming_the_argument():
    masked = np.ma.masked_array([10.0, 20.0], mask=[False, True])
    with pytest.raises(ValueError, match=r"^delta_deg: a masked array with 1 masked entries"):
        fitbead.forward("stick", xi=1.0, delta_deg=masked)
    with pytest.raises(ValueError, match=r"^v: a masked array"):
        fitbead.Dataset.from_arrays(xi=1.0, delta_deg=[10.0, 20.0], v=np.ma.masked_array([0.5, 0.6], mask=[True, False]))
    # A mask that hides nothing loses nothing: accepted, with the same values.
    clear = np.ma.masked_array([10.0, 20.0], mask=[False, False])
    assert np.array_equal(
        fitbead.forward("stick", xi=1.0, delta_deg=clear)["v"],
        fitbead.forward("stick", xi=1.0, delta_deg=[10.0, 20.0])["v"],
        equal_nan=True,
    )


def test_complex_input_is_refused_naming_the_argument():
    with pytest.raises(ValueError, match=r"^delta_deg: complex numbers are not accepted"):
        fitbead.forward("stick", xi=1.0, delta_deg=np.array([10.0 + 1.0j, 20.0]))
    with pytest.raises(ValueError, match=r"^v: complex numbers are not accepted"):
        fitbead.Dataset.from_arrays(xi=1.0, delta_deg=[10.0, 20.0], v=[0.5 + 0j, 0.6])
    with pytest.raises(ValueError, match=r"^xi: complex numbers are not accepted"):
        fitbead.invert_k("stick", xi=1j, delta_deg=[10.0], v=[0.5])
