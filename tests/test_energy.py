"""Energy: conservative systems keep their total energy over 100 periods (DOP853,
rtol = 1e-12); with dampers, the energy lost equals the dissipated power integrated."""

import numpy as np
import pytest
from conftest import integrate
from scipy.integrate import solve_ivp

import rigidfem as rf


def total_energy(system, y):
    n = system.nq
    return np.array([system.kinetic_energy(0.0, x[:n], x[n:]) + system.potential_energy(0.0, x[:n]) for x in y.T])


def test_spatial_double_pendulum_keeps_energy_over_100_periods():
    model, _ = rf.samples.double_pendulum(spatial=True)
    system = model.compile()
    period = 2 * np.pi * np.sqrt(1.0 / 9.81)  # order of the slow mode
    t_end = 100 * period
    q0 = [0.3, 0.5, -0.2, 0.1, -0.6, 0.3]
    qd0 = [0.5, 0.0, 0.4, -0.8, 0.2, 0.1]
    sol = integrate(system, t_end, q0, qd0, t_eval=np.linspace(0, t_end, 2001))
    E = total_energy(system, sol.y)
    scale = np.max([system.kinetic_energy(0.0, x[:6], x[6:]) for x in sol.y.T])  # energy exchanged in the motion
    assert np.max(np.abs(E - E[0])) / scale < 1e-8


def test_spring_pendulum_chain_keeps_energy_over_100_periods():
    """Gravity, joint springs with rest values and a prismatic joint together."""
    model = rf.Model()
    a = model.add_body("a", model.ground, rf.Joint.revolute("y", stiffness=20.0, rest=0.2), mass=1.0,
                       com=(0, 0, -0.5), inertia=(0.08, 0.08, 0.01))
    model.add_body("b", a, rf.Joint.prismatic("z", stiffness=300.0, rest=-0.1), mass=0.5,
                   inertia=(0.01, 0.01, 0.01), placement=rf.transform((0, 0, -1.0)))
    system = model.compile()
    t_end = 100 * 2 * np.pi / np.sqrt(300.0 / 0.5) * 8
    sol = integrate(system, t_end, [0.4, 0.05], [0.0, 0.3], t_eval=np.linspace(0, t_end, 1001))
    E = total_energy(system, sol.y)
    assert system.elastic_energy(0.0, sol.y[:2, 0]) > 0
    scale = np.max([system.kinetic_energy(0.0, x[:2], x[2:]) for x in sol.y.T])
    assert np.max(np.abs(E - E[0])) / scale < 1e-8


def test_energy_lost_equals_dissipated_work():
    c1, c2 = 0.15, 4.0
    model = rf.Model()
    a = model.add_body("a", model.ground, rf.Joint.revolute("y", damping=c1), mass=1.0, com=(0, 0, -0.5),
                       inertia=(0.08, 0.08, 0.01))
    model.add_body("b", a, rf.Joint.prismatic("z", stiffness=300.0, damping=c2), mass=0.5,
                   inertia=(0.01, 0.01, 0.01), placement=rf.transform((0, 0, -1.0)))
    system = model.compile()

    def augmented(t, y):
        # Integrate D = ∫ (c1 q̇1² + c2 q̇2²) dt beside the motion (damping values of this test).
        return np.append(system.rhs(t, y[:4]), c1 * y[2] ** 2 + c2 * y[3] ** 2)

    t = np.linspace(0, 10, 201)
    sol = solve_ivp(augmented, (0, 10), [1.0, 0.05, 0.0, 0.0, 0.0], t_eval=t, method="DOP853", rtol=1e-12,
                    atol=1e-12)
    E = total_energy(system, sol.y[:4])
    lost = E[0] - E
    E_rest = system.potential_energy(0.0, [0.0, -0.5 * 9.81 / 300.0])  # hanging still, spring sagged
    assert lost[-1] > 0.5 * (E[0] - E_rest)  # most of the free energy was dissipated
    np.testing.assert_allclose(lost, sol.y[4], rtol=1e-8, atol=1e-10)
    # The package's own dissipated power agrees with the test's.
    for y in sol.y.T[::20]:
        assert system.dissipated_power(0.0, y[:2], y[2:4]) == pytest.approx(c1 * y[2] ** 2 + c2 * y[3] ** 2, rel=1e-14)
