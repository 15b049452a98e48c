"""Events: the times at which a function g(t, q, q̇) of the run crosses zero (``rf.simulate(..., events=[...])``),
located by the C++ run on the method's dense output, as SciPy's ``solve_ivp`` does
(``cpp/include/rigidfem/events.hpp``).

An ``Event`` names what crosses: a coordinate or its rate, a point's position along an axis, a contact's gap, or a
Python function of (t, q, q̇) (the slow path: called from C++ at every step's end and in the root's search). After
every accepted step each g is evaluated at the step's end; where it changed sign (in the event's ``direction``) its
root is located on the dense output by the Illinois method to a bracket of 1e-12 of the step, and recorded in
``Result.events`` with the state there. A ``terminal`` event ends the run at its first root.

A run with contacts locates every contact's onset and separation (the gap of its shapes crossing zero) unless
``simulate(..., contact_events=False)``: the contact force starts or ends there, a kink in the right-hand side, and
adaptive methods take the step that crossed it again from its start so that it ends a hair (1e-9 of the step) before
the root, then go on from a hair past it. Each step then covers a smooth stretch: its error estimate holds across the
impact as anywhere else, and the sensitivities' equations see the Jacobian change where it does. Such a root is
recorded where that step ends.

With ``sensitivities=[...]`` each root carries dt*/dp = −(∂g/∂y · S)/ġ (``Fired.dt_dp``, s per unit of p).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np

from ..base import _checks
from .._core import Body, Point

#: The axes a point's position is measured along, by name.
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class Event:
    """A function whose zeros a run locates: ``g = of − value``.

    Parameters
    ----------
    name : str
        The event's name in ``Result.events``.
    of :
        What crosses ``value``: a coordinate's name (or its handle; m or rad, its rate with ``rate=True``), a
        ``Point`` or ``Body`` with ``axis`` (its global position along the axis, m), a contact's name or handle
        (``Model.add_contact``: the smallest gap between its shapes, m, negative once they overlap), or a function
        ``of(t, q, qd) -> float`` (a Python call per step and per iteration of the root's search: the slow path).
    value : float
        The level g crosses (the unit of ``of``).
    direction : int
        +1: only where g rises through ``value``, −1: only where it falls, 0 (default): both.
    terminal : bool
        The run ends at the first root (``Result.t[-1]`` is its time).
    axis : "x", "y", "z" or a 3-vector, optional
        For a point: the global direction its position is measured along.
    rate : bool
        For a coordinate: its rate q̇ (m/s or rad/s) crosses ``value``.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.pendulum()
    >>> system = model.compile()
    >>> low = rf.Event("low", "link.ry", value=0.0, direction=-1, terminal=True)
    >>> res = rf.simulate(system, 5.0, q0=[0.5], events=[low])
    >>> round(float(res.t[-1]), 3)
    0.416
    """

    name: str
    of: object
    value: float = 0.0
    direction: int = 0
    terminal: bool = False
    axis: object = None
    rate: bool = False

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise _checks.refuse(f"name: expected a non-empty str, got {self.name!r}")
        object.__setattr__(self, "value", _checks.real(self.value, "value", "the level g crosses (a finite number)"))
        if not np.isfinite(self.value):
            raise _checks.refuse(f"value: expected a finite level, got {self.value!r}")
        if not isinstance(self.direction, (int, np.integer)) or isinstance(self.direction, bool) \
                or self.direction not in (-1, 0, 1):
            raise _checks.refuse(f"direction: expected -1, 0 or 1, got {self.direction!r}")
        object.__setattr__(self, "direction", int(self.direction))
        _checks.boolean(self.terminal, "terminal")
        _checks.boolean(self.rate, "rate")

    def _compiled(self, system, restarts: bool = False) -> tuple:
        """The arguments of ``IntegratorOptions.add_event`` for ``system``; ValueError naming ``events``."""
        of, zero = self.of, np.zeros(3)
        if self.rate and not isinstance(of, (str, int, np.integer)):
            raise _checks.refuse(f"events: expected rate=True with a coordinate (event {self.name!r}), got {of!r}")
        if isinstance(of, Body):
            of = of.origin
        if isinstance(of, Point):
            _checks.same_model(of, system, "events", "points and bodies of the model this system was compiled from")
            if of.body < 0:
                raise _checks.refuse(f"events: expected a point on a moving body (event {self.name!r}), got {of!r}")
            return ("point", self.name, int(of.body), np.asarray(of.r, float), _axis(self), self.value,
                    self.direction, self.terminal, restarts, None)
        if self.axis is not None:
            raise _checks.refuse(f"axis: expected None for an event of {of!r} (an axis is a point's), got {self.axis!r}")
        if isinstance(of, str):
            coordinates, contacts = list(system.coordinate_names), list(system.contact_names)
            if of in coordinates:
                return ("rate" if self.rate else "coordinate", self.name, coordinates.index(of), zero, zero,
                        self.value, self.direction, self.terminal, restarts, None)
            if of in contacts and not self.rate:
                # the contact force starts or ends where the gap crosses zero: adaptive steps end there
                return ("contact", self.name, contacts.index(of), zero, zero, self.value, self.direction,
                        self.terminal, self.value == 0.0, None)
            raise _checks.refuse(f"events: expected a coordinate ({_few(coordinates)}) or contact ({_few(contacts)}) "
                                 f"name (event {self.name!r}), got {of!r}")
        if callable(of):
            return ("function", self.name, -1, zero, zero, self.value, self.direction, self.terminal, restarts,
                    _checked(of, self.name))
        raise _checks.refuse(f"events: expected a coordinate or contact name, a Point or Body, or a function "
                             f"of(t, q, qd) (event {self.name!r}), got {of!r}")


@dataclass(frozen=True)
class Fired:
    """A located root: the ``event``'s name, its time ``t`` (s), the ``direction`` g crossed in (+1 rising, −1
    falling: a contact's onset is −1, its separation +1), the state ``q``, ``qd`` there and, with forward
    sensitivities, ``dt_dp`` {parameter: dt*/dp} (s per unit of the parameter)."""

    event: str
    t: float
    direction: int
    q: np.ndarray = field(repr=False)
    qd: np.ndarray = field(repr=False)
    dt_dp: dict = field(default_factory=dict, repr=False)


def compiled(system, events, contact_events) -> list:
    """The Events of a run, the contacts' own first (``contact_events``), each as add_event's arguments; the names
    unique. ValueError naming ``events``."""
    events = as_list(events)
    own = [Event(name, name) for name in system.contact_names] if _checks.boolean(contact_events, "contact_events") else []
    names = [e.name for e in own + events]
    if len(set(names)) != len(names):
        twice = sorted({n for n in names if names.count(n) > 1})
        raise _checks.refuse(f"events: expected events of different names (the contacts' own carry the contacts' "
                             f"names), got {twice} more than once")
    return [e._compiled(system) for e in own + events]


def as_list(events) -> list:
    """``simulate``'s ``events`` as a list of Events (None: none; one Event: itself); ValueError naming ``events``."""
    if events is None:
        return []
    if isinstance(events, Event):
        return [events]
    if isinstance(events, (str, bytes)):
        raise _checks.refuse(f"events: expected a list of rigidfem.Event, got {events!r}")
    try:
        events = list(events)
    except TypeError:
        raise _checks.refuse(f"events: expected a list of rigidfem.Event, got {events!r}") from None
    for e in events:
        if not isinstance(e, Event):
            raise _checks.refuse(f"events: expected a list of rigidfem.Event, got {e!r} in it")
    return events


def fired(system, specs, records, sensitivities) -> list:
    """The Fired records of a run from ``_core._integrate``'s (event, t, direction, y, dt/dp) tuples."""
    n = system.nq
    return [Fired(specs[k][1], float(t), int(direction), np.array(y[:n]), np.array(y[n:2 * n]),
                  {name: float(v) for name, v in zip(sensitivities, dt_dp)})
            for k, t, direction, y, dt_dp in records]


def _axis(event: Event) -> np.ndarray:
    """A point event's unit axis (global)."""
    axis = event.axis
    if axis is None:
        raise _checks.refuse(f"axis: expected 'x', 'y', 'z' or a 3-vector for the point of event {event.name!r}, "
                             "got None")
    if isinstance(axis, str):
        if axis not in AXES:
            raise _checks.refuse(f"axis: expected 'x', 'y', 'z' or a 3-vector, got {axis!r}")
        return np.array(AXES[axis])
    v = _checks.reals(axis, (3,), "axis")
    size = np.abs(v).max()
    if not size > 0.0:
        raise _checks.refuse(f"axis: expected a non-zero 3-vector, got {axis!r}")
    v = v / size  # scaled first: a tiny vector's norm would underflow
    return v / np.linalg.norm(v)


def _checked(function, name: str):
    """``function`` returning a float, or ValueError naming ``events`` and what it returned."""
    def g(t, q, qd):
        value = function(t, q, qd)
        if isinstance(value, (str, bytes, bool)) or not isinstance(value, (numbers.Real, np.floating, np.integer)) \
                and not (isinstance(value, np.ndarray) and value.shape == () and value.dtype.kind in "fi"):
            raise _checks.refuse(f"events: expected the function of event {name!r} to return a number, got "
                                 f"{value!r} at t = {t:g} s")
        return float(value)
    return g


def _few(names) -> str:
    """Up to six names, for a message."""
    names = list(names)
    return ", ".join(map(repr, names[:6])) + (", ..." if len(names) > 6 else "") if names else "none"
