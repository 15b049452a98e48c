"""Laws on joint coordinates (rigidfem.laws, Model.add_joint_law): the regularised friction law against analytic
motions (a block sliding to a stop, its terminal velocity, its creep below breakaway), the energy balance, its
analytic derivatives against central differences, its constants as named parameters (sensitivities and the
adjoint against differences of runs), and bad input."""

import numpy as np
import pytest
from scipy.optimize import brentq

import rigidfem as rf

from conftest import central_jacobians


def block(law=None, push=0.0, mass=1.0):
    """A block of `mass` kg on a prismatic x joint (no gravity), pushed by a constant force `push` (N), with `law`."""
    model = rf.Model(gravity=None)
    b = model.add_body("block", model.ground, rf.Joint.prismatic("x"), mass=mass, inertia=(0.1, 0.1, 0.1))
    if push:
        model.add_generalized_force(b, push)
    name = model.add_joint_law("block.x.friction", b, law) if law is not None else None
    return model, b, name


def test_a_block_slides_to_a_stop_as_coulomb_says():
    """Coulomb friction F_C alone (F_S = F_C, no viscous part): from v0 the block decelerates at F_C/m, stops at
    t* = m v0/F_C after m v0²/(2 F_C), and stays (the regularisation's creep is zero without a force)."""
    m, v0, F = 2.0, 1.5, 3.0
    model, b, _ = block(rf.laws.Friction(breakaway=F, coulomb=F, smoothing=1e-6), mass=m)
    s = model.compile()
    t_stop = m * v0 / F
    t = np.array([0.4 * t_stop, 0.8 * t_stop, 2.0 * t_stop])
    r = rf.simulate(s, t[-1], "radau5", qd0=[v0], t_eval=t, rtol=1e-9, atol=1e-12)
    a = F / m
    exact = [v0 * t[0] - a * t[0] ** 2 / 2, v0 * t[1] - a * t[1] ** 2 / 2, v0 ** 2 / (2 * a)]
    np.testing.assert_allclose(r.q[:, 0], exact, atol=2e-6)  # the regularisation: v_ε = 1e-6 m/s over ~t*
    np.testing.assert_allclose(r.qd[:2, 0], [v0 - a * t[0], v0 - a * t[1]], atol=1e-7)
    assert abs(r.qd[-1, 0]) < 1e-5


def test_terminal_velocity_with_viscous_friction_and_the_stribeck_fall():
    """Pushed by P above the breakaway force, the block reaches v = (P − F_C)/b where the dry friction has fallen
    to F_C (v ≫ v_S) and the viscous part b v takes the rest; m v̇ = P − F_C − b v then relaxes as e^{−b t/m}."""
    P, FS, FC, vs, b, m = 4.5, 3.0, 2.0, 0.01, 0.5, 1.0
    model, _, _ = block(rf.laws.Friction(breakaway=FS, coulomb=FC, stribeck=vs, viscous=b), push=P, mass=m)
    r = rf.simulate(model.compile(), 40.0, "radau5", t_eval=[10.0, 40.0], rtol=1e-10, atol=1e-12)
    vt = (P - FC) / b
    assert abs(r.qd[-1, 0] - vt) < 1e-7 * vt
    # at 10 s: the exponential approach, shifted by the short start through the Stribeck hump (below 1e-2 s)
    assert abs(r.qd[0, 0] - vt * (1 - np.exp(-b * 10.0 / m))) < vt * b / m * 1e-2


def test_below_breakaway_the_block_creeps_at_the_regularised_rate():
    """Pushed by P below the breakaway force, a regularised law lets the block creep at the v with
    P = g(v) tanh(v/v_ε) (its stick: v ~ v_ε atanh(P/F_S)), found here by root finding."""
    P, FS, FC, vs, ve = 1.5, 3.0, 2.0, 0.01, 1e-4
    model, _, _ = block(rf.laws.Friction(breakaway=FS, coulomb=FC, stribeck=vs, smoothing=ve), push=P)
    r = rf.simulate(model.compile(), 1.0, "radau5", t_eval=[1.0], rtol=1e-10, atol=1e-14)
    g = lambda v: FC + (FS - FC) * np.exp(-(v / vs) ** 2)  # noqa: E731
    creep = brentq(lambda v: g(v) * np.tanh(v / ve) - P, 0.0, vs)
    assert abs(r.qd[-1, 0] - creep) < 1e-6 * creep
    assert abs(creep - ve * np.arctanh(P / FS)) < 1e-2 * creep  # it sticks, up to the regularisation


def test_a_pendulum_with_joint_friction_loses_what_the_friction_dissipates():
    """The energy balance E(0) − E(t) = ∫ P_dissipated dt with the friction's power −Q q̇ in dissipated_power."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    arm = model.add_body("arm", model.ground, rf.Joint.revolute("z"), mass=1.2, inertia=(0.01, 0.1, 0.1),
                         com=(0.5, 0.0, 0.0))
    name = model.add_joint_law("arm.rz.friction", arm, rf.laws.Friction(breakaway=0.4, coulomb=0.3, stribeck=0.2, viscous=0.05,
                                                     smoothing=0.05))
    assert name == "arm.rz.friction"
    s = model.compile()
    t = np.linspace(0.0, 3.0, 3001)
    r = rf.simulate(s, 3.0, "radau5", q0=[0.3], t_eval=t, rtol=1e-11, atol=1e-13)
    lost = r.energy[0] - r.energy
    dissipated = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (r.dissipated_power[1:] + r.dissipated_power[:-1]))])
    assert lost[-1] > 1.0  # most of the swing is gone
    assert np.max(np.abs(lost - dissipated)) < 1e-5 * lost[-1]  # the trapezoid's error at 1 ms
    np.testing.assert_allclose(r.dissipated_power, [s.dissipated_power(tk, q, qd) for tk, q, qd in
                                                    zip(r.t, r.q, r.qd)], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("algorithm", ["recursive", "lagrange"])
def test_the_laws_derivatives_are_exact(algorithm):
    """∂f/∂q̇ holds the friction's analytic −∂Q/∂q̇ (and a Python ForceFunction's differences): the recursive and
    Lagrange engines against central differences of the generalised forces."""
    model, _, rng = rf.samples.random_tree(3, nbodies=4)
    first, last = model.compile().coordinate_names[0], model.compile().coordinate_names[-1]
    for coordinate, law in ((first, rf.laws.Friction(breakaway=2.0, coulomb=1.0, stribeck=0.7, viscous=0.3,
                                                     smoothing=0.4)),
                            (last, rf.laws.ForceFunction(function=lambda t, q, qd: np.sin(q) * qd - 0.3 * qd ** 3))):
        body, axis = coordinate.rsplit(".", 1)
        model.add_joint_law(f"{coordinate}.{law.kind.lower()}", model.body(body), law, coordinate=axis)
    s = model.compile(algorithm)
    for _ in range(3):
        t, q, qd = 0.2, rng.uniform(-0.5, 0.5, s.nq), rng.uniform(-1.0, 1.0, s.nq)
        Kq, Kqd = s.force_jacobians(t, q, qd)
        Fq, Fqd = central_jacobians(s, t, q, qd)
        assert np.abs(Kq - Fq).max() < 1e-6 * max(1.0, np.abs(Fq).max())
        assert np.abs(Kqd - Fqd).max() < 1e-6 * max(1.0, np.abs(Fqd).max())


def test_friction_constants_are_named_parameters_in_the_coordinates_units():
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    arm = model.add_body("arm", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.01, 0.1, 0.1),
                         com=(0.5, 0.0, 0.0))
    model.add_joint_law("hinge", arm, rf.laws.Friction(breakaway=0.4, coulomb=0.3))
    slider = model.add_body("slider", arm, rf.Joint.prismatic("x"), mass=0.5, inertia=(0.01, 0.01, 0.01))
    model.add_joint_law("slider.x.friction", slider, rf.laws.Friction(coulomb=2.0, viscous=0.1))
    p = model.compile().parameters
    assert (p["hinge.breakaway"].value, p["hinge.breakaway"].unit) == (0.4, "N m")
    assert (p["hinge.viscous"].unit, p["slider.x.friction.coulomb"].unit) == ("N m s/rad", "N")
    assert p["slider.x.friction.viscous"].unit == "N s/m"
    assert "hinge.stribeck" not in p and "hinge.smoothing" not in p  # not parameters: the law is not linear in them
    with pytest.raises(ValueError, match="^values: expected hinge.coulomb to be a finite value >= 0 in N m"):
        model.compile().with_parameters({"hinge.coulomb": -1.0})


def test_sensitivities_and_the_adjoint_by_a_friction_constant_match_differences_of_runs():
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    arm = model.add_body("arm", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.01, 0.1, 0.1),
                         com=(0.5, 0.0, 0.0))
    model.add_joint_law("hinge", arm, rf.laws.Friction(breakaway=0.4, coulomb=0.3, stribeck=0.3, viscous=0.05,
                                              smoothing=0.1))
    s = model.compile()
    names = ["hinge.coulomb", "hinge.viscous", "hinge.breakaway"]
    run = dict(method="generalized_alpha", dt=1e-3, q0=[0.4], newton_tol=1e-14)
    r = rf.simulate(s, 1.0, sensitivities=names, **run)
    for name in names:  # the discrete solution's derivative: central differences of runs, h = 1e-5 of the unit
        h = 1e-5
        up = rf.simulate(s.with_parameters({name: s.parameters[name].value + h}), 1.0, **run)
        down = rf.simulate(s.with_parameters({name: s.parameters[name].value - h}), 1.0, **run)
        difference = (up.q[:, 0] - down.q[:, 0]) / (2 * h)
        assert np.abs(r.sensitivity(name)[0][:, 0] - difference).max() < 1e-5 * np.abs(difference).max(), name
    g = rf.gradient(s, 1.0, names, outputs={"angle": "arm.rz"}, terminal=lambda y: y["angle"], dt=1e-3, q0=[0.4],
                    newton_tol=1e-14)
    for name in names:
        assert abs(g[name] - r.sensitivity(name)[0][-1, 0]) < 1e-8 * max(1.0, abs(g[name])), name


def test_the_laws_describe_themselves():
    """Every kind's description comes from C++; its constants are the keyword arguments with their defaults, and
    a law's repr, equality and pickle keep its values."""
    import pickle

    kinds = rf.laws.kinds()
    assert {"SpringDamper", "Rope", "SpringDamping", "Friction", "ForceFunction"} <= set(kinds)
    law = rf.laws.Friction(coulomb=2.0)
    assert law.values["coulomb"] == 2.0 and law.values["stribeck"] == 0.01  # the C++ default
    assert [c.name for c in law.constants] == [c["name"] for c in kinds["Friction"]["constants"]]
    assert pickle.loads(pickle.dumps(law)) == law and repr(law).startswith("Friction(breakaway=0.0, coulomb=2.0")
    assert "``stribeck`` = 0.01 (m/s or rad/s, > 0)" in rf.laws.Friction.__doc__
    assert "| `Rope` | element | `EA` | N |" in rf.laws.table()


def test_bad_joint_law_input():
    model, b, _ = block()
    with pytest.raises(ValueError, match=r"^breakaway: expected a non-negative number in N \(the breakaway"):
        rf.laws.Friction(breakaway=-1.0)
    with pytest.raises(ValueError, match="^stribeck: expected a positive number in m/s"):
        rf.laws.Friction(stribeck=0.0)
    with pytest.raises(ValueError, match="^smoothing: expected a number in m/s, got 'x'"):
        rf.laws.Friction(smoothing="x")
    with pytest.raises(TypeError, match=r"unexpected constants \['mu'\]"):
        rf.laws.Friction(mu=0.3)
    with pytest.raises(ValueError, match="^law: expected a law of a joint coordinate"):
        model.add_joint_law("law", b, rf.laws.Rope(EA=1.0))
    with pytest.raises(ValueError, match="^law: expected a law of a joint coordinate"):
        model.add_joint_law("law", b, rf.laws.SpringDamping())
    with pytest.raises(ValueError, match="^function: expected None"):
        rf.laws.Friction(function=lambda t, q, qd: 0.0)
    model.add_joint_law("f", b, rf.laws.Friction(coulomb=1.0))
    with pytest.raises(ValueError, match="^name: expected a name not yet given"):
        model.add_joint_law("f", b, rf.laws.Friction(coulomb=1.0))
    with pytest.raises(ValueError, match="^body: expected a body of this model"):
        model.add_joint_law("law", model.ground, rf.laws.Friction())
