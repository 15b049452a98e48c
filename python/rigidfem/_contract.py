"""The calling contract of the compiled methods: a wrong type or shape gets a ValueError naming
the argument and what it expects, not pybind11's "incompatible function arguments" TypeError.

The compiled methods convert their arguments themselves (no Python on the fast path); only when
that conversion fails does the guard look at the arguments, in plain Python, to say which one is
wrong. A wrong number of arguments stays a TypeError, as Python's convention wants.
"""

from __future__ import annotations

import functools

import numpy as np

from . import _checks, _core, _deprecation
from ._core import SimulationError, _System

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

def compiled_parameters(function) -> tuple[tuple[str, bool], ...]:
    """(name, has a default) of each parameter of a pybind11 function, read from the signature line that
    pybind11 writes first in its docstring (``name(self: ..., t: float = 0.0, ...) -> ...``): the one
    place the parameters are written is the binding's ``py::arg`` list."""
    line = function.__doc__.splitlines()[0]
    inside = line[line.index("(") + 1:line.rindex(") ->")]
    parts, depth, quoted, start = [], 0, False, 0
    for i, c in enumerate(inside + ","):
        if c == '"':
            quoted = not quoted
        elif not quoted and c in "[(":
            depth += 1
        elif not quoted and c in "])":
            depth -= 1
        elif not quoted and depth == 0 and c == ",":
            parts.append(inside[start:i].strip())
            start = i + 1
    return tuple((part.split(":")[0].strip(), " = " in part) for part in parts)


#: The System methods the guard wraps.
GUARDED = ("forward_dynamics", "mass_matrix", "generalized_forces", "static_forces", "force_jacobians",
           "driving_forces", "rhs", "jacobian", "inverse_dynamics", "inverse_dynamics_derivatives",
           "acceleration_derivatives", "kinetic_energy", "gravity_energy", "elastic_energy", "potential_energy",
           "dissipated_power", "_position", "_positions", "_velocity", "loop_constraints", "loop_multipliers",
           "loop_reactions", "element_states")

_PARAMETERS = {name: compiled_parameters(getattr(_System, name))[1:] for name in GUARDED}  # without self

#: The parameters of each guarded method, in order (the compiled signature without self).
SIGNATURES = {name: tuple(p for p, _ in parameters) for name, parameters in _PARAMETERS.items()}

#: The parameters that take vectors of real numbers, and how many per free coordinate.
VECTORS = {"q": 1, "qd": 1, "qdd": 1, "y": 2}

#: The state's parameters of version 0.1's methods that took t last (optional: 0 without prescribed
#: coordinates), now t first: such calls are reordered with a DeprecationWarning (``_deprecation``).
OLD_ORDERS = {"mass_matrix": ("q", "t"), "kinetic_energy": ("q", "qd", "t"), "gravity_energy": ("q", "t"),
              "elastic_energy": ("q", "t"), "potential_energy": ("q", "t"), "dissipated_power": ("q", "qd", "t")}

#: Vectors the compiled method ignores when a flag is set (it does not check them then): checked here.
UNREAD = {"force_jacobians": ("qd", "static")}

_MISSING = object()


def _real_number(value) -> float | None:
    """``value`` as a float if it is a real number by the bindings' rule (``_core._real``: not a bool,
    string, None, complex number or array), else None."""
    try:
        return _core._real(value, "", "")
    except ValueError:
        return None


def _real_vector(value) -> tuple[np.ndarray | None, str | None]:
    """``value`` as a 1-D float array by the bindings' rule (``_core._real_array``: real numbers, also
    booleans and Python ints beyond int64), or None and what is wrong with it: complex values (numpy
    would drop their imaginary parts), strings, other objects, another shape (a (1, n) or (n, 1) array
    would be taken for a vector). Its size is not looked at."""
    try:
        a = _core._real_array(value, "", "")
    except ValueError as e:
        return None, "complex values (expected real numbers)" if "complex values" in str(e) else f"{value!r}"
    if a.ndim != 1:
        return None, f"shape {a.shape}"
    return a, None


def _problem(name: str, value, system) -> str | None:
    """Why ``value`` cannot be the argument ``name`` (None if it could): "bad", or what is wrong."""
    from ._core import Body, Data, Point

    nq = getattr(system, "nq", 0)
    if name in ("t", "load_factor"):
        v = _real_number(value)
        return None if v is not None and np.isfinite(v) else "bad"
    if name in VECTORS:
        n = VECTORS[name] * nq
        a, problem = _real_vector(value)
        if problem:
            return problem + (f" (expected shape ({n},))" if problem.startswith("shape") else "")
        if a.shape != (n,):
            return f"shape {a.shape} (expected shape ({n},))"
        try:
            with np.errstate(over="ignore"):
                finite = np.all(np.isfinite(a.astype(float)))
        except (OverflowError, TypeError, ValueError):  # a Python int beyond the range of floats
            finite = False
        return None if finite else "NaN or inf"
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
        problem = _problem(name, given[name], system) if name in given else None
        if problem:
            expected = _EXPECTED[name].format(nq=nq, nq2=2 * nq)
            got = repr(given[name]) if problem == "bad" else problem
            return ValueError(f"{name}: expected {expected}, got {got}"[:400])
    missing = [p for p in parameters if p not in given]
    if missing:
        return TypeError(f"{function}() missing the arguments {missing}")
    expected = "; ".join(f"{p}: {_EXPECTED[p].format(nq=nq, nq2=2 * nq)}" for p in parameters)
    return ValueError(f"{parameters[0]}: expected {expected}, got {given!r}"[:400])


def _refuse(function: str, parameters: tuple, name: str, value, args: tuple, kwargs: dict) -> ValueError:
    """The ValueError for the argument ``name`` that the compiled conversion would take wrongly."""
    return explain(function, parameters, (), {name: value}, args[0] if args else kwargs.get("system"))


def guard(function: str, compiled, parameters: tuple, method: bool = True):
    """``compiled`` with its conversion failures explained (see ``explain``): a method of System
    (``method``: the system is self), or a function whose first parameter is the system.

    What the compiled conversion would take wrongly is refused before the call: booleans for t and
    load_factor (they convert to 0 and 1), numpy's complex scalars for them (their imaginary part
    dropped), vectors of complex numbers and (1, n) or (n, 1) arrays for q, qd, qdd and y, anything
    but True or False for ``static``, and the vector ``UNREAD`` would leave unchecked. Calls in the order of
    ``OLD_ORDERS`` are reordered, with a DeprecationWarning."""
    offset = 1 if method else 0
    old_order = OLD_ORDERS.get(function) if method else None
    # (position in args, name, kind): 0 a number, 1 a vector, 2 a flag
    checks = [(k + offset, p, 0 if p in ("t", "load_factor") else 1 if p in VECTORS else 2)
              for k, p in enumerate(parameters) if p in ("t", "load_factor", "static") or p in VECTORS]
    unread = UNREAD.get(function)
    if unread:
        unread_at = (parameters.index(unread[0]) + offset, unread[0], parameters.index(unread[1]) + offset, unread[1])
    ndarray = np.ndarray

    @functools.wraps(compiled)
    def call(*args, **kwargs):
        if old_order is not None and args:
            def default_time():  # a bad vector is named before the missing t
                given = dict(zip(old_order, args[1:])) | kwargs
                for p in old_order:
                    if p in VECTORS and p in given and _problem(p, given[p], args[0]):
                        raise _refuse(function, parameters, p, given[p], args, {})
                return _checks.pose_time(args[0], None)

            state, kwargs = _deprecation.time_first(function, old_order, parameters, args[1:], kwargs, default_time,
                                                    nq=getattr(args[0], "nq", None))
            args = args[:1] + state
        n = len(args)
        converted = None
        for k, p, kind in checks:
            v = args[k] if k < n else kwargs.get(p, _MISSING)
            if kind == 1:
                if v.__class__ is ndarray and v.ndim == 1 and v.dtype.kind in "fiu":
                    continue  # the fast path
                if v is _MISSING:
                    continue
                a, problem = _real_vector(v)
                if problem is None:
                    if a is not v and a.dtype.kind in "fiu":  # converted once here, not again by the call
                        if converted is None:
                            converted = list(args), dict(kwargs)
                        if k < n:
                            converted[0][k] = a
                        else:
                            converted[1][p] = a
                    continue
                if v is None or isinstance(v, (str, bytes, dict)):
                    continue  # the compiled conversion refuses it; explain() names it
                raise _refuse(function, parameters, p, v, args, kwargs)
            elif kind == 0:
                if v.__class__ is float or v is _MISSING:
                    continue
                if isinstance(v, (bool, np.bool_, np.complexfloating)):
                    raise _refuse(function, parameters, p, v, args, kwargs)
            elif not (v is True or v is False or v is _MISSING or isinstance(v, np.bool_)):
                raise _refuse(function, parameters, p, v, args, kwargs)
        if unread:
            k, p, j, flag = unread_at
            f = args[j] if j < n else kwargs.get(flag, False)
            if f is True or (isinstance(f, np.bool_) and f):
                v = args[k] if k < n else kwargs.get(p, _MISSING)
                if v is not _MISSING and _problem(p, v, args[0] if args else kwargs.get("system")):
                    raise _refuse(function, parameters, p, v, args, kwargs)
        if converted is not None:
            args, kwargs = tuple(converted[0]), converted[1]
        try:
            return _finite(function, compiled(*args, **kwargs), parameters, args[1:] if method else args, kwargs)
        except TypeError as e:
            if "incompatible function arguments" not in str(e):
                raise
            system = args[0] if args else kwargs.get("system")
            raise explain(function, parameters, args[1:] if method else args, kwargs, system) from None
        except SimulationError:
            # a numerical failure met before the compiled code checked every argument (a drive
            # evaluated at a huge t before the size of qdd was looked at): name a bad argument instead
            system = args[0] if args else kwargs.get("system")
            given = dict(zip(parameters, args[1:] if method else args)) | kwargs
            for name in parameters:
                if name in VECTORS and name in given and _problem(name, given[name], system):
                    raise _refuse(function, parameters, name, given[name], args, kwargs) from None
            raise

    return call


def _finite(function: str, result, parameters: tuple, args: tuple, kwargs: dict):
    """``result`` unless it holds NaN or inf, which finite inputs (checked by the compiled call) can only
    give by overflowing the range of doubles: then a SimulationError naming the call, its time and the
    largest input."""
    values = result if isinstance(result, tuple) else (result,)
    if all(not isinstance(v, (np.ndarray, float)) or np.all(np.isfinite(v)) for v in values):
        return result
    given = dict(zip(parameters, args)) | kwargs
    t = given.get("t", 0.0)
    t = _real_number(t)
    t = 0.0 if t is None else t
    sizes = ", ".join(f"largest |{p}| = {np.max(np.abs(np.asarray(given[p], dtype=float))):.3g}"
                      for p in parameters if p in VECTORS and p in given and np.size(given[p]))
    error = SimulationError(f"at t = {t:.10g} s: {function}() overflowed: finite inputs ({sizes}) gave NaN or inf, "
                            "beyond the range of doubles")
    error.time, error.cause = t, f"{function}() overflowed"
    raise error


def guard_methods(cls) -> None:
    """Guards every compiled method of ``cls`` listed in ``SIGNATURES`` that ``cls`` inherits."""
    for name, parameters in SIGNATURES.items():
        if name not in cls.__dict__ and hasattr(cls, name):
            setattr(cls, name, guard(name, getattr(cls, name), parameters))
