"""Slider-crank with a flexible connecting rod (issue 11): rigidfem's closed loop with an RFEM rod
against an independent, converged reference computed here with SciPy.

The mechanism, planar (x–y), gravity off:

- crank: rigid, length R = 0.15 m, pinned to the ground at the origin, its angle prescribed by
  Kane's spin-up θ(t) = (Ω/T)[t²/2 + (T/2π)²(cos 2πt/T − 1)] to Ω = 50 rad/s over T = 0.2 s, then
  constant speed (θ(0.45 s) = 17.5 rad: about two revolutions at full speed);
- connecting rod: an elastic aluminium strip, L = 0.6 m, E = 70 GPa, ρ = 2700 kg/m³, 5 mm wide in
  the plane of motion and 20 mm deep (A = 1e-4 m², I = 2.08e-10 m⁴): first bending frequency of
  the pinned–pinned rod 201.5 rad/s, four times the crank speed; pinned to the crank at one end and
  to the slider at the other;
- slider: 0.1 kg on a prismatic guide along x through the crank's pivot.

Outputs over 0 ≤ t ≤ 0.45 s: the rod's midpoint deflection from its chord (crank pin to slider pin;
peak 6.6 mm), the slider position (the rod's foreshortening moves it up to 0.18 mm off the rigid
mechanism's), the slider pin's force on the rod (peak 47 N) and the crank's driving torque (peak
8.1 N·m).

The reference (no rigidfem): the rod as a geometrically exact, inextensible Euler–Bernoulli beam
with rotary inertia (the continuum the RFEM rod converges to), described by its tangent angle
φ(s, t) = Σ_k a_k(t) P_k(2s/L − 1) (Legendre polynomials, k = 0..N, a global Ritz basis) with the
centre line r(s) = r_A(t) + ∫₀ˢ (cos φ, sin φ) dσ hanging on the crank pin r_A. Bending energy
½ ∫ EI φ'² ds is exact (zero moment at the pins is the natural boundary condition); inertia by the
virtual work ∫ ρA δr·r̈ ds + ∫ ρI δφ φ̈ ds + m_s δx_B ẍ_B with δr(s) = ∫₀ˢ e⊥ δφ dσ and
r̈(s) = r̈_A + ∫₀ˢ (e⊥ φ̈ − e φ̇²) dσ, integrated spectrally (Gauss–Legendre nodes and an exact
cumulative-integration matrix of the interpolating polynomial); the slider pin's y_B = 0 is a
constraint with a multiplier (index 1, Baumgarte-stabilised; its residual stays at 1e-15 m).
DOP853 at rtol 1e-8. Converged in N (largest difference over the run against N = 10, measured):
midpoint deflection N = 5: 2.3e-8 m, 6: 2.7e-8 m, 7: 1.7e-10 m, 8: 1.7e-10 m; slider position
8.5e-10, 8.4e-11, 1.3e-12, 3e-13 m; N = 7 against N = 9: pin force 2.2e-5 N, torque 3.0e-6 N·m;
DOP853 at rtol 1e-11 instead of 1e-8 changes N = 7 by 1e-14 m. The tests use N = 7 (4 s).

RFEM model: crank (rigid, prescribed), rod = ``add_beam`` on the crank through a revolute joint
(modified formulation, ``deform=("bend_z",)``; the classical one with the same deformation gives
the same answers), slider on a prismatic joint on the ground, and a revolute loop joint closing
the slider pin (3 of its 5 rows redundant in the plane). dopri5 at rtol 1e-8 (1e-7 at m = 32),
whose own error is below 1e-11 m. Largest error over the run against the reference (measured;
ratio to the previous m):

===  ================  =====  ==============  =====  ==============  =====  ===============  =====
m    deflection (m)    ratio  slider (m)      ratio  pin force (N)   ratio  torque (N·m)     ratio
===  ================  =====  ==============  =====  ==============  =====  ===============  =====
4    2.12e-4                  9.87e-6                1.01e-1                9.70e-3
8    5.27e-5           4.03   2.29e-6         4.31   2.34e-2         4.32   2.31e-3          4.20
16   1.31e-5           4.006  5.63e-7         4.07   5.73e-3         4.08   5.85e-4          3.95
32   3.29e-6           4.002  1.40e-7         4.02   1.43e-3         4.00   1.48e-4          3.95
===  ================  =====  ==============  =====  ==============  =====  ===============  =====

Loop closure at every output: |g| ≤ 1.3e-13 m, |ġ| ≤ 7e-15 m/s (m ≤ 16). Run times (2 cores, loaded): reference
4 s, m = 4, 8, 16: 0.1, 0.4, 2 s; m = 32: 16 s (marked slow with the reference's convergence study:
``pytest -m slow tests/test_slider_crank.py``).
"""

import math

import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy.integrate import solve_ivp

import rigidfem as rf

R, L = 0.15, 0.6                      # crank and rod lengths (m)
E, RHO = 70e9, 2700.0                 # aluminium (Pa, kg/m³)
WIDTH, DEPTH = 0.005, 0.02            # rod section: width in the plane of motion (along y), depth (z) (m)
AREA = WIDTH * DEPTH                  # m²
I_BEND = DEPTH * WIDTH**3 / 12        # second moment for bending in the x–y plane (m⁴)
M_SLIDER = 0.1                        # kg
OMEGA, T_SPIN = 50.0, 0.2             # crank speed (rad/s) reached after the spin-up time (s)
T_END = 0.45                          # s
T_OUT = np.linspace(0.0, T_END, 91)   # output times (s)
N_REF = 7                             # Legendre degree of the reference's angle field
CRANK_MASS, CRANK_INERTIA_C = 1.0, 2e-3  # crank: kg, kg·m² about its centre (at R/2)
CRANK_INERTIA = CRANK_INERTIA_C + CRANK_MASS * (R / 2) ** 2  # about the pivot, kg·m²


def crank_angle(t):
    """Kane's spin-up θ(t), θ̇, θ̈ (rad, rad/s, rad/s²), written out here."""
    if t < T_SPIN:
        c = 2 * math.pi / T_SPIN
        return (OMEGA / T_SPIN * (t * t / 2 + (math.cos(c * t) - 1) / (c * c)),
                OMEGA / T_SPIN * (t - math.sin(c * t) / c), OMEGA / T_SPIN * (1 - math.cos(c * t)))
    return OMEGA * (t - T_SPIN / 2), OMEGA, 0.0


def chord_deflection(a, mid, b):
    """Signed distance (m) of the midpoint ``mid`` from the chord a → b (arrays (n, 2 or 3))."""
    chord = b[:, :2] - a[:, :2]
    rel = mid[:, :2] - a[:, :2]
    return (chord[:, 0] * rel[:, 1] - chord[:, 1] * rel[:, 0]) / np.linalg.norm(chord, axis=1)


def _legendre(x, n):
    """P_k(x) and P_k'(x), k < n, at the points x: two (len(x), n) arrays."""
    P, dP = np.zeros((len(x), n)), np.zeros((len(x), n))
    for k in range(n):
        c = np.zeros(n)
        c[k] = 1.0
        P[:, k], dP[:, k] = legendre.legval(x, c), legendre.legval(x, legendre.legder(c))
    return P, dP


class AngleFieldRod:
    """The reference: inextensible planar Euler–Bernoulli rod (with rotary inertia) in terms of its
    tangent angle φ(s) = Σ a_k P_k(2s/L − 1), k = 0..N, pinned to the crank at s = 0 and to the
    slider (y_B = 0, mass M_SLIDER along x) at s = L. State y = (a, ȧ)."""

    def __init__(self, N, nodes=None, baumgarte=200.0):
        n = self.n = N + 1
        ng = self.ng = nodes or max(2 * N + 16, 32)
        x, w = legendre.leggauss(ng)
        self.w = w * L / 2                                       # Gauss weights on [0, L]
        Pg, _ = _legendre(x, ng + 1)
        # Cumulative integration: ∫_{-1}^{x_i} of the polynomial interpolating f at the nodes, from
        # ∫_{-1}^x P_0 = x + 1, ∫_{-1}^x P_k = (P_{k+1} − P_{k−1})/(2k + 1), and the discrete
        # orthogonality of the P_k at the Gauss nodes (the inverse Vandermonde).
        W = np.zeros((ng, ng))
        W[:, 0] = x + 1
        for k in range(1, ng):
            W[:, k] = (Pg[:, k + 1] - Pg[:, k - 1]) / (2 * k + 1)
        to_coefficients = ((2 * np.arange(ng) + 1) / 2)[:, None] * (Pg[:, :ng].T * w[None, :])
        self.Q = np.vstack([W @ to_coefficients * (L / 2), self.w])  # rows: ∫₀^{s_i}, then ∫₀^L
        self.Psi, dPsi = _legendre(x, n)
        dPsi = dPsi * (2 / L)
        self.K = E * I_BEND * (dPsi.T * self.w) @ dPsi           # ∫ EI φ'² = aᵀ K a
        self.M_rot = RHO * I_BEND * (self.Psi.T * self.w) @ self.Psi  # ∫ ρI φ̇² = ȧᵀ M_rot ȧ
        self.rho_w = (RHO * AREA * self.w)[:, None]
        self.beta = baumgarte
        self._integrand = np.empty((ng, 2 * n + 2))

    def _equations(self, t, y):
        """The augmented system [[M, −Gᵀ], [G, 0]] (ä, λ) = (F, γ) at (t, y); λ is the guide's force
        (N, along y) on the rod's end."""
        n, ng = self.n, self.ng
        a, ad = y[:n], y[n:]
        th, thd, thdd = crank_angle(t)
        c0, s0 = math.cos(th), math.sin(th)
        acc_A = (R * (-thdd * s0 - thd * thd * c0), R * (thdd * c0 - thd * thd * s0))
        phi, phid = self.Psi @ a, self.Psi @ ad
        c, s = np.cos(phi), np.sin(phi)
        p2 = phid * phid
        f = self._integrand  # [e⊥ ⊗ Ψ (x row, y row), −e φ̇²]
        np.multiply(self.Psi, -s[:, None], out=f[:, :n])
        np.multiply(self.Psi, c[:, None], out=f[:, n:2 * n])
        np.multiply(c, -p2, out=f[:, 2 * n])
        np.multiply(s, -p2, out=f[:, 2 * n + 1])
        integral = self.Q @ f
        J = integral[:ng, :2 * n]                          # ∂r(s_i)/∂a: x rows | y rows
        acc = integral[:ng, 2 * n:] + acc_A                # r̈(s_i) at ä = 0
        JL, accL = integral[ng, :2 * n], integral[ng, 2 * n:] + acc_A
        Jw = J * self.rho_w
        MM = Jw.T @ J
        Jx_B, Jy_B = JL[:n], JL[n:]
        aug = np.zeros((n + 1, n + 1))
        aug[:n, :n] = MM[:n, :n] + MM[n:, n:] + self.M_rot + M_SLIDER * np.multiply.outer(Jx_B, Jx_B)
        aug[:n, n], aug[n, :n] = -Jy_B, Jy_B
        rhs = np.empty(n + 1)
        rhs[:n] = -(self.K @ a) - Jw[:, :n].T @ acc[:, 0] - Jw[:, n:].T @ acc[:, 1] - M_SLIDER * accL[0] * Jx_B
        y_B = R * s0 + self.w @ s
        v_B = R * thd * c0 + Jy_B @ ad
        rhs[n] = -accL[1] - 2 * self.beta * v_B - self.beta**2 * y_B
        return aug, rhs, Jx_B, accL

    def rhs(self, t, y):
        aug, rhs, _, _ = self._equations(t, y)
        out = np.empty(2 * self.n)
        out[:self.n] = y[self.n:]
        out[self.n:] = np.linalg.solve(aug, rhs)[:self.n]
        return out

    def reactions(self, t, y):
        """The slider's force on the rod's end (N, (x, y)): −m_s ẍ_B and the guide's λ; and the crank's
        driving torque (N·m): I_O θ̈ + (r_A × F_A)_z, where F_A = ∫ ρA r̈ ds − F_B is the crank's force
        on the rod (the rod's momentum balance)."""
        aug, rhs, Jx_B, accL = self._equations(t, y)
        sol = np.linalg.solve(aug, rhs)
        add = sol[:self.n]
        F_B = np.array([-M_SLIDER * (accL[0] + Jx_B @ add), sol[self.n]])
        n, ng = self.n, self.ng
        integral = self.Q @ self._integrand  # as left by _equations at this state
        th, thd, thdd = crank_angle(t)
        acc_A = np.array([R * (-thdd * math.sin(th) - thd * thd * math.cos(th)),
                          R * (thdd * math.cos(th) - thd * thd * math.sin(th))])
        acc = integral[:ng, 2 * n:] + acc_A + np.stack([integral[:ng, :n] @ add, integral[:ng, n:2 * n] @ add], 1)
        F_A = self.rho_w[:, 0] @ acc - F_B
        torque = CRANK_INERTIA * thdd + R * (math.cos(th) * F_A[1] - math.sin(th) * F_A[0])
        return F_B, torque

    def point(self, t, a, s):
        """Position (2,) of the centre line at arc length s (m), by Gauss–Legendre on [0, s]."""
        x, w = legendre.leggauss(40)
        sg = s * (x + 1) / 2
        phi = _legendre(2 * sg / L - 1, self.n)[0] @ a
        th = crank_angle(t)[0]
        return R * np.array([math.cos(th), math.sin(th)]) + s / 2 * np.array([w @ np.cos(phi), w @ np.sin(phi)])

    def frequencies(self, count=3):
        """Linearised bending frequencies (rad/s) about the straight rod, crank at rest at θ = 0."""
        import scipy.linalg

        aug, _, _, _ = self._equations(0.0, np.zeros(2 * self.n))
        M, G = aug[:self.n, :self.n], aug[self.n, :self.n][None, :]
        Z = scipy.linalg.null_space(G)
        w2 = scipy.linalg.eigh(Z.T @ self.K @ Z, Z.T @ M @ Z, eigvals_only=True)
        return np.sqrt(w2[:count])


def reference_run(N=N_REF, rtol=1e-8, atol=1e-10):
    """(midpoint deflection (m), slider x (m), slider's force on the rod (N, (len, 2)), crank torque (N·m),
    max |y_B| (m)) of the reference at T_OUT."""
    rod = AngleFieldRod(N)
    sol = solve_ivp(rod.rhs, (0.0, T_END), np.zeros(2 * rod.n), method="DOP853", rtol=rtol, atol=atol,
                    t_eval=T_OUT)
    assert sol.success, sol.message
    pts = np.array([[rod.point(t, y[:rod.n], s) for s in (0.0, L / 2, L)] for t, y in zip(sol.t, sol.y.T)])
    forces, torques = zip(*(rod.reactions(t, y) for t, y in zip(sol.t, sol.y.T)))
    return (chord_deflection(pts[:, 0], pts[:, 1], pts[:, 2]), pts[:, 2, 0], np.array(forces), np.array(torques),
            np.abs(pts[:, 2, 1]).max())


@pytest.fixture(scope="module")
def reference():
    return reference_run()


def slider_crank(m, formulation="modified"):
    """The RFEM slider-crank with m sdes (m + 1 rfes) in the rod: (system, rod, slider)."""
    model = rf.Model(gravity=None)
    crank = model.add_body("crank", model.ground, rf.Joint.revolute("z"), mass=CRANK_MASS, com=(R / 2, 0, 0),
                           inertia=(1e-4, CRANK_INERTIA_C, CRANK_INERTIA_C))
    model.prescribe(crank, rf.motion.spin_up(OMEGA, T_SPIN))
    rod = model.add_beam("rod", crank, L, rf.Material(E=E, rho=RHO), rf.Section.rectangle(width=WIDTH, height=DEPTH),
                         elements=m, formulation=formulation, deform=("bend_z",), joint=rf.Joint.revolute("z"),
                         placement=rf.transform((R, 0, 0)))
    slider = model.add_body("slider", model.ground, rf.Joint.prismatic("x"), mass=M_SLIDER, inertia=(1e-5, 1e-5, 1e-5))
    model.add_loop_joint("slider pin", "revolute", slider, rod.tip)  # reaction: on the rod, in global axes
    return model.compile(), rod, slider


_runs = {}


def rfem_run(m, formulation="modified", rtol=1e-8, atol=1e-10):
    """(midpoint deflection (m), slider x (m), slider's force on the rod (N, (len, 2)), crank torque (N·m),
    largest closure residuals (|g|, |ġ|), wall time (s)) of the RFEM model at T_OUT."""
    key = (m, formulation, rtol, atol)
    if key not in _runs:
        system, rod, slider = slider_crank(m, formulation)
        guess = np.zeros(system.nq)
        guess[system.coordinate_index("slider.x")] = R + L     # dead centre, rod straight
        q0, qd0 = system.assemble(guess, t=0.0)
        res = rf.simulate(system, T_END, method="dopri5", rtol=rtol, atol=atol, q0=q0, qd0=qd0, t_eval=T_OUT,
                          stiffness_warning=False)
        d = chord_deflection(res.position(rod.point(0.0)), res.position(rod.point(L / 2)), res.position(rod.tip))
        closure = np.array([[np.abs(v).max() for v in system.loop_constraints(t, q, qd)[:2]]
                            for t, q, qd in zip(res.t, res.q, res.qd)])
        _runs[key] = (d, res.q[:, system.coordinate_index("slider.x")], res.loop_reactions[:, 0, :2],
                      res.driving_forces[:, 0], closure.max(axis=0), res.stats["wall_time"])
    return _runs[key]


def test_reference_is_a_pinned_rayleigh_beam_and_closes_the_guide(reference):
    """The reference's own checks: its linearised frequencies converge spectrally in N to the simply
    supported Rayleigh beam's, ω_j² = EI k⁴/(ρA + ρI k²), k = jπ/L (measured relative errors of
    j = 1, 2, 3: N = 7: 2e-11, 2e-5, 2e-4; N = 10: 1e-15, 1e-11, 1e-6; N = 14: all < 5e-12), so its
    stiffness and mass are the continuum's; the slider pin stays on the guide; the deflection is visible
    but moderate; the slider leaves the rigid mechanism's path (by the rod's foreshortening)."""
    k = np.arange(1, 4) * np.pi / L
    exact = np.sqrt(E * I_BEND * k**4 / (RHO * AREA + RHO * I_BEND * k**2))
    np.testing.assert_allclose(AngleFieldRod(14).frequencies(3), exact, rtol=1e-10)
    np.testing.assert_allclose(AngleFieldRod(N_REF).frequencies(1), exact[:1], rtol=1e-10)
    assert 3.5 < exact[0] / OMEGA < 4.5                     # first bending mode four times the crank speed
    d, x_B, force, torque, off_guide = reference
    assert off_guide < 1e-12
    assert 3e-3 < np.abs(d).max() < 1e-2                    # 6.6 mm: moderate, and well resolved
    th = np.array([crank_angle(t)[0] for t in T_OUT])
    rigid = R * np.cos(th) + np.sqrt(L * L - (R * np.sin(th)) ** 2)
    flexible = np.abs(x_B - rigid).max()
    assert 1e-5 < flexible < 1e-3


def test_rfem_rod_converges_to_the_reference_at_second_order(reference):
    """m = 4, 8, 16 sdes: the midpoint deflection's largest error over the run falls by 4 per doubling
    of m (measured 4.03, 4.006; m = 32: 4.002), the slider position, the pin force and the crank
    torque converge alike, and the loop stays closed at every output."""
    d_ref, x_ref, f_ref, tau_ref, _ = reference
    errors = []
    for m in (4, 8, 16):
        d, x_B, force, torque, closure, _ = rfem_run(m)
        errors.append((np.abs(d - d_ref).max(), np.abs(x_B - x_ref).max(), np.abs(force - f_ref).max(),
                       np.abs(torque - tau_ref).max()))
        assert closure[0] < 1e-10 and closure[1] < 1e-8
    errors = np.array(errors)
    ratios = errors[:-1] / errors[1:]
    assert np.all(ratios > 3.5) and np.all(ratios < 4.5), ratios
    # m = 16 (measured): 1.31e-5 m of the 6.6 mm peak deflection, 5.6e-7 m of the slider's travel
    # (the rod's foreshortening moves it by up to 1.8e-4 m), 5.7e-3 N of the 47 N pin force,
    # 5.8e-4 N·m of the 8.1 N·m crank torque.
    assert errors[-1, 0] < 2e-5
    assert errors[-1, 1] < 1e-6
    assert errors[-1, 2] < 1e-2
    assert errors[-1, 3] < 1e-3


def test_classical_formulation_gives_the_same_rod():
    """With bending the only deformation, the classical formulation's rod (each rfe turned about its sde)
    is the modified one's: the same history to the integrator's tolerance."""
    for m in (4, 8):
        modified, classical = rfem_run(m), rfem_run(m, "classical")
        np.testing.assert_allclose(classical[0], modified[0], rtol=0, atol=1e-11)
        np.testing.assert_allclose(classical[1], modified[1], rtol=0, atol=1e-11)


@pytest.mark.slow
def test_reference_converges_in_degree_and_tolerance(reference):
    """The reference at N = 7 against N = 5, N = 9 and N = 7 with DOP853 at rtol 1e-11: its own error is
    far below the RFEM errors it measures (1.3e-5 m at m = 16, 3.3e-6 m at m = 32)."""
    runs = {N: reference_run(N) for N in (5, 9)}
    runs["tight"] = reference_run(N_REF, rtol=1e-11, atol=1e-13)
    diff = {key: [np.abs(np.asarray(a) - np.asarray(b)).max() for a, b in zip(run[:4], reference[:4])]
            for key, run in runs.items()}
    print("reference differences from N = 7 (deflection m, slider m, pin force N, torque N m):", diff)
    assert diff[9][0] < 1e-9 and diff[9][1] < 1e-11 and diff[9][2] < 1e-4 and diff[9][3] < 1e-5
    assert diff["tight"][0] < 1e-10 and diff["tight"][1] < 1e-11
    assert diff[5][0] > 10 * diff[9][0]  # converging, not insensitive to N


@pytest.mark.slow
def test_rfem_rod_at_m32_stays_on_the_second_order_line(reference):
    """m = 32 (34 coordinates, about 30 s): the ratio of the m = 16 and m = 32 errors is still 4."""
    d_ref, x_ref = reference[:2]
    e16 = np.abs(rfem_run(16)[0] - d_ref).max()
    d32, x32, _, _, closure, _ = rfem_run(32, rtol=1e-7, atol=1e-9)
    e32 = np.abs(d32 - d_ref).max()
    print("m = 32: deflection error", e32, "ratio", e16 / e32, "slider error", np.abs(x32 - x_ref).max())
    assert 3.8 < e16 / e32 < 4.2
    assert e32 < 5e-6 and closure[0] < 1e-10
