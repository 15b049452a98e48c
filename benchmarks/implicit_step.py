"""Where an implicit step's time goes: generalised-α with the exact tangent on Kane's beam::

    python -m benchmarks implicit_step [--quick] [--output DIR]

The chains: Kane's spin-up beam (planar modified RFEM, m = 10 … 1000 rfes, n = m coordinates),
generalised-α at a fixed step over 5 s of the spin-up, with the dense tangent at every size
(``iteration_matrix="tangent"``; the default takes the matrix-free one above 200 coordinates). Measured: the C++ wall time per step and
the counts per step (Newton iterations, tangents, factorisations), and, timed in C++ on one
workspace at the run's final state, the parts: one residual r = M q̈ − f (kinematics and inverse
dynamics), one tangent (∂r/∂q, ∂r/∂q̇ and M), one dense LU factorisation and one LU solve.

The floor of a step is one residual and one solve per Newton iteration; the model adds the
tangents and factorisations the run made; "other" is what the step costs beyond the model
(predictor, updates, error estimate, dense-output bookkeeping, allocation).
"""

from __future__ import annotations

import numpy as np

import rigidfem as rf
from rigidfem import samples
from rigidfem._core._bench import implicit_step_parts_seconds
from rigidfem.studies.study import Table

from ._common import machine, report

ELEMENTS = (10, 20, 50, 100, 200, 500, 1000)
QUICK_ELEMENTS = (10, 20)


def step_breakdown(elements=ELEMENTS, t_end: float = 5.0, dt: float = 0.01) -> Table:
    """Per m: seconds per step measured and modelled from its parts (see the module docstring)."""
    rows = []
    for m in elements:
        model, _ = samples.kane_beam(omega=6.0, duration=15.0, elements=m)
        system = model.compile()
        # the dense tangent at every size, the matrix the parts time ("auto" takes the matrix-free one above 200
        # coordinates, whose iterations the parts do not model)
        runs = [rf.simulate(system, t_end, method="generalized_alpha", dt=dt, t_eval=[t_end], iteration_matrix="tangent")
                for _ in range(3)]
        stats = min(runs, key=lambda r: r.stats["wall_time"]).stats
        steps = stats["steps"]
        q, qd = runs[0].q[-1], runs[0].qd[-1]
        qdd = system.forward_dynamics(t_end, q, qd)
        parts = implicit_step_parts_seconds(system, t_end, q, qd, qdd, max(3, int(2e5 / m)))
        per = {k: stats[k] / steps for k in ("newton_iterations", "jacobians", "factorizations")}
        floor = per["newton_iterations"] * (parts["residual"] + parts["lu_solve"])
        tangents = per["jacobians"] * (parts["tangent"] + parts["lu_factor"])
        step = stats["wall_time"] / steps
        rows.append({"m": m, "nq": system.nq, "step_s": step, "iterations_per_step": per["newton_iterations"],
                     "tangents_per_step": per["jacobians"], "residual_s": parts["residual"],
                     "lu_solve_s": parts["lu_solve"], "tangent_s": parts["tangent"],
                     "lu_factor_s": parts["lu_factor"], "floor_s": floor, "tangent_share": tangents / step,
                     "other_share": (step - floor - tangents) / step, "step_over_floor": step / floor})
    return Table(rows, tuple(rows[0]))


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    table = step_breakdown(QUICK_ELEMENTS if quick else ELEMENTS, t_end=1.0 if quick else 5.0)
    return report({"implicit_step": ("Generalised-α step on Kane's beam: measured against its parts (s)", table)},
                  output_dir)
