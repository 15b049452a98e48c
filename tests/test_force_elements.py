"""Force elements between two bodies (spring-dampers, force-controlled cylinders): against the
equations of motion derived by hand (SymPy), central differences, energy and moment balances."""

import numpy as np
import pytest
import sympy as sp

import rigidfem as rf
from conftest import central_jacobians

ENGINES = ("recursive", "lagrange")


def spring_pendulum(algorithm, m=1.3, L=0.8, Izz=0.05, k=40.0, c=0.7, l0=0.5, P=(0.3, 0.6, 0.0), g=9.81):
    """A planar pendulum (revolute z at the origin, gravity −y) whose bob at (L, 0, 0) hangs on a
    spring-damper to the ground point P."""
    model = rf.Model(gravity=(0.0, -g, 0.0))
    arm = model.add_body("arm", model.ground, rf.Joint.revolute("z"), m, (0.03, 0.03, Izz), com=(L, 0.0, 0.0))
    model.add_spring_damper("spring", model.ground.point(P), arm.point((L, 0.0, 0.0)), stiffness=k, length=l0, damping=c)
    return model.compile(algorithm)


def spring_pendulum_reference(m=1.3, L=0.8, Izz=0.05, k=40.0, c=0.7, l0=0.5, P=(0.3, 0.6, 0.0), g=9.81):
    """θ̈(θ, θ̇) from Lagrange's equations with V = m g y + ½ k (l − l₀)², D = ½ c l̇² (SymPy)."""
    th, thd = sp.symbols("theta thetadot")
    r = sp.Matrix([L * sp.cos(th), L * sp.sin(th)])
    d = r - sp.Matrix(P[:2])
    l = sp.sqrt(d.dot(d))
    ld = sp.diff(l, th) * thd
    J = m * L**2 + Izz
    Q = -sp.diff(m * g * r[1] + k * (l - l0) ** 2 / 2, th) - c * ld * sp.diff(l, th)
    return sp.lambdify((th, thd), Q / J, "numpy")


@pytest.mark.parametrize("algorithm", ENGINES)
def test_spring_pendulum_matches_lagranges_equations(algorithm):
    s = spring_pendulum(algorithm)
    reference = spring_pendulum_reference()
    rng = np.random.default_rng(1)
    for th, thd in rng.uniform(-3.0, 3.0, (8, 2)):
        assert s.forward_dynamics(0.0, [th], [thd])[0] == pytest.approx(reference(th, thd), rel=1e-12, abs=1e-12)


def chain_with_elements(algorithm, law=False):
    """A 3D chain of four bodies with elements between bodies of different branches, between a
    body and its descendant and to the ground (every tangent case: neither, one or both points
    carried by a coordinate)."""
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    a = model.add_body("a", model.ground, rf.Joint.spherical(), 2.0, (0.1, 0.2, 0.15), com=(0.4, 0.0, 0.0))
    b = model.add_body("b", a, rf.Joint.universal(("y", "z")), 1.5, (0.05, 0.08, 0.07), com=(0.3, 0.1, 0.0),
                       placement=rf.transform(translation=(0.8, 0.0, 0.0)))
    c = model.add_body("c", a, rf.Joint.prismatic("y"), 0.7, (0.02, 0.03, 0.04), com=(0.0, 0.0, 0.1),
                       placement=rf.transform(translation=(0.2, 0.0, 0.3)))
    d = model.add_body("d", b, rf.Joint.revolute("x"), 0.9, (0.03, 0.02, 0.05), com=(0.0, 0.2, 0.0),
                       placement=rf.transform(translation=(0.6, 0.0, 0.0)))
    model.add_spring_damper("element0", c.point((0.1, 0.2, 0.0)), d.point((0.0, 0.3, 0.1)), stiffness=120.0, length=0.4,
                            damping=3.0)
    model.add_spring_damper("element1", model.ground.point((0.5, 0.5, 1.0)), b.point((0.2, 0.0, 0.0)), stiffness=60.0,
                            length=0.9, damping=1.0)
    model.add_spring_damper("element2", a.point((0.3, 0.0, 0.1)), d.point((0.1, 0.1, 0.0)), stiffness=30.0, length=0.5)
    if law:
        model.add_cylinder("element3", model.ground.point((-0.3, 0.2, 0.0)), c.point((0.0, 0.1, 0.0)),
                           lambda t, l, ld: 5.0 * np.sin(3.0 * l) - 0.4 * ld * abs(ld) + 2.0 * t, damping=0.5)
    else:
        model.add_cylinder("element3", model.ground.point((-0.3, 0.2, 0.0)), c.point((0.0, 0.1, 0.0)),
                           rf.motion.harmonic(4.0, 2.0), damping=0.5)
    return model.compile(algorithm)


@pytest.mark.parametrize("law", [False, True])
def test_force_jacobians_are_exact(law):
    """The recursive engine's analytic ∂f/∂q and ∂f/∂q̇ (geometric term, change of the line and of
    the force, velocity of the points) against central differences; the engines agree."""
    rec, lag = chain_with_elements("recursive", law), chain_with_elements("lagrange", law)
    rng = np.random.default_rng(7)
    for _ in range(3):
        t, q, qd = 0.37, rng.uniform(-0.6, 0.6, rec.nq), rng.uniform(-2.0, 2.0, rec.nq)
        Kq, Kqd = rec.force_jacobians(t, q, qd)
        Fq, Fqd = central_jacobians(rec, t, q, qd)
        scale = np.abs(Fq).max()
        assert np.abs(Kq - Fq).max() < 1e-7 * scale
        assert np.abs(Kqd - Fqd).max() < 1e-7 * np.abs(Fqd).max()
        np.testing.assert_allclose(lag.forward_dynamics(t, q, qd), rec.forward_dynamics(t, q, qd), rtol=1e-10,
                                   atol=1e-10)
        np.testing.assert_allclose(lag.generalized_forces(t, q, qd), rec.generalized_forces(t, q, qd), rtol=1e-11,
                                   atol=1e-10)


@pytest.mark.parametrize("algorithm", ENGINES)
def test_energy_balance_with_springs_and_dampers(algorithm):
    """Kinetic + gravity + elastic energy (with ½ k (l − l₀)² of the elements) plus the work of the
    dampers (∫ c l̇² dt) stays constant."""
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    a = model.add_body("a", model.ground, rf.Joint.spherical(), 2.0, (0.1, 0.2, 0.15), com=(0.4, 0.0, 0.0))
    b = model.add_body("b", a, rf.Joint.universal(("y", "z")), 1.5, (0.05, 0.08, 0.07), com=(0.3, 0.1, 0.0),
                       placement=rf.transform(translation=(0.8, 0.0, 0.0)))
    model.add_spring_damper("element0", model.ground.point((0.5, 0.5, 1.0)), b.point((0.2, 0.0, 0.0)), stiffness=60.0,
                            length=0.9, damping=0.8)
    model.add_spring_damper("element1", model.ground.point((0.0, -0.4, 0.2)), a.point((0.3, 0.0, 0.1)), stiffness=200.0,
                            length=0.3)
    s = model.compile(algorithm)
    q0 = np.array([0.2, -0.3, 0.1, 0.4, -0.2])
    r = rf.simulate(s, 2.0, method="dopri5", rtol=1e-11, atol=1e-12, q0=q0, qd0=np.zeros(s.nq),
                    t_eval=np.linspace(0.0, 2.0, 4001))
    P = np.array([s.dissipated_power(t, q, qd) for t, q, qd in zip(r.t, r.q, r.qd)])
    work = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(r.t))])
    total = r.energy + work
    assert work[-1] > 0.1 * abs(r.energy[0] - r.energy.min())  # the dampers did work
    assert np.abs(total - total[0]).max() < 2e-6 * np.abs(r.kinetic_energy).max()
    # the stored energy of the elements is in elastic_energy: at rest, q = 0, it is Σ ½ k (l − l₀)²
    lengths = s.element_states(0.0, np.zeros(s.nq), np.zeros(s.nq))[:, 0]
    assert s.elastic_energy(0.0, np.zeros(s.nq)) == pytest.approx(
        0.5 * 60.0 * (lengths[0] - 0.9) ** 2 + 0.5 * 200.0 * (lengths[1] - 0.3) ** 2, rel=1e-14)


def test_lateral_stiffness_of_a_pretensioned_spring():
    """A mass on a prismatic joint across a spring of length L stretched from l₀: the only
    stiffness is geometric, T / L with T = k (L − l₀); ω² = k (L − l₀) / (L m)."""
    L, l0, k, m = 2.0, 1.5, 300.0, 2.0
    for algorithm in ENGINES:
        model = rf.Model(gravity=(0.0, 0.0, 0.0))
        slider = model.add_body("slider", model.ground, rf.Joint.prismatic("y"), m, (1.0, 1.0, 1.0))
        model.add_spring_damper("element0", model.ground.point((-L, 0.0, 0.0)), slider, stiffness=k, length=l0, damping=5.0)
        modes = rf.modal_analysis(model.compile(algorithm), np.zeros(1))
        assert modes.omega[0] == pytest.approx(np.sqrt(k * (L - l0) / (L * m)), rel=1e-10)
        assert modes.damping_ratios[0] == 0.0  # the damper acts along x only


@pytest.mark.parametrize("algorithm", ENGINES)
def test_cylinder_holds_a_boom_in_static_equilibrium(algorithm):
    """A boom (revolute z, gravity −y) lifted by a cylinder from the ground point (a, 0) to the boom
    point (b, 0) pushing with F: moment balance F (e × r_B)_z = m g x_C, solved by hand."""
    m, xc, a, b, F = 50.0, 1.2, 0.6, 0.9, 600.0
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    boom = model.add_body("boom", model.ground, rf.Joint.revolute("z"), m, (3.0, 3.0, 5.0), com=(xc, 0.0, 0.0))
    model.add_cylinder("lift", model.ground.point((a, -0.5, 0.0)), boom.point((b, 0.0, 0.0)), F)
    s = model.compile(algorithm)
    eq = rf.static_equilibrium(s, [0.8])
    th = eq.q[0]

    def moment(th):
        rb = np.array([b * np.cos(th), b * np.sin(th)])
        d = rb - np.array([a, -0.5])
        e = d / np.linalg.norm(d)
        return F * (rb[0] * e[1] - rb[1] * e[0]) - m * 9.81 * xc * np.cos(th)

    from scipy.optimize import brentq

    assert th == pytest.approx(brentq(moment, 0.5, 1.5, xtol=1e-15), abs=1e-10)
    assert s.element_names == ["lift"]
    np.testing.assert_allclose(s.element_states(0.0, eq.q, [0.0])[0, 2], F, rtol=1e-15)


def test_python_law_equals_the_built_in_spring_damper():
    """The slow path (a Python law F(t, l, l̇)) and the built-in linear element give the same motion,
    and Result.element_forces is −k (l − l₀) − c l̇ along it."""
    k, l0, c = 40.0, 0.5, 0.7

    def build(python):
        model = rf.Model(gravity=(0.0, -9.81, 0.0))
        arm = model.add_body("arm", model.ground, rf.Joint.revolute("z"), 1.3, (0.03, 0.03, 0.05), com=(0.8, 0, 0))
        ends = model.ground.point((0.3, 0.6, 0.0)), arm.point((0.8, 0.0, 0.0))
        if python:
            model.add_cylinder("element0", *ends, lambda t, l, ld: -k * (l - l0) - c * ld)
        else:
            model.add_spring_damper("element0", *ends, stiffness=k, length=l0, damping=c)
        return model.compile(), ends

    (built_in, ends), (slow, _) = build(False), build(True)
    runs = [rf.simulate(s, 1.0, method="generalized_alpha", dt=1e-3, q0=[0.4]) for s in (built_in, slow)]
    np.testing.assert_allclose(runs[1].q, runs[0].q, rtol=0, atol=1e-12)
    r = runs[0]
    x = r.position(ends[1]) - np.asarray(ends[0].r)
    l = np.linalg.norm(x, axis=1)
    v = r.qd[:, :1] * 0.8 * np.stack([-np.sin(r.q[:, 0]), np.cos(r.q[:, 0])], axis=1)  # ṙ_B = θ̇ e_z × r_B
    ld = np.einsum("ij,ij->i", x[:, :2] / l[:, None], v)
    np.testing.assert_allclose(r.element_forces[:, 0], -k * (l - l0) - c * ld, rtol=1e-12, atol=1e-10)


def test_cylinder_in_a_closed_chain_with_implicit_methods():
    """A cylinder (force control) lifts a four-bar: the index-3 generalised-α and DOPRI5 agree, and
    the loop stays closed."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    crank = model.add_body("crank", model.ground, rf.Joint.revolute("z"), 1.0, (0.01, 0.01, 0.02),
                           com=(0.2, 0.0, 0.0))
    coupler = model.add_body("coupler", crank, rf.Joint.revolute("z"), 1.0, (0.04, 0.04, 0.08), com=(0.5, 0, 0),
                             placement=rf.transform(translation=(0.4, 0.0, 0.0)))
    rocker = model.add_body("rocker", model.ground, rf.Joint.revolute("z"), 1.0, (0.03, 0.03, 0.05),
                            com=(0.35, 0.0, 0.0), placement=rf.transform(translation=(1.0, 0.0, 0.0)))
    model.add_loop_joint("loop0", "revolute", coupler.point((1.0, 0.0, 0.0)), rocker.point((0.7, 0.0, 0.0)))
    model.add_cylinder("element0", model.ground.point((0.5, -0.4, 0.0)), coupler.point((0.5, 0.0, 0.0)),
                       rf.motion.polynomial([0.0, 60.0]), damping=2.0)
    s = model.compile()
    q0, qd0 = s.assemble([1.2, -0.9, 1.9])
    a = rf.simulate(s, 1.0, method="dopri5", rtol=1e-10, atol=1e-12, q0=q0, qd0=qd0, t_eval=[1.0])
    b = rf.simulate(s, 1.0, method="generalized_alpha", dt=5e-4, q0=q0, qd0=qd0, t_eval=[1.0])
    assert np.abs(a.q[-1] - b.q[-1]).max() < 1e-5
    assert np.abs(a.q[-1] - q0).max() > 0.05  # it moved
    g, _, _ = s.loop_constraints(1.0, b.q[-1], b.qd[-1])
    assert np.abs(g).max() < 1e-10


@pytest.mark.parametrize(
    "kwargs, argument",
    [
        (dict(name="spring", stiffness=-1.0, length=1.0), "stiffness"),
        (dict(name="spring", stiffness=1.0, length=float("nan")), "length"),
        (dict(name="spring", stiffness=1.0, length=1.0, damping="x"), "damping"),
        (dict(name="twice", stiffness=1.0, length=1.0), "name"),
        (dict(name=3, stiffness=1.0, length=1.0), "name"),
        (dict(name="", stiffness=1.0, length=1.0), "name"),
        (dict(name="b", stiffness=1.0, length=1.0), "name"),
    ],
)
def test_bad_spring_damper_input(kwargs, argument):
    model = rf.Model()
    body = model.add_body("b", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.add_spring_damper("twice", model.ground.point((1, 0, 0)), body.point((0, 1, 0)), stiffness=1.0, length=1.0)
    with pytest.raises(ValueError, match=f"^{argument}: expected"):
        model.add_spring_damper(a=model.ground.point((1, 0, 0)), b=body.point((0, 1, 0)), **kwargs)


def test_bad_cylinder_input_and_failures():
    model, other = rf.Model(), rf.Model()
    body = model.add_body("b", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    stranger = other.add_body("s", other.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    with pytest.raises(ValueError, match="^force: expected a finite number in N, a rigidfem.motion profile"):
        model.add_cylinder("cylinder", model.ground, body.point((1, 0, 0)), "strong")
    with pytest.raises(ValueError, match="^b: expected a Body or Point of this model"):
        model.add_cylinder("cylinder", model.ground, stranger, 1.0)
    with pytest.raises(ValueError, match="^b: expected a body other than a"):
        model.add_cylinder("cylinder", body, body.point((1, 0, 0)), 1.0)
    with pytest.raises(ValueError, match="^a: expected a Body or Point"):
        model.add_cylinder("cylinder", "ground", body, 1.0)
    # the points meet: no line of action, a SimulationError naming the element and the time
    model.add_cylinder("degenerate", model.ground, body, 1.0)
    s = model.compile()
    with pytest.raises(rf.SimulationError, match="force element 'degenerate' coincide"):
        s.forward_dynamics(0.25, [0.0], [0.0])
    # a law that returns no number: a ForceLawError naming the law, the element and the state
    model = rf.Model()
    body = model.add_body("b", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.add_cylinder("bad", model.ground.point((1, 1, 0)), body.point((1, 0, 0)), lambda t, l, ld: None)
    s = model.compile()
    with pytest.raises(rf.ForceLawError, match="force element 'bad'.*got None at t = 0 s, l = 1, ld = 0"):
        s.forward_dynamics(0.0, [0.0], [0.0])
    with pytest.raises(rf.SimulationError, match="force element 'bad'"):
        rf.simulate(s, 0.1)


# --------------------------------------------------------------------------- buffers (Hunt–Crossley)

def _drop_on_buffer(law, m=2.0, v0=1.5, gap=0.3):
    """A block of mass m (kg) on a prismatic z joint, no gravity, moving down at v0 (m/s) from z = gap + l0 above a
    buffer from the ground: the buffer touches at z = l0."""
    model = rf.Model(gravity=None)
    block = model.add_body("block", model.ground, rf.Joint.prismatic("z"), mass=m, inertia=(0.1, 0.1, 0.1))
    model.add_force_element("stop", model.ground, block, law)
    return model.compile(), law.values["length"] + gap


@pytest.mark.parametrize("n", [1.0, 1.5])
def test_an_elastic_buffer_returns_the_speed_and_reaches_the_energys_penetration(n):
    """Without dissipation the block leaves at the speed it came (energy), after pushing in to
    δ_max = ((n + 1) m v0² / (2 k))^(1/(n + 1)); a linear buffer (n = 1) holds it for π √(m/k)."""
    m, v0, k, l0 = 2.0, 1.5, 4e4, 0.5
    system, z0 = _drop_on_buffer(rf.laws.Buffer(stiffness=k, exponent=n, length=l0), m, v0)
    t = np.linspace(0.0, 1.0, 20001)
    r = rf.simulate(system, 1.0, "radau5", q0=[z0], qd0=[-v0], t_eval=t, rtol=1e-10, atol=1e-12)
    assert abs(r.qd[-1, 0] - v0) < 1e-7 * v0
    depth = ((n + 1) * m * v0**2 / (2 * k)) ** (1 / (n + 1))
    assert abs((l0 - r.q[:, 0].min()) - depth) < 1e-6 * depth
    if n == 1.0:
        inside = t[r.q[:, 0] < l0]
        assert abs((inside[-1] - inside[0]) - np.pi * np.sqrt(m / k)) < 2 * (t[1] - t[0])
    assert np.ptp(r.energy) < 2e-7 * 0.5 * m * v0**2  # the touch is a kink radau5 steps over (no event yet)


def test_hunt_crossley_restitution_matches_the_impact_integral():
    """m δ̈ = −k δⁿ (1 + α δ̇) integrates over the contact to v_out − ln(1 + α v_out)/α = v_in − ln(1 + α v_in)/α
    (δ from 0 back to 0); its root v_out < 0, found here, against the block's speed after the impact, and the energy
    lost against ∫ P dt of dissipated_power."""
    from scipy.optimize import brentq

    m, v0, k, n, alpha, l0 = 2.0, 1.5, 4e4, 1.5, 0.3, 0.5
    system, z0 = _drop_on_buffer(rf.laws.Buffer(stiffness=k, exponent=n, length=l0, dissipation=alpha), m, v0)
    t = np.linspace(0.0, 1.0, 40001)
    r = rf.simulate(system, 1.0, "radau5", q0=[z0], qd0=[-v0], t_eval=t, rtol=1e-10, atol=1e-12)
    g = lambda v: v - np.log1p(alpha * v) / alpha  # noqa: E731
    v_out = brentq(lambda v: g(v) - g(v0), -1.0 / alpha + 1e-12, -1e-9)  # the other root: leaving
    assert abs(r.qd[-1, 0] - (-v_out)) < 1e-6 * v0, (r.qd[-1, 0], -v_out)
    assert -v_out < 0.9 * v0  # it did dissipate
    lost = r.energy[0] - r.energy[-1]
    dissipated = np.sum(0.5 * np.diff(t) * (r.dissipated_power[1:] + r.dissipated_power[:-1]))
    assert abs(lost - dissipated) < 1e-5 * lost
    assert abs(lost - 0.5 * m * (v0**2 - v_out**2)) < 1e-6 * lost


def test_a_buffers_derivatives_are_exact_and_its_constants_are_parameters():
    law = rf.laws.Buffer(stiffness=3e3, exponent=1.5, length=1.2, dissipation=0.2)
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    arm = model.add_body("arm", model.ground, rf.Joint.revolute("y"), mass=1.0, inertia=(0.1, 0.1, 0.1),
                         com=(1.0, 0.0, 0.0))
    model.add_force_element("stop", model.ground.point((1.0, 0.0, -1.0)), arm.point((1.0, 0.0, 0.0)), law)
    s = model.compile()
    for q, qd in (([0.3], [0.5]), ([0.2], [-0.4]), ([-0.3], [0.1])):  # pushing, leaving, not touching
        Kq, Kqd = s.force_jacobians(0.0, np.array(q), np.array(qd))
        Fq, Fqd = central_jacobians(s, 0.0, np.array(q), np.array(qd))
        np.testing.assert_allclose(Kq, Fq, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(Kqd, Fqd, rtol=1e-6, atol=1e-6)
    p = s.parameters
    assert (p["stop.stiffness"].unit, p["stop.dissipation"].unit) == ("N/m^n", "s/m")
    assert "stop.exponent" not in p and "stop.length" not in p
    with pytest.raises(ValueError, match=r"^exponent: expected a number >= 1 in 1"):
        rf.laws.Buffer(stiffness=1.0, exponent=0.5)
    with pytest.raises(ValueError, match="^profile: expected None"):
        rf.laws.Buffer(stiffness=1.0, profile=rf.motion.constant(1.0))


def test_sliding_friction_stops_a_block_and_its_derivatives_are_exact():
    """rf.laws.SlidingFriction along an element (a cylinder's seals): a block on a slide pushed off at v0 stops after
    m v0²/(2 F_C); the law's ∂F/∂l̇ against central differences on the 3D chain; the energy lost is ∫ P dt."""
    m, v0, Fc = 2.0, 1.5, 3.0
    model = rf.Model(gravity=None)
    block = model.add_body("block", model.ground, rf.Joint.prismatic("x"), m, (0.1, 0.1, 0.1))
    seal = model.add_force_element("seal", model.ground.point((-1.0, 0.0, 0.0)), block,
                                   rf.laws.SlidingFriction(breakaway=Fc, coulomb=Fc, smoothing=1e-6))
    s = model.compile()
    assert seal.kind == "SlidingFriction" and set(s.parameters) >= {"seal.breakaway", "seal.coulomb", "seal.viscous"}
    r = rf.simulate(s, 2.0, qd0=[v0], t_eval=np.linspace(0.0, 2.0, 2001), method="radau5", rtol=1e-10, atol=1e-12)
    assert r.q[-1, 0] == pytest.approx(m * v0 ** 2 / (2 * Fc), abs=2e-6)
    lost = np.concatenate([[0.0], np.cumsum(0.5 * (r.dissipated_power[1:] + r.dissipated_power[:-1]) * np.diff(r.t))])
    assert np.abs(r.energy + lost - r.energy[0]).max() < 1e-3 * r.energy[0]
    # derivatives: the law between two bodies of a 3D chain, a Stribeck fall and viscous friction
    chain = rf.Model(gravity=(0.0, 0.0, -9.81))
    a = chain.add_body("a", chain.ground, rf.Joint.spherical(), 2.0, (0.1, 0.2, 0.15), com=(0.4, 0.0, 0.0))
    b = chain.add_body("b", a, rf.Joint.universal(("y", "z")), 1.5, (0.05, 0.08, 0.07),
                       placement=rf.transform((0.8, 0.0, 0.0)))
    chain.add_force_element("seal", chain.ground.point((0.3, 0.5, 0.2)), b.point((0.2, 0.1, 0.0)),
                            rf.laws.SlidingFriction(breakaway=5.0, coulomb=3.0, stribeck=0.5, viscous=0.7, smoothing=0.2))
    rec = chain.compile()
    rng = np.random.default_rng(4)
    for _ in range(3):
        t, q, qd = 0.0, rng.uniform(-0.6, 0.6, rec.nq), rng.uniform(-1.0, 1.0, rec.nq)
        Kq, Kqd = rec.force_jacobians(t, q, qd)
        Fq, Fqd = central_jacobians(rec, t, q, qd)
        assert np.abs(Kq - Fq).max() < 1e-7 * np.abs(Fq).max()
        assert np.abs(Kqd - Fqd).max() < 1e-7 * np.abs(Fqd).max()


def test_a_position_controlled_actuators_seal_friction_adds_to_the_force_it_must_exert():
    """Friction on an actuator under position control: a SlidingFriction element between the actuator's own points.
    The motion is the actuator's, so the run is the frictionless one, and the actuator's force (its loop's reaction)
    is the frictionless force less the seal's F(l̇) = −(F_C + (F_S − F_C) e^{−(l̇/v_S)²}) tanh(l̇/v_ε) − b l̇, computed
    here (1e-8 of the force; the reactions of dopri5's outputs, the forward dynamics' at each state): the cylinder
    pushes harder while extending and pulls harder while retracting."""
    FS, FC, vS, b, ve = 800.0, 500.0, 0.05, 200.0, 1e-3

    def luffed(seal):
        model = rf.Model(gravity=(0.0, -9.81, 0.0))
        boom = model.add_body("boom", model.ground, rf.Joint.revolute("z"), 5.0, (0.01, 1.7, 1.7), com=(1.0, 0.0, 0.0))
        a, tip = model.ground.point((0.5, 0.0, 0.0)), boom.point((1.0, 0.0, 0.0))
        model.add_actuator("cylinder", a, tip, rf.motion.harmonic(0.15, 2.0, offset=1.0))  # extends, then retracts
        if seal:
            model.add_force_element("seal", a, tip, rf.laws.SlidingFriction(breakaway=FS, coulomb=FC, stribeck=vS,
                                                                             viscous=b, smoothing=ve))
        return model.compile()

    t = np.linspace(0.0, 3.0, 301)
    runs = []
    for seal in (False, True):
        s = luffed(seal)
        q0, qd0 = s.assemble([np.arccos((0.25 + 1.0 - 1.0) / 1.0)], [0.0])
        runs.append(rf.simulate(s, 3.0, method="dopri5", rtol=1e-10, atol=1e-12, q0=q0, qd0=qd0, t_eval=t))
    plain, sealed = runs
    np.testing.assert_allclose(sealed.q, plain.q, atol=1e-9)
    # l̇ at the outputs (the actuator's l = 1 + 0.15 sin 2t)
    s = luffed(True)
    v = np.array([s.element_states(tk, q, qd)[0, 1] for tk, q, qd in zip(t, sealed.q, sealed.qd)])
    np.testing.assert_allclose(v, 0.3 * np.cos(2.0 * t), atol=1e-6)
    friction = -(FC + (FS - FC) * np.exp(-(v / vS) ** 2)) * np.tanh(v / ve) - b * v
    F_plain, F_sealed = plain.loop_reactions[:, 0, 0], sealed.loop_reactions[:, 0, 0]
    np.testing.assert_allclose(F_sealed, F_plain - friction, atol=1e-8 * np.abs(F_sealed).max())
    assert (F_sealed - F_plain)[v > 0.05].min() > FC and (F_sealed - F_plain)[v < -0.05].max() < -FC
