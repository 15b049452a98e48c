"""Sea states for a moving base (``Model.add_moving_base``): the JONSWAP wave spectrum,
its discretisation into harmonic components with seeded random phases, and response
amplitude operators (RAOs) that turn the wave elevation into a vessel's six motions.

Conventions (SI; angles in rad):

- the wave elevation at the vessel's reference point is η(t) = Σ_k a_k sin(ω_k t + φ_k) (m);
- an RAO is the complex transfer function H(ω) from η to one motion, whose response is
  x(t) = Σ_k |H(ω_k)| a_k sin(ω_k t + φ_k + arg H(ω_k)). |H| is in m/m for surge, sway and
  heave and in rad/m for roll, pitch and yaw (convert tables in deg/m with ``np.radians``);
  arg H is in rad, positive when the motion leads the elevation. RAOs are those of one wave
  heading: the sea state is long-crested.

For example (``model`` a ``rigidfem.Model``)::

    waves = rf.sea.jonswap_waves(hs=2.0, tp=8.0, n=200, seed=1)
    deck = model.add_moving_base("deck", waves.motion({"heave": rf.sea.RAO.oscillator(6.0, 0.1),
                                                         "roll": np.radians(2.0)}))

Examples
--------
>>> import rigidfem as rf
>>> waves = rf.sea.jonswap_waves(hs=2.0, tp=8.0, n=50, seed=1)
>>> type(waves).__name__, len(waves.amplitude), round(4 * waves.m0 ** 0.5, 2)
('Waves', 50, 2.0)
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..base import _checks
from . import motion
from .._core import Profile
from .model import BASE_DOFS

GAMMA_RANGE = (1.0, 7.0)  # peak enhancement factors for which DNV-RP-C205's A_γ holds
MAX_COMPONENTS = 1_000_000  # the most components of jonswap_waves (n)


def _finite(x, name: str) -> np.ndarray:
    """``x`` as finite real frequencies (rad/s) by the bindings' rule: strings and complex numbers refused."""
    a = _checks._floats(x, name, "real numbers in rad/s")
    if not np.all(np.isfinite(a)):
        raise _checks.refuse(f"{name}: expected finite values, got NaN or inf")
    return a


def _gamma(gamma) -> float:
    g = _checks.scalar(gamma, "gamma")
    if not GAMMA_RANGE[0] <= g <= GAMMA_RANGE[1]:
        raise _checks.refuse(f"gamma: expected a peak enhancement factor in [1, 7], got {g}")
    return g


def jonswap(omega, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """The JONSWAP spectrum S(ω) in m²·s/rad (DNV-RP-C205, 3.5.5) at ``omega`` (rad/s):

    S(ω) = A_γ S_PM(ω) γ^exp(−½ ((ω − ω_p)/(σ ω_p))²),
    S_PM(ω) = (5/16) H_s² ω_p⁴ ω⁻⁵ exp(−(5/4)(ω/ω_p)⁻⁴),

    with ω_p = 2π/T_p, σ = 0.07 for ω ≤ ω_p and 0.09 above, and A_γ = 1 − 0.287 ln γ, which
    keeps m0 = ∫S dω ≈ H_s²/16. ``hs`` H_s (m) and ``tp`` T_p (s) are positive, ``gamma``
    γ in [1, 7] (γ = 1: Pierson–Moskowitz). S = 0 for ω <= 0.
    """
    w = _finite(omega, "omega")
    S = np.zeros_like(w)
    with np.errstate(over="ignore"):  # ln S < ln(max float), else S = inf: refused below
        S[w > 0.0] = np.exp(_log_jonswap(w[w > 0.0], hs, tp, gamma))
    if not np.all(np.isfinite(S)):
        raise _checks.refuse(f"hs, tp: expected a sea state whose spectrum is finite, got S(ω) overflowing for "
                         f"hs = {hs:g} m, tp = {tp:g} s")
    return S


def _log_jonswap(x: np.ndarray, hs, tp, gamma) -> np.ndarray:
    """ln S(ω) of ``jonswap`` at the frequencies ``x`` > 0 (rad/s), after checking hs, tp and gamma; −inf where S
    underflows. In logarithms, r = ln(ω/ω_p):

    ln S = ln(A_γ 5/16 H_s² ω_p⁻¹) − 5 r − (5/4) e^{−4r} + ln γ e^{−½((ω−ω_p)/(σω_p))²},

    so that neither a tiny ω (ω⁻⁵ e^{−(ω_p/ω)⁴} → 0) nor an extreme H_s or T_p overflows on the way."""
    hs = _checks.scalar(hs, "hs", positive=True, unit="m")
    tp = _checks.scalar(tp, "tp", positive=True, unit="s")
    g = _gamma(gamma)
    log_wp = np.log(2.0 * np.pi) - np.log(tp)  # (2π/tp overflows for a subnormal tp)
    r = np.log(x) - log_wp
    sigma = np.where(r <= 0.0, 0.07, 0.09)
    with np.errstate(over="ignore"):  # e^{−4r} → inf for ω ≪ ω_p: ln S → −inf, S → 0, exactly the limit
        return (np.log((1.0 - 0.287 * np.log(g)) * 5.0 / 16.0) + 2.0 * np.log(hs) - log_wp - 5.0 * r
                - 1.25 * np.exp(-4.0 * r) + np.log(g) * np.exp(-0.5 * (np.expm1(r) / sigma) ** 2))


class RAO:
    """A response amplitude operator H(ω): ``rao(omega)`` gives H as complex numbers, |H| in m/m
    (translations) or rad/m (rotations), arg H in rad. Made by ``RAO.table``, ``RAO.constant``,
    ``RAO.oscillator`` or from a function ``H(omega) -> complex array`` of ω (rad/s).

    A function's values must be finite (ValueError naming ``rao`` otherwise). The one exception is
    ``RAO.oscillator`` of a damping ratio so small that its resonance peak 1/(2ζ) exceeds the largest float
    (ζ < 2.8e-309): H is inf there, with a RuntimeWarning naming ``damping_ratio``."""

    def __init__(self, function: Callable[[np.ndarray], np.ndarray], description: str = "function"):
        if not callable(function):
            raise _checks.refuse(f"function: expected a callable H(omega) -> complex array, got {function!r}")
        self._h = function
        self._description = description
        self._overflow = None  # what makes H overflow where its exact value is beyond the floats (the oscillator's)

    def __call__(self, omega) -> np.ndarray:
        w = _finite(omega, "omega")
        try:
            H = np.asarray(self._h(w), dtype=complex)
        except (TypeError, ValueError) as error:
            raise _checks.refuse(f"rao: expected {self} to return complex numbers, got {error!r}") from error
        finite = np.isfinite(H)
        if H.shape != w.shape or not (np.all(finite) or (getattr(self, "_overflow", None) and not np.any(np.isnan(H)))):
            raise _checks.refuse(f"rao: expected {self} to return finite values of shape {w.shape}, got {H!r}")
        if not np.all(finite):
            warnings.warn(f"{self._overflow}: |H| = inf at ω = {w[~finite][0]:g} rad/s", RuntimeWarning, stacklevel=2)
        return H

    def __repr__(self) -> str:
        return f"<rigidfem RAO {self._description}>"

    @classmethod
    def table(cls, omega, amplitude, phase=None) -> RAO:
        """Tabulated |H| (m/m or rad/m) and arg H (rad; zeros when omitted) at increasing
        ``omega`` (rad/s): both interpolated linearly in ω (the phase unwrapped), held at their
        end values outside the table."""
        w = _checks.vector(omega, "omega", min_length=1)
        if np.any(np.diff(w) <= 0.0):
            raise _checks.refuse("omega: expected strictly increasing frequencies in rad/s")
        amp = _checks.vector(amplitude, "amplitude")
        arg = np.zeros_like(w) if phase is None else np.unwrap(_checks.vector(phase, "phase"))
        for values, name in ((amp, "amplitude"), (arg, "phase")):
            if values.size != w.size:
                raise _checks.refuse(f"{name}: expected {w.size} values (len(omega)), got {values.size}")
        if np.any(amp < 0.0):
            raise _checks.refuse("amplitude: expected non-negative values |H|")
        return cls(functools.partial(_table, w, amp, arg), f"table({w.size} points)")

    @classmethod
    def constant(cls, amplitude: float, phase: float = 0.0) -> RAO:
        """H(ω) = ``amplitude`` e^(i ``phase``) at every ω: the motion is the elevation scaled
        (amplitude 1, phase 0 for heave: a small buoy riding the waves)."""
        H = _checks.scalar(amplitude, "amplitude", nonnegative=True) * np.exp(1j * _checks.scalar(phase, "phase"))
        return cls(functools.partial(_constant, H), f"constant({H:.6g})")

    @classmethod
    def oscillator(cls, period: float, damping_ratio: float) -> RAO:
        """The long-wave heave RAO of a floating body with natural ``period`` T_n (s) and
        ``damping_ratio`` ζ: H(ω) = 1/(1 − r² + 2iζr), r = ω T_n/2π, in m/m (the wave force is
        its hydrostatic stiffness times η, a fair model for wavelengths long against the body).

        H is computed scaled: finite, and exact to rounding, for every positive finite T_n and ζ and every
        finite ω (→ 0 where |H| underflows), except at resonance (r = 1) for ζ < 2.8e-309, whose peak
        1/(2ζ) exceeds the largest float: such a ζ is taken with a RuntimeWarning naming ``damping_ratio``,
        and H is inf there (another RuntimeWarning when it is computed)."""
        period = _checks.scalar(period, "period", positive=True, unit="s")
        zeta = _checks.scalar(damping_ratio, "damping_ratio", positive=True)
        rao = cls(functools.partial(_oscillator, period, zeta),
                  f"oscillator(period={period:.6g} s, damping_ratio={zeta:.6g})")
        with np.errstate(over="ignore"):
            peak = 1.0 / (2.0 * zeta)
        if not np.isfinite(peak):
            rao._overflow = (f"damping_ratio: ζ = {zeta:g} makes the resonance peak |H| = 1/(2ζ) of {rao} overflow "
                             f"(ζ < 2.8e-309)")
            warnings.warn(f"{rao._overflow}: H is inf at ω = 2π/T_n = {2.0 * np.pi / period:g} rad/s", RuntimeWarning,
                          stacklevel=2)
        return rao


# The RAOs' functions, at module level so that an RAO pickles (a sweep's processes, a saved scene).
def _table(w, amplitude, phase, x):
    """|H| and arg H interpolated linearly in ω, held at the ends."""
    return np.interp(x, w, amplitude) * np.exp(1j * np.interp(x, w, phase))


def _constant(H, x):
    return np.full(np.shape(x), H)


def _oscillator(period, zeta, x):
    """H = 1/(1 − r² + 2iζr), r = ω T_n/2π; for |r| > 1 as r⁻²/(r⁻² − 1 + 2iζ/r), so that neither r² nor ζr
    overflows where H is finite (H → 0 as r → inf)."""
    with np.errstate(over="ignore", under="ignore"):
        r = (np.asarray(x, dtype=float) / (2.0 * np.pi)) * period  # inf beyond the floats: H = 0 there
        near = np.abs(r) <= 1.0
        far = np.where(near, 2.0, r)  # |r| > 1 (placeholders where near)
        q = 1.0 / far**2
        H = _reciprocal(np.where(near, 1.0 - r * r, q - 1.0), np.where(near, 2.0 * zeta * r, 2.0 * zeta / far))
    with np.errstate(invalid="ignore"):  # q H where near (discarded) may be NaN where H is inf
        return np.where(near, H, q * H)


def _reciprocal(a, b) -> np.ndarray:
    """1/(a + ib) for real a, b (either may be inf: 0 then), scaled by max(|a|, |b|) so that nothing overflows on
    the way: inf only where the exact value is beyond the floats."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
        s = np.maximum(np.abs(a), np.abs(b))
        big = np.isinf(s)
        s = np.where(big, 1.0, s)
        a, b = np.where(big, 0.0, a / s), np.where(big, 0.0, b / s)
        n = np.where(big, 1.0, a * a + b * b)  # in [1, 2]
        H = np.empty(a.shape, dtype=complex)
        H.real, H.imag = (a / n) / s, (-b / n) / s  # (not a − 1j b: 1j * inf has a NaN real part)
    return H


def _scaled_variance(amplitude: np.ndarray) -> tuple[float, float]:
    """(s, Σ (a_k/s)²/2) with s = max |a_k|: m0 = Σ a_k²/2 = s² times the second, computed without overflow."""
    s = float(np.max(np.abs(amplitude))) if amplitude.size else 0.0
    return s, (0.5 * float(np.sum((amplitude / s) ** 2)) if s > 0.0 else 0.0)


def _as_rao(rao, name: str) -> RAO:
    if isinstance(rao, RAO):
        return rao
    try:
        return RAO.constant(rao)
    except ValueError:
        raise _checks.refuse(f"{name}: expected an RAO or a non-negative gain, got {rao!r}") from None


@dataclass(frozen=True, eq=False)
class Waves:
    """Harmonic components of a sea state: η(t) = Σ_k a_k sin(ω_k t + φ_k) (m) with
    ``omega`` ω_k (rad/s), ``amplitude`` a_k (m) and ``phase`` φ_k (rad), 1-D arrays of one
    length (kept as read-only copies). ``jonswap_waves`` makes them from a spectrum."""

    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray

    def __post_init__(self):
        a = _checks.vector(self.amplitude, "amplitude", min_length=1)
        for name in ("omega", "phase", "amplitude"):
            values = np.array(_checks.vector(getattr(self, name), name))  # a copy, then read-only
            if values.size != a.size:
                raise _checks.refuse(f"{name}: expected {a.size} values (len(amplitude)), got {values.size}")
            values.flags.writeable = False
            object.__setattr__(self, name, values)

    @property
    def m0(self) -> float:
        """Variance of η (m²): m0 = Σ a_k²/2, the discrete spectrum's zeroth moment. Amplitudes beyond about
        1e154 m make it overflow: inf, with a RuntimeWarning naming ``amplitude`` (``hs`` is still finite)."""
        s, ratio = _scaled_variance(self.amplitude)
        with np.errstate(over="ignore"):
            m0 = s * (s * ratio)
        if not np.isfinite(m0):
            warnings.warn(f"amplitude: components up to {s:g} m make m0 = Σ a_k²/2 overflow: inf (hs = 4√m0 = "
                          f"{self.hs:g} m)", RuntimeWarning, stacklevel=2)
        return m0

    @property
    def hs(self) -> float:
        """Significant wave height H_s = 4 √m0 (m) of the components, computed scaled: finite where ``m0``
        overflows (amplitudes up to about 1e307 m), exact for tiny amplitudes whose m0 underflows."""
        s, ratio = _scaled_variance(self.amplitude)
        with np.errstate(over="ignore"):
            hs = s * (4.0 * np.sqrt(ratio))
        if not np.isfinite(hs):
            warnings.warn(f"amplitude: components up to {s:g} m make hs = 4√m0 overflow: inf", RuntimeWarning,
                          stacklevel=2)
        return hs

    def elevation(self) -> Profile:
        """η(t) (m) as a ``rigidfem.motion.harmonics`` profile, evaluated in C++."""
        return motion.harmonics(self.amplitude, self.omega, self.phase)

    def response(self, rao) -> Profile:
        """x(t) = Σ_k |H(ω_k)| a_k sin(ω_k t + φ_k + arg H(ω_k)) for an ``RAO`` (or a constant
        gain), as a harmonics profile: m for translations, rad for rotations."""
        H = _as_rao(rao, "rao")(self.omega)
        with np.errstate(over="ignore"):
            amplitude = np.abs(H) * self.amplitude
        if not np.all(np.isfinite(amplitude)):
            k = int(np.argmax(~np.isfinite(amplitude)))
            raise _checks.refuse(f"rao: expected an RAO whose responses |H(ω_k)| a_k to these waves are finite, got "
                             f"|H| = {abs(H[k]):g} at ω = {self.omega[k]:g} rad/s, a_k = {self.amplitude[k]:g} m")
        return motion.harmonics(amplitude, self.omega, self.phase + np.angle(H))

    def motion(self, raos: dict) -> dict[str, Profile]:
        """The base motion for ``Model.add_moving_base``: ``raos`` maps degrees of freedom (ship
        names "surge", "sway", "heave", "roll", "pitch", "yaw", or "x" ... "rx") to an ``RAO``
        or a constant gain; the result maps them to their responses. Missing ones stay at 0."""
        if not isinstance(raos, dict):
            raise _checks.refuse(f"raos: expected a dict of degrees of freedom to RAOs, got {raos!r}")
        names = list(BASE_DOFS) + list(BASE_DOFS.values())
        for dof in raos:
            if dof not in names:
                raise _checks.refuse(f"raos: expected keys from {names}, got {dof!r}")
        return {dof: self.response(_as_rao(rao, f"raos[{dof!r}]")) for dof, rao in raos.items()}


def jonswap_waves(hs: float, tp: float, gamma: float = 3.3, n: int = 200, omega_range=None, seed=0) -> Waves:
    """A JONSWAP sea state (``jonswap``) as ``n`` components of equal Δω.

    ω_k = ω_lo + (k − ½) Δω (k = 1 ... n), Δω = (ω_hi − ω_lo)/n, a_k = √(2 S(ω_k) Δω), and
    phases φ_k uniform in [0, 2π) from ``np.random.default_rng(seed)`` (``seed`` an int or a
    Generator): one seed, one record. ``omega_range`` (ω_lo, ω_hi) in rad/s defaults to
    (0.5 ω_p, 5 ω_p), which holds all but 0.2 % of m0. The record's envelope repeats after
    2π/Δω: raise ``n`` for longer simulations.

    The amplitudes are computed in logarithms (finite, not 0, for a tiny ``hs``); a sea state whose
    variance m0 ≈ H_s²/16 overflows (H_s beyond about 5e154 m) is a ValueError naming hs, tp.
    """
    tp = _checks.scalar(tp, "tp", positive=True, unit="s")
    wp = 2.0 * np.pi / tp
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)):
        raise _checks.refuse(f"n: expected a positive number of components, got {n!r}")
    n = _checks.integer(n, "n", minimum=1, maximum=MAX_COMPONENTS)
    if omega_range is None and not np.isfinite(5.0 * wp):
        raise _checks.refuse(f"tp: expected a peak period whose default frequencies 0.5 to 5 times 2π/tp are finite "
                         f"(tp >= 1.8e-307 s; or give omega_range), got {tp:g} s")
    lo, hi = (0.5 * wp, 5.0 * wp) if omega_range is None else _omega_range(omega_range)
    dw = (hi - lo) / n
    w = lo + (np.arange(n) + 0.5) * dw
    hs = _checks.scalar(hs, "hs", positive=True, unit="m")
    a = np.zeros_like(w)
    with np.errstate(over="ignore"):  # a_k² / 2 = S(ω_k) Δω, in logarithms: neither S nor S Δω over- or underflows
        a[w > 0.0] = np.exp(0.5 * (np.log(2.0) + np.log(dw) + _log_jonswap(w[w > 0.0], hs, tp, gamma)))
        s, ratio = _scaled_variance(a) if np.all(np.isfinite(a)) else (np.inf, 1.0)
        m0 = s * (s * ratio)
    if not np.isfinite(m0):
        raise _checks.refuse(f"hs, tp: expected a sea state whose variance m0 ≈ hs²/16 is finite, got m0 overflowing for "
                         f"hs = {hs:g} m, tp = {tp:g} s")
    if not isinstance(seed, np.random.Generator):
        try:
            seed = np.random.default_rng(seed)
        except (TypeError, ValueError):
            raise _checks.refuse(f"seed: expected an int or a numpy Generator, got {seed!r}") from None
    return Waves(w, a, seed.uniform(0.0, 2.0 * np.pi, n))


def _omega_range(omega_range) -> tuple[float, float]:
    r = _checks.array(omega_range, (2,), "omega_range")
    if not 0.0 <= r[0] < r[1]:
        raise _checks.refuse(f"omega_range: expected (lo, hi) with 0 <= lo < hi in rad/s, got {tuple(r)}")
    return float(r[0]), float(r[1])
