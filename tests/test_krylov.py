"""The matrix-free Newton matrix (iteration_matrix="krylov", newton_matrix.hpp): the exact tangent
applied as directional derivatives of the inverse dynamics and solved by GMRES preconditioned with
the spring matrix, O(n) per iteration. References: the same methods with the dense tangent, and
implicit_spring (the same generalised-α scheme, so the same discrete solution)."""

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import samples


def kane(m=12):
    model, hd = samples.kane_beam(elements=m)
    return model.compile(), hd["beam"].tip


def large_beam(m, loop=False):
    """A planar steel cantilever (1 m, bending only) under gravity and a 20 N tip load; with loop,
    its tip held 0.5 m from a ground point by a distance loop."""
    model, hd = samples.cantilever(elements=m, deform=("bend_z",), gravity=(0.0, -9.81, 0.0))
    model.add_force("load0", hd["beam"].tip, (0.0, 20.0, 0.0))
    if loop:
        model.add_loop_joint("loop0", "distance", hd["beam"].tip, model.ground.point((1.0, 0.5, 0.0)), length=0.5)
    return model.compile(), hd["beam"].tip


@pytest.mark.parametrize("method,options", [("generalized_alpha", {"dt": 0.02}),
                                            ("esdirk43", {"rtol": 1e-7, "atol": 1e-10}),
                                            ("radau5", {"rtol": 1e-7, "atol": 1e-7}),
                                            ("radau9", {"rtol": 1e-7, "atol": 1e-7})])
def test_krylov_gives_the_dense_tangents_solution_on_kanes_beam(method, options):
    """Kane's spin-up beam over the spin-up (the centrifugal stiffness the spring matrix leaves out):
    the tip with the matrix-free tangent is the dense tangent's to far below the tolerance."""
    system, tip = kane()
    t = np.linspace(0.0, 4.0, 9)
    runs = {m: rf.simulate(system, 4.0, method=method, t_eval=t, iteration_matrix=m, **options)
            for m in ("tangent", "krylov")}
    assert runs["tangent"].stats["linear_iterations"] == 0 and runs["krylov"].stats["linear_iterations"] > 0
    a, b = (runs[m].position(tip) for m in ("tangent", "krylov"))
    scale = np.abs(a - a[0]).max()  # the tip's travel
    assert np.abs(a - b).max() < 1e-6 * scale


def test_the_preconditioner_is_the_spring_matrix_in_real_and_complex_arithmetic():
    """On a cantilever the spring matrix M + diag(c1 b + c2 k) is the tangent but for gravity's and
    the load's small terms, so GMRES converges in one iteration per solve: radau5's real and complex
    blocks (the complex articulated-body factorisation; radau9's two complex blocks each their own) and
    generalised-α's."""
    system, _ = large_beam(300)
    for method, solves in (("radau5", 2), ("radau9", 3), ("generalized_alpha", 1)):
        res = rf.simulate(system, 0.01, method=method, dt=1e-3, adaptive=False, iteration_matrix="krylov")
        st = res.stats
        assert st["linear_iterations"] <= solves * st["newton_iterations"] * 1.05, (method, st)


def test_auto_takes_krylov_above_200_coordinates():
    small, _ = large_beam(150)
    big, tip = large_beam(250)
    assert rf.simulate(small, 0.005, method="generalized_alpha", dt=1e-3).stats["linear_iterations"] == 0
    auto = rf.simulate(big, 0.005, method="generalized_alpha", dt=1e-3, t_eval=[0.005])
    dense = rf.simulate(big, 0.005, method="generalized_alpha", dt=1e-3, t_eval=[0.005], iteration_matrix="tangent")
    assert auto.stats["linear_iterations"] > 0
    assert np.allclose(auto.position(tip), dense.position(tip), rtol=0, atol=1e-12)


@pytest.mark.parametrize("method,options", [("generalized_alpha", {"dt": 1e-3}),
                                            ("esdirk43", {"dt": 1e-3, "adaptive": False}),
                                            ("radau5", {"dt": 1e-3, "adaptive": False}),
                                            ("radau9", {"dt": 1e-3, "adaptive": False})])
def test_closed_loop_with_krylov(method, options):
    """The loops' Schur complement with GMRES solves: the dense tangent's solution, the loop closed."""
    system, tip = large_beam(40, loop=True)
    runs = [rf.simulate(system, 0.02, method=method, iteration_matrix=m, t_eval=[0.02], **options)
            for m in ("tangent", "krylov")]
    a, b = (r.position(tip)[-1] for r in runs)
    assert np.abs(a - b).max() < 1e-9
    g = system.loop_constraints(0.02, runs[1].q[-1], runs[1].qd[-1])[0]
    assert np.abs(g).max() < 1e-10


def test_a_3000_element_beam_steps_in_o_n():
    """3000 coordinates: a dense tangent would need a 3000 × 3000 LU (complex for radau5) per
    factorisation. The matrix-free generalised-α gives implicit_spring's solution (the same scheme),
    and radau5 and auto (radau5 from the start) agree with it to the step's accuracy."""
    system, tip = large_beam(3000)
    spring = rf.simulate(system, 3e-3, method="implicit_spring", dt=1e-3, t_eval=[3e-3])
    alpha = rf.simulate(system, 3e-3, method="generalized_alpha", dt=1e-3, t_eval=[3e-3])
    assert alpha.stats["linear_iterations"] > 0
    assert np.abs(alpha.position(tip) - spring.position(tip)).max() < 1e-10
    radau = rf.simulate(system, 3e-3, method="radau5", dt=1e-3, adaptive=False, t_eval=[3e-3])
    auto = rf.simulate(system, 1e-3, rtol=0.0, atol=1e-4, t_eval=[1e-3])
    assert "radau5" in auto.stats["method"] and auto.stats["linear_iterations"] > 0
    travel = np.abs(spring.position(tip)[-1] - [1.0, 0.0, 0.0]).max()  # from the straight beam's tip
    assert travel > 1e-6
    assert np.abs(radau.position(tip)[-1] - alpha.position(tip)[-1]).max() < 0.05 * travel


def test_krylov_needs_the_recursive_formulation():
    model, _ = samples.cantilever(elements=4)
    system = model.compile("lagrange")
    with pytest.raises(ValueError, match="^iteration_matrix: 'krylov' needs a system compiled with algorithm"):
        rf.simulate(system, 0.01, method="generalized_alpha", dt=1e-3, iteration_matrix="krylov")
