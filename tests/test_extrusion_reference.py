"""Tests of the independent reference solver for a cantilever of time-varying free length
(tests/extrusion_reference.py): the rest limit, the quasi-static limit, an independent
finite-difference discretisation, convergence in the number of modes, and the energy balance
of the free part (spaghetti problem)."""

import numpy as np
import pytest
from numpy.polynomial import Polynomial
from scipy.integrate import cumulative_simpson

import extrusion_reference as er

STEEL = er.steel_tape()          # E, I, rho, A of the 20 mm × 2 mm steel tape
GRAV = 9.81
UNIT = (1.0, 1.0, 1.0, 1.0)      # nondimensional: EI = ρA = 1


def _rel(a, b, scale=None):
    a, b = np.asarray(a), np.asarray(b)
    return np.max(np.abs(a - b)) / (np.max(np.abs(b)) if scale is None else scale)


# ------------------------------------------------------------------------------------------------
# closed forms and the transformation
# ------------------------------------------------------------------------------------------------

def test_static_deflection_solves_the_cantilever_problem():
    E, I, rho, A = STEEL
    L = 0.65
    x = Polynomial([0.0, 1.0])
    c = -rho * A * GRAV / (24 * E * I)
    w = c * x**2 * (6 * L**2 - 4 * L * x + x**2)
    xs = np.linspace(0, L, 7)
    assert np.allclose(er.static_deflection(E, I, rho, A, GRAV, L, xs), w(xs), rtol=1e-14, atol=0)
    assert np.isclose(E * I * w.deriv(4)(0.3), -rho * A * GRAV, rtol=1e-12)        # EI w'''' = −ρAg
    assert abs(w(0)) == 0 and abs(w.deriv(1)(0)) == 0                                # clamped
    assert abs(w.deriv(2)(L)) < 1e-12 * abs(w.deriv(2)(0)) and abs(w.deriv(3)(L)) < 1e-12 * abs(w.deriv(3)(0))
    assert np.isclose(er.static_deflection(E, I, rho, A, GRAV, L), -rho * A * GRAV * L**4 / (8 * E * I), rtol=1e-14)


def test_transformed_operator_equals_the_eulerian_one():
    """D²w/Dt² = w_tt + 2v w_xt + v² w_xx + v̇ w_x at fixed x equals the ξ = x/L(t) form used by both
    discretisations, for W = a(t) ξ^p with symbolic p; likewise the axial-force term."""
    d = er.derive_transformed_operator()
    assert d["difference"] == 0
    assert d["axial_difference"] == 0


def test_clamped_free_roots_and_mode_shapes():
    beta = er.clamped_free_beta(3)
    assert np.allclose(beta[:2], [1.8751040687, 4.6940911330], atol=1e-10, rtol=0)
    assert np.isclose(beta[2], 7.8547574382, atol=1e-9)
    x = np.linspace(0, 1, 9)
    for k, b in enumerate(beta, 1):
        s = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))
        direct = np.cosh(b * x) - np.cos(b * x) - s * (np.sinh(b * x) - np.sin(b * x))
        assert np.allclose(er.clamped_free_mode(k, 1.0)(x), direct / direct[-1], atol=1e-12)
    # stable evaluation for a high mode: finite, tip = 1, ≈ 0 and flat at the clamp
    phi = er.clamped_free_mode(20, 2.0)
    assert np.isclose(phi(2.0), 1.0) and abs(phi(0.0)) < 1e-12 and abs(phi(1e-6)) < 1e-6


# ------------------------------------------------------------------------------------------------
# (a) no motion: frequencies of the clamped–free beam, static equilibrium under gravity
# ------------------------------------------------------------------------------------------------

def test_rest_frequencies_equal_the_clamped_free_beam():
    E, I, rho, A = STEEL
    exact = er.clamped_free_frequencies(E, I, rho, A, 0.5, n=3)
    assert np.allclose(exact[:2], np.array([1.8751040687, 4.6940911330]) ** 2 * np.sqrt(E * I / (rho * A * 0.5**4)),
                       rtol=1e-10)
    assert np.allclose(er.galerkin_frequencies(E, I, rho, A, 0.5, modes=12, n=3), exact, rtol=1e-10)
    assert np.allclose(er.galerkin_frequencies(E, I, rho, A, 0.5, modes=8, n=2), exact[:2], rtol=1e-7)


@pytest.mark.parametrize("k", [1, 2])
def test_rest_free_vibration_in_time(k):
    """v = 0, no gravity, released from the k-th mode: tip = a cos(ω_k t) over 3 periods."""
    E, I, rho, A = STEEL
    L = 0.5
    om = er.clamped_free_frequencies(E, I, rho, A, L, n=k)[-1]
    t = np.linspace(0, 3 * 2 * np.pi / om, 121)
    s = er.solve(E, I, rho, A, 0.0, er.ConstantSpeed(L, 0.0), t_span=(0, t[-1]), t_eval=t, modes=12,
                 w0=("mode", k, 1e-3))
    assert _rel(s.tip, 1e-3 * np.cos(om * t), scale=1e-3) < 1e-7
    # the mode shape is the analytic one
    x = np.linspace(0, L, 11)
    assert _rel(s.w(x, 0.0), er.clamped_free_mode(k, L, 1e-3)(x), scale=1e-3) < 1e-8


def test_rest_under_gravity_stays_at_the_static_deflection():
    E, I, rho, A = STEEL
    L = 0.8
    t = np.linspace(0, 1.0, 11)
    s = er.solve(E, I, rho, A, GRAV, er.ConstantSpeed(L, 0.0), t_span=(0, 1.0), t_eval=t, modes=8)
    ws = er.static_deflection(E, I, rho, A, GRAV, L)
    assert np.isclose(ws, -0.0563, rtol=2e-3)
    assert _rel(s.tip, np.full_like(t, ws)) < 1e-12
    x = np.linspace(0, L, 9)
    assert _rel(s.w(x, 0.55), er.static_deflection(E, I, rho, A, GRAV, L, x)) < 1e-12


# ------------------------------------------------------------------------------------------------
# (b) quasi-static extrusion
# ------------------------------------------------------------------------------------------------

def _quasi_static_correction(E, I, rho, A, g, L, v, vd):
    """Tip deflection δ of the first inertia correction: EI δ'''' = −ρA D²w_s/Dt² with w_s(x; L(t)) the static
    deflection of the current length (the O(T⁻²) term of a slow stroke of duration T)."""
    x = Polynomial([0.0, 1.0])
    c = -rho * A * g / (24 * E * I)
    ws = c * x**2 * (6 * L**2 - 4 * L * x + x**2)
    wt = c * x**2 * (12 * L - 4 * x) * v                        # ∂w_s/∂L · L̇ at fixed x
    wtt = c * x**2 * (12 * v**2 + (12 * L - 4 * x) * vd)
    acc = wtt + 2 * v * wt.deriv() + v**2 * ws.deriv(2) + vd * ws.deriv()
    q = -rho * A * acc
    Q1, Q2 = q.integ(), (x * q).integ()
    m = (Q2(L) - Q2) - x * (Q1(L) - Q1)                          # EI δ'' = ∫ₓᴸ (s − x) q(s) ds (free end)
    d = ((L - x) * m).integ()
    return (d(L) - d(0)) / (E * I)


def test_slow_extrusion_follows_the_static_deflection():
    """Stroke 0.3 → 0.8 m of the steel tape in 8 s: the tip stays within 1e-3 of −ρAgL(t)⁴/(8EI), and the
    remaining difference is the first quasi-static inertia correction (residual ≈ 1 % of it, O(T⁻⁴))."""
    E, I, rho, A = STEEL
    T = 8.0
    m = er.SmoothStroke(0.3, 0.8, 0.0, T)
    t = np.linspace(0, T, 161)
    s = er.solve(E, I, rho, A, GRAV, m, t_span=(0, T), t_eval=t, modes=6)
    st = s.static_tip()
    scale = np.max(np.abs(st))
    dev = s.tip - st
    assert np.allclose(s.L, [m(ti)[0] for ti in t]) and s.L[-1] == 0.8
    assert np.max(np.abs(dev)) / scale < 1e-3
    assert np.max(np.abs(dev)) / scale > 1e-4                     # the stroke is not trivially slow
    corr = np.array([_quasi_static_correction(E, I, rho, A, GRAV, *m(ti)) for ti in t])
    assert np.max(np.abs(dev - corr)) < 0.03 * np.max(np.abs(dev))


# ------------------------------------------------------------------------------------------------
# convergence in the number of modes
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("L0, L1, T, tol8, tol12", [
    (0.3, 0.8, 0.25, 1e-8, 1e-9),     # extrusion, peak speed 4.4 m/s
    (0.8, 0.3, 0.15, 3e-6, 1e-8),     # retraction, peak speed 7.3 m/s
])
def test_modes_convergence_steel_tape(L0, L1, T, tol8, tol12):
    E, I, rho, A = STEEL
    m = er.SmoothStroke(L0, L1, 0.0, T)
    t = np.linspace(0, T + 0.05, 31)
    tips = {n: er.solve(E, I, rho, A, GRAV, m, t_span=(0, t[-1]), t_eval=t, modes=n).tip for n in (8, 12, 16)}
    assert _rel(tips[8], tips[16]) < tol8
    assert _rel(tips[12], tips[16]) < tol12
    assert _rel(tips[8], tips[16]) > _rel(tips[12], tips[16])


# ------------------------------------------------------------------------------------------------
# (c) an independent discretisation: finite differences of the strong form
# ------------------------------------------------------------------------------------------------

FD_CASES = {
    # name: (material, g, motion, t_end, w0, axial_inertia, FD grids)
    "extrusion to constant speed, static start": (UNIT, 1.0, er.RampToSpeed(1.0, 0.5, 0.0, 0.5), 3.0, "static", False,
                                                  (20, 40, 80)),
    "retraction at constant speed, first mode": (UNIT, 0.0, er.RampToSpeed(1.0, -0.2, 0.0, 0.5), 2.5, ("mode", 1, 0.1),
                                                 False, (24, 48, 96)),
    "stroke with axial inertia": (UNIT, 1.0, er.SmoothStroke(0.6, 1.2, 0.0, 1.0), 2.0, "static", True, (20, 40, 80)),
    "steel tape stroke": (STEEL, GRAV, er.SmoothStroke(0.3, 0.8, 0.0, 0.25), 0.3, "static", False, (20, 40, 80)),
}


@pytest.mark.parametrize("name", list(FD_CASES))
def test_galerkin_agrees_with_finite_differences(name):
    (E, I, rho, A), g, m, T, w0, ax, grids = FD_CASES[name]
    t = np.linspace(0, T, 26)
    gal = er.solve(E, I, rho, A, g, m, t_span=(0, T), t_eval=t, modes=12, w0=w0, axial_inertia=ax)
    _, fd, tips = er.solve_fd_extrapolated(E, I, rho, A, g, m, t_span=(0, T), t_eval=t, w0=w0, axial_inertia=ax,
                                           points=grids)
    assert _rel(fd, gal.tip) < 1e-5
    # the FD solutions themselves converge at second order towards it
    e = [_rel(tp, gal.tip) for tp in tips]
    assert 3.5 < e[0] / e[1] < 4.5 and 3.5 < e[1] / e[2] < 4.5


def test_axial_inertia_matters_only_when_the_speed_changes():
    E, I, rho, A = UNIT
    t = np.linspace(0, 2.0, 21)
    kw = dict(t_span=(0, 2.0), t_eval=t, modes=8, w0="static")
    for m, changes in ((er.SmoothStroke(0.6, 1.2, 0.0, 1.0), True), (er.RampToSpeed(1.0, 0.3, 0.0, 0.5), True)):
        with_n = er.solve(E, I, rho, A, 1.0, m, axial_inertia=True, **kw).tip
        without = er.solve(E, I, rho, A, 1.0, m, axial_inertia=False, **kw).tip
        assert _rel(with_n, without) > 1e-2
        assert np.array_equal(with_n[:1], without[:1])
    # after the ramp (v̇ = 0) both models obey the same equations: started from the same state they coincide
    m = er.ConstantSpeed(1.0, 0.3)
    kw = dict(t_span=(0, 0.2), t_eval=t[:3], modes=6, w0=("mode", 1, 0.1))
    a = er.solve(E, I, rho, A, 0.0, m, axial_inertia=True, **kw)
    b = er.solve(E, I, rho, A, 0.0, m, axial_inertia=False, **kw)
    assert np.array_equal(a.tip, b.tip) and abs(a.tip[-1] - a.tip[0]) > 1e-3


# ------------------------------------------------------------------------------------------------
# (d) energy of the free part: the spaghetti problem
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("v", [-0.1, 0.1])
def test_energy_grows_in_retraction_and_decays_in_extrusion(v):
    """Undamped, no gravity, first mode, smooth ramp to constant speed v (L0 = 1, EI = ρA = 1).
    dE/dt = −½ v EI w_xx(0,t)²: energy grows while retracting (v < 0) and decays while extruding; the
    balance holds along the motion. Slow enough for adiabatic behaviour: E/ω₁ ∝ E L² stays ≈ constant,
    hence the tip amplitude ∝ √L DEcreases in retraction although the energy increases."""
    E, I, rho, A = UNIT
    T = 4.0
    m = er.RampToSpeed(1.0, v, 0.0, 0.5)
    t = np.linspace(0, T, 801)
    s = er.solve(E, I, rho, A, 0.0, m, t_span=(0, T), t_eval=t, modes=8, w0=("mode", 1, 0.1))
    en, p = s.energy(), s.power()
    work = cumulative_simpson(p, x=t, initial=0.0)
    assert np.max(np.abs(en - en[0] - work)) < 1e-5 * en[0]
    assert np.all(p * v <= 0)
    ratio = en[-1] / en[0]
    if v < 0:
        assert ratio > 1.6 and np.all(np.diff(en) >= -1e-6 * en[0])
    else:
        assert ratio < 0.8 and np.all(np.diff(en) <= 1e-6 * en[0])
    assert abs(ratio * (s.L[-1] / s.L[0]) ** 2 - 1.0) < 0.05              # adiabatic invariant E/ω₁
    n = len(t) // 8
    amp0, amp1 = np.max(np.abs(s.tip[:n])), np.max(np.abs(s.tip[-n:]))
    assert abs(amp1 / amp0 / np.sqrt(s.L[-1] / s.L[0]) - 1.0) < 0.05


def test_energy_balance_with_gravity_and_axial_inertia():
    """Accelerated stroke with gravity: E = kinetic + bending + gravity energy obeys
    dE/dt = −½ v EI w_xx(0)² + ρA v̇ ∫(L − x) w_x u_x dx, and the axial-force power is not negligible."""
    E, I, rho, A = STEEL
    T = 0.3
    m = er.SmoothStroke(0.3, 0.8, 0.0, 0.25)
    t = np.linspace(0, T, 1201)
    s = er.solve(E, I, rho, A, GRAV, m, t_span=(0, T), t_eval=t, modes=8, axial_inertia=True)
    en, p = s.energy(), s.power()
    work = cumulative_simpson(p, x=t, initial=0.0)
    scale = np.max(np.abs(en - en[0]))
    assert np.max(np.abs(en - en[0] - work)) < 1e-5 * scale
    s.axial_inertia = False                      # the guide term alone does not balance
    work_guide = cumulative_simpson(s.power(), x=t, initial=0.0)
    assert np.max(np.abs(en - en[0] - work_guide)) > 1e-3 * scale


# ------------------------------------------------------------------------------------------------
# API
# ------------------------------------------------------------------------------------------------

def test_callables_give_the_same_result_as_a_motion():
    E, I, rho, A = STEEL
    m = er.SmoothStroke(0.3, 0.5, 0.0, 0.1)
    t = np.linspace(0, 0.1, 6)
    a = er.solve(E, I, rho, A, GRAV, m, t_span=(0, 0.1), t_eval=t, modes=6)
    b = er.solve(E, I, rho, A, GRAV, m.L, m.v, m.vdot, t_span=(0, 0.1), t_eval=t, modes=6)
    assert np.array_equal(a.tip, b.tip)
    assert np.isclose(a.w(a.L[-1], t[-1]), a.tip[-1], rtol=1e-14)
    assert np.isclose(a.tip_at(0.0713), a.w(m(0.0713)[0], 0.0713), rtol=1e-13)
    with pytest.raises(ValueError):
        er.solve(E, I, rho, A, GRAV, m.L, t_span=(0, 0.1))
    with pytest.raises(ValueError):
        er.solve(E, I, rho, A, GRAV, m, m.v, m.vdot, t_span=(0, 0.1))
    with pytest.raises(ValueError):
        er.solve(E, I, rho, A, GRAV, m, t_span=(0, 0.1), w0="bent")


def test_initial_rate_is_eulerian():
    """``wdot0`` is ∂w/∂t at fixed x: the material transverse velocity at t0 is Dw/Dt = wdot0 + v w_x, so the
    initial energy is bending + gravity + ½ρA ∫ (wdot0 + v w_x)² dx. (Dw/Dt ≡ 0 is impossible for v ≠ 0: the
    clamp forces w_t = w_xt = 0 at x = 0, hence (Dw/Dt)_x(0) = v w_xx(0).)"""
    E, I, rho, A = STEEL
    L, v = 0.5, 2.0
    x = Polynomial([0.0, 1.0])
    ws = -rho * A * GRAV / (24 * E * I) * x**2 * (6 * L**2 - 4 * L * x + x**2)
    rate = 0.3 * x**2 * (1 - x / L)                                  # satisfies the clamped conditions
    kw = dict(t_span=(0, 1e-4), t_eval=[0.0, 1e-4], modes=6)
    bend_grav = ((0.5 * E * I * ws.deriv(2) ** 2 + rho * A * GRAV * ws).integ())(L)
    for speed, wdot0, u in ((0.0, None, 0 * x), (v, None, v * ws.deriv()), (v, rate, rate + v * ws.deriv())):
        s = er.solve(E, I, rho, A, GRAV, er.ConstantSpeed(L, speed), wdot0=wdot0, **kw)
        assert np.isclose(s.energy(0.0), bend_grav + ((0.5 * rho * A * u**2).integ())(L), rtol=1e-12)
