"""Is a tolerance asked for a tolerance delivered? (issue 16, item 4)::

    python -m benchmarks tolerance [--quick] [--output DIR]

Kane's spin-up beam (planar modified RFEM, Ω_s = 6 rad/s, T_s = 15 s, over 20 s, m = 20 elements)
run by every adaptive method of ``rigidfem.simulate`` — dopri5, rkf45, esdirk43, radau5, auto and
the Newmark family (newmark, hht, generalized_alpha, implicit_spring) with ``adaptive=True`` — at
rtol = 1e-2 … 1e-6 with atol = 1e-3 rtol. For each run: the tip's RMS error (m, in the hub's frame,
at 51 output times) against dopri5 at rtol = 1e-12 on the same chain, and ``delivered_over_asked``,
that error over what was asked: rtol × the model's size L (``stats["model_size"]``, 9.75 m) for the
runs that measure their error on the bodies' displacements (radau5, auto, the adaptive Newmark
family: ``error_on=None``), rtol × the tip's RMS deflection (the RMS of the reference tip
displacement in the hub frame from its undeformed position: the error a relative tolerance on every
coordinate asks for on the quantity one watches) for those that hold the state (dopri5, rkf45,
esdirk43). A method keeps its word when this ratio stays within a small factor (say 10), or when it
says it could not (``warned``: a warning or a SimulationError, with its text in ``note``).

A second table runs implicit_spring and generalized_alpha at fixed steps dt = 0.05, 0.042 and
0.04 s: does the run finish, or fail, where, and with what error?

``--quick``: m = 10, rtol = 1e-3 and 1e-4, dopri5, esdirk43 and adaptive generalized_alpha, one
fixed step (a smoke run of a few seconds).
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from rigidfem import simulate
from rigidfem.studies.study import Table, reference, scenes

from ._common import machine, report

ADAPTIVE = ("dopri5", "rkf45", "esdirk43", "radau5", "auto", "newmark", "hht", "generalized_alpha",
            "implicit_spring")
NEWMARK_FAMILY = ("newmark", "hht", "generalized_alpha", "implicit_spring")
RTOLS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
FIXED = ("implicit_spring", "generalized_alpha")
DTS = (0.05, 0.042, 0.04)

COLUMNS = ("method", "rtol", "tip_error_rms_m", "delivered_over_asked", "warned", "steps", "rejected_steps",
           "wall_time_s", "note")
FIXED_COLUMNS = ("method", "dt", "finished", "failed_at_s", "tip_error_rms_m", "tip_deflection_rms_m", "steps",
                 "wall_time_s", "note")


def settings(quick: bool = False):
    """(methods, rtols, fixed methods, fixed steps, elements) of the study."""
    if quick:
        return ("dopri5", "esdirk43", "generalized_alpha"), (1e-3, 1e-4), ("implicit_spring",), (0.04,), 10
    return ADAPTIVE, RTOLS, FIXED, DTS, 20


def _tip(scene, result):
    return result.position(scene.tip, frame=scene.frame)


def _short(text: str, n: int = 200) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 3] + "..."


def _run(scene, method: str, **kw):
    """(result or None, list of warning texts, SimulationError text or "", wall s)."""
    from rigidfem import SimulationError

    error = ""
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = simulate(scene.system, scene.t_end, method=method, t_eval=scene.t_eval, **kw)
        except SimulationError as e:
            result, error = e, str(e)
    wall = time.perf_counter() - start
    return result, [f"{w.category.__name__}: {w.message}" for w in caught], error, wall


def study(elements: int = 20, methods=ADAPTIVE, rtols=RTOLS, fixed=FIXED, dts=DTS,
          max_steps: int = 2_000_000) -> tuple[Table, Table]:
    """The tolerance table (one row per method and rtol) and the fixed-step table."""
    scene = scenes.kane(6.0, elements, t_end=20.0)
    ref = reference(scene, rtol=1e-12)
    tip_ref = _tip(scene, ref)
    deflection = tip_ref - tip_ref[0]  # the tip starts undeformed, at (L, 0, 0) in the hub frame
    deflection_rms = float(np.sqrt(np.mean(np.sum(deflection**2, axis=1))))

    def error_of(result):
        err = np.linalg.norm(_tip(scene, result) - tip_ref, axis=1)
        return float(np.sqrt(np.mean(err**2)))

    rows = []
    for method in methods:
        for rtol in rtols:
            kw = dict(rtol=rtol, atol=1e-3 * rtol, max_steps=max_steps)
            if method in NEWMARK_FAMILY:
                kw["adaptive"] = True
            result, caught, failure, wall = _run(scene, method, **kw)
            row = {"method": method, "rtol": rtol, "warned": "no", "note": ""}
            if failure:
                partial = getattr(result, "result", None)
                row.update(tip_error_rms_m=np.inf, delivered_over_asked=np.inf, warned="SimulationError",
                           steps=partial.stats.get("steps", -1) if partial is not None else -1,
                           rejected_steps=partial.stats.get("rejected_steps", -1) if partial is not None else -1,
                           wall_time_s=wall, note=_short(failure))
            else:
                err = error_of(result)
                size = result.stats.get("model_size", np.nan)
                asked = rtol * (size if np.isfinite(size) else deflection_rms)
                row.update(tip_error_rms_m=err, delivered_over_asked=err / asked,
                           steps=int(result.stats["steps"]), rejected_steps=int(result.stats["rejected_steps"]),
                           wall_time_s=wall)
                if method == "auto":
                    row["note"] = _short(result.stats.get("method", ""), 60)
            if caught:
                row["warned"] = "warning" if not failure else "SimulationError + warning"
                row["note"] = _short("; ".join([*caught, row["note"]] if row["note"] else caught))
            rows.append(row)
            print(f"  {method:18s} rtol={rtol:<6g} error={row['tip_error_rms_m']:.3g} m "
                  f"ratio={row['delivered_over_asked']:.3g} warned={row['warned']} steps={row['steps']} "
                  f"{row['wall_time_s']:.2f} s", flush=True)

    fixed_rows = []
    for method in fixed:
        for dt in dts:
            result, caught, failure, wall = _run(scene, method, dt=dt, max_steps=max_steps)
            row = {"method": method, "dt": dt, "finished": "no" if failure else "yes", "failed_at_s": "-",
                   "tip_deflection_rms_m": deflection_rms, "wall_time_s": wall, "note": ""}
            if failure:
                partial = result.result if getattr(result, "result", None) is not None else None
                row.update(failed_at_s=float(getattr(result, "time", np.nan)), tip_error_rms_m=np.inf,
                           steps=partial.stats.get("steps", -1) if partial is not None else -1,
                           note=_short(failure))
            else:
                row.update(tip_error_rms_m=error_of(result), steps=int(result.stats["steps"]))
            if caught:
                row["note"] = _short("; ".join([*caught, row["note"]] if row["note"] else caught))
            fixed_rows.append(row)
            print(f"  {method:18s} dt={dt:<6g} finished={row['finished']} {row['note'][:80]}", flush=True)
    table = Table(rows, COLUMNS)
    table.deflection_rms = deflection_rms
    return table, Table(fixed_rows, FIXED_COLUMNS)


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    methods, rtols, fixed, dts, m = settings(quick)
    tolerance, fixed_steps = study(elements=m, methods=methods, rtols=rtols, fixed=fixed, dts=dts)
    print(f"\nKane's beam m = {m}: tip RMS deflection (hub frame) {tolerance.deflection_rms:.4g} m; "
          f"asked = rtol x that (state) or rtol x the model's size (bodies)", flush=True)
    return report({"tolerance": (f"Tolerances delivered on Kane's beam (m = {m}): tip RMS error delivered against the tolerance asked: rtol x "
                                 f"the model's size (bodies) or x the tip's RMS deflection (state); atol = 1e-3 rtol",
                                 tolerance),
                   "tolerance_fixed_steps": (f"Fixed steps on Kane's beam (m = {m}): generalised-α and implicit_spring",
                                             fixed_steps)}, output_dir)
