"""Moving bases and sea states: the harmonic series against its closed form and central
differences, the JONSWAP spectrum against DNV-RP-C205's formula written out here (m0 by
quadrature, its peak), seeded components (variance of a long record), RAOs, and the physics
of bodies on a moving base in both engines: a base-excited spring-mass-damper against its
closed-form steady state, a pendulum on a surging and heaving base against its own equation
solved by solve_ivp, and the driving forces of a heaving and rolling base by Newton–Euler."""

import numpy as np
import pytest
from conftest import integrate
from scipy.integrate import quad, solve_ivp
from scipy.optimize import minimize_scalar

import rigidfem as rf
from rigidfem import motion, sea

G = 9.81
A = np.array([0.3, -0.1, 0.05])  # amplitudes (m or rad)
W = np.array([0.7, 1.9, 4.2])  # rad/s
PH = np.array([0.2, -1.0, 2.5])  # rad
C = 0.4  # offset
ENGINES = ["recursive", "lagrange"]


def series(a, w, ph, c, t):
    """q, q̇, q̈ of c + Σ a_k sin(ω_k t + φ_k), written out."""
    s, co = np.sin(w * t + ph), np.cos(w * t + ph)
    return np.array([c + np.sum(a * s), np.sum(a * w * co), -np.sum(a * w**2 * s)])


# --- the harmonic series ------------------------------------------------------------------


@pytest.mark.parametrize("t", [-1.0, 0.0, 0.83, 12.5, 400.0])
def test_harmonics_closed_form(t):
    np.testing.assert_allclose(motion.harmonics(A, W, PH, offset=C)(t), series(A, W, PH, C, t), rtol=1e-13,
                               atol=1e-13)


@pytest.mark.parametrize("t", [0.0, 0.83, 12.5])
def test_harmonics_rates_by_central_differences(t):
    p, h = motion.harmonics(A, W, PH, offset=C), 1e-5
    q, qd, qdd = p(t)
    assert qd == pytest.approx((p(t + h)[0] - p(t - h)[0]) / (2 * h), rel=1e-8, abs=1e-10)
    assert qdd == pytest.approx((p(t + h)[1] - p(t - h)[1]) / (2 * h), rel=1e-8, abs=1e-10)


def test_one_harmonic_and_default_phases():
    for t in (0.0, 0.3, 7.1):
        one = motion.harmonics([0.3], [2.0], [0.5], 1.0)
        np.testing.assert_allclose(one(t), motion.harmonic(0.3, 2.0, 0.5, 1.0)(t), rtol=1e-15, atol=1e-15)
        np.testing.assert_allclose(motion.harmonics(A, W)(t), series(A, W, 0 * W, 0.0, t), rtol=1e-13, atol=1e-13)
    assert "harmonics(3 components" in repr(motion.harmonics(A, W))


# --- the JONSWAP spectrum -----------------------------------------------------------------


def dnv_jonswap(w, hs, tp, gamma):
    """DNV-RP-C205 (3.5.5.1): S_J = A_γ S_PM γ^exp(−½((ω−ω_p)/(σω_p))²), written out."""
    wp = 2 * np.pi / tp
    s_pm = 5 / 16 * hs**2 * wp**4 / w**5 * np.exp(-5 / 4 * (w / wp) ** -4)
    sigma = 0.07 if w <= wp else 0.09
    return (1 - 0.287 * np.log(gamma)) * s_pm * gamma ** np.exp(-0.5 * ((w - wp) / (sigma * wp)) ** 2)


@pytest.mark.parametrize("hs, tp, gamma", [(2.0, 8.0, 3.3), (5.0, 12.0, 1.0), (1.0, 5.0, 2.0), (3.0, 9.0, 5.0)])
def test_jonswap_formula_moment_and_peak(hs, tp, gamma):
    w = np.array([0.1, 0.5, 2 * np.pi / tp, 0.9, 1.7, 3.0])
    np.testing.assert_allclose(sea.jonswap(w, hs, tp, gamma), [dnv_jonswap(x, hs, tp, gamma) for x in w], rtol=1e-13)
    m0 = quad(lambda x: sea.jonswap(x, hs, tp, gamma), 0, np.inf, limit=200, epsabs=0, epsrel=1e-10)[0]
    assert m0 == pytest.approx(hs**2 / 16, rel=0.01)  # A_γ's normalisation: measured within 0.25 %
    wp = 2 * np.pi / tp
    peak = minimize_scalar(lambda x: -sea.jonswap(x, hs, tp, gamma), bounds=(0.8 * wp, 1.2 * wp), method="bounded",
                           options={"xatol": 1e-10})
    assert peak.x == pytest.approx(wp, rel=1e-6)


def test_jonswap_is_zero_at_non_positive_frequencies_and_keeps_the_shape():
    S = sea.jonswap(np.array([[-1.0, 0.0], [0.5, 1.0]]), 2.0, 8.0)
    assert S.shape == (2, 2) and S[0, 0] == 0.0 and S[0, 1] == 0.0 and np.all(S[1] > 0)


# --- seeded components ----------------------------------------------------------------------


def test_components_discretise_the_spectrum():
    hs, tp = 2.0, 8.0
    waves = sea.jonswap_waves(hs, tp, n=150, seed=3)
    wp = 2 * np.pi / tp
    dw = 4.5 * wp / 150
    np.testing.assert_allclose(waves.omega, 0.5 * wp + (np.arange(150) + 0.5) * dw, rtol=1e-14)
    np.testing.assert_allclose(waves.amplitude**2 / 2, [dnv_jonswap(x, hs, tp, 3.3) * dw for x in waves.omega],
                               rtol=1e-12)
    assert np.all((0 <= waves.phase) & (waves.phase < 2 * np.pi))
    assert waves.m0 == pytest.approx(hs**2 / 16, rel=0.005)  # measured 1.0011 hs²/16
    assert waves.hs == pytest.approx(4 * np.sqrt(waves.m0))
    with pytest.raises(ValueError, match="read-only"):
        waves.phase[0] = 1.0


def test_same_seed_same_sea_other_seed_other_sea():
    a, b = sea.jonswap_waves(2.0, 8.0, seed=7), sea.jonswap_waves(2.0, 8.0, seed=7)
    c = sea.jonswap_waves(2.0, 8.0, seed=8)
    np.testing.assert_array_equal(a.phase, b.phase)
    assert [a.elevation()(t) for t in (0.0, 3.3)] == [b.elevation()(t) for t in (0.0, 3.3)]
    assert not np.allclose(a.phase, c.phase)
    g = np.random.default_rng(7)
    np.testing.assert_array_equal(sea.jonswap_waves(2.0, 8.0, seed=g).phase, a.phase)


@pytest.mark.parametrize("seed", [1, 2])
def test_long_record_variance_is_m0(seed):
    hs = 2.0
    waves = sea.jonswap_waves(hs, 8.0, seed=seed)
    eta = waves.elevation()
    t = np.arange(0.0, 3 * 3600.0, 0.5)  # three hours
    record = np.array([eta(x)[0] for x in t])
    for k in range(0, len(t), 997):  # the C++ profile against the sum written out
        np.testing.assert_allclose(eta(t[k]), series(waves.amplitude, waves.omega, waves.phase, 0.0, t[k]),
                                   rtol=1e-12, atol=1e-12)
    assert abs(record.mean()) < 0.01 * hs
    assert record.var() == pytest.approx(hs**2 / 16, rel=0.02)  # measured 1.0042, 1.0018


def test_ensemble_at_one_instant_has_variance_m0():
    """Over seeds, η(t) = Σ a_k sin(ω_k t + φ_k) at one t is a sum of independent terms of
    variance a_k²/2: its ensemble variance is m0 (2000 seeds: standard error 3.2 %)."""
    values = [sea.jonswap_waves(2.0, 8.0, n=60, seed=s).elevation()(11.0)[0] for s in range(2000)]
    assert np.var(values) == pytest.approx(sea.jonswap_waves(2.0, 8.0, n=60).m0, rel=0.13)


# --- RAOs -----------------------------------------------------------------------------------


def test_response_of_a_tabulated_rao():
    waves = sea.jonswap_waves(2.0, 8.0, n=40, seed=5)
    w_tab, amp_tab, ph_tab = [0.3, 0.8, 1.5, 3.0], [1.0, 1.4, 0.4, 0.0], [0.0, -0.5, -2.0, -3.0]
    x = waves.response(sea.RAO.table(w_tab, amp_tab, ph_tab))
    amp, arg = np.interp(waves.omega, w_tab, amp_tab), np.interp(waves.omega, w_tab, ph_tab)
    for t in (0.0, 4.2, 100.0):
        # response = Σ |H(ω_k)| a_k sin(ω_k t + φ_k + arg H(ω_k))
        np.testing.assert_allclose(x(t), series(amp * waves.amplitude, waves.omega, waves.phase + arg, 0.0, t),
                                   rtol=1e-12, atol=1e-12)


def test_rao_phase_is_unwrapped_and_held_outside_the_table():
    rao = sea.RAO.table([1.0, 2.0], [1.0, 3.0], [3.0, -3.0])  # −3 = 3 + (2π − 6): 0.283 rad on
    H = rao([0.5, 1.5, 9.0])
    np.testing.assert_allclose(np.abs(H), [1.0, 2.0, 3.0], rtol=1e-14)
    np.testing.assert_allclose(np.angle(H[1]), np.pi, atol=1e-14)  # not 0
    np.testing.assert_allclose(np.angle(H[[0, 2]]), [3.0, -3.0], rtol=1e-14)


def test_oscillator_and_constant_raos():
    rao = sea.RAO.oscillator(6.0, 0.1)
    wn = 2 * np.pi / 6.0
    # ẍ + 2ζω_n ẋ + ω_n² x = ω_n² η: H(ω) = ω_n²/(ω_n² − ω² + 2iζω_nω);
    # at resonance 1/(2ζ), lag π/2.
    H = rao([1e-6, wn, 10.0])
    assert H[0] == pytest.approx(1.0, abs=1e-6) and abs(H[1]) == pytest.approx(5.0)
    r = 10.0 / wn
    assert np.angle(H[1]) == pytest.approx(-np.pi / 2) and abs(H[2]) == pytest.approx(1 / np.hypot(1 - r**2, 0.2 * r))
    assert sea.RAO.constant(0.5, 0.3)(np.array([0.2, 2.0])) == pytest.approx(0.5 * np.exp(0.3j))
    motions = sea.jonswap_waves(2.0, 8.0, n=30).motion({"heave": 1.0, "rx": sea.RAO.constant(0.02)})
    assert set(motions) == {"heave", "rx"}
    waves = sea.jonswap_waves(2.0, 8.0, n=30)
    assert motions["heave"](3.0) == waves.elevation()(3.0)


# --- the moving base ------------------------------------------------------------------------


def rot_zyx(psi, theta, phi):
    cz, sz, cy, sy, cx, sx = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta), np.cos(phi), np.sin(phi)
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    return Rz @ Ry @ Rx


@pytest.mark.parametrize("engine", ENGINES)
def test_six_dof_pose_ship_names_and_aliases(engine):
    dofs = {"surge": 0.5, "sway": motion.harmonic(0.2, 1.0), "heave": motion.harmonics(A, W, PH, C),
            "yaw": motion.harmonic(0.3, 0.5), "pitch": motion.polynomial([0.05, 0.02]),
            "roll": motion.harmonic(0.1, 2.0)}
    model = rf.Model()
    base = model.add_moving_base("deck", dofs, placement=rf.transform((1.0, 0, 2.0)))
    system = model.compile(engine)
    assert system.nq == 0 and system.prescribed_names == ["deck." + c for c in ("x", "y", "z", "rz", "ry", "rx")]
    t = 1.7
    T = system.transform(base, t, [])
    xyz = [dofs[k](t)[0] if not isinstance(dofs[k], float) else dofs[k] for k in ("surge", "sway", "heave")]
    np.testing.assert_allclose(T[:3, 3], np.add(xyz, (1.0, 0, 2.0)), atol=1e-14)
    np.testing.assert_allclose(T[:3, :3], rot_zyx(*(dofs[k](t)[0] for k in ("yaw", "pitch", "roll"))), atol=1e-14)
    # Coordinate names are aliases; missing degrees of freedom are held at 0.
    other = rf.Model()
    b2 = other.add_moving_base("deck", {"z": motion.harmonics(A, W, PH, C)})
    np.testing.assert_allclose(other.compile(engine).transform(b2, t, [])[:3, 3], [0, 0, dofs["heave"](t)[0]],
                               atol=1e-15)


@pytest.mark.parametrize("engine", ENGINES)
def test_base_excited_spring_mass_damper_steady_state(engine):
    """Mass m on a spring k and damper c riding a base heaving y = Y sin Ωt: the steady state is
    x = −mg/k + X sin(Ωt − ψ) with X/Y = √(1 + (2ζr)²)/√((1 − r²)² + (2ζr)²) and
    tan ψ = 2ζr³/(1 − r² + (2ζr)²) (r = Ω/ω_n, ζ = c/(2√(km))). Started on it, it stays on it."""
    m, k, c, Y, Om = 2.0, 800.0, 12.0, 0.15, 14.0
    wn, zeta = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    r = Om / wn
    X = Y * np.sqrt(1 + (2 * zeta * r) ** 2) / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
    psi = np.arctan2(2 * zeta * r**3, 1 - r**2 + (2 * zeta * r) ** 2)
    model = rf.Model(gravity=(0, 0, -G))
    base = model.add_moving_base("base", {"heave": motion.harmonics([Y], [Om])})
    mass = model.add_body("mass", base, rf.Joint.prismatic("z", stiffness=k, damping=c), mass=m, inertia=(1, 1, 1))
    system = model.compile(engine)

    def x(t):  # absolute height and rate of the mass
        return -m * G / k + X * np.sin(Om * t - psi), X * Om * np.cos(Om * t - psi)

    u0, ud0 = x(0.0)[0] - 0.0, x(0.0)[1] - Y * Om  # relative to the base
    t = np.linspace(0.0, 3.0, 61)
    sol = integrate(system, 3.0, [u0], [ud0], t_eval=t)
    z = [system.position(mass, t[j], sol.y[:1, j])[2] for j in range(len(t))]
    np.testing.assert_allclose(z, x(t)[0], atol=1e-9 * X)
    assert X / Y == pytest.approx(1.8526, abs=1e-4)  # r = 0.7, ζ = 0.15: amplified (isolation needs r > √2)


@pytest.mark.parametrize("engine", ENGINES)
def test_pendulum_on_surging_and_heaving_base(engine):
    """A rod hinged about the base's y axis, centre of mass d below: in the base frame
    (I + m d²) θ̈ = m d (ẍ_b cos θ − (g + z̈_b) sin θ), solved here by solve_ivp."""
    m, d, I = 3.0, 0.8, 0.05
    xa, xw, xp = np.array([0.4, 0.1]), np.array([1.1, 2.3]), np.array([0.0, 0.7])
    za, zw, zp = np.array([0.3, 0.05]), np.array([0.9, 3.1]), np.array([1.2, -0.4])
    model = rf.Model(gravity=(0, 0, -G))
    base = model.add_moving_base("base", {"surge": motion.harmonics(xa, xw, xp), "heave": motion.harmonics(za, zw, zp)})
    model.add_body("rod", base, rf.Joint.revolute("y"), mass=m, inertia=(I, I, 0.01), com=(0, 0, -d))
    system = model.compile(engine)

    def rhs(t, y):
        xdd, zdd = series(xa, xw, xp, 0, t)[2], series(za, zw, zp, 0, t)[2]
        return [y[1], m * d * (xdd * np.cos(y[0]) - (G + zdd) * np.sin(y[0])) / (I + m * d**2)]

    t = np.linspace(0.0, 8.0, 81)
    ref = solve_ivp(rhs, (0, 8.0), [0.2, 0.0], t_eval=t, method="DOP853", rtol=1e-12, atol=1e-12)
    sol = integrate(system, 8.0, [0.2], [0.0], t_eval=t)
    np.testing.assert_allclose(sol.y[0], ref.y[0], atol=1e-8)
    assert np.ptp(sol.y[0]) > 0.5  # the base drives it well beyond its start


@pytest.mark.parametrize("engine", ENGINES)
def test_driving_forces_of_a_heaving_and_rolling_base(engine):
    """A box fixed on a base that heaves z(t) and rolls φ(t), centre of mass at (0, a, b) in the
    base: ρ = R_x(φ)(0, a, b), a_box = z̈ e_z + φ̈ e_x × ρ − φ̇² ρ; the drives carry
    Q_y = m a_y, Q_z = m (a_z + g) + m_b (z̈ + g), Q_rx = [ρ × m(a + g e_z)]_x + (I_x + I_bx) φ̈,
    and nothing on x, rz, ry."""
    m, a, b, Ix, mb, Ibx = 40.0, 0.6, 1.1, 3.0, 5.0, 0.7
    heave, roll = motion.harmonics([0.8, 0.2], [0.6, 1.3], [0.1, 2.0]), motion.harmonics([0.1, 0.03], [0.5, 1.7])
    model = rf.Model(gravity=(0, 0, -G))
    base = model.add_moving_base("deck", {"heave": heave, "roll": roll}, mass=mb, inertia=(Ibx, 0.9, 1.2))
    model.add_body("box", base, rf.Joint.fixed(), mass=m, inertia=(Ix, 2.0, 2.5), com=(0, a, b))
    system = model.compile(engine)
    for t in (0.0, 1.3, 4.9):
        (_, _, zdd), (phi, phid, phidd) = heave(t), roll(t)
        rho = np.array([0, a * np.cos(phi) - b * np.sin(phi), a * np.sin(phi) + b * np.cos(phi)])
        acc = np.array([0, 0, zdd]) + phidd * np.cross([1, 0, 0], rho) - phid**2 * rho
        F = m * (acc + [0, 0, G])
        expected = [0, F[1], F[2] + mb * (zdd + G), 0, 0, np.cross(rho, F)[0] + (Ix + Ibx) * phidd]
        np.testing.assert_allclose(system.driving_forces(t, [], []), expected, rtol=1e-12, atol=1e-9)


def test_default_base_mass_is_negligible():
    model = rf.Model(gravity=(0, 0, -G))
    base = model.add_moving_base("deck", {"heave": motion.harmonic(1.0, 1.0)})
    model.add_body("box", base, rf.Joint.fixed(), mass=10.0, inertia=(1, 1, 1))
    Qz = model.compile().driving_forces(0.5, [], [])[2]
    assert Qz == pytest.approx(10.0 * (G - np.sin(0.5)), rel=1e-6)


# --- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize("call, name", [
    (lambda: motion.harmonics([], []), "amplitudes"),
    (lambda: motion.harmonics([1.0, 2.0], [1.0]), "omegas"),
    (lambda: motion.harmonics([1.0], [1.0], [0.0, 1.0]), "phases"),
    (lambda: motion.harmonics([np.nan], [1.0]), "amplitudes"),
    (lambda: motion.harmonics([1.0], [1.0], offset="up"), "offset"),
    (lambda: rf._core._make_profile("harmonic_series_profile", [1.0], [1.0, 2.0], [0.0], 0.0), "omegas"),
    (lambda: rf._core._make_profile("harmonic_series_profile", [1.0], [np.inf], [0.0], 0.0), "omegas"),
    (lambda: rf.Model().add_moving_base("b", {"bob": 1.0}), "motion"),
    (lambda: rf.Model().add_moving_base("b", {"heave": 1.0, "z": 2.0}), "motion"),
    (lambda: rf.Model().add_moving_base("b", {"roll": "fast"}), "motion['roll']"),
    (lambda: rf.Model().add_moving_base("b", [motion.constant(0.0)]), "motion"),
    (lambda: rf.Model().add_moving_base("b", {}, mass=0.0), "mass"),
    (lambda: sea.jonswap(1.0, 0.0, 8.0), "hs"),
    (lambda: sea.jonswap(1.0, 2.0, -8.0), "tp"),
    (lambda: sea.jonswap(1.0, 2.0, 8.0, gamma=0.5), "gamma"),
    (lambda: sea.jonswap([1.0, np.nan], 2.0, 8.0), "omega"),
    (lambda: sea.jonswap_waves(2.0, 8.0, n=0), "n"),
    (lambda: sea.jonswap_waves(2.0, 8.0, n=2.5), "n"),
    (lambda: sea.jonswap_waves(2.0, 8.0, omega_range=(3.0, 1.0)), "omega_range"),
    (lambda: sea.jonswap_waves(2.0, 8.0, seed="abc"), "seed"),
    (lambda: sea.RAO.table([1.0, 1.0], [1.0, 1.0]), "omega"),
    (lambda: sea.RAO.table([1.0, 2.0], [1.0]), "amplitude"),
    (lambda: sea.RAO.table([1.0, 2.0], [1.0, -1.0]), "amplitude"),
    (lambda: sea.RAO.table([1.0, 2.0], [1.0, 1.0], [0.0]), "phase"),
    (lambda: sea.RAO.oscillator(-6.0, 0.1), "period"),
    (lambda: sea.RAO.oscillator(6.0, 0.0), "damping_ratio"),
    (lambda: sea.RAO("not callable"), "function"),
    (lambda: sea.RAO(lambda w: np.ones(3))(np.ones(2)), "rao"),
    (lambda: sea.jonswap_waves(2.0, 8.0).motion({"heel": 1.0}), "raos"),
    (lambda: sea.jonswap_waves(2.0, 8.0).motion({"roll": "big"}), "raos['roll']"),
    (lambda: sea.jonswap_waves(2.0, 8.0).motion([1.0]), "raos"),
    (lambda: sea.Waves([1.0, 2.0], [0.1], [0.0]), "omega"),
])
def test_bad_input_names_the_argument(call, name):
    with pytest.raises(ValueError, match=r"^" + name.replace("[", r"\[").replace("]", r"\]")):
        call()
