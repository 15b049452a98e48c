"""Robust at every position and size (issue 27): no silent NaN or inf from finite inputs, the contract of
the loop and element methods and of rf.joint_transform, loop reactions with the Maxwell arms' forces,
closed chains refused by the scipy: methods, dt given to an adaptive method, every run's stats["method"],
the growth warning, and rf.sweep's parameters."""

import numpy as np
import pytest

import rigidfem as rf


def four_bar(arm: bool = False):
    """rf.samples.four_bar with a spring-damper from the ground to the coupler and, optionally, a Maxwell arm
    on the crank's joint: (model, system, q0 closing the loop, crank)."""
    model, h = rf.samples.four_bar()
    model.add_spring_damper("element0", model.ground, h["coupler"], stiffness=10.0, length=0.5)
    if arm:
        model.add_maxwell_arm(h["crank"], stiffness=50.0, tau=0.1)
    system = model.compile()
    return model, system, system.assemble([0.4, -1.9, 4.6])[0], h["crank"]


@pytest.mark.parametrize("name", ["loop_constraints", "loop_multipliers", "loop_reactions", "element_states"])
@pytest.mark.parametrize("bad, says", [("complex", "complex values"), ("row", r"shape \(1, 3\)"), ("text", "'abc'")])
def test_loop_and_element_methods_name_a_bad_q(name, bad, says):
    _, system, q, _ = four_bar()
    value = {"complex": q.astype(complex), "row": q[None, :], "text": "abc"}[bad]
    with pytest.raises(ValueError, match=f"^q: expected a 1-D array of coordinates.*{says}"):
        getattr(system, name)(0.0, value, np.zeros(3))


@pytest.mark.parametrize("bad, says", [([0.1 + 1j], "complex values"), ([[0.1]], "an array of 2 dimensions"),
                                       ("x", "'x'"), ([0.1, 0.2], "got 2")])
def test_joint_transform_names_a_bad_q(bad, says):
    with pytest.raises(ValueError, match=f"^q: expected.*{says}"):
        rf.joint_transform(["rz"], bad)
    with pytest.raises(ValueError, match="^coordinates: expected a list of names"):
        rf.joint_transform("rz", [0.1])
    with pytest.raises(ValueError, match="^i: expected the index of a coordinate"):
        rf.joint_transform_derivative(["rz"], [0.1], "0")


def test_overflowing_results_are_simulation_errors():
    """Finite but huge rates make the velocity terms overflow: a SimulationError naming the call and the
    largest input, never NaN or inf returned."""
    model, h = rf.samples.kane_beam(elements=3)
    system = model.compile()
    q, huge = np.zeros(system.nq), np.full(system.nq, 1e200)
    for call in (lambda: system.generalized_forces(0.0, q, huge), lambda: system.inverse_dynamics(0.0, q, huge, q),
                 lambda: system.kinetic_energy(0.0, q, huge)):
        with pytest.raises(rf.SimulationError, match=r"overflowed: finite inputs \(.*largest \|qd\| = 1e\+200"):
            call()
    stiff = rf.Model(gravity=None)
    stiff.add_body("b", stiff.ground, rf.Joint.prismatic("x", stiffness=1e300), mass=1e-12, inertia=(1, 1, 1))
    with pytest.raises(rf.SimulationError, match="modal analysis: the eigenvalues overflowed"):
        rf.modal_analysis(stiff.compile())


def test_a_huge_initial_angle_is_refused_and_energies_stay_finite():
    model, h = rf.samples.pendulum()
    system = model.compile()
    with pytest.raises(ValueError, match=r"q0: expected coordinates within ±1e\+15"):
        rf.simulate(system, 0.1, q0=[1e300])
    # no spring: its coordinate adds no elastic energy even where (q − q⁰)² would overflow
    assert system.elastic_energy(0.0, [1e200]) == 0.0
    r = rf.simulate(system, 0.1, q0=[1e12])
    assert np.all(np.isfinite(r.energy))


def test_loop_reactions_hold_the_arm_forces():
    """A four-bar with a Maxwell arm on the crank, released with the arm's force s0 = 5 N·m: its reactions
    are those of the same four-bar without the arm under a constant torque −5 N·m on the crank (the arm's
    force acts as −s on its coordinate), and differ from the relaxed arm's."""
    _, system, q0, _ = four_bar(arm=True)
    t = np.linspace(0.0, 0.05, 3)
    with_arm = rf.simulate(system, 0.05, q0=q0, t_eval=t, s0=[5.0])
    model, _, _, crank = four_bar()
    model.add_generalized_force(crank, -5.0)
    torqued = model.compile()
    expected = torqued.loop_reactions(0.0, with_arm.q[0], with_arm.qd[0])
    np.testing.assert_allclose(with_arm.loop_reactions[0], expected, rtol=1e-9, atol=1e-9)
    relaxed = rf.simulate(system, 0.05, q0=q0, t_eval=t)
    assert np.abs(relaxed.loop_reactions[0] - with_arm.loop_reactions[0]).max() > 1.0


def test_the_newmark_family_reports_its_own_multipliers(tmp_path):
    """generalized_alpha's loop reactions are its own index-3 multipliers λ_{n+1} (linear inside a step):
    second order against a tight esdirk43 reference (whose reactions are the forward dynamics' at its
    outputs), distinct from the forward dynamics' at its own outputs, and said so in stats; kept by npz."""
    import dataclasses

    _, system, q0, _ = four_bar(arm=True)
    t = np.linspace(0.0, 0.5, 11)  # outputs inside the steps of 3 ms and on those of 1.5 ms
    ref = rf.simulate(system, 0.5, q0=q0, t_eval=t, s0=[5.0], method="esdirk43", rtol=1e-11, atol=1e-12)
    assert ref.stats["loop_reactions"] == "the forward dynamics' multipliers at each output's state"
    errors = []
    for dt in (3e-3, 1.5e-3):
        r = rf.simulate(system, 0.5, q0=q0, t_eval=t, s0=[5.0], method="generalized_alpha", dt=dt)
        assert r.stats["loop_reactions"] == "generalized_alpha's own multipliers (index 3, linear between its steps' ends)"
        errors.append(np.abs(r.loop_reactions - ref.loop_reactions).max())
        state = dataclasses.replace(r, multipliers=None).loop_reactions  # the forward dynamics' at r's outputs
        assert 0.05 * errors[-1] < np.abs(r.loop_reactions - state).max() < 10 * errors[-1]
    assert 3.5 < errors[0] / errors[1] < 4.5, errors
    back = rf.load_npz(r.to_npz(tmp_path / "r.npz"), system)
    assert np.array_equal(back.loop_reactions, r.loop_reactions)


@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
def test_the_jacobian_of_a_closed_chain_is_that_of_its_constrained_rhs(algorithm):
    """A spatial double pendulum held by a cylinder from the ground to its tip: System.jacobian and
    acceleration_derivatives against central differences of System.rhs (they used to leave out the loops:
    an error of 1.65e4 against entries of 61, and solve_ivp's Radau with jac= took 360 times the work)."""
    from scipy.integrate import solve_ivp

    model, h = rf.samples.double_pendulum(spatial=True)
    model.add_actuator("loop0", model.ground.point((1.0, 0.0, 0.0)), h["tip"], rf.motion.polynomial([1.5, 0.1]))
    system = model.compile(algorithm)
    q, qd = system.assemble(0.2 * np.ones(6), 0.1 * np.ones(6))
    y = np.r_[q, qd]
    eps = 1e-4  # the constrained q̈ carries rounding of ~1e-11 relative (its SVD): a step above round-off's
    J = np.column_stack([(system.rhs(0.0, y + eps * e) - system.rhs(0.0, y - eps * e)) / (2 * eps) for e in np.eye(12)])
    np.testing.assert_allclose(system.jacobian(0.0, y), J, atol=3e-6 * np.abs(J).max())
    dq, dqd = system.acceleration_derivatives(0.0, q, qd)
    np.testing.assert_allclose(np.hstack([dq, dqd]), J[6:], atol=3e-6 * np.abs(J).max())
    runs = [solve_ivp(system.rhs, (0.0, 1.0), y, method="Radau", rtol=1e-6, atol=1e-8, jac=jac)
            for jac in (None, system.jacobian)]
    assert runs[1].status == 0 and runs[1].nfev <= 2 * runs[0].nfev, (runs[0].nfev, runs[1].nfev)


@pytest.mark.parametrize("bad", [5, None, "nope", ["spring"]])
def test_a_bad_iteration_matrix_is_named_whatever_the_method(bad):
    model, _ = rf.samples.pendulum()
    system = model.compile()
    for method in ("auto", "radau5", "generalized_alpha"):
        with pytest.raises(ValueError, match="^iteration_matrix: expected 'auto', 'tangent', 'spring' or 'krylov'"):
            rf.simulate(system, 0.1, method=method, iteration_matrix=bad)


def test_modes_of_a_closed_chain_beyond_doubles_are_simulation_errors():
    """A four-bar whose crank spring overflows the loops' geometric stiffness, and an eigenproblem whose matrices
    hold inf: SimulationErrors naming what overflowed (no RuntimeWarning, no SciPy 'array must not contain infs'
    ValueError)."""
    from rigidfem.analysis import modes

    model, _ = rf.samples.four_bar(crank_spring=dict(stiffness=1.7e308))
    system = model.compile()
    q = system.assemble([0.4, -1.9, 4.6])[0]
    with pytest.raises(rf.SimulationError, match="modal analysis: geometric stiffness of the loops has NaN or inf"):
        rf.modal_analysis(system, q=q)
    M, K = np.eye(2), np.array([[np.inf, 0.0], [0.0, 1.0]])
    with pytest.raises(rf.SimulationError, match="modal analysis: the eigen"):
        modes._solved_modes(M, K, np.zeros((2, 2)), 0.0)


def test_scipy_methods_refuse_closed_chains():
    _, system, q0, _ = four_bar()
    with pytest.raises(ValueError, match="method: expected a C\\+\\+ method for a system with loop closures"):
        rf.simulate(system, 0.1, q0=q0, method="scipy:Radau")


def test_dt_to_an_adaptive_method_warns_and_every_run_names_its_method():
    model, _ = rf.samples.pendulum()
    system = model.compile()
    with pytest.warns(UserWarning, match="dt: 'dopri5' is adaptive: dt = 0.1 s only sets its first step"):
        r = rf.simulate(system, 1.0, method="dopri5", dt=0.1, q0=[0.5])
    assert r.stats["steps"] > 10 and r.stats["method"] == "dopri5"
    assert rf.simulate(system, 1.0, method="rk4", dt=0.1, q0=[0.5]).stats["method"] == "rk4"
    assert rf.simulate(system, 0.1, method="scipy:RK45", q0=[0.5]).stats["method"] == "scipy:RK45"
    assert "(" not in repr(r).split(":")[0]  # the method once, not "dopri5 (dopri5)"


def test_a_diverging_state_is_reported():
    """The linear Kane model spun up: its angles grow to 1e26 rad; the run says so."""
    model, _ = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=5, linear=True)
    with pytest.warns(RuntimeWarning, match=r"the state grew .* times beyond its start: beam\.rfe"):
        rf.simulate(model.compile(), 20.0)


def test_sweep_names_parameters_the_function_does_not_take():
    def f(a, b=1.0):
        return a + b

    with pytest.raises(ValueError, match=r"cases: expected parameters of f\(a, b\), got \['c'\]"):
        rf.sweep(f, grid={"a": [1.0], "c": [2.0]})
    with pytest.raises(ValueError, match="seed: expected None for a function without a 'seed' parameter"):
        rf.sweep(f, grid={"a": [1.0]}, seed=3)
    assert rf.sweep(lambda **kw: sum(kw.values()), grid={"x": [1.0, 2.0]}, as_frame=False) is not None
