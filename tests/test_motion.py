"""Prescribed motions of rigidfem.motion: closed forms, rates by finite differences,
Kane's spin-up, natural cubic splines (against scipy) and bad input."""

import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from rigidfem import motion

SPLINE_T = np.array([0.0, 0.3, 0.7, 1.5, 2.0, 3.1])
SPLINE_Q = np.array([0.2, -0.5, 1.1, 0.4, 2.0, -0.3])


def state(p, t):
    out = p(t)
    assert len(out) == 3
    return np.array(out, dtype=float)


# --- closed forms --------------------------------------------------------------------------


@pytest.mark.parametrize("t", [-2.0, 0.0, 0.5, 17.0])
def test_constant(t):
    np.testing.assert_array_equal(state(motion.constant(2.5), t), [2.5, 0.0, 0.0])


@pytest.mark.parametrize(
    "c", [[3.0], [1.0, -2.0], [0.5, 0.0, 3.0], [1.0, -2.0, 0.5, 0.25, -0.125], [0.0, 0.0, 0.0, 0.0, 0.0, 2.0]]
)
@pytest.mark.parametrize("t", [-1.3, 0.0, 0.4, 2.7])
def test_polynomial(c, t):
    P = np.polynomial.Polynomial(c)
    q, qd, qdd = state(motion.polynomial(c), t)
    assert q == pytest.approx(P(t), rel=1e-13, abs=1e-13)
    assert qd == pytest.approx(P.deriv(1)(t), rel=1e-13, abs=1e-13)
    assert qdd == pytest.approx(P.deriv(2)(t), rel=1e-13, abs=1e-13)


def test_polynomial_explicit_cubic():
    # q = 1 + 2t + 3t² + 4t³ at t = 2: 49; q̇ = 2 + 6t + 12t² = 62; q̈ = 6 + 24t = 54.
    np.testing.assert_allclose(state(motion.polynomial([1, 2, 3, 4]), 2.0), [49.0, 62.0, 54.0], rtol=1e-15)


@pytest.mark.parametrize("A, w, phase, offset", [(1.0, 1.0, 0.0, 0.0), (0.3, 4.0, 0.7, -1.2), (-2.0, 0.5, -1.0, 3.0)])
@pytest.mark.parametrize("t", [0.0, 0.37, 2.9])
def test_harmonic(A, w, phase, offset, t):
    s, c = math.sin(w * t + phase), math.cos(w * t + phase)
    expected = [offset + A * s, A * w * c, -A * w**2 * s]
    np.testing.assert_allclose(state(motion.harmonic(A, w, phase, offset), t), expected, rtol=1e-14, atol=1e-14)


def test_harmonic_defaults():
    s, c = math.sin(0.75), math.cos(0.75)
    np.testing.assert_allclose(state(motion.harmonic(2.0, 3.0), 0.25), [2 * s, 6 * c, -18 * s], rtol=1e-14)


def test_function_passes_values_through_in_order():
    p = motion.function(lambda t: (t + 1.0, 2.0 * t, -3.0))
    np.testing.assert_array_equal(state(p, 0.5), [1.5, 1.0, -3.0])


# --- Kane's spin-up ------------------------------------------------------------------------


def kane(W, T, t):
    if t < T:
        k = 2 * math.pi / T
        q = (W / T) * (t**2 / 2 + (T / (2 * math.pi)) ** 2 * (math.cos(k * t) - 1))
        qd = (W / T) * (t - math.sin(k * t) / k)
        qdd = (W / T) * (1 - math.cos(k * t))
        return [q, qd, qdd]
    return [W * (t - T / 2), W, 0.0]


@pytest.mark.parametrize("W, T", [(6.0, 15.0), (4.0, 1.0), (-2.5, 0.8)])
def test_spin_up_kane_formula(W, T):
    for t in np.linspace(0.0, 2.0 * T, 23):
        np.testing.assert_allclose(
            state(motion.spin_up(W, T), t), kane(W, T, t), rtol=1e-12, atol=1e-12, err_msg=f"t={t}"
        )


@pytest.mark.parametrize("W, T", [(6.0, 15.0), (4.0, 1.0)])
def test_spin_up_continuity_at_the_end_of_the_ramp(W, T):
    p = motion.spin_up(W, T)
    eps = 1e-9 * T
    before, at, after = state(p, T - eps), state(p, T), state(p, T + eps)
    np.testing.assert_allclose(before, after, atol=1e-7 * max(1.0, abs(W)))
    np.testing.assert_allclose(at, [W * T / 2, W, 0.0], atol=1e-12)
    assert at[1] == W  # q̇(T) = Ω exactly
    # starts at rest
    np.testing.assert_allclose(state(p, 0.0), [0.0, 0.0, 0.0], atol=1e-15)
    # the acceleration peaks mid-ramp at 2Ω/T
    assert state(p, T / 2)[2] == pytest.approx(2 * W / T, rel=1e-12)


# --- natural cubic spline ------------------------------------------------------------------


@pytest.mark.parametrize(
    "t, q",
    [
        (SPLINE_T, SPLINE_Q),
        ([0.0, 1.0], [1.0, 3.0]),  # two points: a straight line
        ([-1.0, 0.5, 2.0], [0.0, 2.0, -1.0]),
        (np.linspace(0, 1, 11), np.sin(3 * np.linspace(0, 1, 11))),
        # unevenly spaced knots: the interval found by bisection where the even-spacing guess misses
        (np.cumsum(np.r_[0.0, np.random.default_rng(3).uniform(0.05, 1.0, 40)]), np.cos(np.arange(41.0))),
    ],
)
def test_spline_matches_scipy_natural_cubic_spline(t, q):
    t, q = np.asarray(t, float), np.asarray(q, float)
    cs = CubicSpline(t, q, bc_type="natural")
    p = motion.spline(t, q)
    grid = np.concatenate([np.linspace(t[0], t[-1], 97), t])  # interior and knots
    got = np.array([state(p, x) for x in grid])
    scale = max(1.0, np.abs(cs(grid, 2)).max())
    np.testing.assert_allclose(got[:, 0], cs(grid), atol=1e-12 * scale)
    np.testing.assert_allclose(got[:, 1], cs(grid, 1), atol=1e-12 * scale)
    np.testing.assert_allclose(got[:, 2], cs(grid, 2), atol=1e-12 * scale)


def test_spline_extrapolates_linearly_with_the_end_slopes():
    cs = CubicSpline(SPLINE_T, SPLINE_Q, bc_type="natural")
    p = motion.spline(SPLINE_T, SPLINE_Q)
    t0, t1 = SPLINE_T[0], SPLINE_T[-1]
    s0, s1 = cs(t0, 1), cs(t1, 1)
    assert abs(s0) > 0.1 and abs(s1) > 0.1  # the test means something
    for dt in [1e-9, 0.01, 0.5, 3.0]:
        np.testing.assert_allclose(state(p, t0 - dt), [SPLINE_Q[0] - s0 * dt, s0, 0.0], atol=1e-12)
        np.testing.assert_allclose(state(p, t1 + dt), [SPLINE_Q[-1] + s1 * dt, s1, 0.0], atol=1e-12)


def test_spline_accepts_lists_and_interpolates_the_table():
    p = motion.spline(list(SPLINE_T), list(SPLINE_Q))
    np.testing.assert_allclose([p(x)[0] for x in SPLINE_T], SPLINE_Q, atol=1e-14)


# --- rates against finite differences of q, for every profile type --------------------------

PROFILES = {
    "constant": lambda: motion.constant(-0.7),
    "polynomial": lambda: motion.polynomial([0.3, -1.0, 0.5, 0.2, -0.05]),
    "harmonic": lambda: motion.harmonic(0.8, 2.5, 0.4, 0.1),
    "spin_up": lambda: motion.spin_up(3.0, 2.0),
    "spline": lambda: motion.spline(SPLINE_T, SPLINE_Q),
    "function": lambda: motion.function(lambda t: (math.exp(t / 2), math.exp(t / 2) / 2, math.exp(t / 2) / 4)),
}
# away from the spline knots and from the end of the spin-up ramp (t = 2)
FD_TIMES = [-0.6, 0.11, 0.52, 1.23, 1.77, 2.61, 3.4, 4.3]


@pytest.mark.parametrize("name", PROFILES)
def test_rates_against_finite_differences(name):
    p = PROFILES[name]()
    q = lambda t: p(t)[0]  # noqa: E731
    for t in FD_TIMES:
        _, qd, qdd = p(t)
        h1, h2 = 1e-6, 1e-4
        fd1 = (q(t + h1) - q(t - h1)) / (2 * h1)
        fd2 = (q(t + h2) - 2 * q(t) + q(t - h2)) / h2**2
        assert qd == pytest.approx(fd1, abs=1e-7), f"{name} qd at t={t}"
        assert qdd == pytest.approx(fd2, abs=1e-5), f"{name} qdd at t={t}"


# --- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize("duration", [0.0, -1.0, float("nan"), float("inf")])
def test_spin_up_bad_duration(duration):
    with pytest.raises(ValueError, match=r"^duration\b"):
        motion.spin_up(1.0, duration)


def test_spin_up_bad_omega():
    with pytest.raises(ValueError, match=r"^omega\b"):
        motion.spin_up(float("nan"), 1.0)


@pytest.mark.parametrize(
    "t, q, argument",
    [
        ([0.0, 1.0, 1.0, 2.0], [0, 1, 2, 3], "t"),  # repeated time
        ([0.0, 2.0, 1.0], [0, 1, 2], "t"),  # decreasing
        ([1.0, 0.0], [0, 1], "t"),
        ([0.0, 1.0, 2.0], [0, 1], "q"),  # len(q) != len(t)
        ([0.0, 1.0], [0, 1, 2], "q"),
        ([0.0, float("nan"), 2.0], [0, 1, 2], "t"),
        ([0.0, 1.0, 2.0], [0, float("nan"), 2], "q"),
        ([0.0, 1.0, float("inf")], [0, 1, 2], "t"),
        ([0.0], [1.0], "t"),  # fewer than 2 points
        ([], [], "t"),
    ],
)
def test_spline_bad_input(t, q, argument):
    with pytest.raises(ValueError, match=rf"^{argument}\b"):
        motion.spline(t, q)


@pytest.mark.parametrize("f", [3.0, None, "sin", (1.0, 0.0, 0.0)])
def test_function_needs_a_callable(f):
    with pytest.raises(ValueError, match=r"^f\b"):
        motion.function(f)


@pytest.mark.parametrize(
    "make, argument",
    [
        (lambda: motion.constant(float("nan")), "value"),
        (lambda: motion.polynomial([]), "coefficients"),
        (lambda: motion.polynomial([1.0, float("inf")]), "coefficients"),
        (lambda: motion.harmonic(float("nan"), 1.0), "amplitude"),
        (lambda: motion.harmonic(1.0, float("inf")), "omega"),
        (lambda: motion.harmonic(1.0, 1.0, phase=float("nan")), "phase"),
        (lambda: motion.harmonic(1.0, 1.0, offset=float("nan")), "offset"),
    ],
)
def test_other_non_finite_parameters(make, argument):
    with pytest.raises(ValueError, match=rf"^{argument}\b"):
        make()
