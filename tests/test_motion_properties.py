"""Property-based tests of rigidfem.motion: random composition trees (depth ≤ 3) of the C++ profile makers
joined by +, −, scalar ·, /, shifts and piecewise joins, checked for

- rates: q̇ against a central difference of q, q̈ against one of q̇, away from every kink, to a tolerance
  from bounds of q''' and q'''' that the test derives for each tree (and a rounding allowance);
- linearity, exact where the arithmetic is exact (a sum of two non-sums, a scalar times a non-sum, a
  negation, a power-of-two factor, a shift) and to 1e-14 of the terms' magnitudes where C++ flattens a
  sum of sums in another order;
- piecewise joins: each piece on its interval, bit for bit, and a join that is not continuous refused,
  naming its break;
- pickling: bit for bit, with the same repr;
- bad input: ValueError for non-finite parameters and p / 0, TypeError for operands that are not numbers.

Every drawn profile carries the Python expression that rebuilds it (shown by hypothesis on a failure).
"""

import bisect
import math
import operator
import pickle
import re
import struct
from dataclasses import dataclass, field

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rigidfem import motion

SETTINGS = settings(max_examples=60, deadline=None, database=None)

EPS = np.finfo(float).eps
T_WINDOW = 15.0  # every leaf is evaluated at |t| ≤ 15 s: test times in [-3, 8] s, at most 3 shifts of ≤ 2 s
H = 1e-5  # central-difference step (s)
MARGIN = 1e-3  # test times keep this far (s) from every kink, so that t ± H never straddles one


def moderate(lo, hi):
    """Floats in [lo, hi] that are 0 or at least 1e-6 in magnitude: no subnormal products, so that
    arithmetic that is exact in reals (a power-of-two factor) is exact in floats too."""
    return st.floats(lo, hi).map(lambda x: x if x == 0.0 or abs(x) >= 1e-6 else 0.0)


VALUES = moderate(-2.0, 2.0)  # positions (m or rad), amplitudes, rates, coefficients
OMEGAS = moderate(-4.0, 4.0)
PHASES = moderate(-math.pi, math.pi)
STARTS = moderate(-1.0, 3.0)  # t0 of moves and ramps (s)
DURATIONS = st.floats(0.5, 3.0)
FRACTIONS = st.floats(0.1, 0.5)  # the trapezoidal law's acceleration share
LAWS = st.sampled_from(motion.LAWS)
FACTORS = st.tuples(st.floats(0.25, 3.0), st.sampled_from([1.0, -1.0])).map(lambda m: m[0] * m[1])
DELAYS = moderate(-2.0, 2.0)
TIMES = moderate(-3.0, 8.0)


# --- drawn profiles ----------------------------------------------------------------------------------------


@dataclass(eq=False)
class Drawn:
    """A drawn profile with what the test knows of it independently of rigidfem."""

    expr: str  # Python expression rebuilding the profile (``motion`` in scope)
    profile: object = field(repr=False)
    kinks: tuple = field(default=(), repr=False)  # times where q''' or q'''' may be discontinuous
    d3: float = field(default=0.0, repr=False)  # bound of |q'''| away from the kinks
    d4: float = field(default=0.0, repr=False)  # bound of |q''''| away from the kinks
    bound: np.ndarray = field(default=None, repr=False)  # bound of the terms of (q, qd, qdd) for |t| ≤ T_WINDOW
    summands: tuple = field(default=(), repr=False)  # a sum's (weight, Drawn) terms ...
    offset: float = field(default=0.0, repr=False)  # ... and its offset
    pieces: tuple = field(default=(), repr=False)  # a piecewise join's pieces (Drawn) ...
    breaks: tuple = field(default=(), repr=False)  # ... and breaks
    same_as: "Drawn" = field(default=None, repr=False)  # another profile equal to this one bit for bit

    @property
    def is_sum(self):
        return bool(self.summands)

    def __call__(self, t):
        return np.array(self.profile(t))

    def scale(self, t):
        """Σ |terms| of (q, qd, qdd) at t that C++ adds in one flat sum: the scale of its rounding."""
        if not self.is_sum:
            return np.abs(self(t))
        return sum(abs(w) * d.scale(t) for w, d in self.summands) + np.array([abs(self.offset), 0.0, 0.0])


def law_bounds(law, fraction):
    """max |s'|, |s''|, |s'''|, |s''''| of a rest-to-rest law s(τ) on (0, 1), the trapezoidal law's
    away from its corners."""
    if law == "quintic":  # s' = 30τ²(1−τ)², s'' = 60τ(1−τ)(1−2τ), s''' = 60(1 − 6τ + 6τ²), s'''' = 60(12τ − 6)
        return 1.875, 6.0, 60.0, 360.0
    if law == "cycloidal":  # s' = 1 − cos 2πτ and its derivatives
        return 2.0, 2 * math.pi, 4 * math.pi**2, 8 * math.pi**3
    v = 1.0 / (1.0 - fraction)
    return v, v / fraction, 0.0, 0.0


def law_kinks(law, t0, duration, fraction):
    """Where a move or ramp starts and stops, and the trapezoidal law's inner corners."""
    corners = (t0 + fraction * duration, t0 + (1.0 - fraction) * duration) if law == "trapezoidal" else ()
    return (t0, t0 + duration) + corners


def law_arguments(law, fraction):
    return f"law={law!r}" + (f", fraction={fraction!r}" if law == "trapezoidal" else "")


def make_constant(value):
    return Drawn(f"motion.constant({value!r})", motion.constant(value), bound=np.array([abs(value), 0.0, 0.0]))


def make_polynomial(c):  # degree ≤ 3: q''' = 6 c3, q'''' = 0
    magnitude = motion.polynomial([abs(x) for x in c])(T_WINDOW)  # Σ |c_k| T^k and its derivatives
    return Drawn(f"motion.polynomial({c!r})", motion.polynomial(c), d3=6 * abs(c[3]) if len(c) == 4 else 0.0,
                 bound=np.array(magnitude))


def make_harmonic(a, w, phase, offset):
    return Drawn(f"motion.harmonic({a!r}, {w!r}, {phase!r}, {offset!r})", motion.harmonic(a, w, phase, offset),
                 d3=abs(a * w**3), d4=abs(a * w**4), bound=np.array([abs(offset) + abs(a), abs(a * w), abs(a * w * w)]))


def make_harmonics(components, offset):
    a, w, phi = (list(x) for x in zip(*components))
    return Drawn(f"motion.harmonics({a!r}, {w!r}, {phi!r}, offset={offset!r})", motion.harmonics(a, w, phi, offset),
                 d3=sum(abs(x * y**3) for x, y in zip(a, w)), d4=sum(abs(x * y**4) for x, y in zip(a, w)),
                 bound=np.array([abs(offset) + sum(map(abs, a)), sum(abs(x * y) for x, y in zip(a, w)),
                                 sum(abs(x * y * y) for x, y in zip(a, w))]))


def make_spin_up(omega, duration):
    # θ̈ = a (1 − cos kt), a = Ω/T, k = 2π/T, for t < T (the formula holds for t < 0 too), Ω(t − T/2) after
    a, k = abs(omega) / duration, 2 * math.pi / duration
    bound = [a * (T_WINDOW**2 / 2 + 2 / k**2) + abs(omega) * (T_WINDOW + duration), a * (T_WINDOW + 1 / k) + abs(omega),
             2 * a]
    return Drawn(f"motion.spin_up({omega!r}, {duration!r})", motion.spin_up(omega, duration), kinks=(duration,),
                 d3=a * k, d4=a * k * k, bound=np.array(bound))


def make_spline(t, q):
    p = motion.spline(t, q)
    m = [p(x)[2] for x in t]  # q̈ at the knots: the natural spline's moments, q''' = Δm/h between them
    d3 = max(abs(m[k + 1] - m[k]) / (t[k + 1] - t[k]) for k in range(len(t) - 1))
    grid = np.abs([p(x) for x in np.linspace(-T_WINDOW, T_WINDOW, 121)]).max(axis=0)
    return Drawn(f"motion.spline({t!r}, {q!r})", p, kinks=tuple(t), d3=d3,
                 bound=2 * grid + max(map(abs, q)) + max(map(abs, m)))


def make_rest_to_rest(start, end, t0, duration, law, fraction):
    d, (s1, s2, s3, s4) = abs(end - start), law_bounds(law, fraction)
    return Drawn(f"motion.rest_to_rest({start!r}, {end!r}, {t0!r}, {duration!r}, {law_arguments(law, fraction)})",
                 motion.rest_to_rest(start, end, t0, duration, law=law, fraction=fraction),
                 kinks=law_kinks(law, t0, duration, fraction), d3=d * s3 / duration**3, d4=d * s4 / duration**4,
                 bound=np.array([max(abs(start), abs(end)) + d, d * s1 / duration, d * s2 / duration**2]))


def make_ramp(rate, t0, duration, law, start, fraction):
    v, (s1, s2, s3, _) = abs(rate), law_bounds(law, fraction)  # q̇ = rate s(τ): q''' = rate s''/T², ...
    return Drawn(f"motion.ramp({rate!r}, {t0!r}, {duration!r}, {law_arguments(law, fraction)}, start={start!r})",
                 motion.ramp(rate, t0, duration, law=law, start=start, fraction=fraction),
                 kinks=law_kinks(law, t0, duration, fraction), d3=v * s2 / duration**2, d4=v * s3 / duration**3,
                 bound=np.array([abs(start) + v * (T_WINDOW + duration), v, v * s1 / duration]))


@st.composite
def splines(draw):
    n = draw(st.integers(2, 5))
    t = [draw(moderate(-2.0, 2.0))]
    for _ in range(n - 1):
        t.append(t[-1] + draw(st.floats(0.3, 2.0)))
    return make_spline(t, draw(st.lists(VALUES, min_size=n, max_size=n)))


LEAVES = st.one_of(
    st.builds(make_constant, VALUES),
    st.builds(make_polynomial, st.lists(VALUES, min_size=1, max_size=4)),
    st.builds(make_harmonic, VALUES, OMEGAS, PHASES, VALUES),
    st.builds(make_harmonics, st.lists(st.tuples(VALUES, OMEGAS, PHASES), min_size=1, max_size=3), VALUES),
    st.builds(make_spin_up, moderate(-5.0, 5.0), DURATIONS),
    splines(),
    st.builds(make_rest_to_rest, VALUES, VALUES, STARTS, DURATIONS, LAWS, FRACTIONS),
    st.builds(make_ramp, VALUES, STARTS, DURATIONS, LAWS, VALUES, FRACTIONS),
)


# --- composition: the profile by rigidfem, its bounds by the rules of calculus -------------------------------


def combined(expr, profile, summands, offset=0.0):
    """A weighted sum Σ w_k d_k + offset of drawn profiles."""
    return Drawn(expr, profile, kinks=sum((d.kinks for _, d in summands), ()),
                 d3=sum(abs(w) * d.d3 for w, d in summands), d4=sum(abs(w) * d.d4 for w, d in summands),
                 bound=sum(abs(w) * d.bound for w, d in summands) + np.array([abs(offset), 0.0, 0.0]),
                 summands=tuple(summands), offset=offset)


def plus(a, b, sign):
    """a + b (sign 1) or a − b (sign −1)."""
    if sign > 0:
        return combined(f"({a.expr} + {b.expr})", a.profile + b.profile, [(1.0, a), (1.0, b)])
    return combined(f"({a.expr} - {b.expr})", a.profile - b.profile, [(1.0, a), (-1.0, b)])


OFFSETS = {  # form: (make, weight, sign of the offset)
    "{a} + {c}": (lambda p, c: p + c, 1.0, 1.0),
    "{c} + {a}": (lambda p, c: c + p, 1.0, 1.0),
    "{a} - {c}": (lambda p, c: p - c, 1.0, -1.0),
    "{c} - {a}": (lambda p, c: c - p, -1.0, 1.0),
}


def offset(a, c, form):
    make, w, sign = OFFSETS[form]
    return combined("(" + form.format(a=a.expr, c=repr(c)) + ")", make(a.profile, c), [(w, a)], sign * c)


def times(a, c, left):
    """c · a (left) or a · c."""
    return combined(f"({c!r} * {a.expr})" if left else f"({a.expr} * {c!r})",
                    c * a.profile if left else a.profile * c, [(c, a)])


def divided(a, c):
    return combined(f"({a.expr} / {c!r})", a.profile / c, [(1.0 / c, a)])


def negated(a):
    return combined(f"(-{a.expr})", -a.profile, [(-1.0, a)])


def shifted(a, delay):
    return Drawn(f"{a.expr}.shifted({delay!r})", a.profile.shifted(delay), kinks=tuple(k + delay for k in a.kinks),
                 d3=a.d3, d4=a.d4, bound=a.bound)


def joined(pieces, breaks, continuity, same_as=None):
    expr = f"motion.piecewise([{', '.join(p.expr for p in pieces)}], {list(breaks)!r}, continuity={continuity})"
    return Drawn(expr, motion.piecewise([p.profile for p in pieces], list(breaks), continuity),
                 kinks=tuple(breaks) + sum((p.kinks for p in pieces), ()), d3=max(p.d3 for p in pieces),
                 d4=max(p.d4 for p in pieces), bound=np.max([p.bound for p in pieces], axis=0),
                 pieces=tuple(pieces), breaks=tuple(breaks), same_as=same_as)


@st.composite
def tree_then_move(draw, trees):
    """x until a break b, then x + r, r a move or ramp from rest at 0 starting at or after b: the pieces
    meet in q, q̇ and q̈ (r is exactly 0 at b), and the join is x + r everywhere."""
    x, b, gap = draw(trees), draw(STARTS), draw(st.floats(0.0, 1.0))
    law, duration, fraction = draw(LAWS), draw(DURATIONS), draw(FRACTIONS)
    if draw(st.booleans()):
        r = make_rest_to_rest(0.0, draw(VALUES), b + gap, duration, law, fraction)
    else:
        r = make_ramp(draw(VALUES), b + gap, duration, law, 0.0, fraction)
    x_plus_r = plus(x, r, 1.0)
    return joined([x, x_plus_r], [b], draw(st.integers(0, 2)), same_as=x_plus_r)


@st.composite
def chained_moves(draw):
    """Rest-to-rest moves one after the other, each starting where the last stopped; each break strictly
    inside the pause between two moves (where both rest at the same place)."""
    n = draw(st.integers(2, 4))
    positions = draw(st.lists(VALUES, min_size=n + 1, max_size=n + 1))
    t, pieces, breaks = draw(STARTS), [], []
    for k in range(n):
        duration, law, fraction = draw(DURATIONS), draw(LAWS), draw(FRACTIONS)
        pieces.append(make_rest_to_rest(positions[k], positions[k + 1], t, duration, law, fraction))
        pause = draw(st.floats(0.05, 1.0))
        breaks.append(t + duration + pause * draw(st.floats(0.1, 0.9)))
        t = t + duration + pause
    return joined(pieces, breaks[:-1], draw(st.integers(0, 2)))


def trees(depth):
    """Profiles composed of at most ``depth`` levels of operations over the leaves (a join of x and x + r
    counting as one)."""
    if depth == 0:
        return LEAVES
    sub = trees(depth - 1)
    return st.one_of(
        LEAVES,
        st.builds(plus, sub, sub, st.sampled_from([1.0, -1.0])),
        st.builds(offset, sub, VALUES, st.sampled_from(sorted(OFFSETS))),
        st.builds(times, sub, FACTORS, st.booleans()),
        st.builds(divided, sub, FACTORS),
        st.builds(negated, sub),
        st.builds(shifted, sub, DELAYS),
        tree_then_move(sub),
        chained_moves(),
    )


TREES = trees(3)
SUBTREES = trees(2)  # operands of one more operation: the result is at most 3 deep
JOINS = st.one_of(tree_then_move(SUBTREES), chained_moves())


# --- checks ------------------------------------------------------------------------------------------------


def central_difference(f, t, h=H):
    """(f(t + h) − f(t − h)) / (2h), dividing by the step actually taken (t ± h rounded)."""
    t_plus, t_minus = t + h, t - h
    return (f(t_plus) - f(t_minus)) / (t_plus - t_minus)


def far_from_kinks(t, kinks):
    return all(abs(t - k) > MARGIN for k in kinks)


def assert_sum(got, expected, scale, exact):
    """got == expected where the arithmetic is the same (``exact``), else within 1e-14 of the terms' scale."""
    if exact:
        assert tuple(got) == tuple(expected)
    else:
        assert np.all(np.abs(np.subtract(got, expected)) <= 1e-14 * scale), (got, expected, scale)


def bits(values):
    return struct.pack("<3d", *values)


# --- rates ---------------------------------------------------------------------------------------------------


# q̇ is the derivative of q and q̈ that of q̇: central differences with step H err by at most
# H²/6 max|q'''| (resp. q'''') away from kinks, plus the rounding of q (resp. q̇) divided by H.
@SETTINGS
@given(node=TREES, t=TIMES)
def test_rates_are_the_derivatives_of_q(node, t):
    assume(far_from_kinks(t, node.kinks))
    q, qd, qdd = node(t)
    fd = central_difference(node, t)
    tol_qd = 2 * H**2 / 6 * node.d3 + 64 * EPS * node.bound[0] / H
    tol_qdd = 2 * H**2 / 6 * node.d4 + 64 * EPS * node.bound[1] / H
    assert abs(qd - fd[0]) <= tol_qd, f"qd = {qd!r}, central difference {fd[0]!r} at t = {t!r}"
    assert abs(qdd - fd[1]) <= tol_qdd, f"qdd = {qdd!r}, central difference {fd[1]!r} at t = {t!r}"


# Every drawn profile is C¹ (even the trapezoidal law's q̇ and every join's), so across each kink q and q̇
# change by no more than their bounded rates allow: this catches a wrong constant in one branch of a
# law (say its integral), which the local differences above do not see.
@SETTINGS
@given(node=TREES)
def test_q_and_qd_are_continuous_at_the_kinks(node):
    delta = 1e-7
    for k in node.kinks:
        before, at, after = node(k - delta), node(k), node(k + delta)
        span = (k + delta) - (k - delta)
        for a, b in ((before, at), (at, after)):
            assert abs(b[0] - a[0]) <= span * node.bound[1] + 64 * EPS * node.bound[0], f"q jumps at t = {k!r}"
            assert abs(b[1] - a[1]) <= span * node.bound[2] + 64 * EPS * node.bound[1], f"qd jumps at t = {k!r}"


# --- linearity -----------------------------------------------------------------------------------------------


# (a ± b)(t) = a(t) ± b(t): the same two additions when neither is a sum, else a flattened sum.
@SETTINGS
@given(a=SUBTREES, b=SUBTREES, t=TIMES)
def test_sums_and_differences_are_those_of_their_parts(a, b, t):
    exact, scale = not (a.is_sum or b.is_sum), a.scale(t) + b.scale(t)
    assert_sum((a.profile + b.profile)(t), a(t) + b(t), scale, exact)
    assert_sum((a.profile - b.profile)(t), a(t) - b(t), scale, exact)


# c·a, a·c, a ± c, c − a and −a are the same operations on a(t) (offsets act on q only); −a and a
# power-of-two factor are exact even through a flattened sum; a / c is a · (1/c): within a few ulps.
@SETTINGS
@given(a=SUBTREES, c=FACTORS, k=st.sampled_from([0.25, 0.5, 2.0, -4.0]), t=TIMES)
def test_scalars_act_on_the_values(a, c, k, t):
    p, at, exact, scale = a.profile, a(t), not a.is_sum, a.scale(t)
    shift = np.array([c, 0.0, 0.0])
    assert_sum((c * p)(t), c * at, abs(c) * scale, exact)
    assert_sum((p * c)(t), c * at, abs(c) * scale, exact)
    assert_sum((p + c)(t), at + shift, scale + abs(shift), exact)
    assert_sum((c + p)(t), shift + at, scale + abs(shift), exact)
    assert_sum((p - c)(t), at - shift, scale + abs(shift), exact)
    assert_sum((c - p)(t), shift - at, scale + abs(shift), exact)
    assert tuple((-p)(t)) == tuple(-at)
    assert tuple((k * p)(t)) == tuple(k * at)
    if exact:
        np.testing.assert_allclose((p / c)(t), at / c, rtol=4 * EPS, atol=0)
    else:
        assert_sum((p / c)(t), at / c, scale / abs(c), exact=False)


# p.shifted(d)(t) = p(t − d), bit for bit (C++ subtracts the same two doubles).
@SETTINGS
@given(a=TREES, d=DELAYS, t=TIMES)
def test_a_shift_is_a_delay(a, d, t):
    assert a.profile.shifted(d)(t) == a.profile(t - d)


# --- piecewise joins -----------------------------------------------------------------------------------------


# A join is piece k on [breaks[k−1], breaks[k]), bit for bit; a tree joined to itself plus a move that
# starts after the break is that sum everywhere.
@SETTINGS
@given(join=JOINS, t=TIMES)
def test_a_join_is_each_piece_on_its_interval(join, t):
    for time in (t, *join.breaks):  # the breaks themselves belong to the piece after them
        k = bisect.bisect_right(join.breaks, time)
        assert bits(join.profile(time)) == bits(join.pieces[k].profile(time))
        if join.same_as is not None:
            assert tuple(join.profile(time)) == tuple(join.same_as.profile(time))


# A chain of moves continuous in q, q̇, q̈ but for a jump in derivative ``order`` at one break (pieces
# j−1 and j): refused with ``continuity ≥ order``, naming the pieces, the break and the quantity; accepted
# with a lower continuity.
@SETTINGS
@given(chain=chained_moves(), data=st.data())
def test_a_join_that_jumps_is_refused_naming_its_break(chain, data):
    j = data.draw(st.integers(1, len(chain.pieces) - 1), label="j")
    order, jump, continuity = data.draw(st.integers(0, 2)), data.draw(FACTORS), data.draw(st.integers(0, 2))
    b = chain.breaks[j - 1]
    step = motion.polynomial([0.0] * order + [jump]).shifted(b)  # its order-th derivative jumps at b
    pieces = [p.profile for p in chain.pieces[:j]] + [p.profile + step for p in chain.pieces[j:]]
    if continuity < order:
        motion.piecewise(pieces, list(chain.breaks), continuity)
        return
    quantity = ("q", "qd", "qdd")[order]
    message = (f"pieces: expected pieces {j - 1} and {j} to meet at the break t = {b:.6g} s with continuity "
               f"{continuity}, got {quantity} = ")
    with pytest.raises(ValueError, match="^" + re.escape(message)):
        motion.piecewise(pieces, list(chain.breaks), continuity)


# --- pickling ------------------------------------------------------------------------------------------------


# A profile unpickles (from its makers' arguments) bit for bit with the same repr; so does its expression.
@SETTINGS
@given(node=TREES, times=st.lists(TIMES, min_size=1, max_size=4))
def test_pickle_round_trips_bit_for_bit(node, times):
    back = pickle.loads(pickle.dumps(node.profile))
    rebuilt = eval(node.expr, {"motion": motion})  # the expression a failure report shows is this profile
    assert repr(back) == repr(node.profile) == repr(rebuilt)
    for t in times:
        assert bits(back(t)) == bits(node.profile(t)) == bits(rebuilt(t))


# --- bad input -----------------------------------------------------------------------------------------------

NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf, np.float64("nan"), np.float64("-inf")])
VALID = {
    motion.rest_to_rest: dict(start=0.0, end=1.0, t0=0.0, duration=1.0, fraction=0.25),
    motion.ramp: dict(rate=1.0, t0=0.0, duration=1.0, start=0.0, fraction=0.25),
}
PARAMETERS = [(maker, name) for maker, valid in VALID.items() for name in valid]


# Each parameter of rest_to_rest and ramp non-finite: a ValueError naming it (fraction: for the
# trapezoidal law, the only one to use it).
@SETTINGS
@given(case=st.sampled_from(PARAMETERS), bad=NON_FINITE, law=LAWS)
def test_non_finite_parameters_of_moves_and_ramps_raise_value_error(case, bad, law):
    maker, name = case
    law = "trapezoidal" if name == "fraction" else law
    with pytest.raises(ValueError, match=f"^{name}:"):
        maker(**{**VALID[maker], name: bad}, law=law)


# A non-finite break (anywhere among them), delay, factor or offset, a NaN divisor, or a division by zero:
# ValueError.
@SETTINGS
@given(node=LEAVES, n=st.integers(1, 3), data=st.data(), bad=NON_FINITE)
def test_non_finite_breaks_factors_and_division_by_zero_raise_value_error(node, n, data, bad):
    breaks = [float(k) for k in range(n)]
    breaks[data.draw(st.integers(0, n - 1), label="which")] = bad
    with pytest.raises(ValueError, match="^breaks:"):
        motion.piecewise([node.profile] * (n + 1), breaks)
    with pytest.raises(ValueError, match="^delay:"):
        node.profile.shifted(bad)
    for operation in (lambda p: p * bad, lambda p: bad * p, lambda p: p + bad, lambda p: bad - p,
                      lambda p: p / math.nan):
        with pytest.raises(ValueError, match="^(weights|offset):"):
            operation(node.profile)
    for zero in (0, 0.0, -0.0, np.float64(0.0)):
        with pytest.raises(ValueError, match="^weights:"):
            node.profile / zero


# Operands that are neither numbers nor (for + and −) profiles: Python's TypeError, either way round.
@SETTINGS
@given(node=LEAVES, other=st.sampled_from(["a", b"a", None, [1.0], (1.0,), {}, object(), 1j]),
       op=st.sampled_from([operator.add, operator.sub, operator.mul, operator.truediv]))
def test_non_numbers_raise_type_error(node, other, op):
    p = node.profile
    with pytest.raises(TypeError):
        op(p, other)
    with pytest.raises(TypeError):
        op(other, p)
    if op in (operator.mul, operator.truediv):  # a profile scales by numbers only
        with pytest.raises(TypeError):
            op(p, p)


@pytest.mark.parametrize("divisor", [math.inf, -math.inf])
def test_an_infinite_divisor_raises_value_error(divisor):
    """p / ±inf was 0 · p (the weight 1/c was checked, not c)."""
    with pytest.raises(ValueError, match="^weights: expected a finite, non-zero divisor"):
        motion.constant(1.0) / divisor


@pytest.mark.parametrize("operand", [np.array([1.0, 2.0]), np.array([2.0]), np.zeros((2, 2))])
def test_an_array_operand_raises_type_error(operand):
    """An array passed the __float__ test, then failed pybind11's cast (RuntimeError); NumPy must not broadcast
    over a profile either (Profile.__array_ufunc__ = None)."""
    p = motion.constant(1.0)
    for combine in (operator.add, operator.sub, operator.mul, operator.truediv):
        with pytest.raises(TypeError):
            combine(p, operand)
        with pytest.raises(TypeError):
            combine(operand, p)


def test_products_of_weights_that_overflow_are_refused():
    """Flattening a sum multiplies weights and offsets: products beyond doubles are refused, as the factors are."""
    p = motion.harmonic(1.0, 2.0)
    with pytest.raises(ValueError, match="^weights: expected finite products"):
        (p * 1e200) * 1e200
    with pytest.raises(ValueError, match="^offset: expected a finite sum"):
        (p + 1e308) * 10
