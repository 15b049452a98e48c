"""Single pendulum: periods against the small-amplitude formula and the elliptic integral."""

import numpy as np
import pytest
from conftest import integrate
from scipy.special import ellipk

import rigidfem as rf

L, M, G = 1.3, 2.0, 9.81


def pendulum():
    model, h = rf.samples.pendulum(length=L, mass=M, gravity=G)
    return model.compile(), h


def measured_period(system, theta0, periods=3):
    """Time between successive upward zero crossings of the angle (event location)."""

    def crossing(t, y):
        return y[0]

    crossing.direction = 1.0
    omega0 = np.sqrt(M * G * L / 2 / (M * L**2 / 3))
    sol = integrate(system, (periods + 1) * 2 * np.pi / omega0 * 1.5, [theta0], [0.0], events=crossing)
    t = sol.t_events[0]
    assert len(t) >= periods
    return np.diff(t).mean()


def test_small_amplitude_period_includes_the_rod_inertia():
    system, _ = pendulum()
    # Physical pendulum: T = 2π sqrt(l_eff/g), l_eff = I_O/(m d) with I_O = m l²/3 (rod about its end).
    d = L / 2
    I_O = M * L**2 / 12 + M * d**2
    T_ref = 2 * np.pi * np.sqrt(I_O / (M * d) / G)
    T = measured_period(system, 1e-4)
    assert T == pytest.approx(T_ref, rel=1e-7)
    # The rod's own inertia matters: a point mass at d would be 18% faster.
    assert abs(T / (2 * np.pi * np.sqrt(d / G)) - 1) > 0.1


@pytest.mark.parametrize("theta0", [0.5, 1.5, 2.8])
def test_large_amplitude_period_is_the_complete_elliptic_integral(theta0):
    system, _ = pendulum()
    d = L / 2
    omega0 = np.sqrt(M * G * d / (M * L**2 / 3))
    # T = (4/ω0) K(k²), k = sin(θ0/2)  (scipy's ellipk takes the parameter m = k²).
    T_ref = 4 / omega0 * ellipk(np.sin(theta0 / 2) ** 2)
    assert measured_period(system, theta0) == pytest.approx(T_ref, rel=1e-8)


def test_tip_position_follows_the_joint_angle():
    system, h = pendulum()
    for theta in (0.0, 0.4, -2.0):
        # Revolute about y: R2(θ) (0, 0, −L) = (−L sin θ, 0, −L cos θ).
        np.testing.assert_allclose(system.position(h["tip"], 0.0, [theta]), [-L * np.sin(theta), 0, -L * np.cos(theta)],
                                   atol=1e-15)
