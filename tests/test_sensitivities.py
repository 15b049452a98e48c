"""Forward sensitivities (rigidfem.sensitivities) against independent references: the complex step through
a Python RK4 of the same equations (rk4's sensitivities are the derivative of its discrete solution), central
differences of whole simulations converging as h² onto them (trees, beams, loops, ropes across slack,
varying-length links, a moving base, the Lagrange formulation), and bad input."""

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import samples
from conftest import boom_angle_derivative, luffed_boom, slider_four_bar

G = 9.81


def pendulum(k=3.0, c=0.2, m=1.5, L=0.4, Ic=0.02):
    """A rod on a revolute z joint with a spring k and damper c, centre of mass L along x, gravity −y."""
    model = rf.Model(gravity=(0.0, -G, 0.0))
    model.add_body("rod", model.ground, rf.Joint.revolute("z", stiffness=k, damping=c), mass=m,
                   inertia=(Ic, Ic, Ic), com=(L, 0.0, 0.0))
    return model.compile()


def rk4_complex(k, c, m, theta0, L=0.4, Ic=0.02, dt=1e-3, steps=400):
    """θ after each step of RK4 on (Ic + m L²) θ̈ = −k θ − c θ̇ − m g L cos θ, in complex arithmetic."""
    y = np.array([theta0, 0.0], dtype=complex)

    def f(y):
        return np.array([y[1], (-k * y[0] - c * y[1] - m * G * L * np.cos(y[0])) / (Ic + m * L * L)])

    out = []
    for _ in range(steps):
        k1 = f(y)
        k2 = f(y + 0.5 * dt * k1)
        k3 = f(y + 0.5 * dt * k2)
        k4 = f(y + dt * k3)
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(y[0])
    return np.array(out)


def test_rk4_sensitivities_are_the_derivatives_of_its_discrete_solution():
    """The complex step h = 1e-30 through a Python RK4 of the same equation at the same steps gives dθ_n/dp
    exact to round-off: rk4's sensitivities (the same stages applied to the sensitivity equations) match it to
    the central differences' 1e-9, while the discretisation error of θ itself is 1e-11 here."""
    s = pendulum()
    t = np.arange(1, 401) * 1e-3
    r = rf.simulate(s, 0.4, "rk4", dt=1e-3, t_eval=t, q0=[0.3],
                    sensitivities=["rod.rz.stiffness", "rod.rz.damping", "rod.mass", "q0[rod.rz]"])
    base = dict(k=3.0, c=0.2, m=1.5, theta0=0.3)
    np.testing.assert_allclose(r.q[:, 0], rk4_complex(**base).real, rtol=0, atol=1e-14)
    for name, arg in [("rod.rz.stiffness", "k"), ("rod.rz.damping", "c"), ("rod.mass", "m"), ("q0[rod.rz]", "theta0")]:
        reference = rk4_complex(**{**base, arg: base[arg] + 1e-30j}).imag / 1e-30
        dq, dqd = r.sensitivity(name)
        assert np.max(np.abs(dq[:, 0] - reference)) <= 1e-9 * np.max(np.abs(reference)), name


def _difference(system, name, h, method, t, **run):
    """The central difference of q over a whole simulation at the parameter ± h."""
    p = system.parameters[name].value
    up = rf.simulate(system.with_parameters({name: p + h}), t[-1], method, t_eval=t, **run).q
    down = rf.simulate(system.with_parameters({name: p - h}), t[-1], method, t_eval=t, **run).q
    return (up - down) / (2 * h)


def _converges(system, names, method, t, steps=(1e-2, 1e-3, 1e-4), floor=1e-6, **run):
    """Central differences of whole runs converge onto the sensitivities as h² (each tenth of h gains at
    least 50 while above round-off) to within `floor` of their largest value."""
    r = rf.simulate(system, t[-1], method, t_eval=t, sensitivities=names, **run)
    for name in names:
        S = r.sensitivity(name)[0]
        p = system.parameters[name].value
        errors = [np.max(np.abs(_difference(system, name, rel * abs(p), method, t, **run) - S)) / np.max(np.abs(S))
                  for rel in steps]
        assert errors[-1] <= floor, (name, errors)
        for coarse, fine in zip(errors, errors[1:]):
            assert fine <= coarse / 50 or fine <= floor / 10, (name, errors)
    return r


@pytest.mark.parametrize("method, run", [("dopri5", dict(rtol=1e-11, atol=1e-13)),
                                         ("generalized_alpha", dict(dt=1e-3, newton_tol=1e-14)),
                                         ("implicit_spring", dict(dt=1e-3, newton_tol=1e-14)),
                                         ("esdirk43", dict(dt=1e-3, adaptive=False, newton_tol=1e-14)),
                                         ("radau5", dict(dt=2e-3, adaptive=False, newton_tol=1e-13))])
def test_closed_loop_sensitivities_converge(method, run):
    """The four-bar (a redundant planar loop) under gravity with a sprung crank: masses and a spring."""
    model, _ = samples.four_bar(crank_spring=dict(stiffness=5.0, damping=0.1))
    s = model.compile()
    q0, qd0 = s.assemble([0.4, -1.9, 4.6], [1.0, 0.0, 0.0])
    r = _converges(s, ["crank.rz.stiffness", "coupler.mass"], method, np.linspace(0, 1, 6), q0=q0, qd0=qd0, **run)
    # the sensitivities stay on the loops' tangent: G ∂q/∂p = 0
    for k in range(len(r.t)):
        G = s.loop_constraints(r.t[k], r.q[k], r.qd[k])[2]
        assert np.max(np.abs(G @ r.sensitivity("coupler.mass")[0][k])) <= 1e-9


def strip(method_deform=("bend_z", "torsion", "bend_y"), tip=0.1, elements=6):
    """A clamped-hinged steel strip on a sprung revolute joint, a tip load and a spring-damper to the ground."""
    m = rf.Model(gravity=(0.0, -G, 0.0))
    b = m.add_beam("strip", m.ground, 1.0, rf.Material(E=2e11, rho=7800.0, G=8e10, retardation=1e-4),
                   rf.Section.rectangle(0.02, 0.005), elements, joint=rf.Joint.revolute("z", stiffness=5.0),
                   tip_mass=tip, deform=method_deform)
    m.add_force("push", b.tip, (0.0, -1.0, 0.0))
    m.add_spring_damper("spring", b.tip, m.ground, stiffness=10.0, damping=0.5, length=0.5)
    return m.compile(), b


@pytest.mark.parametrize("method, run", [("rk4", dict(dt=1e-5)), ("generalized_alpha", dict(dt=1e-5)),
                                         ("implicit_spring", dict(dt=1e-5)),
                                         ("esdirk43", dict(dt=5e-5, adaptive=False)),
                                         ("esdirk43", dict(dt=5e-5, adaptive=False, iteration_matrix="spring")),
                                         ("radau5", dict(dt=1e-4, adaptive=False))])
def test_beam_sensitivities_converge(method, run):
    """A 3D strip: its material, density, damping and section, a spring-damper and a force."""
    s, beam = strip()
    names = ["strip.E", "strip.rho", "strip.retardation", "strip.Iz", "strip.A", "spring.stiffness", "push.force"]
    r = _converges(s, names, method, np.linspace(0, 0.02, 5), steps=(1e-2, 1e-3), floor=1e-5, **run)
    # a point's position: (∂x/∂q) ∂q/∂p against the difference of the runs' tip positions
    p, h = 2e11, 2e7
    x = [rf.simulate(s.with_parameters({"strip.E": p + sign * h}), 0.02, method, t_eval=r.t, **run).position(beam.tip)
         for sign in (1, -1)]
    dx = r.position_sensitivity(beam.tip, "strip.E")
    assert np.max(np.abs(dx - (x[0] - x[1]) / (2 * h))) <= 1e-4 * np.max(np.abs(dx))


def test_moving_base_and_both_formulations():
    """Kane's beam on its prescribed hub, recursive and Lagrange: E and ρ."""
    model, _ = samples.kane_beam(elements=4)
    t = np.linspace(0, 1.0, 5)
    for algorithm in ("recursive", "lagrange"):
        _converges(model.compile(algorithm), ["beam.E", "beam.rho"], "rk4", t, steps=(1e-2, 1e-3, 1e-4), dt=5e-4)


def test_rope_across_slack_phases():
    """A payload dropped onto a rope (slack, caught, bouncing). The tension max(0, ...) is continuous, so the
    flow of the continuous problem is differentiable across the switches and its sensitivity equations need
    no jump there. A fixed-step solution is not: where a switch falls inside a step its position in the step
    moves with the parameter, which the sensitivities (the derivative of the smooth stages) leave out. So the
    differences of whole runs and the sensitivities agree only to O(dt) once the rope switches (measured:
    7.9e-3 of |S| at dt = 1e-4 s, 2.0e-3 at 2.5e-5 s), and both converge to the continuous problem's; while the
    rope stays taut they agree to the differences' own 1e-8."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), 500.0, (1.0, 1.0, 1.0))
    model.add_rope("rope", model.ground, load, EA=2e6, length=10.0, DA=1e3)
    s = model.compile()
    t = np.linspace(0, 1.5, 7)
    errors = []
    for dt in (1e-4, 2.5e-5):
        S = rf.simulate(s, 1.5, "rk4", dt=dt, t_eval=t, q0=[-9.0], sensitivities=["rope.EA"]).sensitivity("rope.EA")[0]
        fd = _difference(s, "rope.EA", 2e3, "rk4", t, dt=dt, q0=[-9.0])
        errors.append(np.max(np.abs(fd - S)) / np.max(np.abs(S)))
    slack = rf.simulate(s, 1.5, "rk4", dt=1e-4, q0=[-9.0])
    assert np.any(slack.element_forces[:, 0] == 0.0) and np.any(slack.element_forces[:, 0] < 0.0)
    assert errors[1] <= errors[0] / 3 and errors[1] <= 3e-3, errors  # first order in dt
    taut = _converges(s, ["rope.EA", "load.mass"], "rk4", t, dt=1e-4, q0=[-10.04])
    assert np.all(taut.element_forces[:, 0] < 0.0)


def test_varying_length_link():
    """A tape sliding out of its guide on a turning hub (flows.hpp): E and ρ of the flowing beam, and the numbers
    of its free length L(t) = c₀ + c₁ t + c₂ t² (they move the flow's terms and its sdes' growth together)."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1.0, 1.0, 1.0))
    model.prescribe(hub, rf.motion.harmonic(0.6, 2.0, 0.3))
    model.add_beam("tape", hub, rf.motion.polynomial([0.5, 0.8, -0.3]), rf.Material(E=2.1e9, rho=7850.0),
                   rf.Section.rectangle(0.02, 0.004), 4, deform=("bend_y", "bend_z"),
                   joint=rf.Joint.revolute("y", stiffness=30.0), placement=rf.transform((0.1, 0.0, 0.0)))
    s = model.compile()
    _converges(s, ["tape.E", "tape.rho"], "rk4", np.linspace(0, 0.3, 4), dt=1e-4)
    _converges(s, ["tape.length.coefficients[0]", "tape.length.coefficients[2]"], "rk4", np.linspace(0, 0.2, 3),
               steps=(1e-4, 1e-5, 1e-6), dt=2e-4)


def test_initial_values_on_a_closed_loop_move_along_it():
    """q0[crank]: a perturbed initial coordinate breaks the loop, so the sensitivity starts from its projection
    onto the loop's tangent in the mass metric, the derivative of System.assemble's closing: against runs from
    assemble(q0 ± h e_crank)."""
    model, _ = samples.four_bar()
    s = model.compile()
    q0, _ = s.assemble([0.4, -1.9, 4.6])
    t = np.linspace(0, 0.5, 6)
    run = dict(rtol=1e-11, atol=1e-13, t_eval=t)
    r = rf.simulate(s, 0.5, "dopri5", q0=q0, sensitivities=["q0[crank.rz]"], **run)
    h = 1e-5
    runs = [rf.simulate(s, 0.5, "dopri5", q0=s.assemble(q0 + [sign * h, 0.0, 0.0])[0], **run).q for sign in (1, -1)]
    S = r.sensitivity("q0[crank.rz]")[0]
    assert 0.0 < S[0, 0] < 1.0  # the crank gives way to the rest of the loop
    np.testing.assert_allclose(S, (runs[0] - runs[1]) / (2 * h), rtol=0, atol=1e-6 * np.max(np.abs(S)))


@pytest.mark.parametrize("method, run", [("rk4", dict(dt=1e-3)), ("generalized_alpha", dict(dt=1e-3)),
                                         ("esdirk43", dict(dt=1e-2, adaptive=False)),
                                         ("radau5", dict(dt=1e-2, adaptive=False))])
def test_an_actuator_moves_its_loop(method, run):
    """The cylinder's numbers move the loop's g(q, t; c) (∂g/∂p, ∂ġ/∂p, ∂γ/∂p): the boom angle's sensitivities
    against the law of cosines' derivative; the boom's mass and spring change only the cylinder's force, so the
    loop holds their sensitivities at zero (the implicit methods' corrections converge to 0, where no relative
    test passes: they once ran out of iterations)."""
    s, _, q0, qd0 = luffed_boom()
    names = ["cylinder.length.coefficients[0]", "cylinder.length.coefficients[1]", "boom.mass", "boom.rz.stiffness"]
    r = rf.simulate(s, 1.0, method, q0=q0, qd0=qd0, sensitivities=names, **run)
    d = boom_angle_derivative(r.t)
    np.testing.assert_allclose(r.sensitivity(names[0])[0][:, 0], d, rtol=1e-9)
    np.testing.assert_allclose(r.sensitivity(names[1])[0][:, 0], r.t * d, rtol=0, atol=1e-9 * np.max(r.t * d))
    for name in names[2:]:
        assert np.max(np.abs(r.sensitivity(name)[0])) <= 1e-12, name


def test_a_drive_inside_a_loop():
    """A four-bar whose rocker pivot rides on a slider driven by x(t) = 0.05 sin(8t + φ) + x₀: the drive's numbers
    move the loop's g, ġ, γ; its offset moves them already at t0, so the initial state moves along the loop as
    System.assemble closes it. Against central differences of whole runs from the states assemble gives."""
    s, _ = slider_four_bar(rf.motion.harmonic(0.05, 8.0))
    guess = np.array([0.4, -1.9, 4.6])
    names = ["slider.x.drive.amplitude", "slider.x.drive.offset"]
    t = np.linspace(0.0, 0.4, 5)
    for method, run in (("rk4", dict(dt=1e-3)), ("generalized_alpha", dict(dt=1e-3, newton_tol=1e-14))):
        q0, qd0 = s.assemble(guess, np.zeros(3), t=0.0)
        r = rf.simulate(s, 0.4, method, q0=q0, qd0=qd0, t_eval=t, sensitivities=names, **run)
        for name in names:
            p, h = s.parameters[name].value, 1e-5
            runs = []
            for sign in (1, -1):
                moved = s.with_parameters({name: p + sign * h})
                a, b = moved.assemble(q0, qd0, t=0.0)
                runs.append(rf.simulate(moved, 0.4, method, q0=a, qd0=b, t_eval=t, **run).q)
            S = r.sensitivity(name)[0]
            np.testing.assert_allclose(S, (runs[0] - runs[1]) / (2 * h), rtol=0, atol=1e-7 * np.max(np.abs(S)))
        assert abs(r.sensitivity("slider.x.drive.offset")[0][0]).max() > 0.1  # q0 moved with the loop


def test_bad_input():
    s = pendulum()
    with pytest.raises(ValueError, match="sensitivities: expected a parameter .*did you mean 'rod.rz.stiffness'.*got 'rod.rz.stifness'"):
        rf.simulate(s, 0.1, "rk4", dt=1e-3, sensitivities=["rod.rz.stifness"])
    with pytest.raises(ValueError, match="sensitivities: expected a list"):
        rf.simulate(s, 0.1, "rk4", dt=1e-3, sensitivities="rod.mass")
    with pytest.raises(ValueError, match="each name once"):
        rf.simulate(s, 0.1, "rk4", dt=1e-3, sensitivities=["rod.mass", "rod.mass"])
    with pytest.raises(ValueError, match="free coordinate in 'q0\\[rod.rx\\]'"):
        rf.simulate(s, 0.1, "rk4", dt=1e-3, sensitivities=["q0[rod.rx]"])
    with pytest.raises(ValueError, match="method: expected a C\\+\\+ method that integrates sensitivities"):
        rf.simulate(s, 0.1, "scipy:Radau", sensitivities=["rod.mass"])
    r = rf.simulate(s, 0.1, "rk4", dt=1e-3, sensitivities=["rod.mass"])
    with pytest.raises(ValueError, match="name: expected one of the sensitivities of this run"):
        r.sensitivity("rod.rz.stiffness")
    model = rf.Model()
    rod = model.add_body("rod", model.ground, rf.Joint.revolute("z", stiffness=1.0), 1.0, (1.0, 1.0, 1.0))
    r = rf.simulate(model.compile(), 0.01, "rk4", dt=1e-3, sensitivities=["rod.mass"])
    for name in (["rod.mass"], {}):  # unhashable: no TypeError
        with pytest.raises(ValueError, match="^name: expected one of the sensitivities of this run"):
            r.sensitivity(name)
        with pytest.raises(ValueError, match="^name: expected one of the sensitivities of this run"):
            r.position_sensitivity(rod.point((1.0, 0.0, 0.0)), name)
    model = rf.Model()
    b = model.add_body("b", model.ground, rf.Joint.revolute("z", stiffness=1.0), 1.0, (1.0, 1.0, 1.0))
    model.add_maxwell_arm(b, 1.0, 0.1)
    with pytest.raises(ValueError, match="Maxwell arms"):
        rf.simulate(model.compile(), 0.1, "rk4", dt=1e-3, sensitivities=["b.mass"])


# ----------------------------------------------------------------- statics and modes


def test_modal_sensitivities_of_a_cantilever_are_the_closed_forms():
    """K ∝ E and M ∝ ρ, C = μ K (Kelvin–Voigt): ω ∝ √(E/ρ) and ζ = μ ω/2 mode by mode, so dω/dE = ω/(2E),
    dω/dρ = −ω/(2ρ), dζ/dμ = ω/2 and dζ/dE = μ/2 dω/dE exactly."""
    E, rho, mu = 2.1e11, 7850.0, 1e-4
    model, _ = samples.cantilever(elements=6, material=rf.Material(E=E, rho=rho, nu=0.3, retardation=mu),
                                  deform=("bend_z", "bend_y"), section=rf.Section.rectangle(0.02, 0.005))
    m = rf.modal_analysis(model.compile(), sensitivities=["beam.E", "beam.rho", "beam.retardation"])
    w = m.omega
    for name, dw, dz in [("beam.E", w / (2 * E), mu * w / (4 * E)), ("beam.rho", -w / (2 * rho), -mu * w / (4 * rho)),
                         ("beam.retardation", 0 * w, w / 2)]:
        got_w, got_z = m.sensitivity(name)
        np.testing.assert_allclose(got_w, dw, rtol=1e-10, atol=1e-12 * np.max(np.abs(w / (2 * E))))
        np.testing.assert_allclose(got_z, dz, rtol=1e-10, atol=1e-300)


def test_a_repeated_frequency_splits_in_the_order_of_its_one_sided_derivatives():
    """A square section's two bending planes share each frequency; raising Iy raises only the bend_y one (its
    spring E Iy, and its rotary inertia ρ Iy a little): within the pair the derivatives are (0, ≈ ω/(2 Iy))
    ascending, the difference of modal analyses at Iy + h."""
    model, _ = samples.cantilever(elements=4, deform=("bend_z", "bend_y"), section=rf.Section.rectangle(0.01, 0.01))
    s = model.compile()
    m = rf.modal_analysis(s, sensitivities=["beam.Iy"])
    Iy = s.parameters["beam.Iy"].value
    dw = m.sensitivity("beam.Iy")[0]
    np.testing.assert_allclose(m.omega[0::2], m.omega[1::2], rtol=1e-12)  # the pairs
    np.testing.assert_allclose(dw[0::2], 0.0, atol=1e-12 * np.max(dw))
    np.testing.assert_allclose(dw[1::2], m.omega[1::2] / (2 * Iy), rtol=5e-3)  # less the rotary inertia's share
    h = 1e-6 * Iy
    up = rf.modal_analysis(s.with_parameters({"beam.Iy": Iy + h})).omega
    np.testing.assert_allclose((up - m.omega) / h, dw, rtol=1e-5, atol=1e-5 * np.max(dw))


def test_statics_and_modes_of_a_closed_loop_against_differences():
    """The four-bar at its static equilibrium: dq*/dp, dω/dp and dζ/dp converge onto the differences of
    equilibria and modal analyses at p ± h as h² (to 1e-7 at h = 1e-4 p)."""
    model, _ = samples.four_bar(crank_spring=dict(stiffness=50.0, damping=0.3))
    s = model.compile()
    names = ["crank.rz.stiffness", "coupler.mass", "crank.rz.damping"]
    eq = rf.static_equilibrium(s, s.assemble([0.4, -1.9, 4.6])[0], sensitivities=names[:2])
    modes = rf.modal_analysis(s, eq.q, sensitivities=names)
    for name in names:
        p = s.parameters[name].value
        errors = []
        for rel in (1e-2, 1e-3, 1e-4):
            h = rel * p
            up, down = s.with_parameters({name: p + h}), s.with_parameters({name: p - h})
            mu, md = rf.modal_analysis(up, eq.q), rf.modal_analysis(down, eq.q)
            dw, dz = modes.sensitivity(name)
            e = [np.max(np.abs((mu.omega - md.omega) / (2 * h) - dw)) / np.max(np.abs(dw) + 1e-300),
                 np.max(np.abs((mu.damping_ratios - md.damping_ratios) / (2 * h) - dz)) / np.max(np.abs(dz))]
            if name in eq.sensitivities:
                dq = (rf.static_equilibrium(up, eq.q).q - rf.static_equilibrium(down, eq.q).q) / (2 * h)
                e.append(np.max(np.abs(dq - eq.sensitivity(name))) / np.max(np.abs(dq)))
            errors.append(max(e) if name != "crank.rz.damping" else e[1])
        assert errors[-1] <= 1e-7 and (errors[1] <= errors[0] / 50 or errors[1] <= 1e-10), (name, errors)  # ζ ∝ c


def test_bad_analysis_sensitivities():
    model, _ = samples.kane_beam(elements=3, deform=("axial", "bend_z"), formulation="classical")  # Coriolis
    s = model.compile()
    with pytest.raises(ValueError, match="gyroscopic"):
        rf.modal_analysis(s, t=20.0, sensitivities=["beam.E"])
    with pytest.raises(ValueError, match="sensitivities: expected a parameter of this system .*'beam.E'"):
        rf.static_equilibrium(s, sensitivities=["beam.e"])
    eq = rf.static_equilibrium(s, sensitivities=["beam.E"])
    with pytest.raises(ValueError, match="name: expected one of the sensitivities asked for"):
        eq.sensitivity("beam.rho")


def test_profile_numbers_converge():
    """The numbers of a drive (Kane's spin-up rate and duration on the moving hub) and of a winch (a payload
    hoisted on a rope from a swinging boom): central differences of whole runs converge onto the sensitivities
    (the residual is not linear in them: their own derivative is a central difference too)."""
    model, _ = samples.kane_beam(elements=4, duration=1.0)
    s = model.compile()
    _converges(s, ["hub.rz.drive.omega", "hub.rz.drive.duration"], "rk4", np.linspace(0, 1.5, 4), dt=5e-4,
               steps=(1e-2, 1e-3, 1e-4))
    m = rf.Model(gravity=(0.0, 0.0, -G))
    boom = m.add_body("boom", m.ground, rf.Joint.revolute("z"), 10.0, (1.0, 1.0, 1.0), com=(1.0, 0.0, 0.0))
    m.prescribe(boom, rf.motion.harmonic(0.3, 1.5))
    load = m.add_body("load", boom, rf.Joint.free(), 5.0, (0.1, 0.1, 0.1), placement=rf.transform((2.0, 0, 0)))
    m.add_rope("rope", boom.point((2.0, 0.0, 0.0)), load, EA=1e6, DA=1e3, length=rf.motion.ramp(-0.2, 0.0, 0.5, start=1.0))  # hoisting from rest, smoothly: the rope stays taut
    s = m.compile()
    r = _converges(s, ["rope.length.rate", "rope.length.duration", "rope.EA"], "generalized_alpha",
                   np.linspace(0, 1.0, 5), steps=(1e-2, 1e-3), floor=2e-6, dt=1e-3, newton_tol=1e-14,
                   q0=[0.0, 0.0, -1.0 - 5 * G / 1e6, 0.0, 0.0, 0.0])
    assert np.all(r.element_forces[:, 0] < 0.0)


@pytest.mark.parametrize("method", ["auto", "radau5", "esdirk43", "dopri5", "generalized_alpha"])
def test_adaptive_runs_take_the_same_steps_with_sensitivities(method):
    """The error is controlled on the state alone: a run with sensitivities is the run without them, step for
    step (auto's hand-over from dopri5 to radau5 too; the Newmark family to Newton's tolerance, as a stalled
    sensitivity correction may refresh the tangent the state's next Newton starts from), and its sensitivities
    agree with the difference of two adaptive runs at E ± 1 % to about the tolerance (their steps differ with p:
    a smaller step of E leaves mostly that difference)."""
    s, beam = strip(("bend_z",), elements=8)
    t = np.linspace(0.0, 0.05, 6)
    adaptive = True if method == "generalized_alpha" else None
    plain = rf.simulate(s, 0.05, method, t_eval=t, adaptive=adaptive)
    r = rf.simulate(s, 0.05, method, t_eval=t, sensitivities=["strip.E"], adaptive=adaptive)
    np.testing.assert_allclose(r.q, plain.q, rtol=0, atol=1e-9 * np.max(np.abs(plain.q)) if adaptive else 0.0)
    assert r.stats["steps"] == plain.stats["steps"] and r.stats["method"] == plain.stats["method"]
    if method == "auto":
        assert r.stats["method"].startswith("dop853, then radau5")  # the default rtol 1e-6
    h = 2e9
    x = [rf.simulate(s.with_parameters({"strip.E": 2e11 + sign * h}), 0.05, method, t_eval=t,
                     adaptive=adaptive).position(beam.tip) for sign in (1, -1)]
    dx = r.position_sensitivity(beam.tip, "strip.E")
    assert np.max(np.abs(dx - (x[0] - x[1]) / (2 * h))) <= 1e-2 * np.max(np.abs(dx))


@pytest.mark.parametrize("method", ["radau5", "esdirk43"])
@pytest.mark.parametrize("algorithm", ["lagrange", "recursive"])
def test_an_exactly_zero_sensitivity_takes_the_runs_steps(algorithm, method):
    """A chain falling freely from rest: its motion does not depend on its masses, so the sensitivity to a mass is
    exactly zero and the corrections of it converge to the round-off of ∂r/∂p's difference, where no relative
    test passes: held to those alone, radau5's ran out of iterations and the recursive run rejected 5 of its
    first steps (12 steps for the run's 8). esdirk43's stages stop at the same floor."""
    model = rf.Model()
    b0 = model.add_body("b0", model.ground, rf.Joint.planar("zx"), mass=1.0, inertia=(0.2, 0.15, 0.35))
    model.add_body("b1", b0, rf.Joint.revolute("z"), mass=5.0, inertia=(0.25, 0.75, 0.99))
    s = model.compile(algorithm)
    plain = rf.simulate(s, 0.05, method=method)
    r = rf.simulate(s, 0.05, method=method, sensitivities=["b0.mass", "b1.mass"])
    assert r.stats["rejected_steps"] == 0 and r.stats["steps"] == plain.stats["steps"]
    for name in ("b0.mass", "b1.mass"):
        dq, dqd = r.sensitivity(name)
        assert np.max(np.abs(dq)) <= 1e-12 and np.max(np.abs(dqd)) <= 1e-12


def test_sensitivities_are_saved_with_the_result(tmp_path):
    """Result.to_npz keeps the sensitivities; load_npz gives them back, position_sensitivity with the system."""
    s = pendulum()
    r = rf.simulate(s, 0.1, "rk4", dt=1e-3, q0=[0.3], sensitivities=["rod.mass", "q0[rod.rz]"])
    back = rf.load_npz(r.to_npz(tmp_path / "r.npz"), s)
    assert list(back.sensitivities) == ["rod.mass", "q0[rod.rz]"]
    for name in back.sensitivities:
        np.testing.assert_array_equal(back.sensitivity(name)[0], r.sensitivity(name)[0])
    np.testing.assert_array_equal(back.position_sensitivity(rf.Point(0, (0.4, 0.0, 0.0)), "rod.mass"),
                                  r.position_sensitivity(rf.Point(0, (0.4, 0.0, 0.0)), "rod.mass"))
    assert rf.load_npz(rf.simulate(s, 0.1, "rk4", dt=1e-3).to_npz(tmp_path / "p.npz")).sensitivities == {}



def _driven_pendulum(fraction, law="trapezoidal"):
    m = rf.Model(gravity=(0.0, -9.81, 0.0))
    arm = m.add_body("arm", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.5, 0.0, 0.0))
    m.add_body("bob", arm, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.5, 0.0, 0.0),
               placement=rf.transform((1.0, 0.0, 0.0)))
    m.prescribe(arm, rf.motion.rest_to_rest(0.0, 1.0, t0=0.0, duration=1.0, law=law, fraction=fraction))
    return m.compile()


def test_a_profile_number_at_the_edge_of_its_values():
    """A trapezoidal drive's fraction at 0.5, the largest it takes: its difference moves inward
    ([p − 2h, p]) instead of refusing the run (fuzz seed 2033567127, case 37: a 1 ms run, on which
    the step grew to 1.8 past the edge). The sensitivity at the edge continues the one just inside it,
    and with the quintic law, which has no fraction, it is zero."""
    name = "arm.rz.drive.fraction"
    edge = rf.simulate(_driven_pendulum(0.5), 1.0, "rk4", dt=1e-4, sensitivities=[name]).sensitivity(name)[0][-1]
    inside = rf.simulate(_driven_pendulum(0.4999), 1.0, "rk4", dt=1e-4, sensitivities=[name]).sensitivity(name)[0][-1]
    assert np.isfinite(edge).all() and np.abs(edge - inside).max() < 0.2 * np.abs(inside).max()  # measured 0.09
    short = rf.simulate(_driven_pendulum(0.5), 1e-3, "rkf45", sensitivities=[name]).sensitivity(name)[0]
    assert np.isfinite(short).all()
    quintic = rf.simulate(_driven_pendulum(0.5, "quintic"), 1.0, "rk4", dt=1e-3, sensitivities=[name])
    assert np.abs(quintic.sensitivity(name)[0]).max() == 0.0


@pytest.mark.parametrize("method", ["radau5", "esdirk43", "auto", "generalized_alpha"])
def test_sensitivities_through_a_rope_going_slack(method):
    """A 10 kg load on a rope of EA 1e5 paid out by a winch, released stretched: it bounces, the rope
    goes slack and taut again. The sensitivities' corrections across the rope's kink did not converge
    with the step's Newton matrix (radau5, esdirk43 and auto failed, and the Newmark family when adaptive);
    such a step is now retried as after Newton's failure (a fresh tangent, then a shorter step). Against
    central differences of two runs."""
    m = rf.Model(gravity=(0.0, 0.0, -9.81))
    load = m.add_body("load", m.ground, rf.Joint.custom(["x", "y", "z"]), mass=10.0, inertia=(0.1, 0.1, 0.1))
    m.add_rope("element0", m.ground.point((0.0, 0.0, 0.0)), load, EA=1e5, length=rf.motion.polynomial([0.9, 0.3]))
    system = m.compile()
    q0 = np.array([0.0, 0.0, -1.0])
    kw = dict(method="radau5", rtol=1e-10, atol=1e-12, t_eval=np.linspace(0.0, 2.0, 21))
    d = 1e-6
    fd = (rf.simulate(system, 2.0, q0=q0 + [d, 0, 0], **kw).q - rf.simulate(system, 2.0, q0=q0 - [d, 0, 0], **kw).q) / (2 * d)
    assert np.abs(fd).max() > 1.0  # the load swings: the sensitivity grows
    # at the default tolerances (where they failed), against the differences within what those allow
    kw = dict(method=method, t_eval=kw["t_eval"], **({"adaptive": True, "dt": 1e-3} if method == "generalized_alpha"
                                                     else {}))
    S, _ = rf.simulate(system, 2.0, q0=q0, sensitivities=["q0[load.x]"], **kw).sensitivity("q0[load.x]")
    np.testing.assert_allclose(S, fd, atol=5e-3)


def test_a_number_that_cannot_change_alone_is_refused_by_name():
    """A piece's value of a piecewise drive (continuity 1: the pieces meet at the break) cannot move alone: the
    sensitivity by it is refused naming sensitivities (parameters for rf.gradient) and the parameter, not the
    profile maker's argument."""
    def build(value=0.5, brk=0.2):
        model = rf.Model(gravity=(0.0, 0.0, -G))
        drive = rf.motion.piecewise([rf.motion.constant(value), rf.motion.polynomial([value])], [brk])
        arm = model.add_body("arm", model.ground, rf.Joint.revolute("y"), 1.0, (0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5))
        model.add_body("tip", arm, rf.Joint.revolute("y", stiffness=5.0), 1.0, (0.1, 0.1, 0.1), com=(0.0, 0.0, -0.5),
                       placement=rf.transform((0.0, 0.0, -1.0)))
        model.prescribe(arm, drive)
        return model.compile()

    s = build()
    piece = "arm.ry.drive.pieces[0].value"
    assert piece in s.parameters
    with pytest.raises(ValueError, match=r"^sensitivities: expected parameters that can change alone, got "
                                         r"'arm\.ry\.drive\.pieces\[0\]\.value'.*pieces: expected pieces 0 and 1 to meet"):
        rf.simulate(s, 0.3, "rk4", dt=1e-3, sensitivities=[piece])
    with pytest.raises(ValueError, match=r"^parameters: expected parameters that can change alone"):
        rf.gradient(s, 0.3, [piece], outputs={"y": 0}, terminal=lambda y: y["y"], dt=1e-3)

