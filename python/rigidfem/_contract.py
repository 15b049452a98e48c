"""The calling contract of the compiled methods: a wrong type or shape gets a ValueError naming
the argument and what it expects, not pybind11's "incompatible function arguments" TypeError.

The compiled methods convert their arguments themselves (no Python on the fast path); only when
that conversion fails does the guard look at the arguments, in plain Python, to say which one is
wrong. A wrong number of arguments stays a TypeError, as Python's convention wants.
"""

from __future__ import annotations

import functools

import numpy as np

#: What each argument of the compiled methods expects, by name; sizes in terms of the system.
_EXPECTED = {
    "t": "a finite time in s",
    "q": "an array of nq = {nq} coordinates (m, rad)",
    "qd": "an array of nq = {nq} rates (m/s, rad/s)",
    "qdd": "an array of nq = {nq} accelerations (m/s², rad/s²)",
    "y": "an array of 2 nq = {nq2} values [q, qd]",
    "load_factor": "a finite number",
    "static": "True or False",
    "body": "a Body of this system or its index",
    "point": "a Point or Body of this system",
    "points": "a list of Points of this system",
    "data": "a workspace from system.make_data()",
    "system": "a System from Model.compile()",
}

#: The parameters of each guarded method, in order (the compiled signature without self).
SIGNATURES = {
    "forward_dynamics": ("t", "q", "qd"),
    "mass_matrix": ("q", "t"),
    "generalized_forces": ("t", "q", "qd", "load_factor"),
    "static_forces": ("t", "q", "load_factor"),
    "force_jacobians": ("t", "q", "qd", "load_factor", "static"),
    "driving_forces": ("t", "q", "qd"),
    "rhs": ("t", "y"),
    "jacobian": ("t", "y"),
    "inverse_dynamics": ("t", "q", "qd", "qdd"),
    "inverse_dynamics_derivatives": ("t", "q", "qd", "qdd"),
    "acceleration_derivatives": ("t", "q", "qd"),
    "kinetic_energy": ("q", "qd", "t"),
    "gravity_energy": ("q", "t"),
    "elastic_energy": ("q", "t"),
    "potential_energy": ("q", "t"),
    "dissipated_power": ("q", "qd", "t"),
    "_position": ("point", "q", "t"),
    "_positions": ("points", "q", "t"),
    "_velocity": ("point", "q", "qd", "t"),
}


def _numeric(value) -> bool:
    """Numbers or an array of them (not strings, not booleans, not None)."""
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        return False
    return kind in "iuf"


def _problem(name: str, value, system) -> str | None:
    """Why ``value`` cannot be the argument ``name`` (None if it could)."""
    from ._core import Body, Data, Point

    nq = getattr(system, "nq", 0)
    if name in ("t", "load_factor"):
        return None if _numeric(value) and np.ndim(value) == 0 and np.isfinite(value) else "bad"
    if name in ("q", "qd", "qdd", "y"):
        n = 2 * nq if name == "y" else nq
        return None if _numeric(value) and np.shape(value) == (n,) and np.all(np.isfinite(value)) else "bad"
    if name == "static":
        return None if isinstance(value, (bool, np.bool_)) else "bad"
    if name == "body":
        return None if isinstance(value, (Body, int, np.integer)) and not isinstance(value, bool) else "bad"
    if name == "point":
        return None if isinstance(value, (Point, Body)) else "bad"
    if name == "points":
        return None if isinstance(value, (list, tuple)) and all(isinstance(p, (Point, Body)) for p in value) else "bad"
    if name == "data":
        return None if isinstance(value, Data) else "bad"
    if name == "system":
        from ._core import _System

        return None if isinstance(value, _System) else "bad"
    return None


def explain(function: str, parameters: tuple, args: tuple, kwargs: dict, system) -> Exception:
    """The exception for a call of ``function(*args, **kwargs)`` whose compiled conversion failed:
    TypeError for a wrong number of arguments or an unknown keyword, else a ValueError naming the
    first argument of the wrong type or shape."""
    required = len(parameters)
    unknown = set(kwargs) - set(parameters)
    if unknown or len(args) > required:
        return TypeError(f"{function}() takes the arguments ({', '.join(parameters)}), got "
                         f"{len(args)} positional and the keywords {sorted(kwargs)}")
    given = dict(zip(parameters, args)) | kwargs
    nq = getattr(system, "nq", 0)
    for name in parameters:
        if name in given and _problem(name, given[name], system):
            expected = _EXPECTED[name].format(nq=nq, nq2=2 * nq)
            return ValueError(f"{name}: expected {expected}, got {given[name]!r}"[:400])
    missing = [p for p in parameters if p not in given]
    if missing:
        return TypeError(f"{function}() missing the arguments {missing}")
    expected = "; ".join(f"{p}: {_EXPECTED[p].format(nq=nq, nq2=2 * nq)}" for p in parameters)
    return ValueError(f"{parameters[0]}: expected {expected}, got {given!r}"[:400])


def guard(function: str, compiled, parameters: tuple, method: bool = True):
    """``compiled`` with its conversion failures explained (see ``explain``): a method of System
    (``method``: the system is self), or a function whose first parameter is the system."""

    # Booleans convert to 0 and 1 in the compiled call: refused for times and load factors.
    numbers = [(k + (1 if method else 0), p) for k, p in enumerate(parameters) if p in ("t", "load_factor")]

    @functools.wraps(compiled)
    def call(*args, **kwargs):
        for k, p in numbers:
            v = args[k] if k < len(args) else kwargs.get(p)
            if isinstance(v, (bool, np.bool_)):
                system = args[0] if args else kwargs.get("system")
                raise explain(function, parameters, (), {p: v}, system)
        try:
            return compiled(*args, **kwargs)
        except TypeError as e:
            if "incompatible function arguments" not in str(e):
                raise
            system = args[0] if args else kwargs.get("system")
            raise explain(function, parameters, args[1:] if method else args, kwargs, system) from None

    return call


def guard_methods(cls) -> None:
    """Guards every compiled method of ``cls`` listed in ``SIGNATURES`` that ``cls`` inherits."""
    for name, parameters in SIGNATURES.items():
        if name not in cls.__dict__ and hasattr(cls, name):
            setattr(cls, name, guard(name, getattr(cls, name), parameters))
