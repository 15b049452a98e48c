"""Materials and cross-sections of beam-like links (SI units)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import _checks


@dataclass(frozen=True)
class Material:
    """An isotropic linear-elastic material with Kelvin–Voigt damping.

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
    damping : float
        Retardation time μ of the Kelvin–Voigt law σ = E (ε + μ ε̇), s. Each sde damper
        is b_k = μ c_k, so mode n is damped with ζ_n = μ ω_n / 2.
    """

    E: float
    rho: float
    nu: float | None = None
    G: float | None = None
    damping: float = 0.0

    def __post_init__(self):
        # Every field is stored as the float it was checked as (a string such as "7850" is refused,
        # not stored to fail later).
        E = _checks.scalar(self.E, "E", positive=True, unit="Pa (Young's modulus)")
        rho = _checks.scalar(self.rho, "rho", positive=True, unit="kg/m³ (density)")
        damping = _checks.scalar(self.damping, "damping", nonnegative=True, unit="s (retardation time)")
        nu = None if self.nu is None else _checks.scalar(self.nu, "nu", unit="(-1, 0.5] (Poisson's ratio)")
        if nu is not None and not -1.0 < nu <= 0.5:
            raise ValueError(f"nu: expected Poisson's ratio in (-1, 0.5], got {nu}")
        if self.G is not None:
            G = _checks.scalar(self.G, "G", positive=True, unit="Pa (shear modulus)")
        else:
            G = E / (2.0 * (1.0 + (0.3 if nu is None else nu)))
        for name, value in (("E", E), ("rho", rho), ("nu", nu), ("G", G), ("damping", damping)):
            object.__setattr__(self, name, value)


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
        w = _checks.scalar(width, "width", positive=True)
        h = _checks.scalar(height, "height", positive=True)
        a, b = max(w, h), min(w, h)
        series = sum(math.tanh(n * math.pi * a / (2 * b)) / n**5 for n in range(1, 200, 2))
        J = a * b**3 / 3 * (1 - 192 * b / (math.pi**5 * a) * series)
        return Section(A=w * h, Iy=w * h**3 / 12, Iz=h * w**3 / 12, J=J)

    @staticmethod
    def circle(d: float) -> Section:
        """Solid circle of diameter ``d`` (m): I = π d⁴/64, J = π d⁴/32, κ = 9/10."""
        d = _checks.scalar(d, "d", positive=True)
        I = math.pi * d**4 / 64
        return Section(A=math.pi * d**2 / 4, Iy=I, Iz=I, J=2 * I, kappa_y=0.9, kappa_z=0.9)

    @staticmethod
    def tube(d_out: float, d_in: float) -> Section:
        """Circular tube (m): I = π (D⁴ − d⁴)/64, J = 2 I, κ = 1/2 (thin-walled)."""
        D = _checks.scalar(d_out, "d_out", positive=True)
        d = _checks.scalar(d_in, "d_in", nonnegative=True)
        if not d < D:
            raise ValueError(f"d_in: expected less than d_out = {D}, got {d}")
        I = math.pi * (D**4 - d**4) / 64
        return Section(A=math.pi * (D**2 - d**2) / 4, Iy=I, Iz=I, J=2 * I, kappa_y=0.5, kappa_z=0.5)
