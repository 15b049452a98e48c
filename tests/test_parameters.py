"""Named parameters (rigidfem.parameters): a system at other parameter values is the system of the model built
with those values, for every kind of parameter; the listing, pickling and bad input."""

import pickle
import warnings

import numpy as np
import pytest

import rigidfem as rf

G = 9.81


def build(E=2e11, Gm=8e10, rho=7800.0, mu=1e-4, A=1e-4, Iy=2.0e-10, Iz=3.3e-9, J=7e-10, hub=2.0, k=5.0, c=0.1,
          Q=0.5, ks=10.0, cs=0.5, F0=0.3, EA=3e4, DA=20.0, force=1.0, torque=0.2, prony=(), tip=0.1):
    """Every kind of parameter in one model: a beam with a tip mass on a sprung hub, a spring-damper with a
    constant push, a rope, a point force and a torque."""
    m = rf.Model(gravity=(0.0, -G, 0.0))
    hub_ = m.add_body("hub", m.ground, rf.Joint.revolute("z", stiffness=k, damping=c), hub, (0.1, 0.1, 0.2),
                      com=(0.05, 0.0, 0.0))
    m.add_generalized_force(hub_, Q)
    mat = rf.Material(E=E, rho=rho, G=Gm, retardation=mu, prony=prony)
    b = m.add_beam("strip", hub_, 1.0, mat, rf.Section(A=A, Iy=Iy, Iz=Iz, J=J), 5, tip_mass=tip,
                   placement=rf.transform((0.1, 0.0, 0.0)))
    m.add_spring_damper("spring", b.point(0.5), m.ground, stiffness=ks, damping=cs, length=0.5)
    m.add_cylinder("cylinder", b.tip, m.ground, F0)
    m.add_rope("rope", b.tip, m.ground, EA=EA, DA=DA, length=0.9)
    m.add_force("push", b.tip, (0.0, -force, 0.0))
    m.add_torque("twist", b.rfes[2], (0.0, 0.0, torque))
    return m.compile()


CHANGES = [  # parameter, new value, keyword of build
    ("strip.E", 1.3e11, "E"), ("strip.G", 3e10, "Gm"), ("strip.rho", 2700.0, "rho"), ("strip.retardation", 3e-3, "mu"),
    ("strip.A", 3e-4, "A"), ("strip.Iy", 5e-10, "Iy"), ("strip.Iz", 1e-9, "Iz"), ("strip.J", 2e-9, "J"),
    ("hub.mass", 0.7, "hub"), ("hub.rz.stiffness", 50.0, "k"), ("hub.rz.damping", 0.0, "c"), ("hub.rz.force", -2.0, "Q"),
    ("spring.stiffness", 1e3, "ks"), ("spring.damping", 4.0, "cs"), ("cylinder.force", -1.5, "F0"),
    ("rope.EA", 1e5, "EA"), ("rope.DA", 0.0, "DA"), ("push.force", 7.0, "force"), ("twist.torque", 0.9, "torque"),
]


@pytest.mark.parametrize("name, value, keyword", CHANGES)
def test_a_changed_parameter_is_the_model_built_with_it(name, value, keyword):
    base = build()
    changed = base.with_parameters({name: value})
    rebuilt = build(**{keyword: value})
    assert changed.parameters[name].value == value and base.parameters[name].value != value
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd = rng.normal(0.0, 0.2, base.nq), rng.normal(0.0, 0.5, base.nq)
        expected = rebuilt.forward_dynamics(0.3, q, qd)
        # the same to round-off (a density or section scales the quadrature's sums: 1e-12 relative)
        np.testing.assert_allclose(changed.forward_dynamics(0.3, q, qd), expected, rtol=0,
                                   atol=1e-10 * np.max(np.abs(expected)))
        np.testing.assert_allclose(changed.elastic_energy(0.3, q), rebuilt.elastic_energy(0.3, q), rtol=1e-12)
        np.testing.assert_allclose(changed.kinetic_energy(0.3, q, qd), rebuilt.kinetic_energy(0.3, q, qd),
                                   rtol=1e-12)
    assert np.max(np.abs(base.forward_dynamics(0.3, q, qd) - expected)) > 1e-8 * np.max(np.abs(expected))  # it matters


def test_listing_units_and_pickling():
    s = build()
    p = s.parameters
    assert p["strip.E"].unit == "Pa" and p["hub.mass"].unit == "kg" and p["rope.EA"].unit == "N"
    assert p["hub.rz.stiffness"].unit == "N m/rad" and p["push.force"].value == pytest.approx(1.0)
    assert not any(name.startswith("strip.rfe") and name.endswith(".mass") for name in p)  # rho sets them
    changed = s.with_parameters({"strip.E": 1e11, "hub.mass": 3.0})
    copy = pickle.loads(pickle.dumps(changed))
    q, qd = np.full(s.nq, 0.1), np.full(s.nq, -0.2)
    np.testing.assert_array_equal(copy.forward_dynamics(0.0, q, qd), changed.forward_dynamics(0.0, q, qd))
    assert copy.parameters["strip.E"].value == 1e11
    # changes compose: E then rho equals both at once
    both = s.with_parameters({"strip.E": 1e11, "strip.rho": 3000.0})
    twice = s.with_parameters({"strip.E": 1e11}).with_parameters({"strip.rho": 3000.0})
    np.testing.assert_array_equal(both.forward_dynamics(0.0, q, qd), twice.forward_dynamics(0.0, q, qd))


def test_viscoelastic_and_varying_beams():
    """A Prony beam's E, G and section values also set its Maxwell arms (k_j = E_j c/E): rho and damping only;
    a beam varying along its length has no single E: no beam parameters."""
    s = build(prony=((1e10, 0.01),))
    assert {"strip.rho", "strip.retardation"} <= set(s.parameters) and not {"strip.E", "strip.A"} & set(s.parameters)
    changed, rebuilt = s.with_parameters({"strip.rho": 2000.0}), build(rho=2000.0, prony=((1e10, 0.01),))
    np.testing.assert_array_equal(changed.arms, rebuilt.arms)
    q = np.full(s.nq, 0.05)
    np.testing.assert_allclose(changed.mass_matrix(0.0, q), rebuilt.mass_matrix(0.0, q), rtol=1e-12, atol=1e-15)
    m = rf.Model()
    m.add_beam("taper", m.ground, 1.0, rf.Material(E=2e11, rho=7800.0),
               lambda s_: rf.Section.rectangle(0.02 - 0.01 * s_, 0.005), 4)
    assert not any(name.startswith("taper.") for name in m.compile().parameters)


def test_bad_values():
    s = build()
    with pytest.raises(ValueError, match="values: expected a parameter of this system .*'strip.E'.*got 'strip.e'"):
        s.with_parameters({"strip.e": 1.0})
    with pytest.raises(ValueError, match="values: expected strip.rho to be a finite value > 0 in kg/m³"):
        s.with_parameters({"strip.rho": -1.0})
    with pytest.raises(ValueError, match="values: expected hub.mass to be a finite value > 0"):
        s.with_parameters({"hub.mass": float("nan")})
    with pytest.raises(ValueError, match="values: expected spring.stiffness to be a finite value >= 0"):
        s.with_parameters({"spring.stiffness": -3.0})
    with pytest.raises(ValueError, match="values: expected strip.E to be .*got 'stiff'"):
        s.with_parameters({"strip.E": "stiff"})
    with pytest.raises(ValueError, match="values: expected a dict"):
        s.with_parameters([("strip.E", 1.0)])
    s.with_parameters({"cylinder.force": -5.0, "hub.rz.force": -1.0})  # forces take any sign


def test_extreme_values_in_range_are_finite_or_refused_by_name():
    """1e299 and 1e300 m² are finite values in range: the rfes' masses stay finite (their ratio to the built area
    overflows, their product with the built pseudo-inertias does not: M is linear in A, M(1e300) = 10 M(1e299)
    − 9 M(A₀)); second moments whose springs E I / l overflow are a ValueError naming them, without NaN or
    numpy's warnings on the way."""
    s = build()
    q = np.full(s.nq, 0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        M0, M299, M300 = (s.with_parameters({"strip.A": a}).mass_matrix(0.0, q) for a in (1e-4, 1e299, 1e300))
        assert np.isfinite(M300).all()
        np.testing.assert_allclose(M300, 10.0 * M299 - 9.0 * M0, rtol=0, atol=1e-12 * np.abs(M300).max())
        for name in ("strip.Iy", "strip.Iz", "strip.J"):
            with pytest.raises(ValueError, match=f"^values: expected values whose rfes' pseudo-inertias, springs and "
                                                 f"dampers are finite .*got {name} = 1e\\+300"):
                s.with_parameters({name: 1e300})


def test_profile_numbers_are_parameters():
    """The numbers of a drive, a winch, a cylinder's force and a load's scale, by their maker's argument names;
    a changed one is the model built with it."""
    def crane(omega=0.8, rate=0.3, amplitude=50.0, scale=2.0):
        m = rf.Model(gravity=(0.0, 0.0, -G))
        boom = m.add_body("boom", m.ground, rf.Joint.revolute("z"), 10.0, (1.0, 1.0, 1.0), com=(1.0, 0.0, 0.0))
        m.prescribe(boom, rf.motion.harmonic(0.3, omega) + rf.motion.polynomial([0.0, 0.1]))
        load = m.add_body("load", boom, rf.Joint.free(), 5.0, (0.1, 0.1, 0.1), placement=rf.transform((2.0, 0, -1.0)))
        m.add_rope("rope", boom.point((2.0, 0.0, 0.0)), load, EA=1e5, length=rf.motion.polynomial([0.9, rate]))
        m.add_cylinder("jack", load, m.ground, rf.motion.harmonic(amplitude, 3.0))
        m.add_force("gust", load, (0.0, 1.0, 0.0), scale=rf.motion.polynomial([scale]))
        return m.compile()

    s = crane()
    names = set(s.parameters)
    assert {"boom.rz.drive.parts[0].omega", "boom.rz.drive.parts[1].coefficients[1]", "rope.length.coefficients[1]",
            "jack.profile.amplitude", "gust.scale.coefficients[0]"} <= names
    rng = np.random.default_rng(5)
    q, qd = rng.normal(0.0, 0.1, s.nq), rng.normal(0.0, 0.1, s.nq)
    for name, value, keyword in [("boom.rz.drive.parts[0].omega", 1.3, "omega"), ("rope.length.coefficients[1]", -0.2, "rate"),
                                 ("jack.profile.amplitude", 20.0, "amplitude"), ("gust.scale.coefficients[0]", 4.0, "scale")]:
        np.testing.assert_array_equal(s.with_parameters({name: value}).forward_dynamics(1.5, q, qd),
                                      crane(**{keyword: value}).forward_dynamics(1.5, q, qd))
    with pytest.raises(ValueError, match=r"values: expected boom.rz.drive.parts\[0\].omega to be a finite value in"):
        s.with_parameters({"boom.rz.drive.parts[0].omega": float("inf")})


def test_a_sum_with_a_python_part_keeps_that_part():
    """A drive that sums a Python function and a ramp: the ramp's numbers are parameters, the function (no
    recipe, no numbers) is kept as it is when one of them changes (found by fuzzing: it was remade and failed)."""
    def build(rate):
        m = rf.Model(gravity=(0.0, -G, 0.0))
        b = m.add_body("b", m.ground, rf.Joint.prismatic("y"), mass=1.0, inertia=(0.1, 0.1, 0.1))
        m.prescribe(b, 2.0 * rf.motion.function(lambda t: (np.sin(t), np.cos(t), -np.sin(t))) - rf.motion.ramp(rate, 0.0, 0.3))
        a = m.add_body("a", b, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.5, 0.0, 0.0))
        return m.compile(), a
    s, a = build(1.0)
    name = next(n for n in s.parameters if n.endswith(".rate"))
    q, qd = np.array([0.3]), np.array([0.1])
    np.testing.assert_array_equal(s.with_parameters({name: 1.5}).forward_dynamics(0.2, q, qd),
                                  build(1.5)[0].forward_dynamics(0.2, q, qd))
    r = rf.simulate(s, 0.2, "rk4", dt=1e-3, q0=[0.3], sensitivities=[name])
    assert np.isfinite(r.sensitivity(name)[0]).all() and np.abs(r.sensitivity(name)[0]).max() > 0.0
