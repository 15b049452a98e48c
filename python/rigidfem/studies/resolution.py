"""The model's resolution chosen for a requested accuracy: ``rf.resolve``.

A user's builder makes the model at a number of elements and a set of deformations::

    def build(elements, deform):
        model = rf.Model(gravity=(0.0, -9.81, 0.0))
        beam = model.add_beam("beam", model.ground, 1.0, steel, section, elements, deform=deform)
        return model, {"tip": beam.tip}

    plan = rf.resolve(build, ["tip"], tol=1e-4, t_end=1.0)     # t_end=None: static equilibrium
    print(plan.report()); plan.system, plan.error

1. **Elements.** The outputs z_m (points' positions, m, over the output times; or any array a
   function of the solution returns) are computed at m = m₀, 2m₀, 4m₀, … with every deformation.
   The differences D_k = max |z_{m_k} − z_{m_{k−1}}| give the observed order p = log₂(D_{k−1}/D_k)
   (clamped to [1, 4]; 2, RFEM's order, until three levels exist) and Richardson's estimate of the
   error of level k−1, E_{k−1} = D_k 2^p/(2^p − 1). The cheapest level whose estimate is within
   ``SPACE`` of tol (half) is chosen; the limit z_∞ = z_k + (z_k − z_{k−1})/(2^p − 1) is kept.
2. **Deformations.** At the chosen m each deformation is dropped alone and the change of the
   outputs measured; the ones that change them least are dropped while the changes add up to at most
   ``DROP`` of tol (a quarter), and the reduced set is checked by one more run (the last drop is
   taken back if the set changes the outputs more than that).
3. **Time.** The chosen model is run at ``atol = TIME × tol`` (a quarter), ``rtol = 0``, with its
   error estimate (``Result.error_estimate``: a second run at tolerances / 10): the time error and
   the cost (wall time of the run) in the report.

The refinement runs integrate at atol = tol/20 so that time errors do not blur the differences.
Errors: a builder that fails, returns no model, other outputs or a model whose coordinates do not
grow with the elements is a ``ResolveError`` (a ValueError) naming it; so is an output whose shape
changes with the resolution (or is empty), and a tol that no level up to ``max_elements`` meets (with
the best estimate reached). Each carries ``runs`` (every analysis made) and ``best`` (the finest
level's plan so far, or None). The options passed on to the runs are judged before any run by the
checks of ``simulate`` and ``static_equilibrium`` (a ValueError naming the option, as they would),
and a t_end the runs cannot reach within max_steps is refused at once (``PACE_STEPS``): a
ResolveError naming t_end. A run that fails numerically is a ``SimulationError`` (with its time
and cause, and the ``runs`` made before it), as ``simulate`` reports it: not a bad argument.
"""

from __future__ import annotations

import inspect
import re
import time
from dataclasses import dataclass, field

import numpy as np

import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Body, Point
from ..analysis.statics import MAX_LOAD_STEPS
from ..model.model import Model, System
from ..base import _checks

#: Shares of tol: the space (elements), the time integration and the dropped deformations.
SPACE, TIME, DROP = 0.5, 0.25, 0.25
#: The time integration's atol during refinement, over tol.
REFINEMENT_TIME = 1.0 / 20.0
#: The deformations resolve tries to drop by default (the modified formulation's).
DEFORMATIONS = ("bend_y", "bend_z", "torsion")
#: The first dynamic analysis runs at most this many steps before its pace is judged: a t_end it cannot reach
#: within max_steps is refused then (at fixed steps: (t_end − t0)/dt > max_steps, as rf.gradient refuses it;
#: adaptive: (t_end − t0)/max_step > max_steps, or the pace of those steps needing over ``PACE_MARGIN`` times
#: max_steps), not after max_steps steps. A run that ends within them is the analysis itself.
PACE_STEPS = 1000
PACE_MARGIN = 100.0


class ResolveError(ValueError):
    """``rf.resolve`` could not meet its task: ``runs`` holds every analysis made, ``best`` the plan of
    the finest level reached (or None).

    Examples
    --------
    >>> import rigidfem as rf
    >>> issubclass(rf.ResolveError, ValueError)
    True
    """

    def __init__(self, message, runs=None, best=None):
        super().__init__(message)
        self.runs, self.best = runs or [], best


@dataclass
class Plan:
    """What ``rf.resolve`` chose, why, and the estimated errors (in the outputs' units: m for points).

    Examples
    --------
    >>> import rigidfem as rf
    >>> def build(elements, deform):
    ...     model, h = rf.samples.cantilever(elements=elements, deform=deform)
    ...     model.add_force("load", h["beam"].tip, (0.0, -1.0, 0.0))
    ...     return model, {"tip": h["beam"].tip}
    >>> plan = rf.resolve(build, "tip", 1e-5, deform=("bend_z",))
    >>> type(plan).__name__, plan.elements >= 4
    ('Plan', True)
    """

    elements: int                 #: the elements passed to the builder
    deform: tuple                 #: the deformations kept
    dropped: dict                 #: deformation -> the largest change of the outputs when dropped alone
    kept: dict                    #: deformation -> the same, for the ones kept
    space_error: float            #: Richardson's estimate of the error of the chosen elements
    drop_error: float             #: the change of the outputs from the dropped deformations together
    time_error: float             #: the chosen model's time-integration error estimate (0 for statics)
    tol: float
    order: float                  #: the observed order of convergence in the elements
    cost_s: float                 #: wall time of the chosen model's analysis (s)
    beams: dict                   #: beam name -> elements, read off the system
    limit: dict                   #: output -> Richardson's limit of its values
    simulate_options: dict        #: how the chosen model was run (atol, rtol)
    system: object = field(repr=False)
    handles: dict = field(repr=False)
    solution: object = field(repr=False)  #: the chosen model's Result (dynamics) or Equilibrium (statics)
    runs: list = field(repr=False, default_factory=list)  #: every analysis made, as dicts

    @property
    def error(self) -> dict:
        """The estimated errors: space, dropped deformations, time, and their sum ("total")."""
        return {"space": self.space_error, "dropped": self.drop_error, "time": self.time_error,
                "total": self.space_error + self.drop_error + self.time_error}

    def report(self) -> str:
        """A few lines: what was chosen, why, and at what estimated error and cost."""
        lines = [f"rigidfem resolve: tol = {self.tol:.3g}",
                 f"  elements {self.elements} ({', '.join(f'{b}: {m}' for b, m in self.beams.items()) or 'no beams'}); "
                 f"observed order {self.order:.2f}, estimated space error {self.space_error:.3g}",
                 f"  deformations kept {self.deform or '()'}"
                 + "".join(f"\n    {d}: dropping it alone changes the outputs by {c:.3g}" for d, c in self.kept.items()),
                 f"  dropped {tuple(self.dropped) or '()'}, together changing the outputs by {self.drop_error:.3g}"
                 + "".join(f"\n    {d}: alone {c:.3g}" for d, c in self.dropped.items()),
                 f"  time error estimate {self.time_error:.3g} at {self.simulate_options or 'statics'}",
                 f"  estimated total {self.error['total']:.3g} (tol {self.tol:.3g}); cost {self.cost_s:.3g} s; "
                 f"{len(self.runs)} analyses made"]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (f"<rigidfem Plan: elements {self.elements}, deform {self.deform}, estimated error "
                f"{self.error['total']:.3g} (tol {self.tol:.3g}), cost {self.cost_s:.3g} s>")


def resolve(build, outputs, tol: float, *, t_end: float | None = None, elements: int = 4,
            max_elements: int = 256, deform=DEFORMATIONS, t_eval=None, load_steps: int = 10,
            **simulate_options) -> Plan:
    """Choose the elements and deformations of a model for outputs accurate to ``tol``.

    Parameters
    ----------
    build : callable
        ``build(elements, deform)`` returns ``(model, handles)`` or ``(model, handles, options)``: a
        Model (or System) with its beams divided into ``elements`` (an int: how it is shared among
        beams is the builder's) and modelling the deformations ``deform`` (a tuple); ``handles`` a dict
        of named outputs — Points or Bodies (their positions, m) or functions ``f(system, solution)``
        returning an array; ``options`` keyword arguments of that model's ``simulate`` (``q0=``, ...).
    outputs : str or list of str
        The names of ``handles`` to make accurate.
    tol : float
        The largest error allowed on every output (its units: m for points), over the output times.
    t_end : float, optional
        Simulate to t_end (s, at ``t_eval`` or 101 times); None: static equilibrium
        (``load_steps``).
    elements, max_elements : int
        The first level m₀ and the budget (the finest level tried).
    deform : tuple of str
        The deformations to keep or drop (default: bend_y, bend_z, torsion).
    t_eval : array, optional
        The output times of a simulation (default: 101 over [0, t_end]).
    load_steps : int
        ``static_equilibrium``'s load steps (1 to 100,000), for t_end = None.
    **simulate_options
        Passed to ``rf.simulate`` (method, rtol, atol, max_steps, ...), for every run; judged before
        any run as simulate judges them. With t_end = None (statics, no simulation) they are refused.

    Returns
    -------
    Plan

    Raises
    ------
    ValueError
        A bad argument, naming it: resolve's own (tol, elements, load_steps, ...) and the options of
        simulate, judged by simulate's and static_equilibrium's checks before any run. An unknown
        option of simulate is a TypeError, as simulate's.
    ResolveError (a ValueError)
        What resolve finds about its arguments with the builder's models: a failing builder, outputs it
        does not return or whose shape changes with the elements (or is empty), a t_end the first
        analysis cannot reach within max_steps (judged in its first ``PACE_STEPS`` steps), no level
        within the budget. ``runs`` holds the analyses made.
    SimulationError
        A run that fails numerically (step size underflow, Newton divergence, max_steps reached
        before t_end, ...): simulate's or static_equilibrium's error, naming the time and the cause,
        with the analysis (elements, deform) in its message and the analyses made before it in
        ``runs``.

    Examples
    --------
    >>> import rigidfem as rf
    >>> def build(elements, deform):
    ...     model, h = rf.samples.cantilever(elements=elements, deform=deform)
    ...     model.add_force("load", h["beam"].tip, (0.0, -1.0, 0.0))
    ...     return model, {"tip": h["beam"].tip}
    >>> plan = rf.resolve(build, "tip", 1e-5, deform=("bend_z",))
    >>> plan.elements >= 4, plan.deform
    (True, ('bend_z',))
    """
    if not callable(build):
        raise ResolveError(f"build: expected a function build(elements, deform) -> (model, handles), got {build!r}")
    names = [outputs] if isinstance(outputs, str) else list(outputs) if _is_sequence(outputs) else None
    if not names or not all(isinstance(n, str) for n in names):
        raise ResolveError(f"outputs: expected the name of a handle or a list of names, got {outputs!r}")
    tol = _checks.scalar(tol, "tol", positive=True)
    elements = _checks.integer(elements, "elements", minimum=1, maximum=10**6)
    max_elements = _checks.integer(max_elements, "max_elements", minimum=elements, maximum=10**6)
    if isinstance(deform, str) or not _is_sequence(deform) or not all(isinstance(d, str) for d in deform):
        raise ResolveError(f"deform: expected a tuple of deformation names such as ('bend_z', 'torsion'), got {deform!r}")
    deform = tuple(deform)
    if t_end is not None:
        t_end = _checks.scalar(t_end, "t_end", positive=True)
        t_eval = np.linspace(0.0, t_end, 101) if t_eval is None else _checks.vector(t_eval, "t_eval")
    load_steps = _checks.integer(load_steps, "load_steps", minimum=1, maximum=MAX_LOAD_STEPS)
    _judge_options(simulate_options, t_end)
    job = _Job(build, names, tol, t_end, t_eval, load_steps, simulate_options)

    # 1. elements: m0, 2 m0, ... with every deformation, until a level is estimated within SPACE · tol
    levels, values, order, chosen = [], [], 2.0, None
    m = elements
    while m <= max_elements and chosen is None:
        values.append(job.outputs(m, deform, REFINEMENT_TIME * tol))
        levels.append(m)
        m *= 2
        if len(levels) < 3:
            continue
        d, d_prev = _difference(values[-1], values[-2]), _difference(values[-2], values[-3])
        if d > 0 and d_prev > 0:
            order = float(np.clip(np.log2(d_prev / d), 1.0, 4.0))
        limit = _limit(values[-1], values[-2], order)
        for j in range(len(levels) - 1):  # the cheapest level estimated within the share
            estimate = _difference(values[j], limit)
            if estimate <= SPACE * tol:
                chosen = (levels[j], estimate, limit)
                break
    if chosen is None:
        best = "none (fewer than three levels)"
        if len(levels) >= 3:
            best = f"{_difference(values[-1], _limit(values[-1], values[-2], order)):.3g} at elements = {levels[-1]}"
        raise ResolveError(f"tol: expected a tolerance that a level up to max_elements = {max_elements} meets "
                           f"({SPACE:g} of tol = {tol:g} for the elements), got {tol:g}: the best estimate reached is "
                           f"{best}; raise max_elements or tol", job.runs)
    m, space_error, limit = chosen

    # 2. deformations: each dropped alone at m, then the cheapest set within DROP · tol
    full = values[levels.index(m)]
    alone = {}
    for d in deform:
        reduced = tuple(x for x in deform if x != d)
        alone[d] = _difference(job.outputs(m, reduced, REFINEMENT_TIME * tol), full)
    dropped, total = [], 0.0
    for d in sorted(alone, key=alone.get):
        if total + alone[d] <= DROP * tol:
            dropped.append(d)
            total += alone[d]
    while dropped:
        kept_set = tuple(x for x in deform if x not in dropped)
        together = _difference(job.outputs(m, kept_set, REFINEMENT_TIME * tol), full)
        if together <= DROP * tol:
            break
        dropped.pop()
    kept_set = tuple(x for x in deform if x not in dropped)
    drop_error = _difference(job.outputs(m, kept_set, REFINEMENT_TIME * tol), full) if dropped else 0.0

    # 3. the chosen model at its own time tolerance, with its time error
    final = job.final(m, kept_set, TIME * tol)
    return Plan(m, kept_set, {d: alone[d] for d in dropped}, {d: alone[d] for d in kept_set}, space_error,
                drop_error, final["time_error"], tol, order, final["cost_s"], _beams(final["system"]),
                dict(zip(names, limit)), final["options"], final["system"], final["handles"], final["solution"],
                job.runs)


class _Job:
    """The builder's calls and the analyses, each recorded in ``runs``."""

    def __init__(self, build, names, tol, t_end, t_eval, load_steps, options):
        self.build, self.names, self.tol, self.t_end, self.t_eval = build, names, tol, t_end, t_eval
        self.load_steps, self.options, self.runs, self.nq = load_steps, options, [], {}
        self.shapes = {}     # output name -> (its shape, the analysis it was first seen in)
        self.paced = False   # the first dynamic analysis's pace judged (PACE_STEPS)

    def model(self, m, deform):
        """(system, handles, options) from the builder, checked."""
        where = f"elements = {m}, deform = {deform}"
        try:
            made = self.build(m, deform)
        except Exception as e:  # noqa: BLE001 (the user's code: any failure is reported with the runs made)
            raise ResolveError(f"build: expected a function that makes the model, got one that failed for {where}: "
                               f"{type(e).__name__}: {e}", self.runs) from e
        if not isinstance(made, tuple) or len(made) not in (2, 3):
            raise ResolveError(f"build: expected (model, handles) or (model, handles, options) for {where}, "
                               f"got {type(made).__name__}", self.runs)
        model, handles, *rest = made
        options = rest[0] if rest else {}
        if isinstance(model, Model):
            model = model.compile()
        if not isinstance(model, System) or not isinstance(handles, dict) or not isinstance(options, dict):
            raise ResolveError(f"build: expected a Model or System, a dict of handles and a dict of options for "
                               f"{where}, got {type(model).__name__}, {type(handles).__name__}, "
                               f"{type(options).__name__}", self.runs)
        missing = [n for n in self.names if n not in handles]
        if missing:
            raise ResolveError(f"outputs: expected names among the handles the builder returns "
                               f"({sorted(handles)}), got {missing} (for {where})", self.runs)
        for n in self.names:
            if not isinstance(handles[n], (Point, Body)) and not callable(handles[n]):
                raise ResolveError(f"build: expected a Point, Body or function as handle {n!r}, got "
                                   f"{type(handles[n]).__name__} (for {where})", self.runs)
        # a topology that changes with m other than through the beams: the coordinates must grow with m
        before = self.nq.get(deform)
        if before is not None and m > before[0] and model.nq <= before[1] and before[1] > 0:
            raise ResolveError(f"build: expected a model whose coordinates grow with the elements, got nq = "
                               f"{model.nq} for elements = {m} and {before[1]} for {before[0]} (deform = {deform}): "
                               "does it pass elements to add_beam?", self.runs)
        self.nq[deform] = (m, model.nq)
        return model, handles, options

    def solve(self, system, options, atol, where):
        """The solution (Result or Equilibrium) and its wall time. A bad option of the run is a ValueError
        naming it (the builder, for one of its own options), a numerical failure a SimulationError naming
        the analysis; the exceptions of the model's own callbacks reach the caller unchanged."""
        from ..analysis.statics import static_equilibrium

        start = time.perf_counter()
        try:
            if self.t_end is None:
                solution = static_equilibrium(system, load_steps=self.load_steps)
            else:
                solution = self._simulate(system, {"rtol": 0.0, "atol": atol, **self.options, **options}, where)
        except ResolveError:
            raise
        except _core.SimulationError as e:
            raise self._failed(e, where) from e
        except (ValueError, TypeError) as e:
            named = _named(str(e))
            if named & set(options) and not named & set(self.options):  # one of the builder's options
                raise ResolveError(f"build: expected options of simulate for {where}, got {sorted(named & set(options))} "
                                   f"refused: {type(e).__name__}: {e}", self.runs) from e
            raise  # simulate's own message, naming the option of resolve's call (or t_end, t_eval)
        return solution, time.perf_counter() - start

    def _simulate(self, system, kw, where):
        """simulate(system, t_end, **kw); the first analysis runs PACE_STEPS steps first and refuses a t_end it
        cannot reach within max_steps (its run, when it ends within them)."""
        from ..simulation import options as options_
        from ..simulation.integration import simulate
        from ..simulation.result import finished

        what = f"resolve ({len(self.runs)} analyses made)"
        if not self.paced:
            self.paced = True
            limit = options_.compiled("auto", {"max_steps": kw.get("max_steps", options_.resolve({})["max_steps"])},
                                      every=True).get("max_steps")  # converted as simulate converts it
            if limit > PACE_STEPS:
                try:
                    return finished(simulate(system, self.t_end, t_eval=self.t_eval,
                                             **dict(kw, max_steps=PACE_STEPS, error_estimate=False)), what)
                except _core.SimulationError as e:
                    if type(e) is not _core.SimulationError or \
                            not re.search(rf"\bmax_steps = {PACE_STEPS} reached", str(getattr(e, "cause", ""))):
                        raise  # the run's own failure, the same as the whole run's
                    self._judge_pace(e, limit, where)
        return finished(simulate(system, self.t_end, t_eval=self.t_eval, **kw), what)

    def _judge_pace(self, error, limit, where):
        """ResolveError naming t_end when the first analysis, stopped after PACE_STEPS steps, cannot reach it
        within max_steps = ``limit``."""
        run, stats = error.result.run, error.result.stats
        t0, reached, steps = run["t0"], float(getattr(error, "time", np.nan)), int(stats.get("steps", PACE_STEPS))
        span = self.t_end - t0
        if run["fixed"]:
            need = np.ceil(span / float(run["dt"]))
            if need > limit:
                raise ResolveError(f"t_end, dt: expected at most max_steps = {limit:,} steps of dt over [t0, t_end], "
                                   f"got (t_end - t0)/dt = {need:g} steps (t_end = {self.t_end:g} s, dt = "
                                   f"{float(run['dt']):g} s)", self.runs)
            return
        fewest = span / run["max_step"]  # max_step = inf: 0
        pace = steps * span / (reached - t0) if reached > t0 else np.inf
        if fewest > limit or not pace <= PACE_MARGIN * limit:
            why = (f"its steps of at most max_step = {run['max_step']:g} s need at least {fewest:.3g}" if fewest > limit
                   else f"the first analysis ({where}) reached t = {reached:.6g} s in {steps:,} steps, a pace that "
                        f"needs about {pace:.3g} steps to t_end (over {PACE_MARGIN:g} times max_steps)")
            raise ResolveError(f"t_end: expected an end time the runs reach within max_steps = {limit:,} steps, got "
                               f"{self.t_end:g} s: {why}; lower t_end or raise max_steps", self.runs)

    def _failed(self, error, where):
        """The run's SimulationError with the analysis named and the runs made; a subclass (a ForceLawError: a
        ValueError too) as it is, with them as a note."""
        context = f"resolve: the analysis of {where} failed"
        if type(error) is _core.SimulationError:
            message = str(error)
            failed = _core.SimulationError(f"{context} {message}" if message.startswith("at t = ")
                                           else f"{context}: {message}")
            for name in ("time", "cause", "result"):
                if hasattr(error, name):
                    setattr(failed, name, getattr(error, name))
        else:
            failed = error
            if hasattr(failed, "add_note"):
                failed.add_note(f"({context}; {len(self.runs)} analyses made before it)")
        failed.runs = self.runs
        return failed

    def values(self, system, handles, solution, where) -> list:
        out = []
        for n in self.names:
            h = handles[n]
            if isinstance(h, (Point, Body)):
                point = h.origin if isinstance(h, Body) else h
                out.append(solution.position(point) if self.t_end is not None else system.position(point, 0.0, solution.q))
            else:
                try:
                    out.append(np.asarray(h(system, solution), dtype=float))
                except Exception as e:  # noqa: BLE001 (the user's function: reported with the runs made)
                    raise ResolveError(f"outputs: expected {n!r} to return an array of numbers for the solution of "
                                       f"{where}, got {type(e).__name__}: {e}", self.runs) from e
            shape = out[-1].shape
            if out[-1].size == 0:
                raise ResolveError(f"outputs: expected a non-empty array from {n!r}, got shape {shape} (for {where})",
                                   self.runs)
            first = self.shapes.setdefault(n, (shape, where))
            if first[0] != shape:
                raise ResolveError(f"outputs: expected the same shape of {n!r} at every resolution, got {shape} for "
                                   f"{where} and {first[0]} for {first[1]}", self.runs)
            if not np.all(np.isfinite(out[-1])):
                raise ResolveError(f"outputs: expected finite values of {n!r}, got NaN or inf (from the model of "
                                   f"nq = {system.nq})", self.runs)
        return out

    def analysis(self, m, deform, atol):
        """(system, handles, solution, wall time, values) of the model at m and deform."""
        where = f"elements = {m}, deform = {deform}"
        system, handles, options = self.model(m, deform)
        solution, wall = self.solve(system, options, atol, where)
        values = self.values(system, handles, solution, where)
        return system, handles, solution, wall, values

    def outputs(self, m, deform, atol) -> list:
        system, _, _, wall, values = self.analysis(m, deform, atol)
        self.runs.append({"elements": m, "deform": deform, "nq": system.nq, "wall_time_s": wall,
                          "values": values})
        return values

    def final(self, m, deform, atol) -> dict:
        system, handles, solution, wall, values = self.analysis(m, deform, atol)
        time_error = 0.0
        if self.t_end is not None:
            estimate = solution.error_estimate
            for n in self.names:
                h = handles[n]
                q = (lambda r, h=h: r.position(h)) if isinstance(h, (Point, Body)) else (lambda r, h=h: h(system, r))
                time_error = max(time_error, float(np.max(estimate.of(q))))
        self.runs.append({"elements": m, "deform": deform, "nq": system.nq, "wall_time_s": wall, "values": values})
        options = {} if self.t_end is None else {"atol": atol, "rtol": 0.0}
        return {"system": system, "handles": handles, "solution": solution, "cost_s": wall,
                "time_error": time_error, "options": options}


def _judge_options(options: dict, t_end) -> None:
    """The options resolve passes to simulate, judged before any run by simulate's own checks (what needs no
    system: the names, the method, each option's conversion; their values against the system are simulate's
    at the first run, before it integrates); with t_end = None (statics) none is taken."""
    from ..simulation import options as options_
    from ..simulation.integration import simulate

    if t_end is None:
        if options:
            name = next(iter(options))
            raise _checks.refuse(f"{name}: expected no options of simulate with t_end = None (a static equilibrium, which "
                             f"takes load_steps), got {name}={options[name]!r}; give t_end to simulate")
        return
    method = options.get("method", "auto")
    options_.method(method)  # ValueError listing the methods
    run = {p.name for p in inspect.signature(simulate).parameters.values() if p.kind is p.KEYWORD_ONLY}
    given = options_.resolve({k: v for k, v in options.items() if k not in run and k != "method"})  # TypeError: unknown
    options_.compiled("dopri5" if method.startswith("scipy:") else method, given, every=True)  # ValueError naming one
    if "error_estimate" in options:  # simulate judges it after its run
        _checks.boolean(options["error_estimate"], "error_estimate")


def _named(message: str) -> set:
    """The arguments a ValueError's message names ("rtol, atol: expected ..." -> {"rtol", "atol"})."""
    match = re.match(r"([A-Za-z_]\w*(?:, ?[A-Za-z_]\w*)*)(?:\[[^\]]*\])?: ", message)
    return {n.strip() for n in match.group(1).split(",")} if match else set()


def _difference(a: list, b: list) -> float:
    """The largest difference between two lists of output arrays (Euclidean over a point's x, y, z)."""
    worst = 0.0
    for x, y in zip(a, b):
        d = np.abs(np.asarray(x) - np.asarray(y))
        if d.ndim >= 1 and d.shape[-1] == 3:
            d = np.linalg.norm(d, axis=-1)
        worst = max(worst, float(np.max(d)) if d.size else 0.0)
    return worst


def _limit(fine: list, coarse: list, order: float) -> list:
    """Richardson's limit z_k + (z_k − z_{k−1})/(2^p − 1) of each output."""
    return [np.asarray(f) + (np.asarray(f) - np.asarray(c)) / (2.0**order - 1.0) for f, c in zip(fine, coarse)]


def _beams(system) -> dict:
    """Beam name -> elements, from the rfes' names ("<beam>.rfe<k>", k = 0 ... m)."""
    beams = {}
    for name in system.body_names:
        match = re.fullmatch(r"(.*)\.rfe(\d+)", name)
        if match:
            beams[match.group(1)] = max(beams.get(match.group(1), 0), int(match.group(2)))
    return beams


def _is_sequence(x) -> bool:
    return isinstance(x, (list, tuple))
