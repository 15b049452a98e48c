"""Closed loops at scale: the cost of a step against the number of coordinates n and of
constraint rows m, against a dense solve of the augmented system::

    python -m benchmarks loops [--quick] [--output DIR]

The model: a cantilever of modified rfes (bending in both planes and torsion, n = 3 × elements)
held by m ropes (distance loops) from points above it to rfes spread along it. Columns: the
constrained forward dynamics timed in C++ (ABA, m ABA solves for Y = M⁻¹Gᵀ, an m × m system);
one step of implicit_spring (index-3 generalised-α with the O(n) Newton matrix, C++ wall time per
step); and numpy's dense LU of the (n + m) augmented matrix [[M, Gᵀ], [G, 0]] alone (the linear
algebra a dense method pays per Newton iteration, not counting M and G). Times in s, the least
of several repeats.
"""

from __future__ import annotations

import time

import numpy as np

import rigidfem as rf
from rigidfem.studies.study import Table

from ._common import cpp_seconds_per_call, machine, report


def roped_beam(elements: int, ropes: int):
    """(system, q0): the beam and its ropes, closed at q = 0 (each rope 0.5 m long)."""
    model = rf.Model(gravity=(0, 0, -9.81))
    beam = model.add_beam("beam", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.02, 0.005), elements, deform=("bend_z", "bend_y", "torsion"))
    for k in range(ropes):
        s = (k + 1) / ropes  # along the beam, the last rope at the tip
        model.add_actuator(f"rope{k}", model.ground.point((s, 0.0, 0.5)), beam.point(s), 0.5)
    system = model.compile()
    q0, _ = system.assemble(np.zeros(system.nq))
    return system, q0


def _least(function, repeats: int = 5) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def step_cost(elements, ropes) -> Table:
    rows = []
    for e in elements:
        for m in ropes:
            system, q0 = roped_beam(e, m)
            qd0 = np.zeros(system.nq)
            fd = min(cpp_seconds_per_call(system, q0, qd0) for _ in range(3))
            steps = 20
            best = np.inf
            for _ in range(3):
                r = rf.simulate(system, steps * 1e-4, method="implicit_spring", dt=1e-4, q0=q0)
                best = min(best, r.stats["wall_time"] / r.stats["steps"])
            M = system.mass_matrix(0.0, q0)
            G = system.loop_constraints(0.0, q0, qd0)[2]
            K = np.block([[M, G.T], [G, np.zeros((m, m))]]) + np.diag(np.r_[np.zeros(system.nq), 1e-12 * np.ones(m)])
            rhs = np.ones(system.nq + m)
            dense = _least(lambda: np.linalg.solve(K, rhs), repeats=3)
            rows.append({"elements": e, "n": system.nq, "m": m, "forward_dynamics_s": fd, "implicit_step_s": best,
                         "dense_augmented_solve_s": dense, "dense_over_step": dense / best})
    return Table(rows, ("elements", "n", "m", "forward_dynamics_s", "implicit_step_s", "dense_augmented_solve_s",
                        "dense_over_step"))


def _fit_exponent(x, y) -> float:
    """k of y ∝ x^k by least squares in log–log."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def exponents(table: Table) -> Table:
    """Fitted exponents of each cost in n (at each m) and in m (at each n)."""
    costs = {"forward_dynamics": "forward_dynamics_s", "implicit_step": "implicit_step_s",
             "dense_solve": "dense_augmented_solve_s"}
    rows = []
    for size, fixed in (("n", "m"), ("m", "n")):
        for value in sorted({r[fixed] for r in table.rows}):
            sel = [r for r in table.rows if r[fixed] == value]
            if len(sel) > 1:
                rows.append({"fit": f"in {size} at {fixed} = {value}"} |
                            {name: _fit_exponent([r[size] for r in sel], [r[col] for r in sel])
                             for name, col in costs.items()})
    return Table(rows, ("fit", *costs))


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    table = step_cost((10, 100) if quick else (10, 100, 1000), (1, 10) if quick else (1, 10, 30))
    return report({
        "loops_step_cost": ("Cost per call and per step with m ropes on a beam of n coordinates (s)", table),
        "loops_exponents": ("Fitted exponents (cost ∝ size^k)", exponents(table)),
    }, output_dir)
