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
import re
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


def test_linearize_refuses_a_sample_time_whose_hold_overflows(pendulum):
    """dt = 1e100: e^(A dt) overflows; the matrices were NaN with only numpy's overflow warning."""
    import warnings

    _, _, system = pendulum
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rf.NotAnEquilibriumWarning)
        with pytest.raises(rf.SimulationError, match=r"zero-order hold at dt = 1e\+100 s\): A has NaN or inf"):
            rf.linearize(system, [0.1], dt=1e100)
        ss, continuous = rf.linearize(system, [0.1], dt=0.01), rf.linearize(system, [0.1])
    import scipy.linalg

    np.testing.assert_allclose(ss.A, scipy.linalg.expm(continuous.A * 0.01), rtol=1e-12)  # the hold: e^(A dt)


def test_a_profile_that_overflows_is_a_simulation_error():
    p = rf.motion.polynomial([0.0] * 10 + [1e300])
    with pytest.raises(rf.SimulationError, match=r"^at t = 1000000 s: the profile polynomial\(degree 10\) is not "
                                                 r"finite: \(q, qd, qdd\) = \(inf"):
        p(1e6)
    assert p(1.0) == pytest.approx((1e300, 1e301, 9e301), rel=1e-15)


def test_a_results_outputs_that_overflow_are_named_in_a_warning():
    """A base of mass 1e308 driven along x: its driving force overflows. System.driving_forces raises at
    that state; the result's were inf without a word."""
    m = rf.Model(gravity=(0.0, 0.0, -9.81))
    base = m.add_body("base", m.ground, rf.Joint.prismatic("x"), mass=1e308, inertia=(1.0, 1.0, 1.0))
    m.prescribe(base, rf.motion.polynomial([0.0, 0.0, 1.0]))
    m.add_body("link", base, rf.Joint.revolute("y"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.0, 0.0, -1.0))
    system = m.compile()
    result = rf.simulate(system, 0.1, q0=[0.1], t_eval=[0.0, 0.05, 0.1])
    with pytest.warns(RuntimeWarning, match=r"^result\.driving_forces: NaN or inf from t = 0 s on \(3 of 3 outputs"):
        forces = result.driving_forces
    assert not np.isfinite(forces).any()
    with pytest.raises(rf.SimulationError, match="driving_forces\\(\\) overflowed"):
        system.driving_forces(0.0, [0.1], [0.0])


# -- the sea: finite spectra, values refused by name ------------------------------------------

def test_jonswap_is_finite_where_it_was_nan_and_equals_the_formula_elsewhere():
    w = np.array([1e-300, 1e-3, 0.3, 0.5, 0.698, 0.8, 1.5, 3.0])
    hs, tp, gamma = 3.0, 9.0, 3.3
    S = rf.sea.jonswap(w, hs, tp, gamma)
    assert np.all(np.isfinite(S)) and S[0] == 0.0 and S[1] == 0.0  # ω ≪ ω_p: S → 0 (was NaN)
    wp = 2 * np.pi / tp  # DNV-RP-C205 3.5.5, directly, where it does not underflow
    sigma = np.where(w[2:] <= wp, 0.07, 0.09)
    ref = ((1 - 0.287 * np.log(gamma)) * 5 / 16 * hs**2 * wp**4 * w[2:] ** -5 * np.exp(-1.25 * (w[2:] / wp) ** -4)
           * gamma ** np.exp(-0.5 * ((w[2:] - wp) / (sigma * wp)) ** 2))
    np.testing.assert_allclose(S[2:], ref, rtol=1e-12)
    assert np.all(rf.sea.jonswap([0.5, 5.0], 2.0, 1e-300) == 0.0)  # T_p → 0: no energy at these ω (was NaN)


@pytest.mark.parametrize("call, name", [
    (lambda: rf.sea.jonswap(0.5, hs=1e300, tp=8.0), "hs, tp"),
    (lambda: rf.sea.jonswap(2**1100, 2.0, 8.0), "omega"),
    (lambda: rf.sea.jonswap("0.5", 2.0, 8.0), "omega"),
    (lambda: rf.sea.jonswap(0.5 + 1j, 2.0, 8.0), "omega"),
    (lambda: rf.sea.jonswap_waves(2.0, 8.0, n=2**1100), "n"),
    (lambda: rf.Section.rectangle(1e300, 1.0), "width"),
    (lambda: rf.Section.rectangle(1.0, 1e-300), "height"),
    (lambda: rf.Section.circle(1e300), "d"),
    (lambda: rf.Section.tube(1e300, 1e299), "d_out"),
    (lambda: rf.Model().add_beam("b", "ground", 1.0, rf.Material(2e11, 7850.0), rf.Section.circle(0.01), 2,
                                 deform=3), "deform"),
])
def test_overflowing_or_wrong_values_are_value_errors_naming_them(call, name):
    """They were OverflowError (34, 'Numerical result out of range'), NaN spectra, numbers parsed from
    strings, imaginary parts dropped, or TypeError from deep inside."""
    with pytest.raises(ValueError, match=rf"^{re.escape(name)}: expected"):
        call()


def test_raos_pickle():
    """RAO.table, RAO.oscillator and RAO.constant kept local lambdas: a sweep's processes could not take them."""
    import pickle

    w = np.linspace(0.0, 3.0, 7)
    for rao in (rf.sea.RAO.table([0.1, 1.0, 2.0], [1.0, 2.0, 0.5], [0.0, 0.5, 1.0]), rf.sea.RAO.oscillator(8.0, 0.1),
                rf.sea.RAO.constant(0.7, 0.2)):
        back = pickle.loads(pickle.dumps(rao))
        assert np.array_equal(back(w), rao(w)) and repr(back) == repr(rao)


# -- wrong input accepted silently --------------------------------------------------------------

@pytest.mark.parametrize("kwargs, name", [
    ({"rtol": []}, "rtol"), ({"atol": []}, "atol"), ({"progress": "yes"}, "progress"), ({"progress": 1}, "progress"),
])
def test_simulate_refuses_what_it_read_by_truthiness_or_replaced_by_defaults(pendulum, kwargs, name):
    _, _, system = pendulum
    with pytest.raises(ValueError, match=rf"^{name}: expected"):
        rf.simulate(system, 0.1, **kwargs)


def test_builders_refuse_non_booleans_for_their_switches():
    """follower="no" made a follower force; linear="no" the linear beam model."""
    m = rf.Model()
    body = m.add_body("b", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match=r"^follower: expected True or False, got 'no'"):
        m.add_force("push", body, (1.0, 0.0, 0.0), follower="no")
    with pytest.raises(ValueError, match=r"^follower: expected True or False, got 0"):
        m.add_torque("twist", body, (1.0, 0.0, 0.0), follower=0)
    with pytest.raises(ValueError, match=r"^linear: expected True or False, got 'no'"):
        m.add_beam("beam", body, 1.0, rf.Material(2e11, 7850.0), rf.Section.circle(0.01), 2, linear="no")
    with pytest.raises(ValueError, match=r"^progress: expected True or False"):
        rf.sweep(lambda x: x, grid={"x": [1]}, progress="yes")


def test_scipy_methods_refuse_a_step_below_the_floor_at_once(pendulum):
    """max_step = 1e-300, or steps that t no longer resolves (t0 = 1e15 s): the C++ methods refuse at once
    (16 ε max(1, |t|)); scipy's ran a million steps (minutes) to max_steps."""
    import time

    _, _, system = pendulum
    for method in ("dopri5", "scipy:RK45", "scipy:Radau"):
        start = time.perf_counter()
        with pytest.raises(rf.SimulationError, match=r"^at t = 0 s: the step size fell below the minimum"):
            rf.simulate(system, 1.0, method=method, q0=[0.1], max_step=1e-300)
        assert time.perf_counter() - start < 5.0  # at once, against the minutes of a million scipy steps
    with pytest.raises(rf.SimulationError, match=r"^at t = 1e\+15 s: "):
        rf.simulate(system, 1e15 + 100.0, method="scipy:LSODA", t0=1e15, q0=[0.1])


def test_position_sensitivity_without_free_coordinates():
    """nq = 0, a drive's number: numpy's zero-size reduction error before; dx/dc₁ of the arm's end at
    angle c₁ t is t (−sin, cos, 0)."""
    m = rf.Model(gravity=(0.0, 0.0, -9.81))
    arm = m.add_body("arm", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1), com=(0.5, 0, 0))
    m.prescribe(arm, rf.motion.polynomial([0.0, 0.3]))
    system = m.compile()
    assert system.nq == 0
    name = "arm.rz.drive.coefficients[1]"
    result = rf.simulate(system, 1.0, method="rk4", dt=0.1, sensitivities=[name])
    dx = result.position_sensitivity(arm.point((1.0, 0.0, 0.0)), name)
    t = result.t
    np.testing.assert_allclose(dx, np.column_stack([-t * np.sin(0.3 * t), t * np.cos(0.3 * t), 0 * t]), atol=1e-8)


def test_simulate_refuses_output_times_whose_states_cannot_fit_before_running(pendulum, monkeypatch):
    """len(t_eval) states of 2 nq (+ nz + 2 nq per sensitivity) doubles against the machine's memory (here
    pretended 4 MB): refused before the run rather than failing after it."""
    from rigidfem.simulation import integration

    _, _, system = pendulum
    monkeypatch.setattr(integration, "_physical_memory", lambda: 4096 * 1000)
    t = np.linspace(0.0, 1.0, 300_000)  # 300,000 × 2 doubles = 4.8 MB
    with pytest.raises(ValueError, match=r"^t_eval: expected at most 256,000 output times \(their states, 2 numbers "
                                         r"each, within the machine's 0.0041 GB\), got 300,000"):
        rf.simulate(system, 1.0, t_eval=t)
    with pytest.raises(ValueError, match=r"^t_eval: expected at most 128,000 output times \(their states, 4 numbers"):
        rf.simulate(system, 1.0, t_eval=t[:200_000], sensitivities=["link.mass"])
    assert len(rf.simulate(system, 1.0, t_eval=t[:1000]).t) == 1000
