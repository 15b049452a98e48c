"""The C++ integrators: observed orders, dense output, the implicit methods on a stiff
beam, long-run energy behaviour, numerical dissipation against ρ∞, high spin, fine
discretisation, gimbal lock, failures, Ctrl-C, progress and the released GIL."""

import os
import signal
import threading
import time

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

import rigidfem as rf

from conftest import DOUBLE_PENDULUM_Y0 as Y0  # the pendulum2 fixture's initial state


@pytest.mark.parametrize("method,dts,order,kw", [
    ("euler", [4e-4, 2e-4, 1e-4], 1, {}),
    ("symplectic_euler", [4e-4, 2e-4, 1e-4], 1, {}),
    ("rk4", [0.02, 0.01, 0.005], 4, {}),
    ("dopri5", [0.04, 0.02, 0.01], 5, {"adaptive": False}),
    ("rkf45", [0.01, 0.005, 0.0025], 4, {"adaptive": False}),
    ("bs23", [0.01, 0.005, 0.0025], 3, {"adaptive": False}),
    ("newmark", [0.01, 0.005, 0.0025], 2, {}),
    ("hht", [0.01, 0.005, 0.0025], 2, {}),
    ("generalized_alpha", [0.01, 0.005, 0.0025], 2, {}),
])
def test_observed_order_of_accuracy(pendulum2, method, dts, order, kw):
    system, ref = pendulum2
    errors = []
    for dt in dts:
        r = rf.simulate(system, 1.0, method=method, dt=dt, q0=Y0[:2], **kw)
        errors.append(np.max(np.abs(np.r_[r.q[-1], r.qd[-1]] - ref.y[:, -1])))
        assert r.stats["steps"] == round(1.0 / dt)
    observed = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(observed > order - 0.3), observed


@pytest.mark.parametrize("method", ["dopri5", "rkf45", "bs23", "dop853", "rk4", "generalized_alpha"])
def test_output_at_t_eval_is_dense_output_not_nearest_steps(pendulum2, method):
    system, ref = pendulum2
    t = np.linspace(0, 1.0, 37)  # not on the step grid
    kw = {"rtol": 1e-10, "atol": 1e-12} if method in ("dopri5", "rkf45", "bs23", "dop853") else {"dt": 1e-3}
    r = rf.simulate(system, 1.0, method=method, q0=Y0[:2], t_eval=t, **kw)
    np.testing.assert_array_equal(r.t, t)
    bound = {"dopri5": 1e-8, "rkf45": 1e-8, "bs23": 1e-8, "dop853": 1e-8, "rk4": 1e-9, "generalized_alpha": 2e-5}[method]
    assert np.max(np.abs(r.q - ref.sol(t)[:2].T)) < bound
    assert np.max(np.abs(r.qd - ref.sol(t)[2:].T)) < 20 * bound
    # A quantity derived at the outputs: q̈ is the forward dynamics at the interpolated state.
    np.testing.assert_allclose(r.qdd[5], system.forward_dynamics(t[5], r.q[5], r.qd[5]), rtol=1e-12)


def test_adaptive_methods_meet_their_tolerance_and_count_work(pendulum2):
    system, ref = pendulum2
    for rtol in (1e-6, 1e-9):
        r = rf.simulate(system, 1.0, method="dopri5", q0=Y0[:2], rtol=rtol, atol=rtol * 1e-2)
        err = np.max(np.abs(np.r_[r.q[-1], r.qd[-1]] - ref.y[:, -1]))
        assert err < 100 * rtol
        s = r.stats
        assert s["rhs_evaluations"] >= 6 * (s["steps"] + s["rejected_steps"])
        assert s["wall_time"] > 0
    # bs23 (3 evaluations a step, FSAL) the same way
    for rtol in (1e-4, 1e-7):
        r = rf.simulate(system, 1.0, method="bs23", q0=Y0[:2], rtol=rtol, atol=rtol * 1e-2)
        assert np.max(np.abs(np.r_[r.q[-1], r.qd[-1]] - ref.y[:, -1])) < 100 * rtol
        assert r.stats["rhs_evaluations"] >= 3 * (r.stats["steps"] + r.stats["rejected_steps"])
    # Tolerances per component of y = [q, q̇]: one tight component drives the step size.
    same = rf.simulate(system, 1.0, q0=Y0[:2], rtol=np.full(4, 1e-6), atol=1e-8)
    loose = rf.simulate(system, 1.0, "dopri5", q0=Y0[:2], rtol=1e-3, atol=1e-8)
    one_tight = rf.simulate(system, 1.0, "dopri5", q0=Y0[:2], rtol=[1e-9, 1e-3, 1e-3, 1e-3], atol=1e-8)
    np.testing.assert_array_equal(same.q, rf.simulate(system, 1.0, q0=Y0[:2], rtol=1e-6, atol=1e-8).q)
    assert one_tight.stats["steps"] > 2 * loose.stats["steps"]
    assert abs(one_tight.q[-1, 0] - ref.y[0, -1]) < 1e-7
    first = rf.simulate(system, 1.0, q0=Y0[:2], rtol=1e-6, first_step=1e-7, t_eval=[1.0])
    assert first.stats["steps"] > 0 and abs(first.q[-1, 0] - ref.y[0, -1]) < 1e-4
    r = rf.simulate(system, 1.0, method="newmark", adaptive=True, q0=Y0[:2], rtol=1e-6, atol=1e-8)
    assert np.max(np.abs(r.q[-1] - ref.y[:2, -1])) < 1e-3
    assert r.stats["jacobians"] >= 1 and r.stats["factorizations"] >= 1 and r.stats["newton_iterations"] > 0


def stiff_beam(m=50):
    """Classical steel cantilever with axial, shear and bending coordinates (stiffness ratio
    (ω_max/ω_1)² > 1e6), released from rest at its small static deflection under 2 N at the tip."""
    model, h = rf.samples.cantilever(elements=m, formulation="classical", deform=("axial", "shear_y", "bend_z"))
    loaded, hl = rf.samples.cantilever(elements=m, formulation="classical", deform=("axial", "shear_y", "bend_z"))
    loaded.add_force("load0", hl["beam"].tip, (0.0, 2.0, 0.0))
    q0 = rf.static_equilibrium(loaded.compile(), load_steps=1).q
    return model.compile(), h["beam"], q0


def modal_reference(system, q0, t):
    """Small-amplitude free vibration released from rest at q0, by modal superposition:
    q(t) = Σ_k φ_k (φ_kᵀ M q0) cos ω_k t with mass-normalised modes of (K, M) at q = 0."""
    z = np.zeros(system.nq)
    M = system.mass_matrix(0.0, z)
    K = -system.force_jacobians(0.0, z, z)[0]
    w2, Phi = scipy.linalg.eigh(0.5 * (K + K.T), M)
    Q = (Phi * (Phi.T @ M @ q0)) @ np.cos(np.outer(np.sqrt(w2), t))
    return Q.T, np.sqrt(w2)


def tip_y(system, beam, Q):
    return np.array([system.position(beam.tip, 0.0, q)[1] for q in Q])


def test_stiff_beam_implicit_methods_take_steps_100_times_the_explicit_limit():
    system, beam, q0 = stiff_beam()
    t = np.linspace(0, 1, 41)
    _, w = modal_reference(system, q0, t)
    assert (w[-1] / w[0]) ** 2 > 1e6  # stiffness ratio
    h_explicit = 2.8 / w[-1]  # RK4's stability limit on the imaginary axis
    dt = 100 * h_explicit
    t_end = 2 * 2 * np.pi / w[0]
    t = np.linspace(0, t_end, 41)
    Q_ref, _ = modal_reference(system, q0, t)
    tip_ref = tip_y(system, beam, Q_ref)
    # Bound: the second mode (~2.5 % of the static tip deflection) is resolved only by Newmark;
    # HHT and generalised-α damp it by design, the reference does not.
    for method in ("newmark", "hht", "generalized_alpha"):
        r = rf.simulate(system, t_end, method=method, dt=dt, q0=q0, t_eval=t)
        assert np.max(np.abs(r.position(beam.tip)[:, 1] - tip_ref)) < 0.03 * np.max(np.abs(tip_ref)), method
    # An explicit method at that step blows up and says so instead of returning garbage.
    with pytest.raises(rf.SimulationError, match=r"at t = .*beyond the stability limit of rk4"):
        rf.simulate(system, t_end, method="rk4", dt=dt, q0=q0)
    # An adaptive explicit one would need ~t_end ω_max/3.3 steps: with a budget it stops clearly.
    with pytest.raises(rf.SimulationError, match="max_steps"):
        rf.simulate(system, t_end, method="dopri5", q0=q0, max_steps=2000)


def test_a_fixed_step_beyond_the_limit_ends_before_an_event_fires_on_noise():
    """An arm on a universal joint held by a spring of 1e8 N/m (ω = 5.3e3 and 6.6e3 rad/s), from rest, at rk4's
    h = 1 ms (h ω ≈ 6, past the limit 2.8): in its first steps the state goes from 0 to 7e6, then to 1e49 in one step
    (the rotations' quadratic terms). The run stops there with a SimulationError naming the stability limit and the
    one step's growth, before its terminal rate event can be located in a step whose state spans 40 orders of
    magnitude (a root there would be rounding noise, not the event's level). At h = 10 µs the same event fires where
    the rate is 0.1."""
    model = rf.Model(gravity=None)
    R = rf.euler_zyx(0.3, 2.0, -0.2)
    arm = model.add_body("arm", model.ground, rf.Joint.universal(("y", "z"), stiffness=[0.0, 20.0]), mass=2.0,
                         inertia=R @ np.diag((0.2, 0.14, 0.3366)) @ R.T,
                         placement=rf.transform((-0.2, -1.0, -0.2), (1.0, -0.2, -0.2)))
    model.add_spring_damper("spring", arm.point((0.3, 0.0, -0.2)), model.ground.point((0.0, 0.0, 0.0)),
                            stiffness=1e8, length=1.0)
    system = model.compile()
    event = rf.Event("fast", "arm.rz", rate=True, value=0.1, terminal=True)
    with pytest.raises(rf.SimulationError, match=r"beyond the stability limit of rk4.*in one step"):
        rf.simulate(system, 0.2, method="rk4", dt=1e-3, events=[event])
    r = rf.simulate(system, 0.2, method="rk4", dt=1e-5, events=[event])
    assert len(r.events) == 1 and r.events[0].qd[0] == pytest.approx(0.1, rel=1e-6)


def test_stiff_beam_explicit_adaptive_finishes_correctly_at_a_documented_cost():
    system, beam, q0 = stiff_beam(m=10)
    _, w = modal_reference(system, q0, [0.0])
    t_end = 2 * np.pi / w[0]
    t = np.linspace(0, t_end, 11)
    r = rf.simulate(system, t_end, method="dopri5", q0=q0, rtol=1e-6, atol=1e-9, t_eval=t)
    tip_ref = tip_y(system, beam, modal_reference(system, q0, t)[0])
    assert np.max(np.abs(r.position(beam.tip)[:, 1] - tip_ref)) < 1e-3 * np.max(np.abs(tip_ref))
    # The cost is set by stability, not accuracy: about t_end ω_max / 3.3 steps.
    assert r.stats["steps"] > 0.2 * t_end * w[-1]
    # At a loose tolerance the stiff modes keep errors ~ rtol ω_max/ω: never silently.
    with pytest.warns(RuntimeWarning, match="stiff"):
        loose = rf.simulate(system, t_end, method="dopri5", q0=q0, rtol=3e-3, atol=3e-5)
    assert loose.stats["stiff_at"] < t_end


def test_implicit_predictor_copes_with_a_stiff_mode_in_the_initial_state():
    """A tiny stiff-mode component (1e-6) at 90 times RK4's stability limit: the first Newton
    solve starts from no extra displacement and converges."""
    system, beam, q0 = stiff_beam(m=10)
    modes = rf.modal_analysis(system)
    dt = 90 * 2.8 / modes.omega.max()
    r = rf.simulate(system, 0.05, method="generalized_alpha", dt=dt, q0=q0 + 1e-6 * modes.shapes[:, -1])
    assert r.stats["jacobians"] <= 5 and np.all(np.isfinite(r.q))


def oscillator_beam(m=4):
    model, h = rf.samples.cantilever(elements=m)
    system = model.compile()
    modes = rf.modal_analysis(system)
    return system, modes


def test_long_run_energy_bounded_for_energy_conserving_choices():
    """10⁴ periods of the first mode at small amplitude: Newmark's average acceleration (at 20
    steps per period) and symplectic Euler (at 0.75 of its stability limit ω_max h = 2) keep
    the energy error bounded: no secular drift."""
    system, modes = oscillator_beam(m=3)
    T1 = 2 * np.pi / modes.omega[0]
    q0 = 1e-4 * modes.shapes[:, 0]
    t_end = 1e4 * T1
    t = np.linspace(0, t_end, 2001)
    E0 = system.potential_energy(0.0, q0)
    for method, dt in (("newmark", T1 / 20), ("symplectic_euler", 1.5 / modes.omega[-1])):
        r = rf.simulate(system, t_end, method=method, dt=dt, q0=q0, t_eval=t, max_steps=10**7)
        dE = np.abs(r.energy - E0) / E0
        assert dE[-200:].max() < 2 * dE[:200].max() + 1e-9, method  # no secular drift
        assert dE.max() < 0.05, method


@pytest.mark.parametrize("method,kw,rho", [
    ("generalized_alpha", {"rho_inf": 0.5}, 0.5),
    ("generalized_alpha", {"rho_inf": 0.0}, 0.0),
    ("hht", {"alpha": -0.2}, 0.8 / 1.2),
    ("newmark", {}, 1.0),
])
def test_numerical_dissipation_of_high_frequencies_follows_rho_inf(method, kw, rho):
    """A spring-mass with ω h = 1000: the amplitude ratio per step tends to the spectral
    radius at infinite frequency (ρ∞ = (1 + α)/(1 − α) for HHT, 1 for Newmark)."""
    model, _ = rf.samples.spring_mass(mass=1.0, stiffness=1e6)
    system = model.compile()
    h = 1000 / 1e3
    r = rf.simulate(system, 800 * h, method=method, dt=h, q0=[1.0], **kw)
    x = np.abs(r.q[:, 0]) + np.abs(r.qd[:, 0]) / 1e3
    if rho == 0.0:
        assert x[-1] < 1e-12
        return
    # The roots at infinity are −ρ∞ (possibly repeated): log-slope over steps 400..800.
    slope = (np.log(x[800]) - np.log(x[400])) / 400
    assert np.exp(slope) == pytest.approx(rho, abs=0.01)


def test_kane_beam_at_high_spin_matches_a_tight_reference():
    model, h = rf.samples.kane_beam(omega=10.0, elements=8)
    system = model.compile()
    t = np.linspace(0, 20, 81)
    with pytest.warns(RuntimeWarning, match="stiff from t ="):  # stability-bound: Hairer's test fires
        r = rf.simulate(system, 20.0, method="dopri5", rtol=1e-8, atol=1e-10, t_eval=t)
    assert 0 < r.stats["stiff_at"] < 20.0
    ref = solve_ivp(system.rhs, (0, 20), np.zeros(2 * system.nq), method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=t)
    tip = r.position(h["beam"].tip, frame=h["hub"])
    tip_ref = rf.Result(system, t, ref.y[: system.nq].T, ref.y[system.nq:].T, r.stats, "ref").position(
        h["beam"].tip, frame=h["hub"])
    assert np.max(np.abs(tip - tip_ref)) < 1e-5
    assert np.max(np.abs(tip[:, 1])) > 1.0  # it bends a lot during the spin-up
    r2 = rf.simulate(system, 20.0, method="generalized_alpha", dt=0.005, t_eval=t)
    assert np.max(np.abs(r2.position(h["beam"].tip, frame=h["hub"]) - tip_ref)) < 0.05


def test_fine_discretisation_runs_and_converges():
    """m = 200 modified beam released from a static deflection: the tip's history agrees with
    m = 100 to O(m⁻²)."""
    tips = {}
    for m in (100, 200):
        loaded, hl = rf.samples.cantilever(elements=m)
        loaded.add_force("load0", hl["beam"].tip, (0.0, 5.0, 0.0))
        q0 = rf.static_equilibrium(loaded.compile(), load_steps=1).q
        model, h = rf.samples.cantilever(elements=m)
        system = model.compile()
        t = np.linspace(0, 0.2, 11)
        r = rf.simulate(system, 0.2, method="generalized_alpha", dt=2e-3, q0=q0, t_eval=t, rho_inf=0.5)
        tips[m] = r.position(h["beam"].tip)[:, 1]
    amplitude = np.max(np.abs(tips[200]))
    assert amplitude > 1e-3
    assert np.max(np.abs(tips[200] - tips[100])) < 3e-3 * amplitude


def test_free_body_near_gimbal_lock_against_a_quaternion_reference():
    """A free body turning mostly about y drives its ZYX pitch to ±90°. The integrators pass
    it (the Euler angles jump to the equivalent branch) and the attitude agrees with
    Euler's equations integrated with a quaternion here; an exact hit raises SimulationError."""
    I = np.array([1.0, 2.0, 3.0])
    model = rf.Model(gravity=None)
    model.add_body("b", model.ground, rf.Joint.free(), mass=1.0, inertia=I)
    system = model.compile()
    w0 = np.array([0.03, 1.0, 0.05])  # body = global axes at t = 0

    def euler_quaternion(t, y):
        w, qt = y[:3], y[3:]
        dw = np.array([(I[1] - I[2]) * w[1] * w[2] / I[0], (I[2] - I[0]) * w[2] * w[0] / I[1],
                       (I[0] - I[1]) * w[0] * w[1] / I[2]])
        a, b, c, d = qt
        dq = 0.5 * np.array([-b * w[0] - c * w[1] - d * w[2], a * w[0] + c * w[2] - d * w[1],
                             a * w[1] - b * w[2] + d * w[0], a * w[2] + b * w[1] - c * w[0]])
        return np.r_[dw, dq]

    ref = solve_ivp(euler_quaternion, (0, 3), np.r_[w0, 1, 0, 0, 0], rtol=1e-12, atol=1e-12).y[3:, -1]
    a, b, c, d = ref / np.linalg.norm(ref)
    R_ref = np.array([[1 - 2 * (c * c + d * d), 2 * (b * c - a * d), 2 * (b * d + a * c)],
                      [2 * (b * c + a * d), 1 - 2 * (b * b + d * d), 2 * (c * d - a * b)],
                      [2 * (b * d - a * c), 2 * (c * d + a * b), 1 - 2 * (b * b + c * c)]])
    # ZYX rates of ω (body = global at t = 0): φ̇3 = ω_z, φ̇2 = ω_y, φ̇1 = ω_x.
    r = rf.simulate(system, 3.0, method="dopri5", rtol=1e-10, atol=1e-12, qd0=[0, 0, 0, w0[2], w0[1], w0[0]])
    assert np.all(np.isfinite(r.q))
    assert np.max(np.abs(r.q[:, 4])) > 1.4  # the pitch came near π/2
    np.testing.assert_allclose(system.transform(0, 0.0, r.q[-1])[:3, :3], R_ref, atol=1e-6)
    # At every pitch where |cos φ2| < 1e-9 (π/2 + kπ, to within 1e-9 rad), and only there.
    for pitch in (np.pi / 2, -np.pi / 2, 3 * np.pi / 2, -5 * np.pi / 2 + 5e-10, np.pi / 2 - 5e-10):
        assert abs(np.cos(pitch)) < 1e-9
        with pytest.raises(rf.SimulationError, match="gimbal lock"):
            system.forward_dynamics(0.0, [0, 0, 0, 0, pitch, 0], np.zeros(6))
    # Far out (a run blowing up) π/2 + kπ in floating point is 4e-7 off the lock: no gimbal-lock message there
    for pitch in (np.pi / 2 - 1e-6, 3 * np.pi / 2 + 1e-6, np.pi, np.pi / 2 + 3e9 * np.pi):
        assert abs(np.cos(pitch)) > 1e-9
        assert np.all(np.isfinite(system.forward_dynamics(0.0, [0, 0, 0, 0, pitch, 0], np.zeros(6))))


def test_bad_options_are_value_errors():
    model, _ = rf.samples.pendulum()
    system = model.compile()
    for kw, arg in ((dict(method="leapfrog"), "method"), (dict(method="rk4"), "dt"), (dict(t_end=-1.0), "t_end"),
                    (dict(method="hht", dt=0.01, alpha=0.2), "alpha"),
                    (dict(method="generalized_alpha", dt=0.01, rho_inf=2.0), "rho_inf"),
                    (dict(method="newmark", dt=0.01, beta=0.1), "beta"), (dict(q0=[0.0, 1.0]), "q0"),
                    (dict(t_eval=[0.5, 0.2]), "t_eval"), (dict(method="rk4", dt=0.01, adaptive=True), "adaptive"),
                    (dict(method="scipy:Euler"), "method"), (dict(rtol=[1e-6, 1e-6, 1e-6]), "rtol"),
                    (dict(atol=-1.0), "atol"), (dict(first_step=0.0), "first_step")):
        args = {"t_end": 1.0, **kw}
        with pytest.raises(ValueError, match=rf"^{arg}\b"):
            rf.simulate(system, **args)


def test_ctrl_c_returns_the_partial_result_with_a_warning():
    system, _, q0 = stiff_beam(m=30)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.warns(RuntimeWarning, match="interrupted"):
            r = rf.simulate(system, 1e3, method="rk4", dt=1e-7, q0=q0, t_eval=np.linspace(0, 1e3, 11))
    finally:
        timer.cancel()
    assert r.interrupted and len(r.t) >= 1 and r.t[-1] < 1e3


def test_progress_reports_and_the_gil_is_released(capsys):
    system, _, q0 = stiff_beam(m=20)
    counter = {"n": 0}
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            counter["n"] += 1
            time.sleep(0)

    thread = threading.Thread(target=spin)
    thread.start()
    try:
        r = rf.simulate(system, 0.04, method="rk4", dt=2e-6, q0=q0, progress=True)  # > 0.2 s on the fastest build
    finally:
        stop.set()
        thread.join()
    assert r.stats["wall_time"] > 0.2
    assert counter["n"] > 1000  # Python ran beside the C++ loop
    assert "simulate" in capsys.readouterr().err


def test_threads_with_one_system_give_identical_results():
    model, _ = rf.samples.double_pendulum(spatial=True)
    system = model.compile()
    q0 = [0.3, 0.5, -0.2, 0.1, -0.6, 0.3]
    results = [None] * 4

    def job(k):
        results[k] = rf.simulate(system, 2.0, method="dopri5", rtol=1e-9, q0=q0).q[-1]

    threads = [threading.Thread(target=job, args=(k,)) for k in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for k in range(1, 4):
        np.testing.assert_array_equal(results[k], results[0])


def test_result_outputs_and_driving_forces():
    model, h = rf.samples.kane_beam(omega=4.0, elements=4)
    system = model.compile()
    r = rf.simulate(system, 2.0, method="dopri5", t_eval=np.linspace(0, 2, 5))
    assert r.driving_forces.shape == (5, 1) and r.qdd.shape == (5, system.nq)
    for k in range(5):
        np.testing.assert_allclose(r.driving_forces[k], system.driving_forces(r.t[k], r.q[k], r.qd[k]), rtol=1e-12)
        assert r.energy[k] == pytest.approx(system.kinetic_energy(r.t[k], r.q[k], r.qd[k])
                                            + system.potential_energy(r.t[k], r.q[k]), rel=1e-12)
    # In the hub's frame the undeformed tip would sit at (L, 0, 0).
    tip_hub = r.position(h["beam"].tip, frame=h["hub"])
    assert np.all(np.abs(tip_hub[:, 0] - 10.0) < 0.1)
    assert "dopri5" in repr(r)
