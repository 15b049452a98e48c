"""Sweeps on every core and on Dask: the wall time of one ``rf.sweep`` per executor::

    python -m benchmarks sweep [--quick] [--output DIR]

The study: Kane's spin-up beam (3D modified RFEM, 40 elements, 120 coordinates; generalised-α,
h = 5e-4 s over 20 s, about 1.3 s per run on one core) at 8 spin rates Ω_s, each case building
its model and running it. Executors: serial (one thread), a pool of 2 threads, 2 processes and a
Dask LocalCluster of 2 worker processes (one thread each; its start-up is timed apart). Speed-up
= serial time / time; efficiency = speed-up / 2 workers. The overhead per case is the wall time
per case of a sweep of 200 tiny cases (a one-coordinate pendulum over 10 ms, about 50 µs of
work), less that work. Executors are timed in interleaved rounds, the least time kept.
"""

from __future__ import annotations

import time

import numpy as np

import rigidfem as rf
from rigidfem import samples
from rigidfem.studies.study import Table

from ._common import machine, report

SPINS = (4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0)  # Ω_s, rad/s
WORKERS = 2


def kane_case(omega: float, elements: int = 40, dt: float = 5e-4) -> dict:
    """One case: Kane's beam spun up to ``omega`` (rad/s); the tip's largest deflection (m)."""
    model, h = samples.kane_beam(omega=omega, duration=15.0, elements=elements,
                                 deform=("bend_z", "bend_y", "torsion"))
    system = model.compile()
    result = rf.simulate(system, 20.0, method="generalized_alpha", dt=dt, t_eval=np.linspace(0, 20, 201))
    tip = result.position(h["beam"].tip, frame=h["hub"])
    return {"tip_deflection_m": float(np.abs(tip[:, 1]).max()), "steps": result.stats["steps"]}


def tiny_case(angle: float) -> dict:
    """One tiny case: a pendulum over 10 ms (per-task overhead)."""
    return {"q": rf.simulate(_PENDULUM, 0.01, q0=[angle], method="rk4", dt=1e-3).q[-1, 0]}


def _pendulum():
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    model.add_body("rod", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1e-3, 0.08, 0.08),
                   com=(0.5, 0.0, 0.0))
    return model.compile()


_PENDULUM = _pendulum()


def _executors(client):
    """Name -> the executor argument of rf.sweep (and its workers)."""
    return {"serial (1 thread)": ("serial", None), f"threads ({WORKERS})": ("threads", WORKERS),
            f"processes ({WORKERS})": ("processes", WORKERS), f"Dask LocalCluster ({WORKERS} workers)": (client, None)}


def _timed_sweep(function, cases, executor, workers) -> tuple[float, object]:
    start = time.perf_counter()
    table = rf.sweep(function, cases, executor=executor, workers=workers, as_frame=False)
    return time.perf_counter() - start, table


def scaling(spins=SPINS, elements: int = 40, rounds: int = 2, tiny: int = 200) -> Table:
    """Wall time of the sweep per executor, speed-up and efficiency against serial, and the
    overhead per case on tiny cases (s)."""
    from distributed import Client, LocalCluster

    cases = [{"omega": w, "elements": elements} for w in spins]
    tiny_cases = [{"angle": a} for a in np.linspace(0.1, 1.0, tiny)]
    start = time.perf_counter()
    with LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        startup = time.perf_counter() - start
        executors = _executors(client)
        best = {name: np.inf for name in executors}
        tiny_best = dict(best)
        reference = None
        for _ in range(rounds):  # interleaved rounds
            for name, (executor, workers) in executors.items():
                seconds, table = _timed_sweep(kane_case, cases, executor, workers)
                best[name] = min(best[name], seconds)
                values = [r["tip_deflection_m"] for r in table.rows]
                reference = reference or values
                assert values == reference, f"{name}: results differ from the serial run"
                tiny_best[name] = min(tiny_best[name], _timed_sweep(tiny_case, tiny_cases, executor, workers)[0])
    work = _tiny_work(tiny_cases)
    serial = best["serial (1 thread)"]
    rows = [{"executor": name, "cases": len(cases), "wall_time_s": best[name], "speed_up": serial / best[name],
             "efficiency": serial / best[name] / (1 if name.startswith("serial") else WORKERS),
             "overhead_per_case_s": tiny_best[name] / len(tiny_cases) - work,
             "startup_s": startup if name.startswith("Dask") else 0.0} for name in executors]
    return Table(rows, ("executor", "cases", "wall_time_s", "speed_up", "efficiency", "overhead_per_case_s",
                        "startup_s"))


def _tiny_work(cases) -> float:
    """Seconds of work in one tiny case, run directly (least of 3 passes, per case)."""
    passes = []
    for _ in range(3):
        start = time.perf_counter()
        for case in cases:
            tiny_case(**case)
        passes.append((time.perf_counter() - start) / len(cases))
    return min(passes)


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    table = scaling(SPINS[:4], elements=10, rounds=1, tiny=50) if quick else scaling()
    return report({"sweep_scaling": ("rf.sweep of Kane's beam at 8 spin rates, per executor", table)}, output_dir)
