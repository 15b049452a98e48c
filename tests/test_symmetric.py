"""gauss6, the symmetric method (Gauss–Legendre, 3 stages): its order 6, a quadratic invariant kept at any
step, time reversibility, and the energy of conservative mechanisms (a pendulum, a closed four-bar) over long
runs without drift, where radau5 and rk4 at the same step lose it steadily; its refusals. References: SciPy's
DOP853, the exact invariants of the problems, and the other methods at the same step."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rigidfem as rf

from conftest import DOUBLE_PENDULUM_Y0 as Y0


def test_order_six_on_the_double_pendulum(pendulum2):
    """Fixed steps 0.1 ... 0.0125 s against DOP853 at 1e-13: the error falls 64-fold per halving (measured orders
    3.8, 6.0, 6.0: at h = 0.1 s the error has not settled into its asymptote)."""
    system, ref = pendulum2
    errors = []
    for dt in (0.1, 0.05, 0.025, 0.0125):
        r = rf.simulate(system, 1.0, method="gauss6", dt=dt, q0=Y0[:2], newton_tol=1e-13, newton_max_iterations=50)
        assert r.stats["steps"] == round(1.0 / dt)
        errors.append(np.max(np.abs(np.r_[r.q[-1], r.qd[-1]] - ref.y[:, -1])))
    observed = np.log2(np.array(errors[:-1]) / errors[1:])[1:]
    assert np.all(observed > 5.6) and np.all(observed < 6.5), (observed, errors)


def test_a_quadratic_invariant_is_kept_at_any_step():
    """A mass on a spring (ω = 20 rad/s) at h = 2.5 s (hω = 50): Gauss–Legendre keeps ½kx² + ½mẋ² of a linear
    system exactly (measured 1.7e-13 of it over 100 steps), where radau5, L-stable, removes the oscillation in a
    step or two."""
    system = rf.samples.spring_mass()[0].compile()
    runs = {m: rf.simulate(system, 250.0, method=m, dt=2.5, adaptive=False, q0=[0.01]) for m in ("gauss6", "radau5")}
    E = runs["gauss6"].energy
    assert E[0] == pytest.approx(0.5 * 800.0 * 0.01**2, rel=1e-14)
    assert np.max(np.abs(E / E[0] - 1)) < 1e-11
    assert runs["radau5"].energy[-1] < 1e-6 * E[0]


@pytest.mark.parametrize("dt", [0.05, 0.02])
def test_time_reversible(dt):
    """Symmetric: the double pendulum run 1 s forward, its velocities reversed, and run 1 s again comes back to
    its initial state to Newton's tolerance (measured 4.6e-11 and 3.1e-12); radau5 at the same steps misses by its
    error (8.6e-5 and 9.0e-7)."""
    model, _ = rf.samples.double_pendulum()
    system = model.compile()
    miss = {}
    for method in ("gauss6", "radau5"):
        there = rf.simulate(system, 1.0, method=method, dt=dt, adaptive=False, q0=Y0[:2], qd0=Y0[2:])
        back = rf.simulate(system, 1.0, method=method, dt=dt, adaptive=False, q0=there.q[-1], qd0=-there.qd[-1])
        miss[method] = np.max(np.abs(np.r_[back.q[-1] - Y0[:2], -back.qd[-1] - Y0[2:]]))
    assert miss["gauss6"] < 1e-9
    assert miss["radau5"] > 100 * miss["gauss6"]


def _energy_error(result, part):
    """The largest |E − E₀| (J) over the first and the last ``part`` of the outputs."""
    dE = np.abs(result.energy - result.energy[0])
    k = int(len(dE) * part)
    return dE[:k].max(), dE[-k:].max()


def test_a_pendulums_energy_does_not_drift():
    """A pendulum released at 2.5 rad (its energy a nonlinear function of the state), h = 0.05 s over 500 s
    (10,000 steps, about 140 periods): gauss6's energy error is the same over the last fifth as over the first
    (measured 4.18e-8 and 4.17e-8 J), against radau5's steady loss (2.5e-4 then 1.3e-3 J) and rk4's (5.4e-3 then
    2.7e-2 J) at the same step. The period of the swing, by SciPy at 1e-12, checks the run's phase."""
    system = rf.samples.pendulum()[0].compile()
    t_eval = np.linspace(0.0, 500.0, 5001)
    runs = {m: rf.simulate(system, 500.0, method=m, dt=0.05, adaptive=False, q0=[2.5], t_eval=t_eval)
            for m in ("gauss6", "radau5", "rk4")}
    first, last = _energy_error(runs["gauss6"], 0.2)
    assert last < 1.5 * first and last < 1e-7
    for other in ("radau5", "rk4"):
        o_first, o_last = _energy_error(runs[other], 0.2)
        assert o_last > 3 * o_first and o_last > 1000 * last, other
    ref = solve_ivp(system.rhs, (0.0, 500.0), [2.5, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t_eval)
    assert np.max(np.abs(runs["gauss6"].q[:, 0] - ref.y[0])) < 1e-3


def test_a_closed_four_bars_energy_does_not_drift():
    """The four-bar (a loop joint, 3 of its 5 rows redundant) falling under gravity at h = 10 ms over 100 s: each
    step projected onto the loop (closure within 1e-12), gauss6's energy error stays within 1.5 times its first
    fifth's (measured 9.5e-8 and 1.0e-7 J over 200 s), where radau5's grows (3.3e-6 then 1.2e-5 J)."""
    from test_loops import closed_q, four_bar

    system = four_bar()
    q0, _ = system.assemble(closed_q(0.4))
    t_eval = np.linspace(0.0, 100.0, 1001)
    runs = {m: rf.simulate(system, 100.0, method=m, dt=0.01, adaptive=False, q0=q0, t_eval=t_eval)
            for m in ("gauss6", "radau5")}
    g = runs["gauss6"]
    closure = max(np.abs(system.loop_constraints(tk, qk, qdk)[0]).max() for tk, qk, qdk in zip(g.t, g.q, g.qd))
    assert closure <= 1e-12
    first, last = _energy_error(g, 0.2)
    assert last < 1.5 * first and last < 3e-7
    r_first, r_last = _energy_error(runs["radau5"], 0.2)
    assert r_last > 2 * r_first and r_last > 10 * last


def test_refusals(pendulum2):
    """gauss6 runs at fixed steps only and without sensitivities, Maxwell arms or the spring matrix; each refusal
    names the argument."""
    system, _ = pendulum2
    with pytest.raises(ValueError, match="dt: expected a positive step"):
        rf.simulate(system, 1.0, method="gauss6")
    with pytest.raises(ValueError, match="adaptive: the method 'gauss6' has no error estimate"):
        rf.simulate(system, 1.0, method="gauss6", dt=0.01, adaptive=True)
    with pytest.raises(ValueError, match="sensitivities: gauss6"):
        rf.simulate(system, 1.0, method="gauss6", dt=0.01, sensitivities=["link1.mass"])
    with pytest.raises(ValueError, match="iteration_matrix: gauss6"):
        rf.simulate(system, 1.0, method="gauss6", dt=0.01, iteration_matrix="spring")
    from test_viscoelastic import zener_oscillator

    with pytest.raises(ValueError, match="method: 'gauss6' does not integrate Maxwell arms"):
        rf.simulate(zener_oscillator()[0].compile(), 1.0, method="gauss6", dt=0.01)
    assert rf.methods()["gauss6"].order == 6 and not rf.methods()["gauss6"].adaptive
