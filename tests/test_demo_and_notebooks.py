"""The README's main job and the notebooks run; the notebooks are executed headless (the A-frame
notebook, 04, asserts its own physical checks: statics against the rigid moment balance and beam
theory, the payload's hanging line, the work balance, the loops' closure and the growth rate of the
force-controlled drift)."""

import pathlib

import nbclient
import nbformat
import pytest

from rigidfem.studies import demo
from rigidfem.__main__ import main

NOTEBOOKS = sorted((pathlib.Path(__file__).parent.parent / "notebooks").glob("*.ipynb"))


def test_demo_prints_a_summary_and_writes_a_plot(tmp_path, capsys):
    out = tmp_path / "demo.png"
    assert main(["demo", "--t-end", "20", "--output", str(out)]) == 0
    text = capsys.readouterr().out
    assert "nonlinear model" in text and "linear model" in text
    assert out.stat().st_size > 10_000
    summary = demo.run(t_end=20.0, output=None, elements=5)
    assert summary["nonlinear_max_m"] < 3.0 and summary["linear_final_m"] > 1e3


def test_there_are_notebooks():
    assert NOTEBOOKS, "notebooks/ holds the teaching notebooks"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_executes(path):
    nb = nbformat.read(path, as_version=4)
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}).execute()


def test_a_frame_notebook_is_committed_with_its_figures():
    """notebooks/04_a_frame.ipynb is committed executed, so its plots show on the repository page:
    every code cell has run, without errors, and the five figures are there as PNGs."""
    path = pathlib.Path(__file__).parent.parent / "notebooks" / "04_a_frame.ipynb"
    nb = nbformat.read(path, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(c.execution_count is not None for c in code)
    outputs = [o for c in code for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert sum("image/png" in o.get("data", {}) for o in outputs) >= 5
