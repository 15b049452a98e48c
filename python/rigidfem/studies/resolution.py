"""The model's resolution chosen for a requested accuracy: ``rf.resolve`` (issue 24, item 4).

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
grow with the elements is a ``ResolveError`` (a ValueError) naming it; so is a tol that no level up to
``max_elements`` meets (with the best estimate reached). Either carries ``runs`` (every analysis
made) and ``best`` (the finest level's plan so far, or None).
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field

import numpy as np

from .._core import Body, Point
from ..model.model import Model, System

#: Shares of tol: the space (elements), the time integration and the dropped deformations.
SPACE, TIME, DROP = 0.5, 0.25, 0.25
#: The time integration's atol during refinement, over tol.
REFINEMENT_TIME = 1.0 / 20.0
#: The deformations resolve tries to drop by default (the modified formulation's).
DEFORMATIONS = ("bend_y", "bend_z", "torsion")


class ResolveError(ValueError):
    """``rf.resolve`` could not meet its task: ``runs`` holds every analysis made, ``best`` the plan of
    the finest level reached (or None)."""

    def __init__(self, message, runs=None, best=None):
        super().__init__(message)
        self.runs, self.best = runs or [], best


@dataclass
class Plan:
    """What ``rf.resolve`` chose, why, and the estimated errors (in the outputs' units: m for points)."""

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
    **simulate_options
        Passed to ``rf.simulate`` (method, ...), for every run.

    Returns
    -------
    Plan

    Raises
    ------
    ResolveError (a ValueError)
        Bad arguments, a failing builder, outputs it does not return, or no level within the budget.
    """
    from ..base import _checks

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

    def model(self, m, deform):
        """(system, handles, options) from the builder, checked."""
        where = f"elements = {m}, deform = {deform}"
        try:
            made = self.build(m, deform)
        except Exception as e:  # noqa: BLE001 (the user's code: any failure is reported with the runs made)
            raise ResolveError(f"build: failed for {where}: {type(e).__name__}: {e}", self.runs) from e
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

    def solve(self, system, options, atol):
        """The solution (Result or Equilibrium) and its wall time."""
        from ..analysis.statics import static_equilibrium
        from ..simulation.integration import simulate
        from ..simulation.result import finished

        start = time.perf_counter()
        if self.t_end is None:
            solution = static_equilibrium(system, load_steps=self.load_steps)
        else:
            kw = dict(dict(rtol=0.0, atol=atol), **self.options)
            kw.update(options)
            solution = finished(simulate(system, self.t_end, t_eval=self.t_eval, **kw),
                                f"resolve ({len(self.runs)} analyses made)")
        return solution, time.perf_counter() - start

    def values(self, system, handles, solution) -> list:
        out = []
        for n in self.names:
            h = handles[n]
            if isinstance(h, (Point, Body)):
                point = h.origin if isinstance(h, Body) else h
                out.append(solution.position(point) if self.t_end is not None else system.position(point, 0.0, solution.q))
            else:
                out.append(np.asarray(h(system, solution), dtype=float))
            if not np.all(np.isfinite(out[-1])):
                raise ResolveError(f"outputs: expected finite values of {n!r}, got NaN or inf (from the model of "
                                   f"nq = {system.nq})", self.runs)
        return out

    def outputs(self, m, deform, atol) -> list:
        system, handles, options = self.model(m, deform)
        try:
            solution, wall = self.solve(system, options, atol)
            values = self.values(system, handles, solution)
        except ResolveError:
            raise
        except Exception as e:  # noqa: BLE001 (reported with the runs made)
            raise ResolveError(f"build: the analysis of elements = {m}, deform = {deform} failed: "
                               f"{type(e).__name__}: {e}", self.runs) from e
        self.runs.append({"elements": m, "deform": deform, "nq": system.nq, "wall_time_s": wall,
                          "values": values})
        return values

    def final(self, m, deform, atol) -> dict:
        system, handles, options = self.model(m, deform)
        solution, wall = self.solve(system, options, atol)
        values = self.values(system, handles, solution)
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
