"""Kane's spin-up beam (Kane, Ryan & Banerjee 1987), Ω_s = 6 rad/s:
the nonlinear model stays bounded, the linear one grows without bound at the rate the
loss of geometric stiffening predicts; steady-spin modal analysis against a rotating
Hermite-beam reference with centrifugal tension computed here."""

import numpy as np
import pytest
from conftest import hermite_cantilever_frequencies, integrate

import rigidfem as rf

P = rf.samples.KANE_PARAMETERS["kane"]
W = 6.0


def tip_in_hub_frame(system, hub, beam, sol):
    """(len(t), 3) tip position in the hub's frame (m)."""
    out = []
    for t, y in zip(sol.t, sol.y.T):
        q = y[: system.nq]
        T = system.transform(hub.index, t, q)
        out.append((rf.inverse(T) @ np.append(system.position(beam.tip, t, q), 1.0))[:3])
    return np.array(out)


def spin_up(linear, t_end, m=10):
    model, h = rf.samples.kane_beam(omega=W, elements=m, linear=linear)
    system = model.compile()
    t = np.linspace(0, t_end, int(10 * t_end) + 1)
    sol = integrate(system, t_end, np.zeros(system.nq), np.zeros(system.nq), t_eval=t, rtol=1e-9, atol=1e-10)
    return system, h, sol, tip_in_hub_frame(system, h["hub"], h["beam"], sol)


def test_nonlinear_model_stays_bounded_and_settles():
    system, h, sol, tip = spin_up(False, 30.0)
    y = tip[:, 1]
    assert np.max(np.abs(y)) < 3.0
    assert np.max(np.abs(y)) > 0.5  # the spin-up does bend it (lagging tip)
    steady = sol.t > 15.0
    assert np.max(np.abs(y[steady])) < 0.1
    assert abs(np.mean(y[steady])) < 0.2 * np.max(np.abs(y[steady]))  # oscillates about zero
    # No spurious stretching: the tip stays near radius L in the hub frame.
    assert np.all(tip[:, 0] > P["L"] - 0.25) and np.all(tip[:, 0] <= P["L"] + 1e-9)


def test_nonlinear_tip_history_converges_in_m():
    """Tip deflection histories over the spin-up for m = 5, 10, 20: successive differences
    shrink by > 3 (about m⁻²) and m = 10 is within 3 % of the peak from m = 20."""
    y = {m: spin_up(False, 15.0, m=m)[3][:, 1] for m in (5, 10, 20)}
    d1, d2 = np.max(np.abs(y[5] - y[10])), np.max(np.abs(y[10] - y[20]))
    assert d1 / d2 > 3.0
    assert d2 < 0.03 * np.max(np.abs(y[20]))


def test_linear_model_diverges_at_the_rate_of_lost_stiffening():
    """Linear kinematics keep each rfe's x fixed, so the centrifugal potential −½Ω² ∫|r|² dm
    only softens: in the hub frame M q̈ + (K − Ω² M) q ≈ 0 after spin-up, and the first
    mode grows as exp(σ t), σ = sqrt(Ω² − ω1²) with ω1 the linear model's own first frequency."""
    system, h, sol, tip = spin_up(True, 22.0)
    model_at_rest, _ = rf.samples.kane_beam(omega=W, linear=True)
    w1 = rf.modal_analysis(model_at_rest.compile()).omega[0]  # hub at rest at t = 0
    sigma = np.sqrt(W**2 - w1**2)
    late = sol.t >= 18.0
    rate = np.polyfit(sol.t[late], np.log(np.abs(tip[late, 1])), 1)[0]
    assert rate == pytest.approx(sigma, rel=0.01)
    assert np.abs(tip[-1, 1]) > 1e6  # without bound


def test_steady_spin_modal_analysis():
    """Hub turning at a constant rate: the nonlinear model's in-plane frequencies stiffen as a
    rotating beam with centrifugal tension T(x) = ρAΩ²(L² − x²)/2 and lateral softening −Ω²ρA
    (reference: Hermite elements here); the linear model has a real eigenvalue sqrt(Ω² − ω1²)."""
    L, E, rho, A, I = P["L"], P["E"], P["rho"], P["A"], P["I"]
    ref = hermite_cantilever_frequencies(
        L, EI=lambda x: E * I, rhoA=lambda x: rho * A, rhoI=lambda x: rho * I,
        tension=lambda x: rho * A * W**2 * (L**2 - x**2) / 2, softening=W**2, n=2)
    omegas = []
    for m in (20, 40):
        model, h = rf.samples.kane_beam(omega=W, duration=15.0, elements=m)
        modes = rf.modal_analysis(model.compile(), t=20.0)  # the spin-up's steady phase: Ω = W after 15 s
        assert modes.stable
        omegas.append(modes.omega[:2])
    err = np.array([np.abs(w / ref - 1) for w in omegas])
    assert np.all(np.log2(err[0] / err[1]) > 1.9)
    assert np.all(err[1] < 4e-3)
    at_rest = hermite_cantilever_frequencies(L, lambda x: E * I, lambda x: rho * A, lambda x: rho * I, n=1)
    assert omegas[-1][0] > 1.4 * at_rest[0]  # centrifugal stiffening is substantial at Ω = 6
    model, h = rf.samples.kane_beam(omega=W, duration=15.0, elements=20, linear=True)
    system = model.compile()
    w1 = rf.modal_analysis(system, t=0.0).omega[0]  # at rest before the spin-up
    modes = rf.modal_analysis(system, t=20.0)
    assert not modes.stable
    assert modes.eigenvalues.real.max() == pytest.approx(np.sqrt(W**2 - w1**2), rel=0.01)
