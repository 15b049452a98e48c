"""method="auto" (the default): dopri5, or dop853 at rtol <= 1e-6, on non-stiff problems (bit for bit), its stiff
method where dopri5's steps reach its stability boundary (never on rejected steps alone), the choice reported in Result.stats and repr, deterministic (work is
counted, not timed), and the delivered error against independent references."""

import concurrent.futures
import sys
from pathlib import Path

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import samples


def pendulum():
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    model.add_body("rod", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1e-3, 0.08, 0.08),
                   com=(0.5, 0.0, 0.0))
    return model.compile()


def spring_chain(n=8, k=1e6, m=1.0):
    """n masses in a row joined by springs k (prismatic joints, each relative to the last): the
    stiff modes reach 2√(k/m) = 2000 rad/s, the slow one (gravity along the chain) hangs."""
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    parent = model.ground
    for i in range(n):
        parent = model.add_body(f"m{i}", parent, rf.Joint.prismatic("z", stiffness=k), mass=m, inertia=(1, 1, 1))
    return model.compile()


@pytest.mark.parametrize("rtol,explicit", [(2e-6, "dopri5"), (1e-6, "dop853"), (1e-8, "dop853")])
def test_non_stiff_runs_its_explicit_method_bit_for_bit(rtol, explicit):
    """Not stiff: dopri5, or dop853 at rtol <= 1e-6 (the default), exactly as asked for by name."""
    system = pendulum()
    auto = rf.simulate(system, 5.0, q0=[1.0], rtol=rtol, atol=1e-2 * rtol)
    alone = rf.simulate(system, 5.0, method=explicit, q0=[1.0], rtol=rtol, atol=1e-2 * rtol)
    assert auto.stats["method"] == explicit and auto.stats["auto_trials"] == 0
    assert np.array_equal(auto.q, alone.q) and np.array_equal(auto.t, alone.t)
    assert f"auto ({explicit})" in repr(auto) and auto.method == "auto"


def test_stiff_hands_over_and_is_cheaper_than_dopri5():
    """Kane's beam (m = 10): stiff for dopri5 (its step held at ~3.3/ω_max); auto's estimate of ω_max
    at t0 says so and runs the stiff method from the start, does far less work than dopri5 at the
    same tolerance and meets a tight reference to the tolerance's order."""
    model, h = samples.kane_beam(omega=6.0, duration=15.0, elements=10)
    system = model.compile()
    t_eval = np.linspace(0, 20, 201)
    ref = rf.simulate(system, 20.0, method="dopri5", rtol=1e-11, atol=1e-13, t_eval=t_eval, stiffness_warning=False)
    tip = lambda r: r.position(h["beam"].tip, frame=h["hub"])  # noqa: E731
    auto = rf.simulate(system, 20.0, rtol=1e-5, atol=1e-7, t_eval=t_eval)
    dopri = rf.simulate(system, 20.0, method="dopri5", rtol=1e-5, atol=1e-7, t_eval=t_eval, stiffness_warning=False)
    # ω_max = 469 rad/s: dopri5 would need 20 s · 469 / 3.3 = 2800 steps for stability alone (>= 200), so the
    # stiff method (radau5, with no Maxwell arms) runs from the start, without a dopri5 probe
    assert auto.stats["method"] == "radau5 from the start (omega_max = 469 rad/s: stiff for dopri5)"
    assert auto.stats["probe_steps"] == 0
    assert auto.stats["switched_at"] == 0.0 and auto.t[0] == 0.0 and np.all(np.diff(auto.t) > 0)
    alone = rf.simulate(system, 20.0, method="radau5", rtol=1e-5, atol=1e-7, t_eval=t_eval)
    np.testing.assert_array_equal(auto.q, alone.q)  # the same run as the stiff method's own, bit for bit
    loose = rf.simulate(system, 20.0, rtol=0.06, atol=1e-4, t_eval=t_eval)
    assert loose.stats["method"].startswith("radau5 from the start (omega_max")  # at every tolerance
    spring = rf.simulate(system, 20.0, rtol=1e-5, atol=1e-7, t_eval=t_eval, iteration_matrix="spring")
    assert spring.stats["method"].startswith("esdirk43 from the start (omega_max")  # radau5 has no O(n) matrix
    assert auto.stats["rhs_evaluations"] < 0.5 * dopri.stats["rhs_evaluations"]
    error = np.abs(tip(auto) - tip(ref)).max()
    assert error < 1e-2, error  # the tip moves 2 m: a relative error below 1 %


def test_short_stiff_run_is_found_by_a_probe():
    """Kane's beam over 1 s: dopri5 would need 1 · 469 / 3.3 = 142 steps for stability, under the
    200 that start the stiff method at once; a dopri5 probe finds its steps at the stability limit in
    its first window (0.14 s, within a fifth of the run) and the stiff method runs from the start,
    measured against the probe."""
    model, _ = samples.kane_beam(omega=6.0, duration=15.0, elements=10)
    system = model.compile()
    t = np.linspace(0, 1, 31)
    auto = rf.simulate(system, 1.0, rtol=1e-5, atol=1e-7, t_eval=t)
    assert auto.stats["method"] == "radau5 from the start (a dopri5 probe of 20 steps found the problem stiff)"
    alone = rf.simulate(system, 1.0, method="radau5", rtol=1e-5, atol=1e-7, t_eval=t)
    np.testing.assert_array_equal(auto.q, alone.q)


def test_dop853_hands_over_where_its_steps_reach_the_stability_boundary_not_where_they_are_rejected():
    """At rtol <= 1e-7 auto's explicit method is dop853, held to the same rules by its own stability boundary
    (h ρ > 3.6 counted near it): on Kane's beam over 1 s its steps grow to the boundary and the run goes to radau5;
    on the Bricard linkage, rigid and not stiff, a window of dop853's steps through the singular configuration at
    t = 4 s rejects 7 of 20, which is no hand-over (radau5 took 7 times dop853's time there)."""
    model, _ = samples.kane_beam(omega=6.0, duration=15.0, elements=10)
    kane = rf.simulate(model.compile(), 1.0, rtol=1e-8, atol=1e-10)
    assert kane.stats["method"].startswith("dop853, then radau5 from t = ")
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from benchmarks import loop_peers

    scene = loop_peers.bricard()
    auto = rf.simulate(scene.system, scene.t_end, q0=scene.q0, t_eval=scene.t_eval, rtol=1e-7, atol=1e-9)
    alone = rf.simulate(scene.system, scene.t_end, "dop853", q0=scene.q0, t_eval=scene.t_eval, rtol=1e-7, atol=1e-9)
    assert auto.stats["method"] == "dop853" and alone.stats["rejected_steps"] >= 7
    np.testing.assert_array_equal(auto.q, alone.q)


def test_omega_max_is_the_highest_natural_frequency():
    """auto's estimate of the Jacobian's spectral radius against the spring chain's highest natural
    frequency from numpy's eigh (absolute coordinates z = L x: M z'' = −K z)."""
    n, k = 6, 1e6
    system = spring_chain(n, k)
    K_abs = k * (np.diag(np.r_[np.full(n - 1, 2.0), 1.0]) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1))
    omega_max = np.sqrt(np.linalg.eigvalsh(K_abs).max())  # m = 1 kg
    result = rf.simulate(system, 0.01, q0=np.linspace(1e-3, -1e-3, n), t_eval=[0.0, 0.01])
    assert abs(result.stats["omega_max"] - omega_max) < 1e-2 * omega_max  # measured: 0.23 % low
    dopri = rf.simulate(system, 0.01, method="dopri5", q0=np.zeros(n), t_eval=[0.0, 0.01], stiffness_warning=False)
    assert np.isnan(dopri.stats["omega_max"])
    # stiff: 2 s · 1942 / 3.3 = 1180 dopri5 steps for stability alone, so radau5 from the start
    long = rf.simulate(system, 2.0, q0=np.linspace(1e-3, -1e-3, n), t_eval=[0.0, 2.0], rtol=1e-5, atol=1e-8)
    assert long.stats["method"] == "radau5 from the start (omega_max = 1.94e+03 rad/s: stiff for dopri5)"


def test_choice_is_deterministic_across_threads():
    model, _ = samples.kane_beam(omega=6.0, duration=15.0, elements=8)
    system = model.compile()

    def run(_):
        return rf.simulate(system, 5.0, rtol=1e-4, t_eval=np.linspace(0, 5, 11))

    serial = [run(k) for k in range(2)]
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        threaded = list(pool.map(run, range(4)))
    for r in threaded + serial[1:]:
        assert np.array_equal(r.q, serial[0].q) and r.stats["method"] == serial[0].stats["method"]


def test_stiff_spring_chain_against_the_modal_solution():
    """Linear: the exact solution is the modal superposition of x'' = −K x + g (computed here with
    numpy's eigh); auto hands over and stays within the tolerance's order."""
    n, k = 6, 1e6
    system = spring_chain(n, k)
    # Coordinates: each mass's offset from the previous one; K of the relative coordinates via the
    # absolute positions z = L x (L lower-triangular ones): M z'' = −K_abs z + m g.
    L = np.tril(np.ones((n, n)))
    K_abs = k * (np.diag(np.r_[np.full(n - 1, 2.0), 1.0]) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1))
    x0 = np.linspace(1e-3, -1e-3, n)
    z0 = L @ x0
    z_static = np.linalg.solve(K_abs, np.full(n, -9.81))
    w2, V = np.linalg.eigh(K_abs)
    t = np.linspace(0.0, 0.05, 51)
    modal = V.T @ (z0 - z_static)
    z = z_static[:, None] + V @ (modal[:, None] * np.cos(np.sqrt(w2)[:, None] * t[None, :]))
    x_exact = np.linalg.solve(L, z).T
    result = rf.simulate(system, 0.05, q0=x0, t_eval=t, rtol=1e-6, atol=1e-9)
    assert result.stats["method"] != "dopri5"
    assert np.abs(result.q - x_exact).max() < 1e-3 * np.abs(x0).max()


def four_bar(crank_spring: dict, guess):
    """A four-bar (crank 0.3 m, coupler 0.8 m, rocker 0.6 m, ground 0.7 m) under gravity, the crank's
    joint with ``crank_spring``; the system and q0 closing the loop nearest ``guess``."""
    model = rf.Model(gravity=(0, -9.81, 0))

    def rod(L):
        return dict(mass=1.0, inertia=(1e-4, L * L / 12, L * L / 12), com=(L / 2, 0, 0))

    crank = model.add_body("crank", model.ground, rf.Joint.revolute("z", **crank_spring), **rod(0.3))
    coupler = model.add_body("coupler", crank, rf.Joint.revolute("z"), **rod(0.8), placement=rf.transform((0.3, 0, 0)))
    rocker = model.add_body("rocker", model.ground, rf.Joint.revolute("z"), **rod(0.6),
                            placement=rf.transform((0.7, 0, 0)))
    model.add_loop_joint("loop0", "revolute", coupler.point((0.8, 0, 0)), rocker.point((0.6, 0, 0)))
    system = model.compile()
    return system, system.assemble(guess)[0]


def test_closed_chain_runs_and_stays_closed():
    system, q0 = four_bar(dict(stiffness=15.0, rest=1.2), [0.4, -1.9, 4.6])
    result = rf.simulate(system, 2.0, q0=q0, t_eval=np.linspace(0, 2, 21))
    g = [np.abs(system.loop_constraints(t, q, np.zeros(3))[0]).max() for t, q in zip(result.t, result.q)]
    assert max(g) < 1e-10 and result.stats["method"] == "dop853"  # the default rtol 1e-6
    tight = rf.simulate(system, 2.0, method="dopri5", q0=q0, t_eval=np.linspace(0, 2, 21), rtol=1e-11, atol=1e-13)
    assert np.abs(result.q - tight.q).max() < 100 * 1e-6 * np.abs(tight.q).max()


def work(stats, nq):
    """auto's counted work (auto_method.cpp): right-hand sides, nq per tangent, one per O(n) factorisation."""
    return stats["rhs_evaluations"] + nq * stats["jacobians"] + stats["factorizations"]


def test_stiff_closed_chain_hands_over_and_stays_closed():
    """A four-bar whose crank spring (1e6 N·m/rad, damped by 100 N·m·s/rad) is stiff: dop853 (the default rtol)
    resolves its fast mode while it decays, then its steps sit at the stability boundary and auto hands over to
    radau5, which projects every step onto the loop. Measured: 0.72 of dop853's CPU time and 0.63 of radau5's;
    its state within 20 rtol of a tight dopri5 run."""
    system, q0 = four_bar(dict(stiffness=1e6, rest=1.2, damping=100.0), [1.25, -1.9, 4.6])
    t = np.linspace(0, 0.2, 11)
    auto = rf.simulate(system, 0.2, q0=q0, t_eval=t, rtol=1e-6, atol=1e-9)
    alone = rf.simulate(system, 0.2, method="dop853", q0=q0, t_eval=t, rtol=1e-6, atol=1e-9, stiffness_warning=False)
    ref = rf.simulate(system, 0.2, method="dopri5", q0=q0, t_eval=t, rtol=1e-10, atol=1e-13, stiffness_warning=False)
    assert auto.stats["method"].startswith("dop853, then radau5")
    assert work(auto.stats, system.nq) < 0.8 * work(alone.stats, system.nq)  # measured 2140 against 3254
    assert np.abs(auto.q - ref.q).max() < 20 * 1e-6 * np.abs(ref.q).max()
    g = [np.abs(system.loop_constraints(tk, q, np.zeros(3))[0]).max() for tk, q in zip(auto.t, auto.q)]
    assert max(g) < 1e-10


def test_rejected_steps_alone_do_not_hand_over():
    """A double pendulum swinging wide is not stiff, but dopri5 rejects steps where it turns sharply: auto keeps
    dopri5 (bit for bit), where counting rejections as stiffness once handed it to radau5 at 2.2 times dopri5's
    CPU time (1.68 against 0.75 ms at rtol 1e-4)."""
    system = samples.double_pendulum()
    system = (system[0] if isinstance(system, tuple) else system).compile()
    t = np.linspace(0, 10, 101)
    q0 = np.ones(system.nq)
    auto = rf.simulate(system, 10.0, q0=q0, t_eval=t, rtol=1e-4, atol=1e-6)
    alone = rf.simulate(system, 10.0, method="dopri5", q0=q0, t_eval=t, rtol=1e-4, atol=1e-6)
    assert alone.stats["rejected_steps"] * 6 >= 20  # a window's worth, which the old rule counted as stiff
    assert auto.stats["method"] == "dopri5" and auto.stats["auto_trials"] == 0
    np.testing.assert_array_equal(auto.q, alone.q)


def test_no_free_coordinate():
    """Every coordinate prescribed (nq = 0): the default method runs the drives (it crashed once on
    the empty tolerance vector)."""
    model = rf.Model()
    body = model.add_body("a", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    model.prescribe(body, rf.motion.harmonic(1.0, 2.0))
    result = rf.simulate(model.compile(), 1.0, t_eval=[0.0, 0.5, 1.0], rtol=0.1)
    assert result.q.shape == (3, 0) and result.driving_forces.shape == (3, 1)
    assert result.driving_forces[1, 0] == pytest.approx(-1.0 * 4.0 * np.sin(1.0), rel=1e-12)  # I θ̈, θ = sin 2t


def test_bad_options():
    with pytest.raises(ValueError, match="adaptive"):
        rf.simulate(pendulum(), 1.0, method="auto", adaptive=False)
