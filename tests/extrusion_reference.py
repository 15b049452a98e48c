r"""Independent reference solver (numpy/scipy only, no rigidfem): transverse vibration of a
cantilever tape of time-varying free length L(t) extruded from / retracted into a rigid guide
(the "telescopic rapier", Wittbrodt, Adamiec-Wójcik & Wojciech, *Dynamics of Flexible Multibody
Systems. Rigid Finite Element Method*, ch. 7.2).

Problem
-------
A uniform Euler–Bernoulli beam (E, I, ρ, A) slides out of a rigid guide with axial speed
v(t) = L̇(t) (extrusion v > 0, retraction v < 0). In the guide-fixed (Eulerian) coordinate x the
free part occupies 0 < x < L(t); the transverse deflection w(x, t) of the material passing x obeys

    ρA (w_tt + 2 v w_xt + v² w_xx + v̇ w_x) − (N w_x)_x + EI w_xxxx = −ρA g,
    w(0,t) = w_x(0,t) = 0   (clamped at the guide exit),
    w_xx(L,t) = w_xxx(L,t) = 0   (free end; the end is a material point).

The bracket is the transverse acceleration of a material particle, D²w/Dt² with D/Dt = ∂_t + v ∂_x
(x_particle(t) has ẋ = v, ẍ = v̇). Gravity g acts transversally (horizontal guide); linear theory.

Axial force. The tape is inextensible and all of it moves axially with v(t); the axial momentum
balance of the free part beyond a section x gives N_x = ρA v̇ and N(L) = 0, hence

    N(x, t) = −ρA v̇ (L − x)    (compression while the tape is accelerated out of the guide).

Its transverse contribution −(N w_x)_x = ρA v̇ [(L − x) w_xx − w_x] is included with
``axial_inertia=True`` and omitted (N ≡ 0, the usual "axial tension neglected" model) with
``axial_inertia=False`` (the default). Note that with it, the v̇ w_x terms cancel and the
v̇-dependent part becomes ρA v̇ (L − x) w_xx. At constant speed (v̇ = 0) the option has no effect.
The axial gravity component and any guide friction are not modelled.

Energy. With u = Dw/Dt and E(t) = ∫₀ᴸ [½ρA u² + ½EI w_xx² + ρA g w] dx (transverse kinetic,
bending and gravity energy of the free part; the constant axial kinetic energy is left out),
the PDE and the boundary conditions give exactly (the Leibniz boundary terms at x = L cancel)

    dE/dt = −½ v EI w_xx(0,t)²  +  ρA v̇ ∫₀ᴸ (L − x) w_x u_x dx · [axial_inertia].

So without axial inertia (or at constant speed) the energy of the free part decreases during
extrusion (v > 0) and increases during retraction (v < 0): the bending energy carried through the
guide exit is removed/supplied by the guide — the beam version of Carrier's "spaghetti problem"
(retraction destabilises, extrusion stabilises; no damping is needed for either effect).
For slow motions the mode-1 vibration is adiabatic, E/ω₁ ∝ E L² ≈ const: in retraction the
energy grows like L⁻² but the tip amplitude (∝ √(E L³/EI)) shrinks like √L — "growth" refers to
the energy (and the curvature and velocity amplitudes), not to the tip deflection.

Method (Galerkin on the normalised domain)
------------------------------------------
The moving domain is mapped to ξ = x / L(t) ∈ [0, 1]. Time derivatives at fixed x and at fixed ξ
are related by ∂_t|_x = ∂_t|_ξ − ξ (L̇/L) ∂_ξ, so (L̇ = v) the material derivative becomes

    D/Dt = ∂_t|_ξ + c ∂_ξ,   c(ξ, t) = v (1 − ξ) / L   (the ξ-velocity of a material particle),

and, exactly (checked with SymPy by ``derive_transformed_operator``),

    D²w/Dt² = w_tt + 2c w_tξ + (c_t + c c_ξ) w_ξ + c² w_ξξ
            = w_tt + (2v/L)(1−ξ) w_tξ + (v̇/L − 2v²/L²)(1−ξ) w_ξ + (v²/L²)(1−ξ)² w_ξξ,

with x-derivatives ∂_x = L⁻¹ ∂_ξ. With w = Σ_k φ_k(ξ) a_k(t), test functions φ_j(x/L(t)) on the
current domain, dx = L dξ, the bending term integrated by parts twice (the free-end conditions
are natural, the clamped ones essential) and the axial term once (N(L) = 0, φ_j(0) = 0), the
weighted residual divided by ρA L gives the linear, time-varying second-order system

    M a'' + (2v/L) G a' + [ (v̇/L − 2v²/L²) G + (v²/L²) H − κ_N (v̇/L) P + (EI/(ρA L⁴)) S ] a = −g f

    M_jk = ∫ φ_j φ_k,   G_jk = ∫ (1−ξ) φ_j φ_k',   H_jk = ∫ (1−ξ)² φ_j φ_k'',
    P_jk = ∫ (1−ξ) φ_j' φ_k',   S_jk = ∫ φ_j'' φ_k'',   f_j = ∫ φ_j      (∫ = ∫₀¹ dξ),

κ_N = 1 with axial inertia, else 0. M, G, H, P, S, f are constant: the whole time dependence is in
the scalars L, v, v̇. They are computed by Gauss–Legendre quadrature, exactly (polynomials).

Shape functions: φ_k'' = √(2k+1) P_k(2ξ−1) (shifted Legendre), φ_k(0) = φ_k'(0) = 0,
k = 0 … n−1. They span every polynomial of degree ≤ n+1 with a double zero at ξ = 0 and give
S = I. Why polynomials and not the clamped–free eigenfunctions: the solution is analytic in ξ
but its w_xxxx does not vanish at the clamp, so eigenfunction coefficients decay only
algebraically (the static tip deflection projected on 8 / 16 eigenfunctions is off by 1.5e-6 /
4.9e-8, ∝ n⁻⁵), whereas the polynomial Galerkin converges exponentially; the static deflection
(a quartic) is represented exactly from 3 functions on. The
price is a stiff spectrum (largest/lowest discrete frequency ≈ 740 for 8, 8300 for 16 functions),
which is why the default integrator is the implicit, L-stable Radau IIA (order 5) of
``scipy.integrate.solve_ivp`` with the exact Jacobian: for smooth motions the unphysical top of
the spectrum is not excited and Radau does not resolve it (8× / 35× / >200× faster than DOP853
for 8 / 12 / 16 functions at equal accuracy — DOP853 is stability-limited; it remains available via
``method=``). Radau's error at the output times is ≈ rtol (checked against DOP853 at rtol 1e-13). The system is
integrated in the coordinates q of the v = 0 problem (a = Φ q, ΦᵀMΦ = I, ΦᵀSΦ = Λ) obtained
stably from the eigen-decomposition of M alone (S = I).

An independent second discretisation, ``solve_fd``, is the method of lines on a uniform grid in ξ:
second-order central differences of the *strong* form above, the four boundary conditions by ghost
points, Radau with a sparse Jacobian; its symmetric stencils give an error expansion in h², h⁴, …
so ``solve_fd_extrapolated`` (grids h, h/2, h/4 and repeated Richardson extrapolation) reaches
~1e-8. It shares with the Galerkin solver only the transformed operator (itself checked with SymPy
against the Eulerian PDE); the weak form, the basis and the boundary treatment are independent.
(Chebyshev collocation of the strong form was tried and rejected: with the boundary rows deleted
the 4th-order collocation matrix has spurious complex eigenvalues, unstable even at v = 0.)
The discrete "static" initial state is each model's own equilibrium at L(t0), so that no
grid-scale vibration is started by the discretisation error of the initial shape.

Initial conditions: ``w0`` is ``None``/"static" (static deflection at L(t0) under g), "rest"/"zero"
(w = 0), ``("mode", k, tip)`` (the discrete model's k-th natural mode at L(t0), tip value ``tip``)
or a callable w0(x); ``wdot0`` is ∂w/∂t at fixed x (Eulerian), ``None`` = 0, or a callable.
(If v(t0) = 0 every notion of "initially at rest" coincides.) Callables are L²-projected.

Accuracy and cost (measured, tests/test_extrusion_reference.py; 2-core machine under load)
-------------------------------------------------------------------------------------------
* Steel tape (E = 2.1e11, ρ = 7850, 20 × 2 mm), gravity, ``SmoothStroke`` 0.3 → 0.8 m in 0.25 s
  (peak 4.4 m/s): max tip difference over the run relative to max |tip|, against 20 functions:
  4: 3.3e-5, 6: 1.9e-7, 8: 5.7e-9, 12: 1.4e-10, 16: 1.3e-10 (the Radau floor, rtol 1e-10);
  0.07 s per solve. Retraction 0.8 → 0.3 m in 0.15 s (peak 7.3 m/s): 8: 5.7e-7, 12: 5.5e-9,
  16: 1.2e-10; 0.5 s per solve.
* Galerkin (12 functions) against FD extrapolated from 20/40/80 (24/48/96) intervals: 6.7e-9
  (steel stroke), 1.5e-8 (nondimensional ramp to v = 0.5), 4.4e-7 (retraction at v = −0.2 with
  mode-1 vibration), 7.1e-7 (stroke with axial inertia); the finest FD grid alone is 7e-5 … 1e-3
  off and its errors fall by 4.0 per halving of h.
* Energy balance E(t) − E(0) = ∫ power dt: 1e-7 … 1e-6 of the energy (change).
* Discontinuous speed (``ConstantSpeed`` from t0 with v ≠ 0) is a physical impact: the field
  loses smoothness, all modes are excited, convergence becomes algebraic and Radau slow (steel
  tape from L = 0.8 m at −5 m/s: 12 vs 16 functions differ by 1e-5, 10 s per solve; +5 m/s from
  0.3 m: 9e-7, 1 s). For reference comparisons prefer ``RampToSpeed``/``SmoothStroke`` (C³).

API
---
``solve(E, I, rho, A, g, L, v=None, vdot=None, t_span=(0, 1), t_eval=None, modes=8, w0=None,
axial_inertia=False, ...)`` → ``Solution`` (``.t``, ``.tip`` = w(L(t),t), ``.L``, ``.w(x, t)``,
``.energy(t)``, ``.power(t)``...). ``L`` is a ``Motion`` (``ConstantSpeed``, ``SmoothStroke``,
``RampToSpeed``, ``CallableMotion``) or a callable L(t) together with callables ``v`` and ``vdot``.
``solve_fd`` has the same signature with ``points`` (grid intervals) instead of ``modes``;
``solve_fd_extrapolated(..., points=(20, 40, 80))`` returns (t, extrapolated tip, tips per grid).
``static_deflection``, ``clamped_free_beta``, ``clamped_free_frequencies``, ``clamped_free_mode``,
``galerkin_frequencies``, ``derive_transformed_operator``.
"""

import numpy as np
from numpy.polynomial import legendre as _leg
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

__all__ = [
    "Motion", "ConstantSpeed", "SmoothStroke", "RampToSpeed", "CallableMotion", "Solution", "solve", "solve_fd",
    "solve_fd_extrapolated",
    "static_deflection", "clamped_free_beta", "clamped_free_frequencies", "clamped_free_mode",
    "galerkin_frequencies", "derive_transformed_operator", "steel_tape",
]


def steel_tape(b=0.020, h=0.002):
    """(E, I, rho, A) of the consumer's steel tape: 2.1e11 Pa, 7850 kg/m³, b × h section bent about
    the thin direction (I = b h³/12)."""
    return 2.1e11, b * h**3 / 12.0, 7850.0, b * h


# ----------------------------------------------------------------------------------------------
# closed-form results
# ----------------------------------------------------------------------------------------------

def static_deflection(E, I, rho, A, g, L, x=None):
    """Static deflection of the clamped–free beam under its weight: w(x) = −ρAg x²(6L² − 4Lx + x²)/(24EI);
    ``x=None`` gives the tip value −ρAgL⁴/(8EI). ``x`` may be an array."""
    x = L if x is None else np.asarray(x, float)
    return -rho * A * g * x**2 * (6 * L**2 - 4 * L * x + x**2) / (24.0 * E * I)


def clamped_free_beta(n=3):
    """First n roots β_k L of 1 + cos β cosh β = 0 (1.8751040687, 4.6940911330, 7.8547574382, ...)."""
    f = lambda b: np.cos(b) + 1.0 / np.cosh(b)
    return np.array([brentq(f, (k - 0.5) * np.pi - 0.5 * np.pi + 1e-9 if k > 1 else 1.0,
                            (k - 0.5) * np.pi + 0.5 * np.pi - 1e-9 if k > 1 else 2.5, xtol=1e-15, rtol=1e-15)
                     for k in range(1, n + 1)])


def clamped_free_frequencies(E, I, rho, A, L, n=3):
    """ω_k = (β_k L)² √(EI/(ρA L⁴)) (rad/s), k = 1 … n."""
    return clamped_free_beta(n) ** 2 * np.sqrt(E * I / (rho * A * L**4))


def clamped_free_mode(k, L, amplitude=1.0):
    """Callable x ↦ k-th (1-based) clamped–free mode shape on [0, L], scaled to tip value ``amplitude``.
    Evaluated in a cancellation-free form (cosh − σ sinh written with decaying exponentials)."""
    b = clamped_free_beta(k)[-1]
    sig = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))
    eb = np.exp(-b)
    c_plus = (np.sin(b) - np.cos(b) - eb) / (1.0 - eb**2 + 2.0 * np.sin(b) * eb)   # ½(1−σ) e^{β}

    def raw(xi):
        y = b * xi
        # cosh y − σ sinh y = ½(1−σ) e^{y} + ½(1+σ) e^{−y};  ½(1−σ)e^{y} = c_plus e^{y−β}
        ch_sh = c_plus * np.exp(y - b) + 0.5 * (1.0 + sig) * np.exp(-y)
        return ch_sh - np.cos(y) + sig * np.sin(y)

    tip = raw(1.0)
    return lambda x: amplitude * raw(np.asarray(x, float) / L) / tip


# ----------------------------------------------------------------------------------------------
# motions L(t), v(t), v̇(t)
# ----------------------------------------------------------------------------------------------

class Motion:
    """Free length L(t), speed v(t) = L̇ and v̇(t); ``m(t)`` returns the triple."""

    def L(self, t):
        raise NotImplementedError

    def v(self, t):
        raise NotImplementedError

    def vdot(self, t):
        raise NotImplementedError

    def __call__(self, t):
        return self.L(t), self.v(t), self.vdot(t)


class ConstantSpeed(Motion):
    """L(t) = L0 + v (t − t0)."""

    def __init__(self, L0, v, t0=0.0):
        self.L0, self.speed, self.t0 = float(L0), float(v), float(t0)

    def L(self, t):
        return self.L0 + self.speed * (t - self.t0)

    def v(self, t):
        return self.speed + 0.0 * t

    def vdot(self, t):
        return 0.0 * t

    def __call__(self, t):
        return self.L0 + self.speed * (t - self.t0), self.speed, 0.0


class _TripleMotion(Motion):
    """A motion defined by ``__call__`` (t -> (L, v, v̇)); L, v and v̇ of arrays element-wise."""

    def _part(self, t, k):
        return np.vectorize(lambda s: self(s)[k])(t) if np.ndim(t) else self(t)[k]

    def L(self, t):
        return self._part(t, 0)

    def v(self, t):
        return self._part(t, 1)

    def vdot(self, t):
        return self._part(t, 2)


class SmoothStroke(_TripleMotion):
    """L goes from L0 (t ≤ t0) to L1 (t ≥ t1) along the C³ septic smoothstep
    s(τ) = 35τ⁴ − 84τ⁵ + 70τ⁶ − 20τ⁷ (v, v̇, v̈ vanish at both ends); peak speed 35/16 (L1−L0)/(t1−t0)."""

    def __init__(self, L0, L1, t0, t1):
        self.L0, self.L1, self.t0, self.t1 = float(L0), float(L1), float(t0), float(t1)
        self.T = self.t1 - self.t0

    def __call__(self, t):
        tau = min(max((t - self.t0) / self.T, 0.0), 1.0)
        d = self.L1 - self.L0
        s = tau**4 * (35 + tau * (-84 + tau * (70 - 20 * tau)))
        ds = tau**3 * (140 + tau * (-420 + tau * (420 - 140 * tau))) / self.T
        dds = tau**2 * (420 + tau * (-1680 + tau * (2100 - 840 * tau))) / self.T**2
        return self.L0 + d * s, d * ds, d * dds


class RampToSpeed(_TripleMotion):
    """Starts at rest with length L0 at t0, reaches the speed v smoothly at t0 + t_ramp (speed profile
    v·s(τ), s the C³ septic smoothstep) and keeps it: L = L0 + v t_ramp (7τ⁵ − 14τ⁶ + 10τ⁷ − 5τ⁸/2)
    during the ramp, L0 + v t_ramp/2 + v (t − t0 − t_ramp) after it."""

    def __init__(self, L0, v, t0=0.0, t_ramp=1.0):
        self.L0, self.speed, self.t0, self.tr = float(L0), float(v), float(t0), float(t_ramp)

    def __call__(self, t):
        u = (t - self.t0) / self.tr
        V, tr = self.speed, self.tr
        if u <= 0:
            return self.L0, 0.0, 0.0
        if u >= 1:
            return self.L0 + V * tr * (0.5 + (u - 1.0)), V, 0.0
        iS = u**5 * (7 + u * (-14 + u * (10 - 2.5 * u)))
        S = u**4 * (35 + u * (-84 + u * (70 - 20 * u)))
        dS = u**3 * (140 + u * (-420 + u * (420 - 140 * u)))
        return self.L0 + V * tr * iS, V * S, V * dS / tr


class CallableMotion(Motion):
    """Wraps user callables L(t), v(t) (= L̇), v̇(t)."""

    def __init__(self, L, v, vdot):
        self._L, self._v, self._vd = L, v, vdot

    def L(self, t):
        return self._L(t)

    def v(self, t):
        return self._v(t)

    def vdot(self, t):
        return self._vd(t)


def _motion(L, v, vdot):
    if isinstance(L, Motion):
        if v is not None or vdot is not None:
            raise ValueError("give either a Motion or the callables L, v, vdot")
        return L
    if v is None or vdot is None:
        raise ValueError("L as a callable needs the callables v = L̇ and vdot")
    return CallableMotion(L, v, vdot)


# ----------------------------------------------------------------------------------------------
# discretisations: each maps the state to values of w, w_ξ, w_ξξ on given ξ and provides the ODE
# ----------------------------------------------------------------------------------------------

class _Galerkin:
    """Legendre-based clamped polynomial Galerkin basis, in the orthonormal modal coordinates q."""

    def __init__(self, n):
        if n < 1:
            raise ValueError("modes must be ≥ 1")
        self.n = n
        # φ_k(ξ) = F_k(2ξ−1)/4·√(2k+1) with F_k'' = P_k, F_k(−1) = F_k'(−1) = 0  ⇒ φ_k'' = √(2k+1) P_k(2ξ−1)
        self._F = [_leg.Legendre.basis(k).integ(2, lbnd=-1) * (np.sqrt(2 * k + 1) / 4.0) for k in range(n)]
        xg, wg = _leg.leggauss(n + 6)
        xi, wq = 0.5 * (xg + 1), 0.5 * wg
        P0, P1, P2 = (self._phi(xi, d) for d in range(3))
        M = (P0 * wq) @ P0.T
        S = (P2 * wq) @ P2.T
        G = (P0 * wq * (1 - xi)) @ P1.T
        H = (P0 * wq * (1 - xi) ** 2) @ P2.T
        P = (P1 * wq * (1 - xi)) @ P1.T
        f = P0 @ wq
        # S = I up to round-off ⇒ generalised problem S x = λ M x reduces to the eigen-decomposition of M
        assert np.allclose(S, np.eye(n), atol=1e-11)
        mu, U = np.linalg.eigh(M)
        self.Phi = U / np.sqrt(mu)                    # ΦᵀMΦ = I, ΦᵀSΦ = diag(1/μ)
        self.lam = 1.0 / mu
        order = np.argsort(self.lam)
        self.lam, self.Phi = self.lam[order], self.Phi[:, order]
        T = lambda X: self.Phi.T @ X @ self.Phi
        self.G, self.H, self.P = T(G), T(H), T(P)
        self.f = self.Phi.T @ f
        self.M_raw = M

    def _phi(self, xi, d):
        """Rows φ_k^(d)(ξ) of the raw basis."""
        y = 2.0 * np.asarray(xi, float) - 1.0
        return np.array([F.deriv(d)(y) * 2.0**d if d else F(y) for F in self._F])

    def values(self, xi, d):
        """(len ξ) × n matrix mapping q to ∂_ξ^d w at ξ."""
        return self._phi(np.atleast_1d(xi), d).T @ self.Phi

    def project(self, values_at):
        """Coefficients q of the L² projection of the function ξ ↦ values_at(ξ)."""
        xg, wg = _leg.leggauss(self.n + 40)
        xi, wq = 0.5 * (xg + 1), 0.5 * wg
        return self.values(xi, 0).T @ (wq * values_at(xi))   # ΦᵀMΦ = I

    def system(self, kappa, g, axial):
        """Return (K(L, v, v̇), C(L, v), F) of q'' + C q' + K q = F."""
        n, lam, G, H, P = self.n, self.lam, self.G, self.H, self.P
        F = -g * self.f

        def KC(L, v, vd):
            K = (vd / L - 2 * v * v / L**2) * G + (v * v / L**2) * H
            if axial:
                K = K - (vd / L) * P
            K[np.diag_indices(n)] += kappa / L**4 * lam
            return K, (2 * v / L) * G

        def accel(L, v, vd, q, qd):
            a = F - (kappa / L**4) * lam * q - G @ ((vd / L - 2 * v * v / L**2) * q + (2 * v / L) * qd) \
                - (v * v / L**2) * (H @ q)
            if axial:
                a += (vd / L) * (P @ q)
            return a

        self.accel = accel
        return KC, F


class _FiniteDifference:
    """Method of lines on the uniform grid ξ_i = i h, h = 1/N, unknowns w_1 … w_N (w_0 = 0), second-order
    central differences of the strong form, the boundary conditions by ghost points:
    w_{−1} = w_1 (w_ξ(0) = 0), w_{N+1} = 2w_N − w_{N−1} (w_ξξ(1) = 0),
    w_{N+2} = 4w_N − 4w_{N−1} + w_{N−2} (central w_ξξξ(1) = 0). The PDE is imposed at nodes 1 … N
    (the free end included). Symmetric stencils ⇒ error expansion in even powers of h (Richardson)."""

    sparse = True

    def __init__(self, N):
        import scipy.sparse as sps

        if N < 8:
            raise ValueError("points must be ≥ 8")
        self.N, self.n = N, N
        h = 1.0 / N
        self.xi = np.arange(N + 1) * h
        # extension: values at indices −2 … N+2 (position k ↔ index k − 2) from u = (w_1 … w_N)
        Ext = np.zeros((N + 5, N))
        for i in range(1, N + 1):
            Ext[i + 2, i - 1] = 1.0
        Ext[1, 0] = 1.0                                    # w_{−1} = w_1   (w_0 = 0: row 2 stays zero)
        Ext[N + 3] = 2 * Ext[N + 2] - Ext[N + 1]           # row 0 (w_{−2}) is never reached from nodes ≥ 1
        Ext[N + 4] = 4 * Ext[N + 2] - 4 * Ext[N + 1] + Ext[N]
        self._Ext = Ext
        st = {1: np.array([-0.5, 0.0, 0.5]) / h, 2: np.array([1.0, -2.0, 1.0]) / h**2,
              4: np.array([1.0, -4.0, 6.0, -4.0, 1.0]) / h**4}
        ops = {}
        for d, c in st.items():
            r = len(c) // 2
            Op = np.zeros((N, N + 5))
            for i in range(1, N + 1):
                Op[i - 1, i + 2 - r:i + 3 + r] = c
            ops[d] = Op @ Ext
        self.A1, self.A2, self.A4 = (sps.csr_matrix(ops[d]) for d in (1, 2, 4))
        self._ops = ops
        self.s = 1.0 - self.xi[1:]
        self._sps = sps

    def values(self, xi, d):
        xi = np.atleast_1d(np.asarray(xi, float))
        idx = np.rint(xi * self.N).astype(int)
        on = np.abs(idx - xi * self.N) < 1e-9
        out = np.zeros((len(xi), self.N))
        if d == 0:
            for r, (x, i, o) in enumerate(zip(xi, idx, on)):
                if o:
                    if i > 0:
                        out[r, i - 1] = 1.0
                else:                                      # linear interpolation off the grid
                    j = min(int(np.floor(x * self.N)), self.N - 1)
                    f = x * self.N - j
                    if j > 0:
                        out[r, j - 1] = 1 - f
                    out[r, j] = f
            return out
        if d not in self._ops or not on.all():
            raise NotImplementedError("finite differences: derivatives only at grid nodes (d = 1, 2, 4)")
        for r, i in enumerate(idx):
            if i == 0:
                raise NotImplementedError("finite differences: no derivative rows at ξ = 0")
            out[r] = self._ops[d][i - 1]
        return out

    def project(self, values_at):
        return values_at(self.xi[1:])

    def system(self, kappa, g, axial):
        s, A1, A2, A4, sps = self.s, self.A1, self.A2, self.A4, self._sps
        F = np.full(self.n, -g)
        S = sps.diags(s)

        def KC(L, v, vd):
            c = v * s / L
            alpha = (vd / L - 2 * v * v / L**2) * s
            K = sps.diags(alpha) @ A1 + sps.diags(c * c) @ A2 + (kappa / L**4) * A4
            if axial:
                K = K + (vd / L) * (S @ A2 - A1)
            return K, sps.diags(2.0 * c) @ A1

        def accel(L, v, vd, q, qd):   # F − K q − C q̇ without assembling K, C (the rhs' hot path)
            c = v * s / L
            d1, d2 = A1 @ q, A2 @ q
            a = F - (vd / L - 2 * v * v / L**2) * s * d1 - c * c * d2 - (kappa / L**4) * (A4 @ q) - 2.0 * c * (A1 @ qd)
            if axial:
                a -= (vd / L) * (s * d2 - d1)
            return a

        self.accel = accel
        return KC, F


# ----------------------------------------------------------------------------------------------
# solution object
# ----------------------------------------------------------------------------------------------

class Solution:
    """Result of ``solve``/``solve_fd``.

    Attributes: ``t`` (the t_eval), ``tip`` = w(L(t), t), ``L``, ``v``, ``vdot`` at t, ``q``, ``qd``
    (state: Galerkin modal coordinates or the grid values w_1 … w_N, and their rates at fixed ξ),
    ``sol`` (the OdeResult; ``sol.sol`` is the dense output), ``nfev``, ``params``."""

    def __init__(self, disc, motion, ode, params, axial):
        self._d, self.motion, self.sol, self.params, self.axial_inertia = disc, motion, ode, params, axial
        n = disc.n
        self.t = ode.t
        self.q, self.qd = ode.y[:n], ode.y[n:]
        trip = np.array([motion(s) for s in self.t]).T.reshape(3, -1)
        self.L, self.v, self.vdot = trip
        self.tip = (disc.values(1.0, 0) @ self.q)[0]
        self.nfev = ode.nfev

    def _state(self, t):
        i = np.flatnonzero(self.t == t)
        y = self.sol.y[:, i[0]] if len(i) else self.sol.sol(t)
        n = self._d.n
        return y[:n], y[n:]

    def w(self, x, t):
        """Deflection w(x, t), x in [0, L(t)] (array)."""
        q, _ = self._state(t)
        L = self.motion(t)[0]
        return self._d.values(np.asarray(x, float) / L, 0) @ q

    def tip_at(self, t):
        q, _ = self._state(t)
        return (self._d.values(1.0, 0) @ q)[0]

    def _quad(self):
        if not hasattr(self, "_qcache"):
            xg, wg = _leg.leggauss(2 * self._d.n + 20)
            xi = 0.5 * (xg + 1)
            self._qcache = (xi, 0.5 * wg, *(self._d.values(xi, d) for d in range(3)), self._d.values(0.0, 2)[0])
        return self._qcache

    def _states(self, t):
        if t is None:
            return self.t, self.q, self.qd
        ts = np.atleast_1d(np.asarray(t, float))
        Y = np.column_stack([np.r_[self._state(s)] for s in ts])
        return ts, Y[:self._d.n], Y[self._d.n:]

    def energy(self, t=None):
        """E = ∫₀ᴸ [½ρA (Dw/Dt)² + ½EI w_xx² + ρAg w] dx at the times t (default: all output times)."""
        E, I, rho, A, g = self.params
        ts, q, qd = self._states(t)
        xi, wq, V0, V1, V2, _ = self._quad()
        L, v, _ = np.array([self.motion(s) for s in ts]).T
        u = V0 @ qd + (1 - xi)[:, None] * (v / L) * (V1 @ q)      # Dw/Dt = w_t|ξ + c w_ξ
        dens = 0.5 * rho * A * u**2 + 0.5 * E * I * (V2 @ q) ** 2 / L**4 + rho * A * g * (V0 @ q)
        out = L * (wq @ dens)
        return out if t is None or np.ndim(t) else out[0]

    def power(self, t=None):
        """dE/dt from the balance: −½ v EI w_xx(0)² (+ ρA v̇ ∫(L−x) w_x u_x dx with axial inertia)."""
        E, I, rho, A, g = self.params
        ts, q, qd = self._states(t)
        xi, wq, V0, V1, V2, r0 = self._quad()
        L, v, vd = np.array([self.motion(s) for s in ts]).T
        p = -0.5 * v * E * I * ((r0 @ q) / L**2) ** 2
        if self.axial_inertia:
            w_xi = V1 @ q
            s_ = (1 - xi)[:, None]
            u_xi = V1 @ qd + (v / L) * (s_ * (V2 @ q) - w_xi)          # ∂_ξ(w_t|ξ + c w_ξ)
            p = p + rho * A * vd * (wq @ (s_ * w_xi * u_xi))
        return p if t is None or np.ndim(t) else p[0]

    def static_tip(self):
        """−ρAgL(t)⁴/(8EI) at the output times."""
        E, I, rho, A, g = self.params
        return static_deflection(E, I, rho, A, g, self.L)


# ----------------------------------------------------------------------------------------------
# drivers
# ----------------------------------------------------------------------------------------------

def _run(disc, E, I, rho, A, g, L, v, vdot, t_span, t_eval, w0, wdot0, axial_inertia, method, rtol, atol):
    motion = _motion(L, v, vdot)
    t0, t1 = map(float, t_span)
    if t_eval is None:
        t_eval = np.linspace(t0, t1, 201)
    t_eval = np.asarray(t_eval, float)
    kappa = E * I / (rho * A)
    n = disc.n
    L0, v0, _ = motion(t0)

    # initial deflection (function of ξ at t0) and Eulerian rate
    KC, F = disc.system(kappa, g, axial_inertia)
    static = w0 is None or (isinstance(w0, str) and w0 == "static")
    if static:   # the discrete model's own equilibrium at L(t0), v = 0 (Galerkin: exact static deflection)
        K0, _ = KC(L0, 0.0, 0.0)
        q_static = np.linalg.solve(K0.toarray() if hasattr(K0, "toarray") else K0, F)
        w0f = lambda xi: disc.values(xi, 0) @ q_static
    elif isinstance(w0, tuple) and len(w0) == 3 and w0[0] == "mode":
        # the discrete model's own k-th natural mode at L(t0), v = 0, scaled to the tip value w0[2]
        K0, _ = KC(L0, 0.0, 0.0)
        K0 = K0.toarray() if hasattr(K0, "toarray") else K0
        lam, vec = np.linalg.eig(K0)
        k = np.argsort(lam.real)[int(w0[1]) - 1]
        shape = vec[:, k].real
        q_mode = shape * (w0[2] / (disc.values(1.0, 0) @ shape)[0])
        w0f = lambda xi: disc.values(xi, 0) @ q_mode
    elif isinstance(w0, str) and w0 in ("rest", "zero"):
        w0f = lambda xi: 0.0 * xi
    elif callable(w0):
        w0f = lambda xi: np.asarray(w0(xi * L0), float) + 0.0 * xi
    else:
        raise ValueError("w0 must be None, 'static', 'rest'/'zero', ('mode', k, tip) or a callable w0(x)")
    q0 = q_static if static else q_mode if isinstance(w0, tuple) else disc.project(w0f)
    wx0 = lambda xi: disc.values(xi, 1) @ q0                      # w_ξ of the projected shape
    wd = (lambda xi: 0.0 * xi) if wdot0 is None else (lambda xi: np.asarray(wdot0(xi * L0), float) + 0.0 * xi)
    qd0 = disc.project(lambda xi: wd(xi) + xi * (v0 / L0) * wx0(xi))   # w_t|ξ = w_t|x + ξ (v/L) w_ξ

    accel = getattr(disc, "accel", None)

    def rhs(t, y):
        Lt, vt, vdt = motion(t)
        if accel is not None:
            return np.concatenate([y[n:], accel(Lt, vt, vdt, y[:n], y[n:])])
        K, C = KC(Lt, vt, vdt)
        return np.concatenate([y[n:], F - K @ y[:n] - C @ y[n:]])

    if getattr(disc, "sparse", False):
        import scipy.sparse as sps

        Id = sps.identity(n, format="csr")

        def jac(t, y):
            K, C = KC(*motion(t))
            return sps.bmat([[None, Id], [-K, -C]], format="csc")
    else:
        Z, Id = np.zeros((n, n)), np.eye(n)

        def jac(t, y):
            K, C = KC(*motion(t))
            return np.block([[Z, Id], [-K, -C]])

    if atol is None:
        Ls = [motion(s)[0] for s in np.linspace(t0, t1, 51)]
        Lmin, Lmax = min(Ls), max(Ls)
        if Lmin <= 0:
            raise ValueError("L(t) must stay positive")
        W = max(abs(static_deflection(E, I, rho, A, g, Lmax)),
                np.max(np.abs(disc.values(np.linspace(0, 1, 21), 0) @ q0)),
                np.max(np.abs(disc.values(np.linspace(0, 1, 21), 0) @ qd0)) / (3.5 * np.sqrt(kappa) / Lmax**2),
                1e-300)
        om = 3.516 * np.sqrt(kappa) / Lmin**2
        atol = np.r_[np.full(n, rtol * W), np.full(n, rtol * W * om)]
    kw = dict(jac=jac) if method in ("Radau", "BDF", "LSODA") else {}
    ode = solve_ivp(rhs, (t0, t1), np.r_[q0, qd0], method=method, rtol=rtol, atol=atol, t_eval=t_eval,
                    dense_output=True, **kw)
    if not ode.success:
        raise RuntimeError(ode.message)
    return Solution(disc, motion, ode, (E, I, rho, A, g), axial_inertia)


def solve(E, I, rho, A, g, L, v=None, vdot=None, t_span=(0.0, 1.0), t_eval=None, modes=8, w0=None,
          axial_inertia=False, wdot0=None, method="Radau", rtol=1e-10, atol=None):
    """Galerkin reference solution (see the module docstring).

    ``L`` is a ``Motion`` or a callable L(t) with callables ``v`` = L̇ and ``vdot``; ``modes`` the
    number of polynomial shape functions; ``w0`` None/"static" | "rest" | callable w0(x);
    ``wdot0`` None | callable (∂w/∂t at fixed x). Returns a ``Solution`` (``.tip`` over ``.t``,
    ``.w(x, t)``, ``.energy(t)``, ``.power(t)``)."""
    return _run(_Galerkin(int(modes)), E, I, rho, A, g, L, v, vdot, t_span, t_eval, w0, wdot0, axial_inertia,
                method, rtol, atol)


def solve_fd(E, I, rho, A, g, L, v=None, vdot=None, t_span=(0.0, 1.0), t_eval=None, points=40, w0=None,
             axial_inertia=False, wdot0=None, method="Radau", rtol=1e-8, atol=None):
    """Independent check: finite differences (method of lines) of the strong form on ``points``
    intervals of ξ ∈ [0, 1] (second order in h = 1/points). Same arguments and result as ``solve``
    (``Solution.w`` interpolates linearly; ``energy``/``power`` are not available). rtol defaults to
    1e-8: the 1/h⁴ stencil loses ~8 digits to cancellation, tighter tolerances only stall Radau."""
    return _run(_FiniteDifference(int(points)), E, I, rho, A, g, L, v, vdot, t_span, t_eval, w0, wdot0, axial_inertia,
                method, rtol, atol)


def solve_fd_extrapolated(*args, points=(20, 40, 80), **kw):
    """Tip deflection by ``solve_fd`` on the grids ``points`` (each twice the previous) and repeated
    Richardson extrapolation (errors ∝ h², h⁴, …). Returns (t, tip_extrapolated, [tip on each grid])."""
    tips, t = [], None
    for N in points:
        s = solve_fd(*args, points=N, **kw)
        tips.append(s.tip)
        t = s.t
    table = [list(tips)]
    for level in range(1, len(tips)):
        f = 4.0**level
        prev = table[-1]
        table.append([(f * prev[i + 1] - prev[i]) / (f - 1) for i in range(len(prev) - 1)])
    return t, table[-1][0], tips


def galerkin_frequencies(E, I, rho, A, L, modes=8, n=3):
    """Lowest n natural frequencies (rad/s) of the Galerkin model at rest (v = 0)."""
    return np.sqrt(_Galerkin(int(modes)).lam[:n] * E * I / (rho * A * L**4))


# ----------------------------------------------------------------------------------------------
# symbolic check of the coordinate transformation
# ----------------------------------------------------------------------------------------------

def derive_transformed_operator():
    """SymPy: for w(x, t) = W(ξ, t), ξ = x/L(t), W = a(t) ξ^p (p symbolic, hence by linearity any
    power series), return (eulerian, transformed) expressions of D²w/Dt² (in terms of ξ) whose
    difference simplifies to 0, plus the transformed axial term check. Returns a dict."""
    import sympy as sp

    x, t, xi, p = sp.symbols("x t xi p", positive=True)
    Lf, af = sp.Function("L")(t), sp.Function("a")(t)
    v = sp.diff(Lf, t)
    vd = sp.diff(Lf, t, 2)
    w = af * (x / Lf) ** p
    euler = sp.diff(w, t, 2) + 2 * v * sp.diff(w, x, t) + v**2 * sp.diff(w, x, 2) + vd * sp.diff(w, x)
    W = af * xi**p
    c = v * (1 - xi) / Lf
    transformed = (sp.diff(W, t, 2) + 2 * c * sp.diff(W, xi, t)
                   + (vd / Lf - 2 * v**2 / Lf**2) * (1 - xi) * sp.diff(W, xi)
                   + (v**2 / Lf**2) * (1 - xi) ** 2 * sp.diff(W, xi, 2))
    diff_acc = sp.simplify(sp.expand(euler.subs(x, xi * Lf) - transformed))
    # axial term −(N w_x)_x / (ρA) with N = −ρA v̇ (L − x) against (v̇/L)[(1−ξ)W_ξξ − W_ξ]
    ax_euler = sp.diff(vd * (Lf - x) * sp.diff(w, x), x)
    ax_trans = (vd / Lf) * ((1 - xi) * sp.diff(W, xi, 2) - sp.diff(W, xi))
    diff_ax = sp.simplify(sp.expand(ax_euler.subs(x, xi * Lf) - ax_trans))
    return {"eulerian": euler, "transformed": transformed, "difference": diff_acc, "axial_difference": diff_ax}
