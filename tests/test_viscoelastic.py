"""The viscoelastic sde laws (issue 15, item 1): Kelvin–Voigt, the standard linear solid (Zener) and
the generalised Maxwell model (Prony series), whose arms' forces are internal variables of the state.

References derived here, not read off the code:
- a mass on a spring c with one Maxwell arm (k, τ): y = [q, q̇, s], ẏ = [[0, 1, 0], [−c/m, 0, −1/m],
  [0, k, −1/τ]] y, solved by the matrix exponential;
- a beam whose every sde has Kelvin–Voigt damping b = μc: each undamped mode ω has λ² + μω²λ + ω² = 0,
  so ζ = μω/2 exactly;
- a beam whose every sde stiffness c carries arms (g_j c, τ_j): each relaxed mode ω (the springs
  E∞) has (λ² + ω²) Π_j (1 + λτ_j) + ω² λ Σ_j g_j τ_j Π_{i≠j} (1 + λτ_i) = 0 — a cubic for Zener;
- the energy balance: kinetic + gravity + elastic (with the arms' s²/2k) + ∫ dissipated power = E(0).
"""

import pickle
import warnings

import numpy as np
import pytest
import scipy.linalg
from numpy.polynomial import polynomial as P
from scipy.integrate import cumulative_trapezoid

import rigidfem as rf

M_, C_, K1, TAU = 2.0, 50.0, 30.0, 0.2  # kg, N/m, N/m, s
T_END = 2.0


def zener_oscillator(arms=((K1, TAU),)):
    model = rf.Model(gravity=None)
    body = model.add_body("mass", model.ground, rf.Joint.prismatic("x", stiffness=C_), mass=M_, inertia=(1, 1, 1))
    for k, tau in arms:
        model.add_maxwell_arm(body, k, tau)
    return model, body


def exact_oscillator(t, y0):
    A = np.array([[0.0, 1.0, 0.0], [-C_ / M_, 0.0, -1.0 / M_], [0.0, K1, -1.0 / TAU]])
    return np.array([scipy.linalg.expm(A * tk) @ y0 for tk in t])


def oscillator_error(system, method, t_eval, **options):
    y0 = np.array([0.1, 0.0, 0.5])  # the arm starts loaded: s0 is a state like q0
    r = rf.simulate(system, T_END, method=method, q0=[y0[0]], s0=[y0[2]], t_eval=t_eval, **options)
    return np.max(np.abs(np.c_[r.q, r.qd, r.arm_forces] - exact_oscillator(t_eval, y0)))


@pytest.mark.parametrize("method, order, dt", [
    ("euler", 1, 2e-4), ("symplectic_euler", 1, 2e-4), ("rk4", 4, 2e-2), ("newmark", 2, 1e-2), ("hht", 2, 1e-2),
    ("generalized_alpha", 2, 1e-2), ("implicit_spring", 2, 1e-2), ("esdirk43", 4, 4e-2)])
def test_fixed_steps_converge_at_their_order_with_arms(method, order, dt):
    system = zener_oscillator()[0].compile()
    t_eval = np.linspace(0.0, T_END, 11)
    options = {"adaptive": False} if method == "esdirk43" else {}
    e1 = oscillator_error(system, method, t_eval, dt=dt, **options)
    e2 = oscillator_error(system, method, t_eval, dt=dt / 2, **options)
    observed = np.log2(e1 / e2)
    assert abs(observed - order) < 0.35, (e1, e2, observed)


@pytest.mark.parametrize("method", ["dopri5", "rkf45", "esdirk43", "auto", "generalized_alpha"])
def test_adaptive_methods_meet_their_tolerance_with_arms(method):
    system = zener_oscillator()[0].compile()
    t_eval = np.linspace(0.0, T_END, 41)
    options = {"adaptive": True} if method == "generalized_alpha" else {}
    tight = oscillator_error(system, method, t_eval, rtol=1e-9, atol=1e-12, **options)
    loose = oscillator_error(system, method, t_eval, rtol=1e-5, atol=1e-8, **options)
    assert tight < 1e-5 if method == "generalized_alpha" else tight < 1e-7
    assert tight < loose


def test_several_arms_add_up_like_their_sum_when_their_times_agree():
    # Two arms with one τ are one arm of the summed stiffness: the same motion.
    one = rf.simulate(zener_oscillator()[0].compile(), 1.0, method="dopri5", q0=[0.1], rtol=1e-10, atol=1e-13,
                      t_eval=np.linspace(0, 1, 11))
    two = rf.simulate(zener_oscillator(((0.25 * K1, TAU), (0.75 * K1, TAU)))[0].compile(), 1.0, method="dopri5",
                      q0=[0.1], rtol=1e-10, atol=1e-13, t_eval=np.linspace(0, 1, 11))
    np.testing.assert_allclose(two.q, one.q, atol=1e-9)
    np.testing.assert_allclose(two.arm_forces.sum(axis=1), one.arm_forces[:, 0], atol=1e-7)


def beam_system(material, elements=4, formulation="classical", gravity=None, deform=None):
    model = rf.Model(gravity=gravity)
    beam = model.add_beam("b", model.ground, 1.0, material, rf.Section.rectangle(0.02, 0.01), elements,
                          formulation=formulation, deform=deform)
    return model.compile(), beam


def nearest_distance(computed, expected):
    """max over expected roots of the relative distance to the nearest computed one."""
    return max(np.min(np.abs(computed - r)) / abs(r) for r in expected)


def test_kelvin_voigt_damps_every_mode_with_zeta_mu_omega_over_2():
    mu = 2e-4  # s
    system, _ = beam_system(rf.Material(E=70e9, rho=2700.0, nu=0.3, retardation=mu))
    relaxed, _ = beam_system(rf.Material(E=70e9, rho=2700.0, nu=0.3))
    omega = rf.modal_analysis(relaxed).omega
    lam = np.linalg.eigvals(rf.linearize(system, np.zeros(system.nq)).A)
    expected = np.concatenate([np.roots([1.0, mu * w * w, w * w]) for w in omega])  # λ² + μω²λ + ω²
    assert nearest_distance(lam, expected) < 1e-9
    np.testing.assert_allclose(rf.modal_analysis(system).damping_ratios, mu * omega / 2, rtol=1e-9)


@pytest.mark.parametrize("prony", [((2e9, 1e-3),), ((1.5e9, 2e-4), (0.5e9, 5e-3))])
def test_maxwell_arms_put_each_modes_eigenvalues_at_the_roots_of_its_polynomial(prony):
    E_inf = 1e9
    material = rf.Material(E=E_inf, rho=1200.0, nu=0.35, prony=prony)
    system, _ = beam_system(material)  # classical: axial, shear, torsion and bending sdes, all 3D
    assert system.nz == len(prony) * system.nq
    relaxed, _ = beam_system(rf.Material(E=E_inf, rho=1200.0, nu=0.35))
    omega = rf.modal_analysis(relaxed).omega
    lam = np.linalg.eigvals(rf.linearize(system, np.zeros(system.nq)).A)
    expected = []
    def product(taus):  # Π (1 + λτ), coefficients low to high
        poly = np.array([1.0])
        for tau in taus:
            poly = P.polymul(poly, [1.0, tau])
        return poly

    taus = [tau for _, tau in prony]
    for w in omega:  # (λ² + ω²) Π_j (1 + λτ_j) + ω² λ Σ_j g_j τ_j Π_{i≠j} (1 + λτ_i)
        poly = P.polymul([w * w, 0.0, 1.0], product(taus))
        for j, (E_j, tau_j) in enumerate(prony):
            poly = P.polyadd(poly, P.polymul([0.0, w * w * (E_j / E_inf) * tau_j], product(taus[:j] + taus[j + 1:])))
        expected.extend(P.polyroots(poly))
    assert len(expected) == len(lam)
    assert nearest_distance(lam, np.array(expected)) < 1e-9


def test_zener_material_and_relaxation_fit():
    mat = rf.Material.zener(E0=3e9, E_inf=1e9, tau=0.01, rho=1200.0)
    assert mat.E == 1e9 and mat.prony == ((2e9, 0.01),)
    np.testing.assert_allclose(mat.relaxation_modulus([0.0, 0.01, np.inf]), [3e9, 1e9 + 2e9 / np.e, 1e9])
    # Relaxation data of a known two-term series, fitted on its own relaxation times.
    t = np.logspace(-4, 1, 60)
    E_t = 1e9 + 2e9 * np.exp(-t / 1e-3) + 0.5e9 * np.exp(-t / 1e-1)
    fit = rf.Material.from_relaxation(t, E_t, rho=1200.0, times=[1e-3, 1e-2, 1e-1])
    np.testing.assert_allclose(fit.relaxation_modulus(t), E_t, rtol=1e-6)
    np.testing.assert_allclose(fit.E, 1e9, rtol=1e-6)
    # The default times (one per decade) approximate it.
    approx = rf.Material.from_relaxation(t, E_t, rho=1200.0)
    assert np.max(np.abs(approx.relaxation_modulus(t) / E_t - 1.0)) < 0.05


def test_energy_balance_of_a_zener_beam_in_large_amplitude_vibration():
    # A thin strip falling from straight under gravity: the tip swings by a good fraction of L.
    mat = rf.Material(E=2e9, rho=1200.0, nu=0.35, retardation=1e-4, prony=((1e9, 0.02), (0.5e9, 0.2)))
    model = rf.Model()
    beam = model.add_beam("b", model.ground, 1.0, mat, rf.Section.rectangle(0.02, 0.002), 8, formulation="modified",
                          deform=("bend_y",))
    system = model.compile()
    t = np.linspace(0.0, 1.0, 2001)
    for method, options in (("dopri5", dict(rtol=1e-9, atol=1e-12)), ("esdirk43", dict(rtol=1e-8, atol=1e-11)),
                            ("newmark", dict(dt=2.5e-4)), ("auto", {})):
        r = rf.simulate(system, 1.0, method=method, t_eval=t, **options)
        assert abs(r.position(beam.tip)[:, 2].min()) > 0.3  # large amplitude
        dissipated = cumulative_trapezoid(r.dissipated_power, t, initial=0.0)
        balance = r.energy + dissipated - r.energy[0]
        scale = np.ptp(r.energy)
        # measured: 2.7e-7 (dopri5, esdirk43) to 4.3e-7 (newmark) of the energy given up
        assert np.max(np.abs(balance)) < 1e-5 * scale, (method, np.max(np.abs(balance)) / scale)
        assert np.all(np.diff(dissipated) >= 0.0) and dissipated[-1] > 0.5 * scale
        # the arms hold a good part of the elastic energy (s²/2k), so leaving them out would show
        k = system.arms[:, 1]
        assert np.max(0.5 * np.sum(r.arm_forces ** 2 / k, axis=1)) > 0.1 * scale


def test_arm_states_survive_pickling_and_npz(tmp_path):
    model, _ = zener_oscillator(((K1, TAU), (2 * K1, 5 * TAU)))
    system = model.compile()
    again = pickle.loads(pickle.dumps(system))
    np.testing.assert_array_equal(again.arms, system.arms)
    r = rf.simulate(system, 0.5, method="dopri5", q0=[0.1], t_eval=np.linspace(0, 0.5, 6))
    loaded = rf.load_npz(r.to_npz(tmp_path / "r.npz"), system)
    np.testing.assert_array_equal(loaded.arm_forces, r.arm_forces)
    np.testing.assert_allclose(loaded.energy, r.energy)


def test_bad_input_names_the_argument():
    model, body = zener_oscillator()
    for kwargs, argument in ((dict(stiffness=-1.0, tau=1.0), "stiffness"), (dict(stiffness=1.0, tau=0.0), "tau"),
                             (dict(stiffness="a", tau=1.0), "stiffness")):
        with pytest.raises(ValueError, match=argument):
            model.add_maxwell_arm(body, **kwargs)
    with pytest.raises(ValueError, match="coordinate"):
        model.prescribe(body, rf.motion.constant(0.0))
    system = model.compile()
    with pytest.raises(ValueError, match="radau5"):
        rf.simulate(system, 1.0, method="radau5")
    with pytest.raises(ValueError, match="method"):
        rf.simulate(system, 1.0, method="scipy:Radau")
    with pytest.raises(ValueError, match="s0"):
        rf.simulate(system, 1.0, s0=[1.0, 2.0])
    with pytest.warns(UserWarning, match="Maxwell arms"):
        rf.modal_analysis(system)
    for prony in (((1e9,),), ((1e9, -1.0),), "x", ((-1e9, 1.0),)):
        with pytest.raises(ValueError, match="prony"):
            rf.Material(E=1e9, rho=1000.0, prony=prony)
    with pytest.raises(ValueError, match="E_inf"):
        rf.Material.zener(E0=1e9, E_inf=2e9, tau=1.0, rho=1000.0)
    with pytest.raises(ValueError, match="material"):
        rf.Model().add_beam("b", "ground", 1.0, [rf.Material(E=1e9, rho=1e3, prony=((1e9, 1.0),))] * 2,
                            rf.Section.rectangle(0.01, 0.01), 2)
    with pytest.raises(ValueError, match="material"):
        rf.Model().add_beam("b", "ground", rf.motion.polynomial([1.0, 0.1]), rf.Material(E=1e9, rho=1e3, prony=((1e9, 1.0),)),
                            rf.Section.rectangle(0.01, 0.01), 2, deform=("bend_z",))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rf.linearize(system, [0.0])  # the arms are states there: no warning
