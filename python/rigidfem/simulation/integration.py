"""``rf.simulate``: time integration in C++ (book ch. 5.2) with results as numpy arrays (``Result``).

Methods (``method=``; the C++ method table, ``rigidfem.methods()``, and SciPy's solvers):

{methods}

The implicit methods solve M(q) q̈ = f(q, q̇, t) at the end of each step by Newton's
method with the iteration matrix M + γ′h ∂r/∂q̇ + β′h² ∂r/∂q of the residual
r = M q̈ − f (∂r/∂q holds K = −∂f/∂q, ∂r/∂q̇ is C = −∂f/∂q̇), reused while it converges:
analytic for the default recursive engine, by central differences for
``compile(algorithm="lagrange")``. ``implicit_spring`` keeps only its diagonal
springs c and dampers b, and falls back on the exact tangent for a step whose spring
iterations do not converge (a spinning beam's centrifugal stiffness). ``adaptive=True``
controls their step by the local error estimate h²(β − 1/6)(a_{n+1} − a_n) per unit step (held
to the tolerance times h/(t_end − t0)): these second-order methods propagate the solution they
estimate, so the steps' errors add up, in phase, over an oscillation. Measured on Kane's beam
(m = 20, 20 s, ``python -m benchmarks tolerance``): the tip error is 0.12–0.45 of rtol × the
tip's deflection at rtol = 1e-2 … 1e-6 (held per step instead, 5–276 times it), at the price of
a second-order method: 500 steps at rtol = 1e-2, 62 000 at 1e-6 (esdirk43: 38 and 526).

``esdirk43`` writes each stage for the second-order system: with the stage's unknown
acceleration A_i, V_i = v̂_i + γh A_i and Q_i = q̂_i + γh V_i (v̂_i, q̂_i from the earlier
stages), and Newton solves M(Q_i) A_i = f(Q_i, V_i, t_i) with M + γh C + (γh)² K (the exact
tangent, kept over stages and steps while Newton contracts fast and refactorised when h changes)
or, with ``iteration_matrix="spring"``, the O(n) matrix of ``implicit_spring``. Its error is
controlled on y = [q, q̇]: on a flexible beam give ``atol`` well below ``rtol`` × the size of the
sde angles (e.g. ``atol = 1e-3 rtol``, the defaults' ratio), since a tip moves by the sum of many
small angles times their lever arms. Measured on Kane's beam (m = 10 and 20, 20 s, rtol = 1e-4,
1e-6, 1e-8, the error held on the state), the tip's RMS error over rtol × the tip's deflection:
esdirk43 0.01–0.28, radau5 0.008–0.017 and radau9 0.0007–0.043 with atol = 1e-3 rtol, but 15–170,
5.7–80 and 0.23–43 with atol = rtol.

``radau5`` solves its three stages together: the stage accelerations A (nq, 3) give
V = q̇_n 1ᵀ + h A aᵀ and Q = q_n 1ᵀ + h V aᵀ, Newton's matrix I⊗M + h a⊗C + h² a²⊗K splits, by
the eigenvectors of the Butcher matrix a, into one real and one complex block of the form
M + g C + g² K. Its error estimate (of order 3, Hairer & Wanner IV.8) is held to Hairer's
rtol' = 0.1 rtol^(2/3) (atol scaled alike), as in radau5.f, since it bounds an order-5 solution
from far above. Both methods: output at ``t_eval`` by the quintic Hermite interpolant of q through
(q, q̇, q̈) at both ends of each step. Loop closures: ``esdirk43`` holds them at the acceleration
level in each stage (M A − f − Gᵀλ = 0 with G A = γ, by the Schur complement as in the Newmark
family) and projects each step's end onto them, like the explicit methods; ``radau5`` holds them in
all its stages at once (the Schur complement W = 𝒢 𝒮⁻¹ 𝒢ᵀ over the stages, each stage with its own
G_i, on the rows' r independent combinations at the step's first stage: 3r × 3r, factorised once a
step; the 3 nl rows with least-norm multipliers where the stages cross a singular position) and
projects likewise.

``gauss6`` (Gauss–Legendre, 3 stages, order 6) solves its stages as radau5 does (the same real and
complex blocks, its own Butcher matrix) and ends the step at y_n + h Σ b_i f(Y_i). It is symmetric:
run forward, its velocities reversed and run again, the double pendulum comes back to its start to
Newton's tolerance (4.6e-11 at h = 50 ms; radau5 misses by 8.6e-5). It keeps a linear system's
energy at any step (a spring-mass at hω = 50: to 1.7e-13 over 100 steps) and a regular conservative
mechanism's without drift (a pendulum from 2.5 rad over 500 s at h = 50 ms: 4.2e-8 J over the first
fifth and over the last; radau5 2.5e-4 then 1.3e-3 J, rk4 5.4e-3 then 2.7e-2 J). Fixed steps only
(no error estimate), no sensitivities, no Maxwell arms; Newton to 1e-4 ``newton_tol``, since the
leftovers of a looser Newton, of one sign, would make the energy drift.

``radau9`` (Radau IIA, 5 stages, order 9) is radau5 with five stages: one real and two complex blocks,
Hairer's estimate of order 5 (on the state held to rtol' = 0.1 rtol^(3/5), on outputs to the tolerances
as asked, as radau5's), loops as radau5. It pays at tight tolerances and where modes ring that a step
must follow: on the whippy strip (m = 16, 2 s, released from rest) it reached a largest tip error of
7.8e-7 m in 1,158 steps (27 ms) where radau5's cheapest run took 2,497 (37 ms) for 9.9e-7 m. Its output between steps is the collocation polynomial of q̇ and its integral for q (the
quintic Hermite interpolant of radau5 lost 12-76 times the step's accuracy in q over its longer steps).
No sensitivities, no adjoint, no Maxwell arms.
"""

from __future__ import annotations

import functools
import os
import warnings

import numpy as np

from ..base import _checks, _interrupt
import rigidfem._core as _core  # the compiled core, by its absolute name
from . import error_control
from . import events as events_
from . import sensitivities as sensitivities_
from . import options as options_
from ..base._progress import ProgressBar
from .result import Result
from .scipy_ivp import _run_scipy

__doc__ = __doc__.replace("{methods}", "\n".join(f"- ``{m.name}`` ({m.family}{f', order {m.order}' if m.order else ''}): "
                                                  f"{m.doc}" for m in options_.methods().values()))


def simulate(system, t_end: float, method: str = "auto", *, t0: float = 0.0, q0=None, qd0=None, s0=None,
             t_eval=None, progress: bool = False, stop=None, error_estimate: bool = False, sensitivities=None,
             events=None, contact_events: bool = True, **options) -> Result:
    """Integrate ``system`` from ``t0`` to ``t_end`` (s) in C++ (no Python per step).

    The run's arguments come by name after ``method``; the integrator's ``**options`` (``dt``,
    ``rtol``, ``atol``, ``error_on``, ...) are listed once, with their defaults, units and the methods
    that read them, in ``rigidfem.integrator_options`` (below, and
    ``rigidfem.integrator_options(method)`` for one method's). An unknown option is a TypeError; one
    the method does not read is left unused, so one set of options can drive several methods.

    Parameters
    ----------
    method : str
        "auto" (default): dopri5 while it is the cheaper, a stiff method where it is not: radau5, or
        esdirk43 with Maxwell arms or with ``iteration_matrix="spring"`` (radau5 takes neither). At
        rtol <= 1e-6 (the default) dop853 takes dopri5's place (its order 8 takes fewer evaluations
        there: at rtol 1e-6, 1.1-1.6 times as fast on a double pendulum, the Bricard linkage and a
        chain of stiff springs; at 3e-6 the double pendulum went to dopri5), by the same rules with its
        stability boundary (h ρ > 3.6 counted near it, where dopri5's is h ρ > 2). dopri5
        holds the state (its stability rests on its error control); radau5 measures its error on the
        outputs (``error_on``: the bodies' displacements by default), esdirk43 holds the state. First auto estimates the
        spectral radius ρ of the Jacobian of (q̇, q̈) at t0 (``stats["omega_max"]``, rad/s: the highest
        natural frequency of an undamped structure; power iteration, at most 41 right-hand sides).
        Where dopri5 would need at least 200 steps for stability alone ((t_end − t0) ρ / 3.3 >= 200)
        the stiff method runs from t0. Otherwise dopri5 runs in windows of 20 accepted steps (at
        rtol <= 1e-3: looser, its error control lets the stiff modes of a beam go unstable). If its
        first window holds a fifth of its steps at the stability boundary (h ρ > 2), the stiff
        method starts again from the initial state (dopri5 was a probe: its state at the stability
        boundary carries errors in the stiff modes that an undamped beam keeps ringing) and, when it
        reaches the time the probe reached, keeps the run if it has advanced 1.25 times as far per
        unit of work as the probe — counted, not timed (right-hand sides, nq per tangent, (nq/50)²
        per dense factorisation), so the choice is the same on every machine and thread — else
        dopri5 goes on. A later window that looks bounded by stability (a fifth of its steps at
        h ρ > 2) hands the run over to the stiff method from the state reached, after waiting twice
        as many windows if the probe's trial was lost; rejected steps alone do not (a swinging double
        pendulum rejects a third of dopri5's steps and is not stiff). A hand-over is final. The rule
        by ρ can misjudge: a pendulum over 1000 s (over 500 periods) runs radau5, 1.5 times dopri5's
        time at rtol = 1e-3, 0.88 and 0.79 times at 1e-6 and 1e-9; and where the stiff mode itself
        rings (a four-bar's crank on a 1e6 N·m/rad spring, barely damped, over 2 s) radau5 must
        follow it and took 1.6-3.5 times dop853's time at rtol 1e-3 to 1e-7. Name the method there.
        ``stats["method"]`` says what ran ("dopri5", "radau5 from the start (omega_max = ... rad/s:
        stiff for dop853)", "radau5 from the start (a dopri5 probe of ... steps found the problem
        stiff)", or "dop853, then radau5 from t = ... s"), ``stats["switched_at"]``,
        ``stats["auto_trials"]``, ``stats["probe_steps"]`` and ``stats["omega_max"]`` the details.
        Closed chains too (both methods project each step onto the loops).
        Otherwise see the module docstring: "euler", "symplectic_euler", "rk4", "dopri5", "rkf45",
        "dop853", "bs23", "newmark", "hht", "generalized_alpha", "implicit_spring", "esdirk43", "radau5",
        "radau9", "gauss6", or "scipy:Radau",
        "scipy:BDF",
        "scipy:LSODA", "scipy:RK45", "scipy:DOP853". "implicit_spring" is generalised-α (``rho_inf``)
        whose Newton matrix holds only the coordinates' springs and dampers,
        M + diag(γ'h b + β'h² c): the articulated-body algorithm solves it in O(n), so a stiff beam
        takes steps far beyond the explicit stability limit at O(n) per Newton iteration.
    t0 : float
        Start time (s).
    t_eval : array, optional
        Output times (within [t0, t_end]) by dense output; default: every step.
    q0, qd0 : (nq,) arrays
        Initial state (m, rad; per s); zeros by default.
    progress : bool
        Show a progress bar (tqdm when installed).
    stop : threading.Event, optional
        Checked about every 0.05 s of wall time: once set, the run stops and returns its partial
        result (with a RuntimeWarning). The way to stop a run in a worker thread, which Ctrl-C
        does not reach (Python delivers signals to the main thread only).
    s0 : (nz,) array, optional
        Initial forces (N or N·m) of the Maxwell arms (``system.arms``: the Zener and Prony sde
        laws of ``rigidfem.Material``); zero (relaxed) by default. Every C++ method integrates them
        with the state except radau5, radau9 and gauss6 (ValueError; scipy: methods too): the explicit ones carry
        them in y = [q, q̇, s], the Newmark family advances them exactly for q linear over each
        step (s ← e^{−h/τ} s + k (1 − e^{−h/τ})/(h/τ) Δq), esdirk43 as stages. Errors are
        controlled on [q, q̇].

    error_estimate : bool
        Compute ``Result.error_estimate`` with the run (a second run at tolerances / 10, or at dt / 2
        for fixed steps); it is computed on first use otherwise.
    sensitivities : list of str, optional
        Forward sensitivities by these named parameters (``System.parameters``) or initial values
        (``"q0[<coordinate>]"``, ``"qd0[<coordinate>]"``), integrated with the state by every C++
        method (``rigidfem.sensitivities``); ``Result.sensitivity(name)`` and
        ``Result.position_sensitivity(point, name)`` return them.
    events : list of rigidfem.Event, optional
        Functions whose zeros the run locates (``rigidfem.simulation.events``): a coordinate or its rate, a point's
        position along an axis, a contact's gap, or a Python function of (t, q, qd) (the slow path). Each root is
        located on the method's dense output to 1e-12 of its step and recorded in ``Result.events`` (time, state,
        direction, and dt*/dp with ``sensitivities``); a terminal one ends the run there. C++ methods only.
    contact_events : bool
        Locate every contact's onset and separation (``Model.add_contact``; True by default, C++ methods): adaptive
        methods take the step that crossed one again so that it ends there, and the impact's error is controlled
        like the rest of the run. They are recorded in ``Result.events`` under the contacts' names.
    **options
        The integrator's options (``rigidfem.integrator_options``):

{options}

    Returns
    -------
    Result

    Raises
    ------
    ValueError
        Bad input, naming the argument.
    SimulationError
        With the time, the step size and the cause (step size underflow, NaN state, Newton
        divergence, singular matrix, max_steps). Its ``result`` attribute holds the partial
        Result up to the last accepted step, ``time`` and ``cause`` the failure's time (s) and
        cause.

    Notes
    -----
    Systems with loop closures (``Model.add_loop_joint``, ``add_actuator``): q0 and qd0 must close
    every loop (``System.assemble`` finds them); explicit methods project every accepted step back
    onto the loops (closure residual <= 1e-12), the Newmark family solves the index-3 equations
    (Arnold & Brüls: the constraints hold at every step to Newton's tolerance), esdirk43 holds them
    at the acceleration level in its stages and projects like the explicit methods, radau5 likewise
    for its three stages together. ``scipy:`` methods refuse them (ValueError): they would integrate
    the constrained accelerations without holding the loops closed.

    Ctrl-C in the main thread — in the C++ loop, in a Python drive or force law, or in a
    ``scipy:`` method — returns the partial result with a RuntimeWarning (``result.interrupted``).

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> res = rf.simulate(system, 1.0, q0=[0.5])
    >>> res.stats["method"], round(float(res.q[-1, 0]), 4)
    ('dop853', -0.4034)
    """
    o = options_.resolve(options)
    dt, rtol, atol, error_on, first_step = o["dt"], o["rtol"], o["atol"], o["error_on"], o["first_step"]
    adaptive, max_steps, max_step = o["adaptive"], o["max_steps"], o["max_step"]
    system = _checks.system(system)
    n = system.nq
    # converted here; their values judged by the core (_core._check_options: finite, t_end after t0, t_eval within)
    q0 = np.zeros(n) if q0 is None else _checks.reals(q0, (n,), "q0")
    qd0 = np.zeros(n) if qd0 is None else _checks.reals(qd0, (n,), "qd0")
    t0 = _checks.real(t0, "t0", "a start time in s")
    t_end = _checks.real(t_end, "t_end", "an end time in s")
    t_eval = np.zeros(0) if t_eval is None else _checks.reals(t_eval, (np.size(t_eval),), "t_eval")
    if not isinstance(method, str):
        raise _checks.refuse(f"method: expected a method name such as 'dopri5' (see rigidfem.simulate), got {method!r}")
    rtol, atol = _tolerance(rtol, "rtol", n, 1e-6), _tolerance(atol, "atol", n, 1e-9)
    per_component = np.size(rtol) > 1 or np.size(atol) > 1
    if per_component and error_on is not None and not (isinstance(error_on, str) and error_on == "state"):
        raise _checks.refuse(f"rtol, atol: expected one value each with error_on={error_on!r} (per-component "
                         f"tolerances hold the state: error_on='state'), got {np.size(rtol)} and {np.size(atol)}")
    scipy = method.startswith("scipy:")
    if scipy and method not in options_.SCIPY:
        raise _checks.refuse(f"method: expected one of {list(options_.SCIPY)}, got {method!r}")
    # the C++ options, each converted by the bindings (ValueError naming it); scipy: methods check the C++ ones too
    # (they use only first_step of them), so that a bad option is named whatever the method
    opt = options_.compiled("dopri5" if scipy else method, o)  # what the method reads; the others at their defaults
    # every option given, for their values to be judged: the same options where the method reads them all
    judged = opt if options_.read_by(method, o) and not scipy else options_.compiled("dopri5" if scipy else method, o,
                                                                                       every=True)
    row = options_.method(method)
    fixed = adaptive is False or (not row.adaptive and adaptive is not True)
    if error_on is not None and (scipy or fixed) and not (isinstance(error_on, str) and error_on == "state"):
        raise _checks.refuse(f"error_on: expected None or 'state' for {method!r}"
                         f"{' at fixed steps' if fixed else ''} (it controls no error on outputs), got {error_on!r}")
    state = per_component or scipy or (error_on is None and not _core._measures_outputs(system, opt))
    outputs = [] if state else error_control.specs(system, error_on)
    if stop is not None and not callable(getattr(stop, "is_set", None)):
        raise _checks.refuse(f"stop: expected None or a threading.Event (an object with is_set()), got {stop!r}")
    nz = system.nz
    s0 = np.zeros(nz) if s0 is None else _checks.reals(s0, (nz,), "s0")
    if method == "auto" and adaptive is False:
        raise _checks.refuse("adaptive: expected None or True with method 'auto' (it controls its steps), got False")
    for x in (opt, judged):
        x.set("rtol", rtol)
        x.set("atol", atol)
        if scipy:
            x.set("adaptive", None)  # SciPy's solvers are adaptive whatever it says (its type is checked)
        x.s0 = s0
        x.set_error_on(outputs)
    _core._check_options(system, t0, t_end, q0, qd0, t_eval, judged)  # the values, once (the sensitivities': integrate)
    names = sensitivities_.directions(system, sensitivities, opt, t0, t_end)
    events = events_.as_list(events)
    specs = events_.compiled(system, events, _checks.boolean(contact_events, "contact_events") and not scipy)
    if specs and scipy:
        raise _checks.refuse(f"method: expected a C++ method for a run with events, got {method!r}")
    for spec in specs:
        opt.add_event(*spec)
    if names and scipy:  # the options are checked first: a bad one is named whatever the method
        raise _checks.refuse(f"method: expected a C++ method that integrates sensitivities (dopri5, rk4, generalized_alpha, "
                         f"...), got {method!r}")
    _check_output_memory(len(t_eval), 2 * n * (1 + len(names)) + nz)
    _check_closed(system, t0, q0, qd0)
    if system.nl and scipy:
        raise _checks.refuse(f"method: expected a C++ method for a system with loop closures ({system.nl} constraint rows), "
                         f"got {method!r}: SciPy's solvers integrate the constrained accelerations without holding "
                         "g(q) = 0, whose residual drifts (2.5e-4 on a four-bar at rtol = 1e-8); use 'auto', 'radau5', "
                         "'dopri5' or 'generalized_alpha', which close the loops at every output")
    if nz and scipy:
        raise _checks.refuse(f"method: expected a C++ method for a system with Maxwell arms ({nz} arm forces as internal "
                         f"variables), got {method!r}; use 'auto', 'esdirk43', 'generalized_alpha' or 'dopri5'")
    max_steps, max_step = opt.get("max_steps"), opt.get("max_step")
    bar = ProgressBar(t_end - t0, "s", "simulate") if _checks.boolean(progress, "progress") else None
    try:
        if dt is not None and adaptive is None and first_step is None and row.adaptive and not scipy:
            warnings.warn(f"dt: {method!r} is adaptive: dt = {opt.get('dt'):g} s only sets its first step; give "
                          "adaptive=False for fixed steps of dt, or first_step= for the first step without this warning",
                          UserWarning, stacklevel=2)
        if scipy:
            first = None if first_step is None else opt.get("dt")
            run = _run_scipy(system, method[6:], t0, t_end, q0, qd0, t_eval, rtol, atol, max_step, max_steps,
                             _keep_going(bar, stop, t0), first)
        else:
            run = _core._integrate(system, t0, t_end, q0, qd0, t_eval, opt, _keep_going(bar, stop, t0))
    finally:
        if bar is not None:
            bar.close()
    t, q, qd, stats, interrupted, failure, *extra = run
    arms, own, raw, records = extra if extra else (np.zeros((len(t), 0)), None, None, [])
    if own is not None and not (system.nl and np.isfinite(own).all()):
        own = None  # the method has no multipliers of its own (NaN rows from _core._integrate)
    if scipy:
        stats["method"] = method  # the C++ runs say what ran (auto: what it chose)
    if system.nl:
        stats["loop_reactions"] = _reactions_source(own, method)
    call = dict(o, method=method, t_end=t_end, t0=t0, q0=q0, qd0=qd0, s0=s0, t_eval=t_eval if len(t_eval) else None,
                rtol=rtol, atol=atol, max_steps=max_steps, max_step=max_step, events=events,
                contact_events=contact_events)
    result = Result(system, t, q, qd, stats, method, interrupted, arms, own,
                    dict(call, outputs=bool(outputs), fixed=fixed),
                    sensitivities=sensitivities_.split(system, names, raw) if names else {}, made_by=simulate,
                    events=events_.fired(system, specs, records, names))
    if failure is not None:
        message, time, cause = failure
        error = _core.SimulationError(message)
        error.result, error.time, error.cause = result, time, cause
        raise error
    if o["stiffness_warning"] and method != "auto" and np.isfinite(stats.get("stiff_at", np.nan)):
        warnings.warn(f"{method}: the problem is stiff from t = {stats['stiff_at']:.6g} s on (h rho at the stability "
                      "boundary): the step is bounded by stability, the cost grows with the highest frequency and at "
                      "loose tolerances the stiff modes keep errors above the tolerance, or grow; an implicit method "
                      "(auto, esdirk43, radau5, generalized_alpha) is cheaper and keeps the tolerance here",
                      RuntimeWarning, stacklevel=2)
    _warn_growth(result, q0, qd0)
    if interrupted and (swept := _interrupt.current_sweep_stop()) is not None:
        swept.set()  # Ctrl-C in a sweep's case (serial sweeps: the main thread's) stops the sweep
    if interrupted:
        warnings.warn(f"simulation interrupted at t = {t[-1] if len(t) else t0:g} s: returning the partial result",
                      RuntimeWarning, stacklevel=2)
    elif _checks.boolean(error_estimate, "error_estimate"):
        result.estimate = result.error_estimate
    return result



simulate.__doc__ = simulate.__doc__.replace("{options}", options_.docstring())

#: A coordinate that grows this many times beyond its start (the larger of 1, |q0| and |qd0| × the run's
#: length) is reported: a model run far outside its range or an unstable system, not an answer.
GROWTH_WARNING = 1e6


def _warn_growth(result: Result, q0, qd0) -> None:
    """RuntimeWarning when a coordinate grew GROWTH_WARNING times beyond its start (the linear Kane model
    finished with angles of 1e26 rad without a word)."""
    if not result.q.size or np.abs(result.q).max() <= GROWTH_WARNING:  # every start is at least 1 (and NaN goes on)
        return
    span = result.t[-1] - result.t[0] if len(result.t) else 0.0
    start = np.maximum(1.0, np.maximum(np.abs(q0), np.abs(qd0) * span))
    with np.errstate(over="ignore", invalid="ignore"):
        growth = np.abs(result.q) / start
    if not np.nanmax(growth) > GROWTH_WARNING:
        return
    k, j = np.unravel_index(np.nanargmax(growth), growth.shape)
    warnings.warn(f"the state grew {growth[k, j]:.3g} times beyond its start: {result.system.coordinate_names[j]} "
                  f"reached {result.q[k, j]:.3g} (m or rad) at t = {result.t[k]:g} s; a model run far outside its "
                  "range (a linear beam model bent or spun beyond small deflections) or an unstable system",
                  RuntimeWarning, stacklevel=3)


def _check_closed(system, t0, q0, qd0, tol=1e-8):
    """ValueError unless (q0, qd0) close every loop (to tol, m or cosine) and move along them."""
    if not system.nl:
        return
    g, gd, _ = system.loop_constraints(t0, q0, qd0)
    names = system.loop_names
    for what, v in (("q0", g), ("qd0", gd)):
        if np.max(np.abs(v)) > tol:
            raise _checks.refuse(f"{what}: expected initial {'coordinates' if what == 'q0' else 'rates'} that close every "
                             f"loop of {names} (max |g{'' if what == 'q0' else 'd'}| = {np.max(np.abs(v)):.3g} > {tol:g}); "
                             "system.assemble(q0, qd0, t=t0) finds the nearest ones")



def _reactions_source(own, method: str) -> str:
    """Where ``Result.loop_reactions`` come from, for ``stats["loop_reactions"]``: the method's own
    multipliers (``own``: the Newmark family's, at every output) or, with None, the forward dynamics'."""
    if own is not None:
        return f"{method}'s own multipliers (index 3, linear between its steps' ends)"
    return "the forward dynamics' multipliers at each output's state"


def _keep_going(bar, stop, t0):
    """The monitor of a run, called about every 0.05 s with t: updates the progress bar, and
    returns False once ``stop`` is set. None when there is nothing to do."""
    swept = _interrupt.current_sweep_stop()  # the run of a sweep's case: the sweep's Ctrl-C stops it too
    if bar is None and stop is None and swept is None:
        return None

    def keep_going(t):
        if bar is not None:
            bar.update(t - t0)
        return (stop is None or not stop.is_set()) and (swept is None or not swept.is_set())

    return keep_going


@functools.cache
def _physical_memory() -> int | None:
    """The machine's memory (bytes), asked once; None where sysconf cannot tell."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def _check_output_memory(outputs: int, numbers: int) -> None:
    """ValueError naming t_eval when its outputs' states (``numbers`` doubles each: q, q̇, the arms' forces, the
    sensitivities) would not fit in the machine's memory: refused before the run rather than after it."""
    memory = _physical_memory()
    if memory is None:  # no sysconf (Windows): the run finds out itself
        return
    need = 8.0 * outputs * numbers
    if need > memory:
        raise _checks.refuse(f"t_eval: expected at most {int(memory // (8 * max(numbers, 1))):,} output times (their "
                         f"states, {numbers} numbers each, within the machine's {memory / 1e9:.3g} GB), got {outputs:,} "
                         f"({need / 1e9:.3g} GB)")


def _tolerance(x, name, n, default) -> np.ndarray:
    """One tolerance or 2 nq of them (an empty array when nq = 0: then ``default``, which no
    component uses)."""
    expected = f"a non-negative number or {2 * n} (2 nq) of them"
    tol = np.atleast_1d(_checks._floats(x, name, expected))  # real numbers (not complex, not strings)
    if tol.ndim != 1:
        raise _checks.refuse(f"{name}: expected {expected}, got shape {tol.shape}")
    return np.array([default]) if tol.size == 0 and n == 0 else tol  # the values: _core._check_options


