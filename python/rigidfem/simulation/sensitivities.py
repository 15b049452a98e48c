"""Forward sensitivities: the derivatives of a simulation's state and outputs by a few parameters.

``rigidfem.simulate(system, t_end, method, sensitivities=[...])`` integrates, with the state and in C++,
S_j = [∂q/∂p_j, ∂q̇/∂p_j] for each name p_j given: a named parameter of the system
(``System.parameters``: ``"<beam>.E"``, ``"<body>.mass"``, ``"<element>.stiffness"``, ...) or an initial
value, ``"q0[<coordinate>]"`` or ``"qd0[<coordinate>]"``. Differentiating A(q; p) q̈ = f(q, q̇, t; p),

    A S̈ + (∂r/∂q) S_q + (∂r/∂q̇) S_q̇ + ∂r/∂p = 0,      r = A q̈ − f,

(with closed loops also Gᵀ δλ and G S̈ = δγ). The explicit Runge–Kutta methods integrate S with the same
stages as the state, so S is the derivative of their discrete solution at the same steps; the Newmark family
(newmark, hht, generalized_alpha, implicit_spring), esdirk43 and radau5 solve each step's (stages')
differentiated equations with their own Newton matrix after the step has converged (the staggered direct
method); auto carries them through its probe and hand-over. ∂r/∂p = (r(p + h) − r(p))/h with
the system at p + h (``System.with_parameters``: the constants a parameter sets enter the residual linearly,
so this is exact to round-off; a profile's number by a central difference); the derivatives along S are the
analytic tangent's K S_q + C S_q̇ (recursive systems up to 200 coordinates: O(n²) per state, shared by the
parameters) or central differences of the residual along the direction (about 1e-10 relative), and A⁻¹ is
the forward dynamics' own factorisation (O(n)). Step sizes are the state's, and the
sensitivities' error is not controlled. A Python force law or drive is differentiated through these central
differences alike. Closed loops: the sensitivities are projected onto the tangent of the constraints with the
state (the derivative of its projection); an initial value moves along the loops as ``System.assemble``
closes them. A drive's or an actuator's numbers move the loops' g(q, t; p) too: their ∂g/∂p, ∂ġ/∂p, ∂γ/∂p
(central differences of the systems at p ± h) enter the differentiated constraints and the projection.

``Result.sensitivity(name)`` returns (∂q/∂p, ∂q̇/∂p), each (len t, nq); ``Result.position_sensitivity(point,
name)`` the derivative (len t, 3) of a point's position. Not yet: Maxwell arms (refused).

Examples
--------
>>> import rigidfem as rf
>>> model, h = rf.samples.spring_mass()
>>> res = rf.simulate(model.compile(), 1.0, "rk4", dt=1e-3, q0=[0.1], sensitivities=["q0[block.x]"])
>>> dq, dqd = res.sensitivity("q0[block.x]")
>>> round(float(dq[0, 0]), 6), dq.shape
(1.0, (1001, 1))
"""

from __future__ import annotations

import numpy as np

from ..base import _checks
from ..model import parameters as parameters_


def directions(system, names, options, t0: float, t1: float, argument: str = "sensitivities",
               one_sided_drives: bool = False) -> list[str]:
    """Adds each named direction's systems at p + h (and p − h for a profile's number) and initial sensitivity
    to the C++ ``options`` for a run over [t0, t1] (s); returns the names. ``one_sided_drives`` (the adjoint's,
    which differences only a drive's (q, q̇, q̈), not the residual): a number a drive's profile is affine in (a
    spline's values) takes the system at p + h alone, h = |p| (1 at p = 0), on a system without loops (whose g,
    G and γ the prescribed coordinates reach nonlinearly). ValueError naming what is not a parameter or an
    initial value of the system."""
    system = _checks.system(system)
    names = parameters_.names_argument(names, argument, "parameter names (System.parameters) or initial "
                                                              "values 'q0[<coordinate>]', 'qd0[<coordinate>]'")
    n = system.nq
    for name in names:
        S0 = np.zeros(2 * n)
        initial = parameters_.initial_value(system, name, argument)
        if initial is not None:
            part, k = initial
            S0[k if part == "q0" else n + k] = 1.0
            options.add_sensitivity(None, None, 0.0, S0)
            continue
        params = system._parameters
        parameter = params.parameter(name, argument)  # ValueError naming an unknown one
        if parameter.linear or (one_sided_drives and not system.nl and params.drive_affine(name)):
            h = params.step(name)
            options.add_sensitivity(params.shifted(system, name, h), None, h, S0)
            continue
        plus, minus, h = params.profile_pair(system, name, t0, t1, argument)
        options.add_sensitivity(plus, minus, h, S0)
    return names


def split(system, names: list[str], raw: np.ndarray) -> dict[str, np.ndarray]:
    """{name: (len t, 2 nq) [∂q/∂p, ∂q̇/∂p]} of the C++ run's (len t, 2 nq P) rows."""
    system = _checks.system(system)
    m = 2 * system.nq
    return {name: np.ascontiguousarray(raw[:, m * j:m * (j + 1)]) for j, name in enumerate(names)}
