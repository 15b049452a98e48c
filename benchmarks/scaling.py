"""Scaling benchmarks: cost against the number of coordinates nq of modified-RFEM 3D
cantilevers (``samples.cantilever`` with bend_z, bend_y and torsion: 3 rotations per sde).

- ``dynamics_scaling``: time per forward-dynamics call, recursive (ABA) against the book's
  Lagrange formulation;
- ``implicit_step_scaling``: time per step of ``implicit_spring`` (O(n) Newton matrix)
  against generalised-α with the exact tangent, and one rk4 step for scale;
- ``implicit_methods_scaling``: time per step of every implicit method (the Newmark family,
  esdirk43, radau5, auto) with its default Newton matrix on planar bending-only cantilevers of
  10² … 10⁴ rfes, open and with a closed loop: O(n) once the tangent is matrix-free (Krylov,
  ``rigidfem.simulate``'s ``iteration_matrix``);
- ``run``: all three, written to ``dynamics_scaling.csv``, ``implicit_step_scaling.csv`` and
  ``implicit_methods_scaling.csv``::

    python -m benchmarks scaling [--quick] [--output DIR]

Times in s, timed in C++ where marked; the fitted exponents are slopes of log(time)
against log(nq).
"""

from __future__ import annotations

import numpy as np

from rigidfem import samples
from rigidfem.simulation import simulate
from rigidfem.studies.study import Table

from ._common import cpp_seconds_per_call, machine, report

ELEMENTS = (10, 20, 50, 100, 200, 500, 1000)
QUICK_ELEMENTS = (10, 20, 40)
DEFORM = ("bend_z", "bend_y", "torsion")


def _fit_exponent(rows, cost: str, exponent: str, smallest_nq: int = 60) -> None:
    """Writes into every row the slope of log(cost) against log(nq), fitted over the rows with
    nq ≥ smallest_nq that have a positive cost (at least two)."""
    pts = [(r["nq"], r[cost]) for r in rows if cost in r and r["nq"] >= smallest_nq and r[cost] > 0.0]
    if len(pts) >= 2:
        slope = float(np.polyfit(np.log([p[0] for p in pts]), np.log([p[1] for p in pts]), 1)[0])
        for r in rows:
            r[exponent] = slope


def _least_cpp_seconds(system, q, qd, calls: int | None = None) -> float:
    """Least of 3 batches of ``cpp_seconds_per_call`` (s per call)."""
    return min(cpp_seconds_per_call(system, q, qd, calls) for _ in range(3))


def dynamics_scaling(elements=ELEMENTS, lagrange_up_to: int = 200) -> Table:
    """Time per forward-dynamics call (s, timed in C++, minimum of 3 batches) against the
    number of coordinates for modified-RFEM 3D cantilevers (3 rotations per sde): recursive
    (ABA) against the book's Lagrange formulation (for m ≤ ``lagrange_up_to``), with the
    fitted exponent of each (nq ≥ 60)."""
    rows = []
    for m in elements:
        model, _ = samples.cantilever(elements=m, deform=DEFORM)
        row = {"m": m}
        for algorithm in ("recursive", "lagrange"):
            if algorithm == "lagrange" and m > lagrange_up_to:
                continue
            system = model.compile(algorithm)
            rng = np.random.default_rng(0)
            q, qd = rng.uniform(-1e-3, 1e-3, system.nq), rng.uniform(-1e-2, 1e-2, system.nq)
            calls = None if algorithm == "recursive" else max(3, int(2e6 / system.nq**2))
            row[f"{algorithm}_s"] = _least_cpp_seconds(system, q, qd, calls)
            row["nq"] = system.nq
        rows.append(row)
    for algorithm in ("recursive", "lagrange"):
        _fit_exponent(rows, f"{algorithm}_s", f"{algorithm}_exponent")
    return Table(rows, ("m", "nq", "recursive_s", "lagrange_s", "recursive_exponent", "lagrange_exponent"))


def implicit_step_scaling(elements=ELEMENTS, tangent_up_to: int = 200, steps: int = 50) -> Table:
    """Cost per step (s, timed in C++) of the implicit methods against the number of coordinates
    for modified-RFEM 3D cantilevers (steel, 1 m, 20 × 5 mm, 3 rotations per sde) set vibrating
    by a 20 N tip load, at the step h = T₁/50 (T₁ = 2π/105 s its first period, far beyond the
    explicit stability limit of the sdes), over ``steps`` steps: ``implicit_spring`` (O(n)
    Newton matrix) against generalised-α with the exact tangent (analytic derivatives, dense
    LU; m ≤ ``tangent_up_to``), and the cost of one rk4 step (four ABA calls) for scale. Also
    the Newton iterations per step and the fitted exponent of the implicit_spring cost."""
    h = 2 * np.pi / 105.0 / 50
    rows = []
    for m in elements:
        model, hd = samples.cantilever(elements=m, deform=DEFORM)
        model.add_force("load0", hd["beam"].tip, (0.0, 20.0, 10.0))
        system = model.compile()
        row = {"m": m, "nq": system.nq}
        runs = [("implicit_spring", {}), ("generalized_alpha", {"iteration_matrix": "tangent"})]
        for name, kw in runs:
            if name == "generalized_alpha" and m > tangent_up_to:
                continue
            best = min((simulate(system, steps * h, method=name, dt=h, **kw) for _ in range(2)),
                       key=lambda r: r.stats["wall_time"])
            key = "spring" if name == "implicit_spring" else "tangent"
            row[f"{key}_s_per_step"] = best.stats["wall_time"] / best.stats["steps"]
            row[f"{key}_iterations_per_step"] = best.stats["newton_iterations"] / best.stats["steps"]
            if key == "tangent":
                row["tangent_jacobians"] = best.stats["jacobians"]
        q = np.zeros(system.nq)
        row["rk4_s_per_step"] = 4 * _least_cpp_seconds(system, q, q)
        rows.append(row)
    _fit_exponent(rows, "spring_s_per_step", "spring_exponent")
    return Table(rows, ("m", "nq", "spring_s_per_step", "spring_iterations_per_step", "tangent_s_per_step",
                        "tangent_iterations_per_step", "tangent_jacobians", "rk4_s_per_step", "spring_exponent"))


LARGE_ELEMENTS = (100, 300, 1000, 3000, 10000)
QUICK_LARGE_ELEMENTS = (100, 300)
#: (method, options): fixed steps of 1 ms, and auto at atol = 1e-4 m; the Krylov form of the tangent at
#: every size (the default takes the dense tangent below 200 coordinates, where it is the cheaper).
IMPLICIT_METHODS = (("implicit_spring", {"dt": 1e-3}),
                    ("generalized_alpha", {"dt": 1e-3, "iteration_matrix": "krylov"}),
                    ("esdirk43", {"dt": 1e-3, "adaptive": False, "iteration_matrix": "krylov"}),
                    ("radau5", {"dt": 1e-3, "adaptive": False, "iteration_matrix": "krylov"}),
                    ("auto", {"rtol": 0.0, "atol": 1e-4, "iteration_matrix": "krylov"}))
#: The two run lengths (s) whose difference gives the cost per step without the set-up.
SHORT_RUN, LONG_RUN = 5e-3, 25e-3


def large_beam(elements: int, loop: bool = False):
    """A planar steel cantilever of 1 m (20 × 5 mm, ``bend_z`` only: one coordinate per sde) under
    gravity and a 20 N tip load; with ``loop``, its tip held 0.5 m from the ground point
    (1, 0.5, 0) m by a distance loop (one constraint row)."""
    model, hd = samples.cantilever(elements=elements, deform=("bend_z",), gravity=(0.0, -9.81, 0.0))
    model.add_force("load0", hd["beam"].tip, (0.0, 20.0, 0.0))
    if loop:
        model.add_loop_joint("loop0", "distance", hd["beam"].tip, model.ground.point((1.0, 0.5, 0.0)), length=0.5)
    return model.compile()


def implicit_methods_scaling(elements=LARGE_ELEMENTS, rounds: int = 3) -> Table:
    """Cost per step (s, timed in C++) of each implicit method against nq on ``large_beam`` (open and
    closed), the tangent in its Krylov form at every size (matrix-free products, GMRES preconditioned
    by the O(n) spring matrix): fixed steps of 1 ms (esdirk43 and radau5 with ``adaptive=False``), and
    the default method ``auto`` holding every body's displacement to 1e-4 m.

    Each method runs to ``SHORT_RUN`` and to ``LONG_RUN`` (5 and 25 ms), the quickest of ``rounds``
    runs each, the rounds interleaved over the sizes (a slow spell of the machine spreads over all
    of them): the cost per step is the difference of the two wall times over the difference of their
    steps, and ``setup_s`` the short run's time less its steps at that cost (workspaces, the initial
    state and accelerations, auto's ω_max estimate; allocations of a few MB each above ~10³ rfes,
    whose page faults would otherwise weigh on a fit of short runs). Also the Newton and GMRES
    iterations per step and, per method and scene, the fitted exponent of the cost per step over all
    the sizes and over 10³–10⁴ rfes, and of the cost per step relative to implicit_spring's (the
    O(n) reference) at the same size and scene."""
    systems = {(loop, m): large_beam(m, loop) for loop in (False, True) for m in elements}
    best = {}
    for _ in range(rounds):
        for (loop, m), system in systems.items():
            for name, options in IMPLICIT_METHODS:
                for t_end in (SHORT_RUN, LONG_RUN):
                    st = simulate(system, t_end, method=name, t_eval=[t_end], **options).stats
                    key = (loop, m, name, t_end)
                    if key not in best or st["wall_time"] < best[key]["wall_time"]:
                        best[key] = st
    rows = []
    for (loop, m), system in systems.items():
        for name, _ in IMPLICIT_METHODS:
            short, long = best[loop, m, name, SHORT_RUN], best[loop, m, name, LONG_RUN]
            per_step = (long["wall_time"] - short["wall_time"]) / (long["steps"] - short["steps"])
            if not per_step > 0.0:  # a slow spell in the short run's best outweighed the longer run's steps
                per_step = long["wall_time"] / long["steps"]  # the long run's mean: an upper bound, setup included
            rows.append({"scene": "loop" if loop else "open", "m": m, "nq": system.nq, "method": name,
                         "steps": long["steps"], "s_per_step": per_step,
                         "setup_s": short["wall_time"] - short["steps"] * per_step,
                         "newton_per_step": long["newton_iterations"] / long["steps"],
                         "gmres_per_step": long["linear_iterations"] / long["steps"]})
    for scene in ("open", "loop"):
        spring = {r["m"]: r["s_per_step"] for r in rows if r["scene"] == scene and r["method"] == "implicit_spring"}
        for name, _ in IMPLICIT_METHODS:
            mine = [r for r in rows if r["scene"] == scene and r["method"] == name]
            for r in mine:  # the cost in steps of implicit_spring, the O(n) reference, at the same size
                r["per_spring_step"] = r["s_per_step"] / spring[r["m"]]
            _fit_exponent(mine, "s_per_step", "exponent")
            _fit_exponent(mine, "s_per_step", "exponent_from_1000", smallest_nq=1000)
            _fit_exponent(mine, "per_spring_step", "relative_exponent")
    return Table(rows, ("scene", "method", "m", "nq", "steps", "s_per_step", "setup_s", "newton_per_step",
                        "gmres_per_step", "per_spring_step", "exponent", "exponent_from_1000", "relative_exponent"))


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks scaling``: the three studies (m = 10 … 1000 rfes and 10² … 10⁴ for
    the implicit methods; ``quick``: m = 10, 20, 40, 20 implicit steps and 100, 300), written to
    ``output_dir`` as ``<name>.csv`` and printed as markdown. Returns name -> Table."""
    elements = QUICK_ELEMENTS if quick else ELEMENTS
    print(machine(), flush=True)
    return report({
        "dynamics_scaling": ("Forward dynamics against nq: time per call (s, timed in C++)",
                             dynamics_scaling(elements)),
        "implicit_step_scaling": ("Implicit step against nq: time per step (s), h = T1/50",
                                  implicit_step_scaling(elements, steps=20 if quick else 50)),
        "implicit_methods_scaling": ("Every implicit method against nq: time per step (s), 10^2-10^4 rfes",
                                     implicit_methods_scaling(QUICK_LARGE_ELEMENTS if quick else LARGE_ELEMENTS)),
    }, output_dir)
