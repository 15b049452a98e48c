"""The result of a simulation: its outputs at the times ``t`` as numpy arrays, computed from (q, q̇) in C++ on first
use, its error estimate (a second run of the function that made it) and its exports."""

from __future__ import annotations

import dataclasses
import functools
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..base import _checks, display, export
import rigidfem._core as _core  # the compiled core, by its absolute name
from . import error_control
from . import events as events_
from . import options as options_
from ..model import parameters as parameters_
from ..base.persistence import Versioned, read_result
from .._core import Body, Point


#: The outputs ``_core._evaluate_outputs`` computes, in its order (Result's properties).
OUTPUTS = ("qdd", "driving_forces", "kinetic_energy", "gravity_energy", "elastic_energy", "dissipated_power",
           "loop_reactions", "element_forces")


@dataclass
class Result(Versioned):
    """A simulation's output at the times ``t`` (s).

    ``q``, ``qd`` are (len(t), nq) in m, rad and per s; ``arm_forces`` (len(t), nz) the forces s
    of the Maxwell arms (N or N·m; the viscoelastic sde laws, ``system.arms``), zero columns
    without arms. The other arrays are computed from them on first use: ``qdd`` (len(t), nq),
    ``driving_forces`` (len(t), np; N or N·m), energies (len(t),; J; the elastic energy holds the
    arms' Σ s²/(2k)) and ``dissipated_power`` (len(t),; W). ``stats`` holds steps, rejected_steps,
    rhs_evaluations, jacobians, factorizations, newton_iterations, linear_iterations (GMRES, of the
    matrix-free tangent), wall_time (s) and model_size (m: the L that a relative tolerance on outputs
    refers to; NaN when the run held the state), method (what ran) and, with loops, loop_reactions (whose
    multipliers ``loop_reactions`` are).
    ``error_estimate`` is the error bar of the time integration (computed on first use: a second run);
    ``run`` keeps the arguments of the call that made the result.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> res = rf.simulate(system, 1.0, q0=[0.5], t_eval=[0.0, 0.5, 1.0])
    >>> res.t, res.q.shape
    (array([0. , 0.5, 1. ]), (3, 1))
    >>> res.q[:, 0].round(3)
    array([ 0.5  , -0.157, -0.403])
    """

    system: object = field(repr=False)
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    stats: dict
    method: str
    interrupted: bool = False
    arm_forces: np.ndarray = None
    #: (len(t), nl) the loop multipliers the method solved for itself at each output (the Newmark family's);
    #: None where it has none of its own (``loop_reactions`` then takes the forward dynamics')
    multipliers: np.ndarray = field(default=None, repr=False)
    run: dict = field(default=None, repr=False)        #: the arguments of the simulate call that made it
    estimate: object = field(default=None, repr=False)  #: the ErrorEstimate, once computed
    #: {name: (len(t), 2 nq)} the forward sensitivities [∂q/∂p, ∂q̇/∂p] of ``simulate(sensitivities=...)``
    sensitivities: dict = field(default_factory=dict, repr=False)
    #: the function that made it (``rigidfem.simulate``), which its error estimate runs again
    made_by: object = field(default=None, repr=False)
    #: the names of q's columns (``system.coordinate_names``; the saved ones for a result loaded without its system)
    coordinate_names: list = field(default=None, repr=False)
    #: the located roots of the run's events (``simulate(events=...)``, the contacts' onsets and separations), in
    #: time order: ``rigidfem.simulation.events.Fired`` (event, t, direction, q, qd, dt_dp)
    events: list = field(default_factory=list, repr=False)

    def __post_init__(self):
        if self.arm_forces is None:
            self.arm_forces = np.zeros((len(self.t), 0 if self.system is None else self.system.nz))
        if self.coordinate_names is None and self.system is not None:
            self.coordinate_names = list(self.system.coordinate_names)

    @functools.cached_property
    def _outputs(self):
        _checks.result(self, "result", needs="qdd, energies, driving and element forces and loop reactions")
        nl = self.system.nl
        own = np.zeros((0, nl)) if self.multipliers is None else np.ascontiguousarray(self.multipliers, dtype=float)
        outputs = _core._evaluate_outputs(self.system, self.t, self.q, self.qd, self.arm_forces, own)
        for name, values in zip(OUTPUTS, outputs):  # kept, but not without a word
            rows = ~np.isfinite(values).reshape(len(self.t), -1).all(axis=1)
            if rows.any():
                warnings.warn(f"result.{name}: NaN or inf from t = {self.t[np.argmax(rows)]:g} s on ({rows.sum()} of "
                              f"{len(self.t)} outputs; they overflow at these states)", RuntimeWarning, stacklevel=4)
        return outputs

    def _output(self, name: str) -> np.ndarray:
        """One of the ``OUTPUTS``, by its name."""
        return self._outputs[OUTPUTS.index(name)]

    @property
    def qdd(self) -> np.ndarray:
        return self._output("qdd")

    @property
    def driving_forces(self) -> np.ndarray:
        """Forces/torques of the drives (len(t), np), in ``system.prescribed_names`` order."""
        return self._output("driving_forces")

    @property
    def kinetic_energy(self) -> np.ndarray:
        return self._output("kinetic_energy")

    @property
    def gravity_energy(self) -> np.ndarray:
        return self._output("gravity_energy")

    @property
    def elastic_energy(self) -> np.ndarray:
        return self._output("elastic_energy")

    @property
    def potential_energy(self) -> np.ndarray:
        return self._output("gravity_energy") + self._output("elastic_energy")

    @property
    def energy(self) -> np.ndarray:
        """Kinetic + gravity + elastic energy (J)."""
        return self._output("kinetic_energy") + self._output("gravity_energy") + self._output("elastic_energy")

    @property
    def dissipated_power(self) -> np.ndarray:
        """Power (W) dissipated by the dampers (Σ b q̇², force elements' c l̇², ropes) and the Maxwell
        arms (Σ s²/(k τ)): its integral over t closes the energy balance with ``energy``."""
        return self._output("dissipated_power")

    @property
    def loop_reactions(self) -> np.ndarray:
        """Reactions of the loop closures (len(t), nloops, 6): force (N) and torque (N·m) on body
        b in frame A's axes, per ``system.loop_names``; an actuator's force in column 0.
        ``stats["loop_reactions"]`` says where they come from:

        - the Newmark family (newmark, hht, generalized_alpha, implicit_spring) solves for its own
          multipliers λ_{n+1} with q̈_{n+1} at each step's end (index 3, Arnold & Brüls): those, linear
          between the steps' ends at outputs inside a step. They converge as h² to the exact ones and
          differ by O(h²) from the forward dynamics' at the output's (q, q̇);
        - every other method: the multipliers of the forward dynamics at each output's (q, q̇) and
          Maxwell arms' forces, the same computation as ``qdd``. esdirk43 and radau5 solve the loops at
          the acceleration level inside their stages and take exactly these at each step's end, after
          the projection onto the loops; the explicit methods and SciPy's have none of their own.

        ``system.loop_reactions(t, q, qd)`` gives the forward dynamics' at any state."""
        return self._output("loop_reactions").reshape(len(self.t), len(self.system.loop_names), 6)

    @property
    def element_forces(self) -> np.ndarray:
        """Axial forces (len(t), nelements) in N of the force elements (spring-dampers, cylinders, ropes),
        per ``system.element_names``; positive pushing the two points apart (a rope's −T)."""
        return self._output("element_forces")

    @property
    def error_estimate(self):
        """The estimated global time-integration error of the outputs the run measured its error on
        (``error_on``; "bodies" by default), an ``ErrorEstimate``: computed on first use by a second run
        at tolerances 10 times smaller (adaptive methods) or at half the step (fixed steps; Richardson's
        factor 2^p/(2^p − 1) for order p), then kept; ``simulate(..., error_estimate=True)`` computes it
        with the run. ``res.error_estimate.of(lambda r: r.position(beam.tip))`` estimates any other
        quantity's error. The model's own (spatial) error is ``rigidfem.resolve``'s."""
        if self.estimate is None:
            self.estimate = _estimate_error(self)
        return self.estimate

    def position(self, point, frame: Body | None = None) -> np.ndarray:
        """Positions (len(t), 3) in m of a ``Point`` (or a ``Body``'s origin), in the global
        frame or in the frame of the body ``frame``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> res = rf.simulate(system, 1.0, q0=[0.5], t_eval=[0.0, 0.5, 1.0])
        >>> res.position(h["tip"]).shape
        (3, 3)
        >>> res.position(h["tip"])[0].round(4)
        array([-0.4794,  0.    , -0.8776])
        """
        _checks.result(self, "result", needs="positions")
        if isinstance(point, Body):
            point = point.origin
        if not isinstance(point, Point):
            raise _checks.refuse(f"point: expected a Point or a Body, got {point!r}")
        if frame is not None and not isinstance(frame, Body):
            raise _checks.refuse(f"frame: expected None or a Body, got {frame!r}")
        _checks.same_model(point, self.system, "point")
        if frame is not None:
            _checks.same_model(frame, self.system, "frame", "None or a Body of the model this system was compiled from")
        return _core._point_positions(self.system, point.body, point.r, -1 if frame is None else frame.index,
                                      self.t, self.q)

    def sensitivity(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(∂q/∂p, ∂q̇/∂p), each (len(t), nq), by the parameter or initial value ``name`` the run was asked
        for (``simulate(sensitivities=...)``; units of q and q̇ per unit of the parameter).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.spring_mass()
        >>> res = rf.simulate(model.compile(), 1.0, "rk4", dt=1e-3, q0=[0.1], sensitivities=["q0[block.x]"])
        >>> dq, dqd = res.sensitivity("q0[block.x]")
        >>> round(float(dq[0, 0]), 6), dq.shape
        (1.0, (1001, 1))
        """
        if not isinstance(name, str) or name not in self.sensitivities:
            raise _checks.refuse(f"name: expected one of the sensitivities of this run {list(self.sensitivities)}, "
                             f"got {name!r}")
        S = self.sensitivities[name]
        n = self.q.shape[1]
        return S[:, :n], S[:, n:]

    def position_sensitivity(self, point, name: str, frame: Body | None = None) -> np.ndarray:
        """dx/dp (len(t), 3) of a point's position x (``position``: global, or in ``frame``'s axes) by
        ``name``: (∂x/∂q) ∂q/∂p, by a central difference of x along ∂q/∂p at each output (about 1e-10
        relative; m per unit of the parameter), plus, for a profile's number, ∂x/∂p at fixed q: a drive's
        number moves its prescribed coordinate, and the point with it (a central difference of x on the
        systems at p ± h).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> res = rf.simulate(system, 1.0, "rk4", dt=1e-3, q0=[0.5], t_eval=[0.0, 1.0],
        ...                   sensitivities=["q0[link.ry]"])
        >>> res.position_sensitivity(h["tip"], "q0[link.ry]")[0].round(4)
        array([-0.8776,  0.    ,  0.4794])
        """
        _checks.result(self, "result", needs="positions")
        dq, _ = self.sensitivity(name)
        size = np.max(np.abs(dq), axis=1, initial=0.0) / np.maximum(1.0, np.max(np.abs(self.q), axis=1, initial=0.0))
        eps = 6e-6 / np.where(size > 0.0, size, 1.0)  # the largest relative change of q: 6e-6
        up, down = (dataclasses.replace(self, q=self.q + sign * eps[:, None] * dq).position(point, frame)
                    for sign in (1.0, -1.0))
        dx = (up - down) / (2.0 * eps[:, None])  # zero where ∂q/∂p is
        params = self.system._parameters
        if parameters_.initial_value(self.system, name) is None and not params.parameter(name).linear:
            plus, minus, h = params.profile_pair(self.system, name, self.t[0], self.t[-1], "name")
            up, down = (dataclasses.replace(self, system=shifted).position(point, frame) for shifted in (plus, minus))
            dx += (up - down) / (2.0 * h)
        return dx

    def event_times(self, name: str) -> np.ndarray:
        """The times (s) of the roots of the event called ``name`` (``simulate(events=...)``, or a contact's name: its
        onsets and separations), in order; ValueError for a name the run had no event of.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> up = rf.Event("up", "link.ry", direction=1)
        >>> res = rf.simulate(system, 3.0, q0=[0.5], events=[up])
        >>> res.event_times("up").round(3)
        array([1.248, 2.912])
        """
        known = {e[1] for e in self._event_specs()} if self.system is not None and self.run else set()
        if not isinstance(name, str) or name not in known | {f.event for f in self.events}:
            raise _checks.refuse(f"name: expected the name of one of the run's events ({sorted(known) or 'none'}), "
                                 f"got {name!r}")
        return np.array([f.t for f in self.events if f.event == name])

    def _event_specs(self) -> list:
        """The run's events as it compiled them (the contacts' own with them)."""
        return events_.compiled(self.system, self.run.get("events"), self.run.get("contact_events", True) and
                                not str(self.method).startswith("scipy:"))

    def __repr__(self) -> str:
        s = self.stats
        chosen = f" ({s['method']})" if s.get("method", self.method) != self.method else ""
        bar = ""
        if self.estimate is not None:
            bar = ", estimated error " + ", ".join(f"{n} {m:.2g} {u}" for n, u, m in self.estimate.table())
        return (f"<rigidfem Result {self.method}{chosen}: {len(self.t)} outputs to t = {self.t[-1]:g} s, {s['steps']} steps "
                f"({s['rejected_steps']} rejected), {s['rhs_evaluations']} rhs, {s['wall_time']:.3g} s{bar}"
                f"{', interrupted' if self.interrupted else ''}>")

    def _repr_html_(self) -> str:
        """Notebook display: method, outputs, steps, rhs evaluations, wall time (``rigidfem.display``)."""
        return display.result_html(self)

    def to_dataframe(self, points=None):
        """pandas DataFrame indexed by ``t`` (s): a column per coordinate (q, m or rad, named as in
        ``system.coordinate_names``), ``<name>.dot`` per coordinate (q̇, m/s or rad/s) and, for
        ``points={"tip": beam.tip}`` (Points or Bodies), ``tip.x``, ``tip.y``, ``tip.z`` (global
        position, m). ImportError when pandas is not installed (``to_csv`` needs none).

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> res = rf.simulate(system, 1.0, q0=[0.5], t_eval=[0.0, 0.5, 1.0])
        >>> list(res.to_dataframe(points={"tip": h["tip"]}).columns)
        ['link.ry', 'link.ry.dot', 'tip.x', 'tip.y', 'tip.z']
        """
        return export.to_dataframe(self, points)

    def to_csv(self, path, points=None):
        """Write the table of ``to_dataframe`` as CSV with a header line ``t,<columns>`` (numpy only;
        17 significant digits) to ``path`` (a str or ``os.PathLike``). Returns ``path``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> res = rf.simulate(system, 1.0, q0=[0.5], t_eval=[0.0, 0.5, 1.0])
        >>> import pathlib, tempfile
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.csv"
        >>> _ = res.to_csv(path, points={"tip": h["tip"]})
        >>> path.read_text().splitlines()[0]
        't,link.ry,link.ry.dot,tip.x,tip.y,tip.z'
        """
        return export.to_csv(self, _checks.path(path), points)

    def to_npz(self, path):
        """Save t, q, qd, the forward sensitivities (if any), coordinate_names, method, stats and interrupted in a
        NumPy archive at ``path`` (a str or ``os.PathLike``); ``rigidfem.load_npz(path, system)`` reads it back.
        The run's events (``events``) are not saved. Returns ``path``.

        Examples
        --------
        >>> import rigidfem as rf
        >>> model, h = rf.samples.pendulum()
        >>> system = model.compile()
        >>> import pathlib, tempfile
        >>> res = rf.simulate(system, 0.5, q0=[0.5])
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.npz"
        >>> _ = res.to_npz(path)
        >>> back = rf.load_npz(path, system)
        >>> bool((back.q == res.q).all())
        True
        """
        return export.to_npz(self, _checks.path(path))


def load_npz(path, system=None) -> Result:
    """The Result saved by ``Result.to_npz`` at ``path`` (a str or ``os.PathLike``). Give the ``system`` it was
    computed with (its coordinate names must match; ValueError otherwise) to use the outputs that need it:
    positions, energies. Without it, ``t``, ``q``, ``qd``, ``stats``, the sensitivities, ``to_npz`` and the table of
    coordinates (``to_dataframe``, ``to_csv`` without points) work; what needs the system says so (ValueError).
    A file that is not such an archive is a ValueError naming ``path``; a missing one a FileNotFoundError.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> import pathlib, tempfile
    >>> res = rf.simulate(system, 0.5, q0=[0.5])
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.npz"
    >>> _ = res.to_npz(path)
    >>> back = rf.load_npz(path, system)
    >>> bool((back.q == res.q).all())
    True
    """
    return Result(system, **read_result(path, system))


def finished(result: Result, what: str) -> Result:
    """``result`` if Ctrl-C did not stop its run; KeyboardInterrupt naming ``what`` otherwise. For the callers
    that need a whole run (an error estimate's second run, resolve, a study): a partial result taken as a
    finished one would be compared with runs of another length."""
    if result.interrupted:
        at = f"{result.t[-1]:g}" if len(result.t) else "the start"
        raise KeyboardInterrupt(f"{what}: interrupted at t = {at} s")
    return result


def _estimate_error(result: Result):
    """Result.error_estimate: the second run (tolerances / TIGHTER, or dt / 2) at the same output times."""
    run = result.run
    if run is None or result.made_by is None:
        raise _checks.refuse("result: expected a Result made by rigidfem.simulate (a loaded one has no run to repeat)")
    terminal = {e.name for e in run.get("events") or [] if isinstance(e, events_.Event) and e.terminal}
    ended = bool(result.events) and result.events[-1].event in terminal  # at a terminal root (outputs up to it)
    if result.interrupted or not len(result.t) or (result.t[-1] < run["t_end"] and not ended):
        raise _checks.refuse("result: expected a finished run for its error estimate, got one that stopped at "
                         f"t = {result.t[-1] if len(result.t) else run['t0']:g} s")
    kw = {k: v for k, v in run.items() if k not in ("outputs", "fixed")}
    kw["t_eval"], kw["stiffness_warning"] = result.t, False
    if ended:  # the second run to the same end
        kw["t_end"] = result.events[-1].t
    if terminal:  # its events located but none ending it: the first run's end is the second's, a root there or not
        kw["events"] = [dataclasses.replace(e, terminal=False) if isinstance(e, events_.Event) else e
                        for e in run["events"]]
    if run["fixed"]:
        kw["dt"] = run["dt"] / 2.0
        order = options_.method(run["method"]).order  # Richardson's factor 2^p/(2^p − 1)
    else:
        kw["rtol"], kw["atol"] = run["rtol"] / error_control.TIGHTER, run["atol"] / error_control.TIGHTER
        kw["max_steps"] = 10 * run["max_steps"]
        order = None
    try:
        rerun = finished(result.made_by(result.system, **kw), "error_estimate (its second run)")
    except _core.SimulationError as e:
        raise _core.SimulationError(f"error_estimate: the second run failed {e}") from e
    return error_control.estimate(result, rerun, order)
