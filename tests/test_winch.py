"""A rope wound on a drum (Model.add_rope(..., drum=, radius=)): the drum's rotation pays it out, l_u = l₀ + r φ, and
takes r P. Checked against a SciPy solution of the hanging load's own equation (a drum at a prescribed speed), the
energy balance with a motor torque (a free drum), the Jacobians against central differences in both modes and
engines, and the adjoint gradient by the rope's EA against differences of whole runs."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rigidfem as rf
from conftest import central_jacobians
from test_derivatives import check_both_modes

G, H = 9.81, 5.0  # gravity (m/s²); the sheave's height (m)


def winch(m=200.0, EA=2e6, DA=2e3, r=0.3, l0=2.0, J=4.0, drive=None, algorithm="recursive", torque=None, mu=0.0):
    """A load of m kg on a vertical slide (z) hanging from a sheave at height H by a rope (μ kg/m) wound on a drum of
    radius r and inertia J (rotation y, φ): the rope's unstretched length l_u = l₀ + r φ. The drum prescribed (drive),
    or free under a torque profile."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    drum = model.add_body("drum", model.ground, rf.Joint.revolute("y"), 20.0, (J, J, J),
                          placement=rf.transform((-1.0, 0.0, H)))
    load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), m, (1.0, 1.0, 1.0))
    model.add_rope("rope", model.ground.point((0.0, 0.0, H)), load.origin, EA=EA, DA=DA, length=l0, drum=drum, radius=r,
                   mass_per_length=mu)
    if drive is not None:
        model.prescribe(drum, drive)
    if torque is not None:
        model.add_torque("motor", drum, (0.0, 1.0, 0.0), scale=torque)
    return model.compile(algorithm=algorithm)


def test_a_drum_at_a_prescribed_speed_lowers_the_load_as_its_own_equation_says():
    """φ = ω t: the load's m z̈ = −m g + T(l = H − z, l_u = l₀ + r ω t), solved here by SciPy (1e-12), independently
    of the model's coordinates and of its rope law."""
    m, EA, DA, r, l0, w = 200.0, 2e6, 2e3, 0.3, 2.0, 1.5
    system = winch(m, EA, DA, r, l0, drive=rf.motion.polynomial([0.0, w]))
    z0 = H - l0 * (1 + m * G / EA)  # hanging at rest

    def rhs(t, y):
        z, v = y
        lu, lud = l0 + r * w * t, r * w
        T = max(0.0, (EA * (H - z - lu) + DA * (-v - lud)) / lu)
        return [v, -G + T / m]

    t_eval = np.linspace(0.0, 2.0, 41)
    ref = solve_ivp(rhs, (0.0, 2.0), [z0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t_eval)
    res = rf.simulate(system, 2.0, "dopri5", q0=[z0], t_eval=t_eval, rtol=1e-11, atol=1e-13)
    assert np.abs(res.q[:, 0] - ref.y[0]).max() < 1e-9
    # the drum's torque holds the rope's pull: r P, P = T + ½ EA ε² (the load lowered at r ω)
    assert ref.y[0][-1] == pytest.approx(z0 - r * w * 2.0, abs=5e-3)


@pytest.mark.parametrize("mu", [0.0, 30.0])
def test_a_motor_driven_drum_keeps_the_energy_balance_to_the_last_term(mu):
    """A free drum of inertia J under a motor torque M(t) lifting the load: the kinetic, gravity and rope energies
    change by ∫ M φ̇ dt − ∫ DA/l_u (l̇ − l̇_u)² dt (trapezoids over 12,001 outputs), to 3e-8 of the energy moved. The
    drum takes r (T + ½ EA ε²): with T r alone ½ EA ε² ṡ, about 2 J here (7e-4 of it), would be missing. A heavy
    rope (μ = 30 kg/m) too: its span's potential is in the gravity energy, and the drum winds its weight in."""
    m, r = 200.0, 0.3
    torque = rf.motion.polynomial([-(1.2 * m + 2.0 * mu) * G * r, 50.0])  # more than the weight: it winds in
    system = winch(m=m, r=r, torque=torque, mu=mu)
    z0 = H - 2.0 * (1 + (m + mu) * G / 2e6)  # the span's weight: half on the load (T = (m + ½ μ l_u) g)
    t_eval = np.linspace(0.0, 1.5, 12001)
    res = rf.simulate(system, 1.5, "dopri5", q0=[0.0, z0], t_eval=t_eval, rtol=1e-11, atol=1e-13)
    phi_dot = res.qd[:, 0]
    motor = (-(1.2 * m + 2.0 * mu) * G * r + 50.0 * t_eval) * phi_dot

    def integral(f):
        return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t_eval))])

    E = res.energy
    balance = E - E[0] - integral(motor) + integral(res.dissipated_power)
    moved = np.abs(E - E[0]).max()
    assert phi_dot[-1] < -1.0 and moved > 1e3  # the drum winds the rope in: the load rises
    assert np.abs(balance).max() < 3e-8 * moved


def test_a_heavy_rope_holds_its_load_and_its_drum_as_the_hanging_continuum_does():
    """A load m hanging at rest on l_u of rope of μ kg/m: in the continuum, T(σ) = (m + μ σ) g at σ of unstretched rope
    above the load, so the rope is stretched by (m g l_u + ½ μ g l_u²)/EA and the drum holds r (m + μ l_u) g. The model
    (a straight span, half its weight on each point) rests at that stretch (the load's z̈ = 0 to 1e-9 g) and its drum
    turns under J φ̈ = r (m + μ l_u) g to O(ε) (ε = 2e-6 here); the massless rope would miss μ l_u = 40 % of the load."""
    m, mu, r, J, EA, l0, phi = 200.0, 20.0, 0.3, 4.0, 1e9, 2.0, 10.0
    system = winch(m=m, EA=EA, r=r, l0=l0, J=J, mu=mu)
    lu = l0 + r * phi
    stretch = (m * G * lu + 0.5 * mu * G * lu**2) / EA
    acc = system.forward_dynamics(0.0, np.array([phi, H - lu - stretch]), np.zeros(2))
    assert abs(acc[1]) < 1e-9 * G
    eps = stretch / lu
    assert J * acc[0] == pytest.approx(r * (m + mu * lu) * G, rel=3 * eps)
    assert J * acc[0] > 1.3 * r * m * G


def test_a_drum_lowering_a_heavy_rope_follows_the_inextensible_ropes_closed_form():
    """A free drum lets the load and the rope down: for an inextensible rope the drop x obeys
    (m + J/r²) ẍ = (m + μ (l₀ + x)) g (the rope's weight grows as it leaves the drum), so x = (a/b)(cosh √b t − 1),
    a = (m + μ l₀) g/M, b = μ g/M, M = m + J/r² (the rope stays taut while m + μ l_u < M). A stiff rope (EA = 1e9 N)
    follows it to 1e-5 m over 1 s (2.9 m of drop); the massless rope falls 0.57 m short."""
    m, mu, r, J, l0 = 200.0, 20.0, 0.3, 20.0, 2.0
    t = np.linspace(0.0, 1.0, 11)

    def drop(mu):
        system = winch(m=m, EA=1e9, DA=1e6, r=r, l0=l0, J=J, mu=mu)
        z0 = H - l0 - (m * G * l0 + 0.5 * mu * G * l0**2) / 1e9
        res = rf.simulate(system, 1.0, q0=[0.0, z0], t_eval=t, rtol=1e-10, atol=1e-12)
        assert (res.element_forces < -100.0).all()  # taut
        return z0 - res.q[:, 1], r * res.q[:, 0]

    M = m + J / r**2
    a, b = (m + mu * l0) * G / M, mu * G / M
    x = a / b * (np.cosh(np.sqrt(b) * t) - 1.0)
    load, paid_out = drop(mu)
    np.testing.assert_allclose(load, x, atol=1e-5)
    np.testing.assert_allclose(paid_out, x, atol=1e-5)
    assert x[-1] - drop(0.0)[0][-1] > 0.5


def heavy_crane(mu=25.0, DA=3e3):
    """A jib turning about y at the ground (4 m), a drum on it (rotation y) paying a heavy rope out over the jib's tip
    to a load free in the x-z plane: the rope's both points move, so its weights' and pull's derivatives are whole."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    jib = model.add_body("jib", model.ground, rf.Joint.revolute("y", stiffness=4e5), 500.0, (20.0, 600.0, 600.0),
                         com=(2.0, 0.0, 0.0))
    drum = model.add_body("drum", jib, rf.Joint.revolute("y"), 30.0, (2.0, 2.0, 2.0),
                          placement=rf.transform((0.5, 0.0, 0.3)))
    load = model.add_body("load", model.ground, rf.Joint.custom(("x", "z")), 150.0, (1.0, 1.0, 1.0))
    model.add_rope("rope", jib.point((4.0, 0.0, 0.0)), load.origin, EA=5e6, DA=DA, length=3.0, drum=drum, radius=0.25,
                   mass_per_length=mu)
    model.add_torque("motor", drum, (0.0, 1.0, 0.0), scale=rf.motion.constant(-0.25 * 160.0 * G))
    return model.compile()


def test_a_heavy_ropes_jacobians_are_exact_in_both_modes_and_its_adjoint_gradient_by_its_mass():
    """∂f/∂q, ∂f/∂q̇ of the heavy rope's weights (½ μ l_u g on the tip, μ s taken from the drum there) and pull
    (½ μ g·(r_B − r_A)) against central differences (2e-6); forward and reverse modes to round-off; rf.gradient by
    "rope.mass_per_length" and "rope.EA" of the load's height after 0.4 s against central differences of whole runs
    (1e-6)."""
    system = heavy_crane()
    names = system.coordinate_names
    t, q, qd = 0.0, np.array([0.02, 0.4, 3.5, -3.3]), np.array([0.1, -0.5, 0.3, 0.2])
    assert names == ["jib.ry", "drum.ry", "load.x", "load.z"]
    Kq, Kqd = system.force_jacobians(t, q, qd)
    Fq, Fqd = central_jacobians(system, t, q, qd, h=1e-6)
    np.testing.assert_allclose(Kq, Fq, rtol=2e-6, atol=2e-6 * np.abs(Fq).max())
    np.testing.assert_allclose(Kqd, Fqd, rtol=2e-6, atol=2e-6 * np.abs(Fqd).max())
    light = heavy_crane(mu=0.0)
    assert np.abs(light.generalized_forces(t, q, qd) - system.generalized_forces(t, q, qd)).max() > 1e2
    check_both_modes(system, np.random.default_rng(11), spread=0.05)
    q0 = np.array([0.0, 0.0, 4.0, -3.0])
    run = dict(dt=1e-3, q0=q0, newton_tol=1e-13)
    grad = rf.gradient(system, 0.4, ["rope.mass_per_length", "rope.EA"], outputs={"z": "load.z"},
                       terminal=lambda y: y["z"], **run)

    def height(**values):
        r = rf.simulate(system.with_parameters(values), 0.4, method="generalized_alpha", t_eval=[0.4], **run)
        return r.q[-1, 3]

    for name, value in (("rope.mass_per_length", 25.0), ("rope.EA", 5e6)):
        h = 1e-4 * value
        fd = (height(**{name: value + h}) - height(**{name: value - h})) / (2 * h)
        assert grad[name] == pytest.approx(fd, rel=1e-6, abs=1e-6 * abs(fd))


@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
def test_the_drums_coupling_has_exact_jacobians_in_both_modes_and_engines(algorithm):
    """∂f/∂q and ∂f/∂q̇ with the drum's row and column (the rope's force by φ, the drum's pull by z) against central
    differences; the recursive engine's forward and reverse modes against them; both engines' forces agree."""
    system = winch(torque=rf.motion.constant(-500.0), algorithm=algorithm)
    t, q, qd = 0.3, np.array([0.4, H - 2.2]), np.array([-0.7, 0.9])  # l = 2.2 m, l_u = 2.12 m: taut
    Kq, Kqd = system.force_jacobians(t, q, qd)
    Fq, Fqd = central_jacobians(system, t, q, qd, h=1e-6)
    assert abs(Kq[0, 1]) > 1e5 and abs(Kq[1, 0]) > 1e5  # coupled both ways
    np.testing.assert_allclose(Kq, Fq, rtol=2e-6, atol=2e-6 * np.abs(Fq).max())
    np.testing.assert_allclose(Kqd, Fqd, rtol=2e-6, atol=2e-6 * np.abs(Fqd).max())
    if algorithm == "recursive":
        check_both_modes(system, np.random.default_rng(5))  # z in (-1, 1) m: the rope taut
        lagrange = winch(torque=rf.motion.constant(-500.0), algorithm="lagrange")
        np.testing.assert_allclose(system.forward_dynamics(t, q, qd), lagrange.forward_dynamics(t, q, qd), rtol=1e-10)


def test_the_adjoint_gradient_by_the_ropes_stiffness_through_a_wound_rope():
    """rf.gradient by "rope.EA" and "rope.DA" of the load's height after 0.5 s against central differences of whole
    runs (1e-6): the adjoint's parameter terms hold the drum's pull too."""
    system = winch(torque=rf.motion.constant(-1.1 * 200.0 * G * 0.3))
    z0 = H - 2.0 * (1 + 200.0 * G / 2e6)
    run = dict(dt=1e-3, q0=[0.0, z0], newton_tol=1e-13)
    g = rf.gradient(system, 0.5, ["rope.EA", "rope.DA"], outputs={"z": "load.z"}, terminal=lambda y: y["z"], **run)

    def height(**values):
        r = rf.simulate(system.with_parameters(values), 0.5, method="generalized_alpha", t_eval=[0.5], **run)
        return r.q[-1, 1]

    for name, value in (("rope.EA", 2e6), ("rope.DA", 2e3)):
        h = 1e-4 * value
        fd = (height(**{name: value + h}) - height(**{name: value - h})) / (2 * h)
        assert g[name] == pytest.approx(fd, rel=1e-6, abs=1e-12)


def test_bad_drums_are_refused_by_name():
    model = rf.Model()
    drum = model.add_body("drum", model.ground, rf.Joint.revolute("y"), 1.0, (1.0, 1.0, 1.0))
    load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), 1.0, (1.0, 1.0, 1.0))
    two = model.add_body("two", model.ground, rf.Joint.universal(), 1.0, (1.0, 1.0, 1.0))
    sheave = model.ground.point((0.0, 0.0, 5.0))
    with pytest.raises(ValueError, match="radius: expected a positive"):
        model.add_rope("r1", sheave, load.origin, EA=1e6, length=1.0, drum=drum, radius=0.0)
    with pytest.raises(ValueError, match="drum: expected a body"):
        model.add_rope("r2", sheave, load.origin, EA=1e6, length=1.0, drum="drum", radius=0.3)
    with pytest.raises(ValueError, match="coordinate: expected a coordinate name"):
        model.add_rope("r3", sheave, load.origin, EA=1e6, length=1.0, drum=two, radius=0.3)
    with pytest.raises(ValueError, match="length: expected a number l0"):
        model.add_rope("r4", sheave, load.origin, EA=1e6, length=rf.motion.polynomial([1.0, 0.1]), drum=drum,
                       radius=0.3)
    with pytest.raises(ValueError, match="radius: expected a positive drum radius"):
        model.add_rope("r5", sheave, load.origin, EA=1e6, length=1.0, drum=drum)
    model.add_rope("r6", sheave, load.origin, EA=1e6, length=1.0, drum=(two, "ry"), radius=0.3)  # a named rotation
    s = model.compile()
    # wound all in: the drum's φ = −l₀/r leaves no rope
    with pytest.raises(rf.SimulationError, match="its drum has wound it all in"):
        s.generalized_forces(0.0, np.array([0.0, 0.0, 0.0, -1.0 / 0.3 - 0.1]), np.zeros(4))
    assert math.isfinite(s.generalized_forces(0.0, np.zeros(4), np.zeros(4))[0])


def sheave(M1, M2, mu=0.3, wrap=math.pi, EA=1e8, DA=2e5, smoothing=1e-4):
    """Two loads on vertical slides hanging from one rope over a fixed sheave 5 m up: the heavy one (M1) on the span
    "left", the light one (M2) on "right", which runs over the sheave with friction μ and wrap θ."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    heavy = model.add_body("heavy", model.ground, rf.Joint.prismatic("z"), M1, (1.0, 1.0, 1.0),
                           placement=rf.transform((-0.5, 0.0, 0.0)))
    light = model.add_body("light", model.ground, rf.Joint.prismatic("z"), M2, (1.0, 1.0, 1.0),
                           placement=rf.transform((0.5, 0.0, 0.0)))
    left = model.add_rope("left", model.ground.point((-0.5, 0.0, H)), heavy, EA=EA, DA=DA, length=H)
    right = model.add_rope("right", model.ground.point((0.5, 0.0, H)), light, EA=EA, DA=DA, length=H)
    model.add_sheave("sheave", left, right, mu=mu, wrap=wrap, mass=0.1, smoothing=smoothing)
    s = model.compile()
    q0 = np.zeros(s.nq)
    q0[s.coordinate_names.index("heavy.z")] = -M1 * G * H / EA  # each at its own static stretch
    q0[s.coordinate_names.index("light.z")] = -M2 * G * H / EA
    return s, q0


@pytest.mark.parametrize("ratio", [0.8, 1.5])
def test_a_rope_over_a_sheave_holds_below_eulers_ratio_and_slips_at_it(ratio):
    """The capstan: loads in the ratio M1/M2 = 0.8 e^{μθ} hold, the rope creeping at the regularised law's
    u̇ = v_ε atanh(ln(M1/M2)/(μθ)) (1e-3); at 1.5 e^{μθ} the rope slips with the tensions in Euler's ratio,
    T_left = e^{μθ} T_right + m_s ü (1e-6 of T_left; m_s = 0.1 kg the slipping rope's mass, 7e-4 of it here), and the
    loads accelerate at g (M1 − M2 e^{μθ})/(M1 + M2 e^{μθ} + m_s) (1e-4). The energy lost is ∫ P dt of
    dissipated_power, the sheave's friction with the ropes' dampers (1e-5 of the energy moved and lost)."""
    mu, wrap, v_eps = 0.3, math.pi, 1e-4
    euler = math.exp(mu * wrap)
    M2 = 10.0
    M1 = ratio * euler * M2
    s, q0 = sheave(M1, M2, mu, wrap, smoothing=v_eps)
    t = np.linspace(0.0, 2.0, 4001)
    r = rf.simulate(s, 2.0, "radau5", q0=q0, t_eval=t, rtol=1e-10, atol=1e-13)
    u, light = s.coordinate_names.index("sheave.rz"), s.coordinate_names.index("light.z")
    T = -r.element_forces  # left, right
    if ratio < 1.0:
        assert r.qd[-1, u] == pytest.approx(v_eps * math.atanh(math.log(M1 / M2) / (mu * wrap)), rel=1e-3)
        assert abs(r.q[-1, u]) < 1e-3
    else:
        udd = s.forward_dynamics(t[-1], r.q[-1], r.qd[-1])[u]  # the model's ü at the end (not a difference quotient)
        assert T[-1, 0] == pytest.approx(euler * T[-1, 1] + 0.1 * udd, rel=1e-6)
        k1, k2 = np.searchsorted(t, [1.5, 2.0])
        accel = (r.qd[k2, light] - r.qd[k1, light]) / (t[k2] - t[k1])
        assert accel == pytest.approx(G * (M1 - M2 * euler) / (M1 + M2 * euler + 0.1), rel=1e-4)
    # from 0.1 s on, past the slip's first transient (faster than the outputs' 0.5 ms)
    k = np.searchsorted(t, 0.1)
    E, P = r.energy[k:], r.dissipated_power[k:]
    lost = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(t[k:]))])
    assert np.abs(E + lost - E[0]).max() < 1e-5 * (np.abs(E - E[0]).max() + lost[-1])


def test_a_sheaves_coupling_has_exact_jacobians_and_bad_sheaves_are_refused():
    """∂f/∂q, ∂f/∂q̇ with the slip's row and column and the capstan's rate derivative against central differences
    (2e-6), both modes of the RNEA to round-off; bad arguments named."""
    s, q0 = sheave(30.0, 10.0, smoothing=0.05)
    t, q, qd = 0.0, q0 + np.array([-0.01, 0.02, 0.03]), np.array([0.01, -0.02, 0.02])
    Kq, Kqd = s.force_jacobians(t, q, qd)
    Fq, Fqd = central_jacobians(s, t, q, qd, h=1e-7)
    np.testing.assert_allclose(Kq, Fq, rtol=2e-6, atol=2e-6 * np.abs(Fq).max())
    np.testing.assert_allclose(Kqd, Fqd, rtol=2e-6, atol=2e-6 * np.abs(Fqd).max())
    assert abs(Kqd[2, 2]) > 1e3  # the capstan's friction by the slip's rate
    check_both_modes(s, np.random.default_rng(7), spread=0.01)
    model = rf.Model()
    a = model.add_body("a", model.ground, rf.Joint.prismatic("z"), 1.0, (1.0, 1.0, 1.0))
    left = model.add_rope("left", model.ground.point((0.0, 0.0, 5.0)), a, EA=1e6, length=4.0)
    spring = model.add_spring_damper("spring", model.ground.point((0.0, 0.0, 5.0)), a, stiffness=1.0, length=4.0)
    with pytest.raises(ValueError, match="out_of: expected a rope of this model"):
        model.add_sheave("s1", left, spring, mu=0.2, wrap=3.0)
    with pytest.raises(ValueError, match="out_of: expected a rope other than into"):
        model.add_sheave("s2", left, left, mu=0.2, wrap=3.0)
    right = model.add_rope("right", model.ground.point((0.0, 0.0, 5.0)), a, EA=1e6, length=4.0)
    with pytest.raises(ValueError, match="mu: expected a finite number >= 0"):
        model.add_sheave("s3", left, right, mu=-0.2, wrap=3.0)
    with pytest.raises(ValueError, match="mass: expected a positive finite mass"):
        model.add_sheave("s5", left, right, mu=0.2, wrap=3.0, mass=0.0)
    with pytest.raises(ValueError, match="into: expected a rope of this model"):
        model.add_sheave("s4", "left", left, mu=0.2, wrap=3.0)


def test_a_refused_sheave_leaves_the_model_as_it_was_and_its_mass_is_its_inertia():
    """A sheave over a rope paid out by a winch's profile is refused before anything is added (no body left, no rope
    half-wound); another model's rope handle is refused; "<sheave>.mass" sets the slip's inertia, and gravity does no
    work on it."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    a = model.add_body("a", model.ground, rf.Joint.prismatic("z"), 1.0, (1.0, 1.0, 1.0))
    b = model.add_body("b", model.ground, rf.Joint.prismatic("z"), 1.0, (1.0, 1.0, 1.0),
                       placement=rf.transform((1.0, 0.0, 0.0)))
    winched = model.add_rope("winched", model.ground.point((0.0, 0.0, 5.0)), a, EA=1e5,
                             length=rf.motion.polynomial([4.0, 0.1]))
    right = model.add_rope("right", model.ground.point((1.0, 0.0, 5.0)), b, EA=1e5, length=4.0)
    with pytest.raises(ValueError, match="^out_of: expected a rope of constant unstretched length"):
        model.add_sheave("sh", right, winched, mu=0.2, wrap=3.0)
    other = rf.Model()
    c = other.add_body("c", other.ground, rf.Joint.prismatic("z"), 1.0, (1.0, 1.0, 1.0))
    foreign = other.add_rope("right", other.ground.point((0.0, 0.0, 5.0)), c, EA=1e5, length=4.0)
    with pytest.raises(ValueError, match="^into: expected a rope of this model"):
        model.add_sheave("sh", foreign, right, mu=0.2, wrap=3.0)
    s = model.compile()
    assert s.coordinate_names == ["a.z", "b.z"]  # nothing left behind
    plain = model.compile()
    np.testing.assert_allclose(s.generalized_forces(0.0, np.zeros(2), np.ones(2)),
                               plain.generalized_forces(0.0, np.zeros(2), np.ones(2)))
    s2, q0 = sheave(30.0, 10.0)
    pull = lambda T: T + T * T / (2 * 1e8)  # noqa: E731  (P = T + ½ EA ε², ε = T/EA, at each load's static stretch)
    assert s2.generalized_forces(0.0, q0, np.zeros(3))[2] == pytest.approx(pull(30.0 * G) - pull(10.0 * G), rel=1e-9)
    for m in (0.1, 10.0):
        assert s2.with_parameters({"sheave.mass": m}).mass_matrix(0.0, q0)[2, 2] == pytest.approx(m, rel=1e-5)
