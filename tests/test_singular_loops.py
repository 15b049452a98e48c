"""Closed chains through singular positions (issue 27, item 3).

``samples.double_four_bar``: two parallelogram four-bars in a row, released from rest 0.3 rad above
the horizontal, swing through their flat positions (θ = 0 and −π, where each loop's Jacobian loses
a row and the antiparallelogram branch crosses) 23 times in 10 s. The reference is the same linkage
in its one minimal coordinate θ (all rockers at θ, couplers translating), a pendulum integrated by
SciPy at rtol 1e-13; energy is conserved (no damping).
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rigidfem as rf
from rigidfem import samples

L, W, M, MC, G0 = 0.5, 1.0, 1.0, 2.0, 9.81
TH0, T_END = 0.3, 10.0
BRANCH = np.array([1.0, 1.0, 1.0, -1.0, -1.0])  # (r0, r1, r2, c1, c2) on the parallelogram branch


@pytest.fixture(scope="module")
def system():
    model, _ = samples.double_four_bar(rocker=L, span=W, rocker_mass=M, coupler_mass=MC)
    return model.compile()


@pytest.fixture(scope="module")
def reference():
    """θ(t) of the minimal model: (3 m L²/3 + 2 m_c L²) θ̈ = −g cos θ (3 m L/2 + 2 m_c L)."""
    inertia = 3 * M * L**2 / 3 + 2 * MC * L**2
    moment = G0 * (3 * M * L / 2 + 2 * MC * L)
    sol = solve_ivp(lambda t, y: [y[1], -moment * np.cos(y[0]) / inertia], (0.0, T_END), [TH0, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-14, dense_output=True)
    return sol.sol


def energy(system, q, qd):
    return system.kinetic_energy(0.0, q, qd) + system.potential_energy(0.0, q)


def test_the_swing_passes_the_singular_positions(system, reference):
    """The reference crosses sin θ = 0 many times, and G (10 rows) has rank 4 off them, 2 on them."""
    th = reference(np.linspace(0.0, T_END, 20001))[0]
    assert np.count_nonzero(np.diff(np.sign(np.sin(th)))) >= 20
    for theta, rank in ((0.7, 4), (0.0, 2), (-np.pi, 2)):
        _, _, G = system.loop_constraints(0.0, BRANCH * theta, np.zeros(5))
        s = np.linalg.svd(G, compute_uv=False)
        assert np.count_nonzero(s > 1e-9 * s[0]) == rank


# Measured θ(10) errors: radau5 7e-9, 9e-9, 2e-8; esdirk43 1e-6; dopri5 3e-8 (before the fix each of
# these runs failed). Without passages (released below the horizontal) the same runs reach 2e-11,
# 9e-13, 3e-12, 2e-7, 4e-9: the passages add ~1e-8 to the tight runs.
@pytest.mark.parametrize("method, rtol, bound", [
    ("radau5", 1e-9, 1e-7), ("radau5", 1e-10, 1e-7), ("radau5", 1e-11, 1e-7),
    ("esdirk43", 1e-8, 1e-5), ("dopri5", 1e-10, 2e-7),
])
def test_tight_tolerances_pass_the_singular_positions(system, reference, method, rtol, bound):
    res = rf.simulate(system, T_END, method=method, rtol=rtol, atol=rtol / 100, q0=BRANCH * TH0, qd0=np.zeros(5))
    assert res.t[-1] == T_END
    # still on the parallelogram branch (the antiparallelogram one crosses it at every passage)
    np.testing.assert_allclose(res.q[-1], BRANCH * res.q[-1, 0], atol=1e-8)
    assert abs(res.q[-1, 0] - reference(T_END)[0]) < bound
    E = [energy(system, q, qd) for q, qd in zip(res.q, res.qd)]
    assert np.ptp(E) < 1e3 * rtol + 1e-7


def run_rk4(system, dt):
    return rf.simulate(system, T_END, method="rk4", dt=dt, q0=BRANCH * TH0, qd0=np.zeros(5))


@pytest.fixture(scope="module")
def rk4_runs(system):
    return {dt: run_rk4(system, dt) for dt in (4e-3, 2e-3, 1e-3)}


def test_rk4_converges_at_fourth_order_through_the_passages(system, reference, rk4_runs):
    """θ(10) errors at dt = 4, 2, 1 ms (measured 2.1e-8, 1.6e-9, 2.1e-10; before: 3e-8 to 8e-4, no
    convergence): the order between 4 and 2 ms is 3.7; at 1 ms the passages' floor (~1.4e-10, also
    at 0.5 ms) shows, still 100 times below the old error."""
    err = {dt: abs(r.q[-1, 0] - reference(T_END)[0]) for dt, r in rk4_runs.items()}
    assert np.log2(err[4e-3] / err[2e-3]) > 3.4
    assert err[2e-3] > 4 * err[1e-3]
    assert err[1e-3] < 5e-10


def test_energy_is_not_lost_in_the_projection_at_a_passage(system, rk4_runs):
    """rk4's energy change over each step at 2 ms: at a passage (|sin θ| < 0.01 at either end) within 10 times the
    integrator's own change elsewhere (3.9e-11 J at most). Rounding, amplified near the singular position, scatters
    the ratio: 0.4-2.5 over eight starts 1e-9 rad apart with libm's sine and cosine, 0.5-4.1 with the core's.
    Before the fix one step lost 4.7e-5 J, a million times more."""
    r = rk4_runs[2e-3]
    E = np.array([energy(system, q, qd) for q, qd in zip(r.q, r.qd)])
    near = np.abs(np.sin(r.q[:, 0])) < 0.01
    passage = near[:-1] | near[1:]
    assert passage.sum() >= 20
    step = np.abs(np.diff(E))
    assert step[passage].max() < 10 * step[~passage].max() + 1e-12
    assert abs(E[-1] - E[0]) < 1e-8


def test_velocity_projection_is_mass_weighted_at_a_singular_position(system):
    """Projected at the flat position θ = 0 from a rate off the branch, q̇ keeps the admissible part
    of the motion: the kinetic energy never rises, and a rate on the branch is left as it is."""
    q = np.zeros(5)
    on = BRANCH * 3.0
    q_on, qd_on = system.assemble(q, on, t=0.0)
    np.testing.assert_allclose(qd_on, on, atol=1e-12)
    rng = np.random.default_rng(3)
    for _ in range(5):
        qd = on + rng.normal(0.0, 0.1, 5)
        _, qd_p = system.assemble(q, qd, t=0.0)
        assert system.kinetic_energy(0.0, q, qd_p) <= system.kinetic_energy(0.0, q, qd) + 1e-12
        g, gd, _ = system.loop_constraints(0.0, q, qd_p)
        assert np.abs(gd).max() < 1e-12


def _pseudo_inverse(A, b):
    """A⁺ b by numpy's eigh: eigenvalues at most 1e-10 of the largest count as zero."""
    lam, V = np.linalg.eigh(A)
    keep = lam > 1e-10 * lam.max() if lam.max() > 0 else np.zeros(len(lam), bool)
    c = V.T @ b
    c[keep] /= lam[keep]
    c[~keep] = 0.0
    return V @ c


@pytest.mark.parametrize("n, rank, zero_rows, gap", [(5, 4, 0, 0.0), (5, 2, 3, 0.0), (6, 6, 0, 0.0), (8, 5, 1, 0.0),
                                                     (5, 5, 0, 1e-4), (5, 5, 0, 1e-8), (5, 5, 0, 1e-12), (12, 9, 2, 0.0),
                                                     (3, 0, 3, 0.0)])
def test_the_loops_least_norm_solve_is_the_pseudo_inverse(n, rank, zero_rows, gap):
    """The solve of the loops' G M⁻¹ Gᵀ λ = r: exact dependencies (a Bricard linkage's redundant row, a planar
    loop's zero rows out of its plane), a smallest eigenvalue 1e-4 or 1e-8 of the largest (kept) or 1e-12
    (dropped), more rows than the small path takes; against numpy's eigendecomposition with the same floor."""
    rng = np.random.default_rng(n * 100 + rank + zero_rows)
    for _ in range(20):
        B = rng.normal(size=(n, max(rank, 1))) * (rank > 0)
        if gap:
            B[:, -1] *= np.sqrt(gap) * np.linalg.norm(B[:, :-1], 2)
        B[rng.permutation(n)[:zero_rows]] = 0.0
        A = B @ B.T
        b = rng.normal(size=n)
        x = rf._core._least_norm_symmetric(A, b)
        expected = _pseudo_inverse(A, b)
        scale = max(1.0, np.abs(expected).max())
        # to the round-off the conditioning of the eigenvalues kept allows
        lam = np.linalg.eigvalsh(A)
        kept = lam[lam > 1e-10 * lam.max()] if lam.max() > 0 else np.ones(1)
        np.testing.assert_allclose(x, expected, rtol=0, atol=max(1e-10, 1e-14 * kept.max() / kept.min()) * scale)
    with pytest.raises(ValueError, match="A, b"):
        rf._core._least_norm_symmetric(np.eye(3), np.ones(2))


def test_the_loops_least_norm_solve_keeps_to_a_given_rank_where_the_rest_is_small():
    """A step's stage off the loops by a drift δ: A = B Bᵀ (rank r, a redundant row's exact dependency) plus δ² u uᵀ.
    Kept to rank r, the solve is B Bᵀ's pseudo-inverse to O(δ²) (the δ² direction's multiplier, of order 1/δ², left
    out); without the rank it counts that direction (above 1e-10 of the largest eigenvalue); and where the rest is not
    small (δ² = 1e-3 of the trace, over the 1e-6 allowed) the rank is not imposed."""
    rng = np.random.default_rng(5)
    for n, r in ((5, 4), (6, 3), (8, 7), (12, 9)):  # the last by the eigendecomposition
        B = rng.normal(size=(n, r))
        A0, b = B @ B.T, rng.normal(size=n)
        exact = _pseudo_inverse(A0, b)
        u = np.linalg.svd(B.T)[2][-1]  # a unit vector out of B's range, where the drift's eigenvalue grows
        for d2 in (1e-8, 1e-7):
            A = A0 + d2 * np.trace(A0) * np.outer(u, u)
            kept = rf._core._least_norm_symmetric(A, b, r)
            lam = np.linalg.eigvalsh(A0)[n - r:]
            assert np.abs(kept - exact).max() < 10 * d2 * (lam[-1] / lam[0]) ** 2 * np.abs(exact).max()
            counted = rf._core._least_norm_symmetric(A, b)
            np.testing.assert_allclose(counted, _pseudo_inverse(A, b), rtol=1e-5)
            assert np.abs(counted - exact).max() > 1e3 * np.abs(exact).max()
        A = A0 + 1e-3 * np.trace(A0) * np.outer(u, u)
        np.testing.assert_allclose(rf._core._least_norm_symmetric(A, b, r), _pseudo_inverse(A, b), rtol=1e-8)


def test_the_loops_least_norm_solve_follows_a_reordering_of_the_rows():
    """Reordering the rows and columns of A (and b) reorders x alike: the pivots' permutation undone; and a
    symmetric A that is not semi-definite (off the loops' G M⁻¹ Gᵀ) gets the eigendecomposition's answer, its
    negative eigenvalue counted as zero."""
    rng = np.random.default_rng(11)
    for n, rank in ((5, 4), (6, 3), (8, 7), (4, 4)):
        B = rng.normal(size=(n, rank))
        A, b = B @ B.T, rng.normal(size=n)
        x = rf._core._least_norm_symmetric(A, b)
        for _ in range(5):
            perm = rng.permutation(n)
            y = rf._core._least_norm_symmetric(A[np.ix_(perm, perm)], b[perm])
            np.testing.assert_allclose(y, x[perm], rtol=0, atol=1e-10 * max(1.0, np.abs(x).max()))
    A = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    x = rf._core._least_norm_symmetric(A, np.ones(3))
    np.testing.assert_allclose(x, _pseudo_inverse(A, np.ones(3)), atol=1e-14)
