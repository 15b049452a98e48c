"""Force elements between two bodies: spring-dampers, hydraulic cylinders under force control, ropes — any law
of ``rigidfem.laws`` that acts between two points.

An element joins a point A on body ``a`` and a point B on body ``b`` (rigid bodies, rfes of a
beam or the ground) and acts along the line between them (book ch. 7.3). With l = |r_B − r_A|
its length and l̇ its rate it pushes the points apart with its law's axial force F(t, l, l̇)
(N; F > 0 pushes, F < 0 pulls), F e on B and −F e on A, e the unit vector from A to B:

- ``rf.laws.SpringDamper``: F = −k (l − l₀) − c l̇ + F(t), F(t) a constant, a ``rigidfem.motion`` profile (its
  value in N) or a Python function ``law(t, l, ld)`` (the slow path: called under the GIL at every
  evaluation, its derivatives by central differences); ``Model.add_spring_damper`` and ``Model.add_cylinder``
  add one. The spring's energy ½ k (l − l₀)² counts in ``System.elastic_energy`` and the damper's c l̇² in
  ``System.dissipated_power``; the applied part F(t) is scaled by the load factor of statics.
- ``rf.laws.Rope`` (``Model.add_rope``): a massless tension-only element of unstretched length l_u (a number,
  or a profile l_u(t) paid out by a winch) pulling with T = (EA (l − l_u) + DA (l̇ − l̇_u)) / l_u while positive
  and 0 when slack, a spring EA/l_u and a damper DA/l_u acting only while the rope pulls (F = −T);
  ½ (EA/l_u) (l − l_u)² counts as elastic energy while it is stretched.

``System.element_states`` gives (l, l̇, F) of every element and ``Result.element_forces`` their forces over a
simulation. Unlike an actuator (``Model.add_actuator``, a constraint), an element adds no equation: any number
of them can act on a tree or a closed chain.
"""

from __future__ import annotations

import numpy as np

import rigidfem._core as _core  # the compiled core, by its absolute name
from . import handles, laws, parameters
from .._core import Body, Point, Profile
from ..base import _checks


def point_of(model, where, name: str):
    """(body index, point in that body's frame, m) of a Point, a Body (its origin) or the ground."""
    if isinstance(where, Body):
        if not model._owns(where):
            raise _checks.refuse(f"{name}: expected a Body or Point of this model, got {where!r}")
        return where.index, np.zeros(3)
    if isinstance(where, Point):
        if not -1 <= where.body < model.nbodies or where.model not in (0, model.id):
            raise _checks.refuse(f"{name}: expected a Body or Point of this model, got {where!r}")
        return where.body, np.asarray(where.r, dtype=float)
    raise _checks.refuse(f"{name}: expected a Body or Point of this model (or model.ground), got {where!r}")


def points(model, a, b) -> tuple:
    """(body a, point on a, body b, point on b) of an element's two points; ValueError naming ``a`` or ``b``."""
    return (*point_of(model, a, "a"), *point_of(model, b, "b"))


def add_force_element(model, name: str, a, b, law) -> handles.Element:
    """The element ``name`` of ``law`` (a ``rigidfem.laws`` law of a force element) added to ``model`` between ``a``
    and ``b``; returns its handle. Its constants marked as parameters become the
    parameters ``"<name>.<constant>"``, its profile's numbers ``"<name>.<profile name>.<path>"``."""
    if not isinstance(law, laws.Law) or law.info["acts_on"] != "element":
        raise _checks.refuse(f"law: expected a law of a force element ({', '.join(k for k, i in laws.kinds().items() if i['acts_on'] == 'element')} "
                         f"from rigidfem.laws), got {law!r}")
    ia, ra, ib, rb = points(model, a, b)
    name = model._add_force_element(name, ia, ra, ib, rb, law.kind, law.values,
                                    law.profile, law.function)
    k = model._nelements - 1
    info = law.info
    parameters.register(model, parameters.LawGroup(name, ("element", k), info, law.values))
    if law.profile is not None:
        parameters.register(model, parameters.ProfileGroup(f"{name}.{info['profile_name']}", "element", -1, k,
                                                           law.profile, info["profile_units"]))
    return handles.Element(name, law.kind, k)


def cylinder_force(force) -> dict:
    """The arguments of ``rf.laws.SpringDamper`` for a cylinder's ``force``: a number (N), a ``rigidfem.motion``
    profile F(t) or a Python function law(t, l, ld)."""
    if isinstance(force, Profile):
        return {"profile": force}
    if callable(force):
        return {"function": force}
    return {"force": _core._real(force, "force", "a finite number in N, a rigidfem.motion profile F(t) or a function "
                                                  "law(t, l, ld) returning N")}


def unstretched(length) -> dict:
    """The arguments of ``rf.laws.Rope`` for a rope's ``length``: a number (m) or a profile l_u(t)."""
    return {"profile": length} if isinstance(length, Profile) else {"length": length}
