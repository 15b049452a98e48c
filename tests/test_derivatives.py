"""Analytic derivatives of the recursive equations of motion (tangent RNEA) against
Richardson-extrapolated central differences computed here, and the O(n) implicit step
(method="implicit_spring") against the generalised-α method it approximates."""

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

import rigidfem as rf


def richardson(g, x, h=1e-3):
    """Columns ∂g/∂x by central differences extrapolated to h → 0 (error O(h⁴))."""
    def central(step):
        cols = []
        for j in range(len(x)):
            e = np.zeros_like(x)
            e[j] = step
            cols.append((g(x + e) - g(x - e)) / (2 * step))
        return np.array(cols).T
    return (4 * central(h / 2) - central(h)) / 3


def loaded_random_tree(seed, nbodies):
    """A random tree with, besides its springs, dampers, drives and loads, a nonlinear force
    law Q(t, q, q̇) on one free coordinate (the slow path, differenced in C++)."""
    model, handles, rng = rf.samples.random_tree(seed, nbodies)
    names = model.compile().coordinate_names
    if names:
        body_name, coordinate = names[0].split(".")
        body = next(b for b in handles["bodies"] if b.name == body_name)
        model.add_generalized_force(body, lambda t, q, qd: -3.0 * q**3 - 0.5 * qd**3 + np.sin(t),
                                    coordinate=coordinate)
    return model, rng


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nbodies=st.integers(1, 7))
def test_inverse_dynamics_derivatives_on_random_trees(seed, nbodies):
    model, rng = loaded_random_tree(seed, nbodies)
    system = model.compile("recursive")
    n = system.nq
    if n == 0:
        return
    t = float(rng.uniform(0, 3))
    q, qd, qdd = rng.uniform(-1, 1, n), rng.uniform(-2, 2, n), rng.normal(0, 3, n)
    drdq, drdqd = system.inverse_dynamics_derivatives(t, q, qd, qdd)
    ref_q = richardson(lambda x: system.inverse_dynamics(t, x, qd, qdd), q)
    ref_qd = richardson(lambda x: system.inverse_dynamics(t, q, x, qdd), qd)
    for got, ref in ((drdq, ref_q), (drdqd, ref_qd)):
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * max(1.0, np.abs(ref).max()))
    # The residual vanishes at the forward-dynamics accelerations and is A q̈ − f.
    qdd0 = system.forward_dynamics(t, q, qd)
    r0 = system.inverse_dynamics(t, q, qd, qdd0)
    assert np.abs(r0).max() <= 1e-9 * max(1.0, np.abs(system.generalized_forces(t, q, qd)).max())
    np.testing.assert_allclose(system.inverse_dynamics(t, q, qd, qdd) - system.inverse_dynamics(t, q, qd, 0 * qdd),
                               system.mass_matrix(t, q) @ qdd, rtol=0, atol=1e-10 * max(1, np.abs(qdd).max()))


def tangent_at_random_state(system, rng, spread=1.0):
    """A random state (t, q, q̇, q̈), a direction (δq, δq̇, δq̈) and μ, and the analytic K, C and A there."""
    n = system.nq
    t = float(rng.uniform(0, 3))
    q, qd, qdd = rng.uniform(-spread, spread, n), rng.uniform(-2 * spread, 2 * spread, n), rng.normal(0, 3, n)
    direction, mu = tuple(rng.normal(0, 1, (3, n))), rng.normal(0, 1, n)
    K, C = system.inverse_dynamics_derivatives(t, q, qd, qdd)
    return (t, q, qd, qdd), direction, mu, (K, C, system.mass_matrix(t, q))


def check_both_modes(system, rng, spread=1.0):
    """The RNEA's forward mode along a direction is K δq + C δq̇ + A δq̈, its reverse mode for μ is (Kᵀμ, Cᵀμ, Aμ),
    of the analytic matrices (each checked against differences above), to round-off."""
    state, direction, mu, (K, C, A) = tangent_at_random_state(system, rng, spread)
    expected = K @ direction[0] + C @ direction[1] + A @ direction[2]
    got = system._inverse_dynamics_direction(*state, *direction)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-10 * max(1.0, np.abs(expected).max()))
    for g, e in zip(system._inverse_dynamics_vjp(*state, mu), (K.T @ mu, C.T @ mu, A @ mu)):
        np.testing.assert_allclose(g, e, rtol=0, atol=1e-10 * max(1.0, np.abs(e).max()))
    return state, mu


def sprung_beams(gravity=(0.0, -9.81, 0.0), flowing=True):
    """What random trees lack: beams (one flowing out of its guide on a driven hub if ``flowing``), a
    spring-damper and a rope between them, follower and fixed forces and a follower torque."""
    model = rf.Model(gravity=gravity)
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1.0, 1.0, 1.0))
    model.prescribe(hub, rf.motion.harmonic(0.6, 2.0, 0.3))
    tape = model.add_beam("tape", hub, rf.motion.polynomial([0.5, 0.8, -0.3]) if flowing else 0.6,
                          rf.Material(E=2.1e9, rho=7850.0), rf.Section.rectangle(0.02, 0.004), 4,
                          deform=("bend_y", "bend_z", "torsion"), joint=rf.Joint.revolute("y", stiffness=30.0),
                          placement=rf.transform((0.1, 0.0, 0.0)))
    arm = model.add_beam("arm", model.ground, 1.0, rf.Material(E=2e9, rho=2700.0), rf.Section.rectangle(0.02, 0.01), 3,
                         joint=rf.Joint.spherical(), placement=rf.transform((0.0, 1.0, 0.0)))
    model.add_spring_damper("element0", tape.tip, arm.tip, stiffness=50.0, damping=2.0, length=0.3)
    model.add_rope("element1", arm.point(0.5), model.ground, EA=1e4, DA=10.0, length=0.5)
    model.add_force("load0", arm.tip, (0.0, 1.0, 2.0), follower=True)
    model.add_force("load1", tape.tip, (1.0, 0.0, -2.0))
    model.add_torque("load2", arm.rfes[1], (0.3, 0.0, 0.1), follower=True)
    return model


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nbodies=st.integers(1, 7))
def test_both_modes_on_random_trees(seed, nbodies):
    """Both modes of the RNEA (O(n) each) on random trees with every joint, drives, loads and a force law."""
    model, rng = loaded_random_tree(seed, nbodies)
    system = model.compile("recursive")
    if system.nq:
        check_both_modes(system, rng)


def test_both_modes_with_elements_flows_and_beams():
    """Both modes on beams with force elements, a rope and loads, with and without a flowing link (its Coriolis,
    relative-acceleration and turning loads transposed too); the Lagrange formulation has no reverse mode."""
    rng = np.random.default_rng(2)
    for flowing in (True, False):
        model = sprung_beams(flowing=flowing)
        for _ in range(3):
            state, mu = check_both_modes(model.compile(), rng, 0.3)
    with pytest.raises(ValueError, match="system: expected a system compiled with algorithm='recursive'"):
        model.compile("lagrange")._inverse_dynamics_vjp(*state, mu)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nbodies=st.integers(1, 6))
def test_acceleration_derivatives_and_jacobian_on_random_trees(seed, nbodies):
    model, rng = loaded_random_tree(seed, nbodies)
    rec, lag = model.compile("recursive"), model.compile("lagrange")
    n = rec.nq
    if n == 0:
        return
    t = float(rng.uniform(0, 3))
    q, qd = rng.uniform(-1, 1, n), rng.uniform(-2, 2, n)
    dq, dqd = rec.acceleration_derivatives(t, q, qd)
    cond = np.linalg.cond(rec.mass_matrix(t, q))
    ref_q = richardson(lambda x: rec.forward_dynamics(t, x, qd), q)
    ref_qd = richardson(lambda x: rec.forward_dynamics(t, q, x), qd)
    for got, ref in ((dq, ref_q), (dqd, ref_qd)):
        np.testing.assert_allclose(got, ref, rtol=0, atol=max(1e-8, 1e-13 * cond) * max(1.0, np.abs(ref).max()))
    # jacobian() of the first-order form, against the Lagrange formulation's central differences.
    y = np.concatenate([q, qd])
    J = rec.jacobian(t, y)
    np.testing.assert_array_equal(J[:n, :n], 0)
    np.testing.assert_array_equal(J[:n, n:], np.eye(n))
    np.testing.assert_allclose(J[n:], np.hstack([dq, dqd]), rtol=0, atol=1e-12 * max(1.0, np.abs(dq).max()))
    Jl = lag.jacobian(t, y)
    np.testing.assert_allclose(J, Jl, rtol=0, atol=max(1e-6, 1e-12 * cond) * max(1.0, np.abs(Jl).max()))
    # force_jacobians: −∂r/∂(q, q̇) at q̈ = 0, both formulations.
    for static in (False, True):
        fr, fl = rec.force_jacobians(t, q, qd, static=static), lag.force_jacobians(t, q, qd, static=static)
        for a, b in zip(fr, fl):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-7 * max(1.0, np.abs(b).max()))


def test_spatial_double_pendulum_derivatives_at_random_states(rng):
    """A second, independent check of the spatial case (SymPy takes minutes there)."""
    model, _ = rf.samples.double_pendulum(spatial=True)
    system = model.compile()
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.2, 1.2, 6), rng.uniform(-3, 3, 6), rng.normal(0, 5, 6)
        drdq, drdqd = system.inverse_dynamics_derivatives(0.0, q, qd, qdd)
        np.testing.assert_allclose(drdq, richardson(lambda x: system.inverse_dynamics(0.0, x, qd, qdd), q),
                                   rtol=0, atol=1e-9 * np.abs(drdq).max())
        np.testing.assert_allclose(drdqd, richardson(lambda x: system.inverse_dynamics(0.0, q, x, qdd), qd),
                                   rtol=0, atol=1e-9 * np.abs(drdqd).max())


def test_inverse_dynamics_bad_input():
    model, _ = rf.samples.double_pendulum()
    system = model.compile()
    with pytest.raises(ValueError, match="^qdd: expected 2 "):
        system.inverse_dynamics(0.0, np.zeros(2), np.zeros(2), np.zeros(3))
    with pytest.raises(ValueError, match="^qdd: expected 2 "):
        system.inverse_dynamics_derivatives(0.0, np.zeros(2), np.zeros(2), np.array([0.0, np.nan]))
    with pytest.raises(ValueError, match="^iteration_matrix: expected 'auto', 'tangent', 'spring' or 'krylov'"):
        rf.simulate(system, 0.1, method="generalized_alpha", dt=0.01, iteration_matrix="diagonal")


# ---------------------------------------------------------------------------------------
# The O(n) implicit step


def stiff_beam(elements=12, algorithm="recursive"):
    """A 3D steel cantilever (bending both ways and torsion) released from a static deflection
    under a skew tip load: its highest frequency (3.6·10⁴ rad/s) is 1.4·10³ times the lowest (rf.modal_analysis)."""
    def build(load):
        model, h = rf.samples.cantilever(elements=elements, deform=("torsion", "bend_y", "bend_z"))
        if load:
            model.add_force("load0", h["beam"].tip, (0.0, 20.0, 10.0))
            model.add_torque("load1", h["beam"].tip, (1.0, 0.0, 0.0))
        return model, h
    loaded, _ = build(True)
    q0 = rf.static_equilibrium(loaded.compile(), load_steps=2).q
    model, h = build(False)
    return model.compile(algorithm), h["beam"], q0


def test_implicit_spring_converges_to_the_generalized_alpha_solution():
    """Same scheme, another Newton matrix: both iterate to the same discrete solution."""
    system, beam, q0 = stiff_beam()
    T1 = 2 * np.pi / 105.0
    kw = dict(t_eval=np.linspace(0, T1, 11), q0=q0, dt=T1 / 100)
    a = rf.simulate(system, T1, method="generalized_alpha", **kw)
    b = rf.simulate(system, T1, method="implicit_spring", **kw)
    c = rf.simulate(system, T1, method="generalized_alpha", iteration_matrix="spring", **kw)
    assert b.stats["jacobians"] == 0 and a.stats["jacobians"] >= 1
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-7 * np.abs(a.q).max())
    np.testing.assert_array_equal(c.q, b.q)


def test_implicit_spring_takes_steps_far_beyond_the_explicit_limit():
    """ω_max h ≈ 20 (rk4 is stable up to 2.8): bounded (the energy, at the interpolated outputs,
    within 5 % of its start and lower at the end: ρ∞ dissipates the unresolved modes) and the
    tip close to a tight reference."""
    system, beam, q0 = stiff_beam(elements=6)
    K = -system.force_jacobians(0.0, q0, 0 * q0)[0]
    omega_max = np.sqrt(scipy.linalg.eigh((K + K.T) / 2, system.mass_matrix(0.0, q0), eigvals_only=True).max())
    T1 = 2 * np.pi / 105.0
    h = T1 / 50
    assert omega_max * h > 15
    t_eval = np.linspace(0, 2 * T1, 41)
    r = rf.simulate(system, 2 * T1, method="implicit_spring", dt=h, t_eval=t_eval, q0=q0, rho_inf=0.5)
    ref = rf.simulate(system, 2 * T1, method="dopri5", rtol=1e-8, atol=1e-10, t_eval=t_eval, q0=q0,
                      stiffness_warning=False)
    with pytest.raises(rf.SimulationError, match="stability limit"):
        rf.simulate(system, 2 * T1, method="rk4", dt=h, q0=q0)
    E = r.energy
    assert E.max() < 1.05 * E[0] and E[-1] < E[0]
    tip, tip_ref = r.position(beam.tip), ref.position(beam.tip)
    deflection = np.abs(tip_ref - tip_ref[-1]).max()
    assert np.abs(tip - tip_ref).max() < 0.01 * deflection


def test_implicit_spring_is_second_order():
    """Global error of the tip ∝ h² while the steps resolve the motion (Kane's beam spinning up)."""
    model, h = rf.samples.kane_beam(omega=4.0, duration=5.0, elements=6)
    system = model.compile()
    t_eval = np.linspace(0, 5.0, 11)
    ref = rf.simulate(system, 5.0, method="dopri5", rtol=1e-11, atol=1e-13, t_eval=t_eval, stiffness_warning=False)
    tip_ref = ref.position(h["beam"].tip, frame=h["hub"])
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        r = rf.simulate(system, 5.0, method="implicit_spring", dt=dt, t_eval=t_eval, rho_inf=0.9)
        errors.append(np.abs(r.position(h["beam"].tip, frame=h["hub"]) - tip_ref).max())
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all((orders > 1.8) & (orders < 2.3)), (errors, orders)


def test_implicit_spring_on_a_lagrange_system_agrees():
    """The Lagrange formulation solves the same Newton matrix densely."""
    rec, beam, q0 = stiff_beam(elements=5)
    lag = stiff_beam(elements=5, algorithm="lagrange")[0]
    kw = dict(t_eval=np.linspace(0, 0.02, 5), q0=q0, dt=2e-4, method="implicit_spring", newton_tol=1e-12)
    np.testing.assert_allclose(rf.simulate(rec, 0.02, **kw).q, rf.simulate(lag, 0.02, **kw).q, rtol=0, atol=1e-9)
