"""Shapes on bodies, for contact: ``Sphere``, ``Capsule``, ``Box``, ``HalfSpace`` and ``Capsules`` (one capsule per
rigid finite element of a beam).

A shape is a value, placed on a body by ``Model.add_shape(name, body, shape)``; ``Model.add_contact(name, a, b,
law)`` makes two shapes (or groups of them) push each other apart where they overlap, with a ``rigidfem.laws.Contact``
law (cpp/include/rigidfem/contact.hpp: the normal force, the friction, the restitution). Lengths in m, in the body's
frame. Which pairs touch: spheres and capsules each other and half-spaces, boxes half-spaces only (by their eight
corners), half-spaces everything but half-spaces.

>>> import rigidfem as rf
>>> rf.shapes.Sphere(0.1)
Sphere(radius=0.1, center=(0.0, 0.0, 0.0))

Examples
--------
>>> import rigidfem as rf
>>> rf.shapes.Capsule(0.02, (0.0, 0.0, 0.0), (0.1, 0.0, 0.0))
Capsule(radius=0.02, a=(0.0, 0.0, 0.0), b=(0.1, 0.0, 0.0))
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._core import Body
from ..base import _checks
from . import handles


def _vec3(x, name: str) -> tuple[float, float, float]:
    return tuple(float(v) for v in _checks.reals(x, (3,), name))


@dataclass(frozen=True)
class Sphere:
    """A sphere of ``radius`` (m) about ``center`` (m, body frame)."""

    radius: float
    center: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "radius", _checks.real(self.radius, "radius", "a radius in m"))
        object.__setattr__(self, "center", _vec3(self.center, "center"))

    def _core(self) -> dict:
        return {"kind": "sphere", "a": self.center, "radius": self.radius}


@dataclass(frozen=True)
class Capsule:
    """The segment ``a``–``b`` (m, body frame) swept by a sphere of ``radius`` (m): a rod, a cable, a link."""

    radius: float
    a: tuple = (0.0, 0.0, 0.0)
    b: tuple = (1.0, 0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "radius", _checks.real(self.radius, "radius", "a radius in m"))
        object.__setattr__(self, "a", _vec3(self.a, "a"))
        object.__setattr__(self, "b", _vec3(self.b, "b"))

    def _core(self) -> dict:
        return {"kind": "capsule", "a": self.a, "b": self.b, "radius": self.radius}


@dataclass(frozen=True)
class Box:
    """A box of ``half_extents`` (m) about ``center`` (m), its axes the columns of ``rotation`` (body frame; identity
    by default). It touches half-spaces only, by its eight corners."""

    half_extents: tuple
    center: tuple = (0.0, 0.0, 0.0)
    rotation: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "half_extents", _vec3(self.half_extents, "half_extents"))
        object.__setattr__(self, "center", _vec3(self.center, "center"))
        R = np.eye(3) if self.rotation is None else _checks.reals(self.rotation, (3, 3), "rotation")
        object.__setattr__(self, "rotation", tuple(map(tuple, R)))

    def _core(self) -> dict:
        return {"kind": "box", "a": self.center, "half_extents": self.half_extents, "rotation": np.array(self.rotation)}


@dataclass(frozen=True)
class HalfSpace:
    """The solid below the plane through ``point`` (m) with the outward unit ``normal`` (body frame): the ground
    (on ``model.ground``: z up by default), a deck, a wall."""

    normal: tuple = (0.0, 0.0, 1.0)
    point: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "normal", _vec3(self.normal, "normal"))
        object.__setattr__(self, "point", _vec3(self.point, "point"))

    def _core(self) -> dict:
        return {"kind": "half_space", "a": self.point, "normal": self.normal}


@dataclass(frozen=True)
class Capsules:
    """One capsule per rigid finite element of a beam, along its length from its frame to the next one's (to the tip
    for the last), of ``radius`` (m; None: that of each rfe's section, the radius √(2 J_x/m) of the solid circle of
    its polar inertia J_x and mass m — exact for round sections, 0.82 of the half-diagonal of a rectangle)."""

    radius: float | None = None

    def __post_init__(self):
        if self.radius is not None:
            object.__setattr__(self, "radius", _checks.real(self.radius, "radius", "a radius in m"))


SHAPES = (Sphere, Capsule, Box, HalfSpace, Capsules)


def add_shape(model, name: str, body, shape) -> handles.Shape:
    """The shape ``name`` on ``body`` (see ``Model.add_shape``): its handle."""
    from .beams import Beam

    if not isinstance(shape, SHAPES):
        raise _checks.refuse(f"shape: expected a shape from rigidfem.shapes (Sphere, Capsule, Box, HalfSpace, "
                             f"Capsules), got {shape!r}")
    if isinstance(shape, Capsules) != isinstance(body, Beam):
        raise _checks.refuse(f"body: expected a Beam for Capsules and a Body (or model.ground) for one shape, got "
                             f"{body!r}")
    if isinstance(shape, Capsules):
        return _beam_capsules(model, name, body, shape.radius)
    index = _add(model, name, _body_index(model, body), shape._core())
    return handles.Shape(name, shape._core()["kind"], [index])


def _body_index(model, body) -> int:
    """The index of ``body`` (a Body of this model, or ``model.ground``: −1)."""
    if isinstance(body, Body) and body.index == -1:
        return -1
    return model._point(body).body


def _beam_capsules(model, name: str, beam, radius) -> handles.Shape:
    if beam.varying:
        raise _checks.refuse(f"body: expected a beam of constant length (the capsules of a link of varying length are "
                             f"not supported), got {beam.name!r}")
    ends = np.append(beam.frames[1:], beam.length)
    indices = []
    for k, rfe in enumerate(beam.rfes):
        p = beam.rfe[k]
        r = radius if radius is not None else float(np.sqrt(2.0 * p.inertia[0, 0] / p.mass))
        core = {"kind": "capsule", "a": (0.0, 0.0, 0.0), "b": (float(ends[k] - beam.frames[k]), 0.0, 0.0), "radius": r}
        indices.append(_add(model, f"{name}[{k}]", rfe.index, core))
    return handles.Shape(name, "capsules", indices)


def _add(model, name: str, body: int, core: dict) -> int:
    zero = (0.0, 0.0, 0.0)
    return model._add_shape(name, body, core["kind"], core.get("a", zero), core.get("b", zero),
                            core.get("normal", (0.0, 0.0, 1.0)), core.get("half_extents", zero),
                            core.get("rotation", np.eye(3)), core.get("radius", 0.0))


def shape_indices(model, group, argument: str) -> list[int]:
    """The shapes' indices of ``group``: a shape handle or a list of them (ValueError naming ``argument``)."""
    items = [group] if isinstance(group, handles.Shape) else group
    if not isinstance(items, (list, tuple)) or not items or not all(isinstance(h, handles.Shape) for h in items):
        raise _checks.refuse(f"{argument}: expected a shape of this model (Model.add_shape) or a list of them, "
                             f"got {group!r}")
    indices = [k for h in items for k in h.shapes]
    names = [row["name"] for row in model._shape_table]  # built once: the table is made anew at each access
    if any(k >= len(names) or names[k] not in (h, f"{h}[{j}]") for h in items for j, k in enumerate(h.shapes)):
        raise _checks.refuse(f"{argument}: expected shapes of this model, got {group!r}")
    return indices
