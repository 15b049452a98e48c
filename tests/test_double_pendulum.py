"""Double pendulum, planar and spatial: mass matrix and accelerations against Lagrange's
equations derived independently here with SymPy (rotation matrices, ½ m v² + ½ ωᵀ I ω)."""

import functools

import numpy as np
import pytest
import sympy as sp

import rigidfem as rf

L1, L2, M1, M2, G = 1.0, 0.8, 1.0, 0.7, 9.81


def rot(axis, a):
    c, s = sp.cos(a), sp.sin(a)
    return {
        "x": sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


@functools.lru_cache
def sympy_lagrange(spatial):
    """Symbols q, q̇ and the symbolic M(q), f(q, q̇) of M q̈ = f from the Lagrangian."""
    n = 3 if spatial else 1
    q = sp.symbols(f"q0:{2 * n}")
    qd = sp.symbols(f"qd0:{2 * n}")

    def joint(angles):  # ZYX (spatial) or a rotation about y (planar)
        return rot("z", angles[0]) * rot("y", angles[1]) * rot("x", angles[2]) if spatial else rot("y", angles[0])

    R1 = joint(q[:n])
    R2 = R1 * joint(q[n:])
    down = lambda l: sp.Matrix([0, 0, -l])  # noqa: E731
    c1 = R1 * down(L1 / 2)
    c2 = R1 * down(L1) + R2 * down(L2 / 2)
    qv, qdv = sp.Matrix(q), sp.Matrix(qd)
    T = 0
    V = 0
    for m, l, c, R in ((M1, L1, c1, R1), (M2, L2, c2, R2)):
        It = m * l**2 / 12
        I = sp.diag(It, It, It * 1e-3)  # rf.samples.rod_inertia: axial moment 1e-3 of the transverse one
        v = c.jacobian(qv) * qdv
        Rdot = sum((R.diff(qi) * qdi for qi, qdi in zip(q, qd)), sp.zeros(3, 3))
        W = R.T * Rdot  # S(ω) in body axes
        w = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
        T += (m * v.dot(v) + (w.T * I * w)[0]) / 2
        V += m * G * c[2]
    Lag = T - V
    Mm = sp.hessian(T, qd)
    # M q̈ = ∂L/∂q − (∂²L/∂q̇∂q) q̇
    f = sp.Matrix([Lag.diff(qi) for qi in q]) - sp.Matrix([Lag.diff(qdi) for qdi in qd]).jacobian(qv) * qdv
    return q, qd, Mm, f


@functools.lru_cache
def sympy_equations(spatial):
    """Returns numeric functions M(q) and f(q, qd) of M q̈ = f from the Lagrangian."""
    q, qd, Mm, f = sympy_lagrange(spatial)
    Mf = sp.lambdify([q], Mm, cse=True)
    ff = sp.lambdify([q, qd], f, cse=True)
    return (lambda x: np.array(Mf(x), float)), (lambda x, xd: np.array(ff(x, xd), float).ravel())


@functools.lru_cache
def sympy_residual_derivatives(spatial):
    """Numeric ∂r/∂q and ∂r/∂q̇ of the residual r = M(q) q̈ − f(q, q̇), differentiated symbolically."""
    q, qd, Mm, f = sympy_lagrange(spatial)
    qdd = sp.symbols(f"qdd0:{len(q)}")
    r = Mm * sp.Matrix(qdd) - f
    drdq = sp.lambdify([q, qd, qdd], r.jacobian(sp.Matrix(q)), cse=True)
    drdqd = sp.lambdify([q, qd, qdd], r.jacobian(sp.Matrix(qd)), cse=True)
    return (lambda *x: np.array(drdq(*x), float)), (lambda *x: np.array(drdqd(*x), float))


@pytest.mark.parametrize("algorithm", ["lagrange", "recursive"])
@pytest.mark.parametrize("spatial", [False, True])
def test_mass_matrix_and_accelerations_against_sympy(spatial, algorithm, rng):
    model, _ = rf.samples.double_pendulum(lengths=(L1, L2), masses=(M1, M2), spatial=spatial, gravity=G)
    system = model.compile(algorithm)
    M_ref, f_ref = sympy_equations(spatial)
    for _ in range(5):
        q = rng.uniform(-1.2, 1.2, system.nq)
        qd = rng.uniform(-3, 3, system.nq)
        M = system.mass_matrix(0.0, q)
        np.testing.assert_allclose(M, M_ref(q), rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(system.generalized_forces(0.0, q, qd), f_ref(q, qd), rtol=1e-11, atol=1e-11)
        # Solving A q̈ = f amplifies round-off by cond(A) (~1e6 here: the rods' axial inertia is
        # 1e-3 of the transverse one), in the reference's solve as in ours.
        qdd_ref = np.linalg.solve(M_ref(q), f_ref(q, qd))
        tol = max(1e-10, 1e-14 * np.linalg.cond(M)) * np.max(np.abs(qdd_ref))
        np.testing.assert_allclose(system.forward_dynamics(0.0, q, qd), qdd_ref, rtol=0, atol=tol)


@pytest.mark.parametrize("spatial", [False])  # the spatial derivation takes SymPy minutes: see test_derivatives
def test_analytic_derivatives_against_sympy(spatial, rng):
    """The recursive engine's ∂r/∂q, ∂r/∂q̇ (tangent RNEA) and ∂q̈/∂(q, q̇) = −A⁻¹ ∂r against
    SymPy's derivatives of the Lagrangian equations (planar)."""
    model, _ = rf.samples.double_pendulum(lengths=(L1, L2), masses=(M1, M2), spatial=spatial, gravity=G)
    system = model.compile("recursive")
    M_ref, f_ref = sympy_equations(spatial)
    drdq_ref, drdqd_ref = sympy_residual_derivatives(spatial)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.2, 1.2, system.nq), rng.uniform(-3, 3, system.nq), rng.normal(0, 5, system.nq)
        drdq, drdqd = system.inverse_dynamics_derivatives(0.0, q, qd, qdd)
        Kref, Cref = drdq_ref(q, qd, qdd), drdqd_ref(q, qd, qdd)
        np.testing.assert_allclose(drdq, Kref, rtol=0, atol=1e-11 * np.abs(Kref).max())
        np.testing.assert_allclose(drdqd, Cref, rtol=0, atol=1e-11 * np.abs(Cref).max())
        # At the forward-dynamics accelerations: ∂q̈/∂x = −M⁻¹ ∂r/∂x.
        qdd0 = np.linalg.solve(M_ref(q), f_ref(q, qd))
        Mref = M_ref(q)
        dq, dqd = system.acceleration_derivatives(0.0, q, qd)
        for got, ref in ((dq, -np.linalg.solve(Mref, drdq_ref(q, qd, qdd0))),
                         (dqd, -np.linalg.solve(Mref, drdqd_ref(q, qd, qdd0)))):
            tol = max(1e-10, 1e-14 * np.linalg.cond(Mref)) * np.abs(ref).max()
            np.testing.assert_allclose(got, ref, rtol=0, atol=tol)


def test_planar_mass_matrix_closed_form():
    """The textbook closed form for two uniform rods."""
    model, _ = rf.samples.double_pendulum(lengths=(L1, L2), masses=(M1, M2))
    system = model.compile()
    for q2 in (0.0, 0.7, 2.5):
        c = np.cos(q2)
        a11 = M1 * L1**2 / 3 + M2 * L1**2 + M2 * L2**2 / 3 + M2 * L1 * L2 * c
        a12 = M2 * L2**2 / 3 + M2 * L1 * L2 * c / 2
        a22 = M2 * L2**2 / 3
        np.testing.assert_allclose(system.mass_matrix(0.0, [0.3, q2]), [[a11, a12], [a12, a22]], rtol=1e-13)
