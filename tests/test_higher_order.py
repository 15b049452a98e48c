"""The implicit Runge–Kutta methods of high order (esdirk43, radau5, radau9): orders observed by convergence
in h on a nonlinear problem and on a stiff chain at h·ω ≫ 1, L-stability, the tolerance delivered
on Kane's beam, prescribed drives at the stage times, dense output, the iteration matrices, the
statistics, failures and bad options. References come from other solvers (SciPy's DOP853 and
Radau, dopri5 at 1e-12), never from the methods' own output."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rigidfem as rf

from conftest import DOUBLE_PENDULUM_Y0 as Y0  # the pendulum2 fixture's initial state

METHODS = ["esdirk43", "radau5", "radau9"]
ORDER = {"esdirk43": 4, "radau5": 5, "radau9": 9}
# Fixed steps whose errors stay above round-off at each method's order (radau9's are 1e-5 to 1e-11 here)
STEPS = {"esdirk43": (0.1, 0.05, 0.025), "radau5": (0.1, 0.05, 0.025), "radau9": (0.4, 0.2, 0.1)}
DRIVE_STEPS = {"esdirk43": (0.05, 0.025, 0.0125), "radau5": (0.05, 0.025, 0.0125), "radau9": (0.2, 0.1, 0.05)}
# Fixed steps: Newton to near round-off, so that its error stays below the method's at the finest step.
TIGHT = {"newton_tol": 1e-13, "newton_max_iterations": 50}


def _observed_orders(errors):
    return np.log2(np.array(errors[:-1]) / errors[1:])


@pytest.mark.parametrize("method,iteration_matrix", [("esdirk43", "tangent"), ("esdirk43", "spring"),
                                                     ("radau5", "tangent")])
def test_order_on_the_double_pendulum(pendulum2, method, iteration_matrix):
    system, ref = pendulum2
    errors = []
    for dt in (0.05, 0.025, 0.0125):
        r = rf.simulate(system, 1.0, method=method, dt=dt, adaptive=False, q0=Y0[:2],
                        iteration_matrix=iteration_matrix, **TIGHT)
        assert r.stats["steps"] == round(1.0 / dt) and r.stats["rejected_steps"] == 0
        errors.append(np.max(np.abs(np.r_[r.q[-1], r.qd[-1]] - ref.y[:, -1])))
    observed = _observed_orders(errors)
    p = ORDER[method]
    assert np.all(observed > p - 0.4) and np.all(observed < p + 0.5), observed


def _stiff_chain(k_stiff=1e8):
    """Three unit masses in series on prismatic joints (springs 100, k_stiff, 50 N/m; the stiff one
    gives ω ≈ 1.4e4 rad/s), the last pushed by 1 N · sin 2t: a linear, stiff system whose slow
    motion is smooth."""
    model = rf.Model(gravity=None)
    body = model.ground
    for i, k in enumerate((100.0, k_stiff, 50.0)):
        body = model.add_body(f"m{i}", body, rf.Joint.prismatic("x", stiffness=k), mass=1.0, inertia=(1e-3,) * 3)
    model.add_force("load0", body, (1.0, 0.0, 0.0), scale=rf.motion.harmonic(1.0, 2.0))
    return model.compile()


@pytest.mark.parametrize("method", METHODS)
def test_order_kept_at_large_h_omega_on_a_stiff_chain(method):
    """Stiff accuracy: at h·ω from 1400 down to 350 (radau9 5600 to 1400) the error still falls as h^p in every
    coordinate (radau9: 8.75, 9.06 and 8.75 measured),
    the stiff spring's quasi-static stretch included (no order reduction); generalised-α, second
    order, for contrast."""
    system = _stiff_chain()
    y0 = np.zeros(6)
    ref = solve_ivp(system.rhs, (0, 2.0), y0, method="Radau", rtol=1e-13, atol=1e-15, jac=system.jacobian).y[:, -1]
    omega = np.max(np.abs(np.linalg.eigvals(system.jacobian(0.0, y0))))
    assert omega > 1e4
    dts = STEPS[method]
    errors = []
    for dt in dts:
        r = rf.simulate(system, 2.0, method=method, dt=dt, adaptive=False, **TIGHT)
        errors.append(np.abs(np.r_[r.q[-1], r.qd[-1]] - ref))
    assert dts[-1] * omega > 300
    orders = np.log2(errors[0][:3] / errors[-1][:3]) / 2  # over two halvings, per coordinate q
    assert np.all(orders > ORDER[method] - 0.3), orders
    alpha = rf.simulate(system, 2.0, method="generalized_alpha", dt=dts[-1])
    assert np.max(np.abs(np.r_[alpha.q[-1], alpha.qd[-1]] - ref)) > 100 * np.max(errors[-1])


@pytest.mark.parametrize("method", METHODS)
def test_stiff_modes_are_damped(method):
    """L-stability: the stiff spring stretched by 1 mm at rest, h·ω ≈ 1400: after one step its
    oscillation is gone (R(∞) = 0: ~1e-4 of it is left), where generalised-α with ρ∞ = 1 keeps its
    full amplitude."""
    system = _stiff_chain()
    q0 = np.array([0.0, 1e-3, 0.0])
    r = rf.simulate(system, 0.5, method=method, dt=0.1, adaptive=False, q0=q0)
    assert np.all(np.abs(r.q[1:, 1]) < 1e-6), r.q[:, 1]
    kept = rf.simulate(system, 0.5, method="generalized_alpha", dt=0.1, q0=q0, rho_inf=1.0)
    assert np.all(np.abs(kept.q[:, 1]) > 0.9e-3)


@pytest.fixture(scope="module")
def kane10():
    """Kane's beam (m = 10, Ω_s = 6 rad/s, T_s = 15 s) over 20 s: the tip in the hub's frame at 201
    times, by dopri5 at rtol = atol = 1e-12 (converged to ~1e-11 m)."""
    model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=10)
    system = model.compile()
    t = np.linspace(0.0, 20.0, 201)
    ref = rf.simulate(system, 20.0, method="dopri5", rtol=1e-12, atol=1e-12, t_eval=t, stiffness_warning=False)
    return system, h, t, ref.position(h["beam"].tip, frame=h["hub"])


def _tip_rms_error(result, h, tip_ref):
    tip = result.position(h["beam"].tip, frame=h["hub"])
    return np.sqrt(np.mean(np.sum((tip - tip_ref) ** 2, axis=1)))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_tolerance_delivered_on_kanes_beam(kane10, method, rtol):
    """The tip's RMS error (m) within 10× rtol times the tip's deflection (about 2 m) when atol is
    well below the sde angles (atol = 1e-3 rtol), and not wastefully far below it (measured:
    0.02-0.2× for esdirk43, 0.72-1.08× for radau5, 0.05-0.45× for radau9, their error held on the bodies'
    displacements); the hub is a prescribed drive,
    evaluated at the stage times."""
    system, h, t, tip_ref = kane10
    scale = np.max(np.abs(tip_ref[:, 1]))
    r = rf.simulate(system, 20.0, method=method, rtol=rtol, atol=1e-3 * rtol, t_eval=t)
    error = _tip_rms_error(r, h, tip_ref)
    assert 1e-3 * rtol * scale < error < 10 * rtol * scale, (error, rtol * scale)
    s = r.stats
    assert s["jacobians"] >= 1 and s["factorizations"] >= s["jacobians"]
    stages_per_iteration = {"esdirk43": 1, "radau5": 3, "radau9": 5}[method]  # radau iterates on all its stages
    assert s["rhs_evaluations"] >= stages_per_iteration * s["newton_iterations"] >= s["steps"]
    assert s["newton_iterations"] >= {"esdirk43": 5, "radau5": 1, "radau9": 1}[method] * s["steps"]


@pytest.mark.parametrize("method", METHODS)
def test_order_with_a_prescribed_drive(method):
    """The double pendulum's first joint driven, θ₁ = sin 3t: were the drive evaluated anywhere but
    at each stage's time, the order would fall to 1 or 2 (radau9 measured 8.86 and 9.14)."""
    model, h = rf.samples.double_pendulum()
    model.prescribe(h["link1"], rf.motion.harmonic(1.0, 3.0))
    system = model.compile()
    ref = rf.simulate(system, 2.0, method="dopri5", rtol=1e-13, atol=1e-13, q0=[0.5], t_eval=[2.0])
    errors = []
    for dt in DRIVE_STEPS[method]:
        r = rf.simulate(system, 2.0, method=method, dt=dt, adaptive=False, q0=[0.5], t_eval=[2.0], **TIGHT)
        errors.append(np.max(np.abs(np.r_[r.q[-1] - ref.q[-1], r.qd[-1] - ref.qd[-1]])))
    observed = _observed_orders(errors)
    assert np.all(observed > ORDER[method] - 0.4), (observed, errors)


@pytest.mark.parametrize("method", ["esdirk43", "radau5"])  # radau9's: test_radau9_dense_output_is_its_collocation...
def test_dense_output_between_steps(pendulum2, method):
    system, ref = pendulum2
    t = np.linspace(0, 1.0, 37)
    r = rf.simulate(system, 1.0, method=method, q0=Y0[:2], t_eval=t, rtol=1e-7, atol=1e-9)
    steps = rf.simulate(system, 1.0, method=method, q0=Y0[:2], rtol=1e-7, atol=1e-9)  # the same steps
    np.testing.assert_array_equal(r.t, t)
    assert r.stats["steps"] == steps.stats["steps"] and not np.isin(t[1:-1], steps.t).any()  # all inside steps
    # q̇ is the quintic's derivative, an order lower: between steps its error was 1.3-2.05 times that at the
    # steps for esdirk43 at rtol 3e-8 to 1e-6 (0.84-1.09 for radau5; q's 0.99-1.01 for both)
    for k, what, most in ((slice(0, 2), "q", 2), (slice(2, 4), "qd", 3)):
        at_steps = np.max(np.abs(getattr(steps, what) - ref.sol(steps.t)[k].T))
        between = np.max(np.abs(getattr(r, what) - ref.sol(t)[k].T))
        assert between < most * at_steps, (what, between, at_steps)
    # Fixed steps: the quintic Hermite interpolant of (q, q̇, q̈) is O(h⁶) in q, beyond the methods'
    # own order: at mid-steps the error is no larger than at the steps' ends.
    at_ends = rf.simulate(system, 1.0, method=method, dt=0.05, adaptive=False, q0=Y0[:2], **TIGHT)
    mid = rf.simulate(system, 1.0, method=method, dt=0.05, adaptive=False, q0=Y0[:2],
                      t_eval=np.arange(0.025, 1.0, 0.05), **TIGHT)
    err_ends = np.max(np.abs(at_ends.q - ref.sol(at_ends.t)[:2].T))
    err_mid = np.max(np.abs(mid.q - ref.sol(mid.t)[:2].T))
    assert err_mid < 2 * err_ends, (err_mid, err_ends)


def test_esdirk_spring_matrix_agrees_with_the_tangent(kane10):
    system, h, t, tip_ref = kane10
    spring = rf.simulate(system, 20.0, method="esdirk43", rtol=1e-6, atol=1e-9, t_eval=t, iteration_matrix="spring")
    tangent = rf.simulate(system, 20.0, method="esdirk43", rtol=1e-6, atol=1e-9, t_eval=t)
    assert spring.stats["jacobians"] == 0 and tangent.stats["jacobians"] >= 1
    assert _tip_rms_error(spring, h, tip_ref) < 2e-5
    assert _tip_rms_error(tangent, h, tip_ref) < 2e-5


@pytest.mark.parametrize("method", METHODS)
def test_failures_name_time_and_cause(pendulum2, method):
    system, _ = pendulum2
    # Newton allowed one iteration at a large fixed step: it cannot converge.
    with pytest.raises(rf.SimulationError, match="Newton") as info:
        rf.simulate(system, 1.0, method=method, dt=0.5, adaptive=False, q0=Y0[:2], newton_max_iterations=1)
    assert info.value.time == 0.0 and len(info.value.result.t) == 1
    with pytest.raises(rf.SimulationError, match="max_steps") as info:
        rf.simulate(system, 1.0, method=method, q0=Y0[:2], rtol=1e-10, max_steps=20)
    assert 0.0 < info.value.time < 1.0
    # q̈ = 10 q³ from q = 1 at rest blows up at t* = ∫₁^∞ dq / √(5 (q⁴ − 1)) = 1.311029 / √5 = 0.586316 s
    # (the lemniscate constant ϖ/2): the step size collapses there.
    model, handles = rf.samples.spring_mass(mass=1.0, stiffness=0.0)
    model.add_generalized_force(handles["block"], lambda t, q, qd: 10.0 * q**3)
    with pytest.raises(rf.SimulationError) as info:
        rf.simulate(model.compile(), 2.0, method=method, q0=[1.0])
    assert 0.58 < info.value.time <= 0.586316, info.value
    assert any(word in info.value.cause for word in ("minimum", "NaN", "Newton")), info.value.cause


@pytest.mark.parametrize("method", METHODS)
def test_bad_options(pendulum2, method):
    system, _ = pendulum2
    with pytest.raises(ValueError, match="dt"):
        rf.simulate(system, 1.0, method=method, adaptive=False, q0=Y0[:2])
    with pytest.raises(ValueError, match="iteration_matrix"):
        rf.simulate(system, 1.0, method=method, iteration_matrix="jacobian", q0=Y0[:2])
    with pytest.raises(ValueError, match="rtol"):
        rf.simulate(system, 1.0, method=method, rtol=-1e-6, q0=Y0[:2])
    with pytest.raises(ValueError, match="method"):
        rf.simulate(system, 1.0, method=method[:-1], q0=Y0[:2])


@pytest.mark.parametrize("method", ["radau5", "radau9"])
def test_radau_refuses_the_spring_matrix(pendulum2, method):
    system, _ = pendulum2
    with pytest.raises(ValueError, match="iteration_matrix.*spring"):
        rf.simulate(system, 1.0, method=method, iteration_matrix="spring", q0=Y0[:2])


def test_auto_takes_its_stiff_methods_refusals():
    """auto's stiff method (a private option) is held to that method's own checks: radau9 or radau5 on a Maxwell arm
    is a ValueError naming stiff_method (radau9 crashed the interpreter before), esdirk43 runs."""
    from rigidfem import _core
    from rigidfem.simulation import options
    from test_viscoelastic import zener_oscillator

    system = zener_oscillator()[0].compile()
    o = options.compiled("auto", {})
    for method in ("radau9", "radau5"):
        o.stiff_method = method
        with pytest.raises(ValueError, match=f"^stiff_method: auto's stiff method '{method}' refuses the run "
                                             f"\\(method: '{method}' does not integrate Maxwell arms"):
            _core._integrate(system, 0.0, 0.1, [0.01], [0.0], np.array([]), o, lambda t: True)
    o.stiff_method = "esdirk43"
    _core._integrate(system, 0.0, 0.1, [0.01], [0.0], np.array([]), o, lambda t: True)


def test_radau9_refusals(pendulum2):
    """radau9 has no sensitivities, no adjoint and no Maxwell arms; each refusal names the argument. Its row of the
    method table: order 9, adaptive."""
    from test_viscoelastic import zener_oscillator

    with pytest.raises(ValueError, match="method: 'radau9' does not integrate Maxwell arms"):
        rf.simulate(zener_oscillator()[0].compile(), 1.0, method="radau9")
    assert rf.methods()["radau9"].order == 9 and rf.methods()["radau9"].adaptive
    system, _ = pendulum2
    with pytest.raises(ValueError, match="^sensitivities: radau9 has no sensitivities; use radau5"):
        rf.simulate(system, 1.0, method="radau9", q0=Y0[:2], sensitivities=["link1.mass"])
    with pytest.raises(ValueError, match="^method: expected one of .*radau5.*the methods with an adjoint.*radau9"):
        rf.gradient(system, 1.0, ["link1.mass"], method="radau9", dt=0.01, outputs=lambda t, q, qd: q[0])


def test_radau_on_a_free_four_bar():
    """The four-bar of test_loops (3 of its 5 rows redundant) falling under gravity: every stage holds
    M A_i − f_i − G_iᵀλ_i = 0 and G_i A_i = γ_i (Newton's Schur complement over the stages, least-norm
    multipliers), each step ends projected onto the loop. Order 5 at fixed steps against dopri5 at
    1e-12 (measured 9.4, 4.3, 5.1 from dt = 0.02), the closure at every output, and adaptive runs
    against the same reference."""
    from test_loops import closed_q, four_bar

    system = four_bar()
    q0, _ = system.assemble(closed_q(0.4))
    ref = rf.simulate(system, 1.0, method="dopri5", q0=q0, rtol=1e-12, atol=1e-12, t_eval=[1.0])
    errors = []
    for dt in (0.02, 0.01, 0.005, 0.0025):
        r = rf.simulate(system, 1.0, method="radau5", q0=q0, dt=dt, adaptive=False, **TIGHT)
        errors.append(np.abs(r.q[-1] - ref.q[-1]).max())
        closure = [np.abs(system.loop_constraints(tk, qk, qdk)[0]).max() for tk, qk, qdk in zip(r.t, r.q, r.qd)]
        assert max(closure) <= 1e-12
    observed = _observed_orders(errors)[1:]  # from dt = 0.02 the error falls 670-fold (a cancellation)
    assert np.all(observed > 4.2) and observed.mean() > 4.6, (observed, errors)  # measured 4.33, 5.14
    # measured 5.8e-7 and 1.2e-8 (|q| up to 5 rad); 5.3e-6 and 3.3e-7 while Newton was held to radau5's
    # looser rtol' = 0.1 rtol^(2/3) instead of rtol (its errors add up over the steps)
    for rtol, bound in ((1e-6, 2e-6), (1e-8, 6e-8)):
        adaptive = rf.simulate(system, 1.0, method="radau5", q0=q0, rtol=rtol, atol=1e-2 * rtol, t_eval=[1.0])
        assert np.abs(adaptive.q[-1] - ref.q[-1]).max() < bound


@pytest.mark.parametrize("iteration_matrix", ["tangent", "spring"])
def test_esdirk_on_a_free_four_bar(iteration_matrix):
    """A closed loop (the four-bar of test_loops, 3 of its 5 rows redundant) falling under gravity:
    the stages hold G A = γ with their multipliers, each step ends projected onto the loop. Order 4
    at fixed steps against dopri5 at 1e-12, the closure at every output, and an adaptive run within
    its tolerance."""
    from test_loops import closed_q, four_bar

    system = four_bar()
    q0, _ = system.assemble(closed_q(0.4))
    ref = rf.simulate(system, 1.0, method="dopri5", q0=q0, rtol=1e-12, atol=1e-12, t_eval=[1.0])
    errors = []
    for dt in (0.02, 0.01, 0.005):
        r = rf.simulate(system, 1.0, method="esdirk43", q0=q0, dt=dt, adaptive=False,
                        iteration_matrix=iteration_matrix, **TIGHT)
        errors.append(np.abs(r.q[-1] - ref.q[-1]).max())
        closure = [np.abs(system.loop_constraints(tk, qk, qdk)[0]).max() for tk, qk, qdk in zip(r.t, r.q, r.qd)]
        assert max(closure) <= 1e-12
    observed = _observed_orders(errors)
    assert np.all(observed > 3.7), (observed, errors)
    adaptive = rf.simulate(system, 1.0, method="esdirk43", q0=q0, rtol=1e-8, atol=1e-10, t_eval=[1.0],
                           iteration_matrix=iteration_matrix)
    assert np.abs(adaptive.q[-1] - ref.q[-1]).max() < 1e-6


@pytest.mark.parametrize("method", METHODS)
def test_nothing_to_solve(method):
    """Every coordinate prescribed (nq = 0): one step over the span, outputs at t_eval."""
    model, h = rf.samples.pendulum()
    model.prescribe(h["link"], rf.motion.harmonic(1.0, 2.0))
    system = model.compile()
    r = rf.simulate(system, 1.0, method=method, t_eval=[0.5, 1.0])
    assert r.q.shape == (2, 0) and r.stats["steps"] == 1


def test_dop853_is_of_order_eight_with_a_dense_output_of_order_seven_and_takes_fewer_evaluations():
    """x'' = −ω² x (ω = 2 rad/s), x = cos ω t over 10 s. At fixed steps h = 0.2, 0.1, 0.05 s the end's error falls
    at order 8 and the outputs between steps (dense output, three more stages) at order 7 at least; adaptive, it
    meets the tolerance with 3 to 7 times fewer evaluations than dopri5 at rtol 1e-9 and 1e-12."""
    model = rf.Model(gravity=(0.0, 0.0, 0.0))
    model.add_body("mass", model.ground, rf.Joint.prismatic("x", stiffness=4.0), 1.0, (1.0, 1.0, 1.0))
    system = model.compile()
    t_mid = np.linspace(0.0, 10.0, 38)[1:-1] + 0.0137  # between the steps
    ends, middles = [], []
    for h in (0.2, 0.1, 0.05):
        r = rf.simulate(system, 10.0, "dop853", dt=h, adaptive=False, q0=[1.0], t_eval=np.r_[t_mid, 10.0])
        assert r.stats["steps"] == round(10.0 / h)
        ends.append(abs(r.q[-1, 0] - np.cos(20.0)))
        middles.append(np.abs(r.q[:-1, 0] - np.cos(2.0 * t_mid)).max())
    assert np.all(np.log2(np.array(ends[:-1]) / ends[1:]) > 7.7), ends
    assert np.all(np.log2(np.array(middles[:-1]) / middles[1:]) > 6.7), middles
    t = np.linspace(0.0, 10.0, 37)
    for rtol in (1e-9, 1e-12):
        eight = rf.simulate(system, 10.0, "dop853", q0=[1.0], t_eval=t, rtol=rtol, atol=1e-2 * rtol)
        five = rf.simulate(system, 10.0, "dopri5", q0=[1.0], t_eval=t, rtol=rtol, atol=1e-2 * rtol)
        assert np.abs(eight.q[:, 0] - np.cos(2.0 * t)).max() < 10 * rtol
        assert five.stats["rhs_evaluations"] > 3 * eight.stats["rhs_evaluations"]


def test_dop853_on_a_free_four_bar_keeps_the_loop_and_agrees_with_radau5():
    """The four-bar of test_loops falling under gravity: dop853's steps drift off the loop and are projected back,
    so every output closes it (1e-12); adaptive runs at rtol 1e-8 and 1e-11 agree with radau5 at 1e-12 (measured
    3.8e-9 and 1.3e-11 rad)."""
    from test_loops import closed_q, four_bar

    system = four_bar()
    q0, _ = system.assemble(closed_q(0.4))
    t = np.linspace(0.0, 1.0, 11)
    ref = rf.simulate(system, 1.0, method="radau5", q0=q0, rtol=1e-12, atol=1e-12, t_eval=t)
    for rtol, bound in ((1e-8, 2e-8), (1e-11, 1e-10)):
        r = rf.simulate(system, 1.0, method="dop853", q0=q0, rtol=rtol, atol=1e-2 * rtol, t_eval=t)
        assert np.abs(r.q - ref.q).max() < bound
        closure = [np.abs(system.loop_constraints(tk, qk, qdk)[0]).max() for tk, qk, qdk in zip(r.t, r.q, r.qd)]
        assert max(closure) <= 1e-12


def _tableau(name):
    """c, a of Radau IIA (Hairer & Wanner IV.5, Table 5.6, from √6) or Gauss–Legendre (Table 5.2, from √15)."""
    if name == "radau":
        r6 = np.sqrt(6.0)
        return np.array([[(88 - 7 * r6) / 360, (296 - 169 * r6) / 1800, (-2 + 3 * r6) / 225],
                         [(296 + 169 * r6) / 1800, (88 + 7 * r6) / 360, (-2 - 3 * r6) / 225],
                         [(16 - r6) / 36, (16 + r6) / 36, 1 / 9]])
    r15 = np.sqrt(15.0)
    return np.array([[5 / 36, 2 / 9 - r15 / 15, 5 / 36 - r15 / 30],
                     [5 / 36 + r15 / 24, 2 / 9, 5 / 36 - r15 / 24],
                     [5 / 36 + r15 / 30, 2 / 9 + r15 / 15, 5 / 36]])


@pytest.mark.parametrize("name,constructor", [("radau", "RadauTableau::RadauTableau"),
                                              ("gauss", "GaussTableau::GaussTableau")])
def test_collocation_decomposition_constants(name, constructor):
    """radau.cpp writes Radau IIA's and Gauss–Legendre's a = P diag(d) P⁻¹ as hexadecimal constants: read from the
    source, they must be the eigen-decomposition of a computed here to round-off, with d(0) real and
    Im d(1) > 0, and P⁻¹ P's inverse."""
    import re
    from pathlib import Path

    source = (Path(__file__).parents[1] / "cpp" / "src" / "radau.cpp").read_text()
    source = source[source.index(constructor + "()"):]

    def constants(key, count):
        block = re.search(rf"\b{key} << (.*?);", source, re.S).group(1)
        pairs = re.findall(r"C\(([-+0-9a-fx.p]+), ([-+0-9a-fx.p]+)\)", block)
        assert len(pairs) == count
        return np.array([complex(float.fromhex(x), float.fromhex(y)) for x, y in pairs])

    d, P, Pinv = constants("d", 3), constants("P", 9).reshape(3, 3), constants("Pinv", 9).reshape(3, 3)
    a = _tableau(name)
    assert d[0].imag == 0.0 and d[1].imag > 0.0 and d[2] == np.conj(d[1])
    np.testing.assert_allclose(np.sort_complex(d), np.sort_complex(np.linalg.eigvals(a)), rtol=0, atol=1e-15)
    np.testing.assert_allclose(a @ P, P @ np.diag(d), rtol=0, atol=1e-15)  # P's columns: eigenvectors
    np.testing.assert_allclose(P @ Pinv, np.eye(3), rtol=0, atol=1e-15)
    np.testing.assert_allclose((P @ np.diag(d) @ Pinv).real, a, rtol=0, atol=1e-15)


def test_radau5_renews_a_long_serving_tangent_when_newton_slows():
    """A steel strip (1 m, 20 × 2 mm, m = 8, bending only, undamped) released from rest under gravity
    for 2 s: the tangent taken at the start would serve the whole run while Newton's contraction
    slows as the strip bends (θ > 0.05). Renewed once it has served 20 steps, it keeps Newton under
    2.1 iterations a step (measured: 2.02 with 8 tangents; 2.22 with the start's alone) at no cost
    in accuracy: the tip within 10 rtol of its sag of a run at rtol 1e-10."""
    s = _released_strip_stats(8, "radau5")
    assert s["jacobians"] >= 4 and s["newton_iterations"] < 2.1 * s["steps"], s


def _released_strip_stats(m, method):
    """A steel strip (1 m, 20 × 2 mm, m rfes, bending only, undamped) released from rest under gravity for 2 s, run
    by `method` at rtol 1e-5 (atol 1e-7): asserts the tip within 10 rtol of its sag of radau5 at rtol 1e-10 and
    returns the run's statistics."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    beam = model.add_beam("beam", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.002, 0.02), m, deform=("bend_z",))
    system = model.compile()
    t = np.linspace(0.0, 2.0, 201)
    r = rf.simulate(system, 2.0, method=method, rtol=1e-5, atol=1e-7, t_eval=t, stiffness_warning=False)
    ref = rf.simulate(system, 2.0, method="radau5", rtol=1e-10, atol=1e-12, t_eval=t, stiffness_warning=False)
    sag = np.max(np.abs(ref.position(beam.tip)[:, 1] - ref.position(beam.tip)[0, 1]))
    assert np.max(np.abs(r.position(beam.tip) - ref.position(beam.tip))) < 10 * 1e-5 * sag
    return r.stats


def test_radau9_tableau_constants():
    """radau.cpp writes every number of Radau IIA's 5-stage tableau as a hexadecimal constant. Computed here
    independently: c the zeros of d⁴/dx⁴ (x⁴ (x − 1)⁵), a by the collocation conditions Σ_j a_ij c_j^(k−1) = c_i^k/k
    (k = 1..5), b = a's last row, a = P diag(d) P⁻¹ with d(0) real and the pairs conjugate, and the estimate's
    weights dd = a⁻ᵀ(b̂ − b)/d₀ for the order-5 quadrature b̂ on (0, c) whose weight at 0 is d₀ (radau5's dd come
    out of the same rule: −(13 + 7√6)/3, (−13 + 7√6)/3, −1/3)."""
    import re
    from pathlib import Path

    source = (Path(__file__).parents[1] / "cpp" / "src" / "radau.cpp").read_text()
    source = source[source.index("Radau9Tableau::Radau9Tableau()"):]
    source = source[:source.index("\n}\n")]

    def reals(key, count):
        block = re.search(rf"\b{key} << (.*?);", source, re.S).group(1)
        values = [float.fromhex(x) for x in re.findall(r"[-+]?0x[0-9a-f.]+p[-+]?\d+", block)]
        assert len(values) == count
        return np.array(values)

    def complexes(key, count):
        block = re.search(rf"\b{key} << (.*?);", source, re.S).group(1)
        pairs = re.findall(r"C\(([-+0-9a-fx.p]+), ([-+0-9a-fx.p]+)\)", block)
        assert len(pairs) == count
        return np.array([complex(float.fromhex(x), float.fromhex(y)) for x, y in pairs])

    radau = np.polynomial.Legendre.basis(5) - np.polynomial.Legendre.basis(4)  # its zeros in [-1, 1]: 2c − 1
    x = np.sort(radau.roots().real)
    for _ in range(3):  # Newton on the zeros, to round-off
        x = x - radau(x) / radau.deriv()(x)
    c_ref = (x + 1.0) / 2.0
    x4 = np.polynomial.Polynomial.fromroots([0.0] * 4 + [1.0] * 5).deriv(4)  # the same zeros, as the docstring says
    assert np.abs(x4(c_ref)).max() < 1e-12 * np.abs(x4.coef).max()
    V = np.vander(c_ref, 5, increasing=True)  # V_jk = c_j^k
    a_ref = np.linalg.solve(V.T, (c_ref[:, None] ** np.arange(1, 6) / np.arange(1, 6)).T).T
    c, a, dd = reals("c", 5), reals("a", 25).reshape(5, 5), reals("dd", 5)
    d, P, Pinv = complexes("d", 5), complexes("P", 25).reshape(5, 5), complexes("Pinv", 25).reshape(5, 5)
    np.testing.assert_allclose(c, c_ref, rtol=0, atol=1e-15)
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-14)
    assert d[0].imag == 0.0 and d[1].imag > 0.0 and d[3].imag > 0.0
    assert d[2] == np.conj(d[1]) and d[4] == np.conj(d[3])
    np.testing.assert_allclose(np.sort_complex(d), np.sort_complex(np.linalg.eigvals(a_ref)), rtol=0, atol=1e-14)
    np.testing.assert_allclose(a_ref @ P, P @ np.diag(d), rtol=0, atol=1e-14)
    np.testing.assert_allclose(P @ Pinv, np.eye(5), rtol=0, atol=1e-14)
    np.testing.assert_allclose(dd, _estimate_weights(c_ref, a_ref), rtol=1e-12, atol=0)
    r6 = np.sqrt(6.0)  # the same rule gives radau5's weights (radau5.f's DD1, DD2, DD3)
    np.testing.assert_allclose(_estimate_weights(np.array([(4 - r6) / 10, (4 + r6) / 10, 1.0]), _tableau("radau")),
                               [-(13 + 7 * r6) / 3, (-13 + 7 * r6) / 3, -1.0 / 3], rtol=1e-12)


def _estimate_weights(c, a):
    """Hairer's estimate weights dd = a⁻ᵀ(b̂ − b)/d₀ (d₀ a's real eigenvalue, b = a's last row) for the quadrature
    b̂ of order s on the nodes (0, c) whose weight at 0 is d₀: Σ b̂_j c_j^(k−1) = 1/k − d₀ [k = 1], k = 1..s."""
    s = len(c)
    eig = np.linalg.eigvals(a)
    d0 = eig[np.argmin(np.abs(eig.imag))].real
    V = np.vander(c, s, increasing=True).T  # V_kj = c_j^k
    bhat = np.linalg.solve(V, 1.0 / np.arange(1, s + 1) - np.r_[d0, np.zeros(s - 1)])
    return np.linalg.solve(a.T, bhat - a[-1]) / d0


def test_radau9_dense_output_is_its_collocation_polynomial(pendulum2):
    """radau9's steps are long (20 to 56 over the double pendulum's second at rtol 1e-5 to 1e-9): the quintic Hermite
    interpolant of radau5 left q 12-76 times less accurate between its steps than at them. Its q from the
    collocation polynomial of q̇ is within 1.5 times (measured 1.00-1.20); q̇ itself, the collocation polynomial,
    O(h⁶), within 60 times (3-49)."""
    system, ref = pendulum2
    t = np.linspace(0, 1.0, 37)
    for rtol in (1e-5, 1e-7, 1e-9):
        r = rf.simulate(system, 1.0, method="radau9", q0=Y0[:2], t_eval=t, rtol=rtol, atol=1e-2 * rtol)
        steps = rf.simulate(system, 1.0, method="radau9", q0=Y0[:2], rtol=rtol, atol=1e-2 * rtol)
        assert not np.isin(t[1:-1], steps.t).any()
        for k, what, most in ((slice(0, 2), "q", 1.5), (slice(2, 4), "qd", 60)):
            at_steps = np.max(np.abs(getattr(steps, what) - ref.sol(steps.t)[k].T))
            between = np.max(np.abs(getattr(r, what) - ref.sol(t)[k].T))
            assert between < most * at_steps, (rtol, what, between, at_steps)


def test_radau9_on_a_free_four_bar():
    """The four-bar of test_loops falling under gravity: radau9's stages hold the loop as radau5's do (the Schur
    complement over 5 stages). At h = 20 ms its error is 1/500 of radau5's (measured 4.5e-9 and 2.3e-6 rad against
    dopri5 at 1e-12), every output closes the loop, and adaptive runs hold rtol."""
    from test_loops import closed_q, four_bar

    system = four_bar()
    q0, _ = system.assemble(closed_q(0.4))
    ref = rf.simulate(system, 1.0, method="dopri5", q0=q0, rtol=1e-12, atol=1e-12, t_eval=[1.0])
    errors = {}
    for method in ("radau5", "radau9"):
        r = rf.simulate(system, 1.0, method=method, q0=q0, dt=0.02, adaptive=False, **TIGHT)
        errors[method] = np.abs(r.q[-1] - ref.q[-1]).max()
        closure = [np.abs(system.loop_constraints(tk, qk, qdk)[0]).max() for tk, qk, qdk in zip(r.t, r.q, r.qd)]
        assert max(closure) <= 1e-12
    assert errors["radau9"] < 1e-2 * errors["radau5"], errors
    for rtol, bound in ((1e-6, 2e-6), (1e-8, 6e-8)):  # measured 3.3e-7 (35 steps) and 3.9e-10 (61)
        adaptive = rf.simulate(system, 1.0, method="radau9", q0=q0, rtol=rtol, atol=1e-2 * rtol, t_eval=[1.0])
        assert np.abs(adaptive.q[-1] - ref.q[-1]).max() < bound


def test_radau9_on_a_ringing_strip_iterates_twice_a_step():
    """The strip of the test above with 16 rfes (the whippy strip of docs/peers.md) at radau9's long steps, where
    modes ring at hω of 3 to 10: continuing the last step's polynomial started Newton far off (2.47 iterations a
    step); the predictor that came closer on the last step, and a tangent renewed from θ > 0.02, keep it under
    2.15 (measured 2.06), at the tolerance: the tip within 10 rtol of its sag of radau5 at rtol 1e-10."""
    s = _released_strip_stats(16, "radau9")
    assert s["newton_iterations"] < 2.15 * s["steps"], s
