"""Accuracy where the scene needs it (issue 24): the default run against the best of every method::

    python -m benchmarks accuracy [--quick] [--output DIR]

For each scene and target error E — the largest tip error over the output times (m), against a
converged reference (radau5 holding the whole state at rtol = 1e-10, atol = 1e-13, cached in
``DIR/accuracy_references``) — three things side by side, in one run:

- **the default** asked for E: ``rf.simulate(system, t_end, atol=E, rtol=0)`` (method "auto",
  ``error_on=None``: every body's displacement held to E m): its tip error, ``delivered_over_asked``
  = that error / E, its wall time and steps, and its error bar, ``res.error_estimate`` of the tip
  (a second run at tolerances / 10) over the true error;
- **the best run** of a sweep over every method, fixed steps included: auto and radau5 over atol,
  radau5 and esdirk43 holding the state and the adaptive generalised-α over rtol, dopri5, and
  generalised-α, implicit_spring and Newmark at fixed steps halved from t_end/100 (rk4 from its
  stability limit 2.8/ω_max where that is within reach), each sweep stopped once a run is 4 times
  more accurate than the smallest target or takes over 20 s: the least wall time among the runs whose
  tip error is at most E;
- ``auto_over_best``, the default's wall time over the best's.

Wall time is the integration's own (``stats["wall_time"]``: the C++ loop with auto's ω_max
estimate), the minimum of 5 runs after a warm-up one (one run where a run takes over a second).

Scenes: a steel strip (1 m, 20 × 2 mm, bending only, undamped) released from rest under gravity,
2 s, m = 16, 32, 64, to 1e-4 and 1e-6 m; a steel tape (20 × 2 mm) retracted from 1 m and extruded
from 0.5 m at 0.5 m/s under gravity from its static shape, 1 s, m = 20 and 40, to 1e-3 of its
largest tip deflection; and the scenes of ``python -m rigidfem bench`` (m = 10) to 1e-4 and 1e-6 m.
``--quick``: the strip at m = 8 and the modified cantilever at m = 6, to 1e-4 m only.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

import rigidfem as rf
from rigidfem.studies.study import Scene, Table, scenes

from ._common import machine, report

COLUMNS = ("scene", "target_m", "auto_error_m", "delivered_over_asked", "auto_time_s", "auto_steps", "auto_method",
           "best", "best_setting", "best_error_m", "best_time_s", "auto_over_best", "estimate_over_true")
SWEEP_COLUMNS = ("scene", "method", "setting", "value", "tip_error_max_m", "wall_time_s", "steps", "note")


def strip(elements: int, t_end: float = 2.0) -> Scene:
    """The steel strip of issue 24: 1 m, 20 × 2 mm, clamped horizontally, bending in the vertical plane
    only, undamped, released straight from rest under gravity."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    beam = model.add_beam("beam", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.002, 0.02), elements, deform=("bend_z",))
    return Scene(f"strip m={elements}", model.compile(), t_end, beam.tip, outputs=401)


def tape(kind: str, elements: int) -> Scene:
    """A steel tape (20 × 2 mm, bending about y) of free length L(t) = 1 − 0.5 t (retraction) or
    0.5 + 0.5 t (extrusion) under gravity, from its static shape at rest, over 1 s."""
    length = rf.motion.polynomial([1.0, -0.5] if kind == "retraction" else [0.5, 0.5])
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    beam = model.add_beam("tape", model.ground, length, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.02, 0.002), elements, deform=("bend_y",))
    system = model.compile()
    return Scene(f"{kind} m={elements}", system, 1.0, beam.tip, q0=rf.static_equilibrium(system).q, outputs=201)


def todo(quick: bool):
    """(scene, targets (m) or a relative target of the tip deflection) of the study."""
    if quick:
        return [(strip(8), (1e-4,)), (scenes.cantilever("modified", 6), (1e-4,))]
    jobs = [(strip(m), (1e-4, 1e-6)) for m in (16, 32, 64)]
    jobs += [(tape(kind, m), ("1e-3 of the deflection",)) for kind in ("retraction", "extrusion") for m in (20, 40)]
    jobs += [(scenes.cantilever("modified", 10), (1e-4, 1e-6)), (scenes.cantilever("classical", 10), (1e-4, 1e-6)),
             (scenes.stiff_cantilever(10), (1e-4, 1e-6)), (scenes.kane(6.0, 10, t_end=20.0), (1e-4, 1e-6)),
             (scenes.whippy(10, 1.0), (1e-4, 1e-6))]
    return jobs


def _tip(scene: Scene, result) -> np.ndarray:
    return result.position(scene.tip, frame=scene.frame)


def reference(scene: Scene, folder: Path) -> np.ndarray:
    """The tip at the output times by radau5 on the whole state, rtol = 1e-10 (cached)."""
    path = folder / (scene.name.replace(" ", "_").replace("=", "") + ".npy")
    if path.exists():
        return np.load(path)
    r = rf.simulate(scene.system, scene.t_end, method="radau5", rtol=1e-10, atol=1e-13, error_on="state",
                    t_eval=scene.t_eval, q0=scene.q0, qd0=scene.qd0, max_steps=10**8)
    tip = _tip(scene, r)
    folder.mkdir(parents=True, exist_ok=True)
    np.save(path, tip)
    return tip


def timed(scene: Scene, repeats: int = 5, **kw):
    """(result, least wall time s) of rf.simulate on the scene, or (SimulationError, inf)."""
    kw.setdefault("max_steps", 2_000_000)
    times = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            for k in range(repeats + 1):
                r = rf.simulate(scene.system, scene.t_end, t_eval=scene.t_eval, q0=scene.q0, qd0=scene.qd0, **kw)
                times.append(r.stats["wall_time"])
                if k == 0 and r.stats["wall_time"] > 1.0:
                    break
        except rf.SimulationError as e:
            return e, np.inf
    return r, min(times[1:] or times)


def sweep(scene: Scene, tip_ref: np.ndarray, smallest: float, omega_max: float, quick: bool) -> list:
    """Every method over its settings: rows (method, setting, value, tip error, wall time, steps)."""
    grid = np.logspace(-2, -9, 15) if not quick else np.logspace(-3, -7, 5)
    rtols = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8] if not quick else [1e-4, 1e-6]
    plans = [("auto", "atol", grid, {"rtol": 0.0}), ("radau5", "atol", grid, {"rtol": 0.0}),
             ("radau5 (state)", "rtol", rtols, {"error_on": "state"}), ("esdirk43", "rtol", rtols, {}),
             ("generalized_alpha (adaptive)", "rtol", rtols[:4], {"adaptive": True}),
             ("dopri5", "rtol", rtols[1::2], {})]
    dts = scene.t_end / 100 / 2.0 ** np.arange(0, 9 if not quick else 5)
    for method in ("generalized_alpha", "implicit_spring", "newmark"):
        plans.append((method, "dt", dts, {}))
    rk4 = 2.8 / omega_max / 2.0 ** np.arange(0, 3)
    if scene.t_end / rk4[0] < 20000:  # rk4 at its stability limit within reach
        plans.append(("rk4", "dt", rk4, {}))
    rows = []
    for name, key, values, extra in plans:
        method = name.split(" ")[0]
        for value in values:
            kw = dict(extra, **{key: value})
            if key == "rtol" and "atol" not in kw:
                kw["atol"] = 1e-3 * value
            r, wall = timed(scene, method=method, **kw)
            row = {"scene": scene.name, "method": name, "setting": key, "value": float(value), "wall_time_s": wall}
            if isinstance(r, rf.SimulationError):
                row.update(tip_error_max_m=np.inf, steps=-1, note=" ".join(str(r).split())[:100])
            else:
                err = float(np.linalg.norm(_tip(scene, r) - tip_ref, axis=1).max())
                row.update(tip_error_max_m=err, steps=int(r.stats["steps"]), note="")
            rows.append(row)
            if row["tip_error_max_m"] < smallest / 4 or wall > 20.0:
                break  # finer settings only cost more
    return rows


def study(quick: bool = False, folder: Path = Path("bench")) -> tuple[Table, Table]:
    """The accuracy table (one row per scene and target) and the sweep behind it."""
    rows, sweeps = [], []
    for scene, targets in todo(quick):
        start = time.perf_counter()
        tip_ref = reference(scene, folder / "accuracy_references")
        deflection = float(np.linalg.norm(tip_ref - tip_ref[0], axis=1).max())
        targets = [1e-3 * deflection if isinstance(t, str) else t for t in targets]
        probe = rf.simulate(scene.system, scene.t_end, t_eval=scene.t_eval[:2], q0=scene.q0, qd0=scene.qd0)
        omega_max = probe.stats["omega_max"]
        runs = sweep(scene, tip_ref, min(targets), omega_max, quick)
        sweeps += runs
        for target in targets:
            r, wall = timed(scene, atol=target, rtol=0.0)
            err = float(np.linalg.norm(_tip(scene, r) - tip_ref, axis=1).max())
            est = float(np.linalg.norm(r.error_estimate.of(lambda x: _tip(scene, x)), axis=1).max())
            ok = [x for x in runs if x["tip_error_max_m"] <= target]
            best = min(ok, key=lambda x: x["wall_time_s"]) if ok else None
            row = {"scene": scene.name, "target_m": target, "auto_error_m": err, "delivered_over_asked": err / target,
                   "auto_time_s": wall, "auto_steps": int(r.stats["steps"]),
                   "auto_method": r.stats.get("method", "")[:40], "estimate_over_true": est / err}
            if best:
                row.update(best=best["method"], best_setting=f"{best['setting']} {best['value']:.3g}",
                           best_error_m=best["tip_error_max_m"], best_time_s=best["wall_time_s"],
                           auto_over_best=wall / best["wall_time_s"])
            else:
                row.update(best="-", best_setting="-", best_error_m=np.nan, best_time_s=np.nan, auto_over_best=np.nan)
            rows.append(row)
            print(f"  {scene.name:28s} E={target:.2g}: delivered {err / target:.2f}, auto {wall:.4f} s, best "
                  f"{row['best']} {row['best_setting']} {row['best_time_s']:.4f} s -> {row['auto_over_best']:.2f}, "
                  f"estimate/true {est / err:.2f}", flush=True)
        print(f"[{time.perf_counter() - start:6.1f} s] {scene.name}", flush=True)
    return Table(rows, COLUMNS), Table(sweeps, SWEEP_COLUMNS)


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    table, runs = study(quick, Path(output_dir))
    return report({"accuracy": ("The default (atol = E, rtol = 0) against the best of every method at the largest "
                                "tip error E", table),
                   "accuracy_sweep": ("Every run of the sweep", runs)}, output_dir)
