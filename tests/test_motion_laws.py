"""Rest-to-rest laws, ramps and the algebra of profiles (issue 28, item 5): each law against its SymPy
derivatives, rest outside the move, ramps against the quadrature of their rates, sums, shifts and
piecewise joins against their parts, pickling, bad input, and a beam's root joint driven in C++ against
the same law as a Python function (the slow path)."""

import math
import pickle

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import quad

import rigidfem as rf
from rigidfem import motion

TAU = sp.Symbol("tau")
F = sp.Rational(1, 4)  # the trapezoidal law's acceleration share in these tests


def sympy_law(law: str):
    """s(τ) on [0, 1] written from its definition, independently of the C++ code."""
    if law == "quintic":
        return 10 * TAU**3 - 15 * TAU**4 + 6 * TAU**5
    if law == "cycloidal":
        return TAU - sp.sin(2 * sp.pi * TAU) / (2 * sp.pi)
    v = 1 / (1 - F)  # trapezoidal: s'' = v/f, 0, −v/f
    return sp.Piecewise((v * TAU**2 / (2 * F), TAU < F), (v * (TAU - F / 2), TAU <= 1 - F),
                        (1 - v * (1 - TAU) ** 2 / (2 * F), True))


def law_functions(law: str):
    s = sympy_law(law)
    return [sp.lambdify(TAU, e, "math") for e in (s, sp.diff(s, TAU), sp.diff(s, TAU, 2))]


@pytest.mark.parametrize("law", motion.LAWS)
def test_rest_to_rest_follows_its_law_and_rests_outside(law):
    start, end, t0, T = 0.3, -1.2, 0.5, 2.0
    p = motion.rest_to_rest(start, end, t0, T, law=law, fraction=float(F))
    s, ds, dds = law_functions(law)
    d = end - start
    for t in np.linspace(t0 + 1e-3, t0 + T - 1e-3, 37):
        tau = (t - t0) / T
        np.testing.assert_allclose(p(t), [start + d * s(tau), d * ds(tau) / T, d * dds(tau) / T**2],
                                   rtol=1e-12, atol=1e-12)
    for t in (-3.0, t0 - 1e-9, t0):
        assert p(t) == (start, 0.0, 0.0)
    for t in (t0 + T, t0 + T + 1e-9, 100.0):
        assert p(t) == (end, 0.0, 0.0)
    # q̇ integrates to the move and q̈ to q̇ (quadrature, independent of the closed forms)
    f = float(F)
    assert quad(lambda t: p(t)[1], t0, t0 + T, points=[t0 + f * T, t0 + (1 - f) * T])[0] == pytest.approx(d, rel=1e-10)
    tm = t0 + 0.6 * T
    assert quad(lambda t: p(t)[2], t0, tm, points=[t0 + f * T])[0] == pytest.approx(p(tm)[1], rel=1e-10)


@pytest.mark.parametrize("law, peak", [("quintic", 1.875), ("cycloidal", 2.0), ("trapezoidal", 1 / (1 - float(F)))])
def test_peak_rates(law, peak):
    p = motion.rest_to_rest(0.0, 1.0, 0.0, 1.0, law=law, fraction=float(F))
    assert p(0.5)[1] == pytest.approx(peak, rel=1e-14)


@pytest.mark.parametrize("law", ["quintic", "cycloidal"])
def test_smooth_laws_start_and_stop_without_a_jump(law):
    p = motion.rest_to_rest(0.0, 1.0, 0.0, 1.0, law=law)
    for t in (1e-7, 1 - 1e-7):
        q, qd, qdd = p(t)
        assert abs(qd) < 1e-10 and abs(qdd) < 1e-5


@pytest.mark.parametrize("law", motion.LAWS)
def test_ramp_integrates_its_rate(law):
    rate, t0, T, start = -0.8, 1.0, 1.5, 2.0
    r = motion.ramp(rate, t0, T, law=law, start=start, fraction=float(F))
    s, ds, _ = law_functions(law)
    for t in np.linspace(t0 + 1e-3, t0 + T - 1e-3, 11):
        tau = (t - t0) / T
        q, qd, qdd = r(t)
        assert qd == pytest.approx(rate * s(tau), rel=1e-12, abs=1e-14)
        assert qdd == pytest.approx(rate * ds(tau) / T, rel=1e-12, abs=1e-14)
        assert q == pytest.approx(start + quad(lambda x: r(x)[1], t0, t)[0], rel=1e-10)
    assert r(t0 - 1.0) == (start, 0.0, 0.0)
    for t in (t0 + T, 7.0):  # S(1) = 1/2: the ramp lags a constant rate by T/2
        np.testing.assert_allclose(r(t), [start + rate * (t - t0 - T / 2), rate, 0.0], rtol=1e-13)


def test_a_cycloidal_ramp_from_zero_is_kanes_spin_up():
    for t in (0.3, 7.5, 15.0, 20.0):
        np.testing.assert_allclose(motion.ramp(6.0, 0.0, 15.0)(t), motion.spin_up(6.0, 15.0)(t), rtol=1e-12, atol=1e-13)


def test_sums_products_and_shifts_are_those_of_their_parts():
    a = motion.rest_to_rest(0.0, 2.0, 1.0, 3.0)
    b = motion.harmonic(0.3, 2.0, phase=0.4)
    c = motion.polynomial([0.1, -0.2, 0.05])
    pa, pb, pc = (lambda t, p=p: np.array(p(t)) for p in (a, b, c))
    cases = {
        "a + b": (a + b, lambda t: pa(t) + pb(t)),
        "a - 2 b + 1": (a - 2 * b + 1, lambda t: pa(t) - 2 * pb(t) + [1, 0, 0]),
        "3 - (a + c)/2": (3 - (a + c) / 2, lambda t: [3, 0, 0] - (pa(t) + pc(t)) / 2),
        "-a * 1.5": (-a * 1.5, lambda t: -1.5 * pa(t)),
        "(a + b).shifted(0.7)": ((a + b).shifted(0.7), lambda t: pa(t - 0.7) + pb(t - 0.7)),
        "+c": (+c, pc),
    }
    for name, (p, expected) in cases.items():
        for t in (-1.0, 0.0, 1.3, 2.9, 5.0):
            np.testing.assert_allclose(p(t), expected(t), rtol=1e-14, atol=1e-14, err_msg=name)
    assert repr(a - 2 * b + 1).count("·") == 1  # one flat sum: a − 2·b + 1


def ramp_law(t):
    """Module level, so that it pickles: q = t², as a Python drive."""
    return (t * t, 2 * t, 2.0)


def test_composite_profiles_pickle_bit_for_bit():
    a = motion.rest_to_rest(0.0, 2.0, 1.0, 3.0, law="trapezoidal", fraction=0.2)
    f = motion.function(ramp_law)
    profiles = [2 * a - motion.ramp(0.5, 1.0, 2.0) + 1, (f + a).shifted(0.5),
                motion.piecewise([motion.constant(0.0), motion.ramp(1.0, 1.0, 1.0, law="quintic")], [1.0])]
    for p in profiles:
        back = pickle.loads(pickle.dumps(p))
        for t in (0.2, 1.4, 2.7, 4.4):
            assert back(t) == p(t)
        assert repr(back) == repr(p)
    del a, f
    assert pickle.loads(pickle.dumps(profiles[1]))(2.0) == profiles[1](2.0)  # the parts live on with the sum


def test_piecewise_joins_and_checks_continuity():
    # hoist: at rest, a quintic ramp of the rate to 0.5 m/s over 2 s, paying out, then stop rest to rest
    ramp = motion.ramp(0.5, 1.0, 2.0, law="quintic", start=10.0)
    x_stop = ramp(6.0)[0]
    stop = motion.rest_to_rest(x_stop, x_stop + 0.5, 6.0, 2.0, law="quintic")  # peak 0.9375 m/s: no
    with pytest.raises(ValueError, match=r"^pieces: expected pieces 1 and 2 to meet at the break t = 6 s with "
                                         r"continuity 1, got qd = 0.5 before and 0 after"):
        motion.piecewise([motion.constant(10.0), ramp, stop], [1.0, 6.0])
    brake = motion.ramp(-0.5, 6.0, 2.0, law="quintic", start=x_stop) + 0.5 * motion.polynomial([-6.0, 1.0])
    hoist = motion.piecewise([motion.constant(10.0), ramp, brake, motion.constant(brake(8.0)[0])], [1.0, 6.0, 8.0],
                             continuity=2)
    for t, piece in ((0.0, motion.constant(10.0)), (1.0, ramp), (5.999, ramp), (6.0, brake), (7.9, brake)):
        assert hoist(t) == piece(t)
    assert hoist(9.0) == (brake(8.0)[0], 0.0, 0.0) and brake(8.0)[1] == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(ValueError, match="continuity 2, got qdd"):
        motion.piecewise([motion.constant(0.0), motion.polynomial([0.0, 0.0, 1.0])], [0.0], continuity=2)
    motion.piecewise([motion.constant(0.0), motion.polynomial([0.0, 0.0, 1.0])], [0.0], continuity=1)
    with pytest.raises(ValueError, match="continuity 0, got q = 0 before and 1 after"):
        motion.piecewise([motion.constant(0.0), motion.constant(1.0)], [2.0], continuity=0)


@pytest.mark.parametrize("call, message", [
    (lambda: motion.rest_to_rest(0, 1, 0, 1, law="sine"), "^law: expected one of 'quintic', 'cycloidal', 'trapezoidal'"),
    (lambda: motion.rest_to_rest(0, 1, 0, 0.0), "^duration: expected a positive time in s"),
    (lambda: motion.rest_to_rest(0, 1, 0, -1.0, law="cycloidal"), "^duration: expected a positive time in s"),
    (lambda: motion.rest_to_rest(0, math.nan, 0, 1), "^end: expected"),
    (lambda: motion.rest_to_rest(0, 1, 0, 1, law="trapezoidal", fraction=0.6), r"^fraction: expected .* \(0, 0.5\]"),
    (lambda: motion.ramp("fast", 0, 1), "^rate: expected"),
    (lambda: motion.ramp(1.0, 0, 1, law=None), "^law: expected one of"),
    (lambda: motion.piecewise([motion.constant(0)], [1.0]), r"^breaks: expected 0 times"),
    (lambda: motion.piecewise([motion.constant(0)] * 3, [1.0, 1.0]), "^breaks: expected strictly increasing"),
    (lambda: motion.piecewise(motion.constant(0), []), "^pieces: expected a list of rigidfem.motion profiles"),
    (lambda: motion.piecewise([motion.constant(0), 3.0], [1.0]), "^pieces: expected a list"),
    (lambda: motion.piecewise([motion.constant(0)] * 2, [1.0], continuity=3), "^continuity: expected 0"),
    (lambda: motion.piecewise([motion.constant(0)] * 2, [1.0], continuity=1.0), "^continuity: expected 0"),
    (lambda: motion.constant(1.0).shifted("later"), "^delay: expected a finite time in s, got 'later'"),
    (lambda: motion.constant(1.0) / 0, "^weights: expected a finite, non-zero divisor, got 0"),
])
def test_bad_laws_and_joins_name_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_profiles_add_only_numbers_and_profiles():
    p = motion.constant(1.0)
    for other in ("a", None, [1.0]):
        with pytest.raises(TypeError):
            p + other
        with pytest.raises(TypeError):
            p * other
    with pytest.raises(TypeError):
        p * p


def test_a_beams_root_joint_driven_by_a_law_in_cpp_matches_the_python_drive():
    """Kane's beam without its hub: rfe 0 on a revolute joint, prescribed by model.prescribe(beam.rfes[0], ...)
    to turn by 1 rad rest to rest in 2 s (cycloidal). The C++ law and the same law as a Python function give
    the same run; after the move the root stays at 1 rad."""
    def run(drive):
        model = rf.Model(gravity=None)
        p = rf.samples.KANE_PARAMETERS["kane"]
        section = rf.Section(A=p["A"], Iy=p["I"], Iz=p["I"], J=2 * p["I"])
        beam = model.add_beam("beam", model.ground, p["L"], rf.Material(E=p["E"], rho=p["rho"]), section, 4,
                              deform=("bend_z",), joint=rf.Joint.revolute("z"))
        model.prescribe(beam.rfes[0], drive)
        system = model.compile()
        return beam, rf.simulate(system, 3.0, method="generalized_alpha", dt=2e-3, t_eval=np.linspace(0, 3, 31))

    def cycloid(t):
        tau = min(max(t / 2.0, 0.0), 1.0)
        k = 2 * math.pi
        inside = 0.0 < tau < 1.0
        return (tau - math.sin(k * tau) / k, (1 - math.cos(k * tau)) / 2.0 if inside else 0.0,
                k * math.sin(k * tau) / 4.0 if inside else 0.0)

    beam, fast = run(motion.rest_to_rest(0.0, 1.0, 0.0, 2.0, law="cycloidal"))
    _, slow = run(motion.function(cycloid))
    np.testing.assert_allclose(fast.q, slow.q, rtol=0, atol=1e-12)
    axis = fast.position(beam.rfes[0].point((1.0, 0.0, 0.0))) - fast.position(beam.rfes[0])
    np.testing.assert_allclose(np.arctan2(axis[20:, 1], axis[20:, 0]), 1.0, atol=1e-14)  # at rest at 1 rad from t = 2 s
    assert fast.driving_forces.shape == (31, 1) and np.abs(fast.driving_forces[25:, 0]).max() > 1e-3  # the beam rings


def test_a_chirp_sweeps_its_frequency_with_exact_rates():
    """rf.motion.chirp (a kind added as its class and row in profiles.cpp and its builder: two files): its rates are
    the derivatives of its value (central differences), its phase at the end is 2π (f0 + f1) T/2 (the zero crossings
    count it), it goes on at f1 after T and is zero before t0."""
    A, f0, f1, T, t0 = 0.2, 1.0, 6.0, 3.0, 0.5
    p = motion.chirp(A, f0, f1, T, t0=t0)
    assert p(0.3) == (0.0, 0.0, 0.0)
    for t in np.linspace(t0 + 0.01, t0 + T + 1.0, 37):
        h = 1e-6
        q, qd, qdd = p(t)
        assert abs(qd - (p(t + h)[0] - p(t - h)[0]) / (2 * h)) < 1e-6 * max(1.0, abs(qd))
        assert abs(qdd - (p(t + h)[1] - p(t - h)[1]) / (2 * h)) < 1e-5 * max(1.0, abs(qdd))
    t = np.linspace(t0, t0 + T, 200001)
    q = np.array([p(x)[0] for x in t])
    crossings = np.count_nonzero(np.diff(np.signbit(q[1:])))  # each half period once, the start's zero left out
    assert crossings == int(2 * (f0 + f1) * T / 2)  # φ(T)/π = (f0 + f1) T
    after = np.array([p(t0 + T + x)[0] for x in (0.0, 0.5 / f1, 1.0 / f1)])
    assert abs(after[0] - after[2]) < 1e-12 and abs(after[0] + after[1]) < 1e-12  # period 1/f1 after T
    with pytest.raises(ValueError, match="^f1: expected a frequency >= 0 in Hz"):
        motion.chirp(A, 1.0, -1.0, T)
    with pytest.raises(ValueError, match="^duration: expected a positive time in s"):
        motion.chirp(A, 1.0, 2.0, 0.0)


def test_sample_evaluates_many_times_in_one_call():
    # a spline's (q, q̇, q̈) at many times, against the same profile called at each time, and the spin-up's closed form
    knots = np.linspace(0.0, 2.0, 9)
    profiles = [motion.spline(knots, np.sin(3.0 * knots)), motion.spin_up(6.0, 15.0)]
    times = np.linspace(-0.5, 3.0, 37)
    for p in profiles:
        rows = p.sample(times)
        assert rows.shape == (len(times), 3)
        np.testing.assert_array_equal(rows, np.array([p(t) for t in times]))
    W, T, t = 6.0, 15.0, times[times > 0.0]
    theta = W / T * (t**2 / 2 + (T / (2 * math.pi)) ** 2 * (np.cos(2 * math.pi * t / T) - 1))
    np.testing.assert_allclose(profiles[1].sample(t)[:, 0], theta, rtol=1e-12, atol=1e-15)
    with pytest.raises(ValueError, match="times"):
        profiles[0].sample(np.array([0.0, np.nan]))
