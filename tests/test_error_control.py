"""Error control on outputs and the error bar of a result (issue 24, items 1 and 3).

References computed here: the exact solution of the linearised RFEM equations of a strip released under
weak gravity (modes by scipy's eigh, each a 1 − cos ωt), and tight runs holding the whole state."""

import numpy as np
import pytest
import scipy.linalg

import rigidfem as rf

STEEL = rf.Material(E=2.1e11, rho=7850.0)


def strip(m, g=9.81e-3):
    """The strip of issue 24 (1 m, 20 × 2 mm, bending only, undamped) released straight from rest; weak
    gravity keeps the deflection (0.3 mm) in the linear range."""
    model = rf.Model(gravity=(0.0, -g, 0.0))
    beam = model.add_beam("beam", model.ground, 1.0, STEEL, rf.Section.rectangle(0.002, 0.02), m, deform=("bend_z",))
    return model.compile(), beam


def modal_tip(system, beam, t):
    """The tip (len(t), 3) of the linearised equations M q̈ + K q = f₀ from rest at q = 0: with
    K φ = ω² M φ, q = Σ φ_k (φ_kᵀ f₀/ω_k²)(1 − cos ω_k t)."""
    n = system.nq
    q, z = np.zeros(n), np.zeros(n)
    M = system.mass_matrix(0.0, q)
    dfdq, _ = system.force_jacobians(0.0, q, z)
    w2, phi = scipy.linalg.eigh(-dfdq, M)  # φᵀ M φ = I
    f0 = system.generalized_forces(0.0, q, z)
    static = phi.T @ f0 / w2
    Q = ((1.0 - np.cos(np.outer(t, np.sqrt(w2)))) * static) @ phi.T
    return np.array([system.position(beam.tip, 0.0, qk) for qk in Q])


@pytest.fixture(scope="module")
def strip16():
    system, beam = strip(16)
    t = np.linspace(0.0, 0.5, 201)
    return system, beam, t, modal_tip(system, beam, t)


def test_the_default_measures_outputs_and_skips_the_modes_no_output_sees(strip16):
    """The default (every body's displacement, to rtol × the model's size L) takes a tenth of the steps
    of the state measure (every coordinate and rate to rtol) at the same rtol, and holds the tip to what
    it asked."""
    system, beam, t, tip_ref = strip16
    rtol = 1e-6
    default = rf.simulate(system, 0.5, rtol=rtol, atol=0.0, t_eval=t)
    state = rf.simulate(system, 0.5, rtol=rtol, atol=1e-3 * rtol, t_eval=t, error_on="state")
    L = default.stats["model_size"]
    assert L == pytest.approx(1.0, rel=0.02)  # about the strip's length: the box of its bodies
    assert np.isnan(state.stats["model_size"])
    assert default.stats["steps"] < 0.1 * state.stats["steps"], (default.stats["steps"], state.stats["steps"])
    error = np.linalg.norm(default.position(beam.tip) - tip_ref, axis=1).max()
    assert error < rtol * L, (error, rtol * L)


def test_error_on_a_point_holds_that_point(strip16):
    system, beam, t, tip_ref = strip16
    for atol in (1e-7, 1e-9):
        r = rf.simulate(system, 0.5, error_on=[beam.tip], rtol=0.0, atol=atol, t_eval=t)
        error = np.linalg.norm(r.position(beam.tip) - tip_ref, axis=1).max()
        assert error < 2 * atol, (atol, error)  # measured 0.2-0.6 of atol
    coarse = rf.simulate(system, 0.5, error_on=beam.tip, rtol=0.0, atol=1e-7, t_eval=t)
    fine = rf.simulate(system, 0.5, error_on=[beam.tip], rtol=0.0, atol=1e-9, t_eval=t)
    assert coarse.stats["steps"] < fine.stats["steps"]


def test_error_estimate_is_within_a_factor_3_of_the_true_error(strip16):
    """The second run's difference against the exact solution of the linearised equations, for an
    adaptive run (tolerances / 10) and a fixed step (dt / 2, Richardson's 4/3 for order 2)."""
    system, beam, t, tip_ref = strip16
    tip = lambda r: r.position(beam.tip)  # noqa: E731
    # (the linearised reference is within ~1e-11 m of the RFEM's own solution: errors well above that)
    for kw in (dict(rtol=0.0, atol=1e-7), dict(rtol=0.0, atol=1e-9),
               dict(method="generalized_alpha", dt=1e-3), dict(method="rk4", dt=2e-4)):
        r = rf.simulate(system, 0.5, t_eval=t, **kw)
        true = np.linalg.norm(tip(r) - tip_ref, axis=1).max()
        estimate = np.linalg.norm(r.error_estimate.of(tip), axis=1).max()
        assert 1 / 3 < estimate / true < 3, (kw, estimate, true)
        assert r.estimate is r.error_estimate  # computed once, kept
    assert r.error_estimate.names == ["bodies"] and r.error_estimate.units == ["m"]
    assert "estimated error bodies" in repr(r) and "bodies.error" in r.to_dataframe().columns
    assert "estimated error" in r._repr_html_()


def test_error_estimate_with_the_run_and_of_each_output():
    model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=4)
    system = model.compile()
    r = rf.simulate(system, 2.0, rtol=1e-4, error_on=[h["beam"].tip, "beam.rfe2.rz"], error_estimate=True,
                    t_eval=np.linspace(0, 2, 21))
    assert r.estimate is not None and r.error_estimate.names[1] == "beam.rfe2.rz"
    assert r.error_estimate.units == ["m", "rad"] and r.error_estimate.history.shape == (21, 2)
    assert r.error_estimate.max[0] > 0 and "fixed" not in r.error_estimate.how
    # the first output's history is the tip's own estimate
    np.testing.assert_allclose(r.error_estimate.history[:, 0],
                               np.linalg.norm(r.error_estimate.of(lambda x: x.position(h["beam"].tip)), axis=1))


def test_error_on_element_forces_and_loop_reactions():
    """A pendulum hung by a spring-damper element and a four-bar closed by a loop joint: the error
    measured on the element's force and on the loop's reaction, each compared with the state run."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    bob = model.add_body("bob", model.ground, rf.Joint.planar(), mass=1.0, inertia=(0.01, 0.01, 0.01))
    spring = model.add_spring_damper("element0", model.ground, bob, stiffness=400.0, length=1.0, damping=0.5)
    system = model.compile()
    q0 = np.array([0.2, -1.1, 0.0])
    t = np.linspace(0, 1, 51)
    ref = rf.simulate(system, 1.0, q0=q0, rtol=1e-11, atol=1e-13, error_on="state", t_eval=t)
    r = rf.simulate(system, 1.0, q0=q0, rtol=1e-6, atol=0.0, error_on=[spring], t_eval=t)
    error = np.abs(r.element_forces[:, 0] - ref.element_forces[:, 0]).max()
    assert error < 20 * 1e-6 * np.abs(ref.element_forces).max(), error
    model, h = rf.samples.four_bar()
    name = h["loop"]
    system = model.compile()
    q0 = system.assemble([0.4, -1.9, 4.6])[0]
    r = rf.simulate(system, 1.0, q0=q0, rtol=1e-6, atol=0.0, error_on=[name], t_eval=t)
    ref = rf.simulate(system, 1.0, q0=q0, rtol=1e-11, atol=1e-13, error_on="state", t_eval=t)
    scale = np.abs(ref.loop_reactions).max()
    assert np.abs(r.loop_reactions - ref.loop_reactions).max() < 1e-3 * scale


def test_explicit_methods_and_esdirk43_hold_the_state_by_default():
    system, _ = strip(8)
    for method in ("dopri5", "esdirk43"):
        r = rf.simulate(system, 0.05, method=method, stiffness_warning=False)
        assert np.isnan(r.stats["model_size"]), method  # no output measure
    r = rf.simulate(system, 0.05, method="esdirk43", error_on="bodies")
    assert r.stats["model_size"] == pytest.approx(1.0, rel=0.05)


def test_bad_error_on_and_estimate_input():
    system, beam = strip(4)
    other, _ = strip(4)  # _.tip: a point of another model
    with pytest.raises(ValueError, match="error_on: expected a coordinate"):
        rf.simulate(system, 0.1, error_on=["nowhere"])
    with pytest.raises(ValueError, match="error_on: expected at least one output"):
        rf.simulate(system, 0.1, error_on=[])
    with pytest.raises(ValueError, match="error_on: expected coordinate indices 0 ... 3"):
        rf.simulate(system, 0.1, error_on=[7])
    with pytest.raises(ValueError, match="error_on: expected points and bodies of the model"):
        rf.simulate(system, 0.1, error_on=[_.tip])
    with pytest.raises(ValueError, match="error_on: expected None or 'state' for 'scipy:Radau'"):
        rf.simulate(system, 0.1, method="scipy:Radau", error_on=[beam.tip])
    with pytest.raises(ValueError, match="at fixed steps"):
        rf.simulate(system, 0.1, method="rk4", dt=1e-3, error_on=[beam.tip])
    with pytest.raises(ValueError, match="rtol, atol: expected one value each"):
        rf.simulate(system, 0.1, error_on=[beam.tip], rtol=np.full(2 * system.nq, 1e-6))
    with pytest.raises(ValueError, match="error_on: expected None, 'bodies', 'state' or a list"):
        rf.simulate(system, 0.1, error_on=3.5)
    with pytest.raises(ValueError, match="error_estimate: expected"):
        rf.simulate(system, 0.1, error_estimate="yes")
    loaded = rf.Result(system, np.zeros(1), np.zeros((1, 4)), np.zeros((1, 4)), {}, "auto")
    with pytest.raises(ValueError, match="result: expected a Result made by rigidfem.simulate"):
        loaded.error_estimate  # noqa: B018
    with pytest.raises(ValueError, match="quantity: expected a function of a Result"):
        rf.simulate(system, 0.01, error_estimate=True).error_estimate.of("tip")
    assert other is not None
