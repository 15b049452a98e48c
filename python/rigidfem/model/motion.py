"""Prescribed motions q(t) of a joint coordinate, used by ``Model.prescribe`` (and to
scale loads in time). Each returns a profile ``p`` with ``p(t) -> (q, qd, qdd)``;
units follow the coordinate (m or rad; per s; per s²). All but ``function`` are
evaluated in C++ at no Python cost.

Profiles compose, in C++ with their exact rates: ``p + r``, ``p - r``, ``p + c``, ``c * p``,
``p / c``, ``-p`` (c a number in the coordinate's units, or a factor), ``p.shifted(delay)`` (the
same motion ``delay`` s later) and ``piecewise([p0, p1, ...], breaks)`` (one after the other,
checked to join continuously). Rest-to-rest moves (``rest_to_rest``) and smooth ramps of the rate
(``ramp``) stop and start where they say, unlike a polynomial, which keeps growing after its end.

Examples
--------
>>> import rigidfem as rf
>>> p = rf.motion.rest_to_rest(0.0, 1.0, 0.0, 2.0)
>>> [round(x, 6) for x in p(1.0)]
[0.5, 0.9375, 0.0]
>>> [round(x, 6) for x in p(3.0)]
[1.0, 0.0, 0.0]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..base import _checks
import rigidfem._core as _core  # the compiled core, by its absolute name


#: The point-to-point laws s(τ) of ``rest_to_rest`` and ``ramp`` (the C++ table's).
LAWS = tuple(_core._point_to_point_laws())


def _make(maker: str, *arguments) -> _core.Profile:
    """The profile of the kind ``maker`` (``cpp/src/profiles.cpp``: its row of ``profile_kinds``, which converts and
    judges the arguments, naming the first bad one)."""
    return _core._make_profile(maker, *arguments)


def constant(value: float) -> _core.Profile:
    """q(t) = value (a locked coordinate)."""
    return _make("constant_profile", value)


def polynomial(coefficients: Sequence[float]) -> _core.Profile:
    """q(t) = c0 + c1 t + c2 t² + ... (``coefficients`` = [c0, c1, ...])."""
    return _make("polynomial_profile", coefficients)


def harmonic(amplitude: float, omega: float, phase: float = 0.0, offset: float = 0.0) -> _core.Profile:
    """q(t) = offset + amplitude · sin(omega t + phase); omega in rad/s."""
    return _make("harmonic_profile", amplitude, omega, phase, offset)


def harmonics(amplitudes: Sequence[float], omegas: Sequence[float], phases: Sequence[float] | None = None,
              offset: float = 0.0) -> _core.Profile:
    """q(t) = offset + Σ_k a_k sin(ω_k t + φ_k), a sum of harmonics with its exact rates
    q̇ = Σ a_k ω_k cos(ω_k t + φ_k) and q̈ = −Σ a_k ω_k² sin(ω_k t + φ_k).

    ``amplitudes`` a_k (units of the coordinate, m or rad), ``omegas`` ω_k (rad/s) and
    ``phases`` φ_k (rad; zeros when omitted) are 1-D sequences of one length, at least one
    component; ``offset`` c likewise in m or rad. A base motion per degree of freedom
    (``Model.add_moving_base``) and a sea state's responses (``rigidfem.sea``) are such sums.
    """
    if phases is None:
        phases = np.zeros(np.size(amplitudes)) if np.ndim(amplitudes) == 1 else amplitudes  # the maker names a bad one
    return _make("harmonic_series_profile", amplitudes, omegas, phases, offset)


def chirp(amplitude: float, f0: float, f1: float, duration: float, t0: float = 0.0) -> _core.Profile:
    """A linear sweep of ``amplitude`` (m or rad) from ``f0`` to ``f1`` (Hz) over ``duration`` T (s) from ``t0``:
    q = A sin φ, φ = 2π (f0 τ + (f1 − f0) τ²/(2T)), τ = t − t0, with its exact rates; zero before t0 (it starts at
    q = 0 with the rate 2π A f0) and going on at f1 after t0 + T. The input of a frequency response or an
    identification."""
    return _make("chirp_profile", amplitude, f0, f1, t0, duration)


def spin_up(omega: float, duration: float) -> _core.Profile:
    """Kane's spin-up of a hub to the rate ``omega`` (rad/s) over ``duration`` T (s):
    θ = (Ω/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)] for t < T, θ = Ω(t − T/2) after."""
    return _make("spin_up_profile", omega, duration)


def spline(t: Sequence[float], q: Sequence[float]) -> _core.Profile:
    """Natural cubic spline through tabulated (t, q); outside the table q continues
    linearly with the end slope."""
    return _make("spline_profile", t, q)


def rest_to_rest(start: float, end: float, t0: float, duration: float, law: str = "quintic",
                 fraction: float = 1 / 3) -> _core.Profile:
    """A move from rest at ``start`` to rest at ``end`` (m or rad) between ``t0`` and ``t0 + duration``
    (s): q = start before, q = end after, and q = start + (end − start) s(τ), τ = (t − t0)/duration, in
    between, with its exact rates q̇ = (end − start) s'(τ)/T and q̈ = (end − start) s''(τ)/T².

    ``law``:

    - ``"quintic"``: s = 10τ³ − 15τ⁴ + 6τ⁵; q̇ and q̈ zero at both ends (no jump in any force);
      peak rate 1.875 Δ/T;
    - ``"cycloidal"``: s = τ − sin(2πτ)/(2π); likewise, peak rate 2 Δ/T;
    - ``"trapezoidal"``: constant acceleration over the first and last ``fraction`` (0 < f ≤ 1/2) of
      the duration, constant rate 1/(1 − f) · Δ/T between; q̈ jumps at four instants (an adaptive
      method steps onto them). The other laws leave ``fraction`` unread.
    """
    return _make("rest_to_rest_profile", law, start, end, t0, duration, fraction)


def ramp(rate: float, t0: float, duration: float, law: str = "cycloidal", start: float = 0.0,
         fraction: float = 1 / 3) -> _core.Profile:
    """A smooth start of a constant rate: q̇ = rate · s(τ) rises from 0 at ``t0`` to ``rate`` (m/s or
    rad/s) at ``t0 + duration`` by the rest-to-rest ``law`` s (see ``rest_to_rest``), then stays; q =
    start + rate · T · S(τ) with S(τ) = ∫₀^τ s, and q = start + rate (t − t0 − T/2) after the ramp. A winch
    paying out a rope, a hub spun up (``law="cycloidal"`` is Kane's ``spin_up`` from ``t0``)."""
    return _make("ramp_profile", law, rate, t0, duration, start, fraction)


def piecewise(pieces: Sequence[_core.Profile], breaks: Sequence[float], continuity: int = 1) -> _core.Profile:
    """The profiles ``pieces`` one after the other: piece k holds on [breaks[k−1], breaks[k]) (the first
    from −∞, the last on to +∞), each evaluated at the time t itself (``p.shifted(delay)`` starts one
    later). ``breaks`` (s) has one time fewer than ``pieces``, increasing.

    At every break the two pieces must meet — in q (``continuity=0``), in q and q̇ (1, the default:
    a drive without a jump of velocity), or in q, q̇ and q̈ (2) — to 1e-9 (1 + |x|); otherwise a
    ValueError names the break and the jump."""
    return _make("piecewise_profile", pieces, breaks, continuity)


def function(f: Callable[[float], tuple[float, float, float]]) -> _core.Profile:
    """A Python function ``f(t) -> (q, qd, qdd)``. Slow path: Python is called at every
    evaluation, under the GIL.

    ``f`` must return three finite real numbers: anything else (strings, None, NaN, inf, another
    shape) raises ``rigidfem.ForceLawError`` naming the drive, what it returned and the time: a
    ValueError (whose message starts with ``f:``) where a System method evaluates the drive, and a
    ``SimulationError`` with ``time`` and ``cause``. Exceptions ``f`` raises propagate."""
    if not callable(f):
        raise _checks.refuse(f"f: expected a callable f(t) -> (q, qd, qdd), got {f!r}")
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
