"""Flexible links by the rigid finite element method (book ch. 3.1, 3.6, 4).

A straight beam of length L along the x axis of its frame is divided into m equal
segments of length Δ = L/m (primary division); each segment's elasticity and
damping are concentrated in one spring-damping element (sde) at its middle,
x = (i − ½)Δ, i = 1..m. The rigid finite elements (rfe) are the pieces between sdes
(secondary division): rfe 0 = [0, Δ/2] sits on the parent through the beam's joint,
rfe i = [(i − ½)Δ, (i + ½)Δ], rfe m = [L − Δ/2, L]. rfe i ≥ 1 moves relative to the
frame of sde i (on rfe i − 1) through a joint with the coordinates of the chosen
deformations, which carry the sde's springs and dampers. End rfes of half length
make frequencies and deflections converge as O(m⁻²).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from . import _checks, _core
from ._core import Body, Point
from .joints import Joint
from .materials import Material, Section
from .frames import transform

#: Deformation name -> joint coordinate of the sde (book order x, y, z, φ3, φ2, φ1).
DEFORMATIONS = {"axial": "x", "shear_y": "y", "shear_z": "z", "torsion": "rx", "bend_y": "ry", "bend_z": "rz"}
MODIFIED_DEFORMATIONS = ("torsion", "bend_y", "bend_z")

_GAUSS = np.polynomial.legendre.leggauss(8)  # exact for polynomials of degree ≤ 15 on each piece


@dataclass(frozen=True)
class Property:
    """A beam property along the arc length s: one value, a function of s, or one per segment."""

    at: Callable[[float], object]
    breakpoints: tuple[float, ...] = ()

    @staticmethod
    def of(value, kind: type, name: str, length: float, elements: int) -> Property:
        if isinstance(value, kind):
            return Property(lambda s: value)
        if callable(value):
            def checked(s):
                v = value(s)
                if not isinstance(v, kind):
                    raise ValueError(f"{name}: expected the function to return a {kind.__name__} at s = {s}, got {v!r}")
                return v

            return Property(checked)
        if isinstance(value, Sequence) and not isinstance(value, str):
            if len(value) != elements or not all(isinstance(v, kind) for v in value):
                raise ValueError(f"{name}: expected a {kind.__name__}, a function of s or {elements} of them "
                                 f"(one per segment), got {len(value)} items")
            d = length / elements
            values = list(value)
            return Property(lambda s: values[min(max(int(s // d), 0), elements - 1)],
                            tuple(k * d for k in range(1, elements)))
        raise ValueError(f"{name}: expected a {kind.__name__}, a function of s or a list per segment, got {value!r}")


def _integrate(fun, a: float, b: float, breakpoints=()) -> np.ndarray:
    """∫_a^b fun(s) ds by 8-point Gauss–Legendre on each piece between breakpoints."""
    cuts = [a] + [x for x in breakpoints if a < x < b] + [b]
    total = 0.0
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        s = 0.5 * (hi - lo) * _GAUSS[0] + 0.5 * (hi + lo)
        total = total + 0.5 * (hi - lo) * sum(w * np.asarray(fun(x), float) for w, x in zip(_GAUSS[1], s))
    return np.asarray(total)


def _as_property(value, kind, name) -> Property:
    return value if isinstance(value, Property) else Property.of(value, kind, name, 1.0, 1)


@dataclass(frozen=True)
class RfeParameters:
    """Inertia of one rigid finite element, in its frame (x along the beam)."""

    mass: float            #: kg
    com: np.ndarray        #: (3,) m
    inertia: np.ndarray    #: (3, 3) kg·m², about the centre of mass
    H: np.ndarray          #: (4, 4) pseudo-inertia ∫ r rᵀ dm


def rfe_parameters(material, section, start: float, end: float, origin: float | None = None) -> RfeParameters:
    """Mass, centre of mass, inertia and pseudo-inertia of the beam piece [start, end] (m),
    in a frame on the beam axis at arc length ``origin`` (default ``start``).

    With x measured from the frame: m = ∫ρA ds, m x_C = ∫ρA x ds, ∫x² dm = ∫ρA x² ds and
    the section's rotary inertia ∫y² dm = ∫ρ Iz ds, ∫z² dm = ∫ρ Iy ds (book ch. 3.6).
    ``material``/``section`` may be functions of s.
    """
    mat = _as_property(material, Material, "material")
    sec = _as_property(section, Section, "section")
    x0 = start if origin is None else origin

    def density(s):  # [ρA, ρA x, ρA x², ρ Iz, ρ Iy]
        m, c = mat.at(s), sec.at(s)
        x = s - x0
        return [m.rho * c.A, m.rho * c.A * x, m.rho * c.A * x * x, m.rho * c.Iz, m.rho * c.Iy]

    mass, first, xx, yy, zz = _integrate(density, start, end, mat.breakpoints + sec.breakpoints)
    H = np.zeros((4, 4))
    H[:3, :3] = np.diag([xx, yy, zz])
    H[0, 3] = H[3, 0] = first
    H[3, 3] = mass
    com = np.array([first / mass, 0.0, 0.0])
    return RfeParameters(mass, com, _inertia_about_com(H), H)


def _inertia_about_com(H: np.ndarray) -> np.ndarray:
    """Inverse of the pseudo-inertia: I_O = tr(S) 1 − S with S = ∫r rᵀ dm, shifted to the c.o.m."""
    m = H[3, 3]
    c = H[:3, 3] / m
    S = H[:3, :3]
    I_O = np.trace(S) * np.eye(3) - S
    return I_O - m * (c @ c * np.eye(3) - np.outer(c, c))


@dataclass(frozen=True)
class SdeParameters:
    """Stiffness c_k (N/m or N·m/rad) and damping b_k = μ c_k of one sde, by deformation."""

    stiffness: dict
    damping: dict


def sde_parameters(material, section, start: float, end: float) -> SdeParameters:
    """Spring and damper constants of the sde of the segment [start, end] (m), book ch. 3.6:
    c_x = EA/Δ, c_y = κ_y GA/Δ, c_z = κ_z GA/Δ, c_φ1 = GJ/Δ, c_φ2 = E Iy/Δ, c_φ3 = E Iz/Δ,
    b_k = μ c_k. For a varying section each c is the segment's integrated compliance,
    1/c = ∫ ds/(EI)(s), which for a uniform one is Δ/(EI).
    """
    mat = _as_property(material, Material, "material")
    sec = _as_property(section, Section, "section")

    def compliance(s):  # 1 / (stiffness per unit length) of axial, shear_y, shear_z, torsion, bend_y, bend_z
        m, c = mat.at(s), sec.at(s)
        return 1.0 / np.array([m.E * c.A, c.kappa_y * m.G * c.A, c.kappa_z * m.G * c.A, m.G * c.J, m.E * c.Iy,
                               m.E * c.Iz])

    c = 1.0 / _integrate(compliance, start, end, mat.breakpoints + sec.breakpoints)
    mu = mat.at(0.5 * (start + end)).damping
    names = ("axial", "shear_y", "shear_z", "torsion", "bend_y", "bend_z")
    return SdeParameters(dict(zip(names, c)), {k: mu * v for k, v in zip(names, c)})


@dataclass
class Beam:
    """Handle of a beam added by ``Model.add_beam``."""

    name: str
    length: float
    elements: int
    formulation: str
    deform: tuple[str, ...]
    linear: bool
    rfes: list[Body]                      #: the m + 1 rigid finite elements, root to tip
    frames: np.ndarray                    #: (m + 1,) arc length of each rfe frame, m
    rfe: list[RfeParameters] = field(repr=False)
    sde: list[SdeParameters] = field(repr=False)

    @property
    def tip(self) -> Point:
        """The beam's free end (s = L) on the last rfe."""
        return self.point(self.length)

    def point(self, s: float) -> Point:
        """The point at arc length ``s`` (m) of the undeformed beam, on the rfe containing it."""
        s = _checks.scalar(s, "s")
        if not 0.0 <= s <= self.length * (1 + 1e-12):
            raise ValueError(f"s: expected an arc length in [0, {self.length}] m, got {s}")
        i = min(int(np.floor(s / (self.length / self.elements) + 0.5)), self.elements)
        return self.rfes[i].point((s - self.frames[i], 0.0, 0.0))

    def points(self) -> list[Point]:
        """The beam's root, its m sde points (on the rfe before each sde) and its tip."""
        sde = [self.rfes[i - 1].point((self.frames[i] - self.frames[i - 1], 0.0, 0.0))
               for i in range(1, self.elements + 1)]
        return [self.rfes[0].origin, *sde, self.tip]

    def centerline(self, system, q, t: float = 0.0) -> np.ndarray:
        """Deformed centre line (m + 2, 3) in the global frame (m): root, sde points, tip."""
        return np.array([system.position(p, q, t) for p in self.points()])


def add_beam(
    model,
    name: str,
    parent,
    length: float,
    material,
    section,
    elements: int,
    formulation: str = "modified",
    deform: Sequence[str] | None = None,
    linear: bool = False,
    joint=None,
    placement=None,
    tip_mass: float = 0.0,
    tip_inertia=(0.0, 0.0, 0.0),
    tip_offset=(0.0, 0.0, 0.0),
) -> Beam:
    """Divide a straight beam into rfes and sdes and add them to ``model`` (see ``Model.add_beam``)."""
    L = _checks.scalar(length, "length", positive=True)
    if isinstance(elements, bool) or not isinstance(elements, (int, np.integer)) or elements < 1:
        raise ValueError(f"elements: expected an integer number of sdes >= 1, got {elements!r}")
    m = int(elements)
    if formulation not in ("classical", "modified"):
        raise ValueError(f"formulation: expected 'classical' or 'modified', got {formulation!r}")
    allowed = MODIFIED_DEFORMATIONS if formulation == "modified" else tuple(DEFORMATIONS)
    deform = allowed if deform is None else ((deform,) if isinstance(deform, str) else tuple(deform))
    for d in deform:
        if d not in allowed:
            raise ValueError(f"deform: expected deformations from {allowed} for the {formulation} formulation, "
                             f"got {d!r}")
    if len(set(deform)) != len(deform):
        raise ValueError(f"deform: expected each deformation at most once, got {deform}")
    mat = Property.of(material, Material, "material", L, m)
    sec = Property.of(section, Section, "section", L, m)
    tip_m = _checks.scalar(tip_mass, "tip_mass", nonnegative=True)

    d = L / m
    frames = np.array([0.0] + [(i - 0.5) * d for i in range(1, m + 1)])
    ends = np.array([0.5 * d] + [min((i + 0.5) * d, L) for i in range(1, m + 1)])
    rfe = [rfe_parameters(mat, sec, lo, hi, origin=x) for lo, hi, x in zip([0.0, *frames[1:]], ends, frames)]
    sde = [sde_parameters(mat, sec, (i - 1) * d, i * d) for i in range(1, m + 1)]
    names = [f"{name}.rfe{i}" for i in range(m + 1)]
    taken = set(model.body_names) & set(names)
    if taken:
        raise ValueError(f"name: expected a beam name whose rfe bodies are not in the model yet, got {name!r} "
                         f"({sorted(taken)[0]} exists)")
    if tip_m > 0.0:
        # A concentrated body at the tip (offset from s = L in beam axes) joins the last rfe.
        inertia = _tip_inertia(tip_inertia)
        offset = _checks.vec3(tip_offset, "tip_offset") + [L - frames[-1], 0.0, 0.0]
        H = rfe[-1].H + _core.pseudo_inertia(tip_m, offset, inertia)
        rfe[-1] = RfeParameters(H[3, 3], H[:3, 3] / H[3, 3], _inertia_about_com(H), H)

    coords = [DEFORMATIONS[k] for k in deform]
    bodies = []
    for i in range(m + 1):
        if i == 0:
            j, up, B = (joint if joint is not None else Joint.fixed()), parent, placement
        else:
            j = Joint.custom(coords, stiffness=[sde[i - 1].stiffness[k] for k in deform],
                             damping=[sde[i - 1].damping[k] for k in deform])
            if linear:
                up, B = bodies[0], transform(translation=(frames[i], 0.0, 0.0))
                _couple_linear(j, bodies, frames, i)
            else:
                up, B = bodies[-1], transform(translation=(frames[i] - frames[i - 1], 0.0, 0.0))
        p = rfe[i]
        bodies.append(model.add_body(names[i], up, j, mass=p.mass, com=p.com, inertia=p.inertia, placement=B))
    return Beam(name, L, m, formulation, tuple(deform), bool(linear), bodies, frames, rfe, sde)


def _tip_inertia(tip_inertia) -> np.ndarray:
    """A tip body's inertia about its centre of mass (kg·m²): principal moments (3,) or a
    tensor (3, 3), positive semi-definite (zero for a point mass) with I1 + I2 >= I3."""
    try:
        I = np.diag(tip_inertia) if np.shape(tip_inertia) == (3,) else np.asarray(tip_inertia, float)
    except (TypeError, ValueError):
        raise ValueError(f"tip_inertia: expected (3,) moments or a (3, 3) tensor in kg·m², got {tip_inertia!r}") from None
    I = _checks.array(I, (3, 3), "tip_inertia")
    if not np.allclose(I, I.T, rtol=1e-12, atol=0.0):
        raise ValueError("tip_inertia: expected a symmetric tensor, got an asymmetric one")
    moments = np.linalg.eigvalsh(I)
    if moments[0] < -1e-12 * max(moments[-1], 0.0) or moments[0] + moments[1] < moments[2] * (1 - 1e-9):
        raise ValueError(f"tip_inertia: expected principal moments >= 0 with I1 + I2 >= I3, got {moments}")
    return I


def _couple_linear(j, bodies, frames, i):
    """The linear model: rfe i hangs on rfe 0 at its undeformed place and moves with the
    coordinates of sdes 1..i to first order, T_0i = (1 + Σ_k X_k q_k) T_0i(0), where
    X_k = S_k Q S_k⁻¹ is coordinate k's generator Q carried to the undeformed frame S_k of
    sde k. In rfe i's joint frame: G = Trans(x_k − x_i) Q Trans(x_i − x_k)."""
    j.linear = True
    for k in range(1, i):
        shift = transform(translation=(frames[k] - frames[i], 0.0, 0.0))
        for slot, c in enumerate(j.coordinates):
            Q = _core.joint_transform_derivative([c], [0.0], 0)
            j.add_coupling(bodies[k].index, slot, shift @ Q @ _core.inverse(shift))
