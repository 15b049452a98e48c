"""Laws of force elements, of joint coordinates and of contacts, each kind described once, by the C++ core.

A law is a value: ``rf.laws.Rope(EA=2e8, length=12.0, DA=1e6)``, ``rf.laws.Friction(breakaway=3.0, coulomb=2.0)``.
Its kind's description — the constants with their units, defaults, bounds and what they are, what a profile or
a Python function means to it — comes from the C++ law (``cpp/include/rigidfem/laws.hpp``:
``force_elements.hpp``, ``coordinate_laws.hpp``, ``contact.hpp``), and so do the checks of the values (a ValueError naming the
constant, its unit and its bounds). ``Model.add_force_element(name, a, b, law)`` puts a force element's law between
two points, ``Model.add_joint_law(name, body, law, coordinate)`` a joint coordinate's law on it, ``Model.add_contact(name,
a, b, law)`` a contact's between shapes; each law's constants
marked as parameters become named parameters ``"<name>.<constant>"`` of the compiled system.

>>> import rigidfem as rf
>>> rope = rf.laws.Rope(EA=2e8, length=12.0)
>>> [(c.name, c.unit, c.value) for c in rope.constants]
[('EA', 'N', 200000000.0), ('DA', 'N s', 0.0), ('length', 'm', 12.0), ('mass_per_length', 'kg/m', 0.0)]
>>> sorted(rf.laws.kinds())
['Buffer', 'Contact', 'ForceFunction', 'Friction', 'Rope', 'SlidingFriction', 'SpringDamper', 'SpringDamping']

Examples
--------
>>> import rigidfem as rf
>>> rf.laws.Rope(EA=2e8, length=12.0, DA=1e6)
Rope(EA=200000000.0, DA=1000000.0, length=12.0, mass_per_length=0.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Profile
from ..base import _checks


@dataclass(frozen=True)
class Constant:
    """One constant of a law: its ``name``, ``unit`` (``rotation_unit`` on a rotation coordinate), ``value``, the
    smallest value it takes (``lower``; ``positive``: excluded), what it is (``doc``) and whether it is a named
    parameter of a compiled system (``parameter``)."""

    name: str
    unit: str
    rotation_unit: str
    value: float
    lower: float
    positive: bool
    doc: str
    parameter: bool


_KINDS = {info["kind"]: info for info in _core._Model._law_kinds()}


def kinds() -> dict[str, dict]:
    """Every kind of law by name: its description as the C++ core gives it (acts_on, doc, constants, profile,
    function)."""
    return dict(_KINDS)


class Law:
    """A law of one kind (a subclass per kind: ``rf.laws.SpringDamper``, ``Rope``, ``Friction``, ...) with its
    constants' values, its profile and its Python function where its kind takes them."""

    info: dict = {}

    def __init__(self, *, profile: Profile | None = None, function=None, **constants):
        info = self.info
        names = [c["name"] for c in info["constants"]]
        unknown = sorted(set(constants) - set(names))
        if unknown:
            raise TypeError(f"{info['kind']}() got unexpected constants {unknown}; its constants are {names}")
        if profile is not None and (info["profile"] is None or not isinstance(profile, Profile)):
            raise _checks.refuse(f"profile: expected None{' or a rigidfem.motion profile' if info['profile'] else ''} "
                             f"({info['kind']} {'takes ' + info['profile'] if info['profile'] else 'takes none'}), "
                             f"got {profile!r}")
        if function is not None and (info["function"] is None or not callable(function)):
            raise _checks.refuse(f"function: expected None{' or a function' if info['function'] else ''} ({info['kind']} "
                             f"{'takes ' + info['function'] if info['function'] else 'takes none'}), got {function!r}")
        values = _core._Model._check_law(info["kind"], constants, profile)
        self.values = dict(zip(names, values))
        self.profile, self.function = profile, function

    @property
    def kind(self) -> str:
        return self.info["kind"]

    @property
    def constants(self) -> list[Constant]:
        """The constants with their values."""
        return [Constant(c["name"], c["unit"], c["rotation_unit"], self.values[c["name"]], c["lower"], c["positive"],
                         c["doc"], c["parameter"]) for c in self.info["constants"]]

    def __repr__(self) -> str:
        given = [f"{k}={v!r}" for k, v in self.values.items()]
        given += [f"profile={self.profile!r}"] if self.profile is not None else []
        given += [f"function={getattr(self.function, '__qualname__', self.function)!r}"] if self.function else []
        return f"{self.kind}({', '.join(given)})"

    def __eq__(self, other) -> bool:
        return (type(other) is type(self) and other.values == self.values and other.profile is self.profile
                and other.function is self.function)

    def __hash__(self) -> int:
        return hash((self.kind, tuple(self.values.items())))

    def __reduce__(self):
        return _remade, (self.kind, self.values, self.profile, self.function)


def _remade(kind: str, values: dict, profile, function) -> Law:
    return _CLASSES[kind](profile=profile, function=function, **values)


def _law_class(info: dict) -> type:
    """The class of one kind: its docstring from the description (the constants with units and bounds)."""
    lines = [info["doc"], "", "Constants (keyword arguments, their defaults):", ""]
    for c in info["constants"]:
        bound = "" if c["lower"] == -math.inf else f", {'>' if c['positive'] else '>='} {c['lower']:g}"
        bound += f", <= {c['upper']:g}" if c["upper"] < math.inf else ""
        unit = c["unit"] if c["unit"] == c["rotation_unit"] else f"{c['unit']} or {c['rotation_unit']}"
        lines.append(f"- ``{c['name']}`` = {c['default']:g} ({unit}{bound}): {c['doc']}"
                     + ("" if c["parameter"] else " (not a named parameter)"))
    if info["profile"]:
        lines += ["", f"``profile``: {info['profile']}."]
    if info["function"]:
        lines += ["", f"``function``: {info['function']} (the slow path: called under the GIL)."]
    where = {"element": "``Model.add_force_element(name, a, b, law)``",
             "coordinate": "``Model.add_joint_law(name, body, law, coordinate)``",
             "contact": "``Model.add_contact(name, a, b, law)``"}[info["acts_on"]]
    if info["addable"]:
        lines += ["", f"Added by {where}."]
    else:
        lines += ["", "Every joint coordinate's own law (its spring, damper and constant force: ``rf.Joint``, "
                      "``Model.add_generalized_force``); described here, not added."]
    cls = type(info["kind"], (Law,), {"info": info, "__doc__": "\n".join(lines), "__module__": __name__})
    cls.__qualname__ = info["kind"]
    return cls


_CLASSES = {kind: _law_class(info) for kind, info in _KINDS.items()}
globals().update(_CLASSES)

__all__ = ["Constant", "Law", "kinds", *_CLASSES]


def table() -> str:
    """The kinds and their constants as a markdown table (the site's)."""
    lines = ["| law | acts on | constant | unit | default | values | what |", "|---|---|---|---|---|---|---|"]
    for kind, info in _KINDS.items():
        for k, c in enumerate(info["constants"] or [None]):
            first = f"`{kind}`" if k == 0 else ""
            on = info["acts_on"] if k == 0 else ""
            if c is None:
                lines.append(f"| {first} | {on} | | | | | {info['function'] or ''} |")
                continue
            unit = c["unit"] if c["unit"] == c["rotation_unit"] else f"{c['unit']} or {c['rotation_unit']}"
            bound = "any" if c["lower"] == -math.inf else f"{'>' if c['positive'] else '≥'} {c['lower']:g}"
            bound += f", ≤ {c['upper']:g}" if c["upper"] < math.inf else ""
            lines.append(f"| {first} | {on} | `{c['name']}` | {unit} | {c['default']:g} | {bound} | {c['doc']} |")
    return "\n".join(lines)
