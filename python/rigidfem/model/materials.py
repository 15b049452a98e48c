"""Materials and cross-sections of beam-like links (SI units)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..base import _checks


@dataclass(frozen=True)
class Material:
    """An isotropic linear viscoelastic material: Kelvin–Voigt damping and, optionally, a Prony
    series (the standard linear solid, Zener, is its one-term case).

    Parameters
    ----------
    E : float
        Young's modulus, Pa.
    rho : float
        Density, kg/m³.
    nu : float, optional
        Poisson's ratio; gives G = E / (2 (1 + nu)). Default 0.3 when G is not given.
    G : float, optional
        Shear modulus, Pa (overrides nu).
    retardation : float
        Retardation time μ of the Kelvin–Voigt law σ = E (ε + μ ε̇), s (default 0: no material
        damping). Each sde damper is b_k = μ c_k (N·s/m or N·m·s/rad), so mode n is damped with
        ζ_n = μ ω_n / 2.
    prony : sequence of (E_j, tau_j)
        Maxwell arms (Pa, s) in parallel with the spring E: the relaxation modulus is
        E(t) = E + Σ E_j e^{−t/τ_j}, so ``E`` is the long-term (relaxed) modulus E∞ and
        E₀ = E + Σ E_j the instantaneous one; shear relaxes alike, G(t) = G E(t)/E. Every sde
        stiffness c_k gets one arm per term, k_j = (E_j/E) c_k with τ_j
        (``Model.add_maxwell_arm``: its force is an internal variable of the state). Empty by
        default. ``Material.zener`` and ``Material.from_relaxation`` build it.

    Examples
    --------
    >>> import rigidfem as rf
    >>> steel = rf.Material(E=2.1e11, rho=7850.0, nu=0.3)
    >>> round(steel.G / 1e9, 2)
    80.77
    """

    E: float
    rho: float
    nu: float | None = None
    G: float | None = None
    retardation: float = 0.0
    prony: tuple = ()

    def __post_init__(self):
        # Every field is stored as the float it was checked as (a string such as "7850" is refused,
        # not stored to fail later).
        E = _checks.scalar(self.E, "E", positive=True, unit="Pa (Young's modulus)")
        rho = _checks.scalar(self.rho, "rho", positive=True, unit="kg/m³ (density)")
        retardation = _checks.scalar(self.retardation, "retardation", nonnegative=True, unit="s (retardation time)")
        nu = None if self.nu is None else _checks.scalar(self.nu, "nu", unit="(-1, 0.5] (Poisson's ratio)")
        if nu is not None and not -1.0 < nu <= 0.5:
            raise _checks.refuse(f"nu: expected Poisson's ratio in (-1, 0.5], got {nu}")
        if self.G is not None:
            G = _checks.scalar(self.G, "G", positive=True, unit="Pa (shear modulus)")
        else:
            G = E / (2.0 * (1.0 + (0.3 if nu is None else nu)))
        prony = _prony_terms(self.prony)
        for name, value in (("E", E), ("rho", rho), ("nu", nu), ("G", G), ("retardation", retardation),
                            ("prony", prony)):
            object.__setattr__(self, name, value)

    @classmethod
    def zener(cls, E0: float, E_inf: float, tau: float, rho: float, nu: float | None = None,
              G: float | None = None) -> "Material":
        """The standard linear solid: instantaneous modulus ``E0`` and long-term ``E_inf`` (Pa,
        0 < E_inf < E0), relaxation time ``tau`` (s) of E(t) = E∞ + (E₀ − E∞) e^{−t/τ}. ``G`` (if
        given) is the long-term shear modulus."""
        E0 = _checks.scalar(E0, "E0", positive=True, unit="Pa (instantaneous modulus)")
        E_inf = _checks.scalar(E_inf, "E_inf", positive=True, unit="Pa (long-term modulus)")
        if not E_inf < E0:
            raise _checks.refuse(f"E_inf: expected a long-term modulus below E0 = {E0} Pa, got {E_inf}")
        return cls(E=E_inf, rho=rho, nu=nu, G=G, prony=((E0 - E_inf, tau),))

    @classmethod
    def from_relaxation(cls, t, E_t, rho: float, times=None, nu: float | None = None) -> "Material":
        """A Prony series fitted to relaxation data E(t_i) (Pa at times t_i in s): E∞ and E_j ≥ 0 by
        non-negative least squares for the relaxation times ``times`` (s; default one per decade
        from the smallest positive t to the largest), relative to each E(t_i); terms fitted to
        zero are dropped. ValueError if the fit leaves no positive long-term modulus."""
        from scipy.optimize import nnls

        t = np.asarray(_checks.vector(t, "t"), dtype=float)
        E_t = np.asarray(_checks.vector(E_t, "E_t"), dtype=float)
        if len(t) != len(E_t) or len(t) < 2 or np.any(t < 0.0) or np.any(E_t <= 0.0):
            raise _checks.refuse(f"t, E_t: expected as many times >= 0 s as moduli > 0 Pa (at least 2), got {len(t)} "
                             f"times and {len(E_t)} moduli")
        if times is None:
            lo, hi = np.log10(t[t > 0.0].min()), np.log10(t.max())
            times = 10.0 ** np.arange(np.floor(lo), np.ceil(hi) + 1.0)
        times = np.asarray(_checks.vector(times, "times"), dtype=float)
        if np.any(times <= 0.0):
            raise _checks.refuse(f"times: expected positive relaxation times in s, got {times}")
        basis = np.column_stack([np.ones_like(t), np.exp(-t[:, None] / times[None, :])]) / E_t[:, None]
        coef, _ = nnls(basis, np.ones_like(t))
        if not coef[0] > 0.0:
            raise _checks.refuse("E_t: expected relaxation data with a positive long-term modulus, got a fit with E_inf = 0")
        return cls(E=coef[0], rho=rho, nu=nu, prony=tuple((E, tau) for E, tau in zip(coef[1:], times) if E > 0.0))

    def relaxation_modulus(self, t):
        """E(t) = E + Σ E_j e^{−t/τ_j} (Pa) at the times t (s)."""
        t = np.asarray(t, dtype=float)
        return self.E + sum(E_j * np.exp(-t / tau) for E_j, tau in self.prony)


def _prony_terms(prony) -> tuple:
    """The Prony terms as a tuple of (E_j, tau_j) floats, each positive and finite."""
    try:
        terms = tuple(tuple(term) for term in prony)
    except TypeError:
        raise _checks.refuse(f"prony: expected a sequence of (E_j in Pa, tau_j in s) pairs, got {prony!r}") from None
    if any(len(term) != 2 for term in terms):
        raise _checks.refuse(f"prony: expected a sequence of (E_j in Pa, tau_j in s) pairs, got {prony!r}")
    return tuple((_checks.scalar(E, "prony", positive=True, unit="Pa (arm modulus E_j)"),
                  _checks.scalar(tau, "prony", positive=True, unit="s (relaxation time tau_j)")) for E, tau in terms)


#: The sizes (m) a section's dimensions may take: their fourth powers (I, J) finite and positive.
DIMENSIONS = (1e-50, 1e50)


def _dimension(x, name: str) -> float:
    """A section's dimension (m) within ``DIMENSIONS``, so that A, I and J are finite and positive."""
    v = _checks.scalar(x, name, positive=True, unit="m")
    if not DIMENSIONS[0] <= v <= DIMENSIONS[1]:
        raise _checks.refuse(f"{name}: expected a length in [{DIMENSIONS[0]:g}, {DIMENSIONS[1]:g}] m (its fourth power, "
                         f"the section's I and J, finite and positive), got {v:g}")
    return v


@dataclass(frozen=True)
class Section:
    """A beam cross-section in its principal axes y, z (the beam axis is x).

    Parameters
    ----------
    A : float
        Area, m².
    Iy, Iz : float
        Second moments of area about y (∫z² dA, bending ``bend_y``: deflection along z)
        and about z (∫y² dA, ``bend_z``: deflection along y), m⁴.
    J : float
        Torsion constant (Saint-Venant), m⁴; equals Iy + Iz only for circles and tubes.
    kappa_y, kappa_z : float
        Shear coefficients (shear stiffness κ G A) for shear along y and z.

    Examples
    --------
    >>> import rigidfem as rf
    >>> s = rf.Section.rectangle(0.02, 0.005)
    >>> round(s.A * 1e6, 3), s.Iz > s.Iy
    (100.0, True)
    """

    A: float
    Iy: float
    Iz: float
    J: float
    kappa_y: float = 5.0 / 6.0
    kappa_z: float = 5.0 / 6.0

    _UNITS = {"A": "m² (area)", "Iy": "m⁴ (second moment about y)", "Iz": "m⁴ (second moment about z)",
              "J": "m⁴ (torsion constant)", "kappa_y": "(shear coefficient)", "kappa_z": "(shear coefficient)"}

    def __post_init__(self):
        for name, unit in self._UNITS.items():  # stored as the checked floats
            object.__setattr__(self, name, _checks.scalar(getattr(self, name), name, positive=True, unit=unit))

    @property
    def I0(self) -> float:
        """Polar second moment Iy + Iz (m⁴): the section's rotary inertia per ρ about x."""
        return self.Iy + self.Iz

    @staticmethod
    def rectangle(width: float, height: float) -> Section:
        """Solid rectangle: ``width`` (m) along y, ``height`` (m) along z.

        A = w h, Iz = h w³/12, Iy = w h³/12; J from Saint-Venant's series for a
        rectangle with sides a ≥ b: J = (a b³/3) [1 − (192 b/(π⁵ a)) Σ_{n odd} tanh(nπa/2b)/n⁵];
        κ = 5/6.
        """
        w, h = _dimension(width, "width"), _dimension(height, "height")
        a, b = max(w, h), min(w, h)
        series = sum(math.tanh(n * math.pi * a / (2 * b)) / n**5 for n in range(1, 200, 2))
        J = a * b**3 / 3 * (1 - 192 * b / (math.pi**5 * a) * series)
        return Section(A=w * h, Iy=w * h**3 / 12, Iz=h * w**3 / 12, J=J)

    @staticmethod
    def circle(d: float) -> Section:
        """Solid circle of diameter ``d`` (m): I = π d⁴/64, J = π d⁴/32, κ = 9/10."""
        d = _dimension(d, "d")
        I = math.pi * d**4 / 64
        return Section(A=math.pi * d**2 / 4, Iy=I, Iz=I, J=2 * I, kappa_y=0.9, kappa_z=0.9)

    @staticmethod
    def tube(d_out: float, d_in: float) -> Section:
        """Circular tube (m): I = π (D⁴ − d⁴)/64, J = 2 I, κ = 1/2 (thin-walled)."""
        D = _dimension(d_out, "d_out")
        d = _checks.scalar(d_in, "d_in", nonnegative=True, unit="m")  # below d_out: its d⁴ is finite
        if not d < D:
            raise _checks.refuse(f"d_in: expected less than d_out = {D}, got {d}")
        I = math.pi * (D**4 - d**4) / 64
        return Section(A=math.pi * (D**2 - d**2) / 4, Iy=I, Iz=I, J=2 * I, kappa_y=0.5, kappa_z=0.5)
