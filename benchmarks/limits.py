"""Where rigidfem's cheapest runs go on the two rows of docs/peers.md that stay under the lead asked::

    python -m benchmarks limits [--quick] [--output DIR]

The rows: the whippy strip at m = 16 to 1e-6 m (``strip_peers``) and the crane to 1e-4 of the payload's motion
(``crane_peers``), each run by rigidfem's cheapest methods there over rtol (atol = rtol/100): radau5 and radau9 on the
strip, radau5 on the crane:

- ``limits_runs``: per run its error against the scene's converged solution (radau5 at rtol 1e-11), its CPU
  time (least of 3), its counts (steps, Newton iterations, stage residuals, tangents, factorisations) and the
  time the residuals and the tangents take at their cost per call (timed in C++ at the scene's initial state,
  ``_bench.implicit_step_parts_seconds``); ``rest_ms`` is the remainder (factorisations, stage solves, error
  estimates, outputs). ``order`` is the error's observed order in the step count against the previous run,
  log(e_prev/e) / log(N/N_prev);
- ``limits_strip_modes``: the strip's linear modes at rest (``modal_analysis``) against what each contributes to
  the tip's vertical motion in the converged run: the modal coordinate η_k = φ_kᵀ M q / φ_kᵀ M φ_k at each output,
  its part J φ_k η_k of the tip's height (J the tip's height's gradient at rest), half its range over the run
  (m), and h̄ ω_k at the mean step of the runs to 1e-5 and 1e-6 m (2 s over the steps).

``--quick``: the strip at m = 8 and two tolerances of each scene.
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
import rigidfem as rf
from rigidfem import _core
from rigidfem.studies.study import Table

from ._common import report
from .crane_peers import RigidfemCrane, crane, error
from .strip_peers import RigidfemStrip, max_error, tip_position, whippy_strip

RUN_COLUMNS = ("scene", "method", "threshold", "rtol", "error", "cpu_ms", "steps", "newton_per_step", "residuals", "tangents",
               "factorizations", "residual_us", "tangent_us", "residuals_ms", "tangents_ms", "rest_ms", "order")
MODE_COLUMNS = ("mode", "omega_rad_s", "tip_amplitude_m", "h_omega_radau5_at_1e-6_m", "h_omega_radau9_at_1e-6_m")
#: strip_peers' grid about 1e-6 m (radau5's run at 2e-6 may end just above it; radau9's at 1e-5 just below)
STRIP_RUNS = tuple(("radau5", rtol) for rtol in (1e-5, 5e-6, 2e-6, 1e-6)) + \
    tuple(("radau9", rtol) for rtol in (5e-5, 2e-5, 1e-5, 5e-6))
CRANE_RTOLS = (1e-3, 3e-4, 1e-4, 3e-5)


def _cpu(run, rounds: int = 3):
    """The least CPU time (s) of ``rounds`` calls of ``run()``, and its last result."""
    best, out = math.inf, None
    for _ in range(rounds):
        start = time.process_time()
        out = run()
        best = min(best, time.process_time() - start)
    return best, out


def _parts(system, q) -> dict:
    """µs per call of a stage residual and of a tangent (K, C, M) at (q, 0, 0), timed in C++."""
    z = np.zeros(system.nq)
    s = _core._bench.implicit_step_parts_seconds(system, 0.0, np.asarray(q, float), z, z, 2000)
    return {"residual_us": 1e6 * s["residual"], "tangent_us": 1e6 * s["tangent"]}


def _row(scene: str, method: str, threshold: float, rtol: float, err: float, cpu: float, stats: dict,
         parts: dict) -> dict:
    residuals_ms = 1e-3 * stats["rhs_evaluations"] * parts["residual_us"]
    tangents_ms = 1e-3 * stats["jacobians"] * parts["tangent_us"]
    return {"scene": scene, "method": method, "threshold": threshold, "rtol": rtol, "error": err, "cpu_ms": 1e3 * cpu,
            "steps": stats["steps"], "newton_per_step": stats["newton_iterations"] / stats["steps"],
            "residuals": stats["rhs_evaluations"], "tangents": stats["jacobians"],
            "factorizations": stats["factorizations"], **parts, "residuals_ms": residuals_ms,
            "tangents_ms": tangents_ms, "rest_ms": 1e3 * cpu - residuals_ms - tangents_ms}


def _orders(rows: list) -> None:
    """Each row's observed order in the step count against the previous row of its scene and method."""
    for prev, row in itertools.pairwise(rows):
        if (row["scene"], row["method"]) == (prev["scene"], prev["method"]) and row["steps"] != prev["steps"]:
            row["order"] = math.log(prev["error"] / row["error"]) / math.log(row["steps"] / prev["steps"])


def strip_study(m: int, runs) -> tuple[list, Table]:
    """The strip's runs (method, rtol) (tip error, m) and its modes' share of the tip's motion."""
    s = whippy_strip(m)
    runner = RigidfemStrip(s)
    system = s.system
    q_ref = runner.run("radau5", "rtol", 1e-11)
    tip_ref = tip_position(s, q_ref)
    parts = _parts(system, np.zeros(system.nq))
    rows = []
    for method, rtol in runs:
        cpu, result = _cpu(lambda method=method, rtol=rtol: runner.simulation(method, "rtol", rtol))
        err = max_error(tip_position(s, result.q), tip_ref)
        rows.append(_row(f"strip m={m}", method, 1e-6, rtol, err, cpu, result.stats, parts))
    return rows, _modes(s, q_ref, rows)


def _modes(s, q_ref, rows) -> Table:
    """Per linear mode at rest: ω, half the range of its part of the tip's height over the converged run, and
    h̄ω at the mean step of radau5's and radau9's cheapest runs to 1e-6 m."""
    system = s.system
    modes = rf.modal_analysis(system)
    M = modes.M
    q0 = np.zeros(system.nq)
    eps = 1e-7
    J = np.array([(tip_position(s, (q0 + eps * e)[None])[0, 1] - tip_position(s, (q0 - eps * e)[None])[0, 1])
                  / (2 * eps) for e in np.eye(system.nq)])

    def mean_step(method: str) -> float:
        ok = [r for r in rows if r["error"] <= 1e-6 and r["method"] == method]
        return s.t_end / min(ok, key=lambda r: r["cpu_ms"])["steps"] if ok else math.nan

    h5, h9 = mean_step("radau5"), mean_step("radau9")
    out = []
    for k, (omega, phi) in enumerate(zip(modes.omega, modes.shapes.T)):
        eta = (np.asarray(q_ref) @ (M @ phi)) / (phi @ M @ phi)
        part = (J @ phi) * eta
        out.append({"mode": k + 1, "omega_rad_s": float(omega), "tip_amplitude_m": float(np.ptp(part) / 2),
                    "h_omega_radau5_at_1e-6_m": h5 * omega, "h_omega_radau9_at_1e-6_m": h9 * omega})
    return Table(out, MODE_COLUMNS)


def crane_study(rtols) -> list:
    """The crane's radau5 runs (payload error relative to its motion's amplitude)."""
    scene = crane()
    runner = RigidfemCrane(scene)
    reference = runner.reference()
    scene.amplitude = float(np.max(np.linalg.norm(reference - reference[0], axis=1)))
    parts = _parts(scene.system, scene.q0)
    rows = []
    for rtol in rtols:
        cpu, result = _cpu(lambda rtol=rtol: runner.simulation("radau5", "rtol", rtol))
        err = error(scene, np.asarray(result.q)[:, scene.payload_index], reference)
        rows.append(_row(scene.name, "radau5", 1e-4, rtol, err, cpu, result.stats, parts))
    return rows


def run(output_dir="bench", quick: bool = False) -> dict:
    """``python -m benchmarks limits``: the two tables of the module's docstring."""
    strip_rows, modes = strip_study(8 if quick else 16, STRIP_RUNS[::2] if quick else STRIP_RUNS)
    rows = strip_rows + crane_study(CRANE_RTOLS[1:3] if quick else CRANE_RTOLS)
    _orders(rows)
    return report({
        "limits_runs": (("Where the cheapest runs go: radau5 and radau9 on the strip (m = 16, tip error in m), "
                         "radau5 on the crane (payload error relative to its motion), their counts and the time of "
                         "their residuals and tangents at their cost per call"), Table(rows, RUN_COLUMNS)),
        "limits_strip_modes": (("The strip's modes in its motion: each linear mode at rest, half the range of its "
                                "part of the tip's height over the converged run (m), and h ω at the mean step of "
                                "radau5's and radau9's cheapest runs to 1e-6 m"), modes),
    }, output_dir)
