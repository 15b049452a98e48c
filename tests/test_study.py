"""The speed-versus-error study: work-precision tables, the discretisation error, the bench command."""

import csv

import matplotlib
import numpy as np
import pytest

import rigidfem as rf
from rigidfem.__main__ import main

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def scene():
    return rf.study.scenes.kane(omega=6.0, elements=4, t_end=5.0)


def test_work_precision_table(scene, tmp_path):
    table = rf.study.work_precision(scene, [("dopri5", "rtol", [1e-4, 1e-8]), ("rk4", "dt", [0.02, 0.005]),
                                            ("dopri5", "rtol", [1e-6], {"max_steps": 5})], repeats=1)
    rows = {(r["method"], r["value"]): r for r in table.rows}
    # Tighter settings give smaller errors (against the rtol = 1e-12 reference).
    assert rows[("dopri5", 1e-8)]["tip_error_final_m"] < 1e-3 * rows[("dopri5", 1e-4)]["tip_error_final_m"]
    assert rows[("rk4", 0.005)]["tip_error_rms_m"] < rows[("rk4", 0.02)]["tip_error_rms_m"] / 50  # ~4th order
    assert rows[("dopri5", 1e-8)]["tip_error_final_m"] < 1e-6
    for r in table.rows[:4]:
        assert r["wall_time_s"] > 0 and r["steps"] > 0 and r["rhs_evaluations"] >= r["steps"]
    # A failing run is a row with an infinite error and the reason, not an exception.
    failed = rows[("dopri5", 1e-6)]
    assert failed["tip_error_final_m"] == np.inf and "max_steps" in failed["note"]
    path = table.to_csv(tmp_path / "wp.csv")
    with open(path) as f:
        read = list(csv.DictReader(f))
    assert len(read) == 5 and read[0]["method"] == "dopri5"
    assert "dopri5" in str(table)
    assert table.plot() is not None


def test_discretisation_error_converges_at_second_order():
    table = rf.study.discretisation_error(elements=(5, 10, 20), modes=2)
    assert np.all(table.column("order_mode1")[1:] > 1.9)
    assert np.all(table.column("order_elastica")[1:] > 1.9)
    assert table.rows[1]["mode1_rel_error"] < 3e-3


def test_bench_command_writes_the_table_and_plot(tmp_path, capsys):
    assert main(["bench", "--quick", "--output", str(tmp_path)]) == 0
    assert (tmp_path / "work_precision.png").stat().st_size > 10_000
    with open(tmp_path / "work_precision.csv") as f:
        rows = list(csv.DictReader(f))
    scenes = {r["scene"] for r in rows}
    assert any("cantilever modified" in s for s in scenes) and any("cantilever classical" in s for s in scenes)
    assert any("kane" in s for s in scenes) and any("whippy" in s for s in scenes)
    assert any("stiff 3D cantilever" in s for s in scenes)
    assert {r["method"] for r in rows} >= {"dopri5", "rk4", "generalized_alpha", "implicit_spring"}
    assert (tmp_path / "discretisation.csv").exists()
    assert "machine:" in capsys.readouterr().out

