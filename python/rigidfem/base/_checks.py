"""The Python layer's one converter: arguments as the types the core takes, ValueErrors naming the argument.

What counts as a real number or an array of them is the C++ bindings' rule (``bindings.hpp``:
``real_arg``, ``real_array_arg``, reached as ``_core._real`` and ``_core._real_array``), the one
conversion rule of the package. ``real`` and ``reals`` convert only: the values of what goes to the core
are judged there, once (the makers, ``check_options``, the laws' bounds). The other functions also judge
the values (finite, positive) of what the Python layer alone uses (a sweep's workers, a plot's scale, a
material before it becomes springs). Every refusal the Python layer makes is ``raise _checks.refuse(
"<argument>: expected <what>, got <value>")``, the form the core's refusals have (``errors.hpp``: ``bad``);
``tests/test_conventions.py`` holds every such message to it, and no module raises a ValueError of its own.
"""

from __future__ import annotations

import math

import numpy as np

import rigidfem._core as _core  # the compiled core, by its absolute name
from .._core import Body, Point


def refuse(message: str) -> ValueError:
    """The ValueError of a refusal by the Python layer: ``message`` is "<argument>: expected <what>, got
    <value>" (or "<a>, <b>: expected ..." for arguments judged together). Raised by the caller (``raise
    _checks.refuse(...)``, so that its traceback ends where the argument was judged)."""
    return ValueError(message)


def _floats(x, name: str, expected: str) -> np.ndarray:
    """``x`` as a float array by the bindings' rule: complex numbers (numpy would drop their imaginary
    parts), strings (numpy would parse them), None and whatever else is not a number are refused."""
    return _core._real_array(x, name, expected)


def _short(x) -> str:
    s = repr(x)
    return s if len(s) <= 200 else s[:197] + "..."


def real(x, name: str, expected: str = "a number") -> float:
    """``x`` as a float by the bindings' rule (not a string, bool, complex number or array); its value is the
    core's to judge."""
    return _core._real(x, name, expected)


def reals(x, shape: tuple[int, ...], name: str) -> np.ndarray:
    """``x`` as a float array of exactly ``shape`` (real numbers); its values are the core's to judge."""
    a = _floats(x, name, f"numbers of shape {shape}")
    if a.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
    return a


def array(x, shape: tuple[int, ...], name: str) -> np.ndarray:
    """``x`` as a finite float array of exactly ``shape`` (real numbers: complex ones are refused)."""
    a = _floats(x, name, f"numbers of shape {shape}")
    if a.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected finite values, got NaN or inf")
    return a


def vector(x, name: str, min_length: int = 0) -> np.ndarray:
    """``x`` as a finite 1-D float array of at least ``min_length`` values (real numbers)."""
    a = _floats(x, name, "a 1-D sequence of real numbers")
    if a.ndim != 1 or a.size < min_length:
        raise ValueError(f"{name}: expected a 1-D sequence of at least {min_length} numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected finite values, got NaN or inf")
    return a


def vec3(x, name: str) -> np.ndarray:
    return array(x, (3,), name)


def scalar(x, name: str, *, positive: bool = False, nonnegative: bool = False, unit: str = "") -> float:
    """``x`` as a finite float: a real number (not a string, not a bool), positive or non-negative
    if asked; ``unit`` goes into the messages."""
    expected = ("positive " if positive else "non-negative " if nonnegative else "") + "number" + \
        (f" in {unit}" if unit else "")
    v = _core._real(x, name, f"a {expected}")
    if not math.isfinite(v):
        raise ValueError(f"{name}: expected a finite {expected}, got {v}")
    if (positive and not v > 0.0) or (nonnegative and not v >= 0.0):
        raise ValueError(f"{name}: expected a {expected}, got {v}")
    return v


def system(x, name: str = "system"):
    """``x`` if it is a compiled System; a ValueError saying what to do otherwise (a Model: compile it)."""
    if isinstance(x, _core._System):
        return x
    got = "a Model" if isinstance(x, _core._Model) else _short(x)
    raise ValueError(f"{name}: expected a compiled System (call model.compile()), got {got}")


def result(x, name: str = "result", needs: str | None = None):
    """``x`` if it is a Result (``rigidfem.simulate``'s: times, states and the system they are of); ``needs``
    names what the caller computes from the system, refused for a result loaded without it."""
    if not all(hasattr(x, a) for a in ("t", "q", "qd", "system", "stats", "sensitivities")):
        raise ValueError(f"{name}: expected a Result (what rigidfem.simulate returns), got {_short(x)}")
    if needs is not None and x.system is None:
        raise ValueError(f"{name}: expected a Result with its System for {needs}, got one loaded without it "
                         "(rigidfem.load_npz(path, system) gives it)")
    return x


def pose_time(system, t) -> float:
    """The time (s) of a pose of ``system``: ``t``, or 0 when omitted, which only a system without
    prescribed coordinates allows (their drives make the pose depend on t)."""
    if t is not None:
        return t
    if system.np:
        names = system.prescribed_names
        listed = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
        raise ValueError(f"t: required because the system has prescribed coordinates ({listed}) whose drives "
                         "make the pose depend on time; pass t in s")
    return 0.0


def same_model(handle, system, name: str, expected: str = "a Point or Body of the model this system was compiled "
                                                          "from") -> None:
    """Raise ValueError if the Body or Point ``handle`` was made by another model than the one
    ``system`` was compiled from (handles and systems of unknown origin pass)."""
    if isinstance(handle, (Body, Point)):
        own = getattr(system, "_model_id", 0)  # 0: a system made without Model.compile
        if handle.model and own and handle.model != own:
            raise ValueError(f"{name}: expected {expected}, got {handle!r} of another model")


def per_coordinate(x, n: int, name: str, *, nonnegative: bool = False) -> list[float]:
    """A scalar (same for every coordinate) or a sequence of ``n`` values."""
    if np.ndim(x) == 0:
        return [scalar(x, name, nonnegative=nonnegative)] * n
    if np.ndim(x) != 1:
        raise ValueError(f"{name}: expected a number or a 1-D sequence of {n} values, got shape {np.shape(x)}")
    values = list(x)
    if len(values) != n:
        raise ValueError(f"{name}: expected a number or {n} values (one per joint coordinate), got {len(values)}")
    return [scalar(v, name, nonnegative=nonnegative) for v in values]


def integer(x, name: str, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """``x`` as an int (an integral real number by the bindings' rule, not a bool) within [minimum, maximum]."""
    v = _core._real(x, name, "an integer")
    within = (f" in [{minimum}, {maximum}]" if minimum is not None and maximum is not None else
              f" >= {minimum}" if minimum is not None else f" <= {maximum}" if maximum is not None else "")
    if not math.isfinite(v) or v != int(v):
        raise ValueError(f"{name}: expected an integer{within}, got {_short(x)}")
    v = int(x) if isinstance(x, (int, np.integer)) else int(v)
    if (minimum is not None and v < minimum) or (maximum is not None and v > maximum):
        raise ValueError(f"{name}: expected an integer{within}, got {v}")
    return v


def boolean(x, name: str) -> bool:
    """``x`` as a bool: True, False (or numpy's bools)."""
    if not isinstance(x, (bool, np.bool_)):
        raise ValueError(f"{name}: expected True or False, got {x!r}")
    return bool(x)


def path(x, name: str = "path"):
    """``x`` if it is a file path: a non-empty str or an ``os.PathLike`` (``pathlib.Path``); None, numbers, bytes
    and open files are refused (a ValueError naming ``name``, where ``open`` would raise a TypeError)."""
    import os

    if isinstance(x, os.PathLike) or (isinstance(x, str) and x):
        return x
    raise ValueError(f"{name}: expected a file path (str or os.PathLike), got {_short(x)}")


def name(x, what: str = "name") -> str:
    """``x`` as the name of what a builder adds: a non-empty str (numbers, None and handles are refused, not
    converted). Whether it is new is judged where the names are kept."""
    if isinstance(x, str) and x:
        return x
    raise ValueError(f"{what}: expected a non-empty str, got {_short(x)}")
