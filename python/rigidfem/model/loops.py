"""Loop closures: joints that close a kinematic loop between two bodies, and length actuators.

Each adds constraint equations g(q, t) = 0 to the tree's equations (book ch. 2.6, 7.3):

    M(q) q̈ = f(q, q̇, t) + Gᵀ λ,   g(q, t) = 0,   G = ∂g/∂q,

with the multipliers λ the reactions. A loop joint joins frame A on body ``a`` and frame B on
body ``b``, which coincide when the loop is assembled; the joint kind says what it leaves free:

{kinds}

An actuator (``Model.add_actuator``) is a distance loop whose length l(t) is prescribed: a
hydraulic cylinder under position control; its force is the loop's reaction.
"""

from __future__ import annotations

import numpy as np

from ..base import _checks
from . import parameters
import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Point, Profile
from .force_elements import point_of

KINDS = tuple(_core._Model._loop_kinds())  # the C++ table of kinds (constraints.cpp)


def _kinds_table() -> str:
    """The C++ table of kinds as the reST table of this module's docstring: kind, rows, what it leaves free."""
    rows = [(f'``"{k["kind"]}"``', str(k["rows"]), k["free"]) for k in _core._Model._loop_kind_table()]
    widths = [max(len(r[c]) for r in rows + [("kind", "rows", "free relative motion of frame B in frame A")])
              for c in range(3)]
    rule = "  ".join("=" * w for w in widths)
    line = lambda cells: "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()  # noqa: E731
    return "\n".join([rule, line(("kind", "rows", "free relative motion of frame B in frame A")), rule,
                      *(line(r) for r in rows), rule])


__doc__ = __doc__.replace("{kinds}", _kinds_table())


def _frame(model, where, frame, name: str):
    """(body index, 4x4 frame in that body) of a Body (its frame), a Point (the body's axes at the
    point) or the ground; ``frame`` (4, 4) in the body's frame replaces the default."""
    body, origin = point_of(model, where, name)
    if frame is None:
        F = np.eye(4)
        F[:3, 3] = origin
    else:
        if isinstance(where, Point) and np.any(origin != 0.0):
            raise _checks.refuse(f"frame_{name}: expected either a Point or a frame on a Body, not both, got the "
                                 f"point {where!r} and a frame")
        F = _checks.reals(frame, (4, 4), f"frame_{name}")
    return body, F


def add_loop_joint(model, name: str, kind: str, a, b, *, frame_a=None, frame_b=None,
                   length: float | None = None) -> str:
    """Close a loop ``name`` between ``a`` and ``b`` (see ``Model.add_loop_joint``); returns its name."""
    if kind not in KINDS:
        raise _checks.refuse(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    ia, Fa = _frame(model, a, frame_a, "a")
    ib, Fb = _frame(model, b, frame_b, "b")
    if kind == "distance":
        if length is None:
            raise _checks.refuse("length: expected a positive distance in m for a distance loop, got None")
        length = _checks.real(length, "length", "a positive distance in m")
    elif length is not None:
        raise _checks.refuse(f"length: expected None for a {kind} loop (only distance loops have a length), got {length!r}")
    return _add(model, name, kind, ia, Fa, ib, Fb, length or 0.0, None)


def add_actuator(model, name: str, a, b, length) -> str:
    """A linear actuator ``name`` between points ``a`` and ``b`` with prescribed length (see
    ``Model.add_actuator``); returns its name."""
    ia, Fa = _frame(model, a, None, "a")
    ib, Fb = _frame(model, b, None, "b")
    if isinstance(length, Profile):
        name = _add(model, name, "distance", ia, Fa, ib, Fb, 0.0, length, actuator=True)
        parameters.register(model, parameters.ProfileGroup(f"{name}.length", "loop", -1, model._nloops - 1, length,
                                                           "the actuator's (m, s, m/s)"))
        return name
    return _add(model, name, "distance", ia, Fa, ib, Fb, _checks.real(length, "length", "a positive distance in m"), None,
                actuator=True)


def _add(model, name, kind, ia, Fa, ib, Fb, length, drive, actuator=False) -> str:
    """The loop ``name`` added; returns its name."""
    return model._add_loop(name, kind, ia, Fa, ib, Fb, length, drive, actuator)


def assemble(system, q, qd=None, *, t: float | None = None, tol: float = 1e-12, max_iterations: int = 50):
    """Coordinates (q, q̇) on the loops' constraint manifold nearest to a guess (see
    ``System.assemble``)."""
    system = _checks.system(system)
    q = _checks.array(q, (system.nq,), "q")
    qd = np.zeros(system.nq) if qd is None else _checks.array(qd, (system.nq,), "qd")
    t = _checks.scalar(_checks.pose_time(system, t), "t")
    tol = _checks.scalar(tol, "tol", positive=True)
    max_iterations = _checks.integer(max_iterations, "max_iterations", minimum=1, maximum=10_000)
    return system._assemble(t, q, qd, tol, max_iterations)
