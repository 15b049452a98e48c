"""The classes of issue 44, closed for every entry point rather than for the instances found:

- every public function or method taking a ``system`` checks it in the one validation layer
  (``_checks.system``), before anything else: a Model, None or a string is a ValueError naming
  ``system`` and saying to compile;
- every one taking a ``result`` checks it likewise (``_checks.result``), and a result loaded without
  its system says what needs the system instead of failing deep inside.

The entry points are found by introspection of the public namespace, so a new function taking a
system or a result is held to the same rule without a new test.
"""

from __future__ import annotations

import inspect
import types

import numpy as np
import pytest

import rigidfem as rf


def public_callables():
    """(name, callable) of the public API: the package's functions and classes, the public
    modules' functions and classes, the public classes' methods."""
    seen = set()

    def members(owner, prefix, names=None):
        for m in dir(owner) if names is None else names:
            v = getattr(owner, m, None)
            if m.startswith("_") or not callable(v) or not getattr(v, "__module__", "").startswith("rigidfem"):
                continue
            if id(v) not in seen:
                seen.add(id(v))
                yield f"{prefix}.{m}", v
            if inspect.isclass(v):
                for k, f in inspect.getmembers(v, inspect.isfunction):
                    if not k.startswith("_") and id(f) not in seen:
                        seen.add(id(f))
                        yield f"{prefix}.{m}.{k}", f

    yield from members(rf, "rf", rf.__all__)  # some are loaded on first use (rf.animate): not in dir(rf)
    for n in [*rf.__all__, "loops"]:
        obj = getattr(rf, n)
        if isinstance(obj, types.ModuleType):
            yield from members(obj, f"rf.{n}")


#: containers the package fills itself, whose system may be absent (a result loaded without it)
CONTAINERS = {"rf.Result", "rf.ErrorEstimate", "rf.Plan"}


def taking(parameter):
    found = []
    for name, f in public_callables():
        if name in CONTAINERS:
            continue
        try:
            params = inspect.signature(f).parameters
        except (TypeError, ValueError):  # pybind11's builtins: the core's own casters check them
            continue
        if parameter in params:
            found.append(pytest.param(f, params, id=name))
    return found


def _call(f, params, parameter, value, system=None):
    """Call f with ``parameter`` = value, ``system`` for a system, every other required argument None."""
    args, kwargs = [], {}
    for p in params.values():
        if p.name == "self":
            args.append(None)
        elif p.name == "system" and parameter != "system":
            args.append(system)
        elif p.name == parameter:
            (args.append(value) if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) else
             kwargs.__setitem__(p.name, value))
        elif p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD):
            args.append(None)
        elif p.default is p.empty and p.kind == p.KEYWORD_ONLY:
            kwargs[p.name] = None
    return f(*args, **kwargs)


@pytest.fixture(scope="module")
def pendulum():
    model, h = rf.samples.pendulum()
    return model, h, model.compile()


SYSTEM_TAKERS = taking("system")
RESULT_TAKERS = taking("result")


def test_the_introspection_finds_the_entry_points():
    names = {p.id for p in SYSTEM_TAKERS} | {p.id for p in RESULT_TAKERS}
    for expected in ("rf.simulate", "rf.gradient", "rf.linearize", "rf.modal_analysis", "rf.static_equilibrium",
                     "rf.view", "rf.loops.assemble", "rf.plots.shape", "rf.plots.modes", "rf.Beam.centerline",
                     "rf.animate", "rf.plots.energies", "rf.Beam.tip_positions", "rf.export.to_npz", "rf.study.Scene"):
        assert expected in names, expected
    assert len(SYSTEM_TAKERS) >= 15 and len(RESULT_TAKERS) >= 10


@pytest.mark.parametrize(("f", "params"), SYSTEM_TAKERS)
def test_a_model_or_none_for_a_system_is_a_value_error_saying_to_compile(f, params, pendulum):
    model = pendulum[0]
    for wrong, said in ((model, "got a Model"), (None, "got None"), ("system", "got 'system'")):
        if wrong is None and params["system"].default is None:
            continue  # load_npz, read_npz: None means "without its system"
        with pytest.raises(ValueError, match=rf"^system: expected a compiled System \(call model\.compile\(\)\), "
                                             rf"{said}"):
            _call(f, params, "system", wrong)


@pytest.mark.parametrize(("f", "params"), RESULT_TAKERS)
def test_something_else_for_a_result_is_a_value_error_naming_it(f, params, pendulum):
    model, _, system = pendulum
    for wrong in (None, "result", model, system):
        if wrong is None and params["result"].default is None:
            continue  # view: None means "the state q"
        with pytest.raises(ValueError, match=r"^result: expected a Result"):
            _call(f, params, "result", wrong, system)


@pytest.fixture(scope="module")
def loaded(pendulum, tmp_path_factory):
    model, h, system = pendulum
    result = rf.simulate(system, 0.5, q0=[0.3], t_eval=np.linspace(0, 0.5, 11))
    path = tmp_path_factory.mktemp("npz") / "run.npz"
    result.to_npz(path)
    return result, rf.load_npz(path), path


@pytest.mark.parametrize("what", ["qdd", "energy", "kinetic_energy", "driving_forces", "element_forces",
                                  "loop_reactions", "dissipated_power"])
def test_a_result_loaded_without_its_system_says_the_outputs_need_it(loaded, what):
    _, bare, _ = loaded
    with pytest.raises(ValueError, match=r"^result: expected a Result with its System .*rigidfem\.load_npz\(path, "
                                         r"system\)"):
        getattr(bare, what)


def test_a_result_loaded_without_its_system_keeps_what_does_not_need_it(loaded, pendulum, tmp_path):
    result, bare, path = loaded
    _, h, system = pendulum
    assert np.array_equal(bare.q, result.q) and bare.coordinate_names == list(system.coordinate_names)
    again = rf.load_npz(bare.to_npz(tmp_path / "again.npz"), system)  # saved again without the system
    assert np.array_equal(again.qd, result.qd)
    assert np.allclose(again.energy, result.energy, rtol=0, atol=1e-12)
    assert bare.to_dataframe().columns.tolist() == result.to_dataframe().columns.tolist()
    for call, needs in ((lambda: bare.position(h["tip"]), "positions"),
                        (lambda: rf.plots.energies(bare), "energies"),
                        (lambda: rf.animate(bare), "an animation"),
                        (lambda: bare.to_dataframe(points={"tip": h["tip"]}), "positions")):
        with pytest.raises(ValueError, match=f"^result: expected a Result with its System for {needs}"):
            call()


def test_a_scene_and_work_precision_name_what_is_wrong(pendulum):
    model, h, system = pendulum
    with pytest.raises(ValueError, match=r"^scene: expected a rigidfem\.study\.Scene"):
        rf.study.work_precision("x", [("rk4", "dt", [0.1])])
    with pytest.raises(ValueError, match=r"^t_end: expected a positive number in s"):
        rf.study.Scene("pendulum", system, -1.0, h["tip"])
    with pytest.raises(ValueError, match=r"^tip: expected a Point or Body"):
        rf.study.Scene("pendulum", system, 1.0, "tip")


# -- work bounded before it is allocated --------------------------------------------------------

def test_gradient_bounds_its_steps_and_memory_before_allocating(pendulum):
    """t_end/dt beyond max_steps is refused at once (it built every step time first: minutes and all
    the memory); so is a memory that cannot hold the grid and the outputs."""
    _, h, system = pendulum
    kw = dict(outputs={"tip": h["tip"]}, terminal=lambda y: y["tip"][0], dt=1e-3)
    for t_end, max_steps, steps in ((1e300, None, r"1e\+303"), (2000.0, None, r"2e\+06"), (1.0, 999, "1000")):
        extra = {} if max_steps is None else {"max_steps": max_steps}
        with pytest.raises(ValueError, match=rf"^t_end, dt: expected at most max_steps = .* got \(t_end - t0\)/dt = "
                                             rf"{steps} steps"):
            rf.gradient(system, t_end, ["link.mass"], **kw, **extra)
    with pytest.raises(ValueError, match=r"^memory: expected at least 320032 bytes \(the grid and the outputs at its "
                                         r"10001 times\)"):  # 10001 times × (1 + 3 outputs) × 8 bytes
        rf.gradient(system, 10.0, ["link.mass"], **kw, memory=1000)
    g = rf.gradient(system, 1.0, ["link.mass"], **kw, max_steps=1000)  # 1000 steps: within the bound
    assert np.isfinite(g.value)


# -- no NaN or inf without a word ---------------------------------------------------------------

def test_resolve_refuses_outputs_that_are_not_finite():
    """An output function returning NaN or inf made a plan with 'estimated error 0' and a NaN limit."""
    def build(elements, deform):
        model, h = rf.samples.cantilever(elements=elements, deform=deform)
        bad = (lambda system, solution: np.full(3, np.nan)) if elements >= 4 else (lambda s, sol: np.zeros(3))
        return model, {"tip": h["beam"].tip, "bad": bad, "inf": lambda system, solution: np.array([np.inf])}

    for name in ("bad", "inf"):
        with pytest.raises(rf.ResolveError, match=rf"^outputs: expected finite values of '{name}', got NaN or inf"):
            rf.resolve(build, ["tip", name], 1e-3, elements=4)
