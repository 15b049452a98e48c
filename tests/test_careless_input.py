"""Regression tests of the contract violations of issue 10 found by the contract fuzzer
(tests/fuzz_contract.py, tests/fuzz_corpus): careless input gets a ValueError whose message starts
with the argument's name and says what it expects; numerical failures are SimulationErrors naming
the time; nothing is silently taken for something else."""

import re

import numpy as np
import pytest

import rigidfem as rf
from conftest import step_of
from rigidfem import stages


def named(name):
    """pytest.raises(match=...) for a message that starts with the argument's name."""
    return "^" + re.escape(name) + ": "


def two_dof():
    m = rf.Model()
    b = m.add_body("b", m.ground, rf.Joint.universal(("x", "z")), mass=1.0, inertia=(0.1, 0.1, 0.1),
                   com=(0.2, 0.0, 0.0))
    return m, b, m.compile()


def driven():
    """A system with a prescribed coordinate (its drive makes everything depend on t)."""
    m = rf.Model()
    a = m.add_body("a", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.3, 0, 0))
    m.add_body("c", a, rf.Joint.revolute("z", stiffness=2.0, damping=0.1), mass=1.0, inertia=(0.1, 0.1, 0.1),
               com=(0.3, 0, 0), placement=rf.transform((0.5, 0, 0)))
    m.prescribe(a, rf.motion.harmonic(0.4, 3.0))
    return m.compile()


Z2 = np.zeros(2)


# -- complex numbers are refused (numpy would drop their imaginary parts) ------------------------

@pytest.mark.parametrize("call, name", [
    (lambda s: s.forward_dynamics(0.0, Z2 + 1j, Z2), "q"),
    (lambda s: s.forward_dynamics(0.0, Z2, Z2 + 1j), "qd"),
    (lambda s: s.mass_matrix(0.0, np.array([0.1 + 2j, 0.0])), "q"),
    (lambda s: s.rhs(0.0, np.zeros(4, dtype=complex)), "y"),
    (lambda s: s.inverse_dynamics(0.0, Z2, Z2, Z2 + 1j), "qdd"),
    (lambda s: s.kinetic_energy(0.0, Z2, [1j, 0.0]), "qd"),
    (lambda s: s.forward_dynamics(np.complex128(1 + 1j), Z2, Z2), "t"),
    (lambda s: stages.set_state(s, s.make_data(), 0.0, Z2 + 1j, Z2), "q"),
    (lambda s: rf.simulate(s, 0.01, q0=Z2 + 1j), "q0"),
    (lambda s: rf.simulate(s, 0.01, qd0=Z2 + 0j), "qd0"),
    (lambda s: rf.simulate(s, 0.01, rtol=1e-6 + 1j), "rtol"),
    (lambda s: rf.static_equilibrium(s, q0=Z2 + 1j), "q0"),
    (lambda s: rf.modal_analysis(s, q=Z2 + 1j), "q"),
])
def test_complex_values_are_refused(call, name):
    _, _, s = two_dof()
    with pytest.raises(ValueError, match=named(name)) as e:
        call(s)
    if name != "t" and name != "rtol":
        assert "real" in str(e.value) or "complex" in str(e.value)


def test_complex_scalars_are_refused_where_numbers_are_checked():
    with pytest.raises(ValueError, match=named("mass")):
        rf.Model().add_body("b", "ground", rf.Joint.revolute("z"), mass=np.complex128(1.0), inertia=(1, 1, 1))


# -- a vector must be 1-D: (1, n) and (n, 1) arrays are not taken for it -------------------------

@pytest.mark.parametrize("shape", [(1, 2), (2, 1)])
def test_two_dimensional_arrays_are_not_vectors(shape):
    _, b, s = two_dof()
    q = np.zeros(shape)
    for call, name in ((lambda: s.forward_dynamics(0.0, q, Z2), "q"),
                       (lambda: s.position(b, 0.0, q), "q"),
                       (lambda: s.velocity(b, 0.0, Z2, q), "qd"),
                       (lambda: s.rhs(0.0, np.zeros((1, 4))), "y")):
        with pytest.raises(ValueError, match=named(name)) as e:
            call()
        assert "expected a 1-D array" in str(e.value) and f"got shape {np.zeros(shape).shape if name != 'y' else (1, 4)}" in str(e.value)


def test_one_coordinate_system_refuses_a_1x1_array():
    m = rf.Model()
    b = m.add_body("b", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.2, 0, 0))
    s = m.compile()
    with pytest.raises(ValueError, match=named("q")):
        s.position(b, 0.0, np.zeros((1, 1)))


def test_strings_in_vectors_are_refused():
    _, _, s = two_dof()
    with pytest.raises(ValueError, match=named("q")):
        s.forward_dynamics(0.0, ["1", "2"], Z2)


# -- the guard blames the argument that is wrong -------------------------------------------------

def test_the_wrong_argument_is_named_next_to_big_integers():
    _, _, s = two_dof()
    with pytest.raises(ValueError, match=named("t")):
        s.kinetic_energy("x", [10**30, 0], Z2)
    with pytest.raises(ValueError, match=named("qd")):
        s.acceleration_derivatives(7.5, [10**30] * 2, None)


def test_big_integers_and_booleans_are_still_numbers():
    _, _, s = two_dof()
    assert np.all(np.isfinite(s.forward_dynamics(0.0, [10**3, 0], np.ones(2, dtype=bool))))


# -- force_jacobians: static must be a bool, and its qd is checked even when static ---------------

@pytest.mark.parametrize("static", [None, 1, 2.5, "yes"])
def test_force_jacobians_static_must_be_a_bool(static):
    _, _, s = two_dof()
    with pytest.raises(ValueError, match=named("static")):
        s.force_jacobians(0.0, Z2, Z2, 1.0, static)


@pytest.mark.parametrize("qd", [np.zeros(5), [None, None], np.array([np.nan, 0.0])])
@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
def test_force_jacobians_checks_qd_when_static(qd, algorithm):
    m, _, _ = two_dof()
    s = m.compile(algorithm)
    with pytest.raises(ValueError, match=named("qd")):
        s.force_jacobians(0.0, Z2, qd, 1.0, True)
    with pytest.raises(ValueError, match=named("qd")):
        s.force_jacobians(0.0, Z2, qd, static=True)


# -- t comes first, without a default: version 0.1's calls (the state first) are refused ---------------------------

@pytest.mark.parametrize("call", [
    lambda s, q: s.mass_matrix(q),
    lambda s, q: s.kinetic_energy(q, q),
    lambda s, q: s.gravity_energy(q),
    lambda s, q: s.elastic_energy(q),
    lambda s, q: s.potential_energy(q=q),
    lambda s, q: s.dissipated_power(q, q),
])
def test_t_is_required(call):
    s = driven()
    q = np.full(s.nq, 0.2)
    with pytest.raises(TypeError):
        call(s, q)
    with pytest.raises(TypeError):
        s.mass_matrix()


def test_t_given_or_not_needed():
    s = driven()
    q = np.full(s.nq, 0.2)
    # the drive's angle at t moves the second body: the mass matrix does not depend on it, gravity
    # (none here) neither, but the kinetic energy does through the drive's rate
    assert s.kinetic_energy(0.1, q, q) != s.kinetic_energy(0.3, q, q)
    s.mass_matrix(0.5, q)
    s.mass_matrix(0.5, q)
    _, _, free = two_dof()  # no drives: t may be left out
    free.mass_matrix(0.0, Z2)
    free.potential_energy(0.0, Z2)


# -- simulate ------------------------------------------------------------------------------------

@pytest.mark.parametrize("what, expected", [("model", "got a Model"), (None, "got None"), ("system", "got 'system'")])
def test_simulate_wants_a_compiled_system(what, expected):
    m, _, _ = two_dof()
    arg = m if what == "model" else what
    with pytest.raises(ValueError, match=named("system")) as e:
        rf.simulate(arg, 0.1)
    assert "compile()" in str(e.value) and expected in str(e.value)


@pytest.mark.parametrize("method", ["scipy:Radau", "scipy:BDF"])
def test_scipy_radau_and_bdf_take_per_component_rtol(method):
    _, _, s = two_dof()
    r = rf.simulate(s, 0.05, method=method, rtol=np.full(4, 1e-6), q0=[0.1, 0.2])
    r_scalar = rf.simulate(s, 0.05, method=method, rtol=1e-6, q0=[0.1, 0.2])
    # the strictest of equal tolerances is that tolerance: the same run
    assert np.array_equal(r.q, r_scalar.q)


@pytest.mark.parametrize("method", ["rk4", "dopri5", "newmark", "scipy:RK45", "scipy:DOP853", "scipy:LSODA",
                                    "scipy:Radau", "scipy:BDF"])
def test_per_component_tolerances_of_a_system_without_coordinates(method):
    m = rf.Model()
    m.add_body("b", m.ground, rf.Joint.fixed(), mass=0.5, inertia=(0.1, 0.1, 0.1))
    s = m.compile()
    r = rf.simulate(s, 0.2, method=method, **step_of(method, 0.05), rtol=np.full(0, 1e-6), atol=np.full(0, 1e-6))
    assert r.q.shape[1] == 0 and r.t[-1] == pytest.approx(0.2)


@pytest.mark.parametrize("kw, name", [
    (dict(t_eval=[0.5]), "t_eval"),           # after t_end
    (dict(t_eval=[-0.5]), "t_eval"),          # before t0
    (dict(t_eval=[0.05, 0.01]), "t_eval"),    # decreasing
    (dict(dt=float("nan")), "dt"),
    (dict(dt=-0.01), "dt"),
    (dict(first_step=float("nan")), "first_step"),
    (dict(adaptive="yes"), "adaptive"),
    (dict(adaptive=1), "adaptive"),
])
@pytest.mark.parametrize("method", ["scipy:RK45", "scipy:Radau", "dopri5"])
def test_scipy_methods_check_the_options_too(kw, name, method):
    _, _, s = two_dof()
    with pytest.raises(ValueError, match=named(name)):
        rf.simulate(s, 0.1, method=method, **kw)


@pytest.mark.parametrize("method", ["generalized_alpha", "dopri5"])
def test_a_bad_t_eval_is_named_before_tolerances_wrong_only_together(method):
    """rtol = atol = 0 is wrong only together (and unused at fixed steps): a bad t_eval beside them is
    the argument named (fuzz seed 282087024, case 20)."""
    _, _, s = two_dof()
    with pytest.raises(ValueError, match=named("t_eval")):
        rf.simulate(s, 0.1, method=method, **step_of(method, 0.01), rtol=0.0, atol=0.0, t_eval=[0.5])


def test_scipy_first_step_is_used():
    _, _, s = two_dof()
    r = rf.simulate(s, 0.1, method="scipy:RK45", first_step=1e-4, q0=[0.1, 0.2])
    assert r.t[1] == pytest.approx(1e-4)


def test_scipy_overflowing_state_is_a_simulation_error():
    m = rf.Model(None)
    m.add_body("b", m.ground, rf.Joint.custom(["x", "rx"]), mass=2.0, inertia=(0.4, 0.14, 0.5346))
    s = m.compile()
    with pytest.raises(rf.SimulationError, match=r"at t = [-+0-9.e]+ s") as e:
        rf.simulate(s, 0.05, method="scipy:Radau", qd0=[1e150, -3e149])
    assert e.value.result is not None and np.isfinite(e.value.time)


def test_scipy_zero_atol_at_zero_state_is_a_simulation_error_naming_atol():
    m = rf.Model()
    m.add_body("b", m.ground, rf.Joint.revolute("x"), mass=2.0, inertia=(0.2, 0.3, 0.25))
    s = m.compile()
    with pytest.raises(rf.SimulationError, match=r"at t = -1 s") as e:
        rf.simulate(s, -0.8, method="scipy:Radau", t0=-1.0, atol=0.0)
    assert "atol" in str(e.value)


# -- wrong types for the compiled classes and helpers: ValueError naming the argument ----------------

@pytest.mark.parametrize("call, name", [
    (lambda: rf.Point(0, "r"), "r"),
    (lambda: rf.Point(0, (1.0, 2.0)), "r"),
    (lambda: rf.Point(0, (1.0, 2.0, 3.0j)), "r"),
    (lambda: rf.Point("b0", (0.0, 0.0, 0.0)), "body"),
    (lambda: rf.Point(1.5, (0.0, 0.0, 0.0)), "body"),
    (lambda: rf.Point(None, (0.0, 0.0, 0.0)), "body"),
    (lambda: rf.Body(0, "b").point("x"), "r"),
    (lambda: rf.R1("x"), "phi1"),
    (lambda: rf.R1([1.0]), "phi1"),
    (lambda: rf.R2(None), "phi2"),
    (lambda: rf.R3(np.complex128(1.0)), "phi3"),
    (lambda: rf.euler_zyx(0.1, "y", 0.3), "phi2"),
    (lambda: rf.skew(None), "w"),
    (lambda: rf.skew(np.zeros(4)), "w"),
    (lambda: rf.homogeneous(np.eye(3), "x"), "r"),
    (lambda: rf.homogeneous(np.eye(4), np.zeros(3)), "R"),
    (lambda: rf.inverse(np.zeros((5, 4))), "T"),
    (lambda: rf.inverse(np.eye(4) + 0j), "T"),
    (lambda: rf.pseudo_inertia(1.0, "x", np.eye(3)), "com"),
    (lambda: rf.pseudo_inertia("1", np.zeros(3), np.eye(3)), "mass"),
    (lambda: rf.pseudo_inertia(1.0, np.zeros(3), np.eye(4)), "inertia"),
    (lambda: rf.Joint.spherical().add_coupling(0, 0, np.eye(3)), "G"),
    (lambda: rf.Joint.spherical().add_coupling(0, 0, np.full((4, 4), np.nan)), "G"),
    (lambda: rf.Joint.spherical().add_coupling("b0", 0, np.eye(4)), "body"),
    (lambda: rf.Joint.spherical().add_coupling(0, 1.5, np.eye(4)), "slot"),
    (lambda: rf.motion.constant(-1.0)(None), "t"),
    (lambda: rf.motion.constant(-1.0)("0.5"), "t"),
    (lambda: rf.motion.constant(-1.0)(True), "t"),
    (lambda: rf.motion.constant(-1.0)(float("nan")), "t"),
])
def test_compiled_classes_and_helpers_name_the_argument(call, name):
    with pytest.raises(ValueError, match=named(name)):
        call()


def test_helpers_still_take_what_they_took():
    np.testing.assert_array_equal(rf.R3(np.float32(0.0)), np.eye(3))
    np.testing.assert_array_equal(rf.R1(0), np.eye(3))
    np.testing.assert_array_equal(rf.homogeneous([[1, 0, 0], [0, 1, 0], [0, 0, 1]], (1, 2, 3))[:3, 3], [1, 2, 3])
    p = rf.Point(np.int64(2), [0.5, 0.0, 0.0])
    assert p.body == 2 and p.r[0] == 0.5
    assert rf.motion.constant(2.0)(np.float64(0.5)) == (2.0, 0.0, 0.0)
    assert rf.motion.constant(2.0)(1) == (2.0, 0.0, 0.0)


@pytest.mark.parametrize("call, name", [
    (lambda: rf.motion.constant("x"), "value"),
    (lambda: rf.motion.constant(1j), "value"),
    (lambda: rf.motion.harmonic(None, 1.0), "amplitude"),
    (lambda: rf.motion.harmonic(1.0, "w"), "omega"),
    (lambda: rf.motion.harmonic(1.0, 1.0, phase=[0.0]), "phase"),
    (lambda: rf.motion.spin_up("6", 0.5), "omega"),
    (lambda: rf.motion.spin_up(6.0, None), "duration"),
    (lambda: rf.motion.polynomial("ab"), "coefficients"),
    (lambda: rf.motion.polynomial([1.0, None]), "coefficients"),
    (lambda: rf.motion.polynomial(3.0), "coefficients"),
])
def test_motion_profiles_name_the_argument(call, name):
    with pytest.raises(ValueError, match=named(name)):
        call()


def test_model_lookups_name_the_argument():
    m = rf.Model()
    m.add_body("b0", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    for bad in ("nope", None, 3):
        with pytest.raises(ValueError, match=named("name")):
            m.body(bad)
    assert m.body("b0").name == "b0" and m.body("ground").index == -1
    for algorithm in (None, 3):
        with pytest.raises(ValueError, match=named("algorithm")):
            m.compile(algorithm)
    with pytest.raises(ValueError, match=named("coordinate")):
        m.prescribe(m.body("b0"), rf.motion.constant(0.0), coordinate=3)
    with pytest.raises(ValueError, match=named("coordinate")):
        m.add_generalized_force(m.body("b0"), 1.0, coordinate=3)


def test_a_nan_coupling_generator_is_named():
    m = rf.Model()
    m.add_body("b0", m.ground, rf.Joint.custom(["x", "z", "rx"]), mass=1.0, inertia=(1, 1, 1))
    j = rf.Joint.fixed()
    j.linear = True
    with pytest.raises(ValueError, match=named("G")):
        j.add_coupling(0, 0, np.full((4, 4), np.nan))


@pytest.mark.parametrize("elements", [10**12, 2**63, 10**30, rf.model.beams.MAX_ELEMENTS + 1])
def test_huge_element_counts_are_refused_at_once(elements):
    m = rf.Model()
    with pytest.raises(ValueError, match=named("elements")) as e:
        m.add_beam("beam", m.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(0.01), elements)
    assert str(rf.model.beams.MAX_ELEMENTS) in str(e.value)
    assert m.nbodies == 0


# -- drives returning non-numbers ------------------------------------------------------------------

@pytest.mark.parametrize("returned", [("a", 0.0, 0.0), (np.nan, 0.0, 0.0), (0.0, 0.0), None, "abc",
                                      (0.0, 1j, 0.0), (0.0, None, 0.0)])
def test_a_drive_returning_non_numbers_is_named_with_its_time(returned):
    def drive(t):
        return returned

    m = rf.Model()
    b = m.add_body("b", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.3, 0, 0))
    m.add_body("c", b, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.3, 0, 0),
               placement=rf.transform((0.5, 0, 0)))
    m.prescribe(b, rf.motion.function(drive))
    s = m.compile()
    with pytest.raises(ValueError, match=named("f")) as e:
        s.forward_dynamics(2.5, np.zeros(1), np.zeros(1))
    assert "drive" in str(e.value) and "t = 2.5" in str(e.value)
    with pytest.raises(rf.SimulationError, match=r"t = 0\b") as e:
        rf.simulate(s, 0.1, method="rk4", dt=0.01)
    assert e.value.time == 0.0 and "drive" in e.value.cause


def test_a_bad_vector_is_named_even_when_a_drive_fails_first():
    """A drive evaluated at t = 1e300 overflows before the compiled code looks at qdd's size: the
    wrong qdd is the error, not the numerical failure it runs into."""
    m = rf.Model()
    b = m.add_body("b", m.ground, rf.Joint.custom(["y", "rz"]), mass=1.0, inertia=(0.1, 0.1, 0.1))
    m.prescribe(b, rf.motion.polynomial([-1.0, 0.5, 0.5, 2.0]), coordinate="y")
    s = m.compile()
    with pytest.raises(rf.SimulationError):  # the failure itself, with good arguments
        s.inverse_dynamics_derivatives(1e300, np.zeros(1), np.zeros(1), np.zeros(1))
    with pytest.raises(ValueError, match=named("qdd")):
        s.inverse_dynamics_derivatives(1e300, np.zeros(1), np.zeros(1), np.zeros(2))


def test_absurd_load_step_counts_are_refused_not_run():
    """static_equilibrium(load_steps=10**12) was taken and ran for ever."""
    model = rf.Model()
    model.add_body("b", model.ground, rf.Joint.revolute("z", stiffness=1.0), 1.0, (1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match=r"^load_steps: expected an integer in \[1, 100000\], got 1000000000000"):
        rf.static_equilibrium(model.compile(), load_steps=10**12)


def test_stages_refuse_a_workspace_whose_set_state_raised():
    """A drive overflowing at t = 1e300 raises in set_state after the free coordinates were written:
    the stages on that workspace refuse it instead of computing NaN from a half-written state, and
    a successful set_state makes it usable again."""
    model = rf.Model()
    hub = model.add_body("hub", model.ground, rf.Joint.revolute("z"), 1.0, (1.0, 1.0, 1.0))
    arm = model.add_body("arm", hub, rf.Joint.revolute("y"), 1.0, (1.0, 1.0, 1.0))
    model.prescribe(hub, rf.motion.polynomial([0.0, 0.0, 0.0, 1.0]))
    system = model.compile()
    data = system.make_data()
    with pytest.raises(rf.SimulationError, match="drive of hub.rz returned NaN or inf"):
        stages.set_state(system, data, 1e300, [0.1], [0.0])
    for stage in (stages.kinematics, stages.generalized_forces, stages.mass_matrix):
        with pytest.raises(ValueError, match="^data: expected a workspace with a state, got one whose last set_state"):
            stage(system, data)
    stages.set_state(system, data, 1.0, [0.1], [0.0])
    stages.kinematics(system, data)
    assert np.all(np.isfinite(data.T[arm.index]))
