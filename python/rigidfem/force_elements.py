"""Force elements between two bodies: spring-dampers and hydraulic cylinders under force control.

An element joins a point A on body ``a`` and a point B on body ``b`` (rigid bodies, rfes of a
beam or the ground) and acts along the line between them (book ch. 7.3). With l = |r_B − r_A|
its length and l̇ its rate it pushes the points apart with the axial force

    F = −k (l − l₀) − c l̇ + F(t)      (N; F > 0 pushes, F < 0 pulls),

F e on B and −F e on A, e the unit vector from A to B. F(t) is a constant, a ``rigidfem.motion``
profile (its value in N) or a Python function ``law(t, l, ld)`` (the slow path: called under the
GIL at every evaluation, its derivatives by central differences). The spring's energy
½ k (l − l₀)² counts in ``System.elastic_energy`` and the damper's c l̇² in
``System.dissipated_power``; the applied part F(t) is scaled by the load factor of statics.
``System.element_states`` gives (l, l̇, F) of every element and ``Result.element_forces`` their
forces over a simulation.

A rope (``Model.add_rope``) is a massless tension-only element: with l_u its unstretched length
(a number, or a profile l_u(t) paid out by a winch) it pulls with the tension

    T = (EA (l − l_u) + DA (l̇ − l̇_u)) / l_u   while positive, and 0 when slack,

a spring EA/l_u and a damper DA/l_u acting only while the rope pulls (F = −T); ½ (EA/l_u)
(l − l_u)² counts as elastic energy while it is stretched. Unlike an actuator (``Model.add_actuator``, a constraint), an element
adds no equation: any number of them can act on a tree or a closed chain.
"""

from __future__ import annotations

import numpy as np

from . import _checks, parameters
from ._core import Body, Point, Profile


def point_of(model, where, name: str):
    """(body index, point in that body's frame, m) of a Point, a Body (its origin) or the ground."""
    if isinstance(where, Body):
        if not model._owns(where):
            raise ValueError(f"{name}: expected a Body or Point of this model, got {where!r}")
        return where.index, np.zeros(3)
    if isinstance(where, Point):
        if not -1 <= where.body < model.nbodies or where.model not in (0, model.id):
            raise ValueError(f"{name}: expected a Body or Point of this model, got {where!r}")
        return where.body, np.asarray(where.r, dtype=float)
    raise ValueError(f"{name}: expected a Body or Point of this model (or model.ground), got {where!r}")


def _force(force):
    """(constant N, profile or None, law or None) of the ``force`` argument."""
    if isinstance(force, Profile):
        return 0.0, force, None
    if callable(force):
        return 0.0, None, force
    try:
        return _checks.scalar(force, "force", unit="N"), None, None
    except ValueError:
        raise ValueError("force: expected a finite number in N, a rigidfem.motion profile F(t) or a function "
                         f"law(t, l, ld) returning N, got {force!r}") from None


def add_force_element(model, a, b, *, stiffness: float = 0.0, damping: float = 0.0, length: float = 0.0,
                      force=0.0, name: str | None = None) -> str:
    """The element added to ``model`` (see ``Model.add_spring_damper``, ``Model.add_cylinder``);
    returns its name ("element<k>" when ``name`` is None)."""
    ia, ra = point_of(model, a, "a")
    ib, rb = point_of(model, b, "b")
    stiffness = _checks.scalar(stiffness, "stiffness", nonnegative=True, unit="N/m")
    damping = _checks.scalar(damping, "damping", nonnegative=True, unit="N s/m")
    length = _checks.scalar(length, "length", nonnegative=True, unit="m")
    constant, profile, law = _force(force)
    name = model._add_force_element("" if name is None else str(name), ia, ra, ib, rb, stiffness, damping, length,
                                    constant, profile, law)
    parameters.register(model, parameters.ElementGroup(name, model._nelements - 1, {
        "stiffness": stiffness, "damping": damping, "force": constant}))
    if profile is not None:
        parameters.register(model, parameters.ProfileGroup(f"{name}.profile", "element", -1, model._nelements - 1,
                                                           profile, "the force profile's (N, s, rad/s)"))
    return name


def add_rope(model, a, b, *, EA: float, length, damping: float = 0.0, name: str | None = None) -> str:
    """A rope between ``a`` and ``b`` (see ``Model.add_rope``); returns its name."""
    ia, ra = point_of(model, a, "a")
    ib, rb = point_of(model, b, "b")
    EA = _checks.scalar(EA, "EA", positive=True, unit="N")
    DA = _checks.scalar(damping, "damping", nonnegative=True, unit="N s")
    if isinstance(length, Profile):
        lu = length(0.0)[0]
        if not (np.isfinite(lu) and lu > 0.0):
            raise ValueError(f"length: expected a profile l_u(t) with a positive length at t = 0 in m, got {lu}")
        name = model._add_rope("" if name is None else str(name), ia, ra, ib, rb, EA, DA, 0.0, length)
    else:
        name = model._add_rope("" if name is None else str(name), ia, ra, ib, rb, EA, DA,
                               _checks.scalar(length, "length", positive=True, unit="m"), None)
    parameters.register(model, parameters.ElementGroup(name, model._nelements - 1, {"EA": EA, "damping": DA},
                                                       rope=True))
    if isinstance(length, Profile):
        parameters.register(model, parameters.ProfileGroup(f"{name}.length", "element", -1, model._nelements - 1,
                                                           length, "the winch's (m, s, m/s)"))
    return name
