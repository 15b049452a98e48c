"""The maintainers' benchmarks in the checkout's benchmarks/ (not part of the package): the
scaling studies' tables and the ``python -m benchmarks`` runner. Moved here from
test_study.py with the studies (formerly ``rigidfem.study.dynamics_scaling`` and
``rigidfem.study.implicit_step_scaling``)."""

import csv
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import scaling  # noqa: E402
from benchmarks.__main__ import main  # noqa: E402


def test_dynamics_scaling_table():
    """The scaling study's structure (its numbers are benchmarks, reported, not asserted)."""
    table = scaling.dynamics_scaling(elements=(20, 40, 80), lagrange_up_to=40)
    assert [r["nq"] for r in table.rows] == [60, 120, 240] and "lagrange_s" not in table.rows[-1]
    assert all(r["recursive_s"] > 0 for r in table.rows)
    assert np.isfinite(table.rows[0]["recursive_exponent"]) and np.isfinite(table.rows[0]["lagrange_exponent"])


def test_implicit_step_scaling_table():
    """The implicit-step study's structure; its Newton iterations per step stay few at h = T1/50."""
    table = scaling.implicit_step_scaling(elements=(20, 40), tangent_up_to=20, steps=10)
    assert [r["nq"] for r in table.rows] == [60, 120] and "tangent_s_per_step" not in table.rows[-1]
    assert all(r["spring_s_per_step"] > 0 and 1 <= r["spring_iterations_per_step"] <= 10 for r in table.rows)
    assert np.isfinite(table.rows[0]["spring_exponent"])


def test_runner_writes_and_prints_the_scaling_tables(tmp_path, capsys):
    assert main(["scaling", "--quick", "--output", str(tmp_path)]) == 0
    for name in ("dynamics_scaling", "implicit_step_scaling"):
        with open(tmp_path / f"{name}.csv") as f:
            assert [int(r["m"]) for r in csv.DictReader(f)] == list(scaling.QUICK_ELEMENTS)
    out = capsys.readouterr().out
    assert "machine:" in out and "| m | nq | recursive_s |" in out and "| m | nq | spring_s_per_step |" in out


@pytest.mark.filterwarnings("ignore")  # a LocalCluster's start-up notices (ports, dashboards)
def test_sweep_scaling_table():
    """The sweep benchmark's structure: four executors, all giving the serial results (asserted
    inside), speed-up 1 for serial."""
    pytest.importorskip("distributed")
    from benchmarks import sweep

    table = sweep.scaling(spins=(4.0, 6.0), elements=4, rounds=1, tiny=10)
    assert [r["executor"] for r in table.rows][0] == "serial (1 thread)" and len(table.rows) == 4
    assert table.rows[0]["speed_up"] == 1.0 and all(r["wall_time_s"] > 0 for r in table.rows)
    assert table.rows[-1]["startup_s"] > 0


def test_orders_study_table():
    """The high-order study's structure on a 4-element beam: every method reaches 1e-4 m, and the
    summary keeps the least time per method and target."""
    from benchmarks import orders

    sweep, summary = orders.study(elements=(4,), quick=True, repeats=0)
    assert {r["method"] for r in sweep.rows} == {"esdirk43", "esdirk43 (spring)", "radau5", "dopri5",
                                                 "generalized_alpha"}
    assert all(np.isfinite(r["tip_error_rms_m"]) and r["wall_time_s"] > 0 for r in sweep.rows)
    assert len(summary.rows) == 5 and all(r["time_s_to_0.0001"] != "-" for r in summary.rows)
