"""python/examples/tutorial.ipynb is committed with its outputs (every code cell run, its figures
stored), and runs from top to bottom without error (nbclient, a fresh kernel, an empty working
directory outside the checkout).

The stored outputs are not compared with a fresh run's: timings and posterior draws differ from
run to run. To store them anew after editing the notebook, execute it the same way and write it
back (nbclient's ``NotebookClient(nb, kernel_name="python3", resources={"metadata": {"path":
EMPTY_DIR}}).execute()``, then ``nbformat.write``)."""

import copy
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "python" / "examples" / "tutorial.ipynb"


def test_tutorial_notebook_is_stored_with_its_outputs():
    nbformat = pytest.importorskip("nbformat")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code, "the tutorial has code cells"
    for i, cell in enumerate(code):
        assert cell.execution_count is not None, f"code cell {i} was not run before the commit"
    counts = [c.execution_count for c in code]
    assert counts == sorted(counts), f"cells run out of order: {counts}"
    errors = [o for c in code for o in c.outputs if o.output_type == "error"]
    assert not errors, "the stored run ended in an error"
    figures = [o for c in code for o in c.outputs if "image/png" in o.get("data", {})]
    assert len(figures) >= 2, f"{len(figures)} stored figures"


def test_tutorial_notebook_executes(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = copy.deepcopy(nbformat.read(NOTEBOOK, as_version=4))
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs = []
            cell.execution_count = None
    # The notebook takes its data from the package: it runs in an empty directory outside the
    # checkout.
    client = nbclient.NotebookClient(nb, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert not errors
    assert (tmp_path / "tutorial_figure.pdf").read_bytes()[:5] == b"%PDF-"
    assert (tmp_path / "tutorial_figure.png").stat().st_size > 10_000
    assert (tmp_path / "tutorial_slope_errors.png").stat().st_size > 10_000
