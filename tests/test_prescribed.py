"""Prescribed motion: a pendulum hinged on a driven hub against its equation in the
rotating frame, and the drive torque against dL_z/dt computed here."""

import numpy as np
import pytest
from conftest import integrate
from scipy.integrate import solve_ivp

import rigidfem as rf

R, D, MASS, LEN, G = 0.4, 0.3, 1.5, 0.6, 9.81
I_T = MASS * LEN**2 / 12  # rod: transverse moment about its centre of mass
I_A = 0.004  # rod: axial moment
I_HUB = 0.2  # hub: moment about z


def hub_pendulum(profile):
    """Hub turning about z by `profile`; a rod hinged at radius R about the hub's y axis,
    centre of mass D below the hinge. At φ > 0 the rod swings inward: r = R − D sin φ."""
    model = rf.Model(gravity=(0, 0, -G))
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), mass=3.0, inertia=(0.1, 0.1, I_HUB))
    rod = model.add_body("rod", hub, rf.Joint.revolute("y"), mass=MASS, com=(0, 0, -D), inertia=(I_T, I_T, I_A),
                         placement=rf.transform(translation=(R, 0, 0)))
    model.prescribe(hub, profile)
    return model.compile(), rod


def rotating_frame_equation(Omega, Omegad):
    """Lagrangian of the rod in the frame turning at Ω(t):
    L = ½(m d² + I_t) φ̇² + ½ m Ω² (R − d sin φ)² + ½ Ω² (I_t sin²φ + I_a cos²φ) + m g d cos φ."""

    def rhs(t, y):
        phi, phid = y
        s, c = np.sin(phi), np.cos(phi)
        W = Omega(t)
        dL = -MASS * W**2 * (R - D * s) * D * c + (I_T - I_A) * W**2 * s * c - MASS * G * D * s
        return [phid, dL / (MASS * D**2 + I_T)]

    def torque(t, phi, phid):
        # L_z = Ω [I_hub + J(φ)], J = m (R − d sin φ)² + I_t sin²φ + I_a cos²φ; τ = dL_z/dt.
        s, c = np.sin(phi), np.cos(phi)
        J = MASS * (R - D * s) ** 2 + I_T * s**2 + I_A * c**2
        dJ = -2 * MASS * (R - D * s) * D * c + 2 * (I_T - I_A) * s * c
        return Omegad(t) * (I_HUB + J) + Omega(t) * dJ * phid

    return rhs, torque


@pytest.mark.parametrize("kind", ["constant_rate", "spin_up"])
def test_hub_driven_pendulum(kind):
    if kind == "constant_rate":
        W = 4.0
        profile = rf.motion.polynomial([0.0, W])
        Omega, Omegad = (lambda t: W), (lambda t: 0.0)
    else:
        W, Ts = 5.0, 2.0
        profile = rf.motion.spin_up(W, Ts)
        Omega = lambda t: W / Ts * (t - Ts / (2 * np.pi) * np.sin(2 * np.pi * t / Ts)) if t < Ts else W  # noqa: E731
        Omegad = lambda t: W / Ts * (1 - np.cos(2 * np.pi * t / Ts)) if t < Ts else 0.0  # noqa: E731
    system, rod = hub_pendulum(profile)
    assert system.nq == 1 and system.prescribed_names == ["hub.rz"]
    rhs, torque = rotating_frame_equation(Omega, Omegad)
    t = np.linspace(0, 4.0, 161)
    y0 = [0.3, 0.0]
    ref = solve_ivp(rhs, (0, 4.0), y0, t_eval=t, method="DOP853", rtol=1e-12, atol=1e-12)
    sol = integrate(system, 4.0, y0[:1], y0[1:], t_eval=t)
    np.testing.assert_allclose(sol.y[0], ref.y[0], atol=1e-8)
    assert np.ptp(sol.y[0]) > 0.2  # it swings
    for k in range(0, len(t), 8):
        tau = system.driving_forces(t[k], sol.y[:1, k], sol.y[1:, k])
        assert tau[0] == pytest.approx(torque(t[k], sol.y[0, k], sol.y[1, k]), rel=1e-7, abs=1e-9)


def test_driven_coordinate_leaves_the_unknowns_and_sets_the_pose():
    system, rod = hub_pendulum(rf.motion.harmonic(0.5, 2.0, phase=0.3))
    t = 0.8
    theta = 0.5 * np.sin(2.0 * t + 0.3)
    # Rod origin is at radius R on the hub: (R cos θ, R sin θ, 0).
    np.testing.assert_allclose(system.position(rod, t, [0.0]), [R * np.cos(theta), R * np.sin(theta), 0], atol=1e-15)
    assert system.coordinate_names == ["rod.ry"]


def test_python_callable_drive_matches_the_builtin_profile():
    W, Ts = 3.0, 1.5
    builtin = rf.motion.spin_up(W, Ts)
    slow = rf.motion.function(lambda t: builtin(t))
    s1, _ = hub_pendulum(builtin)
    s2, _ = hub_pendulum(slow)
    for t in (0.2, 1.0, 2.0):
        np.testing.assert_array_equal(s1.forward_dynamics(t, [0.4], [0.3]), s2.forward_dynamics(t, [0.4], [0.3]))
        np.testing.assert_array_equal(s1.driving_forces(t, [0.4], [0.3]), s2.driving_forces(t, [0.4], [0.3]))
