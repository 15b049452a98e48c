"""The handles the builders return: every thing a model is built of has a name — its named parameters'
prefix, its column in a result — and its handle carries the name with what it is.

A handle is a ``str`` (the name itself), so it serves wherever the name does: ``system.element_names.index(h)``,
``f"{h}.stiffness"``, ``error_on=[h]``; ``h.name`` is the plain name, ``h.kind`` what it is (the law's kind of a
force element, the loop's kind, "force" or "torque" for a load, "drive" ... for a coordinate) and ``h.index`` its
place among the model's things of its sort. Bodies (``rigidfem.Body``) and beams (``rigidfem.Beam``) have their
own handles, with ``.name`` too.
"""

from __future__ import annotations


class Handle(str):
    """The name of a thing a builder added, with ``kind`` and ``index``."""

    def __new__(cls, name: str, kind: str, index: int):
        handle = super().__new__(cls, name)
        handle.kind, handle.index = kind, index
        return handle

    def __getnewargs__(self):
        return str(self), self.kind, self.index

    @property
    def name(self) -> str:
        """The name, a plain ``str``."""
        return str(self)

    def __repr__(self) -> str:
        return f"<rigidfem {type(self).__name__} {str(self)!r}: {self.kind} #{self.index}>"


class Element(Handle):
    """A force element (``Model.add_force_element``, ``add_spring_damper``, ``add_cylinder``, ``add_rope``): its kind
    is its law's (``rigidfem.laws``), its index its column in ``Result.element_forces``."""


class Load(Handle):
    """A point force or torque (``Model.add_force``, ``add_torque``): kind "force" or "torque"."""


class Loop(Handle):
    """A loop closure (``Model.add_loop_joint``, ``add_actuator``): its kind ("revolute", ..., "distance"), its index
    its row in ``Result.loop_reactions``."""


class JointLaw(Handle):
    """A law of a joint coordinate (``Model.add_joint_law``): its kind is the law's; its index its place among the
    laws of its coordinate."""


class Coordinate(Handle):
    """A joint coordinate that a builder gave something ("<body>.<axis>"): a drive (``Model.prescribe``, kind "drive"),
    a constant or a Python generalised force (``add_generalized_force``: "force"), a Maxwell arm
    (``add_maxwell_arm``: "arm"); its index is its slot in the body's joint."""


class Shape(Handle):
    """A shape on a body (``Model.add_shape``), or a beam's capsules: its kind ("sphere", "capsule", "box",
    "half_space", "capsules"); ``shapes`` the indices of its shapes among the model's (one, or one per rfe), ``index``
    the first."""

    def __new__(cls, name: str, kind: str, shapes):
        handle = super().__new__(cls, name, kind, int(shapes[0]))
        handle.shapes = tuple(int(k) for k in shapes)
        return handle

    def __getnewargs__(self):
        return str(self), self.kind, self.shapes


class Contact(Handle):
    """A contact between shapes (``Model.add_contact``): its kind is its law's (``rigidfem.laws.Contact``), its index
    its place among the model's contacts."""
