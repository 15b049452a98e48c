"""Small named models built in code, shared by tests, notebooks and benchmarks.

Each returns ``(model, handles)``: the Model (not yet compiled, so it can be
changed) and a dict of its bodies and points. Gravity is −9.81 m/s² along Z.
Bodies are slender rods unless said otherwise: mass m, length l, centre of mass at
the middle, inertia m l²/12 about the transverse axes and a small axial one.
"""

from __future__ import annotations

from .joints import Joint
from .model import Model, transform


def rod_inertia(mass: float, length: float, axis: str = "z", axial_fraction: float = 1e-3) -> list[float]:
    """Principal moments (kg·m²) of a slender rod of ``mass`` (kg) and ``length`` (m)
    lying along ``axis``; the axial moment is ``axial_fraction`` of the transverse one."""
    transverse = mass * length**2 / 12.0
    return [transverse * axial_fraction if a == axis else transverse for a in "xyz"]


def pendulum(length: float = 1.0, mass: float = 1.0, gravity: float = 9.81):
    """A rod hanging from a revolute joint about y at the origin, along −z at q = 0.

    Handles: ``link`` and ``tip`` (the free end).
    """
    model = Model(gravity=(0.0, 0.0, -gravity))
    link = model.add_body(
        "link", model.ground, Joint.revolute("y"), mass=mass, com=(0, 0, -length / 2),
        inertia=rod_inertia(mass, length),
    )
    return model, {"link": link, "tip": link.point((0.0, 0.0, -length))}


def double_pendulum(
    lengths=(1.0, 0.8), masses=(1.0, 0.7), spatial: bool = False, gravity: float = 9.81
):
    """Two rods in a chain from the origin, hanging along −z at q = 0.

    ``spatial=False``: revolute joints about y (motion in the x–z plane), nq = 2.
    ``spatial=True``: spherical (ZYX) joints, nq = 6. Handles: ``link1``, ``link2``,
    ``tip``.
    """
    (l1, l2), (m1, m2) = lengths, masses
    joint = Joint.spherical if spatial else (lambda: Joint.revolute("y"))
    model = Model(gravity=(0.0, 0.0, -gravity))
    link1 = model.add_body(
        "link1", model.ground, joint(), mass=m1, com=(0, 0, -l1 / 2), inertia=rod_inertia(m1, l1)
    )
    link2 = model.add_body(
        "link2", link1, joint(), mass=m2, com=(0, 0, -l2 / 2), inertia=rod_inertia(m2, l2),
        placement=transform(translation=(0, 0, -l1)),
    )
    return model, {"link1": link1, "link2": link2, "tip": link2.point((0.0, 0.0, -l2))}


def symmetric_top(mass: float = 1.0, height: float = 0.1, I_axis: float = 4e-3, I_transverse: float = 2e-3):
    """A symmetric top on a spherical joint at the origin: symmetry axis along the
    body x axis (so the roll φ1 is the spin), centre of mass at (height, 0, 0).

    ``I_axis``, ``I_transverse``: moments about the centre of mass (kg·m²).
    """
    model = Model()
    top = model.add_body(
        "top", model.ground, Joint.spherical(), mass=mass, com=(height, 0, 0),
        inertia=(I_axis, I_transverse, I_transverse),
    )
    return model, {"top": top}


def spring_mass(mass: float = 2.0, stiffness: float = 800.0, damping: float = 0.0):
    """A block on a prismatic joint along x with a spring and damper; no gravity."""
    model = Model(gravity=None)
    block = model.add_body(
        "block", model.ground, Joint.prismatic("x", stiffness=stiffness, damping=damping),
        mass=mass, inertia=(1e-3, 1e-3, 1e-3),
    )
    return model, {"block": block}
