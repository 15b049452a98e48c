"""``rf.linearize``: state-space models about a state, checked against references computed here.

A by central differences of ``System.forward_dynamics``; B by the accelerations of the same model
built again with the input's load applied (loads enter linearly); C by central differences of
``System.position`` and ``System.velocity``; the eigenvalues of A against ``rf.modal_analysis``;
the four-bar's static gain against its closed-form potential (SymPy, test_loops_analysis); a step
response of the linear model (scipy.signal.lsim) against the nonlinear simulation; the zero-order
hold against expm of the augmented matrix.
"""

import numpy as np
import pytest
import scipy.linalg
import scipy.signal

import rigidfem as rf
from test_loops_analysis import closed_q, four_bar, four_bar_reference

H = 1e-6  # central-difference step (m, rad; m/s, rad/s)
T0 = 0.4  # s, inside the spin-up: the hub accelerates and turns


def spinning_beam(force=(0, 0, 0), torque=(0, 0, 0), hub_torque=0.0):
    """A hub spun up about z (prescribed) carrying a 3-sde beam bending both ways and twisting, with
    a payload on a damped revolute joint at its tip; gravity −z. Optional loads: ``force`` (N) at
    the tip, ``torque`` (N·m) on the last rfe, ``hub_torque`` (N·m) on the payload's coordinate."""
    model = rf.Model()
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    model.prescribe(hub, rf.motion.spin_up(omega=2.0, duration=1.0))
    mat = rf.Material(E=2e9, rho=2000.0, nu=0.3, retardation=1e-3)
    beam = model.add_beam("beam", hub, 1.0, mat, rf.Section.rectangle(0.03, 0.02), 3,
                          deform=("torsion", "bend_y", "bend_z"))
    payload = model.add_body("payload", beam.rfes[-1], rf.Joint.revolute("y", stiffness=20.0, damping=0.5),
                             mass=0.5, inertia=(0.01, 0.02, 0.01), com=(0.1, 0, 0),
                             placement=rf.transform((1.0 / 6, 0, 0)))
    model.add_force("load0", beam.tip, force)
    model.add_torque("load1", beam.rfes[-1], torque)
    model.add_generalized_force(payload, hub_torque)
    return model.compile(), beam, payload


def state(n, seed=3):
    rng = np.random.default_rng(seed)
    return 0.05 * rng.standard_normal(n), 0.3 * rng.standard_normal(n)


def central(fun, x, h=H):
    """(len(fun(x)), len(x)) central differences."""
    cols = []
    for e in np.eye(len(x)):
        cols.append((fun(x + h * e) - fun(x - h * e)) / (2 * h))
    return np.column_stack(cols)


def close(actual, expected, rtol=1e-6):
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * np.max(np.abs(expected)))


def test_A_B_C_against_finite_differences_away_from_equilibrium():
    system, beam, payload = spinning_beam()
    n = system.nq
    q, qd = state(n)
    d, a = np.array([0.3, 1.0, -0.5]), np.array([0.2, -0.4, 1.0])
    inputs = {"F": ("force", beam.tip, d), "T": ("torque", beam.rfes[-1], a), "Q": "payload.ry"}
    outputs = [("position", beam.tip, "y"), ("position", payload, d), ("velocity", beam.tip, "z"), "beam.rfe2.ry",
               "payload.ry.dot"]
    with pytest.warns(rf.NotAnEquilibriumWarning, match="not an equilibrium"):
        ss = rf.linearize(system, q, qd, t=T0, inputs=inputs, outputs=outputs)

    def qdd(s, x):
        return s.forward_dynamics(T0, x[:n], x[n:])

    x0 = np.concatenate([q, qd])
    A = np.vstack([np.hstack([np.zeros((n, n)), np.eye(n)]), central(lambda x: qdd(system, x), x0)])
    close(ss.A, A)
    # B: the accelerations the unit loads add (exactly linear in the load)
    loaded = [spinning_beam(force=d)[0], spinning_beam(torque=a)[0], spinning_beam(hub_torque=1.0)[0]]
    B = np.column_stack([np.concatenate([np.zeros(n), qdd(s, x0) - qdd(system, x0)]) for s in loaded])
    close(ss.B, B)
    C = np.vstack([
        np.concatenate([central(lambda x: system.position(beam.tip, T0, x), q)[1], np.zeros(n)]),
        np.concatenate([d @ central(lambda x: system.position(payload, T0, x), q), np.zeros(n)]),
        central(lambda x: system.velocity(beam.tip, T0, x[:n], x[n:]), x0)[2],
        np.eye(2 * n)[system.coordinate_index("beam.rfe2.ry")],
        np.eye(2 * n)[n + system.coordinate_index("payload.ry")],
    ])
    close(ss.C, C)
    assert not np.any(ss.D)
    assert ss.input_names == ["F", "T", "Q"]
    assert ss.output_names[3:] == ["beam.rfe2.ry", "payload.ry.dot"]
    assert ss.state_names == system.coordinate_names + [c + ".dot" for c in system.coordinate_names]
    np.testing.assert_allclose(ss.y0[0], system.position(beam.tip, T0, q)[1], rtol=1e-14)


def damped_beam():
    mat = rf.Material(E=2.1e11, rho=7850.0, nu=0.3, retardation=2e-5)
    model, h = rf.samples.cantilever(elements=6, material=mat, deform=("bend_z", "bend_y"))
    return model.compile(), h["beam"]


def both_roots(lam):
    return np.sort_complex(np.concatenate([lam, lam.conj()]))


def test_eigenvalues_of_a_damped_beam_are_the_modal_ones():
    system, _ = damped_beam()
    ss = rf.linearize(system, np.zeros(system.nq))
    modes = rf.modal_analysis(system)
    assert np.all(modes.damping_ratios < 1) and np.all(modes.damping_ratios > 0)  # every mode an oscillating pair
    close(np.sort_complex(np.linalg.eigvals(ss.A)), both_roots(modes.eigenvalues), rtol=1e-8)


def test_four_bar_in_the_loops_null_space_modes_and_static_gain():
    system = four_bar(damping=0.2)
    eq = rf.static_equilibrium(system, q0=closed_q(1.5))
    ss = rf.linearize(system, eq.q, inputs=["crank.rz"], outputs=["crank.rz", "rocker.rz", "coupler.rz.dot"])
    modes = rf.modal_analysis(system, q=eq.q)
    assert ss.A.shape == (2, 2) and ss.state_names == ["y[0]", "y[0].dot"] and ss.basis.shape == (3, 1)
    close(np.sort_complex(np.linalg.eigvals(ss.A)), both_roots(modes.eigenvalues), rtol=1e-8)
    # static gain crank torque -> crank angle is 1/V''(θ*); -> rocker angle (dθ3/dθ)/V'' (closed form)
    _, V2, _, (_, r3), _ = four_bar_reference()
    gain = ss.C @ np.linalg.solve(-ss.A, ss.B)
    np.testing.assert_allclose(gain[:2, 0], [1 / V2, r3 / V2], rtol=1e-6)
    assert abs(gain[2, 0]) < 1e-12  # a rate: zero in the steady state


def chain(force=0.0):
    """Two damped rods hanging along −z (revolute about y); ``force`` (N) along x at the tip."""
    model = rf.Model()
    joint = rf.Joint.revolute("y", damping=0.3)
    a = model.add_body("a", model.ground, joint, mass=1.0, com=(0, 0, -0.5), inertia=(0.08, 0.08, 1e-3))
    b = model.add_body("b", a, joint, mass=0.7, com=(0, 0, -0.4), inertia=(0.04, 0.04, 1e-3),
                       placement=rf.transform((0, 0, -1.0)))
    tip = b.point((0, 0, -0.8))
    model.add_force("load0", tip, (force, 0.0, 0.0))
    return model.compile(), tip


def test_step_response_matches_the_nonlinear_simulation_to_second_order():
    system, tip = chain()
    ss = rf.linearize(system, np.zeros(2), inputs=[("force", tip, "x")], outputs=[("position", tip, "x")])
    t = np.linspace(0.0, 3.0, 301)
    errors = []
    for amplitude in (0.05, 0.1):
        _, y, _ = scipy.signal.lsim(ss, amplitude * np.ones_like(t), t)
        loaded, tip_loaded = chain(amplitude)
        res = rf.simulate(loaded, 3.0, t_eval=t, rtol=1e-11, atol=1e-13)
        x = res.position(tip_loaded)[:, 0] - ss.y0[0]
        errors.append(np.max(np.abs(x - y)) / np.max(np.abs(y)))
    assert errors[0] < 1e-3
    # exact to first order: the relative error falls at least like the amplitude (measured: like its
    # square, the response x being odd in the force)
    assert errors[1] / errors[0] > 3.0


def test_discrete_zero_order_hold_is_expm_of_the_augmented_matrix():
    system, tip = chain()
    dt = 0.01
    kw = dict(inputs=[("force", tip, "x"), "a.ry"], outputs=[("position", tip, "x")])
    ct, dd = rf.linearize(system, np.zeros(2), **kw), rf.linearize(system, np.zeros(2), dt=dt, **kw)
    n, m = ct.B.shape
    E = scipy.linalg.expm(np.block([[ct.A, ct.B], [np.zeros((m, n + m))]]) * dt)
    close(dd.A, E[:n, :n], rtol=1e-12)
    close(dd.B, E[:n, n:], rtol=1e-12)
    np.testing.assert_array_equal(dd.C, ct.C)
    assert dd.dt == dt and ct.dt is None
    assert dd.input_names == ct.input_names == ["force b(0, 0, -0.8)·x", "a.ry"]


def test_warns_away_from_equilibrium_only():
    system, _ = chain()
    rf.linearize(system, np.zeros(2))  # hanging at rest: no warning (warnings are errors here)
    with pytest.warns(rf.NotAnEquilibriumWarning, match=r"rigidfem.linearize: .*b.ry"):
        rf.linearize(system, np.array([0.0, 0.3]))
    assert issubclass(rf.NotAnEquilibriumWarning, UserWarning)


def test_bad_input_is_a_value_error_naming_the_argument():
    system, tip = chain()
    q = np.zeros(2)
    with pytest.raises(ValueError, match=r"inputs\[0\]: expected a coordinate name, one of \['a.ry', 'b.ry'\]"):
        rf.linearize(system, q, inputs=["c.rz"])
    with pytest.raises(ValueError, match=r"outputs\['y'\]: expected a coordinate name, one of"):
        rf.linearize(system, q, outputs={"y": "a.rz"})
    with pytest.raises(ValueError, match="dt: expected a positive number in s"):
        rf.linearize(system, q, dt=0.0)
    with pytest.raises(ValueError, match=r"q: expected shape \(2,\)"):
        rf.linearize(system, np.zeros(3))
    with pytest.raises(ValueError, match=r"qd: expected shape \(2,\)"):
        rf.linearize(system, q, np.zeros(1))
    _, other = chain()
    with pytest.raises(ValueError, match=r"inputs\[0\]: expected .* of another model"):
        rf.linearize(system, q, inputs=[("force", other, "x")])
    with pytest.raises(ValueError, match=r"inputs\[0\]: expected a non-zero direction"):
        rf.linearize(system, q, inputs=[("force", tip, (0, 0, 0))])
    with pytest.raises(ValueError, match=r"outputs\[0\]: expected 'x', 'y', 'z' or a direction"):
        rf.linearize(system, q, outputs=[("position", tip, "w")])
    with pytest.raises(ValueError, match=r"inputs\[0\]: expected \('torque', body, axis\)"):
        rf.linearize(system, q, inputs=[("torque", tip, "x")])
    with pytest.raises(ValueError, match=r"inputs\[0\]: expected a coordinate name, \('force'"):
        rf.linearize(system, q, inputs=[("push", tip, "x")])
    with pytest.raises(ValueError, match="q: expected coordinates that close every loop"):
        rf.linearize(four_bar(), closed_q(1.5) + 0.1)
