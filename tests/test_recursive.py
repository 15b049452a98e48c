"""The recursive algorithms (RNEA, CRBA, ABA) against the book's Lagrange formulation on
random trees (hypothesis): the same q̈, mass matrix, right-hand side and driving forces."""

import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rigidfem as rf


def scale(x):
    return max(1.0, np.max(np.abs(x), initial=0.0))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nbodies=st.integers(1, 9))
def test_recursive_equals_lagrange_on_random_trees(seed, nbodies):
    model, _, rng = rf.samples.random_tree(seed, nbodies)
    lag, rec = model.compile("lagrange"), model.compile("recursive")
    assert (lag.algorithm, rec.algorithm) == ("lagrange", "recursive")
    if rec.nq == 0:
        return
    for _ in range(2):
        # Angles within ±1 rad keep every ZYX joint far from gimbal lock.
        q, qd, t = rng.uniform(-1, 1, rec.nq), rng.uniform(-2, 2, rec.nq), float(rng.uniform(0, 5))
        A = lag.mass_matrix(t, q)
        cond = np.linalg.cond(A)
        np.testing.assert_allclose(rec.mass_matrix(t, q), A, rtol=0, atol=1e-12 * scale(A))
        f = lag.generalized_forces(t, q, qd)
        np.testing.assert_allclose(rec.generalized_forces(t, q, qd), f, rtol=0, atol=1e-12 * scale(f))
        qdd = lag.forward_dynamics(t, q, qd)
        # Both solve the same equations: agreement to round-off amplified by cond(A).
        np.testing.assert_allclose(rec.forward_dynamics(t, q, qd), qdd, rtol=0,
                                   atol=max(1e-10, 1e-14 * cond) * scale(qdd))
        tau = lag.driving_forces(t, q, qd)
        np.testing.assert_allclose(rec.driving_forces(t, q, qd), tau, rtol=0,
                                   atol=max(1e-10, 1e-14 * cond) * scale(tau) * scale(qdd))


def test_linear_beam_models_use_lagrange():
    model, _ = rf.samples.kane_beam(elements=4, linear=True)
    assert model.compile("recursive").algorithm == "lagrange"
    with pytest.raises(ValueError, match="^algorithm"):
        model.compile("featherstone")


def test_one_system_shared_by_threads_gives_identical_results():
    model, _, rng = rf.samples.random_tree(7, 8)
    system = model.compile("recursive")
    q, qd = rng.uniform(-1, 1, system.nq), rng.uniform(-1, 1, system.nq)
    expected = rf.simulate(system, 1.0, method="dopri5", rtol=1e-9, q0=q, qd0=qd, stiffness_warning=False).q
    results = [None] * 4

    def job(k):
        results[k] = rf.simulate(system, 1.0, method="dopri5", rtol=1e-9, q0=q, qd0=qd, stiffness_warning=False).q

    threads = [threading.Thread(target=job, args=(k,)) for k in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for r in results:
        np.testing.assert_array_equal(r, expected)


@pytest.mark.parametrize("size", [1.0, 1e-20])
@pytest.mark.parametrize("slender", [1.0, 1e-4, 1e-8])
@pytest.mark.parametrize("principal", [True, False])
def test_spherical_joints_on_slender_bodies_equal_lagrange(slender, principal, size):
    """A body on three free rotations (a spherical joint, an rfe of the modified formulation) takes the
    articulated-body algorithm's fixed-size path, whose 3 × 3 D = Sᵀ I^A S is inverted from its leading
    minors (the three divisions side by side): against the Lagrange formulation on a tree of spherical
    joints with a driven revolute and a prismatic joint in it; slender bodies (an axial moment down to
    1e-8 of the others, the centre of mass on that axis: the leaf's D ill-conditioned; the others carry
    their children off that axis); inertias on or off their principal axes (D graded or not); placements
    turned or only shifted (the frames' shortcut for a placement without rotation); and bodies of 1e-20 kg
    (springs and dampers scaled alike), whose D's minors are out of range, so that the inverse takes the
    elimination in its own order."""
    rng = np.random.default_rng(3)
    model = rf.Model(gravity=(0.3, -9.81, 1.2))
    parent = model.ground
    bodies = []
    for k in range(7):
        if k == 3:
            joint = rf.Joint.revolute("y")
        elif k == 5:
            joint = rf.Joint.prismatic("z", stiffness=20.0 * size)
        else:
            joint = rf.Joint.spherical(stiffness=float(rng.uniform(1, 30)) * size, damping=0.1 * size)
        moments = np.array([slender, 1.0, 1.0]) * 0.02 * size
        R = np.eye(3) if principal else rf.transform(euler_zyx=rng.uniform(-1, 1, 3))[:3, :3]
        parent = model.add_body(f"b{k}", parent if k != 4 else bodies[1], joint,
                                mass=float(rng.uniform(0.5, 2)) * size,
                                com=0.25 * R[:, 0],  # on the slender axis: D's small eigenvalue stays small
                                inertia=R @ np.diag(moments) @ R.T,
                                placement=rf.transform(translation=(0.5, 0.0, 0.1),
                                                       euler_zyx=rng.uniform(-1, 1, 3) if k % 2 else (0, 0, 0)))
        bodies.append(parent)
    model.prescribe(bodies[3], rf.motion.harmonic(0.4, 2.0))
    lag, rec = model.compile("lagrange"), model.compile("recursive")
    for _ in range(3):
        q, qd, t = rng.uniform(-1.2, 1.2, rec.nq), rng.uniform(-2, 2, rec.nq), float(rng.uniform(0, 2))
        A = lag.mass_matrix(t, q)
        cond = np.linalg.cond(A)
        np.testing.assert_allclose(rec.mass_matrix(t, q), A, rtol=0, atol=1e-12 * np.abs(A).max())
        f = lag.generalized_forces(t, q, qd)
        np.testing.assert_allclose(rec.generalized_forces(t, q, qd), f, rtol=0, atol=1e-12 * np.abs(f).max())
        qdd = lag.forward_dynamics(t, q, qd)
        np.testing.assert_allclose(rec.forward_dynamics(t, q, qd), qdd, rtol=0,
                                   atol=max(1e-10, 1e-14 * cond) * np.abs(qdd).max())


def spherical_chain(bodies=4, driven=False):
    """``bodies`` bodies on spherical joints (ZYX angles) with springs and dampers, under gravity; ``driven``:
    each joint slides along x first by a prescribed harmonic motion (a flow's rfe alike)."""
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    parent = model.ground
    for k in range(bodies):
        joint = rf.Joint.custom(["x", "rz", "ry", "rx"], stiffness=[0, 5, 5, 5], damping=[0, 0.05, 0.05, 0.05]) \
            if driven else rf.Joint.spherical(stiffness=5.0, damping=0.05)
        parent = model.add_body(f"b{k}", parent, joint,
                                mass=1.0, com=(0.3, 0.05, 0.0), inertia=np.diag([0.01, 0.02, 0.025]),
                                placement=rf.transform(translation=(0.6, 0.0, 0.0)))
        if driven:
            model.prescribe(parent, rf.motion.harmonic(0.01, 3.0), "x")
    return model.compile("lagrange"), model.compile("recursive")


@pytest.mark.parametrize("driven", [False, True])
@pytest.mark.parametrize("offset", [1e-1, 1e-2, 1e-4, 1e-6])
def test_spherical_chain_near_gimbal_lock_equals_lagrange(offset, driven):
    """A chain of spherical joints within ``offset`` rad of pitch π/2, where the axes' matrix E has
    |det E| = |cos φ2| and D = Sᵀ I^A S = Eᵀ Q E of each body is ill-conditioned (check_gimbal_lock stops at
    1e-9; within 1e-2 the articulated-body algorithm factorises such a body about its pivot, Q), also behind
    a prescribed slide: the accelerations equal the Lagrange formulation's to round-off amplified by cond(A)
    and satisfy A q̈ = f to ε / |det E|, and their derivatives (factorised with a zero armature) equal the
    Lagrange formulation's differences (D's own inverse failed its Sylvester test at 1e-6)."""
    rng = np.random.default_rng(11)
    lag, rec = spherical_chain(driven=driven)
    q, qd = rng.uniform(-0.5, 0.5, rec.nq), rng.uniform(-1, 1, rec.nq)
    q[1::3] = np.pi / 2 - offset  # every joint's pitch φ2 (coordinates rz, ry, rx)
    t = 0.1
    A = lag.mass_matrix(t, q)
    cond = np.linalg.cond(A)
    assert cond > 0.1 / offset**2
    qdd = lag.forward_dynamics(t, q, qd)
    x = rec.forward_dynamics(t, q, qd)
    np.testing.assert_allclose(x, qdd, rtol=0, atol=max(1e-10, 1e-14 * cond) * scale(qdd))
    # the residual of the equations of motion, which cond(A) does not amplify the way it does q̈'s error
    f = lag.generalized_forces(t, q, qd)
    assert np.abs(A @ x - f).max() <= max(1e-12, 1e-15 / offset) * (np.abs(A).max() * np.abs(x).max() + np.abs(f).max())
    # the derivatives factorise with a zero armature; the Lagrange formulation's are central differences
    # (test_derivatives.py holds them to max(1e-6, 1e-12 cond(A)))
    for expected, got in zip(lag.acceleration_derivatives(t, q, qd), rec.acceleration_derivatives(t, q, qd)):
        np.testing.assert_allclose(got, expected, rtol=0, atol=max(1e-6, 1e-12 * cond) * scale(expected))


def test_spherical_chain_released_near_gimbal_lock_moves_as_lagrange():
    """Released 1e-3 rad from gimbal lock (its first steps' factorisations about the pivots), radau5 and
    dopri5 runs of the recursive system follow the Lagrange system's runs to the tolerance asked."""
    lag, rec = spherical_chain(3)
    q0 = np.tile([0.3, np.pi / 2 - 1e-3, -0.2], 3)
    for method in ("radau5", "dopri5"):
        runs = [rf.simulate(system, 0.05, method=method, rtol=1e-10, atol=1e-12, q0=q0, stiffness_warning=False)
                for system in (lag, rec)]
        np.testing.assert_allclose(runs[1].q[-1], runs[0].q[-1], rtol=0, atol=1e-7)
