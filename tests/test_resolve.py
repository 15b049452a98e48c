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
        model.add_force(beam.tip, (0.0, k * STEEL.E * sec.Iz, 0.0))
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
            model.add_force(tip, (0.0, 0.0, 20.0))
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

    with pytest.raises(rf.ResolveError, match=r"build: failed for elements = 8.*RuntimeError: no mesh") as caught:
        rf.resolve(failing, "tip", tol=1e-4)
    assert len(caught.value.runs) == 1 and caught.value.runs[0]["elements"] == 4  # nothing lost

    def ignoring(m, deform):
        return build(4, deform)

    with pytest.raises(rf.ResolveError, match="coordinates grow with the elements"):
        rf.resolve(ignoring, "tip", tol=1e-4)
    with pytest.raises(rf.ResolveError, match=r"tol: expected a tolerance that a level up to max_elements = 16") as caught:
        rf.resolve(build, "tip", tol=1e-9, max_elements=16)
    assert "the best estimate reached is" in str(caught.value) and len(caught.value.runs) == 3
