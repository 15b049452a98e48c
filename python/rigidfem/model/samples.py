"""Small named models built in code, shared by tests, notebooks and benchmarks.

Each returns ``(model, handles)``: the Model (not yet compiled, so it can be
changed) and a dict of its bodies and points. Gravity is −9.81 m/s² along Z.
Bodies are slender rods unless said otherwise: mass m, length l, centre of mass at
the middle, inertia m l²/12 about the transverse axes and a small axial one.

Examples
--------
>>> import rigidfem as rf
>>> model, h = rf.samples.double_pendulum()
>>> sorted(h), model.compile().nq
(['link1', 'link2', 'tip'], 2)
"""

from __future__ import annotations

from ..base import _checks
from .joints import Joint
from .materials import Material, Section
from .model import Model, transform
from .motion import spin_up

#: Kane, Ryan & Banerjee (1987) beam: L (m), E (Pa), ρ (kg/m³), A (m²), I (m⁴).
KANE_PARAMETERS = {
    "kane": dict(L=10.0, E=68.952e9, rho=2766.67, A=7.2968e-5, I=8.2189e-9),
    "simo": dict(L=10.0, E=7.0e10, rho=3000.0, A=4.0e-4, I=2.0e-7),
}


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
    joint = Joint.spherical if _checks.boolean(spatial, "spatial") else (lambda: Joint.revolute("y"))
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


def four_bar(crank_spring: dict | None = None):
    """A planar four-bar in the x–y plane under gravity −y: crank 0.3 m from the origin, coupler 0.8 m,
    rocker 0.6 m from (0.7, 0, 0), each a 1 kg slender rod on a revolute joint about z; the coupler's
    tip joined to the rocker's by a revolute loop joint "C" (3 of its 5 rows redundant in the plane).
    ``crank_spring``: keyword arguments of the crank's joint (``stiffness=``, ``rest=``, ``damping=``).
    ``System.assemble`` closes the loop from a guess, e.g. (0.4, −1.9, 4.6) rad. Handles: ``crank``,
    ``coupler``, ``rocker``, ``loop`` (the loop's name)."""
    model = Model(gravity=(0.0, -9.81, 0.0))

    def rod(length):
        return dict(mass=1.0, inertia=(1e-4, length**2 / 12, length**2 / 12), com=(length / 2, 0, 0))

    crank = model.add_body("crank", model.ground, Joint.revolute("z", **(crank_spring or {})), **rod(0.3))
    coupler = model.add_body("coupler", crank, Joint.revolute("z"), **rod(0.8), placement=transform((0.3, 0, 0)))
    rocker = model.add_body("rocker", model.ground, Joint.revolute("z"), **rod(0.6), placement=transform((0.7, 0, 0)))
    loop = model.add_loop_joint("C", "revolute", coupler.point((0.8, 0, 0)), rocker.point((0.6, 0, 0)))
    return model, {"crank": crank, "coupler": coupler, "rocker": rocker, "loop": loop}


def double_four_bar(rocker: float = 0.5, span: float = 1.0, rocker_mass: float = 1.0, coupler_mass: float = 2.0):
    """Two parallelogram four-bars in a row sharing the middle rocker, in the x–y plane under gravity −y:
    three rockers of length ``rocker`` (m, ``rocker_mass`` kg slender rods) on revolute joints about z at
    (0, 0), (``span``, 0) and (2 ``span``, 0); coupler "c1" (``span`` m, ``coupler_mass`` kg) on the tip of
    rocker "r0", closed onto the tip of "r1" by revolute loop "A"; coupler "c2" likewise from "r1" to "r2"
    (loop "B"). Coordinates (r0, r1, r2, c1, c2); on the parallelogram branch all rockers at θ and both
    couplers at −θ: one degree of freedom, a pendulum with T = ½ (3 m L²/3 + 2 m_c L²) θ̇² and
    V = g sin θ (3 m L/2 + 2 m_c L). At θ = 0 and π the bars lie flat and each loop's Jacobian loses a row
    (a singular position: the antiparallelogram branch crosses there), so a swing from above the
    horizontal passes singular positions twice a period. Handles: ``rockers``, ``couplers``, ``loops``."""
    model = Model(gravity=(0.0, -9.81, 0.0))

    def rod(length, mass):
        return dict(mass=mass, inertia=(1e-4 * mass, mass * length**2 / 12, mass * length**2 / 12),
                    com=(length / 2, 0, 0))

    rockers = [model.add_body(f"r{i}", model.ground, Joint.revolute("z"), **rod(rocker, rocker_mass),
                              placement=transform((i * span, 0, 0))) for i in range(3)]
    couplers, loops = [], []
    for i, name in enumerate(("A", "B")):
        c = model.add_body(f"c{i + 1}", rockers[i], Joint.revolute("z"), **rod(span, coupler_mass),
                           placement=transform((rocker, 0, 0)))
        couplers.append(c)
        loops.append(model.add_loop_joint(name, "revolute", c.point((span, 0, 0)), rockers[i + 1].point((rocker, 0, 0))))
    return model, {"rockers": rockers, "couplers": couplers, "loops": loops}


def cantilever(elements: int = 10, length: float = 1.0, material: Material | None = None,
               section: Section | None = None, formulation: str = "modified", deform=("bend_z",),
               linear: bool = False, gravity=None):
    """A beam clamped at the origin along x (steel, 20 × 5 mm rectangle by default: 20 mm
    along y, so ``bend_z`` bends it in the x–y plane about its stiff axis). Handles:
    ``beam``."""
    model = Model(gravity=gravity)
    beam = model.add_beam(
        "beam", model.ground, length, material or Material(E=2.1e11, rho=7850.0, nu=0.3),
        section or Section.rectangle(0.02, 0.005), elements, formulation=formulation, deform=deform,
        linear=linear,
    )
    return model, {"beam": beam}


def kane_beam(omega: float = 6.0, duration: float = 15.0, elements: int = 10, linear: bool = False,
              parameters: str = "kane", deform=("bend_z",), formulation: str = "modified"):
    """Kane's spin-up manipulator: a beam clamped on the axis of a hub turned about z by
    ``rigidfem.motion.spin_up(omega, duration)``; no gravity. ``parameters``: "kane"
    (L = 10 m, E = 68.952 GPa, ρ = 2766.67 kg/m³, A = 7.2968e-5 m², I = 8.2189e-9 m⁴) or
    "simo" (E = 70 GPa, ρ = 3000 kg/m³, A = 4e-4 m², I = 2e-7 m⁴). Handles: ``hub``, ``beam``."""
    p = KANE_PARAMETERS[parameters]
    model = Model(gravity=None)
    hub = model.add_body("hub", model.ground, Joint.revolute("z"), mass=1.0, inertia=(1.0, 1.0, 1.0))
    model.prescribe(hub, spin_up(omega, duration))
    section = Section(A=p["A"], Iy=p["I"], Iz=p["I"], J=2 * p["I"])
    beam = model.add_beam("beam", hub, p["L"], Material(E=p["E"], rho=p["rho"]), section, elements,
                          formulation=formulation, deform=deform, linear=linear)
    return model, {"hub": hub, "beam": beam}


def random_tree(seed: int, nbodies: int = 6):
    """A random tree for property tests: every joint type (fixed, revolute, prismatic,
    cylindrical, universal, spherical, planar, free, custom subsets), random placements,
    masses, centres of mass and inertias (positive definite, triangle inequality), joint
    springs and dampers, a drive on some coordinates, point forces, torques and gravity.

    Returns ``(model, handles, rng)``; the generator continues the same stream, for states.
    """
    import numpy as np

    from .motion import harmonic, polynomial

    rng = np.random.default_rng(seed)
    model = Model(gravity=tuple(rng.normal(0.0, 5.0, 3)))
    axes = ("x", "y", "z")
    makers = [
        lambda kw: Joint.fixed(),
        lambda kw: Joint.revolute(rng.choice(axes), **kw),
        lambda kw: Joint.prismatic(rng.choice(axes), **kw),
        lambda kw: Joint.cylindrical(rng.choice(axes), **kw),
        lambda kw: Joint.universal(tuple(rng.choice(axes, 2, replace=False)), **kw),
        lambda kw: Joint.spherical(**kw),
        lambda kw: Joint.planar(rng.choice(["xy", "yz", "zx"]), **kw),
        lambda kw: Joint.free(**kw),
        lambda kw: Joint.custom(list(rng.choice(["x", "y", "z", "rz", "ry", "rx"], int(rng.integers(1, 5)),
                                                replace=False)), **kw),
    ]
    bodies = []
    for p in range(nbodies):
        parent = model.ground if p == 0 or rng.random() < 0.2 else bodies[int(rng.integers(0, p))]
        springs = {"stiffness": float(rng.uniform(0, 50)), "damping": float(rng.uniform(0, 2))}
        joint = makers[int(rng.integers(0, len(makers)))](springs)
        moments = np.sort(rng.uniform(0.05, 1.0, 3))
        moments[2] = min(moments[2], 0.99 * (moments[0] + moments[1]))  # triangle inequality
        Rb = transform(euler_zyx=rng.uniform(-np.pi, np.pi, 3))[:3, :3]
        body = model.add_body(
            f"b{p}", parent, joint, mass=float(rng.uniform(0.5, 3.0)), com=rng.uniform(-0.5, 0.5, 3),
            inertia=Rb @ np.diag(moments) @ Rb.T,
            placement=transform(translation=rng.uniform(-1, 1, 3), euler_zyx=rng.uniform(-1, 1, 3)),
        )
        bodies.append(body)
        if joint.ncoords and rng.random() < 0.3:
            c = str(rng.choice(joint.coordinates))
            drive = harmonic(float(rng.uniform(0.1, 0.5)), float(rng.uniform(0.5, 3)), float(rng.uniform(0, 3))) \
                if rng.random() < 0.5 else polynomial(list(rng.uniform(-0.3, 0.3, 3)))
            model.prescribe(body, drive, coordinate=c)
        if rng.random() < 0.5:
            model.add_force(f"{body.name}_force", body.point(rng.uniform(-1, 1, 3)), rng.normal(0, 3, 3),
                            follower=bool(rng.random() < 0.5))
        if rng.random() < 0.3:
            model.add_torque(f"{body.name}_torque", body, rng.normal(0, 2, 3), follower=bool(rng.random() < 0.5))
    return model, {"bodies": bodies}, rng
