"""Prescribed motions q(t) of a joint coordinate, used by ``Model.prescribe`` (and to
scale loads in time). Each returns a profile ``p`` with ``p(t) -> (q, qd, qdd)``;
units follow the coordinate (m or rad; per s; per s²). All but ``function`` are
evaluated in C++ at no Python cost.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from . import _checks, _core


def constant(value: float) -> _core.Profile:
    """q(t) = value (a locked coordinate)."""
    return _core.constant_profile(_checks.scalar(value, "value"))


def polynomial(coefficients: Sequence[float]) -> _core.Profile:
    """q(t) = c0 + c1 t + c2 t² + ... (``coefficients`` = [c0, c1, ...])."""
    return _core.polynomial_profile(list(_checks.vector(coefficients, "coefficients")))


def harmonic(amplitude: float, omega: float, phase: float = 0.0, offset: float = 0.0) -> _core.Profile:
    """q(t) = offset + amplitude · sin(omega t + phase); omega in rad/s."""
    return _core.harmonic_profile(_checks.scalar(amplitude, "amplitude"), _checks.scalar(omega, "omega"),
                                  _checks.scalar(phase, "phase"), _checks.scalar(offset, "offset"))


def harmonics(amplitudes: Sequence[float], omegas: Sequence[float], phases: Sequence[float] | None = None,
              offset: float = 0.0) -> _core.Profile:
    """q(t) = offset + Σ_k a_k sin(ω_k t + φ_k), a sum of harmonics with its exact rates
    q̇ = Σ a_k ω_k cos(ω_k t + φ_k) and q̈ = −Σ a_k ω_k² sin(ω_k t + φ_k).

    ``amplitudes`` a_k (units of the coordinate, m or rad), ``omegas`` ω_k (rad/s) and
    ``phases`` φ_k (rad; zeros when omitted) are 1-D sequences of one length, at least one
    component; ``offset`` c likewise in m or rad. A base motion per degree of freedom
    (``Model.add_moving_base``) and a sea state's responses (``rigidfem.sea``) are such sums.
    """
    a = _checks.vector(amplitudes, "amplitudes", min_length=1)
    w = _checks.vector(omegas, "omegas")
    phi = np.zeros_like(a) if phases is None else _checks.vector(phases, "phases")
    for values, name in ((w, "omegas"), (phi, "phases")):
        if values.size != a.size:
            raise ValueError(f"{name}: expected {a.size} values (len(amplitudes)), got {values.size}")
    return _core.harmonic_series_profile(list(a), list(w), list(phi), _checks.scalar(offset, "offset"))


def spin_up(omega: float, duration: float) -> _core.Profile:
    """Kane's spin-up of a hub to the rate ``omega`` (rad/s) over ``duration`` T (s):
    θ = (Ω/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)] for t < T, θ = Ω(t − T/2) after."""
    return _core.spin_up_profile(_checks.scalar(omega, "omega"), _checks.scalar(duration, "duration"))


def spline(t: Sequence[float], q: Sequence[float]) -> _core.Profile:
    """Natural cubic spline through tabulated (t, q); outside the table q continues
    linearly with the end slope."""
    return _core.spline_profile(list(_checks.vector(t, "t")), list(_checks.vector(q, "q")))


def function(f: Callable[[float], tuple[float, float, float]]) -> _core.Profile:
    """A Python function ``f(t) -> (q, qd, qdd)``. Slow path: Python is called at every
    evaluation, under the GIL.

    ``f`` must return three finite real numbers: anything else (strings, None, NaN, inf, another
    shape) raises ``rigidfem.ForceLawError`` naming the drive, what it returned and the time: a
    ValueError (whose message starts with ``f:``) where a System method evaluates the drive, and a
    ``SimulationError`` with ``time`` and ``cause``. Exceptions ``f`` raises propagate."""
    if not callable(f):
        raise ValueError(f"f: expected a callable f(t) -> (q, qd, qdd), got {f!r}")
    name = getattr(f, "__qualname__", None) or repr(f)

    def checked(t):
        value = f(t)
        try:
            numbers = None if isinstance(value, (str, bytes)) or np.shape(value) != (3,) else \
                tuple(_checks.scalar(v, "f") for v in value)
        except ValueError:  # an entry that is not a finite real number
            numbers = None
        if numbers is None:
            got = repr(value)
            got = got if len(got) <= 120 else got[:117] + "..."
            cause = f"the drive '{name}' returned {got}; expected three finite numbers (q, qd, qdd)"
            error = _core.ForceLawError(f"f: expected the drive '{name}' to return three finite numbers (q, qd, qdd), "
                                        f"got {got} at t = {t:.10g} s")
            error.time, error.cause = float(t), cause
            raise error
        return numbers

    profile = _core.callback_profile(checked)
    profile.function = f  # pickled as rigidfem.motion.function(f): f must pickle (a module-level function)
    return profile
