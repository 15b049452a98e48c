"""Closed kinematic chains: loop joints and actuators (M q̈ = f + Gᵀλ, g(q, t) = 0).

References computed here: the four-bar's closed-form position analysis (law of cosines), the
power balance τ θ̇ = dE/dt of a driven loop, Newton–Euler for a body held by a loop joint, the
same pendulum built as a tree, and the order of the index-3 generalised-α.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

import rigidfem as rf
from conftest import step_of

A, B, C, D = 0.3, 0.8, 0.6, 0.7  # crank, coupler, rocker, ground link (m)
G0 = 9.81


def rod(L, m=1.0):
    """A slender rod along x: mass m (kg), centre at L/2."""
    return dict(mass=m, inertia=(1e-4, m * L * L / 12, m * L * L / 12), com=(L / 2, 0, 0))


def four_bar(crank_drive=None, algorithm="recursive", kind="revolute"):
    """Planar four-bar in the x–y plane, gravity −y; the loop closes coupler tip to rocker tip
    (a revolute in 3D: 3 of its 5 rows are redundant for the planar motion)."""
    m = rf.Model(gravity=(0, -G0, 0))
    crank = m.add_body("crank", m.ground, rf.Joint.revolute("z"), **rod(A))
    coupler = m.add_body("coupler", crank, rf.Joint.revolute("z"), **rod(B), placement=rf.transform((A, 0, 0)))
    rocker = m.add_body("rocker", m.ground, rf.Joint.revolute("z"), **rod(C), placement=rf.transform((D, 0, 0)))
    m.add_loop_joint("C", kind, coupler.point((B, 0, 0)), rocker.point((C, 0, 0)))
    if crank_drive is not None:
        m.prescribe(crank, crank_drive)
    return m.compile(algorithm)


def closed_form(t1):
    """Coupler and rocker angles (absolute, rad) of the open four-bar for crank angle t1."""
    Ax, Ay = A * np.cos(t1), A * np.sin(t1)
    ex, ey = Ax - D, Ay
    e = np.hypot(ex, ey)
    t3 = np.arctan2(ey, ex) + np.arccos((e * e + C * C - B * B) / (2 * e * C))
    Px, Py = D + C * np.cos(t3), C * np.sin(t3)
    return np.arctan2(Py - Ay, Px - Ax), t3


def wrap(angle):
    """Angle differences in (−π, π]."""
    return np.angle(np.exp(1j * np.asarray(angle)))


def closed_q(t1):
    t2, t3 = closed_form(t1)
    return np.array([t1, t2 - t1, t3])


@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
@pytest.mark.parametrize("method", ["dopri5", "generalized_alpha", "implicit_spring", "esdirk43"])
def test_driven_four_bar_follows_the_closed_form_and_the_power_balance(algorithm, method):
    """Crank driven at θ1 = 0.4 + 2t + t²: rocker and coupler angles against the closed form at every
    output, closure residual ≤ 1e-12, and the crank torque against τ θ̇1 = dE/dt (E: kinetic +
    gravity energy, differenced here)."""
    s = four_bar(rf.motion.polynomial([0.4, 2.0, 1.0]), algorithm)
    assert (s.nq, s.np, s.nl) == (2, 1, 5)
    q0, qd0 = s.assemble(closed_q(0.4)[1:] + 0.02, t=0.0)
    # The rates the loop allows with θ̇1(0) = 2 rad/s: differenced closed form.
    h = 1e-6
    qd_exact = (closed_q(0.4 + 2 * h)[1:] - closed_q(0.4 - 2 * h)[1:]) / (2 * h)
    np.testing.assert_allclose(wrap(q0 - closed_q(0.4)[1:]), 0.0, atol=1e-12)
    _, qd0 = s.assemble(q0, qd_exact + 0.1, t=0.0)
    np.testing.assert_allclose(qd0, qd_exact, atol=1e-7)
    t = np.linspace(0.0, 1.0, 201)
    r = rf.simulate(s, 1.0, method=method, **step_of(method, 1e-3), q0=q0, qd0=qd0, t_eval=t, rtol=1e-10, atol=1e-12)
    theta1 = 0.4 + 2 * t + t * t
    exact = np.array([closed_q(x)[1:] for x in theta1])
    np.testing.assert_allclose(wrap(r.q - exact), 0.0, atol=1e-9)
    residual = [np.abs(s.loop_constraints(tk, qk, qdk)[0]).max() for tk, qk, qdk in zip(r.t, r.q, r.qd)]
    assert max(residual) <= 1e-12
    E = r.kinetic_energy + r.gravity_energy
    power = r.driving_forces[:, 0] * (2 + 2 * t)
    dEdt = np.gradient(E, t, edge_order=2)
    np.testing.assert_allclose(power[2:-2], dEdt[2:-2], atol=2e-3 * np.abs(power).max())


@pytest.mark.parametrize("kind", ["revolute", "spherical", "universal", "prismatic", "cylindrical", "fixed",
                                  "distance"])
def test_the_recursive_loop_equations_are_the_lagrange_ones(kind):
    """g, ġ, G of every loop kind and the constrained q̈ (whose γ is the loops' second rate at
    q̈ = 0) at a random state off the loop, with a prescribed coordinate moving: the recursive
    algorithms' spatial kinematics (axes and spatial velocities along each path) against the
    Lagrange formulation's 4x4 transforms and their rates, T̈ and U."""

    def build(algorithm):
        m = rf.Model(gravity=(0.3, -9.81, 0.5))
        a = m.add_body("a", m.ground, rf.Joint.free(), mass=1.0, inertia=(0.1, 0.2, 0.3), com=(0.2, 0.1, 0))
        b = m.add_body("b", a, rf.Joint.revolute("y"), mass=0.5, inertia=(0.05, 0.04, 0.03), com=(0.3, 0, 0.1),
                       placement=rf.transform((0.4, 0, 0)))
        c = m.add_body("c", m.ground, rf.Joint.free(), mass=0.7, inertia=(0.02, 0.03, 0.04), com=(0.1, 0.2, 0.0),
                       placement=rf.transform((1.0, 0.2, 0.1)))
        m.prescribe(b, rf.motion.polynomial([0.2, 1.5, -2.0]))
        m.add_loop_joint("loop0", kind, b.point((0.5, 0.1, 0.0)), c.point((0.2, -0.1, 0.05)),
                         **(dict(length=0.7) if kind == "distance" else {}))
        return m.compile(algorithm)

    recursive, lagrange = build("recursive"), build("lagrange")
    rng = np.random.default_rng(7)
    for _ in range(3):
        t, q, qd = rng.uniform(0, 1), 0.5 * rng.normal(size=recursive.nq), rng.normal(size=recursive.nq)
        for x, y in zip(recursive.loop_constraints(t, q, qd), lagrange.loop_constraints(t, q, qd)):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-14 * (1 + np.abs(y).max()))
        qdd = lagrange.forward_dynamics(t, q, qd)
        np.testing.assert_allclose(recursive.forward_dynamics(t, q, qd), qdd, rtol=0, atol=1e-12 * np.abs(qdd).max())


@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
@pytest.mark.parametrize("scene", ["driven four-bar", "double four-bar at its flat position"])
def test_the_accelerations_after_a_projection_are_the_forward_dynamics_there(scene, algorithm):
    """The integrators project onto the loops after each step and take q̈ there on the projection's own
    factorisation of M and Y = M⁻¹Gᵀ (project_and_forward_dynamics): that q̈ must be the forward
    dynamics at the projected state, whose q is the projection's and whose q̇ satisfies ġ = 0; from
    1e-3 off the loops (Gauss-Newton iterates) and on a redundant loop at a singular position."""
    rng = np.random.default_rng(3)
    if scene == "driven four-bar":
        system = four_bar(rf.motion.polynomial([0.4, 2.0, -1.0]), algorithm)
        t, q = 0.3, closed_q(0.4 + 2.0 * 0.3 - 0.09)[1:] + 1e-3 * rng.normal(size=2)
    else:
        from rigidfem import samples
        model, _ = samples.double_four_bar(rocker=0.5, span=1.0, rocker_mass=1.0, coupler_mass=2.0)
        system = model.compile(algorithm)
        t, q = 0.0, 1e-3 * rng.normal(size=system.nq)
    qd = rng.normal(size=system.nq)
    q1, qd1, qdd1 = system._assemble_and_accelerate(t, q, qd, 1e-12, 10)
    q0, qd0 = system._assemble(t, q, qd, 1e-12, 10)
    np.testing.assert_array_equal(q1, q0)
    g, gd, _ = system.loop_constraints(t, q1, qd1)
    assert np.abs(g).max() < 1e-12 and np.abs(gd).max() < 1e-12 * (1 + np.abs(qd).max())
    np.testing.assert_allclose(qd1, qd0, rtol=0, atol=1e-6 * np.abs(qd).max())  # M factorised at q1, not q0's iterate
    qdd = system.forward_dynamics(t, q1, qd1)
    np.testing.assert_allclose(qdd1, qdd, rtol=0, atol=1e-12 * np.abs(qdd).max())


def test_free_four_bar_conserves_energy_and_generalized_alpha_converges_at_order_two():
    s = four_bar()
    q0, _ = s.assemble(closed_q(0.4))
    ref = rf.simulate(s, 1.0, method="dopri5", q0=q0, rtol=1e-12, atol=1e-12)
    assert np.ptp(ref.energy) < 1e-9 * np.abs(ref.energy).max() + 1e-9
    errors = []
    for h in (4e-3, 2e-3, 1e-3):
        r = rf.simulate(s, 1.0, method="generalized_alpha", q0=q0, dt=h)
        errors.append(np.abs(r.q[-1] - ref.q[-1]).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 4.0, rtol=0.05)


def test_generalized_alpha_keeps_order_two_down_to_small_steps():
    """The free four-bar at steps down to 15.6 µs: Newton's stopping test holds what it leaves in q̇ to
    a fraction of the step's local error over the run, so the error keeps falling about 16-fold per
    quartering of h. Held to newton_tol (1 + |q̇|) per step, its errors grew as h shrank (measured 6.8e-7
    at 62.5 µs and 1.6e-6 at 15.6 µs, against 1.9e-7 and 1.3e-8 now)."""
    s = four_bar()
    q0, _ = s.assemble(closed_q(0.4))
    ref = rf.simulate(s, 1.0, method="dopri5", q0=q0, rtol=1e-12, atol=1e-14, t_eval=np.linspace(0.0, 1.0, 21))
    errors = []
    for h in (2.5e-4, 6.25e-5, 1.5625e-5):
        r = rf.simulate(s, 1.0, method="generalized_alpha", q0=q0, dt=h, t_eval=ref.t)
        errors.append(np.abs(r.q - ref.q).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 10.0), (errors, ratios)  # measured 14.4, 14.7


def test_a_tight_newton_tol_converges_on_a_redundant_loop():
    """The Bricard linkage (5 coordinates, 5 loop rows, one redundant: benchmarks/loop_peers.py) at
    newton_tol = 1e-13: the stopping test's floor stays above round-off (500 ε (1 + |q|)); at
    1e-3 newton_tol it was below, and Newton gave up in the first step at h = 0.39 ms."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout's benchmarks/
    from benchmarks.loop_peers import bricard

    scene = bricard()
    r = rf.simulate(scene.system, 0.05, method="generalized_alpha", dt=3.9e-4, newton_tol=1e-13, q0=scene.q0)
    assert r.t[-1] == pytest.approx(0.05) and r.stats["newton_iterations"] <= 8 * r.stats["steps"]


def test_generalized_alpha_at_the_default_newton_tol_converges_on_a_redundant_loop():
    """The Bricard linkage over 4 s at the default newton_tol: the error falls about 4-fold per halving of h.
    Newton's iterations there contract slowly with a tangent kept from an earlier step (θ ≥ 1/2); taken for
    round-off and stopped at newton_tol (1 + |q̇|), they left errors that grew as h shrank (measured 1.6e-5,
    5.7e-6, 1.6e-5 rad at h = 1.56, 0.78, 0.39 ms, against 1.8e-5, 4.4e-6, 1.1e-6 at newton_tol = 1e-13)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout's benchmarks/
    from benchmarks.loop_peers import bricard

    scene = bricard()
    t = np.linspace(0.0, 4.0, 81)
    ref = rf.simulate(scene.system, 4.0, method="dopri5", q0=scene.q0, rtol=1e-12, atol=1e-14, t_eval=t)
    errors = []
    for h in (1.5625e-3, 7.8125e-4, 3.90625e-4):
        r = rf.simulate(scene.system, 4.0, method="generalized_alpha", q0=scene.q0, dt=h, t_eval=t)
        errors.append(np.abs(r.q - ref.q).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 3.0), (errors, ratios)


def test_a_steps_stages_keep_the_rank_of_a_redundant_loop():
    """The Bricard linkage's redundant row (rank G = 4 of its 5 rows on the loops). A step's stage lies off the
    loops by a drift δ, where that row's direction has an eigenvalue of G M⁻¹ Gᵀ of order δ² and the row's γ an
    inconsistency of order δ: counted as a constraint, its multiplier makes q̈ jump by O(1) at every δ whose δ²
    passes the rank floor. The stages keep to the rank the projection found on the loops, so that q̈ moves by
    O(δ) as a smooth vector field's does; a drift of 0.1 rad is too far for that, and the stage decides as
    a lone evaluation does. Over a run dopri5 rejects fewer steps (measured at rtol 1e-4 over 10 s: 22 of 117
    attempts against 190 of 581 deciding at each stage)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout's benchmarks/
    from benchmarks.loop_peers import bricard

    scene = bricard()
    s = scene.system
    rng = np.random.default_rng(3)
    swung = rf.simulate(s, 1.0, "dop853", q0=scene.q0, rtol=1e-10, atol=1e-12)  # 1 s into the swing
    q1, qd1, qdd1 = s._assemble_and_accelerate(1.0, swung.q[-1], swung.qd[-1], 1e-12, 10)
    w, v = rng.normal(size=s.nq), rng.normal(size=s.nq)
    moved, jumped = [], []
    for delta in (1e-3, 1e-4):
        stage = (q1 + delta * w, qd1 + delta * v)
        qdd = s._assemble_and_accelerate(1.0, q1, qd1, 1e-12, 10, stage=stage)[3]
        moved.append(np.abs(qdd - qdd1).max())
        jumped.append(np.abs(s.forward_dynamics(1.0, *stage) - qdd1).max())  # deciding its own rank
    assert 8.0 < moved[0] / moved[1] < 12.0  # O(δ)
    assert moved[0] < 1e-2 * np.abs(qdd1).max()
    assert min(jumped) > 0.5 * np.abs(qdd1).max()  # measured 2.7 of it
    far = (q1 + 0.1 * w, qd1)
    np.testing.assert_allclose(s._assemble_and_accelerate(1.0, q1, qd1, 1e-12, 10, stage=far)[3],
                               s.forward_dynamics(1.0, *far), rtol=1e-10)
    kept = rf.simulate(s, 10.0, "dopri5", q0=scene.q0, rtol=1e-4, atol=1e-6)
    assert kept.stats["rejected_steps"] < 0.4 * kept.stats["steps"]


def test_redundant_loop_gives_the_tree_motion_and_newton_euler_reactions():
    """A rod (m = 2 kg, L = 1 m) as a pendulum about z: once as a tree (revolute on the ground),
    once as a free body closed to the ground by a revolute loop (5 rows, none redundant) and once
    moving in the plane (planar joint) closed by a revolute loop (5 rows, 3 of them redundant).
    The angles agree, and the loop's reaction is Newton–Euler's m (a_c − g) on the rod."""
    m_, L = 2.0, 1.0
    theta0 = 0.7

    def model(joint):
        mod = rf.Model(gravity=(0, -G0, 0))
        rod_ = mod.add_body("rod", mod.ground, joint, **rod(L, m_))
        return mod, rod_

    tree, _ = model(rf.Joint.revolute("z"))
    tree = tree.compile()
    t = np.linspace(0, 1.5, 31)
    ref = rf.simulate(tree, 1.5, q0=[theta0], rtol=1e-11, atol=1e-12, t_eval=t)
    for joint in (rf.Joint.free(), rf.Joint.planar("xy")):
        mod, body = model(joint)
        mod.add_loop_joint("pin", "revolute", mod.ground, body)
        s = mod.compile()
        guess = np.zeros(s.nq)
        guess[s.coordinate_index("rod.rz")] = theta0
        q0, _ = s.assemble(guess)
        r = rf.simulate(s, 1.5, q0=q0, rtol=1e-11, atol=1e-12, t_eval=t)
        np.testing.assert_allclose(r.q[:, s.coordinate_index("rod.rz")], ref.q[:, 0], atol=1e-8)
        # Newton–Euler: the pin pulls the rod with F = m (a_c − g), a_c of the centre at L/2.
        th, w = ref.q[:, 0], ref.qd[:, 0]
        al = ref.qdd[:, 0]
        e, n = np.c_[np.cos(th), np.sin(th)], np.c_[-np.sin(th), np.cos(th)]
        ac = L / 2 * (al[:, None] * n - (w * w)[:, None] * e)
        F = m_ * (ac - np.array([0.0, -G0]))
        W = r.loop_reactions[:, 0, :]  # on the rod (b), in the ground frame A's axes
        np.testing.assert_allclose(W[:, :2], F, atol=1e-6)
        np.testing.assert_allclose(W[:, 2:], 0.0, atol=1e-6)


def test_actuator_luffs_a_boom_along_the_triangle():
    """A boom (revolute on the ground) raised by a cylinder from (0.5, 0) on the ground to the boom's
    point at 1 m, length l(t) = 0.9 + 0.3 t: the boom angle from the law of cosines, and the
    cylinder's power −F l̇ (F pushing positive) against dE/dt."""
    mod = rf.Model(gravity=(0, -G0, 0))
    boom = mod.add_body("boom", mod.ground, rf.Joint.revolute("z"), **rod(2.0, 5.0))
    name = mod.add_actuator("cylinder", mod.ground.point((0.5, 0, 0)), boom.point((1.0, 0, 0)), rf.motion.polynomial([0.9, 0.3]))
    s = mod.compile()
    assert s.loop_names == [name] and s.loop_kinds == ["distance"]
    t = np.linspace(0, 1, 101)

    def angle(tt):
        l = 0.9 + 0.3 * tt
        return np.arccos((0.25 + 1.0 - l * l) / (2 * 0.5 * 1.0))

    q0, qd0 = s.assemble([angle(0.0)], [0.0])
    r = rf.simulate(s, 1.0, method="generalized_alpha", dt=1e-3, q0=q0, qd0=qd0, t_eval=t)
    np.testing.assert_allclose(r.q[:, 0], angle(t), atol=1e-9)
    F = r.loop_reactions[:, 0, 0]
    dEdt = np.gradient(r.kinetic_energy + r.gravity_energy, t, edge_order=2)
    np.testing.assert_allclose(F * 0.3, dEdt, atol=2e-3 * np.abs(dEdt).max())
    # It pushes while the boom leans outboard (cos θ > 0) and pulls once past the vertical.
    assert F[0] > 0 and np.cos(r.q[0, 0]) > 0 and F[-1] < 0 and np.cos(r.q[-1, 0]) < 0


def test_bad_loops_are_value_errors_and_unreachable_ones_simulation_errors():
    mod = rf.Model()
    a = mod.add_body("a", mod.ground, rf.Joint.revolute("z"), **rod(1.0))
    with pytest.raises(ValueError, match="^kind: expected one of"):
        mod.add_loop_joint("pin", "hinge", mod.ground, a)
    with pytest.raises(ValueError, match="^b: expected a body other than a"):
        mod.add_loop_joint("pin", "spherical", a, a.point((1, 0, 0)))
    with pytest.raises(ValueError, match="^length: expected a positive distance"):
        mod.add_loop_joint("pin", "distance", mod.ground, a)
    with pytest.raises(ValueError, match="^frame_a: expected a rigid transformation"):
        mod.add_loop_joint("pin", "revolute", mod.ground, a, frame_a=2 * np.eye(4))
    mod.add_loop_joint("rope", "distance", mod.ground.point((0.0, 3.0, 0.0)), a.point((1, 0, 0)), length=0.5)
    with pytest.raises(ValueError, match="^name: expected a name not used by another loop, got 'rope'"):
        mod.add_loop_joint("rope", "spherical", mod.ground, a)
    assert mod.add_loop_joint("loop1", "distance", mod.ground, a.point((1, 0, 0)), length=1.0) == "loop1"  # the default
    s = mod.compile()
    with pytest.raises(ValueError, match=r"^q0: expected initial coordinates that close every loop of \['rope', 'loop1'\]"):
        rf.simulate(s, 1.0, q0=[0.0])
    with pytest.raises(rf.SimulationError, match="loop 'rope' \\(distance, residual"):
        s.assemble([0.0])  # the point at 1 m from the pin never comes within 0.5 m of (0, 3)
    # A rope on the pivot, which no coordinate moves: G = 0, nothing to assemble with.
    mod2 = rf.Model()
    b = mod2.add_body("b", mod2.ground, rf.Joint.revolute("z"), **rod(1.0))
    mod2.add_actuator("stuck", mod2.ground.point((0.0, 0.6, 0.0)), b.origin, 0.5)
    with pytest.raises(rf.SimulationError, match="loop 'stuck' \\(distance, residual 0.1\\)"):
        mod2.compile().assemble([0.3])


def test_a_planar_loop_joint_keeps_a_free_body_in_its_plane():
    """A free body held by a planar loop joint to the ground's x-y plane (added as one row of the table of kinds and
    its name: two files): under in-plane gravity it falls as y = −g t²/2, drifts at its x rate and spins at its
    constant ω_z about principal axes, while z and the tilts stay zero; an out-of-plane push P is the loop's
    reaction, −P along A's z."""
    g, vx, wz, P = 9.81, 0.4, 2.0, 3.0
    model = rf.Model(gravity=(0.0, -g, 0.0))
    body = model.add_body("puck", model.ground, rf.Joint.free(), mass=2.0, inertia=(0.1, 0.2, 0.3))
    loop = model.add_loop_joint("table", "planar", model.ground, body)
    model.add_force("load0", body.origin, (0.0, 0.0, P))
    s = model.compile()
    assert (s.nl, loop.kind) == (3, "planar")
    names = s.coordinate_names
    qd0 = np.zeros(s.nq)
    qd0[names.index("puck.x")], qd0[names.index("puck.rz")] = vx, wz
    t = np.linspace(0.0, 1.0, 11)
    for method, options in (("radau5", dict(rtol=1e-10, atol=1e-12)), ("generalized_alpha", dict(dt=1e-3))):
        r = rf.simulate(s, 1.0, method, qd0=qd0, t_eval=t, **options)
        q = dict(zip(names, r.q.T))
        tol = 1e-8 if method == "radau5" else 1e-5
        np.testing.assert_allclose(q["puck.x"], vx * t, atol=tol)
        np.testing.assert_allclose(q["puck.y"], -0.5 * g * t**2, atol=tol)
        np.testing.assert_allclose(q["puck.rz"], wz * t, atol=tol)
        for out_of_plane in ("puck.z", "puck.ry", "puck.rx"):
            assert np.abs(q[out_of_plane]).max() < 1e-9, (method, out_of_plane)
        np.testing.assert_allclose(r.loop_reactions[:, 0, :3], np.tile([0.0, 0.0, -P], (len(t), 1)), atol=1e-6)
