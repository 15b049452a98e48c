"""Model inputs that used to give silent wrong answers (issue 10, items 7-10): numbers given as
strings, NaN offsets, a coordinate prescribed twice, handles of another model, poses at a
default time that a drive makes wrong, force laws returning something else than a number; and
long beams built in O(m) with their centre line in one kinematics pass.

Every reference is written here: rotations about z, the drive's angle and rate, −k x / m, ρAΔ and
EI/Δ of a uniform beam.
"""

import fractions
import math

import numpy as np
import pytest

import rigidfem as rf
from conftest import step_of

NAN, INF = float("nan"), float("inf")


def rz(theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def arm(gravity=None):
    """A rod of 1 kg along x on a revolute joint about z at the origin."""
    model = rf.Model(gravity=gravity)
    link = model.add_body("arm", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1e-4, 0.1, 0.1),
                          com=(0.5, 0.0, 0.0))
    return model, link


def block(mass=2.0, stiffness=50.0):
    """A block on a spring along x, no gravity: x'' = (−k x + Q) / m."""
    model = rf.Model(gravity=None)
    body = model.add_body("block", model.ground, rf.Joint.prismatic("x", stiffness=stiffness), mass=mass,
                          inertia=(0.1, 0.1, 0.1))
    return model, body


# --- a) numbers that are not numbers --------------------------------------------------------

MATERIAL = dict(E=2.1e11, rho=7850.0, nu=0.3, retardation=1e-4)
SECTION = dict(A=1e-4, Iy=1e-9, Iz=2e-9, J=2.5e-9, kappa_y=0.8, kappa_z=0.8)


@pytest.mark.parametrize("field", ["E", "rho", "nu", "G", "retardation"])
@pytest.mark.parametrize("value", ["7850", b"1", None, NAN, INF, -INF, True, [1.0], 1 + 2j])
def test_material_fields_must_be_finite_numbers(field, value):
    if value is None and field in ("nu", "G"):
        pytest.skip("None is the documented default of nu and G")
    with pytest.raises(ValueError, match=rf"^{field}: expected a (finite )?(positive |non-negative )?number"):
        rf.Material(**{**MATERIAL, field: value})


@pytest.mark.parametrize("field, value", [("E", 0.0), ("E", -1.0), ("rho", 0.0), ("G", -8e10), ("retardation", -1e-3),
                                          ("nu", 0.6), ("nu", -1.0)])
def test_material_fields_must_be_physical(field, value):
    with pytest.raises(ValueError, match=rf"^{field}: expected"):
        rf.Material(**{**MATERIAL, field: value})


def test_material_stores_the_numbers_it_checked():
    mat = rf.Material(E=np.float32(2e11), rho=np.int64(7850), nu=fractions.Fraction(1, 4))
    assert all(type(v) is float for v in (mat.E, mat.rho, mat.nu, mat.G, mat.retardation))
    assert mat.rho == 7850.0 and mat.G == pytest.approx(2e11 / (2 * 1.25), rel=1e-7)
    beam_mass = _uniform_beam_mass(mat)
    assert beam_mass == pytest.approx(7850.0 * 1e-4 * 2.0, rel=1e-12)


def _uniform_beam_mass(mat):
    model = rf.Model(gravity=None)
    beam = model.add_beam("b", model.ground, 2.0, mat, rf.Section(**SECTION), 4, deform="bend_z")
    return sum(p.mass for p in beam.rfe)


@pytest.mark.parametrize("field", list(SECTION))
@pytest.mark.parametrize("value", ["1e-4", None, NAN, INF, 0.0, -1e-9, False])
def test_section_fields_must_be_positive_finite_numbers(field, value):
    with pytest.raises(ValueError, match=rf"^{field}: expected a (finite )?positive number"):
        rf.Section(**{**SECTION, field: value})


@pytest.mark.parametrize("make, name", [(lambda: rf.Section.rectangle("0.05", 0.01), "width"),
                                        (lambda: rf.Section.rectangle(0.05, INF), "height"),
                                        (lambda: rf.Section.circle(None), "d"),
                                        (lambda: rf.Section.tube(0.05, "0.01"), "d_in")])
def test_section_constructors_check_their_numbers(make, name):
    with pytest.raises(ValueError, match=rf"^{name}: expected"):
        make()


def test_section_stores_floats():
    sec = rf.Section(A=np.float32(1e-4), Iy=1, Iz=np.int32(2), J=fractions.Fraction(1, 2))
    assert all(type(getattr(sec, f)) is float for f in SECTION)


@pytest.mark.parametrize("r", [(NAN, 0.0, 0.0), (0.0, INF, 0.0), (0.0, 0.0, -INF)])
def test_point_offsets_must_be_finite(r):
    _, link = arm()
    with pytest.raises(ValueError, match=r"^r: expected a finite offset"):
        link.point(r)
    with pytest.raises(ValueError, match=r"^r: expected a finite offset"):
        rf.Point(link.index, r)


def test_a_coordinate_takes_one_motion():
    model, link = arm()
    model.prescribe(link, rf.motion.constant(0.3))
    with pytest.raises(ValueError, match=r"^coordinate: expected a coordinate not prescribed yet.*'arm\.rz'"):
        model.prescribe(link, rf.motion.constant(0.7))
    system = model.compile()
    assert system.np == 1 and system.nq == 0
    # the first motion holds: the arm's pose is Rz(0.3)
    np.testing.assert_allclose(system.transform(link, 5.0, [])[:3, :3], rz(0.3), atol=1e-15)
    # distinct coordinates of one joint each take their own
    model = rf.Model(gravity=None)
    ball = model.add_body("ball", model.ground, rf.Joint.spherical(), mass=1.0, inertia=(1, 1, 1))
    model.prescribe(ball, rf.motion.constant(0.1), coordinate="rz")
    model.prescribe(ball, rf.motion.constant(0.2), coordinate="rx")
    with pytest.raises(ValueError, match=r"^coordinate: .*'ball\.rz', prescribed already"):
        model.prescribe(ball, rf.motion.constant(0.1), coordinate="phi3")
    assert model.compile().prescribed_names == ["ball.rz", "ball.rx"]


def twins():
    """Two models alike in every name and index: only the model id tells their handles apart."""
    (ma, a), (mb, b) = arm(), arm()
    return ma, a, mb, b


def test_handles_of_another_model_are_refused_by_the_system():
    ma, a, mb, b = twins()
    system = ma.compile()
    q, qd = [0.4], [2.0]
    for handle in (b, b.origin, b.point((1.0, 0.0, 0.0))):
        with pytest.raises(ValueError, match=r"^point: expected a Point or Body of the model this system"):
            system.position(handle, 0.0, q)
        with pytest.raises(ValueError, match=r"^point: expected a Point or Body of the model this system"):
            system.velocity(handle, 0.0, q, qd)
    with pytest.raises(ValueError, match=r"^body: expected a Body of the model this system"):
        system.transform(b, 0.0, q)
    # the system's own handles, and handles of unknown origin (made by hand), are fine
    tip = a.point((1.0, 0.0, 0.0))
    np.testing.assert_allclose(system.position(tip, 0.0, q), rz(0.4) @ [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(system.position(rf.Point(0, np.array([1.0, 0.0, 0.0])), 0.0, q), rz(0.4) @ [1, 0, 0],
                               atol=1e-15)
    np.testing.assert_allclose(system.velocity(tip, 0.0, q, qd), 2.0 * rz(0.4) @ [0.0, 1.0, 0.0], atol=1e-15)
    # a second compile of the same model accepts the same handles
    np.testing.assert_allclose(ma.compile().position(tip, 0.0, q), system.position(tip, 0.0, q), atol=0)


def test_handles_of_another_model_are_refused_by_results_and_beams():
    ma, a, mb, b = twins()
    result = rf.simulate(ma.compile(), 0.1, method="rk4", dt=0.01, qd0=[1.0])
    with pytest.raises(ValueError, match=r"^point: expected a Point or Body of the model"):
        result.position(b.point((1.0, 0.0, 0.0)))
    with pytest.raises(ValueError, match=r"^frame: expected None or a Body of the model"):
        result.position(a.point((1.0, 0.0, 0.0)), frame=b)
    # reference: the arm turns at 1 rad/s (no gravity, no spring)
    np.testing.assert_allclose(result.position(a.point((1.0, 0.0, 0.0))),
                               [rz(t) @ [1.0, 0.0, 0.0] for t in result.t], atol=1e-12)
    np.testing.assert_allclose(result.position(a.point((1.0, 0.0, 0.0)), frame=a),
                               np.tile([1.0, 0.0, 0.0], (len(result.t), 1)), atol=1e-12)

    def with_beam():
        model = rf.Model(gravity=None)
        beam = model.add_beam("b", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                              rf.Section.rectangle(0.02, 0.005), 4, deform="bend_z")
        return model, beam

    (m1, beam1), (m2, beam2) = with_beam(), with_beam()
    s2 = m2.compile()
    with pytest.raises(ValueError, match=r"^system: expected a system compiled from the beam's model"):
        beam1.centerline(s2, np.zeros(s2.nq))


def test_handles_of_another_model_are_refused_by_the_model():
    ma, a, mb, b = twins()
    for call in (lambda: ma.add_force("push", b, (1.0, 0.0, 0.0)),
                 lambda: ma.add_force("push", b.point((1.0, 0.0, 0.0)), (1.0, 0.0, 0.0))):
        with pytest.raises(ValueError, match=r"^point: expected a Point or Body of this model"):
            call()
    with pytest.raises(ValueError, match=r"^parent: expected a body of this model"):
        ma.add_body("more", b, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    with pytest.raises(ValueError, match=r"^body: expected a body of this model"):
        ma.prescribe(b, rf.motion.constant(0.0))
    with pytest.raises(ValueError, match=r"^body: expected a body of this model"):
        ma.add_generalized_force(b, 1.0)
    assert ma.compile().np == 0 and ma.nbodies == 1
    # a handle made by hand (no model id) still names a body by index and name
    ma.add_force("load0", rf.Body(0, "arm"), (1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"^parent: expected a body of this model"):
        ma.add_body("more", rf.Body(0, "other name"), rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    assert ma.body("arm").model == ma.id != mb.id


def test_transform_takes_a_body_handle_or_its_index():
    model, link = arm()
    system = model.compile()
    T = np.eye(4)
    T[:3, :3] = rz(-1.1)
    np.testing.assert_allclose(system.transform(link, 0.0, [-1.1]), T, atol=1e-15)
    np.testing.assert_allclose(system.transform(link.index, 0.0, [-1.1]), T, atol=1e-15)
    np.testing.assert_allclose(system.transform(body=link, q=[-1.1], t=0.0), T, atol=1e-15)
    for bad, argument in ((model.ground, "body"), ("arm", "body"), (2.5, "body"), (7, "body")):
        with pytest.raises(ValueError, match=rf"^{argument}: expected"):
            system.transform(bad, 0.0, [0.0])
    with pytest.raises(ValueError, match=r"^q: expected"):
        system.transform(link, 0.0, [0.0, 1.0])


# --- b) poses at the time the drives say ------------------------------------------------------

def driven_arm():
    """The arm on a hub driven by θ(t) = 0.5 sin(2 t), free to turn about z on the hub."""
    model = rf.Model(gravity=None)
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    link = model.add_body("arm", hub, rf.Joint.revolute("z"), mass=1.0, inertia=(1e-4, 0.1, 0.1), com=(0.5, 0, 0))
    model.prescribe(hub, rf.motion.harmonic(amplitude=0.5, omega=2.0))
    return model, hub, link


def test_poses_need_t_when_drives_move_the_bodies():
    model, hub, link = driven_arm()
    system = model.compile()
    tip = link.point((1.0, 0.0, 0.0))
    q, qd = [0.2], [0.3]
    beam_model = rf.Model(gravity=None)
    hub2 = beam_model.add_body("hub", beam_model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    beam = beam_model.add_beam("b", hub2, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005),
                               3, deform="bend_z")
    beam_model.prescribe(hub2, rf.motion.harmonic(amplitude=0.5, omega=2.0))
    beam_system = beam_model.compile()
    # t comes first and has no default (version 0.1's order, t last or left out, is gone); centerline's t is a
    # keyword, required with drives
    with pytest.raises(TypeError):
        system.position(tip, q)
    with pytest.raises(ValueError, match=r"^t: expected a finite time in s, got \[0.2\]"):
        system.velocity(tip, q, qd, 0.0)
    required = r"^t: required because the system has prescribed coordinates \(hub\.rz\)"
    with pytest.raises(ValueError, match=required):
        beam.centerline(beam_system, np.zeros(beam_system.nq))
    t = 0.7
    theta, theta_d = 0.5 * math.sin(2 * t), math.cos(2 * t)  # the drive, and its rate 0.5 · 2 cos(2t)
    np.testing.assert_allclose(system.position(tip, t, q), rz(theta + 0.2) @ [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(system.velocity(tip, t, q, qd), (theta_d + 0.3) * rz(theta + 0.2) @ [0.0, 1.0, 0.0],
                               atol=1e-14)
    np.testing.assert_allclose(system.transform(link, t, q)[:3, :3], rz(theta + 0.2), atol=1e-15)
    line = beam.centerline(beam_system, np.zeros(beam_system.nq), t=t)
    s = np.concatenate([[0.0], (np.arange(1, 4) - 0.5) / 3, [1.0]])  # root, the 3 sde points, tip
    np.testing.assert_allclose(line, [rz(theta) @ [x, 0.0, 0.0] for x in s], atol=1e-15)


def test_a_state_first_call_is_refused_naming_t_or_the_vector():
    """Version 0.1's order (the state first, t last or left out) is gone: a call in it names t (a vector where t
    comes) or is a TypeError (an argument missing); in the order (t, q, qd) the compiled checks name the vector."""
    model, _ = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=3)
    system = model.compile()
    n = system.nq
    with pytest.raises(ValueError, match=r"^t: expected a finite time in s, got array"):
        system.kinetic_energy(np.zeros(n), np.zeros(n), 0.0)
    with pytest.raises(TypeError):
        system.kinetic_energy(np.full(n, -np.inf), np.zeros(n))
    with pytest.raises(ValueError, match=r"^q: expected \d+ \(nq\) finite values, got NaN or inf"):
        system.kinetic_energy(0.0, np.full(n, -np.inf), np.zeros(n))
    with pytest.raises(ValueError, match=r"^q: "):
        system.dissipated_power(0.0, np.zeros(n + 1), np.zeros(n))
    with pytest.raises(ValueError, match=r"^qd: "):
        system.kinetic_energy(0.0, np.zeros(n), np.zeros(n + 2))


def test_poses_default_to_t_0_without_drives():
    model, link = arm()
    system = model.compile()
    tip = link.point((1.0, 0.0, 0.0))
    np.testing.assert_allclose(system.position(tip, 0.0, [0.5]), rz(0.5) @ [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(system.velocity(tip, 0.0, [0.5], [-1.0]), -rz(0.5) @ [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(system.transform(link, 0.0, [0.5])[:3, :3], rz(0.5), atol=1e-15)


# --- c) force laws that return something else than a number -----------------------------------

@pytest.mark.parametrize("returned, shown", [
    (None, "None"), ("1.0", "'1.0'"), (np.zeros(2), r"an array of shape \(2,\)"),
    (np.array([1.0]), r"an array of shape \(1,\)"), ([1.0], r"\[1.0\]"), (NAN, "nan"), (INF, "inf"),
    (np.float64(-INF), "-inf"), (True, "True"), (np.bool_(False), r"(np\.)?False_?"), (1 + 2j, r"\(1\+2j\)"),
    (np.complex128(1.0), r"np.complex128\(1\+0j\)|\(1\+0j\)"),
])
def test_a_force_law_must_return_a_finite_number(returned, shown):
    def law(t, x, xd):
        return returned

    model, body = block()
    model.add_generalized_force(body, law)
    system = model.compile()
    expected = (r"^force: expected the force law '.*law' on coordinate 'block\.x' to return a finite number "
                rf"\(N or N·m\), got {shown} at t = 0\.25 s, q = 0\.1, qd = -0\.5")
    with pytest.raises(ValueError, match=expected) as info:
        system.forward_dynamics(0.25, [0.1], [-0.5])
    assert isinstance(info.value, rf.SimulationError) and info.value.time == 0.25
    for call in (lambda: system.generalized_forces(0.25, [0.1], [-0.5]), lambda: system.rhs(0.25, [0.1, -0.5])):
        with pytest.raises(ValueError, match=expected):
            call()


@pytest.mark.parametrize("returned", [3, np.float32(3.0), np.int64(3), np.array(3.0), fractions.Fraction(3, 1)])
def test_a_force_law_may_return_any_real_number(returned):
    model, body = block(mass=2.0, stiffness=50.0)
    model.add_generalized_force(body, lambda t, x, xd: returned)
    system = model.compile()
    assert system.forward_dynamics(0.0, [0.1], [0.0])[0] == pytest.approx((-50.0 * 0.1 + 3.0) / 2.0, rel=1e-14)


def test_a_force_law_must_be_a_number_or_a_function():
    model, body = block()
    for bad in ("1.0", None, [1.0, 2.0]):
        with pytest.raises(ValueError, match=r"^force: expected"):
            model.add_generalized_force(body, bad)
    assert model.compile().generalized_forces(0.0, [0.0], [0.0])[0] == 0.0


@pytest.mark.parametrize("method", ["rk4", "dopri5", "generalized_alpha", "implicit_spring"])
@pytest.mark.parametrize("returned", [NAN, None, "oops"])
def test_a_bad_force_law_stops_a_simulation_at_its_time(method, returned):
    t_bad = 0.05

    def law(t, x, xd):
        return returned if t >= t_bad else 0.0

    model, body = block(mass=2.0, stiffness=50.0)
    model.add_generalized_force(body, law)
    with pytest.raises(rf.SimulationError, match=r"^at t = 0\.05\d* s: the force law '.*law' on coordinate "
                                                 r"'block\.x' returned") as info:
        rf.simulate(model.compile(), 1.0, method=method, **step_of(method, 1e-3), q0=[0.01])
    error = info.value
    step = 1e-3 if method == "rk4" else 0.1  # dopri5 and the implicit methods adapt their step
    assert t_bad <= error.time < t_bad + step and "expected a finite number" in error.cause
    partial = error.result
    assert partial.t[-1] < t_bad and np.all(np.isfinite(partial.q))
    # the partial trajectory is the free oscillation x = 0.01 cos(5 t) (ω² = k / m = 25)
    np.testing.assert_allclose(partial.q[:, 0], 0.01 * np.cos(5.0 * partial.t), atol=1e-6)


def test_a_bad_force_law_in_a_scipy_run_names_the_time():
    model, body = block()
    model.add_generalized_force(body, lambda t, x, xd: NAN if t > 0.05 else 0.0)
    with pytest.raises(rf.SimulationError, match=r"at t = 0\.05\d* s, q = "):
        rf.simulate(model.compile(), 1.0, method="scipy:RK45", q0=[0.01], max_step=1e-3)


# --- d) long beams in O(m) --------------------------------------------------------------------

def long_beam(m, **kw):
    model = rf.Model(gravity=None)
    mat, sec = rf.Material(E=2.1e11, rho=7850.0, retardation=1e-4), rf.Section.rectangle(0.02, 0.005)
    beam = model.add_beam("b", model.ground, 2.0, mat, sec, m, **kw)
    return model, beam, mat, sec


def test_a_long_beam_has_the_closed_form_parameters():
    m, L = 20_000, 2.0
    model, beam, mat, sec = long_beam(m, deform=("bend_z", "torsion"))
    system = model.compile()
    d = L / m
    assert system.nq == 2 * m and len(beam.rfes) == m + 1 and len(beam.rfe) == m + 1 and len(beam.sde) == m
    assert system.coordinate_names[-2:] == [f"b.rfe{m}.rz", f"b.rfe{m}.rx"]
    masses = system.masses
    np.testing.assert_allclose(masses[1:-1], mat.rho * sec.A * d, rtol=1e-10)  # Δ = (i + ½)Δ − (i − ½)Δ: rounding
    assert masses[0] == pytest.approx(mat.rho * sec.A * d / 2, rel=1e-12)
    assert masses[-1] == pytest.approx(mat.rho * sec.A * d / 2, rel=1e-12)
    # coordinates in the book's order rz, rx: bending E Iz / Δ, torsion G J / Δ, dampers μ c
    c = np.tile([mat.E * sec.Iz / d, mat.G * sec.J / d], m)
    np.testing.assert_allclose(system.stiffness, c, rtol=1e-11)
    np.testing.assert_allclose(system.damping, 1e-4 * c, rtol=1e-11)
    # handles: by name, with this model's id, and the sequences of parameters read like lists
    assert model.body(f"b.rfe{m // 2}").index == m // 2 == beam.rfes[m // 2].index
    assert beam.rfes[-1].model == model.id and beam.rfes[-1].name == f"b.rfe{m}"
    assert beam.rfe[-1].mass == pytest.approx(mat.rho * sec.A * d / 2, rel=1e-12)
    assert beam.sde[-1].stiffness["bend_z"] == pytest.approx(mat.E * sec.Iz / d, rel=1e-11)
    assert [p.mass for p in beam.rfe[1:3]] == [beam.rfe[1].mass, beam.rfe[2].mass]
    with pytest.raises(IndexError):
        beam.rfe[m + 1]


@pytest.mark.parametrize("linear", [False, True])
def test_a_beam_that_fails_halfway_leaves_the_model_unchanged(linear):
    """E A / Δ overflows to inf: the sdes are refused after the root rfe was added."""
    model = rf.Model(gravity=None)
    model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    huge = rf.Material(E=1e308, rho=1000.0)
    with pytest.raises(ValueError, match=r"^stiffness: expected (a )?(finite )?non-negative"):
        model.add_beam("b", "hub", 1.0, huge, rf.Section(A=1.0, Iy=1.0, Iz=1.0, J=1.0), 10, formulation="classical",
                       deform=("axial",), linear=linear)
    assert model.body_names == ["hub"]
    beam = model.add_beam("b", "hub", 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(0.01), 10)
    assert model.body("b.rfe0").index == 1 and beam.rfes[-1].index == 11 == model.nbodies - 1


def test_a_batch_of_bodies_is_checked_before_any_is_added():
    model = rf.Model(gravity=None)
    n = 4
    args = dict(joint=rf.Joint.revolute("z"), stiffness=np.ones((n, 1)), damping=np.zeros((n, 1)),
                placements=np.tile(np.eye(4).ravel(), (n, 1)), masses=np.ones(n), coms=np.zeros((n, 3)),
                inertias=np.tile(np.eye(3).ravel(), (n, 1)))
    for names, parents, argument in ((["a", "b", "a", "c"], [-1, 0, 1, 2], "name"),
                                     (["a", "b", "c", "d"], [-1, 0, 3, 2], "parent")):
        with pytest.raises(ValueError, match=rf"^{argument}: expected"):
            model._add_bodies(names, parents, **args)
        assert model.nbodies == 0
    bodies = model._add_bodies(["a", "b", "c", "d"], [-1, 0, 1, 2], **args)
    assert [b.index for b in bodies] == [0, 1, 2, 3] and model.body("c").index == 2


# --- e) the centre line in one pass -------------------------------------------------------------

def test_centerline_is_every_point_in_one_pass():
    model, beam, _, _ = long_beam(300, deform="bend_z")
    system = model.compile()
    q = np.full(system.nq, 1e-3)
    one_by_one = np.array([system.position(p, 0.0, q) for p in beam.points()])
    np.testing.assert_allclose(beam.centerline(system, q), one_by_one, rtol=0, atol=1e-15)
    # undeformed: the straight line through root, sde points (i − ½)Δ and tip
    s = np.concatenate([[0.0], (np.arange(1, 301) - 0.5) * 2.0 / 300, [2.0]])
    np.testing.assert_allclose(beam.centerline(system, np.zeros(system.nq)), np.c_[s, 0 * s, 0 * s], atol=1e-15)
    assert beam.points() is not beam.points() and len(beam.points()) == 302  # copies of the kept handles


def test_every_builder_returns_a_handle_with_its_name():
    """Bodies, beams, elements, loads, loops, laws and coordinates: each builder's handle has .name, and the handles
    of named things are their names (str), so they serve where a name does; they pickle with what they are."""
    import inspect
    import pickle

    m = rf.Model()
    a = m.add_body("a", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1), com=(0.5, 0, 0))
    b = m.add_body("b", a, rf.Joint.prismatic("x"), mass=1.0, inertia=(1, 1, 1), placement=rf.transform((1, 0, 0)))
    beam = m.add_beam("strip", b, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005), 2,
                      deform="bend_z")
    base = m.add_moving_base("deck", {"heave": rf.motion.harmonic(0.1, 1.0)})
    made = {
        "add_body": a, "add_beam": beam, "add_moving_base": base,
        "add_spring_damper": m.add_spring_damper("k", m.ground.point((0, 1, 0)), b, stiffness=10.0, length=1.0),
        "add_cylinder": m.add_cylinder("element1", m.ground.point((0, 2, 0)), b, 5.0),
        "add_rope": m.add_rope("element2", base, beam.tip, EA=1e5, length=2.0),
        "add_force_element": m.add_force_element("element3", m.ground.point((0, 3, 0)), b, rf.laws.Buffer(stiffness=1.0)),
        "add_force": m.add_force("push", beam.tip, (0.0, -1.0, 0.0)),
        "add_torque": m.add_torque("load1", a, (0.0, 0.0, 1.0)),
        "add_loop_joint": m.add_loop_joint("loop0", "distance", m.ground.point((2, 0, 0)), b, length=1.5),
        "add_actuator": m.add_actuator("ram", m.ground.point((3, 0, 0)), b, 2.5),
        "add_joint_law": m.add_joint_law("a.rz.friction", a, rf.laws.Friction(coulomb=0.1)),
        "add_generalized_force": m.add_generalized_force(a, 0.5),
        "add_maxwell_arm": m.add_maxwell_arm(b, 10.0, 0.1),
        "prescribe": m.prescribe(beam.rfes[1], rf.motion.constant(0.0)),
        "add_shape": m.add_shape("ball", b, rf.shapes.Sphere(0.1)),
    }
    made["add_contact"] = m.add_contact("touch", made["add_shape"], m.add_shape("floor", m.ground, rf.shapes.HalfSpace()),
                                        rf.laws.Contact())
    over = m.add_rope("over", m.ground.point((0, 4, 0)), b, EA=1e5, length=2.0)
    made["add_sheave"] = m.add_sheave("sheave", made["add_rope"], over, mu=0.2, wrap=3.0)
    builders = {n for n, f in inspect.getmembers(rf.Model, inspect.isfunction) if n.startswith("add_") or n == "prescribe"}
    assert builders == set(made), builders ^ set(made)
    for builder, handle in made.items():
        assert isinstance(handle.name, str) and handle.name, builder
    assert (made["add_spring_damper"], made["add_force"], made["add_actuator"]) == ("k", "push", "ram")
    assert made["add_rope"].kind == "Rope" and made["add_loop_joint"].kind == "distance"
    assert (made["add_joint_law"], made["prescribe"], made["add_maxwell_arm"]) == ("a.rz.friction", "strip.rfe1.rz",
                                                                                    "b.x")
    s = m.compile()
    assert s.element_names.index(made["add_rope"]) == made["add_rope"].index == 2
    assert f"{made['add_spring_damper']}.stiffness" in s.parameters
    back = pickle.loads(pickle.dumps(made["add_loop_joint"]))
    assert (back, type(back), back.kind, back.index) == ("loop0", type(made["add_loop_joint"]), "distance", 0)
