"""Every input answered (integration and the compiled calls): nq = 0, NaN times, pure relative
tolerances, fixed steps on their grid, no lost work on failure or Ctrl-C, ValueErrors for wrong
types, and the per-thread workspaces of calls from Python. References are closed forms."""

import threading
import warnings

import numpy as np
import pytest

import rigidfem as rf
from conftest import step_of
from rigidfem import samples

ALL_METHODS = ["euler", "symplectic_euler", "rk4", "dopri5", "rkf45", "newmark", "hht", "generalized_alpha",
               "implicit_spring", "scipy:Radau", "scipy:BDF", "scipy:LSODA", "scipy:RK45", "scipy:DOP853"]


def driven_hub():
    """A hub (I_zz = 2 kg·m²) turned by q = sin(2t): nq = 0, driving torque τ = I q̈ = −8 sin 2t."""
    model = rf.Model()
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1.0, 1.0, 2.0))
    model.prescribe(hub, rf.motion.harmonic(1.0, 2.0))
    return model.compile(), hub


@pytest.mark.parametrize("method", ALL_METHODS)
def test_no_free_coordinate_gives_the_drive_history(method):
    system, hub = driven_hub()
    assert system.nq == 0
    t = np.linspace(0.0, 1.0, 6)
    r = rf.simulate(system, 1.0, method=method, **step_of(method, 0.05), t_eval=t)
    np.testing.assert_array_equal(r.t, t)
    assert r.q.shape == (6, 0)
    np.testing.assert_allclose(r.driving_forces[:, 0], -8.0 * np.sin(2.0 * t), atol=1e-12)
    tip = r.position(hub.point((1.0, 0.0, 0.0)))
    np.testing.assert_allclose(tip[:, :2], np.c_[np.cos(np.sin(2 * t)), np.sin(np.sin(2 * t))], atol=1e-12)


def test_a_nan_time_is_a_value_error():
    spline = rf.motion.spline([0, 1, 2, 3], [0, 1, 0, 1])
    for t in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="^t: expected a finite time"):
            spline(t)
    assert np.isfinite(spline(7.0)).all() and spline(-1.0)[2] == 0.0  # linear continuation outside the table
    system, hub = driven_hub()
    with pytest.raises(ValueError, match="^t: "):
        system.driving_forces(float("nan"), np.zeros(0), np.zeros(0))


def test_atol_zero_from_rest_follows_the_closed_form():
    """A pure relative tolerance on a state that starts at exactly zero: x = F/k (1 − cos ωt)."""
    model, h = samples.spring_mass(mass=2.0, stiffness=800.0)
    model.add_generalized_force(h["block"], 10.0)
    system = model.compile()
    t = np.linspace(0.0, 0.5, 11)
    r = rf.simulate(system, 0.5, method="dopri5", rtol=1e-10, atol=0.0, t_eval=t)
    x = 10.0 / 800.0 * (1.0 - np.cos(20.0 * t))
    np.testing.assert_allclose(r.q[:, 0], x, rtol=0, atol=1e-9 * 10.0 / 800.0 * 2)


@pytest.mark.parametrize("method", ["rk4", "newmark"])
def test_fixed_steps_land_on_the_grid(method):
    model, _ = samples.spring_mass()
    system = model.compile()
    t0, dt = 0.3, 1e-5
    r = rf.simulate(system, t0 + 0.2, method=method, dt=dt, t0=t0, q0=[0.01])
    k = np.arange(len(r.t))
    assert len(r.t) == 20_001 and r.stats["steps"] == 20_000  # no sliver step at the end
    np.testing.assert_array_equal(r.t[:-1], t0 + k[:-1] * dt)
    assert r.t[-1] == t0 + 0.2


def test_max_steps_keeps_the_partial_result():
    model, _ = samples.spring_mass()
    system = model.compile()
    with pytest.raises(rf.SimulationError, match="max_steps = 100 reached") as info:
        rf.simulate(system, 10.0, method="rk4", dt=1e-3, q0=[0.01], max_steps=100)
    e = info.value
    assert e.time == pytest.approx(0.1) and len(e.result.t) == 101 and e.result.t[-1] == pytest.approx(0.1)
    np.testing.assert_allclose(e.result.q[:, 0], 0.01 * np.cos(20.0 * e.result.t), atol=1e-9)  # ω = √(800/2)
    for method in ("scipy:Radau", "dopri5"):
        with pytest.raises(rf.SimulationError, match="max_steps") as info:
            rf.simulate(system, 10.0, method=method, q0=[0.01], max_steps=5)
        assert len(info.value.result.t) >= 1 and info.value.result.t[-1] < 10.0


def interrupting_drive(after_calls):
    """A Python drive that raises KeyboardInterrupt at its n-th call, as Ctrl-C does in a callback."""
    calls = [0]

    def drive(t):
        calls[0] += 1
        if calls[0] == after_calls:
            raise KeyboardInterrupt
        return 0.5 * t * t, t, 1.0

    return drive


def pendulum_on_a_python_drive(after_calls):
    model = rf.Model(gravity=(0, 0, -9.81))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.add_body("rod", hub, rf.Joint.revolute("y"), 1.0, samples.rod_inertia(1.0, 1.0), com=(0, 0, -0.5))
    model.prescribe(hub, rf.motion.function(interrupting_drive(after_calls)))
    return model.compile()


@pytest.mark.parametrize("method", ["rk4", "dopri5", "generalized_alpha", "scipy:Radau", "scipy:RK45"])
def test_ctrl_c_in_a_python_drive_returns_the_partial_result(method):
    system = pendulum_on_a_python_drive(after_calls=400)
    with pytest.warns(RuntimeWarning, match="interrupted"):
        r = rf.simulate(system, 100.0, method=method, **step_of(method, 1e-3), q0=[0.3], t_eval=np.linspace(0, 100, 10001))
    assert r.interrupted and 1 <= len(r.t) < 10001 and np.all(np.isfinite(r.q))


def test_ctrl_c_in_a_force_law_returns_the_partial_result():
    model, h = samples.spring_mass()
    calls = [0]

    def law(t, q, qd):
        calls[0] += 1
        if calls[0] == 300:
            raise KeyboardInterrupt
        return 0.0

    model.add_generalized_force(h["block"], law)
    with pytest.warns(RuntimeWarning, match="interrupted"):
        r = rf.simulate(model.compile(), 10.0, method="rk4", dt=1e-3, q0=[0.01])
    assert r.interrupted and 50 <= len(r.t) <= 100 and r.t[-1] < 10.0


def test_other_errors_in_a_python_callback_propagate():
    model, h = samples.spring_mass()
    model.add_generalized_force(h["block"], lambda t, q, qd: 1.0 / 0.0)
    with pytest.raises(ZeroDivisionError):
        rf.simulate(model.compile(), 1.0, method="rk4", dt=1e-3)


@pytest.mark.parametrize("method", ["rk4", "scipy:RK45"])
def test_a_run_in_a_worker_thread_stops_on_its_event(method):
    """Ctrl-C reaches only the main thread: a worker's run stops when its `stop` event is set."""
    model, _ = samples.double_pendulum()
    system = model.compile()
    stop, out = threading.Event(), {}

    def work():
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            out["result"] = rf.simulate(system, 1e4, method=method, **step_of(method, 1e-4), q0=[0.5, 0.0], stop=stop,
                                        t_eval=np.linspace(0, 1e4, 11))
        out["warnings"] = [str(w.message) for w in caught]

    worker = threading.Thread(target=work)
    worker.start()
    threading.Timer(0.3, stop.set).start()
    worker.join(timeout=30)
    assert not worker.is_alive()
    assert out["result"].interrupted and any("interrupted" in w for w in out["warnings"])


def test_wrong_types_are_value_errors_naming_the_argument():
    model, h = samples.double_pendulum()
    s = model.compile()
    q = np.zeros(2)
    calls = {
        "t": lambda: s.forward_dynamics(None, q, q),
        "q": lambda: s.mass_matrix(0.0, "q"),
        "qd": lambda: s.generalized_forces(0.0, q, [None, 1]),
        "load_factor": lambda: s.static_forces(0.0, q, "1"),
        "static": lambda: s.force_jacobians(0.0, q, q, 1.0, "yes"),
        "y": lambda: s.rhs(0.0, None),
        "qdd": lambda: s.inverse_dynamics(0.0, q, q, {}),
        "point": lambda: s.position(None, 0.0, q),
        "data": lambda: rf.stages.kinematics(s, None),
    }
    for argument, call in calls.items():
        with pytest.raises(ValueError, match=f"^{argument}: expected"):
            call()
    with pytest.raises(TypeError):  # a wrong number of arguments stays a TypeError
        s.forward_dynamics(0.0, q)
    for bad, argument in ((dict(method=None), "method"), (dict(max_steps=10**20), "max_steps"),
                          (dict(method="scipy:Radau", rtol=-1), "rtol"), (dict(adaptive="yes"), "adaptive"),
                          (dict(max_step=float("nan")), "max_step"), (dict(stop=1), "stop")):
        with pytest.raises(ValueError, match=f"^{argument}: expected"):
            rf.simulate(s, 0.1, **bad)
    for factor in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="^load_factor: expected a finite"):
            s.static_forces(0.0, q, factor)
        with pytest.raises(ValueError, match="^load_factor: expected a finite"):
            s.force_jacobians(0.0, q, q, factor)


def test_calls_reuse_a_workspace_without_changing_answers():
    """Per-thread workspaces: every call gives what a fresh workspace gives, after other calls
    (a load factor does not leak), from several threads at once, and re-entered from a force law."""
    model, _, rng = samples.random_tree(4, nbodies=7)
    s = model.compile()
    q, qd = rng.uniform(-0.5, 0.5, s.nq), rng.uniform(-1, 1, s.nq)

    def fresh_qdd():
        d = s.make_data()
        rf.stages.set_state(s, d, 0.3, q, qd)
        rf.stages.kinematics(s, d)
        rf.stages.generalized_forces(s, d)
        rf.stages.mass_matrix(s, d)
        return rf.stages.accelerations(s, d)

    reference = s.forward_dynamics(0.3, q, qd)
    np.testing.assert_allclose(reference, fresh_qdd(), rtol=1e-10, atol=1e-12)
    s.static_forces(0.3, q, 0.25)  # a call with another load factor, on the same workspace
    np.testing.assert_array_equal(s.forward_dynamics(0.3, q, qd), reference)

    results = [None] * 4

    def work(k):
        results[k] = [s.forward_dynamics(0.3, q, qd) for _ in range(200)]

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert all(np.array_equal(r, reference) for rows in results for r in rows)

    # A force law that calls the same system re-enters the binding while the outer call holds its workspace.
    m2, h2 = samples.spring_mass()
    inner = {}

    def law(t, x, v):
        inner["energy"] = s2.kinetic_energy(t, [x], [v])
        return 0.0

    m2.add_generalized_force(h2["block"], law)
    s2 = m2.compile()
    assert s2.forward_dynamics(0.0, [0.1], [0.5]) == pytest.approx(-800.0 * 0.1 / 2.0)  # −k x / m
    assert inner["energy"] == pytest.approx(0.5 * 2.0 * 0.25)


def test_positions_of_many_points_in_one_pass():
    model, h = samples.cantilever(elements=8)
    s = model.compile()
    q = np.linspace(0.0, 0.1, s.nq)
    points = h["beam"].points()
    one_by_one = np.array([s.position(p, 0.0, q) for p in points])
    np.testing.assert_allclose(s._positions(points, 0.0, q), one_by_one, rtol=0, atol=1e-15)


def test_lagrange_jacobians_check_their_inputs_and_fixed_only_models_run():
    """Found by the fuzzer and UBSan: the Lagrange force_jacobians copied q before any size check
    (a write past the end: SIGSEGV), and nq = 0 indexed empty use tables."""
    system = samples.double_pendulum()[0].compile("lagrange")
    with pytest.raises(ValueError, match="^q: expected 2 \\(nq\\) values, got 0"):
        system.force_jacobians(0.0, np.zeros(0), np.zeros(2), 1.0, False)
    with pytest.raises(ValueError, match="^t: "):
        system.jacobian(np.inf, np.zeros(4))
    model = rf.Model()
    body = model.add_body("b", model.ground, rf.Joint.fixed(), 1.0, (1, 1, 1), placement=rf.transform((1, 2, 3)))
    fixed = model.compile()
    assert fixed.forward_dynamics(0.0, [], []).shape == (0,)
    np.testing.assert_array_equal(fixed.position(body.point((1, 0, 0)), 0.0, []), [2.0, 2.0, 3.0])
