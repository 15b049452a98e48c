"""What a forward sensitivity and an adjoint gradient cost against the run they differentiate::

    python -m benchmarks sensitivities [--quick] [--output DIR]

A steel strip (1 m, 20 × 5 mm, bending in both planes) on a sprung hub and
pushed at its tip, undamped (its damping parameter at 0: the derivative by a damping to add), m = 20, 80 and 320 elements (2 m + 1 coordinates), run over 10 ms by generalized_alpha
(dt = 1e-4 s, exact tangent: dense below 200 coordinates, Krylov above), esdirk43 (dt = 1e-4 s, fixed) and
rk4 (dt = 2.5/ω_max, its stability limit at each size), each without sensitivities and with P = 1 and 4 (E,
rho, damping and the tip force's magnitude). CPU time of the quickest of 3 interleaved rounds;
``per_parameter`` = (time with P − time without)/(P × time without): the cost of one parameter's
sensitivities in units of the run itself.

The adjoint gradient (``rigidfem.gradient``): the same strip on a hub driven by a natural spline through 100
knots (a hub motion to shape, 0.1 sin(100 t) rad), J = ∫ |x_tip|² dt over 0.1 s by generalized_alpha and radau5
(fixed steps, dt = 1e-4 s: 1000 steps), by all its parameters: the 100 knot values, the beam's 8 constants and the tip force (109). ``adjoint_over_forward`` =
CPU time of ``rf.gradient`` (forward run, objective, backward sweep, and the 209 systems at p ± h it sets up)
over that of ``rf.simulate`` of the same run (109 forward sensitivities would cost about 109 times the
per-parameter cost of the first table, in runs).

The smooth case: Kane's beam (m = 40 rfes bending in the plane, the book's aluminium beam of 10 m) on a hub
turned by Kane's spin-up (6 rad/s over 15 s) resampled as a natural spline through 96 knots, J = ∫ y_tip² dt
over the whole 20 s study at fixed steps dt = 0.01 s (2,000 steps) by generalized_alpha, by the 96 knot values
and the hub's and the beam's 12 constants (108 parameters): a slow, smooth run whose forward steps are cheap
(about 3.6 Newton iterations a step, 8 factorisations in the run).

``--quick``: m = 20 and 80, one round.
"""

from __future__ import annotations

import time

import numpy as np

import rigidfem as rf
from rigidfem.studies.study import Table

from ._common import machine, report

NAMES = ("strip.E", "strip.rho", "strip.retardation", "push.force")
METHODS = {"generalized_alpha": dict(dt=1e-4), "esdirk43": dict(dt=1e-4, adaptive=False), "rk4": dict()}
T_END = 0.01
COLUMNS = ("elements", "nq", "method", "parameters", "cpu_s", "per_parameter")
ADJOINT_METHODS = ("generalized_alpha", "radau5")
ADJOINT_COLUMNS = ("elements", "nq", "method", "parameters", "forward_cpu_s", "gradient_cpu_s", "adjoint_over_forward",
                   "backward_cpu_s", "gmres_per_step")
KNOTS = 100
T_ADJOINT = 0.1  # s: 1000 steps, so that setting up the 209 systems at p ± h (O(n) each) is not the most of it


def strip(elements: int):
    """The strip of the module docstring, compiled, and its tip."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    beam = model.add_beam("strip", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.02, 0.005), elements, deform=("bend_z", "bend_y"),
                          joint=rf.Joint.revolute("z", stiffness=50.0))
    model.add_force("push", beam.tip, (0.0, -5.0, 2.0))
    return model.compile(), beam


def driven_strip(elements: int):
    """The strip on a hub turned by a spline through KNOTS knots over the run (a motion to shape), its tip."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (0.1, 0.1, 0.1))
    knots = np.linspace(0.0, T_ADJOINT, KNOTS)
    model.prescribe(hub, rf.motion.spline(knots, 0.1 * np.sin(100.0 * knots)))
    beam = model.add_beam("strip", hub, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005),
                          elements, deform=("bend_z", "bend_y"))
    model.add_force("push", beam.tip, (0.0, -5.0, 2.0))
    return model.compile(), beam


KANE_T, KANE_DT, KANE_KNOTS = 20.0, 0.01, 96


def kane_spline(elements: int = 40):
    """Kane's beam on a hub turned by the spin-up resampled as a spline through KANE_KNOTS knots, its beam."""
    from rigidfem.model.samples import KANE_PARAMETERS
    p = KANE_PARAMETERS["kane"]
    W, Ts = 6.0, 15.0
    tk = np.linspace(0.0, KANE_T, KANE_KNOTS)
    theta = np.where(tk < Ts, W / Ts * (tk**2 / 2 + (Ts / (2 * np.pi)) ** 2 * (np.cos(2 * np.pi * tk / Ts) - 1)),
                     W * (tk - Ts / 2))
    model = rf.Model(gravity=None)
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1.0, 1.0, 1.0))
    model.prescribe(hub, rf.motion.spline(tk, theta))
    section = rf.Section(A=p["A"], Iy=p["I"], Iz=p["I"], J=2 * p["I"])
    beam = model.add_beam("beam", hub, p["L"], rf.Material(E=p["E"], rho=p["rho"]), section, elements,
                          deform=("bend_z",))
    return model.compile(), beam


def _kane_cpu(system, beam, names):
    """CPU times (s) of Kane's smooth run alone and of its gradient by ``names``, and the gradient's stats."""
    start = time.process_time()
    rf.simulate(system, KANE_T, "generalized_alpha", dt=KANE_DT, adaptive=False, t_eval=[KANE_T])
    forward = time.process_time() - start
    start = time.process_time()
    g = rf.gradient(system, KANE_T, names, outputs={"tip": beam.tip}, running=lambda t, y: y["tip"][:, 1] ** 2,
                    dt=KANE_DT)
    return forward, time.process_time() - start, g.stats


def _adjoint_cpu(system, tip, names, method):
    """CPU times (s) of the forward run alone and of the gradient by ``names``, and the gradient's stats."""
    start = time.process_time()
    rf.simulate(system, T_ADJOINT, method, dt=1e-4, adaptive=False, t_eval=[T_ADJOINT])
    forward = time.process_time() - start
    start = time.process_time()
    g = rf.gradient(system, T_ADJOINT, names, method=method, outputs={"tip": tip},
                    running=lambda t, y: np.sum(y["tip"] ** 2, axis=1), dt=1e-4)
    return forward, time.process_time() - start, g.stats


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
    driven = {m: driven_strip(m) for m in sizes}
    gradient_names = {m: [n for n in driven[m][0].parameters if ".q[" in n or n.startswith("strip.") and n.count(".") == 1
                          or n == "push.force"] for m in sizes}
    adjoint = {}
    for _ in range(rounds):
        for m in sizes:
            for method in ADJOINT_METHODS:
                forward, grad, stats = _adjoint_cpu(driven[m][0], driven[m][1].tip, gradient_names[m], method)
                old = adjoint.get((m, method), (np.inf, np.inf, None))
                adjoint[m, method] = (min(old[0], forward), min(old[1], grad), stats if grad < old[1] else old[2])
    kane, kane_beam = kane_spline()
    kane_names = [n for n in kane.parameters if ".drive." not in n or ".q[" in n]
    for _ in range(rounds):
        forward, grad, stats = _kane_cpu(kane, kane_beam, kane_names)
        old = adjoint.get("kane", (np.inf, np.inf, None))
        adjoint["kane"] = (min(old[0], forward), min(old[1], grad), stats if grad < old[1] else old[2])
    adjoint_rows = [{"elements": m, "nq": driven[m][0].nq, "method": method, "parameters": len(gradient_names[m]),
                     "forward_cpu_s": adjoint[m, method][0], "gradient_cpu_s": adjoint[m, method][1],
                     "adjoint_over_forward": adjoint[m, method][1] / adjoint[m, method][0],
                     "backward_cpu_s": adjoint[m, method][2]["backward_time"],
                     "gmres_per_step": adjoint[m, method][2]["linear_iterations"] / adjoint[m, method][2]["steps"]}
                    for m in sizes for method in ADJOINT_METHODS]
    forward, grad, stats = adjoint["kane"]
    adjoint_rows.append({"elements": 40, "nq": kane.nq, "method": "generalized_alpha (Kane, smooth)",
                         "parameters": len(kane_names), "forward_cpu_s": forward, "gradient_cpu_s": grad,
                         "adjoint_over_forward": grad / forward, "backward_cpu_s": stats["backward_time"],
                         "gmres_per_step": stats["linear_iterations"] / stats["steps"]})
    rows = []
    for m in sizes:
        for method in METHODS:
            base = best[(m, method, 0)]
            for P in counts:
                t = best[(m, method, P)]
                rows.append({"elements": m, "nq": systems[m].nq, "method": method, "parameters": P, "cpu_s": t,
                             "per_parameter": (t - base) / (P * base) if P else None})
    print(machine())
    return report({"sensitivities": ("Forward sensitivities: CPU time and cost per parameter against the run",
                                     Table(rows, COLUMNS)),
                   "adjoint": ("Adjoint gradient by 108-109 parameters against one forward run",
                               Table(adjoint_rows, ADJOINT_COLUMNS))}, output_dir)
