"""rf.sweep: grids and case lists, rows in the order of the cases, failing cases in their rows,
per-case seeds, and parallel results equal to serial ones on threads (one shared System),
processes and a two-worker Dask LocalCluster."""

import concurrent.futures
import os
import sys

import numpy as np
import pytest

import rigidfem as rf
from rigidfem.studies.study import Table


def pendulum(length, damping=0.0, angle=0.5):
    """A swinging rod built and run per case: its final angle and largest rate."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    model.add_body("rod", model.ground, rf.Joint.revolute("z", damping=damping), mass=1.0,
                   inertia=(1e-3, length**2 / 12, length**2 / 12), com=(length / 2, 0.0, 0.0))
    if length > 5.0:
        raise RuntimeError(f"length {length} m is too long")
    result = rf.simulate(model.compile(), 1.0, q0=[angle], method="rk4", dt=1e-3)
    return {"final": result.q[-1, 0], "peak_rate": np.abs(result.qd[:, 0]).max(), "q": result.q[:, 0]}


def noisy(scale, seed):
    """A case with random input: the mean of its stream."""
    return {"mean": scale * np.random.default_rng(seed).standard_normal(1000).mean()}


def shared_system():
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    model.add_body("rod", model.ground, rf.Joint.revolute("z", damping=0.01), mass=1.0, inertia=(1e-3, 0.08, 0.08),
                   com=(0.5, 0.0, 0.0))
    return model.compile()


SYSTEM = shared_system()


def swing(angle):
    """Every case runs the one compiled SYSTEM (immutable; shared by threads)."""
    return {"q": rf.simulate(SYSTEM, 2.0, q0=[angle], method="dopri5", rtol=1e-10, atol=1e-12).q[-1, 0]}


GRID = {"length": [0.5, 1.0, 6.0], "damping": [0.0, 0.2]}


def dies_or_returns(k):
    """Case 2 kills its worker process, case 3 returns what does not pickle, the others k²."""
    if k == 2:
        os._exit(3)
    if k == 3:
        return {"value": lambda: k}
    return {"value": k * k}


def missing(v):
    return v is None or (isinstance(v, float) and np.isnan(v))


def same_rows(rows, expected):
    """Row by row the same parameters, values (bitwise; arrays too) and errors; wall times aside."""
    assert len(rows) == len(expected)
    for row, ref in zip(rows, expected):
        assert row.keys() == ref.keys()
        for name in row.keys() - {"wall_time_s"}:
            a, b = row[name], ref[name]
            assert (missing(a) and missing(b)) or np.array_equal(a, b), (name, a, b)


def test_grid_order_failures_and_records():
    table = rf.sweep(pendulum, grid=GRID, executor="serial", as_frame=False)
    assert isinstance(table, Table)
    assert [(r["length"], r["damping"]) for r in table.rows] == [(0.5, 0.0), (0.5, 0.2), (1.0, 0.0), (1.0, 0.2),
                                                                  (6.0, 0.0), (6.0, 0.2)]
    assert table.columns[:2] == ("length", "damping") and table.columns[-2:] == ("error", "wall_time_s")
    failed = [r for r in table.rows if r["error"] is not None]
    assert [r["length"] for r in failed] == [6.0, 6.0]
    assert failed[0]["error"] == "RuntimeError: length 6.0 m is too long" and failed[0]["final"] is None
    # The values are those of a direct call, the damped rod swings less fast.
    direct = pendulum(1.0, 0.2)
    row = table.rows[3]
    assert row["final"] == direct["final"] and np.array_equal(row["q"], direct["q"])
    assert table.rows[1]["peak_rate"] < table.rows[0]["peak_rate"]
    assert all(r["wall_time_s"] > 0 for r in table.rows)
    assert "length" in str(table)


def test_threads_equal_serial_and_dataframe():
    pd = pytest.importorskip("pandas")
    serial = rf.sweep(pendulum, grid=GRID, executor="serial")
    assert isinstance(serial, pd.DataFrame) and len(serial) == 6
    threads = rf.sweep(pendulum, grid=GRID, workers=2)
    same_rows(threads.to_dict("records"), serial.to_dict("records"))
    assert list(serial.columns) == ["length", "damping", "final", "peak_rate", "q", "error", "wall_time_s"]
    assert serial["error"].isna().sum() == 4


def test_one_system_shared_by_threads_equals_serial():
    cases = [{"angle": a} for a in np.linspace(0.1, 2.5, 8)]
    serial = rf.sweep(swing, cases, executor="serial", as_frame=False)
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        threads = rf.sweep(swing, cases, executor=pool, as_frame=False)
    assert [r["q"] for r in threads.rows] == [r["q"] for r in serial.rows]
    assert [r["angle"] for r in threads.rows] == [c["angle"] for c in cases]


def test_processes_equal_serial():
    serial = rf.sweep(pendulum, grid=GRID, executor="serial", as_frame=False)
    processes = rf.sweep(pendulum, grid=GRID, executor="processes", workers=2, as_frame=False)
    same_rows(processes.rows, serial.rows)


def test_a_dying_worker_or_a_value_that_does_not_pickle_costs_one_row():
    """errors="record" in processes: a case that kills its worker (BrokenProcessPool) and one whose
    value does not pickle each get their error; the other cases of their batches keep their values
    (every row was lost: the whole sweep raised)."""
    table = rf.sweep(dies_or_returns, grid={"k": list(range(8))}, executor="processes", workers=2, as_frame=False)
    rows = {r["k"]: r for r in table.rows}
    assert [k for k, r in rows.items() if r["error"] is None] == [0, 1, 4, 5, 6, 7]
    assert all(rows[k]["value"] == k * k for k in (0, 1, 4, 5, 6, 7))
    assert "worker process died" in rows[2]["error"] and rows[2]["value"] is None
    assert all(0.0 <= r["wall_time_s"] < 60.0 for r in rows.values())  # the dead case timed until it died (no NaN)
    assert "return value does not pickle" in rows[3]["error"] and rows[3]["value"] is None


def test_a_dataframes_error_is_none_where_the_case_ran():
    pd = pytest.importorskip("pandas")
    frame = rf.sweep(pendulum, grid=GRID, executor="serial")
    assert [e is None for e in frame["error"]] == [True, True, True, True, False, False]


def test_processes_and_dask_get_the_cases_in_batches():
    """A task per case cost Dask ~3 ms (a sweep of 5 ms runs ran slower on a 2-worker LocalCluster than
    serially): pools and clusters get BATCHES_PER_WORKER batches per worker, threads one case a task;
    the batches cover the cases once, in order, and the rows stay the serial run's."""
    from rigidfem.studies.sweep import BATCHES_PER_WORKER, _batches

    with concurrent.futures.ProcessPoolExecutor(2) as pool:
        for n in (1, 7, 8, 19, 64):
            batches = _batches(pool, n)
            assert [k for b in batches for k in b] == list(range(n))
            assert len(batches) <= BATCHES_PER_WORKER * 2 and (n < 16 or len(batches) >= BATCHES_PER_WORKER)
        cases = [{"length": 0.4 + 0.05 * k} for k in range(19)]
        batched = rf.sweep(pendulum, cases, executor=pool, as_frame=False)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        assert [list(b) for b in _batches(pool, 5)] == [[k] for k in range(5)]
    same_rows(batched.rows, rf.sweep(pendulum, cases, executor="serial", as_frame=False).rows)


def test_seeds_per_case_independent_of_the_executor():
    cases = [{"scale": 1.0}] * 4
    a = rf.sweep(noisy, cases, seed=7, executor="serial", as_frame=False)
    b = rf.sweep(noisy, cases, seed=7, workers=2, as_frame=False)
    c = rf.sweep(noisy, cases, seed=8, executor="serial", as_frame=False)
    seeds = [r["seed"] for r in a.rows]
    assert seeds == [r["seed"] for r in b.rows] and len(set(seeds)) == 4
    assert [r["mean"] for r in a.rows] == [r["mean"] for r in b.rows]
    assert seeds != [r["seed"] for r in c.rows]
    # The stream of a case is numpy's from its seed: the value is reproducible by hand.
    assert a.rows[2]["mean"] == np.random.default_rng(seeds[2]).standard_normal(1000).mean()
    # Cases that carry their own seed keep it.
    own = rf.sweep(noisy, [{"scale": 1.0, "seed": 5}], executor="serial", as_frame=False)
    assert own.rows[0]["seed"] == 5 and own.rows[0]["mean"] == np.random.default_rng(5).standard_normal(1000).mean()


def test_progress_bar_counts_cases(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # the stderr line, whether tqdm is installed or not
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    rf.sweep(pendulum, grid={"length": [0.5, 1.0]}, executor="serial", progress=True, as_frame=False)
    err = capsys.readouterr().err
    assert "sweep: 1 of 2 cases" in err and "sweep: 2 of 2 cases" in err


def test_errors_raise_propagates_the_first_failure():
    with pytest.raises(RuntimeError, match="too long"):
        rf.sweep(pendulum, grid=GRID, executor="serial", errors="raise")


@pytest.mark.parametrize("k, match", [
    (3, r"^function: expected return values that pickle with executor='processes' .*case \{'k': 3\}"),
    (2, r"^function: expected a function that returns, got one whose worker process died running .*'k': 2"),
])
def test_errors_raise_names_the_function_whose_value_does_not_pickle_or_whose_process_dies(k, match):
    """errors='raise' on processes: the function's value that cannot come back, or the worker it ends, is a
    ValueError naming the function and the case (a pickling TypeError and BrokenProcessPool before)."""
    with pytest.raises(ValueError, match=match):
        rf.sweep(dies_or_returns, [{"k": 1}, {"k": k}], executor="processes", workers=1, errors="raise",
                 as_frame=False)


@pytest.mark.parametrize("kwargs, match", [
    (dict(cases=None), "exactly one"),
    (dict(cases=[{"length": 1.0}], grid={"length": [1.0]}), "exactly one"),
    (dict(grid={}), "grid"),
    (dict(grid={"length": 1.0}), r"grid\['length'\]"),
    (dict(cases={"length": 1.0}), "cases"),
    (dict(cases=[1.0]), r"cases\[0\]"),
    (dict(grid=GRID, executor="gpu"), "executor"),
    (dict(grid=GRID, workers=0), "workers"),
    (dict(grid=GRID, errors="ignore"), "errors"),
    (dict(grid=GRID, as_frame="yes"), "as_frame"),
    (dict(grid=GRID, as_frame=1), "as_frame: expected None, True or False, got 1"),
])
def test_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        rf.sweep(pendulum, **kwargs)
    with pytest.raises(ValueError, match="seed"):
        rf.sweep(noisy, [{"scale": 1.0}], seed=-1)
    with pytest.raises(ValueError, match="function"):
        rf.sweep("pendulum", grid=GRID)
    with pytest.raises(ValueError, match="pickles"):
        rf.sweep(lambda length: length, grid=GRID, executor="processes")


@pytest.mark.filterwarnings("ignore")  # a LocalCluster's start-up notices (ports, dashboards)
def test_dask_local_cluster_with_two_workers_equals_serial():
    distributed = pytest.importorskip("distributed")
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # this test module is not importable by workers
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) \
                as cluster, distributed.Client(cluster) as client:
            dask = rf.sweep(pendulum, grid=GRID, executor=client, as_frame=False)
            workers = client.run(lambda: __import__("os").getpid())
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    serial = rf.sweep(pendulum, grid=GRID, executor="serial", as_frame=False)
    assert len(workers) == 2
    same_rows(dask.rows, serial.rows)


class _BreaksAtSubmit(concurrent.futures.ProcessPoolExecutor):
    """A process pool whose worker dies between submissions: the third batch and those after it are refused with
    BrokenProcessPool at submit (a race of a real pool, made certain here)."""

    def __init__(self):
        super().__init__(2)
        self.submitted = 0

    def submit(self, *args, **kwargs):
        self.submitted += 1
        if self.submitted > 2:
            raise concurrent.futures.process.BrokenProcessPool("a child process terminated abruptly")
        return super().submit(*args, **kwargs)


def test_a_pool_that_breaks_while_batches_are_submitted_runs_the_rest_alone():
    """Batches refused at submit (the pool broke meanwhile) are recorded like a batch whose worker died: each of their
    cases runs again alone, so every case gets its value (errors="record"), and errors="raise" names the function."""
    with _BreaksAtSubmit() as pool:
        table = rf.sweep(dies_or_returns, [{"k": k} for k in (0, 1, 4, 5, 6, 7, 8, 9)], executor=pool, errors="record",
                         as_frame=False)
    assert [r["value"] for r in table.rows] == [k * k for k in (0, 1, 4, 5, 6, 7, 8, 9)]
    with _BreaksAtSubmit() as pool, pytest.raises(ValueError, match="^function: expected a function that returns"):
        rf.sweep(dies_or_returns, [{"k": k} for k in (0, 1, 4, 5, 6, 7, 8, 9)], executor=pool, errors="raise")
