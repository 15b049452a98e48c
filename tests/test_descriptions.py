"""Every kind describes itself once, in C++: the tables the Python layer shows (the methods and their options, ...)
are the C++ descriptions read through the bindings, and agree with what the C++ code does."""

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import _core, options
from rigidfem.analysis import adjoint


def test_the_methods_are_the_cpp_table():
    table = {row["name"]: row for row in _core._method_table()}
    methods = rf.methods()
    assert [m for m in methods if not m.startswith("scipy:")] == ["auto"] + [m for m in table if m != "auto"]
    for name, row in table.items():
        m = methods[name]
        assert (m.family, m.order, m.error_estimate, m.adaptive, m.adjoint, m.options, m.doc) == (
            row["family"], row["order"], row["error_estimate"], row["adaptive"], row["adjoint"], tuple(row["options"]),
            row["doc"])
        assert m.error_on == ("bodies" if row["measures_outputs"] else "state")
    assert options.METHODS == tuple(methods)
    with pytest.raises(ValueError, match="^method: expected one of"):
        rf.methods()["nope"] if False else options.method("nope")


def test_each_option_is_described_once_with_the_structs_default_and_its_readers():
    defaults = _core.IntegratorOptions()
    rows = _core._option_table()
    assert [o.name for o in options.OPTIONS] == [r["name"] for r in rows]
    for row, o in zip(rows, options.OPTIONS):
        assert o.default == defaults.get(row["name"]) == row["default"], row["name"]
        assert (o.unit, o.doc, o.expected) == (row["unit"], row["doc"], row["expected"])
        readers = {m for m, method in rf.methods().items() if o.name in method.options}
        assert set(o.methods) == readers, o.name
        assert set(rf.integrator_options(next(iter(readers)))) >= {o.name}
    # every option a method reads is one of the table's
    for method in rf.methods().values():
        assert set(method.options) <= {o.name for o in options.OPTIONS}, method.name


def test_an_option_is_converted_by_its_type_with_a_message_naming_it():
    opt = _core.IntegratorOptions()
    for name, good, bad in (("dt", 0.01, "x"), ("max_steps", 7, 1.5), ("adaptive", True, 1), ("beta", 0.3, None),
                            ("iteration_matrix", "spring", 3), ("rtol", [1e-6, 1e-7], "tight")):
        opt.set(name, good)
        got = opt.get(name)
        assert got == good or (isinstance(good, list) and got == good[0]), name
        with pytest.raises(ValueError, match=f"^{name}: expected "):
            opt.set(name, bad)
    with pytest.raises(ValueError, match="^dt: expected a positive finite step in s, got -1"):
        opt.set("dt", -1.0)
    with pytest.raises(ValueError, match="^name: expected an option of the integrators"):
        opt.set("nope", 1.0)


def test_the_methods_with_an_adjoint_are_those_the_cpp_adjoint_runs():
    assert set(adjoint.METHODS) == {name for name, m in rf.methods().items() if m.adjoint}
    model, h = rf.samples.pendulum()
    system = model.compile()
    for name, m in rf.methods().items():
        if name.startswith("scipy:"):
            continue
        opt = options.compiled(name, {"dt": 0.01})
        if m.adjoint:
            _core._Adjoint(system, opt, [("coordinate", 0, np.zeros(3))], 1e6)
        else:
            with pytest.raises(ValueError, match="^method: expected generalized_alpha"):
                _core._Adjoint(system, opt, [("coordinate", 0, np.zeros(3))], 1e6)


def test_a_fixed_step_error_estimate_takes_the_tables_order():
    """Richardson's factor 2^p/(2^p − 1) of Result.error_estimate at fixed steps is the method's order from the table:
    bs23 (order 3) on a pendulum estimates its own error within 30 % of the error against a tight reference."""
    model, h = rf.samples.pendulum()
    system = model.compile()
    ref = rf.simulate(system, 1.0, "dopri5", q0=[1.0], rtol=1e-12, atol=1e-14, t_eval=[1.0])
    r = rf.simulate(system, 1.0, "bs23", q0=[1.0], dt=0.02, adaptive=False, t_eval=[1.0])
    estimate = r.error_estimate.of(lambda x: x.q[:, 0])
    actual = abs(r.q[-1, 0] - ref.q[-1, 0])
    assert 0.7 * actual < estimate < 1.3 * actual, (estimate, actual)


def test_every_law_kind_is_the_cpp_description_and_what_parameters_and_viewer_read():
    """For every kind of force element: a law of it with the defaults is added by the one generic builder, its
    parameters are the constants the description marks (units, docs, bounds), and the viewer draws it as the
    C++ law says (no table of kinds in Python)."""
    kinds = rf.laws.kinds()
    assert {k: v["acts_on"] for k, v in kinds.items()} == {row["kind"]: row["acts_on"]
                                                             for row in _core._Model._law_kinds()}
    model = rf.Model(gravity=None)
    body = model.add_body("b", model.ground, rf.Joint.prismatic("x"), mass=1.0, inertia=(1, 1, 1))
    elements = [k for k, info in kinds.items() if info["acts_on"] == "element"]
    for k, kind in enumerate(elements):
        model.add_force_element(kind, model.ground.point((0.0, 1.0 + k, 0.0)), body, getattr(rf.laws, kind)())
    system = model.compile()
    for k, kind in enumerate(elements):
        info = kinds[kind]
        marked = {c["name"]: c for c in info["constants"] if c["parameter"]}
        listed = {name.split(".", 1)[1]: p for name, p in system.parameters.items() if name.startswith(kind + ".")}
        assert set(listed) == set(marked), kind
        for name, p in listed.items():
            c = marked[name]
            assert (p.unit, p.description, p.minimum, p.positive) == (c["unit"], c["doc"], c["lower"], c["positive"])
            assert p.value == c["default"]
        law_kind, values, drawn = model._element_law(k)
        assert law_kind == kind and values == [c["default"] for c in info["constants"]]
        assert rf.view(system).data["segments"][k]["kind"] == drawn


def test_every_profile_kind_is_the_cpp_table_with_its_numbers_as_parameters():
    """The named parameters read a profile's numbers by the names of its kind's row (no table in Python), and every
    kind pickles through the one generic maker as its recipe."""
    import pickle

    from rigidfem import parameters

    table = {k["maker"]: [a["name"] for a in k["arguments"]] for k in _core._profile_kinds()}
    assert parameters.PROFILE_ARGUMENTS == {k: tuple(v) for k, v in table.items()}
    made = [rf.motion.constant(1.0), rf.motion.polynomial([1.0, 2.0]), rf.motion.harmonic(1.0, 2.0),
            rf.motion.chirp(0.1, 1.0, 5.0, 2.0),
            rf.motion.harmonics([1.0], [2.0]), rf.motion.spin_up(1.0, 2.0), rf.motion.spline([0.0, 1.0], [0.0, 1.0]),
            rf.motion.rest_to_rest(0.0, 1.0, 0.0, 1.0), rf.motion.ramp(1.0, 0.0, 1.0),
            rf.motion.constant(1.0) + rf.motion.harmonic(1.0, 2.0), rf.motion.constant(1.0).shifted(0.5),
            rf.motion.piecewise([rf.motion.constant(0.0), rf.motion.constant(0.0)], [1.0])]
    assert {p.__reduce__()[1][0] for p in made} == set(table)  # every kind made by a builder of rigidfem.motion
    for p in made:
        make, args = p.__reduce__()
        assert make is _core._make_profile and len(args) == 1 + len(table[args[0]])
        back = pickle.loads(pickle.dumps(p))
        assert repr(back) == repr(p) and back(0.7) == p(0.7)
    assert rf.motion.LAWS == tuple(_core._point_to_point_laws())
    with pytest.raises(ValueError, match="^law: expected one of 'quintic', 'cycloidal', 'trapezoidal', got 'sine'"):
        rf.motion.ramp(1.0, 0.0, 1.0, law="sine")


def test_an_option_the_method_does_not_read_leaves_its_run_unchanged():
    """The method table says what each method reads: rk4 given first_step or max_step (an adaptive run's) steps at dt
    as without them (they once set its step: 2 steps instead of 100), but a bad value is still named."""
    model, _ = rf.samples.pendulum()
    system = model.compile()
    plain = rf.simulate(system, 1.0, "rk4", dt=0.01, q0=[0.5])
    for extra in ({"first_step": 0.05}, {"max_step": 0.003}, {"rho_inf": 0.3}):
        other = rf.simulate(system, 1.0, "rk4", dt=0.01, q0=[0.5], **extra)
        assert other.stats["steps"] == plain.stats["steps"] == 100, extra
        np.testing.assert_array_equal(other.q, plain.q)
    with pytest.raises(ValueError, match="^first_step: expected a positive finite step in s"):
        rf.simulate(system, 1.0, "rk4", dt=0.01, first_step=-1.0)
    for bad, name in (({"max_step": 0.0}, "max_step"), ({"newton_tol": -1.0}, "newton_tol")):
        with pytest.raises(ValueError, match=f"^{name}: expected"):  # the options every run checks: whatever the method
            rf.simulate(system, 1.0, "rk4", dt=0.01, **bad)
    with pytest.raises(ValueError, match="^dt: expected a positive step in s for the fixed-step method 'rk4'"):
        rf.simulate(system, 1.0, "rk4", first_step=0.01)  # not its step: rk4 does not read first_step
    with pytest.raises(ValueError, match="^adaptive: the method 'rk4' has no error estimate"):
        rf.simulate(system, 1.0, "rk4", dt=0.01, adaptive=True)
