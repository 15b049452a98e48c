"""Adjoint gradients (rigidfem.gradient) against independent references: the forward sensitivities of the same
discrete run (the derivative of the same discrete solution, integrated forwards by another code path), central
differences of the objective over whole runs converging as h², the reverse mode's derivatives by the prescribed
coordinates against differences of the residual, closed loops, and bad input."""

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import samples
from conftest import boom_angle_derivative, luffed_boom, slider_four_bar

G = 9.81


def strip(elements=6):
    """A clamped-hinged 3D steel strip on a sprung revolute joint, a tip load and a spring-damper to the ground."""
    m = rf.Model(gravity=(0.0, -G, 0.0))
    b = m.add_beam("strip", m.ground, 1.0, rf.Material(E=2e11, rho=7800.0, G=8e10, retardation=1e-4),
                   rf.Section.rectangle(0.02, 0.005), elements, joint=rf.Joint.revolute("z", stiffness=5.0),
                   tip_mass=0.1, deform=("bend_z", "torsion", "bend_y"))
    m.add_force("push", b.tip, (0.0, -1.0, 0.5))
    m.add_spring_damper("spring", b.tip, m.ground, stiffness=10.0, damping=0.5, length=0.5)
    return m.compile(), b


def boom_and_rope():
    """A boom slewed by a harmonic drive, a payload hoisted on a rope by a winch's ramp (taut throughout)."""
    m = rf.Model(gravity=(0.0, 0.0, -G))
    boom = m.add_body("boom", m.ground, rf.Joint.revolute("z"), 10.0, (1.0, 1.0, 1.0), com=(1.0, 0.0, 0.0))
    m.prescribe(boom, rf.motion.harmonic(0.3, 1.5))
    load = m.add_body("load", boom, rf.Joint.free(), 5.0, (0.1, 0.1, 0.1), placement=rf.transform((2.0, 0, 0)))
    m.add_rope("rope", boom.point((2.0, 0.0, 0.0)), load, EA=1e6, DA=1e3, length=rf.motion.ramp(-0.2, 0.0, 0.5, start=1.0))
    return m.compile(), load.origin, [0.0, 0.0, -1.0 - 5 * G / 1e6, 0.0, 0.0, 0.0]


def running(t, y):
    """L: a point's height squared and a smooth function of its x."""
    return y["p"][:, 1] ** 2 + 0.1 * np.sin(y["p"][:, 0])


def terminal(y):
    return 3.0 * y["p"][1] + y["p"][0] ** 2


def forward_gradient(system, point, names, t_end, method="generalized_alpha", **run):
    """J and dJ/dp of the same discrete objective from the forward sensitivities of the same run (trapezoid on its
    steps): dJ/dp = Σ w_n ∂L/∂x · dx_n/dp + ∂Φ/∂x · dx_N/dp."""
    r = rf.simulate(system, t_end, method, sensitivities=names, **run)
    x = r.position(point)
    w = np.zeros(len(r.t))
    w[:-1] += np.diff(r.t) / 2
    w[1:] += np.diff(r.t) / 2
    J = w @ (x[:, 1] ** 2 + 0.1 * np.sin(x[:, 0])) + 3 * x[-1, 1] + x[-1, 0] ** 2
    out = {}
    for name in names:
        dx = r.position_sensitivity(point, name)
        out[name] = w @ (2 * x[:, 1] * dx[:, 1] + 0.1 * np.cos(x[:, 0]) * dx[:, 0]) + 3 * dx[-1, 1] + 2 * x[-1, 0] * dx[-1, 0]
    return J, out


def assert_gradients_agree(got, expected, rtol):
    scale = max(abs(v) for v in expected.values())
    for name, e in expected.items():
        assert abs(got[name] - e) <= rtol * abs(e) + 1e-12 * scale, (name, got[name], e)


def test_the_adjoint_is_the_derivative_of_the_discrete_run():
    """On a 3D strip, its material, section, damping, springs, force and the initial state: the adjoint's dJ/dp
    equals the one the forward sensitivities give for the same discrete objective to 1e-8 (both are the exact
    derivative of the discrete solution), and J itself equals the run's."""
    s, beam = strip()
    names = ["strip.E", "strip.rho", "strip.retardation", "strip.Iz", "strip.A", "strip.G", "spring.stiffness",
             "spring.damping", "push.force", "strip.rfe0.rz.stiffness", f"q0[{s.coordinate_names[0]}]",
             f"qd0[{s.coordinate_names[2]}]"]
    g = rf.gradient(s, 0.02, names, outputs={"p": beam.tip}, running=running, terminal=terminal, dt=1e-4)
    J, expected = forward_gradient(s, beam.tip, names, 0.02, dt=1e-4)
    assert g.value == pytest.approx(J, rel=1e-10)  # the same run to Newton's tolerance
    assert_gradients_agree(g.gradient, expected, 1e-8)
    assert g.stats["steps"] == 200 and g.stats["objective_derivative"] == "complex step"
    # the gradient by the initial state as arrays
    assert g.q0[0] == pytest.approx(g[f"q0[{s.coordinate_names[0]}]"], rel=1e-14)
    assert g.qd0[2] == pytest.approx(g[f"qd0[{s.coordinate_names[2]}]"], rel=1e-14)


def test_central_differences_of_whole_runs_converge_onto_the_adjoint():
    """dJ/dE and dJ/dρ against (J(p + h) − J(p − h))/2h of whole runs: the error falls as h² onto the adjoint."""
    s, beam = strip(elements=4)
    run = dict(outputs={"p": beam.tip}, running=running, terminal=terminal, dt=2e-4)
    g = rf.gradient(s, 0.02, ["strip.E", "strip.rho"], **run)
    for name in ("strip.E", "strip.rho"):
        p = s.parameters[name].value
        errors = []
        for rel in (1e-2, 1e-3):
            J = [rf.gradient(s.with_parameters({name: p * (1 + sign * rel)}), 0.02, [], **run).value for sign in (1, -1)]
            errors.append(abs((J[0] - J[1]) / (2 * rel * p) - g[name]) / abs(g[name]))
        assert errors[1] <= 1e-6 and errors[1] <= errors[0] / 50, (name, errors)


def test_checkpoints_give_the_same_gradient():
    """With room for a few states only, the run keeps checkpoints every ⌈√N⌉ steps and runs each segment again:
    the same gradient (to Newton's tolerance: the repeated steps start from another iteration matrix), every step
    computed twice."""
    s, beam = strip(elements=4)
    run = dict(outputs={"p": beam.tip}, running=running, terminal=terminal, dt=1e-4)
    names = ["strip.E", "push.force", "spring.stiffness"]
    full = rf.gradient(s, 0.02, names, **run)
    saved = rf.gradient(s, 0.02, names, memory=3e4, **run)
    assert full.stats["recomputed_steps"] == 0 and full.stats["checkpoint_interval"] == 1
    assert saved.stats["checkpoint_interval"] == 15 and saved.stats["recomputed_steps"] == 200
    for name in names:
        assert saved[name] == pytest.approx(full[name], rel=1e-8)
    with pytest.raises(ValueError, match="memory: expected at least"):
        rf.gradient(s, 0.02, names, memory=2e3, **run)


def test_drives_winches_and_ropes():
    """A boom's harmonic drive (its numbers move the prescribed coordinate, and the payload with it), a winch's
    ramp, the rope's EA and damping, the payload's mass and joint springs: the adjoint against the forward
    sensitivities, and one drive number against central differences of whole runs."""
    s, point, q0 = boom_and_rope()
    names = ["boom.rz.drive.amplitude", "boom.rz.drive.omega", "boom.rz.drive.offset", "rope.length.rate",
             "rope.length.duration", "rope.EA", "rope.DA", "load.mass", "load.x.stiffness"]
    run = dict(dt=1e-3, q0=q0, newton_tol=1e-14)
    g = rf.gradient(s, 1.0, names, outputs={"p": point}, running=running, terminal=terminal, **run)
    _, expected = forward_gradient(s, point, names, 1.0, **run)
    assert_gradients_agree(g.gradient, expected, 1e-7)
    h = 1e-5
    J = [rf.gradient(s.with_parameters({"boom.rz.drive.omega": 1.5 + sign * h}), 1.0, [], outputs={"p": point},
                     running=running, terminal=terminal, **run).value for sign in (1, -1)]
    assert (J[0] - J[1]) / (2 * h) == pytest.approx(g["boom.rz.drive.omega"], rel=1e-6)


def test_reverse_mode_by_the_prescribed_motion():
    """∂(μᵀr)/∂ of a prescribed coordinate's value, rate and acceleration from the reverse mode against central
    differences of μᵀr: a polynomial drive at t = 0 has q = c₀, q̇ = c₁, q̈ = 2 c₂ (r is quadratic in q̇ and linear
    in q̈: their differences are exact for any step, so it is large, 0.1, against round-off)."""
    model = rf.Model(gravity=(0.0, -G, 0.0))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1.0, 1.0, 1.0))
    model.prescribe(hub, rf.motion.polynomial([0.3, 0.7, 0.4]))
    beam = model.add_beam("beam", hub, 1.0, rf.Material(E=7e10, rho=2700.0), rf.Section.rectangle(0.02, 0.01), 3,
                          deform=("bend_z", "bend_y"))
    model.add_force("load0", beam.tip, (0.0, 1.0, 0.5), follower=True)
    s = model.compile()
    rng = np.random.default_rng(5)
    q, qd, qdd, mu = rng.normal(0, 0.1, (4, s.nq))
    *_, pq, pqd, pqdd = s._inverse_dynamics_vjp(0.0, q, qd, qdd, mu)
    for k, (got, factor) in enumerate(((pq[0], 1.0), (pqd[0], 1.0), (pqdd[0], 2.0))):
        name, c = f"hub.rz.drive.coefficients[{k}]", [0.3, 0.7, 0.4][k]
        e = 1e-4 if k == 0 else 0.1
        r = [mu @ s.with_parameters({name: c + sign * e}).inverse_dynamics(0.0, q, qd, qdd) for sign in (1, -1)]
        assert got * factor == pytest.approx((r[0] - r[1]) / (2 * e), rel=1e-8), name


@pytest.mark.parametrize("method, options, rtol", [("newmark", {}, 1e-8), ("hht", dict(alpha=-0.2), 1e-8),
                                                   ("implicit_spring", dict(rho_inf=0.6), 1e-8),
                                                   ("generalized_alpha", dict(iteration_matrix="krylov"), 1e-8),
                                                   ("radau5", {}, 1e-7), ("radau5", dict(iteration_matrix="krylov"), 1e-7)])
def test_every_method(method, options, rtol):
    """newmark, hht, implicit_spring, radau5 and Krylov Newton matrices: each adjoint against its own forward
    sensitivities (radau5's stage corrections stop at 1e-9 of them, or at the differences' noise)."""
    s, beam = strip(elements=4)
    names = ["strip.E", "strip.retardation", "push.force", f"q0[{s.coordinate_names[1]}]", f"qd0[{s.coordinate_names[3]}]"]
    g = rf.gradient(s, 0.01, names, method=method, outputs={"p": beam.tip}, running=running, terminal=terminal,
                    dt=1e-4, **options)
    _, expected = forward_gradient(s, beam.tip, names, 0.01, method=method, dt=1e-4, adaptive=False, **options)
    assert_gradients_agree(g.gradient, expected, rtol)


def test_closed_loops():
    """A four-bar (a redundant revolute loop) with a sprung, damped crank: the crank's spring and damper, the
    bodies' masses and an initial rate moved along the loop, against the forward sensitivities (1e-7); a
    four-bar whose rocker pivot rides on a driven slider: the drive's numbers move the loop's g, G and γ, against
    central differences of whole runs."""
    model, h = samples.four_bar(crank_spring=dict(stiffness=5.0, rest=0.3, damping=0.1))
    s = model.compile()
    q0, qd0 = s.assemble([0.4, -1.9, 4.6], [1.0, 0.0, 0.0])
    names = ["crank.rz.stiffness", "crank.rz.damping", "coupler.mass", "rocker.mass", "qd0[crank.rz]"]
    point = h["coupler"].point((0.4, 0.0, 0.0))
    run = dict(outputs={"p": point}, running=running, terminal=terminal, dt=1e-3, q0=q0, qd0=qd0)
    g = rf.gradient(s, 0.5, names, **run)
    _, expected = forward_gradient(s, point, names, 0.5, dt=1e-3, q0=q0, qd0=qd0)
    assert_gradients_agree(g.gradient, expected, 1e-7)

    s, coupler = slider_four_bar(rf.motion.rest_to_rest(0.0, 0.08, 0.1, 0.3))  # at rest at t0 whatever its end
    q0, qd0 = s.assemble([0.4, -1.9, 4.6], [0.0, 0.0, 0.0], t=0.0)
    run = dict(outputs={"p": coupler.point((0.4, 0.0, 0.0))}, running=running, terminal=terminal, dt=1e-3, q0=q0,
               qd0=qd0, newton_tol=1e-14)
    g = rf.gradient(s, 0.5, ["slider.x.drive.end", "rocker.mass"], **run)
    for name, h in (("slider.x.drive.end", 1e-5), ("rocker.mass", 1e-4)):
        p = s.parameters[name].value
        J = [rf.gradient(s.with_parameters({name: p + sign * h}), 0.5, [], **run).value for sign in (1, -1)]
        assert (J[0] - J[1]) / (2 * h) == pytest.approx(g[name], rel=1e-6), name
    _, expected = forward_gradient(s, coupler.point((0.4, 0.0, 0.0)), ["slider.x.drive.end", "rocker.mass"], 0.5,
                                   dt=1e-3, q0=q0, qd0=qd0, newton_tol=1e-14)
    assert_gradients_agree(g.gradient, expected, 1e-7)


def test_an_actuator_and_a_drive_moving_the_loops_at_the_start():
    """A boom luffed by a cylinder l = c₀ + c₁ t: Φ = x_tip(1 s) = 2 cos θ(1) with θ = arccos(1.25 − l²), so
    dΦ/dc₀ = dΦ/dc₁ = −2 sin θ ∂θ/∂l at t = 1 exactly, and the boom's mass moves no point (0). The four-bar on a
    harmonic slider: the drive's offset moves the loop at t0 already, so the initial state moves with it (as
    assemble closes it): the adjoint against the forward sensitivities of the same run."""
    s, boom, q0, qd0 = luffed_boom()
    names = ["cylinder.length.coefficients[0]", "cylinder.length.coefficients[1]", "boom.mass"]
    g = rf.gradient(s, 1.0, names, outputs={"p": boom.point((2.0, 0.0, 0.0))}, terminal=lambda y: y["p"][0],
                    dt=1e-3, q0=q0, qd0=qd0, newton_tol=1e-13)
    theta = np.arccos(1.25 - 1.2**2)
    assert g[names[0]] == pytest.approx(-2 * np.sin(theta) * boom_angle_derivative(1.0), rel=1e-9)
    assert g[names[1]] == pytest.approx(g[names[0]], rel=1e-9)
    assert abs(g["boom.mass"]) <= 1e-12

    s, coupler = slider_four_bar(rf.motion.harmonic(0.05, 8.0))
    q0, qd0 = s.assemble([0.4, -1.9, 4.6], [0.0, 0.0, 0.0], t=0.0)
    names = ["slider.x.drive.offset", "slider.x.drive.amplitude", "crank.mass"]
    point = coupler.point((0.4, 0.0, 0.0))
    g = rf.gradient(s, 0.4, names, outputs={"p": point}, running=running, terminal=terminal, dt=1e-3, q0=q0, qd0=qd0,
                    newton_tol=1e-14)
    _, expected = forward_gradient(s, point, names, 0.4, dt=1e-3, q0=q0, qd0=qd0, newton_tol=1e-14)
    assert_gradients_agree(g.gradient, expected, 1e-7)


def test_a_link_of_varying_length():
    """A tape sliding out of its guide on a turning hub (flows.hpp; the reverse mode of its Coriolis, relative
    acceleration and turning loads): the hub's drive, the material, the section, a push, and the numbers of the
    free length L(t), against the forward sensitivities of the same runs."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1.0, 1.0, 1.0))
    model.prescribe(hub, rf.motion.harmonic(0.6, 2.0, 0.3))
    tape = model.add_beam("tape", hub, rf.motion.polynomial([0.5, 0.8, -0.3]), rf.Material(E=2.1e9, rho=7850.0),
                          rf.Section.rectangle(0.02, 0.004), 4, deform=("bend_y", "bend_z"),
                          joint=rf.Joint.revolute("y", stiffness=30.0), placement=rf.transform((0.1, 0.0, 0.0)))
    model.add_force("push", tape.tip, (0.0, 0.3, 0.0))
    s = model.compile()
    names = ["hub.rz.drive.amplitude", "tape.E", "tape.rho", "tape.A", "tape.Iy", "tape.rfe0.ry.stiffness",
             "push.force"] + [f"tape.length.coefficients[{k}]" for k in range(3)]
    for method, dt in (("generalized_alpha", 1e-3), ("radau5", 2e-3)):
        run = dict(dt=dt, newton_tol=1e-13)
        g = rf.gradient(s, 0.3, names, method=method, outputs={"p": tape.tip}, running=running, terminal=terminal,
                        **run)
        _, expected = forward_gradient(s, tape.tip, names, 0.3, method, adaptive=False, **run)
        assert_gradients_agree(g.gradient, expected, 1e-7)


def test_radau5_with_loops():
    """radau5's stages hold the loops at index 1 (G_i A_i = γ_i) and each step's end is projected onto them: the
    stage saddle systems transposed (the constraints' derivatives by the stages' velocities and positions as
    dG/dt and d²G/dt² along the motion) and the projection's derivative transposed. On the sprung four-bar
    (springs, masses, an initial rate along the loop) and on the harmonic slider (its offset moves the loop, at
    t0 too): against the forward sensitivities of the same runs (3e-7: radau5's stage sensitivities stop at 1e-9
    of their corrections), checkpointed runs against kept states, the offset against central differences."""
    model, h = samples.four_bar(crank_spring=dict(stiffness=5.0, rest=0.3, damping=0.1))
    s = model.compile()
    q0, qd0 = s.assemble([0.4, -1.9, 4.6], [1.0, 0.0, 0.0])
    names = ["crank.rz.stiffness", "crank.rz.damping", "coupler.mass", "rocker.mass", "qd0[crank.rz]"]
    point = h["coupler"].point((0.4, 0.0, 0.0))
    run = dict(dt=2e-3, q0=q0, qd0=qd0, newton_tol=1e-13)
    objective = dict(method="radau5", outputs={"p": point}, running=running, terminal=terminal)
    g = rf.gradient(s, 0.5, names, **objective, **run)
    J, expected = forward_gradient(s, point, names, 0.5, "radau5", adaptive=False, **run)
    assert g.value == pytest.approx(J, rel=1e-12)
    assert_gradients_agree(g.gradient, expected, 3e-7)
    saved = rf.gradient(s, 0.5, names, memory=2e4, **objective, **run)
    assert saved.stats["recomputed_steps"] > 0
    np.testing.assert_allclose(saved.array(), g.array(), rtol=1e-7)

    s, coupler = slider_four_bar(rf.motion.harmonic(0.05, 8.0))
    q0, qd0 = s.assemble([0.4, -1.9, 4.6], [0.0, 0.0, 0.0], t=0.0)
    names = ["slider.x.drive.offset", "slider.x.drive.amplitude", "crank.mass"]
    point = coupler.point((0.4, 0.0, 0.0))
    run = dict(dt=2e-3, q0=q0, qd0=qd0, newton_tol=1e-13)
    objective["outputs"] = {"p": point}
    g = rf.gradient(s, 0.4, names, **objective, **run)
    _, expected = forward_gradient(s, point, names, 0.4, "radau5", adaptive=False, **run)
    assert_gradients_agree(g.gradient, expected, 3e-7)
    J = []
    for sign in (1, -1):
        moved = s.with_parameters({"slider.x.drive.offset": 1e-5 * sign})
        a, b = moved.assemble(q0, qd0, t=0.0)
        J.append(rf.gradient(moved, 0.4, [], **objective, **{**run, "q0": a, "qd0": b}).value)
    assert (J[0] - J[1]) / 2e-5 == pytest.approx(g["slider.x.drive.offset"], rel=1e-6)


def test_radau5_krylov_on_a_long_chain():
    """radau5 with the matrix-free Newton matrix on a 40-element strip on a turning hub: its transposed stages
    preconditioned by the articulated-body factor at the complex shift converge in a few GMRES iterations a step
    and give the dense tangent's gradient. (That factor's rounding once grew up the chain: 300 iterations a step
    and a gradient of 1e45.)"""
    model = rf.Model(gravity=(0.0, -G, 0.0))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (0.1, 0.1, 0.1))
    model.prescribe(hub, rf.motion.harmonic(0.1, 100.0))
    beam = model.add_beam("strip", hub, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005), 40,
                          deform=("bend_z", "bend_y"))
    model.add_force("push", beam.tip, (0.0, -5.0, 2.0))
    s = model.compile()
    run = dict(method="radau5", outputs={"p": beam.tip}, running=running, terminal=terminal, dt=1e-4)
    names = ["strip.E", "push.force", "hub.rz.drive.omega"]
    krylov = rf.gradient(s, 0.005, names, iteration_matrix="krylov", **run)
    dense = rf.gradient(s, 0.005, names, iteration_matrix="tangent", **run)
    assert krylov.stats["linear_iterations"] <= 6 * krylov.stats["steps"]
    np.testing.assert_allclose(krylov.array(), dense.array(), rtol=1e-6)


def test_radau5_on_a_drive_and_a_winch_with_checkpoints():
    """radau5's adjoint on the boom's drive and winch, its states kept or checkpointed, against its forward
    sensitivities and central differences of whole runs (its stages depend on the drive's numbers at three
    times per step)."""
    s, point, q0 = boom_and_rope()
    names = ["boom.rz.drive.omega", "rope.length.rate", "rope.EA", "load.mass"]
    run = dict(method="radau5", dt=2e-3, q0=q0, newton_tol=1e-13, outputs={"p": point}, running=running,
               terminal=terminal)
    g = rf.gradient(s, 0.6, names, **run)
    saved = rf.gradient(s, 0.6, names, memory=6e4, **run)
    assert saved.stats["recomputed_steps"] == 300 and g.stats["recomputed_steps"] == 0
    _, expected = forward_gradient(s, point, names, 0.6, method="radau5", dt=2e-3, q0=q0, newton_tol=1e-13,
                                   adaptive=False)
    assert_gradients_agree(g.gradient, expected, 1e-7)
    for name in names:
        assert saved[name] == pytest.approx(g[name], rel=1e-8), name
    for name in names[:3]:  # the payload's mass moves J by too little for differences of whole runs
        p = s.parameters[name].value
        h = 1e-4 * max(abs(p), 1.0)  # the truncation ∝ h² and the round-off ∝ 1/h both below 1e-7 here
        J = [rf.gradient(s.with_parameters({name: p + sign * h}), 0.6, [], **run).value for sign in (1, -1)]
        assert (J[0] - J[1]) / (2 * h) == pytest.approx(g[name], rel=1e-6), name


def test_objectives_without_complex_arithmetic():
    """A running cost through np.abs (no complex step) is differentiated by central differences, said in stats;
    coordinates as outputs; the default parameters are all of the system's."""
    s, beam = strip(elements=3)
    outputs = {"tip": beam.tip, "hinge": s.coordinate_names[0]}
    g = rf.gradient(s, 0.01, outputs=outputs, running=lambda t, y: np.abs(y["tip"][:, 1] - 1.0) + y["hinge"] ** 2,
                    dt=1e-4)
    assert g.stats["objective_derivative"] == "central differences"
    assert list(g.gradient) == list(s.parameters)
    smooth = rf.gradient(s, 0.01, outputs=outputs, running=lambda t, y: 1.0 - y["tip"][:, 1] + y["hinge"] ** 2,
                         dt=1e-4)
    assert np.all(g.outputs["tip"][:, 1] < 1.0)  # |y − 1| = 1 − y
    np.testing.assert_allclose(g.array(), smooth.array(), rtol=1e-6, atol=1e-12 * np.abs(smooth.array()).max())


def test_bad_input():
    s, beam = strip(elements=2)
    ok = dict(outputs={"p": beam.tip}, running=running, dt=1e-3)
    with pytest.raises(ValueError, match="parameters: expected"):
        rf.gradient(s, 0.01, ["strip.e"], **ok)
    with pytest.raises(ValueError, match="method: expected one of"):
        rf.gradient(s, 0.01, ["strip.E"], method="rk4", **ok)
    with pytest.raises(ValueError, match="dt: expected a fixed step"):
        rf.gradient(s, 0.01, ["strip.E"], **{**ok, "dt": None})
    with pytest.raises(ValueError, match="outputs: expected"):
        rf.gradient(s, 0.01, ["strip.E"], **{**ok, "outputs": {"p": "spring"}})
    with pytest.raises(ValueError, match="outputs: expected a dict"):
        rf.gradient(s, 0.01, ["strip.E"], **{**ok, "outputs": [beam.tip]})
    with pytest.raises(ValueError, match="running: expected a function L"):
        rf.gradient(s, 0.01, ["strip.E"], outputs=ok["outputs"], dt=1e-3)
    for bad in (lambda t, y: np.full(len(t), np.nan), lambda t, y: y["p"], lambda t, y: "big"):
        with pytest.raises(ValueError, match="running: expected an array of L at every step"):
            rf.gradient(s, 0.01, ["strip.E"], **{**ok, "running": bad})
    with pytest.raises(ValueError, match="running: expected an array of L at the 11 steps"):  # NaN later only
        rf.gradient(s, 0.01, ["strip.E"], **{**ok, "running": lambda t, y: np.where(t > 0.005, np.nan, t)})
    with pytest.raises(ValueError, match="terminal: expected a number"):
        rf.gradient(s, 0.01, ["strip.E"], **{**ok, "terminal": lambda y: [1.0, 2.0]})
    with pytest.raises(ValueError, match="algorithm='recursive'"):
        rf.gradient(strip_lagrange(), 0.01, ["strip.E"], outputs={"p": 0}, running=lambda t, y: y["p"], dt=1e-3)
    with pytest.raises(ValueError, match=r"^parameters: expected a free coordinate in 'q0\[nope\]'"):
        rf.gradient(s, 0.01, ["q0[nope]"], **ok)
    m = rf.Model()
    rod = m.add_body("rod", m.ground, rf.Joint.revolute("z"), 1.0, (1.0, 1.0, 1.0), com=(0.5, 0.0, 0.0))
    for ground in (m.ground, m.ground.point((1.0, 0.0, 0.0))):  # the ground's points do not move
        with pytest.raises(ValueError, match="^outputs: expected points on moving bodies"):
            rf.gradient(m.compile(), 0.01, [], outputs={"p": rod, "g": ground}, running=running, dt=1e-3)
        with pytest.raises(ValueError, match="^error_on: expected points on moving bodies"):
            rf.simulate(m.compile(), 0.01, error_on=[ground])
    loop = samples.four_bar()[0].compile()
    q0 = loop.assemble([0.4, -1.9, 4.6])[0]
    with pytest.raises(ValueError, match="q0: expected initial coordinates that close every loop"):
        rf.gradient(loop, 0.01, [], outputs={"q": 0}, running=lambda t, y: y["q"], dt=1e-3)


def strip_lagrange():
    m = rf.Model(gravity=(0.0, -G, 0.0))
    m.add_beam("strip", m.ground, 1.0, rf.Material(E=2e11, rho=7800.0), rf.Section.rectangle(0.02, 0.005), 2)
    return m.compile("lagrange")


@pytest.mark.parametrize("method", ["generalized_alpha", "newmark", "hht", "implicit_spring"])
def test_a_step_whose_iterate_overflows_is_a_simulation_error(method):
    """dt = 1e300 s is a valid step whose Newton predictor overflows: the run fails as Newton does (a
    SimulationError at the step's time saying to reduce dt), in simulate and in rf.gradient's forward run (a
    ValueError 'q: expected ... finite values' from deep inside before)."""
    model = rf.Model(None)
    body = model.add_body("b", model.ground, rf.Joint.universal(("z", "x")), 2.0, (0.2, 0.3, 0.1))
    model.add_force("load0", body.origin, (-1e6, 0.0, 3e5))
    s = model.compile()
    with pytest.raises(rf.SimulationError, match="reduce dt") as caught:
        rf.simulate(s, 1e300, method, dt=1e300)
    assert caught.value.time == 0.0
    if method != "implicit_spring":  # (rf.gradient's methods: the Newmark family)
        with pytest.raises(rf.SimulationError, match="reduce dt"):
            rf.gradient(s, 1e300, ["b.mass"], outputs={"p": body.point((0.0, 1.0, 0.0))},
                        terminal=lambda y: float(np.sum(y["p"] ** 2)), dt=1e300, method=method)


def test_drive_numbers_the_profiles_are_affine_in():
    """The kinds' table says which numbers a profile is affine in (the adjoint differences those one-sided, by a
    large step): the second difference of (q, q̇, q̈) in each such number vanishes at every time, and a number that is
    not (a harmonic's omega) is refused. Each kind is made by its own builder in rigidfem.motion."""
    from rigidfem.model import parameters as P

    law = rf.motion.rest_to_rest(0.2, 1.5, 0.1, 0.8, law="trapezoidal", fraction=0.3)
    profiles = [rf.motion.polynomial([0.3, -0.7, 0.4]), rf.motion.harmonic(0.6, 2.0, 0.3, 0.1),
                rf.motion.spline(np.linspace(0.0, 2.0, 6), [0.0, 0.3, -0.2, 0.5, 0.1, 0.4]), law,
                rf.motion.ramp(1.5, 0.2, 0.6, start=0.3), rf.motion.chirp(0.4, 0.5, 2.0, 0.1, 1.5),
                rf.motion.harmonic(0.6, 2.0) + 0.5 * rf.motion.polynomial([0.1, 0.2])]
    times = np.linspace(-0.5, 2.5, 31)
    for profile in profiles:
        leaves = P.profile_leaves(profile)
        affine = P.affine_leaves(profile)
        assert affine and affine <= set(leaves), profile
        for path in affine:
            e = 0.37 * max(1.0, abs(leaves[path]))
            q = [P.remade(profile, {path: leaves[path] + k * e}).sample(times) for k in range(3)]
            np.testing.assert_allclose(q[2] - 2 * q[1] + q[0], 0.0, atol=1e-12 * max(1.0, np.abs(q[0]).max()),
                                       err_msg=f"{profile!r}: {path}")
    assert P.affine_leaves(rf.motion.harmonic(0.6, 2.0)) == {"amplitude", "offset"}


def test_a_spline_drive_by_its_knots():
    """A hub turned by a spline through 9 knots, a 3-rfe beam on it: the gradient by every knot (each differenced
    one-sided by the adjoint, the spline being affine in its values) against the forward sensitivities of the same
    run (which difference the residual centrally) and one knot against central differences of whole runs."""
    model = rf.Model(gravity=(0.0, -G, 0.0))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1.0, 1.0, 1.0))
    knots = np.linspace(0.0, 0.4, 9)
    model.prescribe(hub, rf.motion.spline(knots, 2.0 * knots**2 + 0.3 * np.sin(10 * knots)))
    beam = model.add_beam("beam", hub, 1.0, rf.Material(E=7e10, rho=2700.0), rf.Section.rectangle(0.02, 0.01), 3,
                          deform=("bend_z", "bend_y"))
    s = model.compile()
    names = [n for n in s.parameters if ".q[" in n]
    assert len(names) == 9
    run = dict(dt=1e-3, newton_tol=1e-14)
    g = rf.gradient(s, 0.4, names, outputs={"p": beam.tip}, running=running, terminal=terminal, **run)
    _, expected = forward_gradient(s, beam.tip, names, 0.4, **run)
    assert_gradients_agree(g.gradient, expected, 1e-7)
    name, h = "hub.rz.drive.q[4]", 1e-4
    p = s.parameters[name].value
    J = [rf.gradient(s.with_parameters({name: p + sign * h}), 0.4, [], outputs={"p": beam.tip}, running=running,
                     terminal=terminal, **run).value for sign in (1, -1)]
    assert (J[0] - J[1]) / (2 * h) == pytest.approx(g[name], rel=1e-6)
