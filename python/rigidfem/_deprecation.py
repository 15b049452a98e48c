"""The argument orders of version 0.1, kept working for one more release with a DeprecationWarning
that shows the new call.

The convention (docs/conventions.md): a state is passed as (t, q, qd, qdd), t first, as in SciPy's
``rhs(t, y)``, in every method that evaluates the system at a state; after the object it is about
where there is one (``position(point, t, q)``). Functions about an operating point whose t has a
default (``assemble``, ``modal_analysis``, ``linearize``, ``static_equilibrium``, ``centerline``,
``shape``) take t by keyword only. ``simulate`` takes its integrator options by keyword.
"""

from __future__ import annotations

import functools
import inspect
import warnings

import numpy as np


#: The default of a parameter that only the old orders may leave out (``required`` hides it).
MISSING = object()


def _warn(message: str) -> None:
    warnings.warn(message, DeprecationWarning, stacklevel=4)


def is_state_vector(value) -> bool:
    """Whether ``value`` is a vector (q of the old order), not a time: an array-like of one dimension."""
    if isinstance(value, (str, bytes)):
        return False
    try:
        return np.ndim(value) >= 1
    except Exception:  # noqa: BLE001 -- a ragged sequence: a (bad) vector, named by the checks that follow
        return True


def time_first(name: str, old: tuple, new: tuple, args: tuple, kwargs: dict, default_time, lead: str = "",
               nq: int | None = None):
    """(args, kwargs) of a call of ``name`` in the order ``new`` (t first) when it was made in the order
    ``old`` of version 0.1 (the state first, t last and optional), with a DeprecationWarning: recognised
    by a vector where t now comes, or by q given by keyword without t. ``default_time()`` gives t when the
    old call left it out (0 without prescribed coordinates, else its ValueError). ``args`` and
    ``kwargs`` hold the state's arguments only (``lead``: how the message shows the ones before them);
    calls in the new order are returned as they are. A call reads as the old order only where it could
    be one: its first argument a vector of ``nq`` values (when given) and no vector where the old order has
    t, so that a bad t of the new order is named as t."""
    first_is_vector = bool(args) and is_state_vector(args[0])
    if first_is_vector and nq is not None and np.size(args[0]) != nq:
        first_is_vector = False
    if first_is_vector and "t" in old:
        k = old.index("t")
        t_old = args[k] if len(args) > k else kwargs.get("t")
        if t_old is not None and is_state_vector(t_old):
            first_is_vector = False
    if not (first_is_vector or (not args and "t" not in kwargs and "q" in kwargs)):
        return args, kwargs
    _warn(f"{name}({lead}{', '.join(old)}) is deprecated: call {name}({lead}{', '.join(new)}), t first as in "
          "forward_dynamics and SciPy's rhs(t, y)")
    values = dict(zip(old, args)) | kwargs
    if values.get("t") is None:
        values["t"] = default_time()
    return tuple(values[p] for p in new if p in values), {}


def keyword_only(*old_positional: str):
    """Decorator: the parameters ``old_positional`` (keyword-only now) may still be passed by position,
    after the positional ones, with a DeprecationWarning."""

    def wrap(function):
        signature = inspect.signature(function)
        positional = sum(p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) for p in signature.parameters.values())

        @functools.wraps(function)
        def call(*args, **kwargs):
            if len(args) > positional:
                extra = args[positional:]
                if len(extra) > len(old_positional):
                    raise TypeError(f"{function.__name__}() takes {positional} positional arguments but "
                                    f"{len(args)} were given")
                names = old_positional[:len(extra)]
                twice = sorted(set(names) & set(kwargs))
                if twice:
                    raise TypeError(f"{function.__name__}() got multiple values for {twice}")
                _warn(f"{function.__name__}: passing {', '.join(names)} by position is deprecated; pass "
                      f"{' and '.join(f'{n}=' for n in names)} by keyword")
                kwargs.update(zip(names, extra))
                args = args[:positional]
            return function(*args, **kwargs)

        return call

    return wrap


def required(*names: str):
    """Decorator: the signature shown (``inspect.signature``, help, the docs) has the parameters ``names``
    without their defaults, which only let the old orders reach ``time_first``."""

    def wrap(function):
        signature = inspect.signature(function)
        function.__signature__ = signature.replace(parameters=[
            p.replace(default=inspect.Parameter.empty) if p.name in names else p
            for p in signature.parameters.values()])
        return function

    return wrap
