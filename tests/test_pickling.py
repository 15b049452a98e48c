"""Pickling (rigidfem.base.persistence): Models, Systems, Results, Modes, Equilibria, tables and the
handles and profiles in them, within a process and across processes, bit for bit."""

import concurrent.futures
import copy
import multiprocessing
import pickle

import numpy as np
import pytest

import rigidfem as rf
from rigidfem.base import persistence

MATERIAL = rf.Material(E=2.1e9, rho=7850.0, retardation=1e-3)
SECTION = rf.Section.rectangle(0.02, 0.004)


def hub_drive(t):  # a Python drive (slow path), module level so that it pickles
    return 0.4 * np.sin(t), 0.4 * np.cos(t), -0.4 * np.sin(t)


def pin_friction(t, q, qd):  # a Python generalised-force law
    return -0.3 * np.tanh(20 * qd)


def cylinder_law(t, l, ld):  # a Python cylinder law
    return 40.0 - 5.0 * (l - 0.7)


def everything():
    """A model using every builder: drives of each kind, loads, laws, a beam of varying length, a
    beam, force elements, a rope, a loop joint and an actuator, a moving base, gravity set late."""
    model = rf.Model(gravity=None)
    base = model.add_moving_base("deck", {"heave": rf.motion.harmonics([0.1, 0.05], [0.8, 1.3], [0.0, 0.4]),
                                          "roll": 0.02})
    hub = model.add_body("hub", base, rf.Joint.revolute("z"), mass=2.0, inertia=(0.1, 0.1, 0.2))
    model.prescribe(hub, rf.motion.function(hub_drive))
    joint = rf.Joint.revolute("y", stiffness=30.0)
    tape = model.add_beam("tape", hub, rf.motion.polynomial([0.5, 0.2]), MATERIAL, SECTION, 3, deform=("bend_y",),
                          joint=joint, placement=rf.transform((0.1, 0.0, 0.0)))
    joint.stiffness = [1e9]  # a later change of a joint spec does not reach the recorded call
    arm = model.add_beam("arm", hub, 0.6, MATERIAL, SECTION, 3, joint=rf.Joint.revolute("x", damping=0.1),
                         placement=rf.transform((-0.1, 0.0, 0.0)))
    rocker = model.add_body("rocker", base, rf.Joint.revolute("x", damping=0.5), mass=1.0, inertia=(0.05, 0.05, 0.01),
                            com=(0.0, 0.3, 0.0), placement=rf.transform((0.0, 0.2, 0.0)))
    pendulum = model.add_body("pendulum", base, rf.Joint.spherical(damping=0.2), mass=0.5, inertia=(0.01,) * 3,
                              com=(0.0, 0.0, -0.4), placement=rf.transform((0.0, -0.3, 0.5)))
    slider = model.add_body("slider", base, rf.Joint.prismatic("x"), mass=0.3, inertia=(0.01,) * 3,
                            placement=rf.transform((0.0, 0.8, 0.0)))
    model.add_generalized_force(rocker, pin_friction)
    model.add_generalized_force(slider, 1.5)
    model.add_force("load0", arm.tip, (0.0, 0.0, -2.0), scale=rf.motion.spin_up(1.0, 2.0))
    model.add_torque("load1", rocker, (0.1, 0.0, 0.0), follower=True, scale=rf.motion.spline([0, 1, 2, 3], [0, 1, 0.5, 0]))
    model.add_spring_damper("element0", rocker.point((0.0, 0.6, 0.0)), base.point((0.0, 0.9, 0.3)), stiffness=50.0, length=0.3,
                            damping=1.0)
    model.add_cylinder("element1", base.point((0.2, 0.0, -0.3)), rocker.point((0.0, 0.5, 0.0)), cylinder_law, damping=2.0)
    model.add_rope("element2", base.point((0.0, -0.3, 0.6)), pendulum.point((0.0, 0.0, -0.4)), EA=5e3, length=0.75)
    model.add_loop_joint("tie", "distance", slider.origin, base.point((0.4, 0.8, 0.3)), length=0.5)
    model.gravity = (0.0, 0.0, -9.81)
    return model, tape, arm


def equal_systems(a, b, rng):
    """Bitwise equal outputs of two systems at random states."""
    assert a.coordinate_names == b.coordinate_names and a.prescribed_names == b.prescribed_names
    for _ in range(3):
        t, q, qd = rng.uniform(0, 2), rng.uniform(-0.3, 0.3, a.nq), rng.uniform(-1, 1, a.nq)
        assert np.array_equal(a.mass_matrix(t, q), b.mass_matrix(t, q))
        assert np.array_equal(a.forward_dynamics(t, q, qd), b.forward_dynamics(t, q, qd))
        assert np.array_equal(a.loop_constraints(t, q, qd)[2], b.loop_constraints(t, q, qd)[2])


def test_model_and_system_round_trip_bit_for_bit():
    model, tape, arm = everything()
    system = model.compile()
    rng = np.random.default_rng(0)
    copy_model = pickle.loads(pickle.dumps(model))
    assert copy_model.id == model.id and copy_model.nbodies == model.nbodies
    equal_systems(system, copy_model.compile(), rng)
    equal_systems(system, pickle.loads(pickle.dumps(system)), rng)
    equal_systems(system, copy.deepcopy(model).compile(), rng)
    # The handles the original made name the same bodies of the copy, in models and systems.
    q = rng.uniform(-0.3, 0.3, system.nq)
    copied = pickle.loads(pickle.dumps(system))
    assert np.array_equal(copied.position(arm.tip, 0.5, q), system.position(arm.tip, 0.5, q))
    copy_model.add_spring_damper("element3", tape.rfes[-1].origin, arm.tip, stiffness=1.0, length=0.1)


def test_joint_spec_changed_after_use_is_not_recorded():
    model, _, _ = everything()
    system = pickle.loads(pickle.dumps(model)).compile()
    names = system.coordinate_names
    assert system.stiffness[names.index("tape.rfe0.ry")] == 30.0  # not the 1e9 set after add_beam


def test_system_keeps_its_model_at_compile_time():
    model = rf.Model()
    body = model.add_body("a", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    system = model.compile()
    model.add_body("b", body, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    assert pickle.loads(pickle.dumps(system)).nbodies == 1
    assert pickle.loads(pickle.dumps(model)).nbodies == 2


def test_failed_builder_calls_are_not_recorded():
    model = rf.Model()
    with pytest.raises(ValueError, match="mass"):
        model.add_body("a", model.ground, rf.Joint.revolute("z"), mass=-1.0, inertia=(1, 1, 1))
    model.add_body("a", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    assert pickle.loads(pickle.dumps(model)).nbodies == 1


def test_handles_of_other_models_still_refused():
    model, _, arm = everything()
    other, _, _ = everything()
    with pytest.raises(ValueError, match="another model"):
        pickle.loads(pickle.dumps(other.compile())).position(arm.tip, 0.0, np.zeros(other.compile().nq))


def test_profiles_handles_and_joint_specs_round_trip():
    profiles = [rf.motion.constant(0.3), rf.motion.polynomial([1.0, -2.0, 0.5]), rf.motion.harmonic(0.2, 3.0, 0.1, 1.0),
                rf.motion.harmonics([0.1, 0.2], [1.0, 2.5], [0.3, 0.0], 0.5), rf.motion.spin_up(6.0, 15.0),
                rf.motion.spline([0.0, 0.5, 1.5, 2.0], [0.0, 1.0, -0.5, 0.2]), rf.motion.function(hub_drive)]
    for p in profiles:
        back = pickle.loads(pickle.dumps(p))
        assert repr(back) == repr(p)
        for t in (-0.3, 0.0, 0.77, 1.2, 30.0):
            assert back(t) == p(t)
    joint = rf.Joint.revolute("y", stiffness=3.0, rest=0.2, damping=0.1)
    back = pickle.loads(pickle.dumps(joint))
    assert (back.kind, back.coordinates, back.stiffness, back.rest, back.damping, back.linear) == \
        (joint.kind, joint.coordinates, joint.stiffness, joint.rest, joint.damping, joint.linear)
    point = rf.Body(3, "x", 77).point((0.1, 0.2, 0.3))
    back = pickle.loads(pickle.dumps(point))
    assert (back.body, back.model) == (3, 77) and np.array_equal(back.r, point.r)


def test_a_lambda_law_names_itself_when_pickled():
    model = rf.Model()
    body = model.add_body("a", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    model.add_generalized_force(body, lambda t, q, qd: -q)
    with pytest.raises((pickle.PicklingError, AttributeError), match="lambda"):
        pickle.dumps(model)


def test_results_modes_equilibria_and_tables_round_trip():
    model, _, _ = everything()
    system = model.compile()
    result = rf.simulate(system, 0.2, method="generalized_alpha", dt=0.01)
    _ = result.energy  # a cached output is not pickled, and is recomputed equal
    back = pickle.loads(pickle.dumps(result))
    assert "_outputs" not in back.__dict__
    for name in ("t", "q", "qd", "energy", "element_forces", "loop_reactions"):
        assert np.array_equal(getattr(back, name), getattr(result, name)), name
    np.testing.assert_equal(back.stats, result.stats)  # NaN (e.g. stiff_at) equal to NaN
    assert back.method == result.method
    spring = rf.Model(gravity=(0, -9.81, 0))
    body = spring.add_body("m", spring.ground, rf.Joint.prismatic("y", stiffness=100.0, damping=1.0), mass=2.0,
                           inertia=(1, 1, 1))
    s = spring.compile()
    eq = rf.static_equilibrium(s)
    modes = rf.modal_analysis(s, q=eq.q)
    for x in (eq, modes):
        y = pickle.loads(pickle.dumps(x))
        for name in x.__dataclass_fields__:
            a, b = getattr(x, name), getattr(y, name)
            assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, name
    table = rf.study.Table([{"a": 1, "b": 2.5}], ("a", "b"))
    assert pickle.loads(pickle.dumps(table)) == table
    assert body.index == 0


def test_a_state_of_another_version_is_refused():
    state = pickle.loads(pickle.dumps(rf.study.Table([], ()))).__getstate__()
    state["rigidfem_state"] = persistence.STATE_VERSION + 1
    with pytest.raises(ValueError, match="state version"):
        rf.study.Table().__setstate__(state)
    model_state = persistence.model_state(rf.Model())
    model_state["rigidfem_state"] = 0
    with pytest.raises(ValueError, match="state version"):
        pickle.loads(pickle.dumps(rf.Model())).__reduce__()[0](model_state)


def test_system_in_another_process_gives_bitwise_identical_results():
    """A fresh interpreter (spawn) unpickles the System, simulates and sends the Result back."""
    model, tape, _ = everything()
    system = model.compile()
    here = rf.simulate(system, 0.3, method="generalized_alpha", dt=0.005)
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        there = pool.submit(rf.simulate, system, 0.3, method="generalized_alpha", dt=0.005).result()
    assert np.array_equal(here.q, there.q) and np.array_equal(here.qd, there.qd)
    assert np.array_equal(here.position(tape.rfes[-1]), there.position(tape.rfes[-1]))
