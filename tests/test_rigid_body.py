"""Spatial rigid bodies: torque-free motion conserves energy and angular momentum;
a heavy symmetric top precesses at the rate of the gyroscopic formula."""

import numpy as np
import pytest
from conftest import integrate

import rigidfem as rf

E = np.eye(3)


def euler_omega(phi, phid):
    """Global angular velocity of R3(φ3) R2(φ2) R1(φ1) from the Euler rates:
    ω = φ̇3 e_z + φ̇2 R3 e_y + φ̇1 R3 R2 e_x."""
    R3 = rf.R3(phi[0])
    R32 = R3 @ rf.R2(phi[1])
    return phid[0] * E[2] + phid[1] * R3 @ E[1] + phid[2] * R32 @ E[0]


def test_free_body_conserves_energy_and_momenta():
    inertia = np.array([1.0, 2.0, 3.0])  # spin mostly about the major axis: stable, far from pitch ±90°
    mass = 2.5
    model = rf.Model(gravity=None)
    body = model.add_body("body", model.ground, rf.Joint.free(), mass=mass, inertia=inertia)
    system = model.compile()
    q0 = np.array([0.1, -0.2, 0.3, 0.2, 0.1, -0.1])
    qd0 = np.array([0.3, 0.1, -0.2, 2.0, 0.3, -0.2])
    sol = integrate(system, 20.0, q0, qd0, t_eval=np.linspace(0, 20, 201))

    def momenta(y):
        q, qd = y[:6], y[6:]
        R = rf.euler_zyx(*q[3:])
        w = euler_omega(q[3:], qd[3:])
        return mass * qd[:3], R @ np.diag(inertia) @ R.T @ w, 0.5 * mass * qd[:3] @ qd[:3] + 0.5 * w @ R @ np.diag(
            inertia) @ R.T @ w

    p0, L0, T0 = momenta(sol.y[:, 0])
    assert system.kinetic_energy(0.0, q0, qd0) == pytest.approx(T0, rel=1e-14)
    for y in sol.y.T:
        p, L, T = momenta(y)
        np.testing.assert_allclose(p, p0, rtol=1e-10)
        np.testing.assert_allclose(L, L0, rtol=1e-9, atol=1e-9 * np.linalg.norm(L0))
        assert T == pytest.approx(T0, rel=1e-9)
        assert system.kinetic_energy(0.0, y[:6], y[6:]) == pytest.approx(T, rel=1e-12)
    assert np.ptp(sol.y[3]) > 10.0  # it really turned: φ3 advanced by several radians
    np.testing.assert_allclose(system.position(body, 0.0, sol.y[:6, -1]), q0[:3] + 20.0 * qd0[:3], rtol=1e-10)


@pytest.mark.parametrize("theta", [np.pi / 3, 2 * np.pi / 5])
def test_heavy_symmetric_top_steady_precession(theta):
    m, h, I3, Ic = 1.2, 0.08, 4e-3, 2.5e-3
    g = 9.81
    model, _ = rf.samples.symmetric_top(mass=m, height=h, I_axis=I3, I_transverse=Ic)
    system = model.compile()
    I1 = Ic + m * h**2  # transverse moment about the fixed point
    w3 = 150.0  # spin: component of ω along the symmetry axis (rad/s)
    # Steady precession Ω about the vertical with the axis at θ from it:
    # I1 cos θ Ω² − I3 ω3 Ω + m g h = 0, slow root; gyroscopic limit Ω ≈ m g h / (I3 ω3).
    Omega = (I3 * w3 - np.sqrt((I3 * w3) ** 2 - 4 * I1 * np.cos(theta) * m * g * h)) / (2 * I1 * np.cos(theta))
    assert Omega == pytest.approx(m * g * h / (I3 * w3), rel=0.02)
    # Symmetry axis = body x = (c3 c2, s3 c2, −s2): θ from the vertical means −s2 = cos θ.
    phi2 = -np.arcsin(np.cos(theta))
    # ω · axis = φ̇1 + φ̇3 (e_z · axis) = φ̇1 + Ω cos θ.
    q0 = [0.0, phi2, 0.0]
    qd0 = [Omega, 0.0, w3 - Omega * np.cos(theta)]
    t_end = 2 * 2 * np.pi / Omega  # two precession periods
    sol = integrate(system, t_end, q0, qd0, t_eval=np.linspace(0, t_end, 400), rtol=1e-11, atol=1e-11)
    # No nutation: the tilt and the precession rate stay put.
    np.testing.assert_allclose(sol.y[1], phi2, atol=1e-7)
    np.testing.assert_allclose(sol.y[3], Omega, rtol=1e-6)
    np.testing.assert_allclose(sol.y[0], Omega * sol.t, atol=1e-6)
