"""The README's main job and the notebooks run; the notebooks are executed headless."""

import pathlib

import nbclient
import nbformat
import pytest

from rigidfem import demo
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
