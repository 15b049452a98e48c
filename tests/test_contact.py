"""Compliant contact between shapes on bodies (rigidfem.shapes, Model.add_contact, rigidfem.laws.Contact): the
restitution against the Hunt–Crossley law's own invariant, Hertz's static penetration, a block sliding to rest by
Coulomb friction, energy, the analytic Jacobians against central differences and the reverse mode against them,
both engines, and bad input."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import beta

import rigidfem as rf
from conftest import central_jacobians
from test_derivatives import check_both_modes


def drop(law, gravity=0.0, radius=0.1, mass=2.0):
    """A ball on a vertical slide (prismatic z) above the ground z = 0: q is its centre's height above z = radius."""
    model = rf.Model(gravity=(0.0, 0.0, -gravity))
    ball = model.add_body("ball", model.ground, rf.Joint.prismatic("z"), mass, (0.01, 0.01, 0.01),
                          placement=rf.transform((0.0, 0.0, radius)))
    model.add_contact("bounce", model.add_shape("s", ball, rf.shapes.Sphere(radius)),
                      model.add_shape("floor", model.ground, rf.shapes.HalfSpace()), law)
    return model.compile()


def rebound(e: float, v_e: float, v_in: float) -> float:
    """The speed a free Hunt–Crossley impact F = k δᵖ (1 + α δ̇) leaves at, from its invariant v − ln(1 + α v)/α,
    with α from e at v_e: solved here by brentq, independently of the core's bisection."""
    u_e = brentq(lambda u: math.log1p(u) - math.log1p(-e * u) - u * (1 + e), 1e-9, (1 - 1e-15) / e)
    alpha = u_e / v_e
    g = lambda v: v - math.log1p(alpha * v) / alpha  # noqa: E731
    return brentq(lambda w: g(-w) - g(v_in), 1e-12, (1 - 1e-15) / alpha)


@pytest.mark.parametrize("exponent", [1.0, 1.5])
@pytest.mark.parametrize("v_in", [2.0, 0.5, 5.0])
def test_an_impact_leaves_with_the_restitution_of_hunt_crossleys_law(exponent, v_in):
    """At the impact speed v_e the ball leaves at e v_e, whatever k and p; slower or faster, as the law's invariant
    says (independent of the exponent and the stiffness)."""
    law = rf.laws.Contact(stiffness=1e6, exponent=exponent, restitution=0.7, impact_speed=2.0)
    r = rf.simulate(drop(law), 0.05, q0=[1e-3], qd0=[-v_in], method="dopri5", rtol=1e-11, atol=1e-13)
    assert r.q[-1, 0] > 0.0  # left the ground
    assert r.qd[-1, 0] == pytest.approx(rebound(0.7, 2.0, v_in), rel=1e-8)
    if v_in == 2.0:
        assert r.qd[-1, 0] == pytest.approx(0.7 * 2.0, rel=1e-8)


def test_an_elastic_impact_keeps_the_energy_and_a_damped_one_loses_what_it_dissipates():
    """e = 1: kinetic + contact energy constant through the impact; e < 1: the loss equals ∫ P dt."""
    for e in (1.0, 0.6):
        s = drop(rf.laws.Contact(stiffness=2e5, exponent=1.5, restitution=e, impact_speed=1.0), gravity=9.81)
        r = rf.simulate(s, 0.4, q0=[0.05], qd0=[-1.0], method="dopri5", rtol=1e-11, atol=1e-13,
                        t_eval=np.linspace(0.0, 0.4, 16001))
        E, P = r.energy, r.dissipated_power
        assert E[0] == pytest.approx(0.5 * 2.0 * 1.0 ** 2 + 2.0 * 9.81 * (0.1 + 0.05))
        lost = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(r.t))])
        assert np.abs(E + lost - E[0]).max() < 2e-6 * E[0]
        assert (lost[-1] > 0.1 * E[0]) == (e < 1.0)


@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_a_resting_ball_sinks_to_hertzs_penetration(exponent):
    """Statics: k δᵖ = m g."""
    k, m, g = 3e5, 2.0, 9.81
    s = drop(rf.laws.Contact(stiffness=k, exponent=exponent), gravity=g, mass=m)
    eq = rf.static_equilibrium(s, q0=[-1e-3])
    assert -eq.q[0] == pytest.approx((m * g / k) ** (1.0 / exponent), rel=1e-9)


def sliding_block(mu, v0, smoothing=1e-5):
    """A box on the ground (x slides, z falls), its corners touching; released at rest vertically."""
    model = rf.Model()
    block = model.add_body("block", model.ground, rf.Joint.planar("xz") if hasattr(rf.Joint, "planar") else None,
                           1.0, (0.01, 0.01, 0.01))
    return model, block


def test_a_sliding_box_stops_where_coulomb_friction_says():
    """A box sliding at v0 on the ground with μ stops after v0²/(2 μ g) (its four lower corners share the weight;
    the regularised friction creeps at ~v_ε, a distance of order v_ε t)."""
    mu, v0, g = 0.4, 2.0, 9.81
    model = rf.Model(gravity=(0.0, 0.0, -g))
    block = model.add_body("block", model.ground, rf.Joint.cylindrical("x") if False else rf.Joint.free(), 1.0,
                           (0.01, 0.01, 0.01))
    box = model.add_shape("box", block, rf.shapes.Box((0.1, 0.1, 0.05)))
    floor = model.add_shape("floor", model.ground, rf.shapes.HalfSpace())
    law = rf.laws.Contact(stiffness=1e7, exponent=1.0, restitution=0.2, impact_speed=0.1, mu_s=mu, mu_k=mu,
                          smoothing=1e-5)
    model.add_contact("on ground", box, floor, law)
    s = model.compile()
    names = s.coordinate_names
    q0 = np.zeros(s.nq)
    q0[names.index("block.z")] = 0.05 - 9.81 / 4e7  # at rest on its four corners, each k δ = m g/4
    qd0 = np.zeros(s.nq)
    qd0[names.index("block.x")] = v0
    t_stop = v0 / (mu * g)
    r = rf.simulate(s, 1.5 * t_stop, q0=q0, qd0=qd0, method="radau5", rtol=1e-8, atol=1e-10)
    x = r.q[:, names.index("block.x")]
    assert x[-1] == pytest.approx(v0 ** 2 / (2 * mu * g), rel=1e-3)
    assert abs(r.qd[-1, names.index("block.x")]) < 1e-3


def contact_scene(algorithm="recursive", friction=True):
    """A 3D chain with every pair the core knows, overlapping at q = 0: a capsule (b), a sphere (c) and a box (d)
    against the ground and against a deck on body a; the capsule against the sphere."""
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    a = model.add_body("a", model.ground, rf.Joint.spherical(), 2.0, (0.1, 0.2, 0.15), com=(0.4, 0.0, 0.0))
    b = model.add_body("b", a, rf.Joint.universal(("y", "z")), 1.5, (0.05, 0.08, 0.07), com=(0.3, 0.1, 0.0),
                       placement=rf.transform(translation=(0.8, 0.0, 0.0)))
    c = model.add_body("c", a, rf.Joint.prismatic("y"), 0.7, (0.02, 0.03, 0.04), com=(0.0, 0.0, 0.1),
                       placement=rf.transform(translation=(0.2, 0.0, -0.1)))
    d = model.add_body("d", b, rf.Joint.revolute("x"), 0.9, (0.03, 0.02, 0.05), com=(0.0, 0.2, 0.0),
                       placement=rf.transform(translation=(0.6, 0.0, 0.0)))
    rod = model.add_shape("rod", b, rf.shapes.Capsule(0.15, (0.0, 0.0, 0.0), (0.5, 0.1, 0.0)))
    ball = model.add_shape("ball", c, rf.shapes.Sphere(0.2, (0.7, 0.05, 0.05)))
    brick = model.add_shape("brick", d, rf.shapes.Box((0.2, 0.1, 0.15), (0.1, 0.0, 0.0), rf.euler_zyx(0.3, 0.2, 0.1)))
    floor = model.add_shape("floor", model.ground, rf.shapes.HalfSpace((0.1, 0.0, 1.0) / np.linalg.norm((0.1, 0.0, 1.0)),
                                                                      (0.0, 0.0, -0.1)))
    deck = model.add_shape("deck", a, rf.shapes.HalfSpace((0.0, 0.0, 1.0), (0.0, 0.0, -0.2)))
    mu = dict(mu_s=0.6, mu_k=0.4, stribeck=0.3, smoothing=0.05) if friction else {}
    law = rf.laws.Contact(stiffness=1e4, exponent=1.5, restitution=0.5, impact_speed=1.0, **mu)
    model.add_contact("on ground", [rod, ball, brick], floor, law)
    model.add_contact("on deck", deck, [rod, brick], law)
    model.add_contact("rod and ball", rod, ball, rf.laws.Contact(stiffness=5e3, exponent=1.0, **mu))
    return model.compile(algorithm)


def states_in_contact(s, rng, n):
    """n random states with overlaps of every contact and slip."""
    found = 0
    while found < n:
        t, q, qd = 0.3, rng.uniform(-0.25, 0.25, s.nq), rng.uniform(-1.5, 1.5, s.nq)
        touching = {c["contact"] for c in s.contact_states(t, q, qd) if c["normal_force"] > 0}
        if touching == set(s.contact_names):
            found += 1
            yield t, q, qd


@pytest.mark.parametrize("friction", [False, True])
def test_the_contacts_jacobians_are_exact_and_both_engines_agree(friction):
    """The recursive engine's analytic ∂f/∂q and ∂f/∂q̇ (automatic derivatives of the kernels, the contact point
    sliding on both bodies, the deck's plane turning with its body) against central differences; the Lagrange
    engine's forces and accelerations equal the recursive one's."""
    rec, lag = contact_scene("recursive", friction), contact_scene("lagrange", friction)
    rng = np.random.default_rng(3)
    for t, q, qd in states_in_contact(rec, rng, 3):
        Kq, Kqd = rec.force_jacobians(t, q, qd)
        Fq, Fqd = central_jacobians(rec, t, q, qd, h=1e-7)
        assert np.abs(Kq - Fq).max() < 2e-6 * np.abs(Fq).max()
        assert np.abs(Kqd - Fqd).max() < 2e-6 * np.abs(Fqd).max()
        np.testing.assert_allclose(lag.generalized_forces(t, q, qd), rec.generalized_forces(t, q, qd), rtol=1e-11,
                                   atol=1e-9)
        np.testing.assert_allclose(lag.forward_dynamics(t, q, qd), rec.forward_dynamics(t, q, qd), rtol=1e-9,
                                   atol=1e-9)


def test_both_modes_of_the_rnea_with_contacts():
    """Forward (a direction) and reverse (a vector-Jacobian product) modes equal the analytic matrices."""
    rng = np.random.default_rng(5)
    s = contact_scene()
    for _ in range(4):
        check_both_modes(s, rng, 0.25)


def test_contact_states_name_each_overlap_and_a_scene_without_contacts_has_none():
    s = contact_scene()
    states = s.contact_states(0.0, np.zeros(s.nq), np.zeros(s.nq))
    assert {c["contact"] for c in states} <= set(s.contact_names) and states
    for c in states:
        assert c["gap"] < 0 and np.linalg.norm(c["normal"]) == pytest.approx(1.0)
        assert np.dot(c["force"], c["normal"]) == pytest.approx(c["normal_force"])
    model = rf.Model()
    model.add_body("b", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    assert model.compile().contact_states(0.0, [0.0], [0.0]) == [] and model.compile().contact_names == []


def test_restitution_one_is_elastic_and_the_law_is_judged():
    law = rf.laws.Contact(restitution=1.0)
    assert law.values["restitution"] == 1.0
    for kwargs, name in ((dict(restitution=1.5), "restitution"), (dict(restitution=0.0), "restitution"),
                         (dict(stiffness=-1.0), "stiffness"), (dict(exponent=0.5), "exponent"),
                         (dict(mu_k=-0.1), "mu_k"), (dict(smoothing=0.0), "smoothing")):
        with pytest.raises(ValueError, match=f"^{name}: expected"):
            drop(rf.laws.Contact(**kwargs))


def test_bad_shapes_and_contacts_are_refused_by_name():
    model = rf.Model()
    b = model.add_body("b", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    c = model.add_body("c", b, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    for call, name in ((lambda: rf.shapes.Sphere("big"), "radius"), (lambda: rf.shapes.Capsule(0.1, (0, 0)), "a"),
                       (lambda: model.add_shape("s", b, rf.shapes.Sphere(-1.0)), "radius"),
                       (lambda: model.add_shape("s", b, rf.shapes.Sphere(0.0)), "radius"),
                       (lambda: model.add_shape("s", b, rf.shapes.HalfSpace((0, 0, 2))), "normal"),
                       (lambda: model.add_shape("s", b, rf.shapes.Box((0.1, -0.1, 0.1))), "half_extents"),
                       (lambda: model.add_shape("s", b, rf.shapes.Box((0.1, 0.1, 0.1), rotation=2 * np.eye(3))),
                        "rotation"),
                       (lambda: model.add_shape("s", b, "sphere"), "shape"),
                       (lambda: model.add_shape("s", b, rf.shapes.Capsules()), "body"),
                       (lambda: model.add_shape("b", b, rf.shapes.Sphere(0.1)), "name")):
        with pytest.raises(ValueError, match=f"^{name}: expected"):
            call()
    s1 = model.add_shape("s1", b, rf.shapes.Sphere(0.1))
    s2 = model.add_shape("s2", c, rf.shapes.Box((0.1, 0.1, 0.1)))
    h1 = model.add_shape("h1", model.ground, rf.shapes.HalfSpace())
    h2 = model.add_shape("h2", c, rf.shapes.HalfSpace())
    s3 = model.add_shape("s3", b, rf.shapes.Sphere(0.2))
    law = rf.laws.Contact()
    for call, name in ((lambda: model.add_contact("k", s1, s2, law), "b"),      # a box against a sphere
                       (lambda: model.add_contact("k", h1, h2, law), "b"),      # two half-spaces
                       (lambda: model.add_contact("k", s1, s3, law), "b"),      # one body
                       (lambda: model.add_contact("k", s1, "h1", law), "b"),
                       (lambda: model.add_contact("k", [], h1, law), "a"),
                       (lambda: model.add_contact("k", s1, h1, rf.laws.Rope(EA=1.0)), "law"),
                       (lambda: model.add_contact("s1", s1, h1, law), "name")):
        with pytest.raises(ValueError, match=f"^{name}: expected"):
            call()
    assert model.add_contact("k", [s1, s2], h1, law).name == "k"


def test_a_beams_capsules_land_on_the_ground_one_per_rfe():
    """Capsules() puts one capsule on each rfe, of the section's radius: a round steel rod lying on the ground at the
    height of its radius carries its weight on its rfes' contacts."""
    d, L, m = 0.02, 1.0, 10
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    rod = model.add_beam("rod", model.ground, L, rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(d), m,
                         joint=rf.Joint.prismatic("z"), placement=rf.transform((0.0, 0.0, d / 2)))
    caps = model.add_shape("rod capsules", rod, rf.shapes.Capsules())
    assert len(caps.shapes) == m + 1
    model.add_contact("on ground", caps, model.add_shape("floor", model.ground, rf.shapes.HalfSpace()),
                      rf.laws.Contact(stiffness=1e7, exponent=1.0))
    s = model.compile()
    eq = rf.static_equilibrium(s, q0=np.zeros(s.nq))
    states = s.contact_states(0.0, eq.q, np.zeros(s.nq))
    weight = 7850.0 * math.pi * d ** 2 / 4 * L * 9.81
    assert sum(c["normal_force"] for c in states) == pytest.approx(weight, rel=1e-6)
    assert all(c["gap"] > -1e-4 for c in states)  # the radius is the rod's: it sinks by k δ = w/n only


def test_the_adjoint_gradient_through_a_bounce_with_friction_agrees_with_differences_of_runs():
    """A ball thrown onto the ground, bouncing and sliding under friction: dJ/dp of J = x + z at the end, by the
    adjoint (its reverse mode through the contact's automatic derivatives), against central differences of whole
    runs of the same fixed-step method."""
    model = rf.Model()
    ball = model.add_body("ball", model.ground, rf.Joint.free(), 2.0, (0.01, 0.01, 0.01),
                          placement=rf.transform((0.0, 0.0, 0.1)))
    model.add_contact("bounce", model.add_shape("s", ball, rf.shapes.Sphere(0.1)),
                      model.add_shape("floor", model.ground, rf.shapes.HalfSpace()),
                      rf.laws.Contact(stiffness=1e5, restitution=0.7, mu_s=0.5, mu_k=0.4, smoothing=1e-2))
    s = model.compile()
    names = s.coordinate_names
    q0, qd0 = np.zeros(s.nq), np.zeros(s.nq)
    q0[names.index("ball.z")], qd0[names.index("ball.x")], qd0[names.index("ball.z")] = 0.05, 1.0, -1.0
    run = dict(dt=2e-4, q0=q0)
    g = rf.gradient(s, 0.3, ["ball.mass", "qd0[ball.x]"], outputs={"p": ball}, terminal=lambda y: y["p"][0] + y["p"][2],
                    qd0=qd0, **run)

    def J(mass, vx):
        changed = s.with_parameters({"ball.mass": mass})
        start = qd0.copy()
        start[names.index("ball.x")] = vx
        r = rf.simulate(changed, 0.3, qd0=start, method="generalized_alpha", t_eval=[0.3], **run)
        p = changed.position(ball, 0.3, r.q[-1])
        return p[0] + p[2]

    h = 1e-5
    assert g.gradient["ball.mass"] == pytest.approx((J(2.0 + h, 1.0) - J(2.0 - h, 1.0)) / (2 * h), rel=1e-5)
    assert g.gradient["qd0[ball.x]"] == pytest.approx((J(2.0, 1.0 + h) - J(2.0, 1.0 - h)) / (2 * h), rel=1e-6)


def test_a_contacts_stiffness_and_friction_are_named_parameters_with_gradients():
    """The law's k, e, μ_s and μ_k are named parameters ("<contact>.stiffness", ...): set by with_parameters like any
    other, and the adjoint's gradient by them agrees with central differences of whole runs."""
    model = rf.Model()
    box = model.add_body("box", model.ground, rf.Joint.free(), 1.0, (0.01, 0.01, 0.01),
                         placement=rf.transform((0.0, 0.0, 0.05)))
    model.add_contact("slide", model.add_shape("brick", box, rf.shapes.Box((0.1, 0.1, 0.05))),
                      model.add_shape("floor", model.ground, rf.shapes.HalfSpace()),
                      rf.laws.Contact(stiffness=1e6, exponent=1.0, restitution=0.5, impact_speed=0.5, mu_s=0.5,
                                      mu_k=0.3, smoothing=1e-2))
    s = model.compile()
    assert [p for p in s.parameters if p.startswith("slide.")] == ["slide.stiffness", "slide.restitution", "slide.mu_s",
                                                                     "slide.mu_k"]
    assert not s.parameters["slide.restitution"].linear  # differenced centrally (its α is a root of e's relation)
    assert s.parameters["slide.mu_k"].value == 0.3 and s.parameters["slide.stiffness"].unit == "N/m^p"
    names = s.coordinate_names
    q0, qd0 = np.zeros(s.nq), np.zeros(s.nq)
    q0[names.index("box.z")], qd0[names.index("box.x")] = -9.81 / 4e6, 1.0  # on its corners, sliding
    run = dict(dt=2e-4, q0=q0, qd0=qd0, newton_tol=1e-13)
    picked = ["slide.stiffness", "slide.restitution", "slide.mu_s", "slide.mu_k"]
    g = rf.gradient(s, 0.5, picked, outputs={"p": box}, terminal=lambda y: y["p"][0] + 10.0 * y["p"][2], **run)

    def J(**values):
        changed = s.with_parameters(values)
        r = rf.simulate(changed, 0.5, method="generalized_alpha", t_eval=[0.5], **run)
        p = changed.position(box, 0.5, r.q[-1])
        return p[0] + 10.0 * p[2]

    for name, value in zip(picked, (1e6, 0.5, 0.5, 0.3)):
        h = 1e-3 * value
        fd = (J(**{name: value + h}) - J(**{name: value - h})) / (2 * h)
        assert g.gradient[name] == pytest.approx(fd, rel=1e-4), name


def test_the_adjoint_gradient_by_a_contacts_stiffness_and_restitution_through_a_bounce():
    """A ball dropped on the ground at 1 m/s bounces once (Hunt–Crossley, k = 1e5 N/m^1.5, e = 0.7): the adjoint's
    dz/dk and dz/de at 0.25 s, after the bounce, against central differences of whole runs of the same fixed-step
    method (1e-6; measured 2e-9 and 3e-8 at steps of 1e-5 k and 1e-6 e)."""
    model = rf.Model()
    ball = model.add_body("ball", model.ground, rf.Joint.prismatic("z"), 2.0, (0.01, 0.01, 0.01),
                          placement=rf.transform((0.0, 0.0, 0.1)))
    model.add_contact("bounce", model.add_shape("s", ball, rf.shapes.Sphere(0.1)),
                      model.add_shape("floor", model.ground, rf.shapes.HalfSpace()),
                      rf.laws.Contact(stiffness=1e5, restitution=0.7))
    s = model.compile()
    run = dict(dt=1e-4, q0=[0.05], qd0=[-1.0], newton_tol=1e-13)
    g = rf.gradient(s, 0.25, ["bounce.stiffness", "bounce.restitution"], outputs={"z": "ball.z"},
                    terminal=lambda y: y["z"], **run)

    def z(**values):
        return rf.simulate(s.with_parameters(values), 0.25, method="generalized_alpha", t_eval=[0.25], **run).q[-1, 0]

    for name, value, step in (("bounce.stiffness", 1e5, 1e-5), ("bounce.restitution", 0.7, 1e-6)):
        h = step * value
        fd = (z(**{name: value + h}) - z(**{name: value - h})) / (2 * h)
        assert g.gradient[name] == pytest.approx(fd, rel=1e-6), name
    assert g.gradient["bounce.restitution"] > 0.1  # a livelier ball is higher after its bounce


def crossing_rods(per_capsule: bool):
    """Two round rods of 20 rfes crossing each other, their capsules in contact: one contact between the two groups
    (sweep and prune: 21 × 21 pairs), or one contact per capsule of the first (each 1 × 21, tested pair by pair)."""
    model = rf.Model()
    steel, rod = rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(0.02)
    one = model.add_beam("one", model.ground, 1.0, steel, rod, 20, joint=rf.Joint.spherical(),
                         placement=rf.transform((0.0, 0.0, 0.0)))
    two = model.add_beam("two", model.ground, 1.0, steel, rod, 20, joint=rf.Joint.spherical(),
                         placement=rf.transform((0.5, -0.5, 0.015), euler_zyx=(np.pi / 2, 0.0, 0.0)))
    a = model.add_shape("one's", one, rf.shapes.Capsules())
    b = model.add_shape("two's", two, rf.shapes.Capsules())
    law = rf.laws.Contact(stiffness=1e7, exponent=1.0, mu_s=0.3, mu_k=0.2)
    if per_capsule:
        for k, index in enumerate(a.shapes):
            single = rf.model.handles.Shape(f"one's[{k}]", "capsule", [index])
            model.add_contact(f"touch {k}", single, b, law)
    else:
        model.add_contact("touch", a, b, law)
    return model.compile()


def test_two_groups_meet_by_sweep_and_prune_as_pair_by_pair():
    """The forces of one contact between two crossing rods' 21 capsules each (sweep and prune) equal those of 21
    contacts tested pair by pair, at states where the rods bend and slide over each other."""
    swept, paired = crossing_rods(False), crossing_rods(True)
    rng = np.random.default_rng(11)
    touched = 0
    for _ in range(5):
        q, qd = rng.normal(0.0, 0.02, swept.nq), rng.normal(0.0, 0.5, swept.nq)
        touched += len(swept.contact_states(0.0, q, qd))
        assert len(swept.contact_states(0.0, q, qd)) == len(paired.contact_states(0.0, q, qd))
        np.testing.assert_allclose(swept.generalized_forces(0.0, q, qd), paired.generalized_forces(0.0, q, qd),
                                   rtol=1e-12, atol=1e-9)
    assert touched >= 5


def test_a_box_on_a_heaving_deck_follows_it_and_is_pushed_by_its_acceleration():
    """A box resting on a deck (a half-space on a moving base) that heaves as a sin ωt with a ω² < g: it stays on the
    deck (every corner touching), and the deck pushes it with m (g + z̈_deck) (1e-3 of mg, the contact's own
    oscillation aside)."""
    a, omega, m, g = 0.05, 2.0 * np.pi, 3.0, 9.81
    model = rf.Model()
    deck = model.add_moving_base("deck", {"heave": rf.motion.harmonic(a, omega)})
    box = model.add_body("box", model.ground, rf.Joint.free(), m, (0.05, 0.05, 0.05),
                         placement=rf.transform((0.0, 0.0, 0.1)))
    k = 1e7
    law = rf.laws.Contact(stiffness=k, exponent=1.0, restitution=0.3, impact_speed=0.1, mu_s=0.5, mu_k=0.5,
                          smoothing=1e-4)
    model.add_contact("on deck", model.add_shape("brick", box, rf.shapes.Box((0.2, 0.2, 0.1))),
                      model.add_shape("deck plane", deck, rf.shapes.HalfSpace()), law)
    s = model.compile()
    q0 = np.zeros(s.nq)
    q0[s.coordinate_names.index("box.z")] = -m * g / k  # at rest on its four lower corners
    t = np.linspace(0.5, 2.0, 61)
    r = rf.simulate(s, 2.0, q0=q0, t_eval=t, method="radau5", rtol=1e-9, atol=1e-11)
    for tk, q, qd in zip(r.t, r.q, r.qd):
        states = s.contact_states(tk, q, qd)
        assert len(states) == 4
        push = sum(c["force"][2] for c in states)
        assert push == pytest.approx(m * (g - a * omega ** 2 * np.sin(omega * tk)), abs=1e-3 * m * g)


def test_hertzs_impact_lasts_and_peaks_as_the_closed_form_says():
    """An elastic Hertz impact (p = 3/2, e = 1) of a ball at v: δ_max = (5 m v²/(4 k))^(2/5), the peak force
    k δ_max^(3/2) and the duration 2 (δ_max/v) ∫₀¹ (1 − x^(5/2))^(−1/2) dx = (4/5) B(2/5, 1/2) δ_max/v. The
    onset and separation are the contact's own events; the deepest point an event of the rate."""
    k, mass, v = 1e6, 2.0, 1.5
    system = drop(rf.laws.Contact(stiffness=k, exponent=1.5, restitution=1.0), mass=mass)
    deepest = rf.Event("deepest", "ball.z", rate=True, direction=1)
    r = rf.simulate(system, 0.05, "dopri5", q0=[1e-3], qd0=[-v], rtol=1e-12, atol=1e-14, events=[deepest])
    delta_max = (5.0 * mass * v ** 2 / (4.0 * k)) ** 0.4
    onset, separation = r.event_times("bounce")
    assert separation - onset == pytest.approx(0.8 * beta(0.4, 0.5) * delta_max / v, rel=1e-9)
    (bottom,) = [f for f in r.events if f.event == "deepest"]
    assert -bottom.q[0] == pytest.approx(delta_max, rel=1e-9)
    states = system.contact_states(bottom.t, bottom.q, bottom.qd)
    assert states[0]["normal_force"] == pytest.approx(k * delta_max ** 1.5, rel=1e-8)
    assert r.qd[-1, 0] == pytest.approx(v, rel=1e-9)  # elastic: it leaves as it came


@pytest.mark.parametrize("v_in", [0.01, 0.1, 1.0, 10.0])
@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_the_restitution_holds_over_impact_speeds_from_a_centimetre_to_ten_metres_per_second(exponent, v_in):
    """The speed at separation (the contact's event, terminal) against the law's invariant at every impact speed
    in 0.01–10 m/s, and e v_e at the impact speed the restitution was set at."""
    left = rf.Event("left", "bounce", direction=1, terminal=True)
    for e_at, v in ((v_in, v_in), (1.0, v_in)):
        law = rf.laws.Contact(stiffness=1e6, exponent=exponent, restitution=0.6, impact_speed=e_at)
        r = rf.simulate(drop(law), 10.0, "dopri5", q0=[1e-6], qd0=[-v], rtol=1e-11, atol=1e-15, events=[left])
        assert r.events[-1].event == "left"
        assert r.events[-1].qd[0] == pytest.approx(rebound(0.6, e_at, v), rel=1e-7)


G, MU_S, MU_K, V_EPS, V_S = 9.81, 0.5, 0.3, 1e-5, 0.01


def block_on_incline(ratio):
    """A block (a sphere that cannot turn: joint x, z) on a plane tilted by α, tan α = ratio μ_s (gravity turned),
    resting on it: (system, q0, α)."""
    alpha = math.atan(ratio * MU_S)
    model = rf.Model(gravity=(G * math.sin(alpha), 0.0, -G * math.cos(alpha)))
    block = model.add_body("block", model.ground, rf.Joint.custom(["x", "z"]), 1.0, (0.01, 0.01, 0.01),
                           placement=rf.transform((0.0, 0.0, 0.05)))
    k = 1e6
    model.add_contact("on slope", model.add_shape("s", block, rf.shapes.Sphere(0.05)),
                      model.add_shape("slope", model.ground, rf.shapes.HalfSpace()),
                      rf.laws.Contact(stiffness=k, exponent=1.0, restitution=0.2, impact_speed=0.1, mu_s=MU_S,
                                      mu_k=MU_K, stribeck=V_S, smoothing=V_EPS))
    settled = -G * math.cos(alpha) / k  # resting on the slope: k δ = m g cos α
    return model.compile(), [0.0, settled], alpha


def creep_speed(alpha):
    """The regularised law's creep: μ(v) tanh(v/v_ε) = tan α (m/s)."""
    mu = lambda u: MU_K + (MU_S - MU_K) * math.exp(-(u / V_S) ** 2)  # noqa: E731
    return brentq(lambda u: mu(u) * math.tanh(u / V_EPS) - math.tan(alpha), 0.0, 10 * V_EPS)


@pytest.mark.parametrize("ratio", [0.9, 1.1])
def test_a_block_on_an_incline_holds_below_mu_s_and_slides_above_at_the_kinetic_rate(ratio):
    """A block on a plane tilted by α: at tan α = 0.9 μ_s it creeps at the regularised law's v with
    μ(v) tanh(v/v_ε) = tan α (micro-metres per second: it holds); at tan α = 1.1 μ_s it slides, accelerating at
    g (sin α − μ_k cos α) once v ≫ v_S."""
    s, q0, alpha = block_on_incline(ratio)
    r = rf.simulate(s, 2.0, "radau5", q0=q0, rtol=1e-10, atol=1e-13, t_eval=[1.0, 1.5, 2.0])
    v = r.qd[:, 0]
    if ratio < 1.0:
        assert v[-1] == pytest.approx(creep_speed(alpha), rel=1e-6)
        assert r.q[-1, 0] < 1e-4
    else:
        assert v[1] > 10 * V_S
        assert (v[2] - v[1]) / 0.5 == pytest.approx(G * (math.sin(alpha) - MU_K * math.cos(alpha)), rel=1e-6)


@pytest.mark.parametrize("rtol", [1e-8, 1e-9, 1e-10, 1e-11])
def test_a_creeping_block_is_not_held_to_tiny_steps_by_its_starting_tangent(rtol):
    """The tangent taken at rest has the friction's slope at v = 0, five times its slope at the creep speed; radau5's
    error estimate is filtered through it, and Newton converges at once at small steps, so only the tangent's age
    renews it. Kept, it held 2 s of creep to 43,000-121,000 steps at rtol 1e-8 to 1e-11; renewed every 100 steps,
    each run takes under 300 and creeps at the law's speed."""
    s, q0, alpha = block_on_incline(0.9)
    r = rf.simulate(s, 2.0, "radau5", q0=q0, rtol=rtol, atol=1e-3 * rtol, t_eval=[2.0])
    assert r.stats["steps"] < 300, r.stats
    assert r.qd[-1, 0] == pytest.approx(creep_speed(alpha), rel=1e-6)


def test_st_venants_rod_strikes_a_wall_for_2l_over_c_and_leaves_at_its_speed():
    """A free steel rod (axial sdes) at v0 against a rigid wall (a contact of stiffness 0.5 m EA/L, elastic): St-Venant's
    contact lasts 2L/c (c = √(E/ρ)) and the rod leaves at −v0. The duration, from the contact's onset to its
    separation (events), converges to 2L/c at first order in m; the rebound of the centre of mass is within 0.3 % of
    v0 (what stays behind is the discrete rod's vibration)."""
    E, rho, d, L, v0 = 2.1e11, 7850.0, 0.02, 1.0, 1.0
    EA, T = E * math.pi * d * d / 4, 2 * L / math.sqrt(E / rho)
    errors = []
    for m in (8, 16, 32, 64):
        model = rf.Model(gravity=(0.0, 0.0, 0.0))
        rod = model.add_beam("rod", model.ground, L, rf.Material(E=E, rho=rho), rf.Section.circle(d), m,
                             formulation="classical", deform=["axial"], joint=rf.Joint.prismatic("x"))
        wall = rf.shapes.HalfSpace(normal=(-1.0, 0.0, 0.0), point=(L + d / 2 + 1e-6, 0.0, 0.0))
        model.add_contact("hit", model.add_shape("caps", rod, rf.shapes.Capsules()),
                          model.add_shape("wall", model.ground, wall),
                          rf.laws.Contact(stiffness=0.5 * m * EA / L, exponent=1.0, restitution=1.0))
        s = model.compile()
        qd0 = np.zeros(s.nq)
        qd0[0] = v0
        r = rf.simulate(s, 2 * T, "auto", qd0=qd0, rtol=1e-9, atol=1e-13, t_eval=[1.8 * T, 2 * T])
        onset, separation = r.event_times("hit")
        errors.append(abs((separation - onset) / T - 1.0))
        x = np.array([[r.position(body)[k, 0] for body in rod.rfes] for k in range(2)])
        masses = np.array(s.masses)
        assert masses @ (x[1] - x[0]) / masses.sum() / (0.2 * T) == pytest.approx(-v0, rel=6e-3 if m == 8 else 3e-3)
    assert all(1.6 < a / b < 2.4 for a, b in zip(errors, errors[1:])) and errors[-1] < 0.04


def test_a_cantilever_strikes_a_stop_converging_in_m_and_in_time_with_an_honest_error_bar():
    """A steel rod clamped at one end sags under gravity onto a ball 2 mm below its tip. The first strike's time
    (the contact's event) converges in m at second order; the tip's error bar (the second run at tolerances / 10)
    is within 3x of its true error (a run at rtol = 1e-12) through the strikes."""
    d, L = 0.02, 1.0

    def cantilever(m):
        model = rf.Model(gravity=(0.0, 0.0, -9.81))
        rod = model.add_beam("rod", model.ground, L, rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(d), m,
                             deform=["bend_y"])
        stop = rf.shapes.Sphere(0.01, center=(L, 0.0, -d / 2 - 2e-3 - 0.01))
        model.add_contact("strike", model.add_shape("caps", rod, rf.shapes.Capsules()),
                          model.add_shape("stop", model.ground, stop),
                          rf.laws.Contact(stiffness=1e8, exponent=1.5, restitution=0.5, impact_speed=0.1))
        return model.compile(), rod

    first = [rf.simulate(cantilever(m)[0], 0.03, rtol=1e-9, atol=1e-12).event_times("strike")[0] for m in (4, 8, 16, 32)]
    steps = np.abs(np.diff(first))
    assert all(steps[1:] < steps[:-1] / 2.5)
    s, rod = cantilever(8)
    t_eval = np.linspace(0.0, 0.1, 201)
    tip = lambda r: r.position(rod.tip)[:, 2]  # noqa: E731
    truth = tip(rf.simulate(s, 0.1, "radau5", t_eval=t_eval, rtol=1e-12, atol=1e-15))
    r = rf.simulate(s, 0.1, t_eval=t_eval, rtol=1e-6, atol=1e-9)
    assert len(r.event_times("strike")) >= 4
    error, estimated = np.abs(tip(r) - truth).max(), np.abs(r.error_estimate.of(tip)).max()
    assert error / 3 < estimated < 3 * error
