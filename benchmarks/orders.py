"""Speed against error of the high-order implicit methods on Kane's beam::

    python -m benchmarks orders [--quick] [--output DIR]

Kane's spin-up beam (planar modified RFEM, Ω_s = 6 rad/s, T_s = 15 s, over 20 s) with m = 20 and 40
elements: the tip's RMS error (m, in the hub's frame, at 51 output times) against dopri5 at
rtol = 1e-12 on the same chain, and the least time of the C++ integration loop (of 3 runs after a
warm-up) to reach 1e-4 m and 1e-6 m, for esdirk43 (the exact tangent and the O(n) spring matrix),
radau5, radau9, generalised-α at fixed steps and dopri5. The tolerance-driven methods run with
atol = 1e-3 rtol (a tip moves by many small sde angles times their lever arms: see rf.simulate).
"""

from __future__ import annotations

import numpy as np

from rigidfem.studies.study import Table, reference, scenes, work_precision

from ._common import machine, report

TARGETS = (1e-4, 1e-6)  # tip RMS error, m


def methods(quick: bool = False) -> list:
    """(method, setting, values, options) of the sweep."""
    rtols = [1e-4, 1e-6] if quick else list(10.0 ** -np.arange(3.0, 9.01, 0.5))
    dts = [0.02, 0.01] if quick else list(0.04 / 2.0 ** np.arange(0.0, 6.01, 0.5))

    def tolerances(method, values, **options):
        return [(method, "rtol", [r], dict(options, atol=1e-3 * r)) for r in values]

    return [*tolerances("esdirk43", rtols), *tolerances("esdirk43", rtols, iteration_matrix="spring"),
            *tolerances("radau5", rtols), *tolerances("radau9", rtols),
            *tolerances("dopri5", rtols[: 4 if quick else 11]),
            ("generalized_alpha", "dt", dts)]


def study(elements=(20, 40), quick: bool = False, repeats: int = 3) -> tuple[Table, Table]:
    """The sweep (one row per run) and its summary (least time to each target per method)."""
    rows = []
    for m in elements:
        scene = scenes.kane(6.0, m, t_end=20.0)
        ref = reference(scene, rtol=1e-12)
        for method, setting, values, *options in methods(quick):
            for row in work_precision(scene, [(method, setting, values, *options)], repeats=repeats, ref=ref).rows:
                if options and options[0].get("iteration_matrix") == "spring":
                    row["method"] += " (spring)"
                rows.append(row)
    sweep = Table(rows, ("scene", "method", "setting", "value", "tip_error_rms_m", "wall_time_s", "steps",
                         "rejected_steps", "rhs_evaluations", "jacobians", "factorizations", "note"))
    return sweep, sweep.summary(TARGETS)


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    sweep, summary = study(elements=(4,) if quick else (20, 40), quick=quick, repeats=1 if quick else 3)
    return report({"orders_sweep": ("Kane's beam: every run", sweep),
                   "orders_summary": ("Kane's beam: least time (s) to a tip RMS error (m)", summary)}, output_dir)
