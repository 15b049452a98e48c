"""Spring-mass on a prismatic joint: frequency sqrt(k/m) and the damped decay rate."""

import numpy as np
import pytest
from conftest import integrate

import rigidfem as rf


def test_undamped_oscillation_is_x0_cos_omega_t():
    m, k = 2.0, 800.0
    model, _ = rf.samples.spring_mass(mass=m, stiffness=k)
    system = model.compile()
    t = np.linspace(0.0, 2.0, 400)
    sol = integrate(system, 2.0, [0.01], [0.0], t_eval=t)
    np.testing.assert_allclose(sol.y[0], 0.01 * np.cos(np.sqrt(k / m) * t), atol=1e-12)


@pytest.mark.parametrize("zeta", [0.02, 0.3])
def test_damped_oscillation_decays_at_zeta_omega(zeta):
    m, k = 2.0, 800.0
    w0 = np.sqrt(k / m)
    c = 2 * zeta * m * w0
    model, _ = rf.samples.spring_mass(mass=m, stiffness=k, damping=c)
    system = model.compile()
    t = np.linspace(0.0, 1.0, 300)
    x0 = 0.02
    sol = integrate(system, 1.0, [x0], [0.0], t_eval=t)
    wd = w0 * np.sqrt(1 - zeta**2)
    x = x0 * np.exp(-zeta * w0 * t) * (np.cos(wd * t) + zeta * w0 / wd * np.sin(wd * t))
    np.testing.assert_allclose(sol.y[0], x, atol=1e-12)


def test_spring_rest_value_and_applied_force_set_the_equilibrium():
    m, k, rest, F = 1.0, 50.0, 0.3, 5.0
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    block = model.add_body("block", model.ground, rf.Joint.prismatic("z", stiffness=k, rest=rest), mass=m,
                           inertia=(1e-3, 1e-3, 1e-3))
    model.add_generalized_force(block, F)
    system = model.compile()
    z_eq = rest + (F - m * 9.81) / k
    assert system.forward_dynamics(0.0, [z_eq], [0.0])[0] == pytest.approx(0.0, abs=1e-13)
    assert system.forward_dynamics(0.0, [z_eq + 0.01], [0.0])[0] == pytest.approx(-k * 0.01 / m, rel=1e-12)
    assert system.elastic_energy(0.0, [z_eq + 0.01]) == pytest.approx(0.5 * k * (z_eq + 0.01 - rest) ** 2, rel=1e-14)


def test_generalized_force_law_is_called_with_time_and_the_coordinate_state():
    calls = []

    def law(t, x, xd):
        calls.append((t, x, xd))
        return -3.0 * x - 0.5 * xd + np.sin(t)

    model, h = rf.samples.spring_mass(mass=2.0, stiffness=0.0)
    model.add_generalized_force(h["block"], law)
    system = model.compile()
    qdd = system.forward_dynamics(0.7, [0.2], [-1.0])
    assert calls[-1] == (0.7, 0.2, -1.0)
    assert qdd[0] == pytest.approx((-3.0 * 0.2 + 0.5 + np.sin(0.7)) / 2.0, rel=1e-14)


def test_exception_in_a_force_law_propagates():
    def law(t, x, xd):
        raise ZeroDivisionError("inside the user's law")

    model, h = rf.samples.spring_mass()
    model.add_generalized_force(h["block"], law)
    system = model.compile()
    with pytest.raises(ZeroDivisionError, match="inside the user's law"):
        system.forward_dynamics(0.0, [0.0], [0.0])
