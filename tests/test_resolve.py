"""The model's resolution chosen for a requested accuracy: rf.resolve (issue 24, item 4).

References computed here: the elastica by scipy's solve_bvp, and a fine model's Richardson limit."""

import numpy as np
import pytest
from scipy.integrate import solve_bvp

import rigidfem as rf

STEEL = rf.Material(E=2.1e11, rho=7850.0)


def elastica_tip(k):
    """The cantilever elastica's tip (x, y)/L under a tip force P normal to the undeformed axis,
    k = PL²/EI: θ'' = −k cos θ, x' = cos θ, y' = sin θ (solve_bvp)."""
    s = np.linspace(0, 1, 201)
    sol = solve_bvp(lambda x, y: np.vstack([y[1], -k * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])]),
                    lambda a, b: np.array([a[0], b[1], a[2], a[3]]), s, np.zeros((4, s.size)), tol=1e-10,
                    max_nodes=100000)
    return sol.sol(1.0)[2:]


@pytest.mark.parametrize("k, tol", [(1.0, 1e-3), (3.0, 1e-4)])
def test_resolve_meets_the_elastica(k, tol):
    """Static tip under PL²/EI = k against the elastica: the chosen m's error within tol, its estimate
    within a factor 2 of the true error, and the Richardson limit ten times closer than tol."""
    sec = rf.Section(A=1e-4, Iy=2e-12, Iz=1e-12, J=3e-12)

    def build(m, deform):
        model = rf.Model(gravity=None)
        beam = model.add_beam("b", model.ground, 1.0, STEEL, sec, m, deform=deform)
        model.add_force("load0", beam.tip, (0.0, k * STEEL.E * sec.Iz, 0.0))
        return model, {"tip": beam.tip}

    plan = rf.resolve(build, "tip", tol=tol, elements=2)
    ref = elastica_tip(k)
    tip = plan.system.position(plan.handles["tip"], 0.0, plan.solution.q)[:2]
    true = np.linalg.norm(tip - ref)
    assert true <= rf.studies.resolution.SPACE * tol and 0.5 < plan.space_error / true < 2, (plan.space_error, true)
    assert np.linalg.norm(plan.limit["tip"][:2] - ref) < 0.1 * tol
    assert plan.deform == ("bend_z",) and set(plan.dropped) == {"bend_y", "torsion"}
    assert plan.beams == {"b": plan.elements} and abs(plan.order - 2.0) < 0.1
    assert plan.error["time"] == 0.0 and "elements" in plan.report()
    # the cheapest: half the elements would not do
    half = rf.resolve(build, "tip", tol=tol, elements=plan.elements // 2 if plan.elements > 2 else 2)
    assert half.elements == plan.elements


def test_resolve_keeps_torsion_only_where_it_matters():
    """A 3D cantilever (20 × 5 mm) under a tip force along z through its axis (bending about y only)
    and under the same force 2 cm off the axis (a torque about x): torsion and the other bending are
    dropped in the first case, torsion kept in the second."""
    sec = rf.Section.rectangle(0.02, 0.005)

    def loaded(offset):
        def build(m, deform):
            model = rf.Model(gravity=None)
            beam = model.add_beam("b", model.ground, 1.0, STEEL, sec, m, deform=deform)
            tip = beam.rfes[-1].point((1.0 / (2 * m), offset, 0.0)) if offset else beam.tip
            model.add_force("load0", tip, (0.0, 0.0, 20.0))
            return model, {"tip": beam.rfes[-1].point((1.0 / (2 * m), 0.01, 0.0))}  # a point beside the axis
        return build

    centred = rf.resolve(loaded(0.0), "tip", tol=1e-5)
    assert "torsion" not in centred.deform and "bend_y" in centred.deform
    eccentric = rf.resolve(loaded(0.02), "tip", tol=1e-5)
    assert "torsion" in eccentric.deform and "bend_y" in eccentric.deform
    assert eccentric.kept["torsion"] > rf.studies.resolution.DROP * 1e-5


def test_resolve_on_kanes_beam_meets_its_richardson_limit():
    """Kane's spin-up beam over 8 s, the tip in the hub frame: the chosen m's tip (at its own time
    tolerance) within tol of a fine model's (m = 64) Richardson-extrapolated tip."""
    def build(m, deform):
        model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=m)
        return model, {"tip": lambda system, r: r.position(h["beam"].tip, frame=h["hub"])}

    tol = 2e-3
    t = np.linspace(0.0, 8.0, 41)
    plan = rf.resolve(build, "tip", tol=tol, t_end=8.0, t_eval=t, deform=("bend_z",))
    fine = []
    for m in (32, 64):
        model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=m)
        r = rf.simulate(model.compile(), 8.0, t_eval=t, rtol=0.0, atol=1e-7)
        fine.append(r.position(h["beam"].tip, frame=h["hub"]))
    limit = fine[1] + (fine[1] - fine[0]) / 3.0
    chosen = plan.handles["tip"](plan.system, plan.solution)
    assert np.linalg.norm(chosen - limit, axis=1).max() < tol
    assert np.linalg.norm(plan.limit["tip"] - limit, axis=1).max() < 0.2 * tol
    assert plan.time_error > 0 and plan.simulate_options == {"atol": rf.studies.resolution.TIME * tol, "rtol": 0.0}


def test_resolve_bad_input_keeps_the_runs():
    sec = rf.Section.rectangle(0.02, 0.005)

    def build(m, deform):
        model = rf.Model(gravity=(0.0, -9.81, 0.0))
        beam = model.add_beam("b", model.ground, 1.0, STEEL, sec, m, deform=deform)
        return model, {"tip": beam.tip}

    with pytest.raises(rf.ResolveError, match=r"outputs: expected names among the handles .*\['tip'\].*\['root'\]"):
        rf.resolve(build, ["root"], tol=1e-4)
    with pytest.raises(ValueError, match="tol: expected a positive"):
        rf.resolve(build, "tip", tol=-1.0)
    with pytest.raises(rf.ResolveError, match="build: expected a function"):
        rf.resolve("model", "tip", tol=1e-4)
    with pytest.raises(rf.ResolveError, match="deform: expected a tuple"):
        rf.resolve(build, "tip", tol=1e-4, deform="bend_z")

    def failing(m, deform):
        if m > 4:
            raise RuntimeError("no mesh")
        return build(m, deform)

    with pytest.raises(rf.ResolveError, match=r"build: expected a function that makes the model, got one that failed for elements = 8.*RuntimeError: no mesh") as caught:
        rf.resolve(failing, "tip", tol=1e-4)
    assert len(caught.value.runs) == 1 and caught.value.runs[0]["elements"] == 4  # nothing lost

    def ignoring(m, deform):
        return build(4, deform)

    with pytest.raises(rf.ResolveError, match="coordinates grow with the elements"):
        rf.resolve(ignoring, "tip", tol=1e-4)
    with pytest.raises(rf.ResolveError, match=r"tol: expected a tolerance that a level up to max_elements = 16") as caught:
        rf.resolve(build, "tip", tol=1e-9, max_elements=16)
    assert "the best estimate reached is" in str(caught.value) and len(caught.value.runs) == 3


# -- the contract (tests/fuzz_contract.py: resolve_options, resolve_output_shape, resolve_huge_t_end) ----------

def strip(calls=None, options=None, **outputs):
    """The fuzzer's builder: a soft strip clamped at the origin, sagging under gravity; ``calls`` counts the
    builder's calls, ``options`` are returned to the runs."""
    def build(elements, deform):
        if calls is not None:
            calls.append(elements)
        model, h = rf.samples.cantilever(elements, material=rf.Material(E=2e7, rho=1000.0),
                                         section=rf.Section.rectangle(0.02, 0.01), deform=deform,
                                         gravity=(0.0, -9.81, 0.0))
        handles = {"tip": h["beam"].tip, **outputs}
        return (model, handles) if options is None else (model, handles, options)
    return build


def test_resolve_judges_the_options_of_its_runs_before_any_run():
    """A bad option of simulate, a bad load_steps: a ValueError naming it (simulate's own checks), before any
    analysis (it was a ResolveError 'build: the analysis of elements = 4 ... failed: ...')."""
    calls = []
    quick = dict(tol=1e-2, max_elements=16, deform=("bend_z",))
    for kw, message in [(dict(method="nope"), r"^method: expected one of \['auto', "),
                        (dict(rtol=-1.0), r"^rtol: expected a non-negative number"),
                        (dict(method="rk4"), r"^dt: expected a positive step in s for the fixed-step method 'rk4'"),
                        (dict(max_steps="x"), r"^max_steps: expected a positive number of steps, got 'x'"),
                        (dict(error_estimate="x"), r"^error_estimate: expected True or False"),
                        (dict(t_eval=[0.0, 1.0]), r"^t_eval: expected increasing times within \[t0, t_end\]")]:
        calls.clear()
        with pytest.raises(ValueError, match=message) as caught:
            rf.resolve(strip(calls), "tip", t_end=0.01, **quick, **kw)
        assert not isinstance(caught.value, rf.SimulationError) and len(calls) <= 1, (kw, calls)
    for load_steps, message in [(0, r"got 0$"), (10**12, r"got 1000000000000$"), ("x", r"got 'x'$")]:
        calls.clear()
        with pytest.raises(ValueError, match=r"^load_steps: expected an integer" + ".*" + message):
            rf.resolve(strip(calls), "tip", load_steps=load_steps, **quick)
        assert calls == []
    # statics simulates nothing: simulate's options are refused, not ignored
    with pytest.raises(ValueError, match=r"^method: expected no options of simulate with t_end = None"):
        rf.resolve(strip(calls), "tip", method="rk4", **quick)
    assert calls == []
    # an unknown option: simulate's TypeError (an unexpected keyword), before the builder is called
    with pytest.raises(TypeError, match=r"unexpected options \['nope'\]"):
        rf.resolve(strip(calls), "tip", t_end=0.01, nope=1, **quick)
    assert calls == []
    # the builder's own options are the builder's fault
    with pytest.raises(rf.ResolveError, match=r"^build: expected options of simulate for elements = 4.*max_steps: "
                                              r"expected a positive number of steps, got -1"):
        rf.resolve(strip(options={"max_steps": -1}), "tip", t_end=0.01, **quick)


def test_resolve_reports_a_failing_run_as_a_simulation_error():
    """A run that fails numerically is a SimulationError naming the time, the cause and the analysis, with the
    runs made before it (it was a ResolveError 'build: ...': a bad argument)."""
    quick = dict(max_elements=16, deform=("bend_z",), t_end=0.01)
    with pytest.raises(rf.SimulationError, match=r"^resolve: the analysis of elements = 4, deform = \('bend_z',\) "
                                                 r"failed at t = [\d.]+ s: max_steps = 2 reached") as caught:
        rf.resolve(strip(), "tip", 1e-2, max_steps=2, **quick)
    e = caught.value
    assert not isinstance(e, ValueError) and e.runs == [] and e.time > 0 and e.cause.startswith("max_steps = 2")
    with pytest.raises(rf.SimulationError, match=r"failed at t = 0 s: the step size fell below the minimum"):
        rf.resolve(strip(), "tip", 1e-300, **quick)  # atol = tol/20 = 5e-302


def test_resolve_refuses_outputs_whose_shape_changes_with_the_elements():
    """An output whose shape follows nq (or an empty one): a ResolveError naming outputs, the output and the
    shapes seen (it was numpy's 'operands could not be broadcast together', or an empty output taken)."""
    build = strip(nq=lambda system, solution: np.zeros(system.nq), empty=lambda system, solution: np.zeros((2, 0)),
                  text=lambda system, solution: "abc")
    quick = dict(tol=1e-2, max_elements=16, deform=("bend_z",))
    with pytest.raises(rf.ResolveError, match=r"^outputs: expected the same shape of 'nq' at every resolution, got "
                                              r"\(8,\) for elements = 8, deform = \('bend_z',\) and \(4,\) for "
                                              r"elements = 4") as caught:
        rf.resolve(build, ["tip", "nq"], **quick)
    assert len(caught.value.runs) == 1
    for t_end in (None, 0.01):
        with pytest.raises(rf.ResolveError, match=r"^outputs: expected a non-empty array from 'empty', got shape "
                                                  r"\(2, 0\)"):
            rf.resolve(build, "empty", t_end=t_end, **quick)
    with pytest.raises(rf.ResolveError, match=r"^outputs: expected 'text' to return an array of numbers .*could not "
                                              r"convert string to float"):
        rf.resolve(build, "text", **quick)


def test_resolve_refuses_a_t_end_it_cannot_reach_at_once():
    """t_end = 1e300 ran max_steps (1,000,000 steps, 10 s; the fuzzer's case) before a ResolveError 'build: ...':
    refused naming t_end after the first analysis's first PACE_STEPS steps; at fixed steps or with max_step by
    (t_end − t0)/dt or /max_step > max_steps, as rf.gradient judges it."""
    import time

    quick = dict(tol=1e-2, max_elements=16, deform=("bend_z",))
    for kw, limit in [({}, "1,000,000"), (dict(method="radau5"), "1,000,000"), (dict(method="dopri5"), "1,000,000")]:
        start = time.perf_counter()
        with pytest.raises(rf.ResolveError, match=rf"^t_end: expected an end time the runs reach within max_steps = "
                                                  rf"{limit} steps, got 1e\+300 s: the first analysis \(elements = 4"):
            rf.resolve(strip(), "tip", t_end=1e300, **quick, **kw)
        assert time.perf_counter() - start < 2.0
    with pytest.raises(rf.ResolveError, match=r"^t_end: .* max_steps = 100,000 steps, got 1e\+300 s"):
        rf.resolve(strip(options={"max_steps": 100_000}), "tip", t_end=1e300, **quick)  # the builder's max_steps
    with pytest.raises(rf.ResolveError, match=r"^t_end, dt: expected at most max_steps = 1,000,000 steps of dt over "
                                              r"\[t0, t_end\], got \(t_end - t0\)/dt = 1e\+07 steps"):
        rf.resolve(strip(), "tip", t_end=1e4, method="rk4", dt=1e-3, **quick)
    with pytest.raises(rf.ResolveError, match=r"^t_end: .*its steps of at most max_step = 0.001 s need at least 1e\+07"):
        rf.resolve(strip(), "tip", t_end=1e4, max_step=1e-3, **quick)
    # a t_end within reach: the first analysis runs past its first PACE_STEPS steps (2,500 here) and resolve goes on
    plan = rf.resolve(strip(), "tip", t_end=0.05, method="rk4", dt=2e-5, **quick)
    assert plan.elements in (4, 8) and len(plan.runs) >= 3
