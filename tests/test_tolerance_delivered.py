"""A tolerance asked for is a tolerance delivered, or the method says it could not (issue 16, item 4;
issue 24).

On Kane's spin-up beam (m = 10, 20 s) against dopri5 at rtol = 1e-12 on the same chain: the tip's
RMS error over what was asked stays within a small factor for every adaptive method that does not
warn. What is asked: rtol × the model's size L (m, ``stats["model_size"]``) where the method measures
its error on the bodies' displacements (radau5, auto, the adaptive Newmark family: error_on=None),
rtol × the tip's RMS deflection where it holds the state (esdirk43, dopri5, rkf45: a relative
tolerance on every coordinate asks about that much of what one watches). Before the Newmark family
held its estimate per unit step, generalized_alpha left 21-210 times the tolerance.
"""

import warnings

import numpy as np
import pytest

import rigidfem as rf
from rigidfem.studies.study import reference, scenes


@pytest.fixture(scope="module")
def kane():
    scene = scenes.kane(6.0, 10, t_end=20.0)
    tip = reference(scene, rtol=1e-12).position(scene.tip, frame=scene.frame)
    deflection = np.sqrt(np.mean(np.sum((tip - tip[0]) ** 2, axis=1)))

    def delivered_over_asked(method, rtol, **options):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = rf.simulate(scene.system, scene.t_end, method=method, t_eval=scene.t_eval, rtol=rtol,
                            atol=1e-3 * rtol, **options)
        error = np.sqrt(np.mean(np.sum((r.position(scene.tip, frame=scene.frame) - tip) ** 2, axis=1)))
        outputs = np.isfinite(r.stats["model_size"])
        return error / (rtol * (r.stats["model_size"] if outputs else deflection)), [str(w.message) for w in caught], r

    return scene, delivered_over_asked


@pytest.mark.parametrize("method", ["newmark", "hht", "generalized_alpha", "implicit_spring"])
def test_the_newmark_family_delivers_its_tolerance(kane, method):
    _, run = kane
    for rtol in (1e-2, 1e-3):
        ratio, caught, _ = run(method, rtol, adaptive=True)
        assert ratio < 2.0 and not caught, (method, rtol, ratio, caught)  # measured (m = 10): 0.56-0.80


@pytest.mark.parametrize("method", ["esdirk43", "radau5", "auto"])
def test_the_high_order_methods_deliver_their_tolerance(kane, method):
    _, run = kane
    for rtol in (1e-2, 1e-4):
        ratio, caught, _ = run(method, rtol)
        assert ratio < 3.0 and not caught, (method, rtol, ratio, caught)  # measured (m = 20): 0.013-1.74


def test_rkf45_says_when_its_step_is_bound_by_stability(kane):
    _, run = kane
    ratio, caught, r = run("rkf45", 1e-3)
    assert np.isfinite(r.stats["stiff_at"])
    assert any("stiff" in c and "rkf45" in c for c in caught), caught


def test_implicit_spring_falls_back_on_the_tangent_where_its_spring_iterations_fail():
    # m = 20 at dt = 0.05 s: the spring iterations alone stopped converging near t = 12 s as the hub spins up.
    scene = scenes.kane(6.0, 20, t_end=20.0)
    spring = rf.simulate(scene.system, scene.t_end, method="implicit_spring", dt=0.05, t_eval=scene.t_eval)
    alpha = rf.simulate(scene.system, scene.t_end, method="generalized_alpha", dt=0.05, t_eval=scene.t_eval)
    assert spring.stats["jacobians"] > 0  # the fallback ran
    np.testing.assert_allclose(spring.q, alpha.q, atol=1e-7)  # both solve the same step equations


def test_a_newton_failure_names_the_iteration_limit_not_the_stability_limit():
    scene = scenes.kane(6.0, 10, t_end=20.0)
    with pytest.raises(rf.SimulationError, match="newton_max_iterations = 1") as caught:
        rf.simulate(scene.system, scene.t_end, method="generalized_alpha", dt=0.5, newton_max_iterations=1)
    assert "stability limit" not in str(caught.value)
