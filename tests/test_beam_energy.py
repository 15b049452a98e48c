"""An undamped beam released from a large static deflection keeps its energy; with
Kelvin–Voigt damping the energy lost equals the work of the sde dampers."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rigidfem as rf

E, RHO, L = 7e10, 2700.0, 1.0
SECTION = rf.Section.rectangle(0.02, 0.01)


def released_beam(linear, damping=0.0, m=6):
    """Deflect a 3D modified beam (both bendings; torsion rigid, it would only make the
    problem stiff) by an oblique tip force (PL²/EI_z = 2), then drop the force."""
    def build(with_force):
        model = rf.Model(gravity=None)
        beam = model.add_beam("b", model.ground, L, rf.Material(E, RHO, nu=0.33, retardation=damping), SECTION, m,
                              deform=("bend_z", "bend_y"), linear=linear)
        if with_force:
            P = 2 * E * SECTION.Iz / L**2
            model.add_force("load0", beam.tip, (0.0, P, 0.3 * P), follower=False)
        return model.compile(), beam

    loaded, _ = build(True)
    q0 = rf.static_equilibrium(loaded, load_steps=5).q
    system, beam = build(False)
    return system, beam, q0


def energy(system, y):
    n = system.nq
    return np.array([system.kinetic_energy(0.0, x[:n], x[n:]) + system.potential_energy(0.0, x[:n]) for x in y.T])


@pytest.mark.parametrize("linear", [False, True])
def test_undamped_beam_keeps_its_energy(linear):
    system, beam, q0 = released_beam(linear)
    assert system.elastic_energy(0.0, q0) > 1.0  # a large deflection: joules stored
    T1 = 2 * np.pi / rf.modal_analysis(system).omega[0]
    t = np.linspace(0, 3 * T1, 301)
    sol = solve_ivp(system.rhs, (0, t[-1]), np.r_[q0, np.zeros(system.nq)], method="DOP853", rtol=1e-11, atol=1e-12,
                    t_eval=t)
    E_t = energy(system, sol.y)
    assert np.max(np.abs(E_t - E_t[0])) < 1e-8 * E_t[0]
    tip = np.array([system.position(beam.tip, 0.0, y[: system.nq]) for y in sol.y.T])
    assert np.ptp(tip[:, 1]) > 0.3 * L  # it really swings through large amplitudes


def test_damped_beam_loses_the_work_of_its_dampers():
    mu = 1e-4
    system, beam, q0 = released_beam(False, damping=mu)
    n = system.nq
    sde = beam.sde[0]  # uniform beam: every sde alike; coordinates per sde in the book's order rz, ry
    b = np.tile([sde.damping["bend_z"], sde.damping["bend_y"]], beam.elements)

    def augmented(t, y):  # D = ∫ Σ b_k q̇_k² dt beside the motion (b from the book's b = μ c)
        return np.append(system.rhs(t, y[:-1]), b @ y[n:-1] ** 2)

    T1 = 2 * np.pi / rf.modal_analysis(system).omega[0]
    t = np.linspace(0, 3 * T1, 61)
    sol = solve_ivp(augmented, (0, t[-1]), np.r_[q0, np.zeros(n), 0.0], method="DOP853", rtol=1e-11, atol=1e-12,
                    t_eval=t)
    E_t = energy(system, sol.y[:-1])
    lost = E_t[0] - E_t
    assert lost[-1] > 0.05 * E_t[0]
    np.testing.assert_allclose(lost, sol.y[-1], rtol=1e-7, atol=1e-9 * E_t[0])
    assert system.coordinate_names[:2] == ["b.rfe1.rz", "b.rfe1.ry"]
