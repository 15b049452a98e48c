"""Ropes (Model.add_rope): tension-only spring-dampers EA/l_u, DA/l_u with a winch l_u(t), against
closed forms (static stretch, frequency, free fall and the energy of the catch) and a slack phase
the implicit methods cross without chatter."""

import numpy as np
import pytest

import rigidfem as rf

G, MASS, EA, LU = 9.81, 500.0, 2.0e6, 10.0


def hoist(length=LU, damping=0.0, EA=EA):
    """A payload on a vertical slide (prismatic z) hanging from a rope fixed at the origin."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), MASS, (1.0, 1.0, 1.0))
    model.add_rope("rope", model.ground, load, EA=EA, length=length, DA=damping)
    return load, model.compile()


@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
def test_static_stretch_and_frequency(algorithm):
    """z = −l_u (1 + m g/EA) and ω² = EA/(l_u m) on the taut rope; T = m g."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), MASS, (1.0, 1.0, 1.0))
    model.add_rope("element0", model.ground, load, EA=EA, length=LU, DA=3e4)
    s = model.compile(algorithm)
    eq = rf.static_equilibrium(s, [-LU * 1.01])
    assert eq.q[0] == pytest.approx(-LU * (1 + MASS * G / EA), rel=1e-13)
    assert s.element_states(0.0, eq.q, [0.0])[0, 2] == pytest.approx(-MASS * G, rel=1e-12)
    modes = rf.modal_analysis(s, eq.q)
    assert modes.omega[0] == pytest.approx(np.sqrt(EA / (LU * MASS)), rel=1e-10)
    assert modes.damping_ratios[0] == pytest.approx(3e4 / LU / (2 * np.sqrt(EA / LU * MASS)), rel=1e-8)


def test_slack_rope_exerts_nothing():
    _, s = hoist()
    q = np.array([-0.5 * LU])  # closer than l_u: slack
    assert s.element_states(0.0, q, [-3.0])[0, 2] == 0.0
    np.testing.assert_allclose(s.forward_dynamics(0.0, q, [-3.0]), [-G], rtol=1e-15)
    Kq, Kqd = s.force_jacobians(0.0, q, np.array([-3.0]))
    assert Kq[0, 0] == 0.0 and Kqd[0, 0] == 0.0


def test_drop_catch_and_rebound():
    """Dropped from rest 2 m above the rope's length: free fall (z = z₀ − g t²/2, T = 0) until the
    rope is taut at t = √(2·2/g); the catch stretches it to s with m g (2 + s) = ½ (EA/l_u) s²;
    without damping it throws the load back up and catches it again. DOPRI5 and the generalised-α
    (which crosses each slack/taut switch in its Newton iterations, without chatter) agree."""
    _, s = hoist()
    z0, t_taut = -(LU - 2.0), np.sqrt(2 * 2.0 / G)
    k = EA / LU
    stretch = (MASS * G + np.sqrt((MASS * G) ** 2 + 2 * k * MASS * G * 2.0)) / k
    t = np.linspace(0.0, 3.0, 3001)
    ref = rf.simulate(s, 3.0, method="dopri5", rtol=1e-11, atol=1e-12, q0=[z0], t_eval=t)
    free = t < t_taut - 1e-3
    np.testing.assert_allclose(ref.q[free, 0], z0 - 0.5 * G * t[free] ** 2, rtol=0, atol=1e-9)
    assert np.all(ref.element_forces[free] == 0.0)
    assert ref.q[:, 0].min() == pytest.approx(-(LU + stretch), abs=1e-8)
    assert np.abs(ref.energy - ref.energy[0]).max() < 1e-6 * MASS * G * 2.0
    taut = ref.element_forces[:, 0] < 0.0
    assert np.count_nonzero(np.diff(taut.astype(int)) == 1) >= 2  # caught at least twice
    ga = rf.simulate(s, 3.0, method="generalized_alpha", dt=2e-4, q0=[z0], t_eval=t)
    assert np.abs(ga.q[:, 0] - ref.q[:, 0]).max() < 1e-5
    assert ga.stats["newton_iterations"] <= 3 * ga.stats["steps"]


def test_winch_pays_out_at_constant_speed():
    """l_u = 10 + 0.5 t: after the start the load descends with the winch, its tension m g and the
    stretch s = l − l_u steady: EA s + DA ṡ = m g l_u with ṡ = m g v/EA."""
    _, s = hoist(length=rf.motion.polynomial([LU, 0.5]), damping=2e5)
    z0 = -LU * (1 + MASS * G / EA)
    r = rf.simulate(s, 6.0, method="generalized_alpha", dt=1e-3, q0=[z0], t_eval=np.linspace(0.0, 6.0, 61))
    late = r.t > 3.0
    lu = LU + 0.5 * r.t[late]
    stretch = (MASS * G * lu - 2e5 * MASS * G * 0.5 / EA) / EA
    np.testing.assert_allclose(r.q[late, 0], -(lu + stretch), rtol=0, atol=1e-8)
    np.testing.assert_allclose(r.element_forces[late, 0], -MASS * G, rtol=1e-3)


def test_bad_rope_input():
    model = rf.Model()
    load = model.add_body("load", model.ground, rf.Joint.prismatic("z"), 1.0, (1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="^EA: expected a positive number in N"):
        model.add_rope("rope", model.ground, load, EA=0.0, length=1.0)
    with pytest.raises(ValueError, match="^length: expected a positive number in m"):
        model.add_rope("rope", model.ground, load, EA=1e6, length=-1.0)
    with pytest.raises(ValueError, match="^length: expected a profile l_u"):
        model.add_rope("rope", model.ground, load, EA=1e6, length=rf.motion.polynomial([0.0, 1.0]))
    with pytest.raises(ValueError, match="^DA: expected a non-negative number in N s"):
        model.add_rope("rope", model.ground, load, EA=1e6, length=1.0, DA=-1.0)
    model.add_rope("reeled", model.ground, load, EA=1e6, length=rf.motion.polynomial([1.0, -1.0]))
    s = model.compile()
    with pytest.raises(rf.SimulationError, match="unstretched length of rope 'reeled' is l_u = -0.5 m"):
        s.forward_dynamics(1.5, [-1.0], [0.0])


def test_a_rope_with_mass_is_the_hanging_chain():
    """A rope with mass and sag is a beam with (almost) no bending stiffness: pinned at its top and
    hanging under gravity, its frequencies converge at second order to the hanging chain's,
    ω_n = (z_n/2) √(g/L) with z_n the zeros of J₀ (Bernoulli, Euler)."""
    from scipy.special import jn_zeros

    g, L = 9.81, 10.0
    exact = jn_zeros(0, 3) / 2 * np.sqrt(g / L)
    errors = []
    for m in (10, 20, 40):
        model = rf.Model(gravity=(0.0, 0.0, -g))
        model.add_beam("rope", model.ground, L, rf.Material(E=1e3, rho=7850.0), rf.Section.rectangle(0.02, 0.02), m,
                       deform=("bend_y",), joint=rf.Joint.revolute("y"),
                       placement=rf.transform(euler_zyx=(0.0, np.pi / 2, 0.0)))  # hanging down
        s = model.compile()
        errors.append(np.abs(rf.modal_analysis(s, np.zeros(s.nq)).omega[:3] / exact - 1.0))
    errors = np.array(errors)
    ratios = errors[:-1] / errors[1:]
    assert np.all(ratios > 3.4) and np.all(ratios < 4.3), ratios
    assert errors[-1, 0] < 3e-5 and errors[-1, 2] < 3e-3
