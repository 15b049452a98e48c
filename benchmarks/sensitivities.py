"""What a forward sensitivity costs against the run it differentiates (issue 26, item 7)::

    python -m benchmarks sensitivities [--quick] [--output DIR]

A steel strip (1 m, 20 × 5 mm, bending in both planes) on a sprung hub and
pushed at its tip, undamped (its damping parameter at 0: the derivative by a damping to add), m = 20, 80 and 320 elements (2 m + 1 coordinates), run over 10 ms by generalized_alpha
(dt = 1e-4 s, exact tangent: dense below 200 coordinates, Krylov above), esdirk43 (dt = 1e-4 s, fixed) and
rk4 (dt = 2.5/ω_max, its stability limit at each size), each without sensitivities and with P = 1 and 4 (E,
rho, damping and the tip force's magnitude). CPU time of the quickest of 3 interleaved rounds;
``per_parameter`` = (time with P − time without)/(P × time without): the cost of one parameter's
sensitivities in units of the run itself.

The adjoint gradient (many parameters for the cost of a few runs) is not implemented yet: its column is
empty.

``--quick``: m = 20 and 80, one round.
"""

from __future__ import annotations

import time

import numpy as np

import rigidfem as rf
from rigidfem.study import Table

from ._common import machine, report

NAMES = ("strip.E", "strip.rho", "strip.damping", "push.force")
METHODS = {"generalized_alpha": dict(dt=1e-4), "esdirk43": dict(dt=1e-4, adaptive=False), "rk4": dict()}
T_END = 0.01
COLUMNS = ("elements", "nq", "method", "parameters", "cpu_s", "per_parameter", "adjoint_over_forward")


def strip(elements: int):
    """The strip of the module docstring, compiled, and its tip."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    beam = model.add_beam("strip", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.02, 0.005), elements, deform=("bend_z", "bend_y"),
                          joint=rf.Joint.revolute("z", stiffness=50.0))
    model.add_force(beam.tip, (0.0, -5.0, 2.0), name="push")
    return model.compile(), beam


def _cpu(system, method, names, dt_rk4):
    options = dict(METHODS[method], **({"dt": dt_rk4} if method == "rk4" else {}))
    start = time.process_time()
    rf.simulate(system, T_END, method, t_eval=[T_END], sensitivities=list(names) or None, **options)
    return time.process_time() - start


def run(output_dir="bench", quick: bool = False):
    sizes = (20, 80) if quick else (20, 80, 320)
    rounds = 1 if quick else 3
    counts = (0, 1, 4)
    best = {}
    systems = {m: strip(m)[0] for m in sizes}
    dt_rk4 = {m: 2.5 / rf.modal_analysis(systems[m]).omega.max() for m in sizes}
    for _ in range(rounds):
        for m in sizes:
            for method in METHODS:
                for P in counts:
                    t = _cpu(systems[m], method, NAMES[:P], dt_rk4[m])
                    key = (m, method, P)
                    best[key] = min(best.get(key, np.inf), t)
    rows = []
    for m in sizes:
        for method in METHODS:
            base = best[(m, method, 0)]
            for P in counts:
                t = best[(m, method, P)]
                rows.append({"elements": m, "nq": systems[m].nq, "method": method, "parameters": P, "cpu_s": t,
                             "per_parameter": (t - base) / (P * base) if P else None, "adjoint_over_forward": None})
    print(machine())
    return report({"sensitivities": ("Forward sensitivities: CPU time and cost per parameter against the run",
                                     Table(rows, COLUMNS))}, output_dir)
