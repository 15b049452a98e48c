"""rf.sea near the ends of the floats: what used to overflow silently (m0 = hs = inf for amplitudes of
1e300 m), was refused only when called (an oscillator RAO of extreme period or damping ratio), or named an
argument the caller never gave ('amplitude' for jonswap_waves(hs=1e300, tp=1e-300)). Each value is either
finite and right (against the formula in 60-digit decimals), a ValueError naming the argument, or inf with a
RuntimeWarning naming it (the contract, docs/reliability.md)."""

import warnings
from decimal import Decimal, localcontext

import numpy as np
import pytest

from rigidfem import sea

WN = 2.0 * np.pi / 6.0  # the resonance of a 6 s oscillator, as a user writes it


def oscillator_exact(period: float, zeta: float, omega: float) -> complex:
    """H = 1/(1 − r² + 2iζr), r = ω T_n/2π, in 60-digit decimals (no overflow), rounded to a complex."""
    with localcontext() as ctx:
        ctx.prec, ctx.Emax, ctx.Emin = 60, 10**6, -10**6
        r = Decimal(omega) / (2 * Decimal(np.pi)) * Decimal(period)
        a, b = 1 - r * r, 2 * Decimal(zeta) * r
        n = a * a + b * b
        return complex(float(a / n), float(-b / n))


@pytest.mark.parametrize("period, zeta", [(1e-300, 0.1), (1e300, 0.1), (6.0, 1e300), (1e300, 1e300),
                                          (1e-300, 1e-300), (6.0, 1e-300), (6.0, 0.1), (1e-300, 1e300)])
def test_an_oscillator_of_extreme_constants_is_finite_and_right_everywhere(period, zeta):
    """Was NaN (refused when called: 'rao: expected ... finite values') where r² or ζr overflowed."""
    omega = np.array([1e-300, 0.1, 1.0, 3.0, 1e10, 1e300])
    rao = sea.RAO.oscillator(period, zeta)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning either: every value is exact
        H, peak = rao(omega), rao(WN)
    assert np.all(np.isfinite(H)) and np.isfinite(peak)
    for h, w in zip(H, omega):  # to rounding, or within the smallest normal float where the exact value underflows
        exact = oscillator_exact(period, zeta, w)
        assert abs(h - exact) <= 1e-12 * abs(exact) + 3e-308, (w, h, exact)
    if period == 6.0:  # at resonance, where 1 − r² is rounding (ω = 2π/6 is not exact): |H| <= 1/(2ζ)
        assert abs(peak) <= (1 + 1e-12) / (2 * zeta)


@pytest.mark.parametrize("zeta", [1e-310, 5e-324])
def test_a_damping_ratio_whose_resonance_peak_overflows_is_said_when_made_and_where_called(zeta):
    """1/(2ζ) beyond the largest float: taken with a RuntimeWarning naming damping_ratio, inf (not NaN) at
    resonance with another, finite and silent elsewhere."""
    with pytest.warns(RuntimeWarning, match=r"^damping_ratio: ζ = .* makes the resonance peak"):
        rao = sea.RAO.oscillator(6.0, zeta)
    with pytest.warns(RuntimeWarning, match=r"^damping_ratio: .*\|H\| = inf at ω = 1.0472 rad/s"):
        H = rao(WN)
    assert H.real == 0.0 and H.imag == -np.inf
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        H = rao(np.linspace(0.1, 3.0, 7))
    assert np.all(np.isfinite(H))


def test_an_infinite_value_of_a_users_function_is_still_refused():
    rao = sea.RAO(lambda w: np.full(np.shape(w), np.inf + 0j))
    with pytest.raises(ValueError, match=r"^rao: expected .* to return finite values"):
        rao([1.0])


def test_waves_of_huge_amplitudes_say_that_m0_overflows_and_keep_hs_finite():
    """m0 = hs = inf came silently (numpy's 'overflow encountered in square' only)."""
    waves = sea.Waves([1.0, 2.0], [1e300, 1e300], [0.0, 0.0])
    assert waves.hs == pytest.approx(4e300, rel=1e-15)  # 4 √(Σ a²/2)
    with pytest.warns(RuntimeWarning, match=r"^amplitude: components up to 1e\+300 m make m0 = Σ a_k²/2 overflow"):
        assert waves.m0 == np.inf
    assert np.all(np.isfinite(waves.elevation()(0.3)))  # the elevation itself is finite


def test_waves_of_tiny_amplitudes_keep_their_hs():
    """hs was 0 for amplitudes whose squares underflow."""
    waves = sea.Waves([1.0, 2.0], [3e-300, 4e-300], [0.0, 0.0])
    assert waves.hs == pytest.approx(4 * 5e-300 / np.sqrt(2), rel=1e-15, abs=0.0)


def test_jonswap_waves_scale_with_hs_down_to_tiny_seas():
    """The amplitudes, computed in logarithms, are hs times those of hs = 1 (they underflowed to 0)."""
    unit = sea.jonswap_waves(1.0, 8.0, n=50, seed=2)
    for hs in (1e-300, 2.0, 1e150):
        waves = sea.jonswap_waves(hs, 8.0, n=50, seed=2)
        np.testing.assert_allclose(waves.amplitude / hs, unit.amplitude, rtol=1e-12)
        assert waves.hs == pytest.approx(hs * unit.hs, rel=1e-12, abs=0.0)
    tiny_tp = sea.jonswap_waves(2.0, 1e-300, n=50, seed=2)  # ω of 3e300 rad/s, a sea of 2 m all the same
    assert tiny_tp.hs == pytest.approx(2.0 * unit.hs, rel=1e-12)


@pytest.mark.parametrize("hs, tp", [(1e300, 1e-300), (1e300, 8.0), (1e300, 1e300), (1e160, 8.0)])
def test_jonswap_waves_whose_variance_overflows_name_hs_and_tp(hs, tp):
    """jonswap_waves(hs=1e300, tp=1e-300) named 'amplitude', an argument of Waves it was never given."""
    with pytest.raises(ValueError, match=r"^hs, tp: expected a sea state whose variance m0 ≈ hs²/16 is finite"):
        sea.jonswap_waves(hs, tp, n=20)


def test_a_peak_period_whose_frequencies_overflow_is_named():
    with pytest.raises(ValueError, match=r"^tp: expected a peak period whose default frequencies"):
        sea.jonswap_waves(2.0, 1e-320)
    assert sea.jonswap_waves(2.0, 1e-320, omega_range=(0.1, 3.0), n=10).hs == 0.0  # T_p → 0: no energy there


def test_a_response_that_overflows_names_the_rao():
    """numpy's overflow, then 'amplitudes: expected a finite number' of the harmonics (no argument of response)."""
    waves = sea.Waves([1.0, 2.0], [1e300, 1e300], [0.0, 0.0])
    with pytest.raises(ValueError, match=r"^rao: expected an RAO whose responses \|H\(ω_k\)\| a_k to these waves are "
                                         r"finite, got \|H\| = 1e\+300 at ω = 1 rad/s, a_k = 1e\+300 m"):
        waves.response(1e300)
    assert np.all(np.isfinite(waves.response(sea.RAO.oscillator(6.0, 0.1))(0.3)))
