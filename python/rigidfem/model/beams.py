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

import functools
import operator
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..base import _checks
import rigidfem._core as _core  # the compiled core, by its absolute name
from . import parameters
from .._core import Body, Point
from .joints import Joint
from .materials import Material, Section
from .frames import transform

#: Deformation name -> joint coordinate of the sde (book order x, y, z, φ3, φ2, φ1).
DEFORMATIONS = {"axial": "x", "shear_y": "y", "shear_z": "z", "torsion": "rx", "bend_y": "ry", "bend_z": "rz"}
MODIFIED_DEFORMATIONS = ("torsion", "bend_y", "bend_z")
#: The most sdes of one beam: each rfe is a body (about 1-2 kB in every workspace), so 10⁵ elements
#: cost ~0.2 GB per workspace; far more would exhaust memory (or take minutes) before failing.
MAX_ELEMENTS = 100_000

_GAUSS = np.polynomial.legendre.leggauss(8)  # exact for polynomials of degree ≤ 15 on each piece


@dataclass(frozen=True)
class Property:
    """A beam property along the arc length s: one value, a function of s, or one per segment.

    ``at(s)`` is the value (a Material or Section) at one s; ``sample(s, fields)`` the named
    fields at an array of s at once, (len(fields), *s.shape) or broadcastable to it, without a
    Python call per s unless the property is a function of s.
    """

    at: Callable[[float], object]
    breakpoints: tuple[float, ...] = ()
    table: Callable[[np.ndarray, tuple[str, ...]], np.ndarray] | None = None

    def sample(self, s: np.ndarray, fields: tuple[str, ...]) -> np.ndarray:
        if self.table is not None:
            return self.table(s, fields)
        values = [self.at(x) for x in s.ravel()]
        return np.array([[getattr(v, f) for v in values] for f in fields], dtype=float).reshape(len(fields), *s.shape)

    @staticmethod
    def of(value, kind: type, name: str, length: float, elements: int) -> Property:
        if isinstance(value, kind):
            def constant(s, fields):  # (len(fields), 1, ...): broadcasts against s
                return np.array([getattr(value, f) for f in fields], dtype=float).reshape(-1, *[1] * np.ndim(s))

            return Property(lambda s: value, (), constant)
        if callable(value):
            def checked(s):
                v = value(s)
                if not isinstance(v, kind):
                    raise _checks.refuse(f"{name}: expected the function to return a {kind.__name__} at s = {s}, got {v!r}")
                return v

            return Property(checked)
        if isinstance(value, Sequence) and not isinstance(value, str):
            if len(value) != elements or not all(isinstance(v, kind) for v in value):
                raise _checks.refuse(f"{name}: expected a {kind.__name__}, a function of s or {elements} of them "
                                 f"(one per segment), got {len(value)} items")
            d = length / elements
            values = list(value)

            def per_segment(s, fields):  # the values of the segment holding each s
                segment = np.clip(np.floor_divide(s, d), 0, elements - 1).astype(int)
                return np.array([[getattr(v, f) for v in values] for f in fields], dtype=float)[:, segment]

            return Property(lambda s: values[min(max(int(s // d), 0), elements - 1)],
                            tuple(k * d for k in range(1, elements)), per_segment)
        raise _checks.refuse(f"{name}: expected a {kind.__name__}, a function of s or a list per segment, got {value!r}")


def _pieces(a: np.ndarray, b: np.ndarray, breakpoints):
    """The intervals [a_i, b_i] cut at the breakpoints inside them: (lo, hi, owner, first), piece k
    being [lo_k, hi_k] of interval owner_k, and first_i the first piece of interval i."""
    B = np.unique(np.asarray(breakpoints, dtype=float))
    n = len(a)
    if not len(B):
        return a, b, np.arange(n), np.arange(n)
    i0 = np.searchsorted(B, a, side="right")  # the first breakpoint > a_i
    inner = np.maximum(np.searchsorted(B, b, side="left") - i0, 0)  # breakpoints strictly inside
    count = inner + 1
    first = np.cumsum(count) - count
    owner = np.repeat(np.arange(n), count)
    j = np.arange(owner.size) - first[owner]  # the piece's number within its interval
    last = len(B) - 1
    lo = np.where(j == 0, a[owner], B[np.clip(i0[owner] + j - 1, 0, last)])
    hi = np.where(j == inner[owner], b[owner], B[np.clip(i0[owner] + j, 0, last)])
    return lo, hi, owner, first


def _integrate(fun, a, b, breakpoints=()) -> np.ndarray:
    """∫_{a_i}^{b_i} fun ds over every interval i by 8-point Gauss–Legendre on each piece between
    breakpoints: ``fun(s, owner)`` takes the nodes s (8, pieces) and the index of each piece's
    interval (pieces,) and returns a list of values, each (8, pieces) or broadcastable to it.
    Returns (nvalues, len(a)); each interval's sum runs in the same order however many there are,
    so one interval is integrated exactly as many are."""
    a, b = np.atleast_1d(np.asarray(a, dtype=float)), np.atleast_1d(np.asarray(b, dtype=float))
    lo, hi, owner, first = _pieces(a, b, breakpoints)
    half, mid = 0.5 * (hi - lo), 0.5 * (hi + lo)
    x, w = _GAUSS
    nodes = x[:, None] * half + mid  # (8, pieces)
    rows = []
    for v in fun(nodes, owner):
        v = np.broadcast_to(v, nodes.shape)
        total = w[0] * v[0]
        for k in range(1, len(w)):
            total = total + w[k] * v[k]
        rows.append(half * total)
    return np.add.reduceat(np.array(rows), first, axis=1)


def _as_property(value, kind, name) -> Property:
    return value if isinstance(value, Property) else Property.of(value, kind, name, 1.0, 1)


@dataclass(frozen=True)
class RfeParameters:
    """Inertia of one rigid finite element, in its frame (x along the beam)."""

    mass: float            #: kg
    com: np.ndarray        #: (3,) m
    inertia: np.ndarray    #: (3, 3) kg·m², about the centre of mass
    H: np.ndarray          #: (4, 4) pseudo-inertia ∫ r rᵀ dm


class _RfeTable:
    """The parameters of n rfes as arrays: mass (n,), com (n, 3), inertia (n, 3, 3), H (n, 4, 4)."""

    def __init__(self, H: np.ndarray):
        self.H = H
        self.mass = H[:, 3, 3]
        self.com = H[:, :3, 3] / self.mass[:, None]
        self.inertia = _inertia_about_com(H)

    def __getitem__(self, i: int) -> RfeParameters:
        return RfeParameters(self.mass[i], self.com[i].copy(), self.inertia[i].copy(), self.H[i].copy())


def _pseudo_inertias(mat: Property, sec: Property, start, end, origin) -> np.ndarray:
    """H (n, 4, 4) of the rfes [start_i, end_i] with frames at the arc lengths origin_i (see rfe_parameters)."""
    x0 = np.atleast_1d(np.asarray(origin, dtype=float))

    def density(s, owner):  # [ρA, ρA x, ρA x², ρ Iz, ρ Iy]
        (rho,), (A, Iz, Iy) = mat.sample(s, ("rho",)), sec.sample(s, ("A", "Iz", "Iy"))
        x = s - x0[owner]  # (8, pieces)
        rhoA = rho * A
        return [rhoA, rhoA * x, rhoA * x * x, rho * Iz, rho * Iy]

    mass, first, xx, yy, zz = _integrate(density, start, end, mat.breakpoints + sec.breakpoints)
    H = np.zeros((len(mass), 4, 4))
    H[:, 0, 0], H[:, 1, 1], H[:, 2, 2] = xx, yy, zz
    H[:, 0, 3] = H[:, 3, 0] = first
    H[:, 3, 3] = mass
    return H


def rfe_parameters(material, section, start: float, end: float, origin: float | None = None) -> RfeParameters:
    """Mass, centre of mass, inertia and pseudo-inertia of the beam piece [start, end] (m),
    in a frame on the beam axis at arc length ``origin`` (default ``start``).

    With x measured from the frame: m = ∫ρA ds, m x_C = ∫ρA x ds, ∫x² dm = ∫ρA x² ds and
    the section's rotary inertia ∫y² dm = ∫ρ Iz ds, ∫z² dm = ∫ρ Iy ds (book ch. 3.6).
    ``material``/``section`` may be functions of s.

    Examples
    --------
    >>> import rigidfem as rf
    >>> p = rf.rfe_parameters(rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005), 0.0, 0.1)
    >>> round(float(p.mass), 6)
    0.0785
    """
    mat = _as_property(material, Material, "material")
    sec = _as_property(section, Section, "section")
    return _RfeTable(_pseudo_inertias(mat, sec, start, end, start if origin is None else origin))[0]


def _inertia_about_com(H: np.ndarray) -> np.ndarray:
    """Inverse of the pseudo-inertia: I_O = tr(S) 1 − S with S = ∫r rᵀ dm, shifted to the c.o.m.
    H (4, 4) or a stack (n, 4, 4); the inertia (3, 3) or (n, 3, 3) about the c.o.m."""
    m = H[..., 3, 3, None, None]
    c = H[..., :3, 3] / H[..., 3, 3, None]
    S = H[..., :3, :3]
    eye = np.eye(3)
    I_O = np.trace(S, axis1=-2, axis2=-1)[..., None, None] * eye - S
    cc = np.sum(c * c, axis=-1)[..., None, None]
    return I_O - m * (cc * eye - c[..., :, None] * c[..., None, :])


@dataclass(frozen=True)
class SdeParameters:
    """Spring and damper constants of one sde by deformation: stiffness c_k (N/m or N·m/rad),
    damping b_k = μ c_k (N·s/m or N·m·s/rad)."""

    stiffness: dict
    damping: dict


SDE_DEFORMATIONS = ("axial", "shear_y", "shear_z", "torsion", "bend_y", "bend_z")


class _SdeTable:
    """The constants of n sdes as arrays (n, 6), columns in SDE_DEFORMATIONS order."""

    def __init__(self, stiffness: np.ndarray, damping: np.ndarray):
        self.stiffness, self.damping = stiffness, damping

    def __getitem__(self, i: int) -> SdeParameters:
        return SdeParameters(dict(zip(SDE_DEFORMATIONS, self.stiffness[i])),
                             dict(zip(SDE_DEFORMATIONS, self.damping[i])))


def _sde_table(mat: Property, sec: Property, start, end) -> _SdeTable:
    """The sdes of the segments [start_i, end_i] (see sde_parameters)."""
    def compliance(s, owner):  # 1 / (stiffness per unit length) of axial, shear_y, shear_z, torsion, bend_y, bend_z
        (E, G), (A, J, Iy, Iz, ky, kz) = mat.sample(s, ("E", "G")), sec.sample(s, ("A", "J", "Iy", "Iz", "kappa_y",
                                                                                  "kappa_z"))
        return [1.0 / (E * A), 1.0 / (ky * G * A), 1.0 / (kz * G * A), 1.0 / (G * J), 1.0 / (E * Iy), 1.0 / (E * Iz)]

    middle = 0.5 * (np.atleast_1d(np.asarray(start, dtype=float)) + np.atleast_1d(np.asarray(end, dtype=float)))
    mu = mat.sample(middle, ("retardation",))[0]
    # An overflow (a stiffness of inf, and 0 · inf damping) is refused by add_body, naming the argument.
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        c = (1.0 / _integrate(compliance, start, end, mat.breakpoints + sec.breakpoints)).T
        return _SdeTable(c, mu[:, None] * c)


def sde_parameters(material, section, start: float, end: float) -> SdeParameters:
    """Spring and damper constants of the sde of the segment [start, end] (m), book ch. 3.6:
    c_x = EA/Δ, c_y = κ_y GA/Δ, c_z = κ_z GA/Δ, c_φ1 = GJ/Δ, c_φ2 = E Iy/Δ, c_φ3 = E Iz/Δ,
    b_k = μ c_k. For a varying section each c is the segment's integrated compliance,
    1/c = ∫ ds/(EI)(s), which for a uniform one is Δ/(EI).

    Examples
    --------
    >>> import rigidfem as rf
    >>> p = rf.sde_parameters(rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005), 0.0, 0.1)
    >>> round(float(p.stiffness["bend_z"]), 1)
    7000.0
    """
    mat = _as_property(material, Material, "material")
    sec = _as_property(section, Section, "section")
    return _sde_table(mat, sec, start, end)[0]


class _Rows(Sequence):
    """A read-only list whose items are made from a table on access (a beam's rfe and sde parameters:
    a long beam's hundred thousand of them cost nothing until read)."""

    def __init__(self, table, n: int):
        self._table, self._n = table, n

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(self._n))]
        k = operator.index(i)
        if not -self._n <= k < self._n:
            raise IndexError(f"index {i} out of range for {self._n} items")
        return self._table[k % self._n]

    def __eq__(self, other) -> bool:
        return isinstance(other, Sequence) and list(self) == list(other)

    def __repr__(self) -> str:
        return f"[{self[0]!r}, ...] ({self._n} items)" if self._n else "[]"


@dataclass
class Beam:
    """Handle of a beam added by ``Model.add_beam``.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.cantilever(elements=4)
    >>> beam = h["beam"]
    >>> beam.elements, len(beam.rfes), beam.deform
    (4, 5, ('bend_z',))
    """

    name: str
    length: float
    elements: int
    formulation: str
    deform: tuple[str, ...]
    linear: bool
    rfes: list[Body]                      #: the m + 1 rigid finite elements, root to tip
    frames: np.ndarray                    #: (m + 1,) arc length of each rfe frame, m
    rfe: Sequence[RfeParameters] = field(repr=False)  #: (m + 1) inertia of each rfe (at L(0) if it varies)
    sde: Sequence[SdeParameters] = field(repr=False)  #: (m) springs and dampers of each sde (at L(0))
    length_profile: object = field(default=None, repr=False)  #: L(t) of a link of varying length, or None

    @property
    def varying(self) -> bool:
        """Whether the free length varies in time (``add_beam(length=profile)``)."""
        return self.length_profile is not None

    def length_at(self, t) -> np.ndarray:
        """The free length L(t) (m) at the times ``t`` (s): constant unless it varies."""
        t = np.asarray(t, dtype=float)
        if not self.varying:
            return np.full(t.shape, self.length)
        return np.vectorize(lambda x: self.length_profile(float(x))[0], otypes=[float])(t)

    def tip_positions(self, result) -> np.ndarray:
        """Global positions (len(t), 3) in m of the free end over a simulation ``result``: the last
        rfe's origin plus its axis times its current length (L(t)/(2m) for a varying length)."""
        result = _checks.result(result, needs="tip positions")
        last = self.rfes[-1]
        origin = result.position(last.origin)
        axis = result.position(last.point((1.0, 0.0, 0.0))) - origin
        return origin + axis * (self.length_at(result.t) / (2 * self.elements))[:, None]
    def rates_at_rest(self, system, q, *, t: float = 0.0) -> np.ndarray:
        """Joint rates q̇ (nq,) that leave this beam's deformed shape in place at time ``t`` (s) while its
        material slides through the guide at v = L̇ (a link of varying length; zeros for a constant one).

        Zero rates are not "at rest" for such a link: its rfe frames sit at fixed fractions ξ_k of the
        free length, so constant angles stretch or shrink the shape with L(t). At rest, the shape in
        the guide stands still, ∂w/∂t = 0 at a fixed distance from the guide (the material's transverse
        velocity is then v ∂w/∂x): here every sde point and the tip move only along the centre line, the
        least-squares q̇ of (I − τ τᵀ)(J q̇ + ∂P/∂t) = 0 at each of them (τ the centre line's tangent, by
        central differences of the polyline; J and ∂P/∂t by central differences of ``centerline``, O(n²)).
        Measured against the continuum of a tape retracted at 0.5 m/s from 0.6 m (tests/test_flows.py):
        from its static shape with these rates the tip converges at second order in m (1.4e-6, 3.5e-7,
        8.7e-8 m at m = 8, 16, 32), with zero rates it stays 1.2 % of the deflection off."""
        system = _checks.system(system)
        n = system.nq
        q = _checks.array(q, (n,), "q")
        t = _checks.scalar(t, "t")
        _checks.same_model(self.rfes[0], system, "system", "a system compiled from the beam's model")
        if not self.varying or n == 0:
            return np.zeros(n)
        step = 1e-7
        X = self.centerline(system, q, t=t)
        tangent = np.vstack([X[1] - X[0], X[2:] - X[:-2], X[-1] - X[-2]])
        tangent /= np.linalg.norm(tangent, axis=1)[:, None]
        across = np.eye(3)[None] - tangent[:, :, None] * tangent[:, None, :]   # (points, 3, 3): I − τ τᵀ
        drives = (self.centerline(system, q, t=t + step) - self.centerline(system, q, t=t - step)) / (2 * step)
        J = np.empty((len(X), 3, n))
        for i in range(n):
            dq = np.zeros(n)
            dq[i] = step
            J[:, :, i] = (self.centerline(system, q + dq, t=t) - self.centerline(system, q - dq, t=t)) / (2 * step)
        A = np.einsum("kab,kbi->kai", across[1:], J[1:]).reshape(-1, n)   # the root sits in the guide
        b = np.einsum("kab,kb->ka", across[1:], drives[1:]).ravel()
        return np.linalg.lstsq(A, -b, rcond=None)[0]

    @property
    def tip(self) -> Point:
        """The beam's free end (s = L) on the last rfe (at L(0) for a varying length: see
        ``tip_positions``)."""
        return self.point(self.length)

    def point(self, s: float) -> Point:
        """The point at arc length ``s`` (m) of the undeformed beam, on the rfe containing it."""
        s = _checks.scalar(s, "s")
        if not 0.0 <= s <= self.length * (1 + 1e-12):
            raise _checks.refuse(f"s: expected an arc length in [0, {self.length}] m, got {s}")
        i = min(int(np.floor(s / (self.length / self.elements) + 0.5)), self.elements)
        return self.rfes[i].point((s - self.frames[i], 0.0, 0.0))

    def points(self) -> list[Point]:
        """The beam's root, its m sde points (on the rfe before each sde) and its tip."""
        return list(self._points)

    @functools.cached_property
    def _points(self) -> tuple[Point, ...]:
        step = np.diff(self.frames)
        sde = [self.rfes[i - 1].point((step[i - 1], 0.0, 0.0)) for i in range(1, self.elements + 1)]
        return (self.rfes[0].origin, *sde, self.tip)
    def centerline(self, system, q, *, t: float | None = None) -> np.ndarray:
        """Deformed centre line (m + 2, 3) in the global frame (m): root, sde points, tip, from one
        positions-only kinematics pass. ``t`` (s) is required when the system has prescribed
        coordinates, as for ``System.position``."""
        system = _checks.system(system)
        points = self._points
        _checks.same_model(points[0], system, "system", "a system compiled from the beam's model")
        t = _checks.pose_time(system, t)
        if not self.varying:
            return system._positions(list(points), t, q)
        # The sdes are the rfes' origins; the tip lies L(t)/(2m) along the last rfe's axis.
        last = self.rfes[-1]
        X = system._positions([b.origin for b in self.rfes] + [last.point((1.0, 0.0, 0.0))], t, q)
        tip = X[-2] + (X[-1] - X[-2]) * self.length_at(t) / (2 * self.elements)
        return np.vstack([X[:-1], tip])


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
    """Divide a straight beam into rfes and sdes and add them to ``model`` (see ``Model.add_beam``).

    O(m) in time and memory for the exact (nonlinear) model: the parameters of all rfes and sdes
    come from one vectorised quadrature and the rfes 1..m are added in one call; the linear model's
    couplings make it O(m²). A ``length`` given as a ``rigidfem.motion`` profile L(t) makes a link
    of varying free length (the equations: ``cpp/include/rigidfem/flows.hpp``): built at L(0), its sde joints get a prescribed
    "x" coordinate first that spreads the rfes over L(t)."""
    flow, name = None, model._new_name(name)
    linear = _checks.boolean(linear, "linear")
    if isinstance(length, _core.Profile):
        flow, length = length, _flow_length(length, material, section, deform, formulation, linear, tip_mass)
    L = _checks.scalar(length, "length", positive=True)
    if isinstance(elements, bool) or not isinstance(elements, (int, np.integer)) or not 1 <= elements <= MAX_ELEMENTS:
        raise _checks.refuse(f"elements: expected an integer number of sdes in [1, {MAX_ELEMENTS}], got {elements!r}")
    m = int(elements)
    if formulation not in ("classical", "modified"):
        raise _checks.refuse(f"formulation: expected 'classical' or 'modified', got {formulation!r}")
    allowed = MODIFIED_DEFORMATIONS if formulation == "modified" else tuple(DEFORMATIONS)
    deform = allowed if deform is None else _deform_names(deform)
    for d in deform:
        if d not in allowed:
            raise _checks.refuse(f"deform: expected deformations from {allowed} for the {formulation} formulation, "
                             f"got {d!r}")
    if len(set(deform)) != len(deform):
        raise _checks.refuse(f"deform: expected each deformation at most once, got {deform}")
    prony, mat_E = _prony(material, flow)
    mat = Property.of(material, Material, "material", L, m)
    sec = Property.of(section, Section, "section", L, m)
    tip_m = _checks.scalar(tip_mass, "tip_mass", nonnegative=True)

    d = L / m
    i = np.arange(1, m + 1)
    frames = np.concatenate([[0.0], (i - 0.5) * d])
    ends = np.concatenate([[0.5 * d], np.minimum((i + 0.5) * d, L)])
    H = _pseudo_inertias(mat, sec, np.concatenate([[0.0], frames[1:]]), ends, frames)
    sde = _sde_table(mat, sec, (i - 1) * d, i * d)
    names = [f"{name}.rfe{k}" for k in range(m + 1)]
    taken = set(model.body_names).intersection(names)
    if taken:
        raise _checks.refuse(f"name: expected a beam name whose rfe bodies are not in the model yet, got {name!r} "
                         f"({sorted(taken)[0]} exists)")
    H_beam, H_tip = H.copy(), np.zeros_like(H)  # the parts a density and section set, and what they leave
    if tip_m > 0.0:
        # A concentrated body at the tip (offset from s = L in beam axes) joins the last rfe.
        inertia = _tip_inertia(tip_inertia)
        offset = _checks.vec3(tip_offset, "tip_offset") + [L - frames[-1], 0.0, 0.0]
        H_tip[-1] = _core.pseudo_inertia(tip_m, offset, inertia)
        H[-1] = H[-1] + H_tip[-1]
    rfe = _RfeTable(H)

    # The sde joints: the chosen deformations' coordinates in the book's order, each with its column
    # of the sde table.
    template = Joint.custom([DEFORMATIONS[k] for k in deform])
    columns = [SDE_DEFORMATIONS.index(next(k for k in deform if DEFORMATIONS[k] == c)) for c in template.coordinates]
    if flow is not None:  # the growth coordinate "x" first, without spring (its column: axial, zeroed)
        template = Joint.custom(["x", *template.coordinates])
        columns = [SDE_DEFORMATIONS.index("axial"), *columns]
        sde = _SdeTable(sde.stiffness.copy(), sde.damping.copy())
        sde.stiffness[:, columns[0]] = sde.damping[:, columns[0]] = 0.0
    first, groups = model.nbodies, dict(model._parameter_groups)
    try:
        root = model.add_body(names[0], parent, joint if joint is not None else Joint.fixed(), mass=rfe.mass[0],
                              com=rfe.com[0], inertia=rfe.inertia[0], placement=placement)
        if linear:
            bodies = [root]
            for k in range(1, m + 1):
                j = Joint.custom(template.coordinates, stiffness=sde.stiffness[k - 1, columns],
                                 damping=sde.damping[k - 1, columns])
                _couple_linear(j, bodies, frames, k)
                bodies.append(model.add_body(names[k], root, j, mass=rfe.mass[k], com=rfe.com[k],
                                             inertia=rfe.inertia[k], placement=transform(translation=(frames[k], 0, 0))))
        else:
            # rfe k hangs on rfe k − 1 at the distance between their frames.
            placements = np.tile(np.eye(4), (m, 1, 1))
            placements[:, 0, 3] = np.diff(frames)
            bodies = [root, *model._add_bodies(
                names[1:], list(range(root.index, root.index + m)), template,
                np.ascontiguousarray(sde.stiffness[:, columns]).reshape(m, len(columns)),
                np.ascontiguousarray(sde.damping[:, columns]).reshape(m, len(columns)),
                placements.reshape(m, 16), rfe.mass[1:], rfe.com[1:], rfe.inertia[1:].reshape(m, 9))]
        _add_arms(model, bodies[1:], template.coordinates, sde.stiffness[:, columns], prony, mat_E)
        if flow is not None:
            model._add_flow(flow, root.index, m)
            parameters.register(model, parameters.ProfileGroup(f"{name}.length", "flow", -1, model._nflows - 1, flow,
                                                               "the link's free length (m, s, m/s)"))
    except BaseException:
        model._truncate(first)  # nothing half-added
        model._parameter_groups = groups
        raise
    # the rfes' masses (and the sdes' springs, bodies of the linear model) are the beam's parameters' to set
    sde_coordinates = {f"{n}.{c}" for n in names[1:] for c in template.coordinates}
    for prefix in [p for p in model._parameter_groups if p in names or p in sde_coordinates]:
        del model._parameter_groups[prefix]
    if isinstance(material, Material) and isinstance(section, Section):
        parameters.register(model, parameters.BeamGroup(
            name, material, section, bool(prony), [b.index for b in bodies], H_beam, H_tip,
            [b.index for b in bodies[1:]], range(len(columns)), [SDE_DEFORMATIONS[c] for c in columns],
            sde.stiffness[:, columns]))
    return Beam(name, L, m, formulation, tuple(deform), bool(linear), bodies, frames, _Rows(rfe, m + 1),
                _Rows(sde, m), flow)


def _prony(material, flow) -> tuple:
    """The Prony terms and E of a viscoelastic beam's material: one Material only (a varying one,
    a list or a function of s, has none), and no varying length."""
    if isinstance(material, Material):
        if material.prony and flow is not None:
            raise _checks.refuse("material: expected a Material without prony terms for a beam of varying length "
                             "(Maxwell arms on its flowing sdes are not supported), got one with "
                             f"{len(material.prony)}")
        return material.prony, material.E
    pieces = material if isinstance(material, (list, tuple)) else (material(0.0),) if callable(material) else ()
    if any(isinstance(v, Material) and v.prony for v in pieces):
        raise _checks.refuse("material: expected one Material for a viscoelastic (prony) beam, got a list per segment or a "
                         "function of s (varying Maxwell arms are not supported)")
    return (), 1.0


def _add_arms(model, sdes, coordinates, stiffness, prony, E) -> None:
    """One Maxwell arm per Prony term (E_j, τ_j) on every sde coordinate of stiffness c > 0:
    k = (E_j/E) c, τ_j (``Model.add_maxwell_arm``)."""
    if not prony:
        return
    c = np.asarray(stiffness).reshape(len(sdes), len(coordinates))
    body, slot = np.nonzero(c > 0.0)
    for E_j, tau in prony:
        model._add_maxwell_arms([sdes[b].index for b in body], [int(k) for k in slot],
                                list(E_j / E * c[body, slot]), [tau] * len(body))


def _deform_names(deform) -> tuple[str, ...]:
    """``deform`` as a tuple of deformation names: one name, or a sequence of them."""
    if isinstance(deform, str):
        return (deform,)
    if not isinstance(deform, (list, tuple, np.ndarray)) or not all(isinstance(d, str) for d in deform):
        raise _checks.refuse(f"deform: expected None, a deformation name or a sequence of them (from "
                         f"{tuple(DEFORMATIONS)}), got {_checks._short(deform)}")
    return tuple(deform)


def _flow_length(profile, material, section, deform, formulation, linear, tip_mass) -> float:
    """L(0) of a link of varying length, refusing what it does not support (yet)."""
    L0 = profile(0.0)[0]
    if not (np.isfinite(L0) and L0 > 0.0):
        raise _checks.refuse(f"length: expected a profile L(t) with a positive length L(0) in m, got L(0) = {L0}")
    if not isinstance(material, Material) or not isinstance(section, Section):
        raise _checks.refuse("material, section: expected one Material and one Section for a beam of varying length "
                         "(its material flows along it: a uniform beam), got properties varying along it")
    if linear:
        raise _checks.refuse("linear: expected False for a beam of varying length (the linear model is not supported), "
                         "got True")
    if deform is not None and "axial" in _deform_names(deform):
        raise _checks.refuse("deform: expected deformations without 'axial' for a beam of varying length (its sde "
                         "joints' x coordinate spreads the rfes over L(t)), got 'axial'")
    if _checks.scalar(tip_mass, "tip_mass", nonnegative=True) > 0.0:
        raise _checks.refuse(f"tip_mass: expected 0 for a beam of varying length (not supported yet), got {tip_mass}")
    return L0


def _tip_inertia(tip_inertia) -> np.ndarray:
    """A tip body's inertia about its centre of mass (kg·m²): principal moments (3,) or a
    tensor (3, 3), positive semi-definite (zero for a point mass) with I1 + I2 >= I3."""
    try:
        I = np.diag(tip_inertia) if np.shape(tip_inertia) == (3,) else np.asarray(tip_inertia, float)
    except (TypeError, ValueError):
        raise _checks.refuse(f"tip_inertia: expected (3,) moments or a (3, 3) tensor in kg·m², got {tip_inertia!r}") from None
    I = _checks.array(I, (3, 3), "tip_inertia")
    if not np.allclose(I, I.T, rtol=1e-12, atol=0.0):
        raise _checks.refuse("tip_inertia: expected a symmetric tensor, got an asymmetric one")
    moments = np.linalg.eigvalsh(I)
    if moments[0] < -1e-12 * max(moments[-1], 0.0) or moments[0] + moments[1] < moments[2] * (1 - 1e-9):
        raise _checks.refuse(f"tip_inertia: expected principal moments >= 0 with I1 + I2 >= I3, got {moments}")
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
