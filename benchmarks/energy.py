"""Conservative mechanisms over long runs: does the energy drift? ::

    python -m benchmarks energy [--quick] [--output DIR]

Four conservative mechanisms, no damping, gravity only: a pendulum released at 2.5 rad (500 s, about 140 swings),
the double pendulum released from (1, 0.5) rad (500 s; chaotic), the four-bar of ``rf.samples.four_bar`` falling from its crank
at 0.4 rad (200 s: a loop joint, 3 of its 5 rows redundant) and the orthogonal Bricard linkage of
``benchmarks.loop_peers`` released under gravity (200 s: a loop of 6 revolutes with one degree of freedom).
Each is run by gauss6 (Gauss–Legendre, symmetric), radau5 (L-stable; here at fixed steps), rk4 and generalised-α
with ρ∞ = 1 (its undamped member) at one fixed step (gauss6 also at twice and four times it), and by dop853 at rtol = 1e-8, 1e-10 and 1e-12
(atol alike). For each
run: the largest energy error |E − E₀| (J) over the first and over the last fifth of the outputs
(``first_fifth_J``, ``last_fifth_J``) and their ratio
(about 1 for an error that oscillates, near 2 to 9 for one that grows like t to t²), the CPU time of the run, its
steps and Newton iterations.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

import rigidfem as rf
from rigidfem.studies.study import Table

from ._common import machine, report

FIXED = ("gauss6", "radau5", "rk4", "generalized_alpha")
ADAPTIVE_RTOLS = (1e-8, 1e-10, 1e-12)
COARSER = (2.0, 4.0)  #: gauss6 also at these multiples of the scene's step
COLUMNS = ("scene", "method", "setting", "first_fifth_J", "last_fifth_J", "last_over_first", "cpu_s", "steps",
           "newton_iterations", "note")


def _four_bar_q(t1: float) -> np.ndarray:
    """rf.samples.four_bar's joint angles (crank, coupler relative to the crank, rocker; rad) closing its loop
    at crank angle t1, by the law of cosines: the assembly's starting guess."""
    a, b, c, d = 0.3, 0.8, 0.6, 0.7  # crank, coupler, rocker, ground link (m)
    ax, ay = a * np.cos(t1), a * np.sin(t1)
    e = np.hypot(ax - d, ay)
    t3 = np.arctan2(ay, ax - d) + np.arccos((e * e + c * c - b * b) / (2 * e * c))
    t2 = np.arctan2(c * np.sin(t3) - ay, d + c * np.cos(t3) - ax)
    return np.array([t1, t2 - t1, t3])


def scenes(quick: bool = False) -> list:
    """(name, system, q0, t_end, dt) of each mechanism; quick: a tenth of each run."""
    from .loop_peers import bricard

    pendulum = rf.samples.pendulum()[0].compile()
    double = rf.samples.double_pendulum()[0].compile()
    bar = rf.samples.four_bar()[0].compile()
    bar_q0, _ = bar.assemble(_four_bar_q(0.4))
    b = bricard()
    cut = 0.1 if quick else 1.0
    return [("pendulum from 2.5 rad", pendulum, np.array([2.5]), 500.0 * cut, 0.05),
            ("double pendulum (chaotic)", double, np.array([1.0, 0.5]), 500.0 * cut, 0.01),
            ("four-bar (loop)", bar, bar_q0, 200.0 * cut, 0.01),
            ("Bricard linkage (loop)", b.system, b.q0, 200.0 * cut, 0.01)]


def _row(name, method, setting, options, system, q0, t_end) -> dict:
    t_eval = np.linspace(0.0, t_end, 1001)
    row = {"scene": name, "method": method, "setting": setting, "note": ""}
    start = time.process_time()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = rf.simulate(system, t_end, method=method, q0=q0, t_eval=t_eval, max_steps=10**8, **options)
    except rf.SimulationError as e:
        row["note"] = f"failed at t = {e.time:.3g} s"
        return row
    row["cpu_s"] = time.process_time() - start
    row["steps"] = r.stats["steps"]
    row["newton_iterations"] = r.stats.get("newton_iterations", 0)
    error = np.abs(r.energy - r.energy[0])
    k = len(error) // 5
    first, last = error[:k].max(), error[-k:].max()
    row.update(first_fifth_J=first, last_fifth_J=last,
               last_over_first=last / first if first > 0 else np.nan)
    return row


def study(quick: bool = False) -> Table:
    rows = []
    for name, system, q0, t_end, dt in scenes(quick):
        for method in FIXED:
            options = {"dt": dt, "adaptive": False}
            if method == "generalized_alpha":
                options["rho_inf"] = 1.0
            rows.append(_row(name, method, f"dt={dt:g}", options, system, q0, t_end))
        for factor in COARSER:
            rows.append(_row(name, "gauss6", f"dt={factor * dt:g}", {"dt": factor * dt}, system, q0, t_end))
        for rtol in ADAPTIVE_RTOLS:
            rows.append(_row(name, "dop853", f"rtol={rtol:g}", {"rtol": rtol, "atol": rtol}, system, q0, t_end))
        print(f"{name}: done", flush=True)
    return Table(rows, COLUMNS)


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    return report({"energy_drift": ("Conservative mechanisms over long runs: the energy error early and late, "
                                    "by method", study(quick))}, output_dir)
