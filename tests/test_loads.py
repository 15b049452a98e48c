"""Loads and energies against virtual work and finite differences computed here:
Q_i = Fᵀ ∂r/∂q_i for a point force, δW = τ · δθ for a torque, −∂V/∂q for gravity,
½ q̇ᵀ A q̇ for the kinetic energy."""

import numpy as np
import pytest

import rigidfem as rf


def chain(gravity=(0.0, 0.0, 0.0)):
    """A three-body tree with mixed joints."""
    model = rf.Model(gravity=gravity)
    a = model.add_body("a", model.ground, rf.Joint.universal(("z", "y")), mass=1.0, com=(0.3, 0, 0),
                       inertia=(0.01, 0.02, 0.025))
    b = model.add_body("b", a, rf.Joint.cylindrical("x"), mass=0.8, com=(0.2, 0.05, 0), inertia=(0.01, 0.015, 0.02),
                       placement=rf.transform((0.6, 0, 0), (0.2, 0.1, 0.0)))
    c = model.add_body("c", a, rf.Joint.spherical(), mass=0.5, com=(0, 0, -0.2), inertia=(0.004, 0.005, 0.003),
                       placement=rf.transform((0.3, 0.1, 0), (0, 0, 0.4)))
    return model, (a, b, c)


def fd_jacobian(fun, q, h=1e-6):
    cols = []
    for i in range(len(q)):
        e = np.zeros(len(q))
        e[i] = h
        cols.append((fun(q + e) - fun(q - e)) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize("follower", [False, True])
def test_point_force_generalized_force_is_its_virtual_work(follower, rng):
    model, (a, b, c) = chain()
    point = c.point((0.1, -0.2, 0.3))
    F = np.array([1.0, -2.0, 3.0])
    model.add_force("load0", point, F, follower=follower)
    system = model.compile()
    for _ in range(3):
        q = rng.uniform(-1, 1, system.nq)
        # A follower force turns with body c: global components R_c F.
        F_global = system.transform(c.index, 0.0, q)[:3, :3] @ F if follower else F
        J = fd_jacobian(lambda x: system.position(point, 0.0, x), q)  # ∂r/∂q (3, nq)
        Q = system.generalized_forces(0.0, q, np.zeros(system.nq))
        np.testing.assert_allclose(Q, F_global @ J, rtol=1e-8, atol=1e-9)


def test_torque_generalized_force_is_its_virtual_work(rng):
    model, (a, b, c) = chain()
    tau = np.array([0.5, -1.0, 2.0])
    model.add_torque("load0", b, tau)
    system = model.compile()
    q = rng.uniform(-1, 1, system.nq)
    # δθ_i from δR Rᵀ = S(δθ): columns of the rotation Jacobian of body b.
    R = lambda x: system.transform(b.index, 0.0, x)[:3, :3]  # noqa: E731
    h = 1e-6
    Q_ref = []
    for i in range(system.nq):
        e = np.zeros(system.nq)
        e[i] = h
        S = (R(q + e) - R(q - e)) / (2 * h) @ R(q).T
        Q_ref.append(tau @ [S[2, 1], S[0, 2], S[1, 0]])
    np.testing.assert_allclose(system.generalized_forces(0.0, q, np.zeros(system.nq)), Q_ref, rtol=1e-8, atol=1e-9)


def test_gravity_is_minus_the_gradient_of_its_potential(rng):
    model, _ = chain(gravity=(1.0, -2.0, -9.81))
    system = model.compile()
    q = rng.uniform(-1, 1, system.nq)
    grad = fd_jacobian(lambda x: np.atleast_1d(system.gravity_energy(0.0, x)), q)[0]
    np.testing.assert_allclose(system.generalized_forces(0.0, q, np.zeros(system.nq)), -grad, rtol=1e-8, atol=1e-9)


def test_kinetic_energy_is_the_quadratic_form_of_the_mass_matrix(rng):
    model, _ = chain()
    system = model.compile()
    q, qd = rng.uniform(-1, 1, (2, system.nq))
    A = system.mass_matrix(0.0, q)
    np.testing.assert_allclose(A, A.T, rtol=1e-15, atol=1e-16)
    assert np.all(np.linalg.eigvalsh(A) > 0)
    assert system.kinetic_energy(0.0, q, qd) == pytest.approx(0.5 * qd @ A @ qd, rel=1e-13)


def test_velocity_of_a_point_is_the_derivative_of_its_position(rng):
    model, (a, b, c) = chain()
    system = model.compile()
    point = b.point((0.1, 0.2, -0.3))
    q, qd = rng.uniform(-1, 1, (2, system.nq))
    J = fd_jacobian(lambda x: system.position(point, 0.0, x), q)
    np.testing.assert_allclose(system.velocity(point, 0.0, q, qd), J @ qd, rtol=1e-8, atol=1e-10)


def test_scaled_load_follows_its_profile():
    model, (a, b, c) = chain()
    model.add_force("load0", b.origin, (0.0, 0.0, 1.0), scale=rf.motion.polynomial([0.0, 2.0]))  # F(t) = 2t e_z
    system = model.compile()
    q = np.full(system.nq, 0.1)
    Q1 = system.generalized_forces(1.0, q, np.zeros(system.nq))
    Q3 = system.generalized_forces(3.0, q, np.zeros(system.nq))
    np.testing.assert_allclose(Q3, 3 * Q1, rtol=1e-14, atol=1e-14)
    assert np.abs(Q1).max() > 0.1
