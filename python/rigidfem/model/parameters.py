"""Named parameters of a compiled system: the physical constants a model was built with, changed
without compiling the model again, and differentiated by ``rigidfem.simulate(..., sensitivities=...)``.

Every builder declares the constants it was given as parameters named ``"<what>.<argument>"``:

- ``<beam>.E``, ``.G`` (Pa): Young's and shear modulus, the sde springs (E: axial and bending, G: shear
  and torsion); E leaves G as it is.
- ``<beam>.rho`` (kg/m³): density, the rfes' masses and inertias (a tip mass stays).
- ``<beam>.retardation`` (s): retardation time μ of the Kelvin–Voigt dampers b = μ c.
- ``<beam>.A``, ``.Iy``, ``.Iz``, ``.J`` (m², m⁴): section values, the springs (EA, κGA, E Iy, E Iz, GJ)
  and the rfes' inertias (A: mass and ∫x² dm; Iy and Iz: rotary inertia).
- ``<body>.mass`` (kg): a rigid body's mass, its centre of mass and inertia about it kept.
- ``<body>.<axis>.stiffness``, ``.damping``, ``.force``: a joint coordinate's spring, damper and constant
  applied force (N/m, N·s/m, N; N·m/rad, N·m·s/rad, N·m for rotations).
- ``<element>.stiffness``, ``.damping``, ``.force``: a spring-damper's or cylinder's k, c and constant
  push F₀ (N/m, N·s/m, N); ``<rope>.EA``, ``.DA``: a rope's axial stiffness and damping (N, N·s).
- ``<law>.<constant>``: the constants of any law (``rigidfem.laws``: a force element's, a joint coordinate's
  friction) that its kind's description marks as parameters, in its units.
- ``<load>.force``, ``.torque`` (N, N·m): the magnitude of a point force or torque, its direction kept.

Beams take parameters when their material and section are one ``Material`` and one ``Section``
(a beam varying along its length has no single E or A); a viscoelastic (Prony) beam takes rho and
damping only (its E, G and section values also set its Maxwell arms, k_j = (E_j/E) c). The rfes of a beam are not
bodies with a ``.mass`` of their own: ``rho`` and the section set them.

``System.parameters`` lists them with their values and units; ``System.with_parameters({name:
value})`` returns the system at other values (O(n): its tables are copied with the new constants,
the model is not compiled again), which simulates exactly as the model built with those values.
Every constant they set but one enters the equations of motion linearly (inertias, springs, dampers, applied
forces), which is what makes the sensitivities' derivatives by them exact to round-off
(``cpp/include/rigidfem/sensitivities.hpp``); a contact's restitution does not (``Parameter.linear`` False), and
is differenced centrally, as a profile's numbers are.

Examples
--------
>>> import rigidfem as rf
>>> model, h = rf.samples.cantilever(elements=4)
>>> system = model.compile()
>>> sorted(system.parameters)[:3]
['beam.A', 'beam.E', 'beam.G']
>>> stiffer = system.with_parameters({"beam.E": 4.2e11})
>>> round(float(rf.modal_analysis(stiffer).omega[0] / rf.modal_analysis(system).omega[0]), 6)
1.414214
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

import rigidfem._core as _core  # the compiled core, by its absolute name
from ..base import _checks


@dataclass(frozen=True)
class Parameter:
    """A named parameter of a system: its current ``value`` in ``unit``, and what it sets.

    Examples
    --------
    >>> import rigidfem as rf
    >>> model, h = rf.samples.spring_mass()
    >>> p = model.compile().parameters["block.mass"]
    >>> p.value, p.unit
    (2.0, 'kg')
    """

    name: str
    value: float
    unit: str
    description: str
    #: the smallest value allowed (``positive``: excluded)
    minimum: float = field(default=0.0, repr=False)
    positive: bool = field(default=False, repr=False)
    #: whether the equations are linear in it (the constants; not a profile's numbers)
    linear: bool = field(default=True, repr=False)
    #: the largest value allowed (included; a contact's restitution: 1)
    maximum: float = field(default=math.inf, repr=False)

    def check(self, value, argument: str = "values") -> float:
        """The value as a float, or ValueError naming ``argument``, the parameter and the values it takes."""
        bound = f" > {self.minimum:g}" if self.positive else "" if self.minimum == -math.inf else f" >= {self.minimum:g}"
        bound += f" and <= {self.maximum:g}" if self.maximum < math.inf else ""
        expected = f"{self.name} to be a finite value{bound} in {self.unit} ({self.description})"
        try:
            x = _core._real(value, argument, "a number")
        except (TypeError, ValueError):
            raise _checks.refuse(f"{argument}: expected {expected}, got {value!r}") from None
        if not math.isfinite(x) or (x <= self.minimum if self.positive else x < self.minimum) or x > self.maximum:
            raise _checks.refuse(f"{argument}: expected {expected}, got {value!r}")
        return x


@dataclass
class Changes:
    """Constants of a compiled system to set (the arguments of ``_core._System(base, ...)``)."""

    coordinates: list = field(default_factory=list)  #: tuples (body, slot, law, name, x) of joint coordinates' laws
    bodies: list = field(default_factory=list)       #: tuples (body, H) with H the (4, 4) pseudo-inertia
    elements: list = field(default_factory=list)     #: tuples (element, constant's name, value)
    loads: list = field(default_factory=list)        #: tuples (load, F (3,), τ (3,))
    profiles: list = field(default_factory=list)     #: tuples (what, body, index, profile): see parameters.hpp
    contacts: list = field(default_factory=list)     #: tuples (contact, constant's name, value)

    def __iadd__(self, other: Changes) -> Changes:
        for name in ("coordinates", "bodies", "elements", "loads", "profiles", "contacts"):
            getattr(self, name).extend(getattr(other, name))
        return self

    def arguments(self) -> tuple:
        """The changes as the arguments of ``_core._System(base, ...)`` after ``base``."""
        return self.coordinates, self.bodies, self.elements, self.loads, self.profiles, self.contacts

    def apply(self, base) -> _core._System:
        return _core._System(base, *self.arguments())


class Group:
    """The parameters of one thing a builder added, and the constants they set: ``parameters`` by
    their short names, ``changes(values)`` the constants at the values (a dict by short name)."""

    def __init__(self, prefix: str, parameters: dict[str, Parameter]):
        self.prefix = prefix
        self.parameters = parameters

    def changes(self, values: dict) -> Changes:  # pragma: no cover - every kind overrides it
        raise NotImplementedError


def _parameter(prefix, name, value, unit, description, positive=False) -> tuple[str, Parameter]:
    return name, Parameter(f"{prefix}.{name}", float(value), unit, description, 0.0, positive, True)


class BeamGroup(Group):
    """A uniform beam's E, G, rho, retardation and section values (``Model.add_beam``).

    Its rfes' pseudo-inertias are H = (ρ/ρ₀) [(A/A₀) H_A + (Iz/Iz₀) H_z + (Iy/Iy₀) H_y] + H_tip, the parts
    ∝ ρA (mass, ∫x dm, ∫x² dm), ∝ ρ Iz (∫y² dm) and ∝ ρ Iy (∫z² dm) at the built values; its sde springs
    c = c₀ · (E/E₀ or G/G₀) · (the section value of the deformation)/(its built value) and dampers b = μ c.
    """

    # the material and section values each deformation's spring is proportional to
    SPRING = {"axial": ("E", "A"), "shear_y": ("G", "A"), "shear_z": ("G", "A"), "torsion": ("G", "J"),
              "bend_y": ("E", "Iy"), "bend_z": ("E", "Iz")}

    def __init__(self, prefix, material, section, viscoelastic, rfes, H, H_tip, sdes, slots, kinds, stiffness):
        names = ("rho", "retardation") if viscoelastic else ("E", "G", "rho", "retardation", "A", "Iy", "Iz", "J")
        info = {"E": ("Pa", "Young's modulus: the axial and bending springs", True),
                "G": ("Pa", "shear modulus: the shear and torsion springs", True),
                "rho": ("kg/m³", "density: the rfes' masses and inertias", True),
                "retardation": ("s", "retardation time of the Kelvin-Voigt dampers b = retardation * c", False),
                "A": ("m²", "area: the axial and shear springs, the rfes' masses", True),
                "Iy": ("m⁴", "second moment about y: the bend_y springs, the rfes' rotary inertia", True),
                "Iz": ("m⁴", "second moment about z: the bend_z springs, the rfes' rotary inertia", True),
                "J": ("m⁴", "torsion constant: the torsion springs", True)}
        built = {"E": material.E, "G": material.G, "rho": material.rho, "retardation": material.retardation,
                 "A": section.A, "Iy": section.Iy, "Iz": section.Iz, "J": section.J}
        super().__init__(prefix, dict(_parameter(prefix, k, built[k], *info[k]) for k in names))
        self.built = built
        self.rfes = np.asarray(rfes, dtype=int)
        H = np.asarray(H, dtype=float)
        self.H_A, self.H_z, self.H_y = np.zeros_like(H), np.zeros_like(H), np.zeros_like(H)
        for i, j in ((0, 0), (0, 3), (3, 0), (3, 3)):
            self.H_A[:, i, j] = H[:, i, j]
        self.H_z[:, 1, 1], self.H_y[:, 2, 2] = H[:, 1, 1], H[:, 2, 2]
        self.H_tip = H_tip
        self.sdes, self.slots, self.kinds = np.asarray(sdes, dtype=int), list(slots), list(kinds)
        self.stiffness = np.asarray(stiffness, dtype=float).reshape(len(self.sdes), len(self.slots))

    def changes(self, values: dict) -> Changes:
        v = {**self.built, **values}

        def scaled(x, k):  # x v_k / v_k₀, divided first (1e300 m⁴ / Iz₀ overflows where x / Iz₀ · 1e300 need not)
            return _scaled(x, v[k], self.built[k])

        H = scaled(scaled(self.H_A, "A") + scaled(self.H_z, "Iz") + scaled(self.H_y, "Iy"), "rho") + self.H_tip
        c = self.stiffness.copy()
        for col, kind in enumerate(self.kinds):
            modulus, section = self.SPRING.get(kind, (None, None))
            if modulus is None:
                c[:, col] = 0.0
                continue
            # the product of the two ratios first, as the springs were built (bit for bit); each ratio in turn
            # only where that product overflows or underflows (an overflow left is refused below)
            with np.errstate(over="ignore", under="ignore"):
                factor = v[modulus] / self.built[modulus] * (v[section] / self.built[section])
                c[:, col] = c[:, col] * factor if math.isfinite(factor) and factor != 0.0 else \
                    scaled(scaled(c[:, col], modulus), section)
        b = _scaled(c, v["retardation"])
        if not (np.isfinite(H).all() and np.isfinite(c).all() and np.isfinite(b).all()):
            given = ", ".join(f"{self.prefix}.{k} = {values[k]!r}" for k in values if values[k] != self.built[k])
            raise _checks.refuse(f"values: expected values whose rfes' pseudo-inertias, springs and dampers are finite "
                             f"(the products of the built ones with the ratios overflow), got {given}")
        out = Changes(bodies=list(zip(self.rfes.tolist(), H)))
        for col, slot in enumerate(self.slots):
            for body, k, d in zip(self.sdes.tolist(), c[:, col].tolist(), b[:, col].tolist()):
                out.coordinates += [(body, slot, -1, "stiffness", k), (body, slot, -1, "damping", d)]
        return out


def _scaled(x: np.ndarray, value: float, built: float = 1.0) -> np.ndarray:
    """x value / built where x is not zero (exact zeros kept: inf times zero would be NaN): x times the ratio, or,
    when the ratio overflows or underflows (1e300 m⁴ / Iz₀), x / built times value."""
    x = np.asarray(x, dtype=float)
    with np.errstate(over="ignore", invalid="ignore", under="ignore", divide="ignore"):
        ratio = value / built
        if math.isfinite(ratio) and (ratio != 0.0 or value == 0.0):
            return np.where(x != 0.0, ratio * x, 0.0)
        return np.where(x != 0.0, (x / built) * value, 0.0)


class BodyGroup(Group):
    """A rigid body's mass (``Model.add_body``): H = pseudo_inertia(m, com, I_c) with com and I_c kept."""

    def __init__(self, prefix, body: int, mass: float, com, inertia):
        super().__init__(prefix, dict([_parameter(prefix, "mass", mass, "kg", "the body's mass", True)]))
        self.body, self.com, self.inertia = body, np.asarray(com, dtype=float), np.asarray(inertia, dtype=float)

    def changes(self, values: dict) -> Changes:
        m = values.get("mass", self.parameters["mass"].value)
        return Changes(bodies=[(self.body, _core.pseudo_inertia(m, self.com, self.inertia))])


class LawGroup(Group):
    """The constants of a law that are named parameters (its kind's description, ``rigidfem.laws``), at the values
    it was built with: a force element's law (``target`` ("element", k)), a contact's (("contact", k)) or a joint
    coordinate's (("coordinate",
    body, slot, law): law −1 is the coordinate's own spring-damping law, k ≥ 0 its further law k). ``rotation``:
    the coordinate is a rotation (the constants' rotation units)."""

    def __init__(self, prefix, target: tuple, info: dict, values: dict, rotation: bool = False):
        super().__init__(prefix, {c["name"]: Parameter(f"{prefix}.{c['name']}", float(values[c["name"]]),
                                                       c["rotation_unit"] if rotation else c["unit"], c["doc"],
                                                       c["lower"], c["positive"], c["linear"], c["upper"])
                                  for c in info["constants"] if c["parameter"]})
        self.target, self.info, self.values, self.rotation = tuple(target), info, dict(values), rotation

    def with_values(self, **values) -> LawGroup:
        """The group with some constants at other values (``Model.add_generalized_force`` adds to the force)."""
        return LawGroup(self.prefix, self.target, self.info, {**self.values, **values}, self.rotation)

    def changes(self, values: dict) -> Changes:
        v = {k: values.get(k, p.value) for k, p in self.parameters.items()}
        if self.target[0] == "element":
            return Changes(elements=[(self.target[1], k, x) for k, x in v.items()])
        if self.target[0] == "contact":
            return Changes(contacts=[(self.target[1], k, x) for k, x in v.items()])
        _, body, slot, law = self.target
        return Changes(coordinates=[(body, slot, law, k, x) for k, x in v.items()])


class LoadGroup(Group):
    """The magnitude of a point force or torque (``Model.add_force``, ``add_torque``), its direction kept."""

    def __init__(self, prefix, load: int, force, torque):
        self.F, self.tau = np.asarray(force, dtype=float), np.asarray(torque, dtype=float)
        params = {}
        for k, vec, unit in (("force", self.F, "N"), ("torque", self.tau, "N m")):
            if np.any(vec):
                params[k] = Parameter(f"{prefix}.{k}", float(np.linalg.norm(vec)), unit,
                                      f"the {k}'s magnitude (its direction kept)")
        super().__init__(prefix, params)
        self.load = load

    def changes(self, values: dict) -> Changes:
        scale = {k: values.get(k, p.value) / p.value for k, p in self.parameters.items()}
        return Changes(loads=[(self.load, self.F * scale.get("force", 1.0), self.tau * scale.get("torque", 1.0))])


def register(model, group: Group) -> None:
    """Adds a builder's group of parameters to ``model`` (a later group of the same prefix replaces it:
    a coordinate's force added twice)."""
    model._parameter_groups[group.prefix] = group


def names_argument(names, argument: str, expected: str = "parameter names (System.parameters)") -> list[str]:
    """The list of distinct names (str) an argument gives (None: none); ValueError naming ``argument`` otherwise."""
    if names is None:
        return []
    if isinstance(names, str) or not isinstance(names, Sequence):
        raise _checks.refuse(f"{argument}: expected a list of {expected}, got {names!r}")
    for name in names:
        if not isinstance(name, str):
            raise _checks.refuse(f"{argument}: expected {expected} (str), got {name!r}")
    if len(set(names)) != len(names):
        raise _checks.refuse(f"{argument}: expected each name once, got {list(names)}")
    return list(names)


def initial_value(system, name: str, argument: str = "sensitivities"):
    """(part, index) of an initial-value parameter "q0[<coordinate>]" or "qd0[<coordinate>]", or None;
    ValueError naming ``argument`` when the coordinate is not one of the system's."""
    system = _checks.system(system)
    for part in ("q0", "qd0"):
        if name.startswith(part + "[") and name.endswith("]"):
            coordinate = name[len(part) + 1:-1]
            if coordinate not in system.coordinate_names:
                raise _checks.refuse(f"{argument}: expected a free coordinate in {name!r} "
                                 f"({_close(coordinate, system.coordinate_names)}), got {coordinate!r}")
            return part, system.coordinate_names.index(coordinate)
    return None


def _close(name: str, names) -> str:
    near = difflib.get_close_matches(name, list(names), n=3)
    return f"did you mean {', '.join(repr(n) for n in near)}?" if near else f"{len(names)} names: System.parameters"


class Parameters:
    """The named parameters of a System and their values (``System.parameters`` is a dict view of them)."""

    def __init__(self, groups: dict[str, Group]):
        self.groups = dict(groups)
        self.where = {}  # full name -> (group prefix, short name)
        for prefix, g in self.groups.items():
            for short, p in g.parameters.items():
                self.where[p.name] = (prefix, short)
        self.values = {p.name: p.value for g in self.groups.values() for p in g.parameters.values()}

    def parameter(self, name, argument: str = "name") -> Parameter:
        """The parameter called ``name`` at its current value; ValueError naming ``argument`` and the names
        nearest to an unknown one."""
        if not isinstance(name, str) or name not in self.where:
            raise _checks.refuse(f"{argument}: expected a parameter of this system "
                             f"({_close(str(name), self.where) if isinstance(name, str) else 'System.parameters'}),"
                             f" got {name!r}")
        prefix, short = self.where[name]
        p = self.groups[prefix].parameters[short]
        return Parameter(p.name, self.values[name], p.unit, p.description, p.minimum, p.positive, p.linear, p.maximum)

    def listing(self) -> dict[str, Parameter]:
        return {name: self.parameter(name) for name in self.values}

    def checked(self, values) -> dict[str, float]:
        """{name: float} of a dict of new values, each checked (ValueError naming it)."""
        if not isinstance(values, dict):
            raise _checks.refuse(f"values: expected a dict of parameter names to values, got {values!r}")
        return {name: self.parameter(name, "values").check(value) for name, value in values.items()}

    def changes(self, values: dict[str, float]) -> Changes:
        """The constants the groups of the named parameters set at the current values updated by ``values``
        (unchecked: the central differences step a value at 0 to both sides)."""
        out = Changes()
        touched = {}
        for name, value in values.items():
            prefix, short = self.where[name]
            touched.setdefault(prefix, {})[short] = value
        for prefix, new in touched.items():
            out += self.groups[prefix].changes({**self._current(prefix), **new})
        return out

    @property
    def _cache(self) -> dict:
        """Per object (its values do not change): each profile group's changed numbers and sampled values."""
        return self.__dict__.setdefault("_memo", {})

    def _current(self, prefix: str) -> dict[str, float]:
        """{short name: value} of a group's parameters; of a profile's, only those that differ from the numbers
        it was made of (a spline's hundred knots: each difference of one of them stays O(1) here)."""
        cache = self._cache
        if prefix not in cache:
            g = self.groups[prefix]
            leaves = g.current_leaves() if isinstance(g, ProfileGroup) else {}
            cache[prefix] = {short: self.values[p.name] for short, p in g.parameters.items()
                             if not isinstance(g, ProfileGroup) or self.values[p.name] != leaves.get(short)}
        return cache[prefix]

    def updated(self, values: dict[str, float]) -> Parameters:
        copy = Parameters.__new__(Parameters)
        copy.groups, copy.where, copy.values = self.groups, self.where, {**self.values, **values}
        return copy

    def shifted(self, base, name: str, h: float) -> _core._System:
        """The compiled system ``base`` with the parameter ``name`` at its value + h (unchecked: a difference's)."""
        return self.changes({name: self.values[name] + h}).apply(base)

    def drive_affine(self, name: str) -> bool:
        """Whether ``name`` is a number of a prescribed coordinate's drive that its profile is affine in: the
        difference of the profiles at p + h and p is then (q, q̇, q̈)'s derivative by it for any h, to round-off."""
        prefix, short = self.where[name]
        group = self.groups[prefix]
        return isinstance(group, ProfileGroup) and group.what == "drive" and group.affine(short)

    def step(self, name: str) -> float:
        """The step h of the parameter's difference (R(p + h) − R(p))/h: the constants it sets enter the
        residual linearly, so any h gives ∂R/∂p to round-off; h = |p| (1 of its unit at p = 0) keeps that
        round-off at the residual's own. A profile's number (not linear) is differenced centrally with a step
        that moves the profile by 1e-6 of its size over [t0, t1] (s): see ``profile_step``."""
        p = self.values[name]
        return abs(p) if p != 0.0 else 1.0

    def profile_pair(self, base, name: str, t0: float, t1: float, argument: str = "sensitivities") -> tuple:
        """(system at p + h, system at p − h, h) of a profile's number for the central difference over
        [t0, t1] (s), h from ``profile_step``. Where p sits at the edge of the values its profile takes
        (a ramp's fraction at 0.5), the side beyond is refused: the pair moves inward by h, [p, p − 2h]
        or [p + 2h, p] (the difference is then first order: the derivative at p ∓ h, its error O(h)).
        ValueError naming ``argument`` for a number that cannot change alone (a piece's value of a piecewise
        drive whose pieces must meet: only a change of both pieces together keeps them meeting)."""
        try:
            h = self.profile_step(name, t0, t1)
        except ValueError as e:
            raise _checks.refuse(f"{argument}: expected parameters that can change alone, got {name!r}, which "
                             f"refuses p ± 1e-6 max(|p|, 1) ({e})") from None
        for low, high in ((-1.0, 1.0), (-2.0, 0.0), (0.0, 2.0)):
            try:
                return self.shifted(base, name, high * h), self.shifted(base, name, low * h), h
            except ValueError:
                continue
        raise _checks.refuse(f"{argument}: expected a parameter that takes values beside "
                         f"{name} = {self.values[name]:g} (p ± {h:.3g}), got none on either side")

    def profile_step(self, name: str, t0: float, t1: float) -> float:
        """h for a profile's number: a trial step δ = 1e-6 max(|p|, 1) moves q(t) over 41 times in [t0, t1] by
        at most Δ; h = δ · 1e-6 max(1, |q|) / Δ, so that the central difference's truncation (∝ h²) and
        round-off (∝ 1/h) both stay near 1e-10 of the derivative; at most 1e3 δ. A law's constant the equations
        are not linear in (a contact's restitution): δ itself."""
        prefix, short = self.where[name]
        group = self.groups[prefix]
        if not isinstance(group, ProfileGroup):
            return 1e-6 * max(abs(self.values[name]), 1.0)
        changed = self._current(prefix)
        times = np.linspace(t0, t1, 41)
        key = (prefix, float(t0), float(t1))
        if key not in self._cache:  # the profile at its current values, once for all its numbers
            base = remade(group.profile, changed)
            self._cache[key] = base.sample(times)[:, 0]
        q = self._cache[key]
        p = self.values[name]
        delta = 1e-6 * max(abs(p), 1.0)
        try:
            moved = remade(group.profile, {**changed, short: p + delta})
        except ValueError:  # p at the upper edge of the values its profile takes: the trial step below it
            moved = remade(group.profile, {**changed, short: p - delta})
        change = np.max(np.abs(moved.sample(times)[:, 0] - q))
        # at most δ · 1e3: a number the profile hardly depends on over [t0, t1] (a ramp's fraction over 1 ms)
        # would otherwise get a step far beyond its values
        return min(delta * 1e-6 * max(1.0, float(np.max(np.abs(q)))) / change, 1e3 * delta) if change > 0.0 \
            else delta


# ----------------------------------------------------------------- profiles

#: The arguments of each kind of profile, in the order of its recipe (``Profile.__reduce__``): the C++ table's
#: (``profile_kinds`` in ``cpp/src/profiles.cpp``).
PROFILE_ARGUMENTS = {k["maker"]: tuple(a["name"] for a in k["arguments"]) for k in _core._profile_kinds()}
#: The arguments each kind of profile is affine in, the others fixed (the same table's ``affine``).
PROFILE_AFFINE = {k["maker"]: frozenset(a["name"] for a in k["arguments"] if a["affine"]) for k in _core._profile_kinds()}
#: The kinds whose parts' numbers stay affine in the whole (Σ w_k p_k + offset, p(t − delay)).
AFFINE_IN_PARTS = frozenset({"sum_profile", "shifted_profile"})


def _recipe(profile):
    """(maker, argument names, arguments) of a remakeable profile, or None (a Python function's)."""
    try:
        make, args = profile.__reduce__()
    except (TypeError, ValueError):
        return None
    if make is not _core._make_profile or not args or args[0] not in PROFILE_ARGUMENTS:
        return None
    return args[0], PROFILE_ARGUMENTS[args[0]], list(args[1:])


def profile_leaves(profile, path: str = "") -> dict[str, float]:
    """The numbers a profile is made of, by their paths: "amplitude", "coefficients[2]", "parts[1].omega"."""
    recipe = _recipe(profile)
    if recipe is None:
        return {}
    _, names, args = recipe
    out = {}
    for name, arg in zip(names, args):
        here = f"{path}{name}"
        if isinstance(arg, _core.Profile):
            out.update(profile_leaves(arg, here + "."))
        elif isinstance(arg, (list, tuple)) and arg and isinstance(arg[0], _core.Profile):
            for k, part in enumerate(arg):
                out.update(profile_leaves(part, f"{here}[{k}]."))
        elif isinstance(arg, (list, tuple)):
            out.update({f"{here}[{k}]": float(v) for k, v in enumerate(arg)})
        elif isinstance(arg, float):
            out[here] = arg
    return out


def affine_leaves(profile, path: str = "") -> set[str]:
    """The paths of profile_leaves the profile is affine in (each alone, the others fixed): its kind's affine
    arguments, and a sum's or a shift's parts' own, by the kinds' table."""
    recipe = _recipe(profile)
    if recipe is None:
        return set()
    maker, names, args = recipe
    out = set()
    for name, arg in zip(names, args):
        here = f"{path}{name}"
        if isinstance(arg, _core.Profile):
            out |= affine_leaves(arg, here + ".") if maker in AFFINE_IN_PARTS else set()
        elif isinstance(arg, (list, tuple)) and arg and isinstance(arg[0], _core.Profile):
            if maker in AFFINE_IN_PARTS:
                for k, part in enumerate(arg):
                    out |= affine_leaves(part, f"{here}[{k}].")
        elif name in PROFILE_AFFINE[maker]:
            out |= {f"{here}[{k}]" for k in range(len(arg))} if isinstance(arg, (list, tuple)) else {here}
    return out


def remade(profile, values: dict[str, float], path: str = ""):
    """The profile made again with the numbers at the paths in ``values`` changed (its maker's checks apply); one
    without a recipe (a Python function's, a part of a sum) has no numbers and stays as it is."""
    recipe = _recipe(profile)
    if recipe is None:
        return profile
    maker, names, args = recipe
    new = []
    for name, arg in zip(names, args):
        here = f"{path}{name}"
        if isinstance(arg, _core.Profile):
            arg = remade(arg, values, here + ".")
        elif isinstance(arg, (list, tuple)) and arg and isinstance(arg[0], _core.Profile):
            arg = [remade(part, values, f"{here}[{k}].") for k, part in enumerate(arg)]
        elif isinstance(arg, (list, tuple)):  # the entries "<here>[k]" named in values
            start = len(here) + 1
            hits = [(int(key[start:-1]), v) for key, v in values.items()
                    if key.startswith(here + "[") and key.endswith("]") and key[start:-1].isdigit()]
            if hits:
                arg = list(arg)
                for k, v in hits:
                    if k < len(arg):
                        arg[k] = v
        elif isinstance(arg, float):
            arg = values.get(here, arg)
        new.append(arg)
    return _core._make_profile(maker, *new)


class ProfileGroup(Group):
    """The numbers of a profile a builder was given — a prescribed coordinate's drive ("<body>.<axis>.drive"),
    a winch's unstretched length ("<rope>.length"), a cylinder's force ("<element>.profile"), a load's scale
    ("<load>.scale"), an actuator's length ("<actuator>.length") or a link's free length ("<beam>.length") — each a parameter "<prefix>.<path>":
    ``coefficients[2]`` of a polynomial, ``amplitude`` of a harmonic, ``q[3]`` of a spline, ``parts[1].omega`` of
    a sum. The residual is not linear in them: their sensitivities difference the systems at p ± h. The adjoint
    (``rf.gradient``) differences only a drive's (q, q̇, q̈): a number the profile is affine in (``affine``) takes
    the system at p + h alone."""

    def __init__(self, prefix, what: str, body: int, index: int, profile, unit: str):
        self.profile, self.what, self.body, self.index = profile, what, body, index
        self.leaves = profile_leaves(profile)
        params = {path: Parameter(f"{prefix}.{path}", value, unit, f"a number of the profile {profile!r}",
                                  -math.inf, False, linear=False)
                  for path, value in self.leaves.items()}
        super().__init__(prefix, params)

    def changes(self, values: dict) -> Changes:
        leaves = self.current_leaves()
        values = {path: v for path, v in values.items() if v != leaves.get(path)}  # the few that change
        try:
            profile = remade(self.profile, values)
        except (TypeError, ValueError) as e:
            raise _checks.refuse(f"values: expected numbers the profile of {self.prefix} takes, got {values} ({e})") from None
        return Changes(profiles=[(self.what, self.body, self.index, profile)])

    def current_leaves(self) -> dict[str, float]:
        """The numbers of the profile the builder was given (kept: a group unpickled from before has none)."""
        if not hasattr(self, "leaves"):
            self.leaves = profile_leaves(self.profile)
        return self.leaves

    def affine(self, short: str) -> bool:
        """Whether the profile is affine in its number ``short`` (``affine_leaves``)."""
        if not hasattr(self, "affine_paths"):
            self.affine_paths = affine_leaves(self.profile)
        return short in self.affine_paths
