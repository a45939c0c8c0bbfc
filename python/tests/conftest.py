"""Shared helpers: the command-line binary the bindings are checked against, CSV reading, and
a Ctrl-C on a timer."""

import _thread
import contextlib
import csv
import io
import os
import pathlib
import signal
import subprocess
import threading

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_DATA = ROOT / "data" / "default.csv"


@contextlib.contextmanager
def ctrl_c_after(seconds):
    """Ctrl-C (SIGINT to the main thread) `seconds` after the block starts. Python's own SIGINT
    handler is installed for the block, also when the suite runs with SIGINT ignored (as a
    background job of a non-interactive shell, where interrupt_main does nothing), and the
    previous handler is restored after it; the timer is cancelled on leaving."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(seconds, _thread.interrupt_main)
    try:
        timer.start()
        yield
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)


def _binary() -> str:
    env = os.environ.get("FITBEAD_BIN")
    if env:
        return env
    exe = ROOT / "target" / "release" / "fitbead"
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "--bin", "fitbead"], cwd=ROOT, check=True)
    return str(exe)


@pytest.fixture(scope="session")
def cli():
    """Runs the command line; returns (exit code, stdout, stderr)."""
    exe = _binary()

    def run(*args, check=True):
        p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"fitbead {' '.join(map(str, args))} failed ({p.returncode}): {p.stderr}")
        return p.returncode, p.stdout, p.stderr

    return run


def read_csv_text(text):
    """A CSV's columns as lists of strings, by header name."""
    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], rows[1:]
    return {h: [r[i] for r in body] for i, h in enumerate(header)}


def numbers(cells):
    """CSV cells as float64: an empty cell is NaN."""
    return np.array([float(c) if c != "" else np.nan for c in cells], dtype=np.float64)


def assert_bits_equal(name, got, cells):
    """The float64 array `got` equals the CSV cells bit for bit (empty cell = NaN)."""
    want = numbers(cells)
    got = np.asarray(got, dtype=np.float64).ravel()
    assert got.shape == want.shape, f"{name}: {got.shape} rows against {want.shape}"
    both_nan = np.isnan(got) & np.isnan(want)
    same = (got.view(np.int64) == want.view(np.int64)) | both_nan
    if not same.all():
        i = int(np.flatnonzero(~same)[0])
        raise AssertionError(
            f"{name}: {int((~same).sum())} rows differ; first at row {i}: python {got[i]!r}, cli {cells[i]!r}"
        )


def assert_text_equal(name, got, cells):
    got = [str(x) for x in np.ravel(got)]
    assert len(got) == len(cells), f"{name}: {len(got)} rows against {len(cells)}"
    bad = [i for i, (a, b) in enumerate(zip(got, cells)) if a != b]
    assert not bad, f"{name}: {len(bad)} rows differ; first at row {bad[0]}: python {got[bad[0]]!r}, cli {cells[bad[0]]!r}"


def write_csv(path, columns):
    """Writes numpy columns with repr() floats, so that the command line reads the same doubles."""
    names = list(columns)
    n = len(next(iter(columns.values())))
    with open(path, "w", newline="") as fh:
        fh.write(",".join(names) + "\n")
        for i in range(n):
            fh.write(",".join(repr(float(columns[k][i])) if not isinstance(columns[k][i], str) else columns[k][i] for k in names) + "\n")
