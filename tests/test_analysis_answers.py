"""Statics and modal analysis answer every input: closed-form frequencies and damping ratios
(spring–mass, a two-mass chain with an overdamped mode, a pendulum upright and hanging, a
mass on a spinning table), empty answers for nq = 0, one SimulationError naming the free
coordinates of a mechanism or the coordinates of a gimbal lock, ValueErrors for bad
arguments. References are computed here from the equations of motion, not from the code."""

import re

import numpy as np
import pytest

import rigidfem as rf

G = 9.81


def spring_mass(m=2.0, k=800.0, c=0.0):
    model, _ = rf.samples.spring_mass(mass=m, stiffness=k, damping=c)
    return model.compile()


def all_prescribed():
    model = rf.Model()
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.prescribe(hub, rf.motion.harmonic(1, 2))
    return model.compile()


# --------------------------------------------------------------------------- nq = 0, bad input

def test_no_free_coordinates_gives_empty_answers():
    system = all_prescribed()
    assert system.nq == 0
    eq = rf.static_equilibrium(system, t=0.3)
    assert eq.q.shape == (0,) and eq.converged and eq.residual == 0.0
    modes = rf.modal_analysis(system, t=0.3)
    assert modes.omega.shape == modes.frequencies_hz.shape == modes.damping_ratios.shape == (0,)
    assert modes.eigenvalues.shape == (0,) and modes.shapes.shape == (0, 0) and modes.M.shape == (0, 0)
    assert modes.stable


@pytest.mark.parametrize("call,name", [
    (lambda s: rf.modal_analysis(s, t=np.nan), "t"),
    (lambda s: rf.modal_analysis(s, t=-np.inf), "t"),
    (lambda s: rf.modal_analysis(s, t="soon"), "t"),
    (lambda s: rf.modal_analysis(s, q=[0.0, 1.0]), "q"),
    (lambda s: rf.modal_analysis(s, qd=[np.nan]), "qd"),
    (lambda s: rf.static_equilibrium(s, t=np.inf), "t"),
    (lambda s: rf.static_equilibrium(s, t=None), "t"),
    (lambda s: rf.static_equilibrium(s, q0=[[0.0]]), "q0"),
    (lambda s: rf.static_equilibrium(s, load_steps=0), "load_steps"),
    (lambda s: rf.static_equilibrium(s, load_steps=2.5), "load_steps"),
    (lambda s: rf.static_equilibrium(s, load_steps=True), "load_steps"),
    (lambda s: rf.static_equilibrium(s, max_iterations=0), "max_iterations"),
    (lambda s: rf.static_equilibrium(s, tol=-1e-9), "tol"),
])
@pytest.mark.parametrize("free", [True, False])
def test_bad_arguments_raise_value_errors_naming_them(call, name, free):
    system = spring_mass() if free else all_prescribed()
    with pytest.raises(ValueError, match=rf"^{name}: expected"):
        call(system)


@pytest.mark.parametrize("t", [1e300, -1e300])
def test_a_drive_that_overflows_is_a_simulation_error_naming_the_time(t):
    model = rf.Model(gravity=None)
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.prescribe(hub, rf.motion.polynomial([0.0, 1.0, 1.0]))  # t²: inf at |t| = 1e300
    model.add_body("arm", hub, rf.Joint.revolute("y", stiffness=10.0, damping=0.1), 1.0, (0.1, 0.1, 0.1),
                   com=(1, 0, 0))
    system = model.compile()
    for call in (rf.modal_analysis, rf.static_equilibrium):
        with pytest.raises(rf.SimulationError, match=re.escape(f"at t = {t:g} s")) as err:
            call(system, t=t)
        assert "hub.rz" in str(err.value)


@pytest.mark.parametrize("t", [1.2e154, -1.2e154])
def test_an_overflowing_spin_rate_is_a_simulation_error_naming_the_time(t):
    """q = t² is finite at |t| = 1.2e154 but the centrifugal stiffness ~ q̇² = 4t² overflows."""
    model = rf.Model(gravity=None)
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.prescribe(hub, rf.motion.polynomial([0.0, 0.0, 1.0]))
    model.add_body("arm", hub, rf.Joint.revolute("y", stiffness=10.0), 1.0, (0.1, 0.1, 0.1), com=(1, 0, 0))
    with pytest.raises(rf.SimulationError, match=re.escape(f"at t = {t:g} s: modal analysis: stiffness K")):
        rf.modal_analysis(model.compile(), t=t)


# --------------------------------------------------------------------------- closed forms

def test_spring_mass_frequency_is_sqrt_k_over_m():
    m, k = 2.0, 800.0
    modes = rf.modal_analysis(spring_mass(m, k))
    assert modes.omega == pytest.approx([np.sqrt(k / m)], rel=1e-14)
    assert modes.frequencies_hz == pytest.approx([np.sqrt(k / m) / (2 * np.pi)], rel=1e-14)
    assert modes.damping_ratios.tolist() == [0.0]
    assert modes.eigenvalues == pytest.approx([1j * np.sqrt(k / m)], rel=1e-14)
    assert modes.stable


@pytest.mark.parametrize("zeta", [0.05, 0.7, 1.0, 3.0])
def test_damped_spring_mass(zeta):
    """ζ = c/(2√(km)); ω stays √(k/m); one root per mode: −ζω + iω√(1 − ζ²) or, overdamped,
    the slower real root −ω(ζ − √(ζ² − 1))."""
    m, k = 2.0, 800.0
    w = np.sqrt(k / m)
    c = 2 * zeta * np.sqrt(k * m)
    modes = rf.modal_analysis(spring_mass(m, k, c))
    assert modes.omega == pytest.approx([w], rel=1e-14)
    assert modes.damping_ratios == pytest.approx([zeta], rel=1e-12)
    s = np.roots([m, c, k])
    expected = s[np.lexsort((s.imag, s.real))[-1]]  # the largest real part, then Im ≥ 0
    # (a double root at ζ = 1 is only determined to √ε)
    assert modes.eigenvalues[0] == pytest.approx(expected, rel=1e-12 if zeta != 1.0 else 1e-6)
    assert modes.stable


def two_mass_chain(m, k, c):
    """Two masses on prismatic joints in series (relative coordinates), spring k and damper c
    in each joint: C = (c/k) K, proportional damping."""
    model = rf.Model(gravity=None)
    a = model.add_body("a", model.ground, rf.Joint.prismatic("x", stiffness=k, damping=c), m, (1, 1, 1))
    model.add_body("b", a, rf.Joint.prismatic("x", stiffness=k, damping=c), m, (1, 1, 1))
    return model.compile()


def test_an_overdamped_mode_keeps_its_undamped_frequency():
    """Fixed–free chain of two masses m and springs k: ω² = (k/m)(3 ∓ √5)/2. Damping c = αk
    in each spring gives ζ_i = α ω_i/2: here mode 1 at ζ = 0.5, mode 2 overdamped (ζ ≈ 1.31).
    The roots are those of m s² + c s + k per mode with k, m → ω²: s² + α ω² s + ω² = 0."""
    m, k = 1.5, 600.0
    w = np.sqrt(k / m * (3 - np.sqrt(5)) / 2), np.sqrt(k / m * (3 + np.sqrt(5)) / 2)
    alpha = 2 * 0.5 / w[0]
    modes = rf.modal_analysis(two_mass_chain(m, k, alpha * k))
    assert modes.omega == pytest.approx(w, rel=1e-12)
    assert modes.damping_ratios == pytest.approx([alpha * w[0] / 2, alpha * w[1] / 2], rel=1e-10)
    assert modes.damping_ratios[1] > 1
    roots = [np.roots([1.0, alpha * wi**2, wi**2]) for wi in w]
    expected = [r[np.lexsort((r.imag, r.real))[-1]] for r in roots]
    np.testing.assert_allclose(modes.eigenvalues, expected, rtol=1e-9)
    assert modes.eigenvalues[1].imag == 0 and modes.eigenvalues[1].real < 0
    # the shapes: mode 1 moves both masses the same way, relative coordinates (1, φ) with φ = (√5 − 1)/2
    assert modes.shapes[:, 0] / modes.shapes[0, 0] == pytest.approx([1.0, (np.sqrt(5) - 1) / 2], rel=1e-10)


def test_a_zero_mode_is_listed_once():
    """A free slider beside a damped spring–mass: modes 0 and √(k/m), not 0 twice; a damped free
    slider: ζ = c/(2√(km)) = inf for k = 0 and its root 0 (not the decay −c/m)."""
    m, k, c = 2.0, 800.0, 4.0
    for free_damping, zeta0 in ((0.0, 0.0), (3.0, np.inf)):
        model = rf.Model(gravity=None)
        model.add_body("free", model.ground, rf.Joint.prismatic("y", damping=free_damping), 1.0, (1, 1, 1))
        model.add_body("block", model.ground, rf.Joint.prismatic("x", stiffness=k, damping=c), m, (1, 1, 1))
        modes = rf.modal_analysis(model.compile())
        assert modes.omega == pytest.approx([0.0, np.sqrt(k / m)], rel=1e-14, abs=0)
        assert modes.damping_ratios[0] == zeta0
        assert modes.damping_ratios[1] == pytest.approx(c / (2 * np.sqrt(k * m)), rel=1e-12)
        assert modes.eigenvalues[0] == 0
        assert modes.eigenvalues[1].imag > 0
        assert np.abs(modes.shapes[:, 0]).tolist() == [1.0, 0.0]
        assert modes.stable


@pytest.mark.parametrize("length", [0.5, 2.0])
def test_pendulum_hanging_and_upright(length):
    """Rod of mass m, length l on a pivot: I = m l²/3, gravity stiffness ±m g l/2, so
    ω = √(3g/(2l)) hanging; upright the same number is the growth rate of a divergence."""
    model, _ = rf.samples.pendulum(length=length, mass=1.3)
    system = model.compile()
    inertia = 1.3 * length**2 / 3  # about the pivot: m l²/12 + m (l/2)²
    w = np.sqrt(1.3 * G * length / 2 / inertia)
    hanging = rf.modal_analysis(system)
    assert hanging.omega == pytest.approx([w], rel=1e-12)
    assert hanging.stable
    upright = rf.modal_analysis(system, q=[np.pi])
    assert upright.omega == pytest.approx([w], rel=1e-12)
    assert upright.eigenvalues == pytest.approx([w + 0j], rel=1e-12)
    assert upright.damping_ratios.tolist() == [-1.0]
    assert not upright.stable


def test_mass_on_a_spinning_table_splits_into_forward_and_backward_whirl():
    """A mass on x–y springs k on a table turned at a steady Ω: in the table's frame
    m(ẍ − 2Ωẏ − Ω²x) + c ẋ + k x = 0 and likewise for y, so
    (m s² + c s + k − mΩ²)² + (2mΩ s)² = 0: undamped |s| = √(k/m) ∓ Ω, each with ζ = c/(2ωm)."""
    m, k, W = 0.8, 320.0, 5.0
    w0 = np.sqrt(k / m)
    for c in (0.0, 1.2):
        model = rf.Model(gravity=None)
        table = model.add_body("table", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
        model.prescribe(table, rf.motion.polynomial([0.0, W]))
        model.add_body("mass", table, rf.Joint.custom(("x", "y"), stiffness=k, damping=c), m, (1e-3, 1e-3, 1e-3),
                       placement=rf.transform(translation=(0.0, 0.0, 0.0)))
        modes = rf.modal_analysis(model.compile(), t=0.7)
        assert modes.omega == pytest.approx([w0 - W, w0 + W], rel=1e-10)
        roots = np.concatenate([np.roots([m, c + 2j * m * W * sign, k - m * W**2]) for sign in (1, -1)])
        roots = roots[roots.imag > 0]
        by_frequency = lambda z: z[np.argsort(z.imag)]  # the real parts are zero to rounding when c = 0
        np.testing.assert_allclose(by_frequency(modes.eigenvalues), by_frequency(roots), rtol=1e-9)
        np.testing.assert_allclose(modes.damping_ratios, c / (2 * modes.omega * m), rtol=1e-9)
        assert modes.stable


# --------------------------------------------------------------------------- singular problems

def test_statics_of_a_mechanism_names_its_free_coordinate():
    """A payload hanging on a spherical joint: gravity resists pitch and roll, nothing the yaw."""
    model = rf.Model()
    model.add_body("payload", model.ground, rf.Joint.spherical(), 10.0, (0.1, 0.2, 0.3), com=(0.1, 0, -1))
    system = model.compile()
    with pytest.raises(rf.SimulationError) as err:
        rf.static_equilibrium(system)  # filterwarnings = error: no LinAlgWarning on the way
    msg = str(err.value)
    assert "at t = 0.0 s" in msg and "payload.rz" in msg
    assert "payload.ry" not in msg and "payload.rx" not in msg
    # with a yaw spring the same payload is in equilibrium
    model = rf.Model()
    model.add_body("payload", model.ground, rf.Joint.spherical(stiffness=(5.0, 0.0, 0.0)), 10.0, (0.1, 0.2, 0.3),
                   com=(0.1, 0, -1))
    eq = rf.static_equilibrium(model.compile(), load_steps=2)
    assert np.all(np.isfinite(eq.q))


def test_statics_names_every_free_coordinate_of_a_crane():
    """A trolley on a rail without a spring carrying a hanging payload on a universal joint
    (pitch and roll, resisted by gravity) and a slewing turntable: two free coordinates."""
    model = rf.Model()
    slew = model.add_body("slew", model.ground, rf.Joint.revolute("z"), 50.0, (5, 5, 5), com=(1, 0, 0))
    trolley = model.add_body("trolley", slew, rf.Joint.prismatic("x"), 20.0, (1, 1, 1),
                             placement=rf.transform(translation=(0, 0, 5)))
    model.add_body("payload", trolley, rf.Joint.universal(("x", "y")), 100.0, (1, 1, 1), com=(0, 0, -3))
    system = model.compile()
    with pytest.raises(rf.SimulationError) as err:
        rf.static_equilibrium(system)
    msg = str(err.value)
    assert "slew.rz" in msg and "trolley.x" in msg and "payload" not in msg.split("nothing resists")[1]


@pytest.mark.parametrize("damping", [0.0, 0.1])
def test_gimbal_lock_is_a_simulation_error_naming_the_coordinates(damping):
    model = rf.Model()
    model.add_body("ball", model.ground, rf.Joint.spherical(stiffness=1.0, damping=damping), 1.0, (0.1, 0.2, 0.3),
                   com=(0, 0, -1))
    system = model.compile()
    for q in ([0.0, np.pi / 2, 0.0], [0.3, -np.pi / 2, -0.2]):
        with pytest.raises(rf.SimulationError, match=r"at t = 0.0 s: modal analysis: the mass matrix") as err:
            rf.modal_analysis(system, q=q)
        msg = str(err.value)
        assert "ball.rz" in msg and "ball.rx" in msg and "ball.ry" not in msg
    # a little off the lock the answer is finite
    assert np.all(np.isfinite(rf.modal_analysis(system, q=[0.0, np.pi / 2 - 1e-3, 0.0]).omega))


@pytest.mark.parametrize("seed", [0, 10, 29, 52])
def test_one_root_per_mode_of_the_full_quadratic_problem(seed):
    """Random trees (non-symmetric K, gyroscopic and damping terms at a random state): every
    reported eigenvalue is a root of det(λ²M + λC + K) (companion matrix here), none twice,
    and ``stable`` agrees with the largest real part of all 2 nq roots."""
    model, _, rng = rf.samples.random_tree(seed)
    system = model.compile()
    n = system.nq
    modes = rf.modal_analysis(system, q=rng.normal(0, 0.3, n), qd=rng.normal(0, 0.3, n), t=0.4)
    M, K, C = modes.M, modes.K, modes.C
    roots = np.linalg.eigvals(np.block([[np.zeros((n, n)), np.eye(n)],
                                        [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]]))
    nearest = np.argmin(np.abs(roots[None, :] - modes.eigenvalues[:, None]), axis=1)
    np.testing.assert_allclose(modes.eigenvalues, roots[nearest], rtol=1e-9, atol=1e-9 * np.abs(roots).max())
    assert len(set(nearest)) == n
    assert np.all(modes.eigenvalues.imag >= 0)
    assert modes.stable == bool(roots.real.max() <= 1e-9 * np.abs(roots[np.argmax(roots.real)]))
    assert modes.eigenvalues.real.max() == pytest.approx(roots.real.max(), rel=1e-9, abs=1e-12)
